//! The highest speed of a class (`classes.<class>.max_speed_mps`): a track that detections
//! running away from its object pull faster is held at that speed over ground in steps with an
//! ego pose, and counted; without a pose, or without the key, it is not; bad values are refused
//! naming the key.

use crate::common::invalid_key;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

const DT_S: f64 = 0.05;

/// A car driving along x at 20 m/s, seen by sensor 2 (front right) every 50 ms; from frame 30 on
/// its detections (and their radial velocities) run ahead, faster every frame, each within the
/// gate of the track's prediction: a feed that, followed, makes the car faster than any car.
fn runaway_frames(posed: bool) -> Vec<Frame> {
    let (mut x_m, mut speed_mps) = (10.0, 20.0);
    (0..70)
        .map(|k| {
            if k >= 30 {
                speed_mps += 6.0;
            }
            x_m += speed_mps * DT_S;
            let mut frame = Frame::new(k as f64 * DT_S);
            frame.measurements.push(Measurement {
                x_m,
                y_m: -3.0,
                radial_velocity_mps: speed_mps * x_m / x_m.hypot(3.0),
                rcs_dbsm: 10.0,
                class: ObjectClass::Car,
                sensor_id: Some(2),
                ground_truth_id: Some(1),
            });
            if posed {
                frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            }
            frame
        })
        .collect()
}

/// The fastest speed any output reported, m/s, and the tracker's count of bounded speeds.
fn fastest(config: &Config, frames: &[Frame]) -> (f64, u64) {
    let mut tracker = Tracker::new(config.clone()).unwrap();
    let mut fastest: f64 = 0.0;
    for frame in frames {
        for output in tracker.step(frame).unwrap() {
            fastest = fastest.max(output.velocity_mps.length());
        }
    }
    (fastest, tracker.stats().speeds_bounded)
}

fn without_bound() -> Config {
    let mut config = Config::default();
    config.classes.car.max_speed_mps = None;
    config
}

#[test]
fn a_track_pulled_ever_faster_is_held_at_its_class_s_highest_speed_in_the_world_frame() {
    let config = Config::default();
    let bound = config.classes.car.max_speed_mps.expect("the shipped configuration bounds cars");
    let frames = runaway_frames(true);
    let (unbounded, never) = fastest(&without_bound(), &frames);
    assert!(
        unbounded > bound + 10.0,
        "the feed makes an unbounded track faster than cars drive: {unbounded}"
    );
    assert_eq!(never, 0);
    let (bounded, count) = fastest(&config, &frames);
    assert!(bounded <= bound + 1e-9, "{bounded} m/s above the bound of {bound}");
    assert!(count > 0);
}

#[test]
fn without_an_ego_pose_speeds_are_relative_and_not_bounded() {
    let frames = runaway_frames(false);
    let (with, count) = fastest(&Config::default(), &frames);
    assert_eq!(count, 0);
    assert_eq!(with, fastest(&without_bound(), &frames).0);
}

#[test]
fn a_car_driving_below_the_bound_is_tracked_exactly_as_without_it() {
    let frames: Vec<Frame> = runaway_frames(true).into_iter().take(30).collect();
    let run = |config: Config| {
        let mut tracker = Tracker::new(config).unwrap();
        let outputs: Vec<_> = frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect();
        (format!("{outputs:?}"), tracker.stats().speeds_bounded)
    };
    let (bounded, count) = run(Config::default());
    assert_eq!(count, 0);
    assert_eq!(bounded, run(without_bound()).0);
}

#[test]
fn a_bound_that_is_not_a_positive_speed_is_refused() {
    for bad in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        let mut config = Config::default();
        config.classes.pedestrian.max_speed_mps = Some(bad);
        assert_eq!(invalid_key(Tracker::new(config)), "classes.pedestrian.max_speed_mps", "{bad}");
    }
}
