//! Late frames tracked in their place (`primm_core::replay`), odometry that jumps or wraps, the
//! full position–velocity state in the outputs and the prediction to a requested time.

use glam::{DMat2, DMat4, DVec2};
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::prediction::PredictError;
use primm_core::track::TrackOutput;
use primm_core::tracker::{StepError, Tracker, TrackerStats};
use primm_core::validation::FrameError;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};

fn imm_config() -> Config {
    // The scene's measurements are its objects' centres.
    Config::default().with_modes(Method::Imm.modes()).with_point_objects()
}

/// The first `count` frames of a generated four-radar sequence (one sensor per frame, every
/// 15 ms, with ego poses).
fn four_radar_frames(count: usize) -> Vec<Frame> {
    let generated = ScenarioGenerator::from_preset(Preset::Default).generate(Split::Validation, 0);
    let frames: Vec<Frame> =
        generated.sequence.frames.iter().take(count).map(|frame| frame.to_frame().unwrap()).collect();
    assert_eq!(frames.len(), count);
    assert!(frames.iter().all(|frame| frame.ego_pose.is_some()));
    frames
}

/// A small deterministic generator (SplitMix64), so that the arrival order is repeatable.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// The frame indices in an arrival order where each frame is held back by up to `max_delay`
/// frames (a bus that delivers the four radars' scans out of order).
fn arrival_order(count: usize, max_delay: u64, seed: u64) -> Vec<usize> {
    let mut random = Random(seed);
    let mut keyed: Vec<(u64, usize)> =
        (0..count).map(|index| (index as u64 + random.next() % (max_delay + 1), index)).collect();
    keyed.sort();
    keyed.into_iter().map(|(_, index)| index).collect()
}

/// The counters that describe the tracking itself (not the late-frame bookkeeping).
fn tracked_counts(stats: &TrackerStats) -> TrackerStats {
    TrackerStats { late_frames_tracked: 0, frames_replayed: 0, ..*stats }
}

#[test]
fn a_four_radar_sequence_delivered_out_of_order_within_the_window_gives_the_same_tracks_as_in_order() {
    let frames = four_radar_frames(360);
    // In order: the outputs after every frame.
    let mut sorted = Tracker::new(imm_config()).unwrap();
    let in_order: Vec<Vec<TrackOutput>> =
        frames.iter().map(|frame| sorted.step(frame).unwrap().to_vec()).collect();

    // Held back by up to 6 frames (90 ms at 15 ms a frame, inside the 150 ms window).
    let order = arrival_order(frames.len(), 6, 7);
    assert!(order.windows(2).any(|pair| pair[1] < pair[0]), "the arrival order must shuffle");
    let mut shuffled = Tracker::new(imm_config()).unwrap();
    let (mut arrived, mut newest, mut prefix_checks, mut late_checks) = (0usize, 0usize, 0, 0);
    let mut has_arrived = vec![false; frames.len()];
    for &index in &order {
        shuffled.step(&frames[index]).unwrap_or_else(|error| panic!("frame {index}: {error}"));
        has_arrived[index] = true;
        let late = shuffled.last_step().late();
        let outputs = shuffled.last_outputs();
        assert_eq!(late, index < newest, "frame {index} after {newest}");
        assert_eq!(late, !shuffled.late_frame_outputs().is_empty(), "frame {index}");
        // A late frame's own outputs, once every older frame is in: those of in-order arrival
        // after that frame.
        if late && has_arrived[..index].iter().all(|&arrived| arrived) {
            assert_eq!(shuffled.late_frame_outputs(), &in_order[index][..], "late frame {index}");
            late_checks += 1;
        }
        newest = newest.max(index);
        arrived += 1;
        // Whenever the frames that arrived are exactly the first ones, the tracks are those of
        // in-order arrival after the newest of them.
        if arrived == newest + 1 {
            assert_eq!(outputs, &in_order[newest][..], "after frame {newest}");
            prefix_checks += 1;
        }
    }
    assert!(prefix_checks > 20, "{prefix_checks}");
    assert!(late_checks > 20, "{late_checks}");
    assert_eq!(shuffled.newest_timestamp_s(), Some(frames.last().unwrap().timestamp_s));
    let stats = shuffled.stats();
    assert!(stats.late_frames_tracked > 50, "{stats:?}");
    assert!(stats.frames_replayed >= stats.late_frames_tracked);
    assert_eq!(stats.frames_rejected_too_late, 0);
    assert_eq!(stats.frames_rejected_timestamp_not_increasing, 0);
    assert_eq!(tracked_counts(stats), tracked_counts(sorted.stats()));
    assert_eq!(stats.frames_tracked, frames.len() as u64);
}

