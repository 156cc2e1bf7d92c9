//! Tracking in the world frame with the frames' ego poses: a scene seen from a moving, turning
//! ego vehicle, poses that come and go, bad poses, sensor mounts.

use glam::DVec2;
use primm_core::config::{Config, CoordinateFrame};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::track::TrackOutput;
use primm_core::tracker::{StepError, Tracker};
use primm_core::validation::FrameError;

const DT_S: f64 = 0.05;

fn config(tracking_frame: CoordinateFrame) -> Config {
    // The scene measures its objects' centres: point objects.
    let mut config = Config::default().with_modes(Method::Imm.modes()).with_point_objects();
    config.frame.tracking_frame = tracking_frame;
    config
}

/// The ego pose at time `t`: driving at 8 m/s while turning left at 0.4 rad/s.
fn ego_pose(t: f64) -> EgoPose {
    let (speed, yaw_rate) = (8.0, 0.4);
    let yaw = 0.3 + yaw_rate * t;
    let radius = speed / yaw_rate;
    EgoPose {
        x_m: 100.0 + radius * (yaw.sin() - 0.3f64.sin()),
        y_m: -50.0 - radius * (yaw.cos() - 0.3f64.cos()),
        yaw_rad: yaw,
    }
}

/// A frame at `t` measuring, from sensor 3, the objects at the world points `objects` (with
/// their world velocities), noise-free, with the pose attached when `with_pose`.
fn frame(t: f64, objects: &[(DVec2, DVec2)], with_pose: bool) -> Frame {
    let pose = ego_pose(t);
    let mut frame = Frame::new(t);
    frame.ego_pose = with_pose.then_some(pose);
    let sensor_world = pose.point_to_world(DVec2::new(3.86, 0.70));
    for (index, &(position, velocity)) in objects.iter().enumerate() {
        let vehicle = pose.world_to_car(position);
        let line_of_sight = (position - sensor_world).normalize();
        frame.measurements.push(Measurement {
            x_m: vehicle.x,
            y_m: vehicle.y,
            radial_velocity_mps: velocity.dot(line_of_sight),
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: Some(3),
            ground_truth_id: Some(index as u64),
        });
    }
    frame
}

/// A parked car and a car crossing, in world coordinates at time `t`.
fn objects(t: f64) -> [(DVec2, DVec2); 2] {
    let parked = (DVec2::new(125.0, -35.0), DVec2::ZERO);
    let crossing_velocity = DVec2::new(-2.0, 6.0);
    let crossing = (DVec2::new(140.0, -60.0) + crossing_velocity * t, crossing_velocity);
    [parked, crossing]
}

fn run(tracker: &mut Tracker, frames: impl Iterator<Item = Frame>) -> Vec<TrackOutput> {
    let mut last = Vec::new();
    for frame in frames {
        last = tracker.step(&frame).unwrap().to_vec();
    }
    last
}

#[test]
fn a_parked_car_seen_from_a_turning_ego_stands_still_in_the_world_frame() {
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let outputs = run(&mut tracker, (0..60).map(|k| frame(k as f64 * DT_S, &objects(k as f64 * DT_S), true)));
    assert_eq!(outputs.len(), 2, "{outputs:?}");
    let t = 59.0 * DT_S;
    let pose = ego_pose(t);
    for output in &outputs {
        let truth = objects(t)[output.ground_truth_id.unwrap() as usize];
        let world = output.world_position_m.expect("tracked in the world frame");
        let velocity = output.world_velocity_mps.expect("tracked in the world frame");
        assert!((world - truth.0).length() < 0.1, "world position {world} vs {}", truth.0);
        assert!((velocity - truth.1).length() < 0.2, "world velocity {velocity} vs {}", truth.1);
        // The reported position is the same point in the vehicle frame of the frame.
        assert!((output.position_m - pose.world_to_car(world)).length() < 1e-9);
        assert!((output.velocity_mps - pose.rotate_to_car(velocity)).length() < 1e-9);
    }
    let stats = tracker.stats();
    assert_eq!(stats.frames_in_world_frame, 60);
    assert_eq!(stats.frames_without_ego_pose, 0);
    assert_eq!(stats.initiations_from_unknown_sensor, 0);
}

#[test]
fn the_world_frame_follows_a_turning_scene_better_than_the_vehicle_frame() {
    // Mean error of the fused prior against the true position over the last 40 frames.
    let prior_error = |tracking_frame| {
        let mut tracker = Tracker::new(config(tracking_frame)).unwrap();
        let (mut total, mut count) = (0.0, 0);
        for k in 0..60 {
            let t = k as f64 * DT_S;
            let outputs = tracker.step(&frame(t, &objects(t), true)).unwrap();
            for output in outputs.iter().filter(|_| k >= 20) {
                let truth = ego_pose(t).world_to_car(objects(t)[output.ground_truth_id.unwrap() as usize].0);
                if let Some(prior) = output.prior_position_m {
                    total += (prior - truth).length();
                    count += 1;
                }
            }
        }
        total / count as f64
    };
    let world = prior_error(CoordinateFrame::World);
    let vehicle = prior_error(CoordinateFrame::Vehicle);
    assert!(world < 0.5 * vehicle, "prior error world {world} m vs vehicle {vehicle} m");
}

