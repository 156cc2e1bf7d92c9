//! `frame.platform`: the frames of a roadside radar carry no ego pose; declared stationary, or
//! found so from the data ("auto"), they are tracked in the world frame at the origin, where
//! the radial velocity is over ground.

use primm_core::config::Config;
use primm_core::coordinates::CoordinateFrame;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::sensor::platform::PlatformModel;
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
fn run(platform: PlatformModel, with_pose: bool) -> (CoordinateFrame, u64, glam::DVec2) {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.frame.platform = platform;
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
    let (frame, without_pose, _) = run(PlatformModel::Stationary, false);
    assert_eq!((frame, without_pose), (CoordinateFrame::World, 0));
    let (frame, without_pose, _) = run(PlatformModel::Moving, false);
    assert_eq!((frame, without_pose), (CoordinateFrame::Vehicle, 20));
}

#[test]
fn declaring_the_sensor_stationary_tracks_as_the_identity_pose_does() {
    // The same frames with the identity pose given: the same velocity to the bit.
    let (_, _, declared) = run(PlatformModel::Stationary, false);
    let (_, _, given) = run(PlatformModel::Moving, true);
    assert_eq!(declared, given);
    assert!((declared - glam::DVec2::new(0.0, 10.0)).length() < 2.0, "{declared}");
}

/// Cars around the sensor at several bearings, seen for `seconds` at 20 Hz without a pose:
/// with `ego_speed_mps` 0 the sensor stands and the radial velocities are those of the tracks'
/// motion; otherwise it drives along x at that speed, the detections are relative to it and the
/// radial velocities over ground (of objects that stand still).
fn scene(ego_speed_mps: f64, seconds: f64) -> Vec<Frame> {
    let starts = [(30.0, -20.0), (-25.0, 15.0), (10.0, 35.0), (40.0, 10.0), (-15.0, -30.0), (20.0, 25.0)];
    let velocities = [(0.0, 8.0), (6.0, 0.0), (-5.0, -3.0), (0.0, -7.0), (4.0, 4.0), (-6.0, 2.0)];
    (0..(seconds * 20.0) as usize)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            for (id, (&start, &velocity)) in starts.iter().zip(&velocities).enumerate() {
                let over_ground =
                    if ego_speed_mps > 0.0 { glam::DVec2::ZERO } else { glam::DVec2::from(velocity) };
                let world = glam::DVec2::from(start) + over_ground * t;
                let relative = world - glam::DVec2::new(ego_speed_mps * t, 0.0);
                let radial_velocity_mps = over_ground.dot(relative.normalize());
                frame.measurements.push(Measurement {
                    x_m: relative.x,
                    y_m: relative.y,
                    radial_velocity_mps,
                    rcs_dbsm: 10.0,
                    class: ObjectClass::Car,
                    sensor_id: None,
                    ground_truth_id: Some(id as u64 + 1),
                });
            }
            frame
        })
        .collect()
}

fn tracking_frame_after(frames: &[Frame]) -> (CoordinateFrame, bool) {
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    for frame in frames {
        tracker.step(frame).unwrap();
    }
    (tracker.last_step().tracking_frame, tracker.sensors().platform().stationary)
}

#[test]
fn auto_finds_a_sensor_that_stands_still_from_its_radial_velocities() {
    assert_eq!(tracking_frame_after(&scene(0.0, 1.0)), (CoordinateFrame::Vehicle, false));
    assert_eq!(tracking_frame_after(&scene(0.0, 4.0)), (CoordinateFrame::World, true));
}

#[test]
fn auto_keeps_a_driving_sensor_without_poses_in_the_vehicle_frame() {
    assert_eq!(tracking_frame_after(&scene(8.0, 4.0)), (CoordinateFrame::Vehicle, false));
}