/// Frames every 50 ms from 0 to 1 s of two cars, tracked.
fn tracked_scene(config: Config) -> (Tracker, Vec<Frame>) {
    let frames: Vec<Frame> = (0..=20).map(|k| two_cars(k as f64 * 0.05)).collect();
    let mut tracker = Tracker::new(config).unwrap();
    for frame in &frames {
        tracker.step(frame).unwrap();
    }
    (tracker, frames)
}

/// Two cars driving along x, seen from sensor 1 in the vehicle frame, at `t`.
fn two_cars(t: f64) -> Frame {
    let mut frame = Frame::new(t);
    for (index, (x0, y, vx)) in [(10.0, 3.0, 5.0), (30.0, -4.0, -3.0)].into_iter().enumerate() {
        let position = DVec2::new(x0 + vx * t, y);
        frame.measurements.push(Measurement {
            x_m: position.x,
            y_m: position.y,
            radial_velocity_mps: DVec2::new(vx, 0.0).dot(position.normalize()),
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: Some(index as u64),
        });
    }
    frame
}

#[test]
fn a_frame_just_beyond_the_window_is_rejected_counted_and_changes_nothing() {
    let (mut tracker, _) = tracked_scene(imm_config());
    let (mut control, _) = tracked_scene(imm_config());
    let window_s = tracker.config().tracker.max_frame_delay_s;
    let newest = tracker.newest_timestamp_s().unwrap();
    let beyond = two_cars(newest - window_s - 0.001);
    assert!(matches!(tracker.step(&beyond), Err(StepError::InvalidFrame(FrameError::TooLate { .. }))));
    assert_eq!(tracker.stats().frames_rejected_too_late, 1);
    assert_eq!(tracker.stats().frames_tracked, control.stats().frames_tracked);
    // Nothing changed: the next frame gives exactly what it gives without the rejected one.
    let next = two_cars(newest + 0.05);
    assert_eq!(tracker.step(&next).unwrap(), control.step(&next).unwrap());
}

#[test]
fn a_frame_just_inside_the_window_is_tracked_in_its_place() {
    let (mut tracker, frames) = tracked_scene(imm_config());
    let newest = tracker.newest_timestamp_s().unwrap();
    let late = two_cars(newest - 0.14);
    tracker.step(&late).unwrap();
    let step = *tracker.last_step();
    assert!(step.late());
    // It went between the frames at 0.85 and 0.9 s: the three newer ones were tracked again.
    assert_eq!(step.counts.frames_replayed, 3);
    assert_eq!(tracker.stats().late_frames_tracked, 1);
    // The same as tracking it in order.
    let mut in_order = Tracker::new(imm_config()).unwrap();
    let mut all: Vec<&Frame> = frames.iter().collect();
    all.push(&late);
    all.sort_by(|a, b| a.timestamp_s.total_cmp(&b.timestamp_s));
    let mut expected = Vec::new();
    for frame in all {
        expected = in_order.step(frame).unwrap().to_vec();
    }
    let next = two_cars(newest + 0.05);
    assert_eq!(tracker.step(&next).unwrap(), in_order.step(&next).unwrap());
    assert!(!expected.is_empty());
}

#[test]
fn with_late_frames_off_an_older_frame_is_rejected_as_not_advancing() {
    let mut config = imm_config();
    config.tracker.replay_frames = 0;
    let (mut tracker, _) = tracked_scene(config);
    let newest = tracker.newest_timestamp_s().unwrap();
    assert!(matches!(
        tracker.step(&two_cars(newest - 0.01)),
        Err(StepError::InvalidFrame(FrameError::TimestampNotIncreasing { .. }))
    ));
    assert_eq!(tracker.stats().frames_rejected_timestamp_not_increasing, 1);
    assert_eq!(tracker.stats().late_frames_tracked, 0);
}

