//! The radar's own noise (`frame.sensors[].range_std_m`, `azimuth_std_rad`,
//! `azimuth_std_max_factor`; `primm_core::sensor_noise`): it changes world-frame steps and only
//! those, a far detection moves a track less across the line of sight than a near one, and bad
//! values are refused naming their section.

use crate::common::{invalid_key, scene_frames, SceneObject};
use glam::DVec2;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::track::TrackOutput;
use primm_core::tracker::Tracker;

/// The shipped configuration with every sensor's own noise removed.
fn without_sensor_noise() -> Config {
    let mut config = Config::default();
    for mount in config.frame.sensors.iter_mut() {
        (mount.range_std_m, mount.azimuth_std_rad, mount.azimuth_std_max_factor) = (0.0, 0.0, 1.0);
    }
    config
}

/// A car and a pedestrian seen by sensor 3 (the front-left radar), from 15 to 60 m.
fn frames(posed: bool) -> Vec<Frame> {
    let objects = [
        SceneObject {
            id: 1,
            class: ObjectClass::Car,
            start: [15.0, 8.0],
            velocity: [8.0, 1.0],
            visible: (0.0, f64::INFINITY),
        },
        SceneObject {
            id: 2,
            class: ObjectClass::Pedestrian,
            start: [12.0, 4.0],
            velocity: [1.2, 0.3],
            visible: (0.0, f64::INFINITY),
        },
    ];
    scene_frames(&objects, 80, 0.05, 0.3, 5)
        .into_iter()
        .map(|mut frame| {
            for measurement in frame.measurements.iter_mut() {
                measurement.sensor_id = Some(3);
            }
            if posed {
                frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            }
            frame
        })
        .collect()
}

fn run(config: &Config, frames: &[Frame]) -> Vec<Vec<TrackOutput>> {
    let mut tracker = Tracker::new(config.clone()).unwrap();
    frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect()
}

#[test]
fn the_radar_noise_changes_the_steps_with_an_ego_pose_and_only_those() {
    let (with, without) = (Config::default(), without_sensor_noise());
    assert!(
        with.frame.sensors.iter().all(|mount| mount.azimuth_std_rad > 0.0),
        "the shipped sensors have noise"
    );
    let vehicle = frames(false);
    assert_eq!(format!("{:?}", run(&with, &vehicle)), format!("{:?}", run(&without, &vehicle)));
    let world = frames(true);
    let (noisy, plain) = (run(&with, &world), run(&without, &world));
    assert_ne!(format!("{noisy:?}"), format!("{plain:?}"));
    // Both still track both objects to the end.
    for outputs in [&noisy, &plain] {
        let last = outputs.last().unwrap();
        assert_eq!(last.iter().filter(|o| o.status.is_confirmed()).count(), 2, "{last:?}");
    }
}

/// How far a standing car's track at `range_m` on a radar's boresight moves across the line of
/// sight when a detection lies 1 m beside the earlier ones.
fn pull_across(config: &Config, range_m: f64) -> f64 {
    let mut tracker = Tracker::new(config.clone()).unwrap();
    let pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
    // Sensor 2 (front right) sits at (3.86, -0.70) and looks 25° to the right: put the
    // detections on its boresight.
    let sensor = DVec2::new(3.86, -0.70);
    let boresight = DVec2::new((-25f64).to_radians().cos(), (-25f64).to_radians().sin());
    let across = boresight.perp();
    let first = sensor + boresight * range_m;
    let detection = |position: DVec2| Measurement {
        x_m: position.x,
        y_m: position.y,
        radial_velocity_mps: 0.0,
        rcs_dbsm: 10.0,
        class: ObjectClass::Car,
        sensor_id: Some(2),
        ground_truth_id: None,
    };
    let mut position = DVec2::NAN;
    // A standing car, seen twelve times at one place, then once 1 m beside it.
    let seen = (0..12).map(|k| (0.05 * k as f64, first)).chain([(0.6, first + across)]);
    for (t, detected) in seen {
        let mut frame = Frame::new(t);
        frame.ego_pose = pose;
        frame.measurements.push(detection(detected));
        let outputs = tracker.step(&frame).unwrap();
        assert_eq!(outputs.len(), 1, "{outputs:?}");
        position = outputs[0].position_m;
    }
    (position - first).dot(across)
}

#[test]
fn a_far_detection_moves_a_track_less_across_the_line_of_sight_than_a_near_one() {
    let (near, far) = (pull_across(&Config::default(), 8.0), pull_across(&Config::default(), 90.0));
    assert!(near > 0.2 && far > 0.0, "near {near} m, far {far} m");
    assert!(far < 0.85 * near, "near {near} m, far {far} m");
    // Without the radar's noise the range does not matter.
    let plain = without_sensor_noise();
    let (near, far) = (pull_across(&plain, 8.0), pull_across(&plain, 90.0));
    assert!((far - near).abs() < 0.05 * near, "near {near} m, far {far} m");
}

#[test]
fn bad_radar_noise_is_refused_naming_the_sensors() {
    let bad: [(f64, f64, f64); 5] =
        [(-0.1, 0.01, 1.0), (f64::NAN, 0.01, 1.0), (0.1, 0.6, 1.0), (0.1, -0.01, 1.0), (0.1, 0.01, 0.5)];
    for (range, azimuth, factor) in bad {
        let mut config = Config::default();
        let mount = &mut config.frame.sensors[1];
        (mount.range_std_m, mount.azimuth_std_rad, mount.azimuth_std_max_factor) = (range, azimuth, factor);
        assert_eq!(invalid_key(Tracker::new(config)), "frame.sensors", "{range} {azimuth} {factor}");
    }
}
