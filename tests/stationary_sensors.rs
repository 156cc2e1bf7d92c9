//! `frame.stationary`: the frames of a roadside radar carry no ego pose; declared stationary,
//! they are tracked in the world frame at the origin, where the radial velocity is over ground.

use primm_core::config::Config;
use primm_core::coordinates::CoordinateFrame;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

/// A car crossing in front of the sensor along y at 10 m/s, 30 m ahead: its radial velocity is
/// the velocity's part along the line of sight from the origin.
fn crossing_car(t: f64) -> Measurement {
    let position = glam::DVec2::new(30.0, -10.0 + 10.0 * t);
    let radial_velocity_mps = glam::DVec2::new(0.0, 10.0).dot(position.normalize());
    Measurement {
        x_m: position.x,
        y_m: position.y,
        radial_velocity_mps,
        rcs_dbsm: 10.0,
        class: ObjectClass::Car,
        sensor_id: None,
        ground_truth_id: Some(1),
    }
}

/// Runs 20 scans without a pose (or with the identity pose) and returns the tracking frame of
/// the last step, the frames counted as without a pose and the track's velocity.
fn run(stationary: bool, with_pose: bool) -> (CoordinateFrame, u64, glam::DVec2) {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.frame.stationary = stationary;
    let mut tracker = Tracker::new(config).unwrap();
    let mut velocity = glam::DVec2::ZERO;
    let mut without_pose = 0;
    for k in 0..20 {
        let t = 0.05 * k as f64;
        let mut frame = Frame::new(t);
        frame.measurements.push(crossing_car(t));
        if with_pose {
            frame.ego_pose = Some(EgoPose::default());
        }
        let outputs = tracker.step(&frame).unwrap();
        velocity = outputs[0].velocity_mps;
        without_pose += tracker.last_step().counts.frames_without_ego_pose;
    }
    (tracker.last_step().tracking_frame, without_pose, velocity)
}

#[test]
fn a_stationary_sensors_frames_without_a_pose_are_tracked_in_the_world_frame() {
    let (frame, without_pose, _) = run(true, false);
    assert_eq!((frame, without_pose), (CoordinateFrame::World, 0));
    let (frame, without_pose, _) = run(false, false);
    assert_eq!((frame, without_pose), (CoordinateFrame::Vehicle, 20));
}

#[test]
fn declaring_the_sensor_stationary_tracks_as_the_identity_pose_does() {
    // The same frames with the identity pose given: the same velocity to the bit.
    let (_, _, declared) = run(true, false);
    let (_, _, given) = run(false, true);
    assert_eq!(declared, given);
    assert!((declared - glam::DVec2::new(0.0, 10.0)).length() < 2.0, "{declared}");
}