#[test]
fn a_frame_repeating_a_tracked_timestamp_is_rejected_as_not_advancing() {
    let (mut tracker, frames) = tracked_scene(imm_config());
    for repeated in [&frames[20], &frames[18]] {
        assert!(matches!(
            tracker.step(repeated),
            Err(StepError::InvalidFrame(FrameError::TimestampNotIncreasing { .. }))
        ));
    }
    assert_eq!(tracker.stats().frames_rejected_timestamp_not_increasing, 2);
}

#[test]
fn a_rejected_late_frame_leaves_the_tracks_alone() {
    let (mut tracker, _) = tracked_scene(imm_config());
    let (mut control, _) = tracked_scene(imm_config());
    let newest = tracker.newest_timestamp_s().unwrap();
    let mut late = two_cars(newest - 0.05 - 0.01);
    late.ego_pose = Some(EgoPose { x_m: f64::NAN, y_m: 0.0, yaw_rad: 0.0 });
    assert!(matches!(tracker.step(&late), Err(StepError::InvalidFrame(FrameError::InvalidEgoPose { .. }))));
    let next = two_cars(newest + 0.05);
    assert_eq!(tracker.step(&next).unwrap(), control.step(&next).unwrap());
}

/// The ego pose at `t`: 8 m/s, turning left at 0.4 rad/s, heading `yaw0` at 0.
fn ego_pose(t: f64, yaw0: f64) -> EgoPose {
    let (speed, yaw_rate) = (8.0, 0.4);
    let yaw = yaw0 + yaw_rate * t;
    let radius = speed / yaw_rate;
    EgoPose {
        x_m: 50.0 + radius * (yaw.sin() - yaw0.sin()),
        y_m: 20.0 - radius * (yaw.cos() - yaw0.cos()),
        yaw_rad: yaw,
    }
}

/// A parked car and a crossing car (world points) measured from the vehicle at `pose`.
fn seen_from(t: f64, pose: EgoPose, world_offset: DVec2) -> Frame {
    let objects = [
        (DVec2::new(70.0, 30.0), DVec2::ZERO),
        (DVec2::new(60.0, 10.0) + DVec2::new(1.0, 4.0) * t, DVec2::new(1.0, 4.0)),
    ];
    let mut frame = Frame::new(t);
    frame.ego_pose = Some(EgoPose { x_m: pose.x_m + world_offset.x, y_m: pose.y_m + world_offset.y, ..pose });
    for (index, (position, velocity)) in objects.into_iter().enumerate() {
        let vehicle = pose.world_to_car(position);
        frame.measurements.push(Measurement {
            x_m: vehicle.x,
            y_m: vehicle.y,
            radial_velocity_mps: velocity.dot((position - pose.position()).normalize()),
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: Some(index as u64),
        });
    }
    frame
}

#[test]
fn an_odometry_reset_keeps_the_tracks_in_place_around_the_vehicle() {
    let mut tracker = Tracker::new(imm_config()).unwrap();
    let mut ids_before = Vec::new();
    for k in 0..60 {
        let t = k as f64 * 0.05;
        // At 1.5 s the odometry restarts 800 m away (the world frame moves, the scene does not).
        let offset = if k >= 30 { DVec2::new(-800.0, 350.0) } else { DVec2::ZERO };
        let outputs = tracker.step(&seen_from(t, ego_pose(t, 0.3), offset)).unwrap().to_vec();
        if k == 29 {
            ids_before = outputs.iter().map(|o| o.id).collect();
        }
        if k > 30 {
            for output in &outputs {
                let truth = seen_from(t, ego_pose(t, 0.3), DVec2::ZERO).measurements
                    [output.ground_truth_id.map_or(0, |id| id as usize)]
                .position();
                if output.ground_truth_id.is_some() {
                    assert!((output.position_m - truth).length() < 1.0, "frame {k}: {output:?}");
                }
            }
        }
    }
    let stats = tracker.stats();
    assert_eq!(stats.odometry_resets, 1, "{stats:?}");
    let ids_after: Vec<u64> = tracker.tracks().iter().map(|track| track.id).collect();
    assert_eq!(ids_after, ids_before, "the same tracks go on across the reset");
    assert_eq!(stats.tracks_initiated, 2);
}

