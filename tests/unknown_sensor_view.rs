//! A radar without a configured mount (`frame.unknown_sensor_margin_rad`,
//! `unknown_sensor_margin_m`; `FieldOfView::spanning`): it is taken to look where its
//! detections of the frame lie, so a track elsewhere keeps its existence when that radar does not
//! detect it; bad margins are refused naming their key.

use crate::common::invalid_key;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

/// Two standing cars, one 30 m ahead and one 30 m to the left, each seen by its own radar,
/// neither of them configured (no sensor id, and id 9): the radars report in turn, 25 ms apart.
fn frames() -> Vec<Frame> {
    (0..80)
        .map(|k| {
            let mut frame = Frame::new(k as f64 * 0.025);
            let (x_m, y_m, sensor_id) = if k % 2 == 0 { (30.0, 0.0, None) } else { (0.0, 30.0, Some(9)) };
            frame.measurements.push(Measurement {
                x_m,
                y_m,
                radial_velocity_mps: 0.0,
                rcs_dbsm: 10.0,
                class: ObjectClass::Car,
                sensor_id,
                ground_truth_id: Some(k % 2),
            });
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            frame
        })
        .collect()
}

/// Each live track's (confirmed, existence probability) after the last frame, and how many
/// times a track missed a detection in view over the whole run.
fn run(config: Config) -> (Vec<(bool, f64)>, u64) {
    let mut tracker = Tracker::new(config).unwrap();
    let (mut last, mut missed) = (Vec::new(), 0);
    for frame in frames() {
        last = tracker
            .step(&frame)
            .unwrap()
            .iter()
            .map(|o| (o.status.is_confirmed(), o.existence_probability))
            .collect();
        missed += tracker.last_step().counts.tracks_missed_in_view;
    }
    (last, missed)
}

#[test]
fn a_track_outside_an_unknown_radars_detections_keeps_its_existence_when_that_radar_misses_it() {
    let (tracks, missed) = run(Config::default());
    let mut everywhere = Config::default();
    everywhere.frame.unknown_sensor_margin_rad = std::f64::consts::PI;
    everywhere.frame.unknown_sensor_margin_m = 1000.0;
    let (tracks_everywhere, missed_everywhere) = run(everywhere);
    assert_eq!(tracks.len(), 2, "{tracks:?}");
    assert_eq!(missed, 0, "each radar's sector holds only its own car");
    assert!(missed_everywhere > 0);
    for (&(confirmed, existence), &(_, existence_everywhere)) in tracks.iter().zip(&tracks_everywhere) {
        assert!(confirmed);
        assert!(existence > existence_everywhere, "{existence} vs {existence_everywhere}");
    }
}

#[test]
fn margins_outside_their_ranges_are_refused() {
    for (angle, distance, key) in [
        (-0.1, 10.0, "frame.unknown_sensor_margin_rad"),
        (3.2, 10.0, "frame.unknown_sensor_margin_rad"),
        (f64::NAN, 10.0, "frame.unknown_sensor_margin_rad"),
        (0.35, -1.0, "frame.unknown_sensor_margin_m"),
        (0.35, f64::INFINITY, "frame.unknown_sensor_margin_m"),
    ] {
        let mut config = Config::default();
        config.frame.unknown_sensor_margin_rad = angle;
        config.frame.unknown_sensor_margin_m = distance;
        assert_eq!(invalid_key(Tracker::new(config)), key, "{angle} {distance}");
    }
}
