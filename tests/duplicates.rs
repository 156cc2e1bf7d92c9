//! Duplicate tracks: one object measured at two points of its body by two sensors makes two
//! tracks that trade its measurements; they are merged into the older, while two objects side
//! by side, measured in the same scans, keep their own tracks.

use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::tracker::Tracker;

fn config(duplicate_updates: u32) -> Config {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.tracker.duplicate_updates = duplicate_updates;
    config.association.cost = primm_core::config::AssociationCost::Paper;
    // A gate tighter than the two reflection points' distance, so that the second starts a track.
    config.classes.car.paper_gate_m = 1.0;
    config.classes.pedestrian.paper_gate_m = 0.5;
    config
}

/// A measurement of an object at (x, y) moving along x at `speed_mps`, seen from the origin.
fn measurement(class: ObjectClass, x: f64, y: f64, speed_mps: f64, sensor: u16, gt: u64) -> Measurement {
    Measurement {
        x_m: x,
        y_m: y,
        radial_velocity_mps: speed_mps * x / x.hypot(y),
        rcs_dbsm: 10.0,
        class,
        sensor_id: Some(sensor),
        ground_truth_id: Some(gt),
    }
}

/// A car at 5 m/s seen alternately by sensor 3 at its rear and sensor 2 at its side, 2 m apart.
fn alternating_car(frames: usize) -> Vec<Frame> {
    (0..frames)
        .map(|k| {
            let t = 0.03 * k as f64;
            let mut frame = Frame::new(t);
            let (x, sensor) = if k % 2 == 0 { (30.0 + 5.0 * t, 3) } else { (32.0 + 5.0 * t, 2) };
            frame.measurements.push(measurement(ObjectClass::Car, x, 2.0, 5.0, sensor, 7));
            frame
        })
        .collect()
}

#[test]
fn two_tracks_trading_one_objects_measurements_are_merged_into_the_older() {
    let frames = alternating_car(40);
    let mut without = Tracker::new(config(0)).unwrap();
    for frame in &frames {
        without.step(frame).unwrap();
    }
    assert!(without.tracks().len() >= 2, "the tight gate makes a second track");
    assert_eq!(without.stats().duplicate_tracks_merged, 0);

    let mut with = Tracker::new(config(4)).unwrap();
    let mut first_ids = Vec::new();
    for frame in &frames {
        let outputs = with.step(frame).unwrap();
        first_ids.push(outputs.iter().map(|o| o.id).min().unwrap());
    }
    assert!(with.stats().duplicate_tracks_merged >= 1, "{:?}", with.stats());
    // The oldest track lives on throughout: merging keeps the older id.
    assert!(first_ids.iter().all(|&id| id == first_ids[0]), "{first_ids:?}");
    // Merged tracks are not counted as deleted: every started track is live, deleted or merged.
    let stats = with.stats();
    assert_eq!(
        stats.tracks_initiated,
        with.tracks().len() as u64 + stats.tracks_deleted + stats.duplicate_tracks_merged
    );
}

#[test]
fn two_pedestrians_side_by_side_measured_in_the_same_scans_are_never_merged() {
    let mut config = config(2);
    config.classes.pedestrian.paper_gate_m = Config::default().classes.pedestrian.paper_gate_m;
    let mut tracker = Tracker::new(config).unwrap();
    for k in 0..60 {
        let t = 0.03 * k as f64;
        let mut frame = Frame::new(t);
        let x = 20.0 + 1.3 * t;
        frame.measurements.push(measurement(ObjectClass::Pedestrian, x, 5.0, 1.3, 3, 1));
        frame.measurements.push(measurement(ObjectClass::Pedestrian, x, 5.8, 1.3, 3, 2));
        tracker.step(&frame).unwrap();
    }
    assert_eq!(tracker.stats().duplicate_tracks_merged, 0);
    assert_eq!(tracker.tracks().len(), 2);
}