#[test]
fn a_heading_that_wraps_at_plus_minus_pi_is_no_jump() {
    // Turning through yaw = pi: once with the yaw wrapped into (-pi, pi], once unwrapped.
    let run = |wrap: bool| {
        let mut tracker = Tracker::new(imm_config()).unwrap();
        let mut outputs = Vec::new();
        for k in 0..60 {
            let t = k as f64 * 0.05;
            let pose = ego_pose(t, 2.5);
            let mut frame = seen_from(t, pose, DVec2::ZERO);
            if wrap {
                let yaw = pose.yaw_rad;
                frame.ego_pose = Some(EgoPose { yaw_rad: yaw.sin().atan2(yaw.cos()), ..pose });
            }
            outputs = tracker.step(&frame).unwrap().to_vec();
        }
        (outputs, tracker.stats().odometry_resets)
    };
    let (wrapped, wrapped_resets) = run(true);
    let (unwrapped, unwrapped_resets) = run(false);
    assert_eq!((wrapped_resets, unwrapped_resets), (0, 0));
    assert_eq!(wrapped.len(), unwrapped.len());
    for (a, b) in wrapped.iter().zip(&unwrapped) {
        assert_eq!(a.id, b.id);
        assert!((a.position_m - b.position_m).length() < 1e-6, "{a:?} vs {b:?}");
        assert!((a.velocity_mps - b.velocity_mps).length() < 1e-6);
    }
}