#[test]
fn without_poses_the_world_setting_tracks_exactly_as_the_vehicle_frame() {
    let frames: Vec<Frame> =
        (0..40).map(|k| frame(k as f64 * DT_S, &objects(k as f64 * DT_S), false)).collect();
    let mut world = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let mut vehicle = Tracker::new(config(CoordinateFrame::Vehicle)).unwrap();
    for frame in &frames {
        assert_eq!(world.step(frame).unwrap(), vehicle.step(frame).unwrap());
    }
    assert_eq!(world.stats().frames_without_ego_pose, 40);
    assert_eq!(world.stats().frames_in_world_frame, 0);
}

#[test]
fn tracks_survive_a_stream_that_stops_and_resumes_sending_poses() {
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let with_pose = |k: usize| !(30..45).contains(&k);
    let mut ids = Vec::new();
    let mut errors = [0.0f64; 70];
    for k in 0..70 {
        let t = k as f64 * DT_S;
        let outputs = tracker.step(&frame(t, &objects(t), with_pose(k))).unwrap();
        ids.push(outputs.iter().map(|o| o.id).collect::<Vec<_>>());
        assert_eq!(outputs.iter().all(|o| o.world_position_m.is_some()), with_pose(k), "frame {k}");
        // In the vehicle frame the filters must first learn the apparent motion of the scene
        // (about 8 m/s here), so errors grow while the poses are missing; with the poses back
        // they settle again.
        let pose = ego_pose(t);
        for output in outputs {
            let truth = pose.world_to_car(objects(t)[output.ground_truth_id.unwrap() as usize].0);
            let error = (output.position_m - truth).length();
            assert!(error < 3.0, "frame {k}: {} vs {truth}", output.position_m);
            if k >= 2 {
                errors[k] = errors[k].max(error);
            }
        }
    }
    let worst_without_poses = errors[30..45].iter().fold(0.0f64, |m, e| m.max(*e));
    assert!(errors[69] < 0.5 && errors[69] < 0.5 * worst_without_poses, "{errors:?}");
    // The same two tracks from the third frame to the end: none lost at either switch.
    assert!(ids[2..].iter().all(|frame_ids| *frame_ids == ids[2]), "{ids:?}");
    assert_eq!(tracker.stats().tracking_frame_changes, 2);
    assert_eq!(tracker.stats().frames_without_ego_pose, 15);
}

#[test]
fn a_frame_with_a_broken_pose_is_rejected_and_changes_no_track() {
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    run(&mut tracker, (0..10).map(|k| frame(k as f64 * DT_S, &objects(k as f64 * DT_S), true)));
    let before = tracker.tracks().to_vec();
    for broken in [
        EgoPose { x_m: f64::NAN, ..ego_pose(0.5) },
        EgoPose { yaw_rad: f64::INFINITY, ..ego_pose(0.5) },
        EgoPose { y_m: 1e300, ..ego_pose(0.5) },
    ] {
        let mut bad = frame(0.5, &objects(0.5), true);
        bad.ego_pose = Some(broken);
        assert!(matches!(
            tracker.step(&bad),
            Err(StepError::InvalidFrame(FrameError::InvalidEgoPose { .. }))
        ));
        assert_eq!(tracker.tracks().len(), before.len());
        assert!(tracker.tracks().iter().zip(&before).all(|(a, b)| a.estimate == b.estimate));
    }
    assert_eq!(tracker.stats().frames_rejected_invalid_ego_pose, 3);
    // The next good frame is tracked.
    assert!(tracker.step(&frame(0.5, &objects(0.5), true)).is_ok());
}

#[test]
fn a_sensor_without_a_mount_is_seen_from_the_reference_point_and_counted() {
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let mut first = frame(0.0, &objects(0.0), true);
    first.measurements[0].sensor_id = Some(99);
    first.measurements[1].sensor_id = None;
    tracker.step(&first).unwrap();
    assert_eq!(tracker.stats().initiations_from_unknown_sensor, 2);
    // With the mount, the initial velocity lies along the line of sight from the sensor.
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let outputs = tracker.step(&frame(0.0, &objects(0.0), true)).unwrap();
    let crossing = outputs.iter().find(|o| o.ground_truth_id == Some(1)).unwrap();
    let pose = ego_pose(0.0);
    let sensor = pose.point_to_world(DVec2::new(3.86, 0.70));
    let line_of_sight = (objects(0.0)[1].0 - sensor).normalize();
    let velocity = crossing.world_velocity_mps.unwrap();
    assert!(velocity.perp_dot(line_of_sight).abs() < 1e-6, "{velocity} not along {line_of_sight}");
    assert!((velocity.dot(line_of_sight) - objects(0.0)[1].1.dot(line_of_sight)).abs() < 1e-9);
}