/// Whether `matrix` is symmetric and positive semi-definite (Cholesky with a tolerance).
fn is_covariance(matrix: &DMat4) -> bool {
    let a = matrix.to_cols_array_2d();
    let mut l = [[0.0f64; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            if (a[i][j] - a[j][i]).abs() > 1e-9 * (1.0 + a[i][j].abs()) {
                return false;
            }
        }
    }
    for j in 0..4 {
        let diagonal = a[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if diagonal < -1e-9 {
            return false;
        }
        l[j][j] = diagonal.max(0.0).sqrt();
        for i in j + 1..4 {
            let value = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = if l[j][j] > 1e-12 { value / l[j][j] } else { 0.0 };
        }
    }
    true
}

fn upper_left(matrix: &DMat4) -> DMat2 {
    DMat2::from_cols(matrix.x_axis.truncate().truncate(), matrix.y_axis.truncate().truncate())
}

#[test]
fn every_output_carries_a_position_velocity_covariance_its_age_and_the_world_frame_alike() {
    let mut tracker = Tracker::new(imm_config()).unwrap();
    let mut outputs = Vec::new();
    for k in 0..40 {
        let t = k as f64 * 0.05;
        let pose = ego_pose(t, 0.3);
        outputs = tracker.step(&seen_from(t, pose, DVec2::ZERO)).unwrap().to_vec();
    }
    let pose = ego_pose(39.0 * 0.05, 0.3);
    assert_eq!(outputs.len(), 2);
    for output in &outputs {
        assert!(is_covariance(&output.state_covariance), "{:?}", output.state_covariance);
        let block = upper_left(&output.state_covariance);
        assert!(
            (block - output.position_covariance_m2).abs_diff_eq(DMat2::ZERO, 1e-9),
            "{block} vs {}",
            output.position_covariance_m2
        );
        // The velocity block is non-zero: the velocity is uncertain.
        assert!(output.state_covariance.z_axis.z > 0.0 && output.state_covariance.w_axis.w > 0.0);
        let world = output.world_state_covariance.expect("tracked in the world frame");
        assert!(is_covariance(&world));
        // The same uncertainty, rotated by the heading.
        let to_vehicle = pose.world_to_vehicle();
        let rotated = to_vehicle.apply_state_covariance(world);
        assert!(rotated.abs_diff_eq(output.state_covariance, 1e-9));
        // Both started with the first frame.
        assert!((output.age_s - 39.0 * 0.05).abs() < 1e-9, "{}", output.age_s);
        assert_eq!(output.age_frames, 39);
    }
}

#[test]
fn predicting_to_a_time_changes_no_state() {
    let (mut tracker, _) = tracked_scene(imm_config());
    let (mut control, _) = tracked_scene(imm_config());
    let newest = tracker.newest_timestamp_s().unwrap();
    let mut out = vec![TrackOutput::default(); 8];
    assert_eq!(tracker.predict_to(newest + 0.2, &mut out).unwrap(), 2);
    let next = two_cars(newest + 0.05);
    assert_eq!(tracker.step(&next).unwrap(), control.step(&next).unwrap());
}

#[test]
fn a_prediction_moves_each_track_along_its_velocity_and_grows_its_uncertainty() {
    let (tracker, _) = tracked_scene(Config::default().with_modes(Method::ConstantVelocity.modes()));
    let newest = tracker.newest_timestamp_s().unwrap();
    let mut now = vec![TrackOutput::default(); 2];
    let mut later = vec![TrackOutput::default(); 2];
    assert_eq!(tracker.predict_to(newest, &mut now).unwrap(), 2);
    assert_eq!(tracker.predict_to(newest + 0.3, &mut later).unwrap(), 2);
    for ((a, b), track) in now.iter().zip(&later).zip(tracker.tracks()) {
        assert_eq!((a.id, b.id), (track.id, track.id));
        let expected = a.position_m + 0.3 * a.velocity_mps;
        assert!((b.position_m - expected).length() < 1e-9, "{b:?}");
        assert!(b.position_covariance_m2.determinant() > a.position_covariance_m2.determinant());
        assert!(b.existence_probability < a.existence_probability);
        assert!((b.age_s - a.age_s - 0.3).abs() < 1e-12);
        assert_eq!(b.measurement_index, None);
    }
}

#[test]
fn a_prediction_to_the_newest_frame_keeps_the_fused_position_and_its_covariance() {
    let mut tracker = Tracker::new(imm_config()).unwrap();
    let mut outputs = Vec::new();
    for k in 0..=20 {
        outputs = tracker.step(&two_cars(k as f64 * 0.05)).unwrap().to_vec();
    }
    let newest = tracker.newest_timestamp_s().unwrap();
    let mut predicted = vec![TrackOutput::default(); 4];
    let count = tracker.predict_to(newest, &mut predicted).unwrap();
    assert_eq!(count, 2);
    // Mixing over no time leaves the fused position and its covariance where the update put
    // them (the modes mix in the position space; each keeps its own velocity, so the fused
    // velocity moves with the mode probabilities, a little).
    for (a, b) in predicted[..count].iter().zip(&outputs) {
        assert_eq!(a.id, b.id);
        assert!((a.position_m - b.position_m).length() < 1e-9, "{a:?} vs {b:?}");
        assert!((a.position_covariance_m2 - b.position_covariance_m2).abs_diff_eq(DMat2::ZERO, 1e-9));
        assert!((a.velocity_mps - b.velocity_mps).length() < 0.5, "{a:?} vs {b:?}");
    }
}

#[test]
fn a_prediction_to_a_time_out_of_range_is_refused() {
    let (tracker, _) = tracked_scene(imm_config());
    let newest = tracker.newest_timestamp_s().unwrap();
    let mut out = vec![TrackOutput::default(); 4];
    assert!(matches!(tracker.predict_to(f64::NAN, &mut out), Err(PredictError::NonFiniteTime { .. })));
    assert!(matches!(
        tracker.predict_to(newest - 0.01, &mut out),
        Err(PredictError::BeforeNewestFrame { .. })
    ));
    let too_far = newest + tracker.config().tracker.max_frame_interval_s + 0.01;
    assert!(matches!(tracker.predict_to(too_far, &mut out), Err(PredictError::TooFarAhead { .. })));
    // A buffer shorter than the tracks gets as many as fit.
    assert_eq!(tracker.predict_to(newest + 0.1, &mut out[..1]).unwrap(), 1);
    // No frame yet: nothing to predict.
    let empty = Tracker::new(imm_config()).unwrap();
    assert_eq!(empty.predict_to(1.0, &mut out).unwrap(), 0);
}