#[test]
fn velocities_change_reference_with_the_frame_when_poses_stop_and_resume() {
    // Poses for 1 s, none for 0.5 s, then poses again. Without poses the tracks learn the
    // velocity relative to the ego (about 8 m/s here); in the frame where the poses return, the
    // ego's velocity over the gap is added back, so the world velocities are about right at
    // once instead of off by the ego's speed.
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    let with_pose = |k: usize| !(20..30).contains(&k);
    let mut worst_after_return = 0.0f64;
    for k in 0..31 {
        let t = k as f64 * DT_S;
        let outputs = tracker.step(&frame(t, &objects(t), with_pose(k))).unwrap().to_vec();
        if k == 20 {
            // Leaving the world frame: the parked car now moves against the moving, turning ego:
            // −(v_ego + ω × (p − p_ego)) in the vehicle's axes.
            let parked = outputs.iter().find(|o| o.ground_truth_id == Some(0)).unwrap();
            let pose = ego_pose(t);
            let offset = objects(t)[0].0 - pose.position();
            let apparent = -(ego_velocity(t) + 0.4 * offset.perp());
            let relative = pose.world_to_vehicle().apply_vector(apparent);
            assert!((parked.velocity_mps - relative).length() < 1.5, "{} vs {relative}", parked.velocity_mps);
        }
        if k == 30 {
            for output in &outputs {
                let truth = objects(t)[output.ground_truth_id.unwrap() as usize].1;
                let velocity = output.world_velocity_mps.expect("back in the world frame");
                worst_after_return = worst_after_return.max((velocity - truth).length());
            }
        }
    }
    assert!(worst_after_return < 2.5, "world velocity error {worst_after_return} m/s where the poses return");
}

/// The ego's velocity over ground at `t`, m/s.
fn ego_velocity(t: f64) -> DVec2 {
    let step = 1e-3;
    (ego_pose(t + step).position() - ego_pose(t - step).position()) / (2.0 * step)
}

#[test]
fn a_pose_that_returns_beyond_the_egos_limits_adds_no_velocity() {
    // After a gap the pose comes back 10 km away: no ego could have driven there, so its
    // "velocity" over the gap is unknown and nothing is added to the tracks.
    let mut tracker = Tracker::new(config(CoordinateFrame::World)).unwrap();
    for k in 0..25 {
        let t = k as f64 * DT_S;
        tracker.step(&frame(t, &objects(t), k < 20)).unwrap();
    }
    let before: Vec<DVec2> = tracker.last_outputs().iter().map(|o| o.velocity_mps).collect();
    let t = 25.0 * DT_S;
    let mut far = frame(t, &objects(t), true);
    far.ego_pose = far.ego_pose.map(|pose| EgoPose { x_m: pose.x_m + 10_000.0, ..pose });
    let outputs = tracker.step(&far).unwrap();
    assert_eq!(outputs.len(), before.len());
    for (output, before) in outputs.iter().zip(&before) {
        let velocity = output.world_velocity_mps.expect("in the world frame again");
        assert!(
            velocity.is_finite() && (velocity.length() - before.length()).abs() < 5.0,
            "{velocity} after {before}"
        );
    }
}

#[test]
fn an_ego_motion_that_would_make_a_track_implausibly_fast_leaves_it_as_it_was() {
    // Far from an ego turning fast, the rotation term alone is 600 m/s: beyond any object.
    let config = Config::default();
    let imm = primm_core::imm::Imm::new(&config.imm_for(ObjectClass::Car));
    let models = primm_core::motion::ModeModels::from_config(config.classes.get(ObjectClass::Car));
    let track_at = |x_m: f64| {
        let first = Measurement {
            x_m,
            y_m: 0.0,
            radial_velocity_mps: 0.0,
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: None,
        };
        let state = imm.initiate(&models, &first);
        primm_core::track::Track::new(1, &first, DVec2::ZERO, 0.0, state, 0.5)
    };
    let turning = primm_core::pose::RigidVelocity {
        velocity_mps: DVec2::ZERO,
        yaw_rate_radps: 3.0,
        centre_m: DVec2::ZERO,
    };
    let max_speed_mps = config.predictor.max_displacement_speed_mps;
    let mut far = track_at(200.0);
    let before = far.estimate;
    assert!(!far.add_velocity_field(&turning, 1.0, max_speed_mps));
    assert_eq!(far.estimate, before);
    let mut near = track_at(5.0);
    assert!(near.add_velocity_field(&turning, 1.0, max_speed_mps));
    let velocity =
        DVec2::new(near.estimate.constant_velocity.mean[2], near.estimate.constant_velocity.mean[3]);
    assert!((velocity - DVec2::new(0.0, 15.0)).length() < 1e-9, "{velocity}");
}
