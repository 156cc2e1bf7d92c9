//! The tracker entry points, called as C would call them.

use super::*;
use crate::helpers::primm_last_error_message;
use crate::types::{
    PRIMM_METHOD_IMM, PRIMM_METHOD_PR_IMM, PRIMM_NO_GROUND_TRUTH_ID, PRIMM_NO_MEASUREMENT_INDEX,
    PRIMM_NO_SENSOR_ID, PRIMM_OBJECT_CLASS_CAR, PRIMM_OBJECT_CLASS_PEDESTRIAN, PRIMM_TRACK_STATUS_CONFIRMED,
};
use core::ptr::{null, null_mut};
use primm_core::config::Config;
use primm_core::measurement::{Frame, ObjectClass};
use std::ffi::CString;

/// A tracker from `options`, or the status and message of the failure.
fn create(options: &PrimmTrackerOptions) -> Result<*mut PrimmTracker, (PrimmStatus, String)> {
    let mut tracker = null_mut();
    // SAFETY: valid options and out-pointer.
    let status = unsafe { primm_tracker_create(options, &mut tracker) };
    if status == PrimmStatus::Ok {
        assert!(!tracker.is_null());
        Ok(tracker)
    } else {
        assert!(tracker.is_null(), "a failed create leaves the handle NULL");
        Err((status, thread_message()))
    }
}

fn imm_options() -> PrimmTrackerOptions {
    PrimmTrackerOptions { method: PRIMM_METHOD_IMM, ..primm_tracker_options_default() }
}

fn thread_message() -> String {
    let mut buf = [0 as c_char; 1024];
    // SAFETY: a writable buffer of its length.
    unsafe { primm_last_error_message(buf.as_mut_ptr(), buf.len()) };
    // SAFETY: NUL-terminated by the call.
    unsafe { CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned()
}

fn tracker_message(tracker: *mut PrimmTracker) -> String {
    let mut buf = [0 as c_char; 1024];
    // SAFETY: a live tracker and a writable buffer of its length.
    unsafe { primm_tracker_last_error(tracker, buf.as_mut_ptr(), buf.len()) };
    // SAFETY: NUL-terminated by the call.
    unsafe { CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned()
}

fn measurement(class_code: u8, x_m: f64, y_m: f64, ground_truth_id: i64) -> PrimmMeasurement {
    PrimmMeasurement {
        x_m,
        y_m,
        radial_velocity_mps: 5.0,
        rcs_dbsm: 10.0,
        ground_truth_id,
        sensor_id: 2,
        class_code,
    }
}

/// Two objects moving along x: frame `k` at `0.05 k` s.
fn two_objects(k: usize) -> [PrimmMeasurement; 2] {
    let x = 0.5 * k as f64;
    [
        measurement(PRIMM_OBJECT_CLASS_CAR, 20.0 + x, 2.0, 11),
        measurement(PRIMM_OBJECT_CLASS_PEDESTRIAN, 8.0, -3.0 + 0.05 * x, 12),
    ]
}

fn step(tracker: *mut PrimmTracker, t: f64, frame: &[PrimmMeasurement]) -> (PrimmStatus, PrimmStepSummary) {
    let mut summary = PrimmStepSummary { track_count: 99, ..Default::default() };
    // SAFETY: a live tracker, `frame.len()` readable measurements, a writable summary.
    let status = unsafe { primm_tracker_step(tracker, t, frame.as_ptr(), frame.len(), &mut summary) };
    (status, summary)
}

fn tracks(tracker: *mut PrimmTracker) -> Vec<PrimmTrack> {
    let mut buffer = vec![PrimmTrack::EMPTY; PRIMM_MAX_TRACKS];
    let mut count = usize::MAX;
    // SAFETY: a live tracker, a buffer of its length, a writable count.
    let status = unsafe { primm_tracker_tracks(tracker, buffer.as_mut_ptr(), buffer.len(), &mut count) };
    assert_eq!(status, PrimmStatus::Ok);
    buffer.truncate(count);
    buffer
}

fn stats(tracker: *mut PrimmTracker) -> PrimmStats {
    let mut stats = PrimmStats::default();
    // SAFETY: a live tracker and a writable struct.
    assert_eq!(unsafe { primm_tracker_stats(tracker, &mut stats) }, PrimmStatus::Ok);
    stats
}

fn destroy(tracker: *mut PrimmTracker) {
    // SAFETY: a live tracker, not used afterwards.
    unsafe { primm_tracker_destroy(tracker) };
}

#[test]
fn a_tracker_from_the_defaults_steps_reports_its_tracks_and_is_destroyed() {
    // NULL options: the default configuration (PR-IMM) with the built-in model.
    let mut tracker = null_mut();
    // SAFETY: NULL options and a valid out-pointer.
    assert_eq!(unsafe { primm_tracker_create(null(), &mut tracker) }, PrimmStatus::Ok);
    for k in 0..10 {
        let (status, summary) = step(tracker, 0.05 * k as f64, &two_objects(k));
        assert_eq!(status, PrimmStatus::Ok);
        assert_eq!((summary.track_count, summary.updated_track_count), (2, 2), "frame {k}");
        assert_eq!(summary.measurements_accepted, 2);
        assert_eq!(summary.tracks_initiated, if k == 0 { 2 } else { 0 });
    }
    let tracks = tracks(tracker);
    assert_eq!(tracks.len(), 2);
    let car = tracks.iter().find(|t| t.class_code == PRIMM_OBJECT_CLASS_CAR).unwrap();
    assert_eq!((car.hits, car.misses, car.age_frames), (10, 0, 9));
    assert_eq!(car.status, PRIMM_TRACK_STATUS_CONFIRMED);
    assert_eq!(car.ground_truth_id, 11);
    assert!(car.has_prior_position && car.prior_x_m.is_finite());
    assert!((car.x_m - 24.5).abs() < 1.5 && (car.y_m - 2.0).abs() < 0.5, "{car:?}");
    assert!(car.velocity_x_mps > 5.0, "{car:?}");
    assert!(car.position_covariance_xx_m2 > 0.0 && car.position_covariance_yy_m2 > 0.0);
    assert!((car.mode_probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    assert!(car.mode_probabilities.iter().all(|&mu| mu > 0.0), "all four modes run: {car:?}");
    let stats = stats(tracker);
    assert_eq!((stats.frames_tracked, stats.measurements_accepted, stats.tracks_initiated), (10, 20, 2));
    assert_eq!(stats.learned_predictions_missing, 0, "the built-in model predicts");
    destroy(tracker);
    // SAFETY: NULL is ignored.
    unsafe { primm_tracker_destroy(null_mut()) };
}

#[test]
fn tracks_copied_out_are_the_core_trackers_outputs_field_for_field() {
    let tracker = create(&imm_options()).unwrap();
    let mut core = Tracker::new(Config::default().with_modes(primm_core::mode::Method::Imm.modes())).unwrap();
    for k in 0..8 {
        let mut frame_measurements = two_objects(k).to_vec();
        if k == 5 {
            frame_measurements.remove(1);
        }
        assert_eq!(step(tracker, 0.04 * k as f64, &frame_measurements).0, PrimmStatus::Ok);
        let mut frame = Frame::new(0.04 * k as f64);
        frame.measurements.extend(frame_measurements.iter().map(|m| m.to_measurement().unwrap()));
        let expected: Vec<PrimmTrack> = core.step(&frame).unwrap().iter().map(PrimmTrack::from).collect();
        let got = tracks(tracker);
        assert_eq!(got.len(), expected.len());
        for (got, expected) in got.iter().zip(&expected) {
            // NaN priors compare unequal; compare bit patterns.
            assert_eq!(format!("{got:?}"), format!("{expected:?}"));
        }
    }
    let last = tracks(tracker);
    assert!(last.iter().all(|t| t.measurement_index != PRIMM_NO_MEASUREMENT_INDEX));
    destroy(tracker);
}

#[test]
fn an_invalid_toml_value_gives_invalid_config_with_a_message_naming_the_key() {
    let text = primm_config::DEFAULT_CONFIG_TOML.replace("paper_gate_m = 8.4", "paper_gate_m = -1.0");
    let text = CString::new(text).unwrap();
    let options = PrimmTrackerOptions { config_toml: text.as_ptr(), ..imm_options() };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::InvalidConfig);
    assert!(message.contains("classes.car.paper_gate_m"), "{message}");

    let text = CString::new("[tracker]\nconfirmation_hitz = 3\n").unwrap();
    let options = PrimmTrackerOptions { config_toml: text.as_ptr(), ..imm_options() };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::InvalidConfig);
    assert!(message.contains("confirmation_hitz"), "{message}");

    let bytes = b"[tracker]\n\xff = 1\n\0";
    let options = PrimmTrackerOptions { config_toml: bytes.as_ptr().cast(), ..imm_options() };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::InvalidConfig);
    assert!(message.contains("not UTF-8"), "{message}");
}

#[test]
fn a_valid_toml_configuration_is_used() {
    let text =
        primm_config::DEFAULT_CONFIG_TOML.replace(r#"modes = ["pr", "cv", "ca", "ct"]"#, r#"modes = ["cv"]"#);
    assert_ne!(text, primm_config::DEFAULT_CONFIG_TOML);
    let text = CString::new(text).unwrap();
    let options = PrimmTrackerOptions {
        config_toml: text.as_ptr(),
        method: PRIMM_METHOD_CONFIG,
        use_builtin_model: false,
        ..primm_tracker_options_default()
    };
    let tracker = create(&options).unwrap();
    assert_eq!(step(tracker, 0.0, &two_objects(0)).0, PrimmStatus::Ok);
    assert_eq!(tracks(tracker)[0].mode_probabilities, [0.0, 1.0, 0.0, 0.0]);
    destroy(tracker);
}

#[test]
fn an_unknown_method_code_is_an_invalid_argument() {
    let options = PrimmTrackerOptions { method: 7, ..primm_tracker_options_default() };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::InvalidArgument);
    assert!(message.contains("unknown method code 7"), "{message}");
}

#[test]
fn bad_model_bytes_give_invalid_model_whether_or_not_the_method_uses_pr() {
    let bytes = b"definitely not an ONNX model";
    for method in [PRIMM_METHOD_PR_IMM, PRIMM_METHOD_IMM] {
        let options = PrimmTrackerOptions {
            method,
            model_onnx: bytes.as_ptr(),
            model_onnx_len: bytes.len(),
            ..primm_tracker_options_default()
        };
        let (status, message) = create(&options).unwrap_err();
        assert_eq!(status, PrimmStatus::InvalidModel, "method {method}");
        assert!(message.contains("not a valid ONNX model"), "{message}");
        assert!(message.contains("primm_tracker_create"), "{message}");
    }
}

#[test]
fn the_pr_mode_without_model_bytes_needs_the_built_in_model() {
    let options = PrimmTrackerOptions {
        method: PRIMM_METHOD_PR_IMM,
        use_builtin_model: false,
        ..primm_tracker_options_default()
    };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::InvalidModel);
    assert!(message.contains("no model was given"), "{message}");
    let options = PrimmTrackerOptions { model_onnx_len: 10, ..imm_options() };
    let (status, message) = create(&options).unwrap_err();
    assert_eq!(status, PrimmStatus::NullArgument);
    assert!(message.contains("model_onnx"), "{message}");
}

#[test]
fn caller_model_bytes_are_loaded_and_used() {
    let options = PrimmTrackerOptions {
        method: PRIMM_METHOD_PR_IMM,
        model_onnx: primm_predictor::DEFAULT_MODEL_ONNX.as_ptr(),
        model_onnx_len: primm_predictor::DEFAULT_MODEL_ONNX.len(),
        use_builtin_model: false,
        ..primm_tracker_options_default()
    };
    let tracker = create(&options).unwrap();
    for k in 0..3 {
        assert_eq!(step(tracker, 0.05 * k as f64, &two_objects(k)).0, PrimmStatus::Ok);
    }
    assert!(tracks(tracker)[0].mode_probabilities[0] > 0.0, "PR runs");
    assert_eq!(stats(tracker).learned_predictions_missing, 0);
    destroy(tracker);
}

#[test]
fn a_null_tracker_is_rejected_with_null_argument() {
    let frame = two_objects(0);
    let mut summary = PrimmStepSummary { track_count: 5, ..Default::default() };
    let mut count = 3;
    let mut stats = PrimmStats::default();
    // SAFETY: every non-NULL pointer is valid.
    unsafe {
        let status = primm_tracker_step(null_mut(), 0.0, frame.as_ptr(), frame.len(), &mut summary);
        assert_eq!(status, PrimmStatus::NullArgument);
        assert_eq!(summary, PrimmStepSummary::default(), "the summary is zeroed on failure");
        assert!(thread_message().contains("`tracker`"), "{}", thread_message());
        let status = primm_tracker_tracks(null_mut(), null_mut(), 0, &mut count);
        assert_eq!(status, PrimmStatus::NullArgument);
        assert_eq!(primm_tracker_stats(null_mut(), &mut stats), PrimmStatus::NullArgument);
        assert_eq!(primm_tracker_reset(null_mut()), PrimmStatus::NullArgument);
        assert_eq!(primm_tracker_last_error(null(), null_mut(), 0), 0);
        assert_eq!(primm_tracker_create(null(), null_mut()), PrimmStatus::NullArgument);
        assert!(thread_message().contains("`out_tracker`"), "{}", thread_message());
    }
}

#[test]
fn null_buffers_on_a_live_tracker_are_rejected_with_null_argument() {
    let tracker = create(&imm_options()).unwrap();
    let mut count = 0;
    // SAFETY: a live tracker; every non-NULL pointer is valid.
    unsafe {
        assert_eq!(primm_tracker_step(tracker, 0.0, null(), 2, null_mut()), PrimmStatus::NullArgument);
        assert!(tracker_message(tracker).contains("`measurements`"), "{}", tracker_message(tracker));
        assert_eq!(
            primm_tracker_step(tracker, 0.0, null(), 0, null_mut()),
            PrimmStatus::Ok,
            "an empty frame"
        );
        assert_eq!(primm_tracker_tracks(tracker, null_mut(), 1, &mut count), PrimmStatus::NullArgument);
        assert_eq!(primm_tracker_tracks(tracker, null_mut(), 0, null_mut()), PrimmStatus::NullArgument);
        assert_eq!(primm_tracker_tracks(tracker, null_mut(), 0, &mut count), PrimmStatus::Ok);
        assert_eq!(count, 0);
        assert_eq!(primm_tracker_stats(tracker, null_mut()), PrimmStatus::NullArgument);
        assert!(tracker_message(tracker).contains("`out`"), "{}", tracker_message(tracker));
    }
    destroy(tracker);
}

#[test]
fn a_buffer_too_small_gives_buffer_too_small_the_count_needed_and_nothing_copied() {
    let tracker = create(&imm_options()).unwrap();
    assert_eq!(step(tracker, 0.0, &two_objects(0)).0, PrimmStatus::Ok);
    let mut buffer = [PrimmTrack::EMPTY; 1];
    let mut count = 0;
    // SAFETY: a live tracker, a buffer of one entry, a writable count.
    let status = unsafe { primm_tracker_tracks(tracker, buffer.as_mut_ptr(), 1, &mut count) };
    assert_eq!((status, count), (PrimmStatus::BufferTooSmall, 2));
    assert_eq!(format!("{:?}", buffer[0]), format!("{:?}", PrimmTrack::EMPTY), "nothing copied");
    assert!(
        tracker_message(tracker).contains("holds 1 entries, 2 are needed"),
        "{}",
        tracker_message(tracker)
    );
    // SAFETY: NULL with capacity 0 queries the count.
    let status = unsafe { primm_tracker_tracks(tracker, null_mut(), 0, &mut count) };
    assert_eq!((status, count), (PrimmStatus::BufferTooSmall, 2));
    destroy(tracker);
}

#[test]
fn a_frame_that_does_not_advance_gives_invalid_frame_and_keeps_the_tracks() {
    let tracker = create(&imm_options()).unwrap();
    for k in 0..3 {
        assert_eq!(step(tracker, 0.05 * k as f64, &two_objects(k)).0, PrimmStatus::Ok);
    }
    let before = tracks(tracker);
    let (status, summary) = step(tracker, 0.1, &two_objects(3));
    assert_eq!(status, PrimmStatus::InvalidFrame);
    assert_eq!(summary, PrimmStepSummary::default());
    let message = tracker_message(tracker);
    assert!(message.contains("does not advance past the previous frame at 0.1 s"), "{message}");
    assert_eq!(thread_message(), message);
    assert_eq!(format!("{:?}", tracks(tracker)), format!("{before:?}"), "the last output is kept");
    let stats = stats(tracker);
    assert_eq!((stats.frames_tracked, stats.frames_rejected_timestamp_not_increasing), (3, 1));
    // The tracks live on: the next frame updates them.
    let (status, summary) = step(tracker, 0.15, &two_objects(3));
    assert_eq!((status, summary.updated_track_count, summary.tracks_initiated), (PrimmStatus::Ok, 2, 0));
    assert!(tracks(tracker).iter().all(|t| t.hits == 4));
    // A NaN timestamp and an oversized frame are rejected too.
    assert_eq!(step(tracker, f64::NAN, &two_objects(4)).0, PrimmStatus::InvalidFrame);
    let oversized = vec![two_objects(4)[0]; PRIMM_MAX_MEASUREMENTS_PER_FRAME_PLUS_ONE];
    assert_eq!(step(tracker, 0.2, &oversized).0, PrimmStatus::InvalidFrame);
    let stats = self::stats(tracker);
    assert_eq!(
        (stats.frames_rejected_non_finite_timestamp, stats.frames_rejected_too_many_measurements),
        (1, 1)
    );
    destroy(tracker);
}

const PRIMM_MAX_MEASUREMENTS_PER_FRAME_PLUS_ONE: usize = crate::types::PRIMM_MAX_MEASUREMENTS_PER_FRAME + 1;

#[test]
fn a_nan_measurement_is_counted_as_rejected_and_the_rest_of_the_frame_is_tracked() {
    let tracker = create(&imm_options()).unwrap();
    let mut frame = two_objects(0).to_vec();
    frame.push(measurement(PRIMM_OBJECT_CLASS_CAR, f64::NAN, 1.0, PRIMM_NO_GROUND_TRUTH_ID));
    frame.push(measurement(9, 30.0, 1.0, PRIMM_NO_GROUND_TRUTH_ID));
    frame.push(measurement(PRIMM_OBJECT_CLASS_CAR, 1e9, 1.0, PRIMM_NO_GROUND_TRUTH_ID));
    let (status, summary) = step(tracker, 0.0, &frame);
    assert_eq!(status, PrimmStatus::Ok);
    assert_eq!((summary.measurements_accepted, summary.measurements_rejected), (2, 3));
    assert_eq!((summary.track_count, summary.tracks_initiated), (2, 2));
    let stats = stats(tracker);
    assert_eq!(stats.measurements_rejected_non_finite, 1);
    assert_eq!(stats.measurements_rejected_unknown_class, 1);
    assert_eq!(stats.measurements_rejected_out_of_range, 1);
    destroy(tracker);
}

#[test]
fn sentinels_map_to_unknown_values_and_back() {
    let mut m = measurement(PRIMM_OBJECT_CLASS_CAR, 1.0, 2.0, PRIMM_NO_GROUND_TRUTH_ID);
    m.sensor_id = PRIMM_NO_SENSOR_ID;
    let core = m.to_measurement().unwrap();
    assert_eq!((core.ground_truth_id, core.sensor_id, core.class), (None, None, ObjectClass::Car));
    m.sensor_id = 70_000;
    m.ground_truth_id = -2;
    let core = m.to_measurement().unwrap();
    assert_eq!((core.ground_truth_id, core.sensor_id), (Some(u64::MAX - 1), None));
    m.sensor_id = 65_535;
    assert_eq!(m.to_measurement().unwrap().sensor_id, Some(65_535));
}

#[test]
fn a_reset_drops_the_tracks_and_time_starts_over() {
    let tracker = create(&imm_options()).unwrap();
    assert_eq!(step(tracker, 1.0, &two_objects(0)).0, PrimmStatus::Ok);
    // SAFETY: a live tracker.
    assert_eq!(unsafe { primm_tracker_reset(tracker) }, PrimmStatus::Ok);
    assert!(tracks(tracker).is_empty());
    assert_eq!(step(tracker, 0.0, &two_objects(0)).0, PrimmStatus::Ok, "earlier time after a reset");
    assert_eq!(stats(tracker).resets, 1);
    destroy(tracker);
}

#[test]
fn a_panic_poisons_the_tracker_and_later_calls_are_refused() {
    let tracker = create(&imm_options()).unwrap();
    // SAFETY: a live tracker.
    let status = unsafe { with_tracker(tracker, |_| panic!("simulated fault")) };
    assert_eq!(status, PrimmStatus::Panic);
    assert_eq!(tracker_message(tracker), "panic inside primm: simulated fault");
    assert_eq!(step(tracker, 0.0, &two_objects(0)).0, PrimmStatus::Poisoned);
    // SAFETY: a live tracker.
    assert_eq!(unsafe { primm_tracker_reset(tracker) }, PrimmStatus::Poisoned);
    destroy(tracker);
}

#[test]
fn the_inference_thread_option_runs_the_pr_mode() {
    let options = PrimmTrackerOptions { inference_thread: true, ..primm_tracker_options_default() };
    let tracker = create(&options).unwrap();
    for k in 0..5 {
        assert_eq!(step(tracker, 0.05 * k as f64, &two_objects(k)).0, PrimmStatus::Ok);
    }
    assert_eq!(tracks(tracker).len(), 2);
    destroy(tracker);
}

/// The frames of a generated scene (`duration_s` long), with the ego poses the scene carries.
fn scenario_frames(duration_s: f64) -> Vec<Frame> {
    use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
    let mut config = Preset::Default.config();
    config.sequence.duration_s = duration_s;
    let generated = ScenarioGenerator::new(config).unwrap().generate(Split::Evaluation, 0);
    let frames = generated.sequence.to_frames().unwrap();
    assert!(frames.iter().all(|frame| frame.ego_pose.is_some()), "the generated scene carries poses");
    frames
}

/// A core measurement as C passes it.
fn to_c(measurement: &primm_core::measurement::Measurement) -> PrimmMeasurement {
    PrimmMeasurement {
        x_m: measurement.x_m,
        y_m: measurement.y_m,
        radial_velocity_mps: measurement.radial_velocity_mps,
        rcs_dbsm: measurement.rcs_dbsm,
        ground_truth_id: measurement.ground_truth_id.map_or(PRIMM_NO_GROUND_TRUTH_ID, |id| id as i64),
        sensor_id: measurement.sensor_id.map_or(PRIMM_NO_SENSOR_ID, i32::from),
        class_code: measurement.class.code(),
    }
}

/// Steps `frame` (with `pose`, NULL for none) through the C API.
fn step_frame(
    tracker: *mut PrimmTracker,
    frame: &Frame,
    pose: Option<&PrimmEgoPose>,
) -> (PrimmStatus, PrimmStepSummary) {
    let measurements: Vec<PrimmMeasurement> = frame.measurements.iter().map(to_c).collect();
    let mut summary = PrimmStepSummary { track_count: 99, ..Default::default() };
    let pose = pose.map_or(null(), |pose| pose as *const PrimmEgoPose);
    // SAFETY: a live tracker, a readable pose or NULL, `measurements.len()` readable
    // measurements, a writable summary.
    let status = unsafe {
        primm_tracker_step_with_pose(
            tracker,
            frame.timestamp_s,
            pose,
            measurements.as_ptr(),
            measurements.len(),
            &mut summary,
        )
    };
    (status, summary)
}

/// The pose of a core frame as C passes it.
fn c_pose(frame: &Frame) -> PrimmEgoPose {
    let pose = frame.ego_pose.expect("a frame with a pose");
    PrimmEgoPose { x_m: pose.x_m, y_m: pose.y_m, yaw_rad: pose.yaw_rad }
}

/// Tracks as text, field for field (NaN priors compare unequal as numbers).
fn tracks_text(tracker: *mut PrimmTracker) -> Vec<String> {
    tracks(tracker).iter().map(|track| format!("{track:?}")).collect()
}

#[test]
fn trackers_on_several_threads_step_at_once_and_keep_their_error_messages_apart() {
    const THREADS: usize = 4;
    /// The frame before which every thread sends a frame back in time.
    const FAULT_FRAME: usize = 12;
    let frames = std::sync::Arc::new(scenario_frames(2.0));
    assert!(frames.len() > FAULT_FRAME + 10);

    // The reference: one tracker on this thread, without the faulty frames.
    let reference = create(&imm_options()).unwrap();
    let expected: Vec<Vec<String>> = frames
        .iter()
        .map(|frame| {
            assert_eq!(step_frame(reference, frame, Some(&c_pose(frame))).0, PrimmStatus::Ok);
            tracks_text(reference)
        })
        .collect();
    destroy(reference);
    assert!(expected.iter().any(|tracks| tracks.len() > 3), "the scene has several tracks at once");

    let barrier = std::sync::Arc::new(std::sync::Barrier::new(THREADS));
    let workers: Vec<_> = (0..THREADS)
        .map(|thread| {
            let frames = std::sync::Arc::clone(&frames);
            let barrier = std::sync::Arc::clone(&barrier);
            std::thread::spawn(move || {
                let tracker = create(&imm_options()).unwrap();
                let mut outputs = Vec::with_capacity(frames.len());
                for (k, frame) in frames.iter().enumerate() {
                    if k == FAULT_FRAME {
                        // Every thread fails at once, each with its own timestamp in the message
                        // (seconds before the scene starts: beyond the late-frame window).
                        barrier.wait();
                        let stale = -1.0 - thread as f64;
                        let (status, _) = step(tracker, stale, &two_objects(0));
                        assert_eq!(status, PrimmStatus::InvalidFrame);
                        barrier.wait();
                        let own = format!("frame timestamp {stale} s is older than the newest frame");
                        for message in [thread_message(), tracker_message(tracker)] {
                            assert!(message.contains(&own), "thread {thread}: {message}");
                            for other in (0..THREADS).filter(|other| *other != thread) {
                                let foreign = format!("timestamp {} s", -1.0 - other as f64);
                                assert!(!message.contains(&foreign), "thread {thread}: {message}");
                            }
                        }
                    }
                    assert_eq!(step_frame(tracker, frame, Some(&c_pose(frame))).0, PrimmStatus::Ok);
                    outputs.push(tracks_text(tracker));
                }
                assert_eq!(stats(tracker).frames_rejected_too_late, 1);
                destroy(tracker);
                outputs
            })
        })
        .collect();
    for (thread, worker) in workers.into_iter().enumerate() {
        let outputs = worker.join().expect("no thread panics");
        assert_eq!(outputs.len(), expected.len());
        for (k, (got, want)) in outputs.iter().zip(&expected).enumerate() {
            assert_eq!(got, want, "thread {thread}, frame {k}: tracks differ from the single-threaded run");
        }
    }
}

#[test]
fn pr_imm_through_the_c_api_equals_the_core_tracker_with_the_built_in_model_and_with_model_bytes() {
    use primm_predictor::onnx::OnnxPredictor;
    let frames = scenario_frames(1.5);
    let config = Config::default().with_modes(primm_core::mode::Method::PrImm.modes());
    let mut predictor = OnnxPredictor::embedded().unwrap();
    predictor.set_engine(primm_config::InferenceConfig::default().engine);
    let mut core = Tracker::with_predictor(config, predictor).unwrap();

    let built_in = create(&PrimmTrackerOptions {
        method: PRIMM_METHOD_PR_IMM,
        use_builtin_model: true,
        ..primm_tracker_options_default()
    })
    .unwrap();
    let from_bytes = create(&PrimmTrackerOptions {
        method: PRIMM_METHOD_PR_IMM,
        model_onnx: primm_predictor::DEFAULT_MODEL_ONNX.as_ptr(),
        model_onnx_len: primm_predictor::DEFAULT_MODEL_ONNX.len(),
        use_builtin_model: false,
        ..primm_tracker_options_default()
    })
    .unwrap();

    let mut pr_weight_seen = false;
    for (k, frame) in frames.iter().enumerate() {
        let expected: Vec<String> = core
            .step(frame)
            .unwrap()
            .iter()
            .map(|output| format!("{:?}", PrimmTrack::from(output)))
            .collect();
        for (name, tracker) in [("built-in model", built_in), ("model bytes", from_bytes)] {
            assert_eq!(step_frame(tracker, frame, Some(&c_pose(frame))).0, PrimmStatus::Ok, "{name}");
            assert_eq!(tracks_text(tracker), expected, "{name}, frame {k}");
        }
        pr_weight_seen |= tracks(built_in).iter().any(|track| track.mode_probabilities[0] > 0.0);
    }
    assert!(pr_weight_seen, "the PR mode carries weight in some track");
    for tracker in [built_in, from_bytes] {
        let stats = stats(tracker);
        assert_eq!(stats.frames_tracked, frames.len() as u64);
        assert_eq!(stats.learned_predictions_missing, 0);
        assert_eq!(stats.frames_in_world_frame, frames.len() as u64);
        destroy(tracker);
    }
}

#[test]
fn an_invalid_pose_is_rejected_with_a_message_and_leaves_the_tracker_as_it_was() {
    let frames = scenario_frames(1.0);
    let faulty = create(&imm_options()).unwrap();
    let clean = create(&imm_options()).unwrap();
    let invalid_poses = [
        PrimmEgoPose { x_m: f64::NAN, y_m: 0.0, yaw_rad: 0.0 },
        PrimmEgoPose { x_m: 0.0, y_m: f64::INFINITY, yaw_rad: 0.0 },
        PrimmEgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: f64::NAN },
        PrimmEgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: f64::NEG_INFINITY },
        PrimmEgoPose { x_m: 1.0e12, y_m: 0.0, yaw_rad: 0.0 },
    ];
    let mut rejected = 0;
    for (k, frame) in frames.iter().enumerate() {
        if k % 4 == 3 {
            let before = tracks_text(faulty);
            let stats_before = stats(faulty);
            let pose = &invalid_poses[(k / 4) % invalid_poses.len()];
            let (status, summary) = step_frame(faulty, frame, Some(pose));
            assert_eq!(status, PrimmStatus::InvalidFrame, "frame {k}, pose {pose:?}");
            rejected += 1;
            assert_eq!(summary, PrimmStepSummary::default(), "a rejected step's summary is zeroed");
            let message = tracker_message(faulty);
            assert!(
                message.contains("ego pose") && message.contains("not finite or too far out"),
                "{message}"
            );
            assert_eq!(thread_message(), message);
            assert_eq!(tracks_text(faulty), before, "frame {k}: the rejected frame changed the tracks");
            let stats_after = stats(faulty);
            assert_eq!(stats_after.frames_tracked, stats_before.frames_tracked);
            assert_eq!(stats_after.frames_rejected_invalid_ego_pose, rejected);
        }
        for tracker in [faulty, clean] {
            assert_eq!(step_frame(tracker, frame, Some(&c_pose(frame))).0, PrimmStatus::Ok, "frame {k}");
        }
        assert_eq!(tracks_text(faulty), tracks_text(clean), "frame {k}: the rejected poses left a trace");
    }
    assert!(rejected >= 4, "{rejected} invalid poses tried");

    // A NULL pose is not an error: the frame is tracked in the vehicle frame and counted.
    let next =
        Frame { timestamp_s: frames.last().unwrap().timestamp_s + 0.05, ..frames.last().unwrap().clone() };
    let (status, summary) = step_frame(faulty, &next, None);
    assert_eq!(status, PrimmStatus::Ok);
    assert!(summary.track_count > 0);
    assert!(tracks(faulty).iter().all(|track| !track.has_world_estimate));
    assert_eq!(stats(faulty).frames_without_ego_pose, 1);
    assert_eq!(stats(faulty).frames_rejected_invalid_ego_pose, rejected);

    // A NULL tracker with a valid pose is refused before anything is read.
    let pose = c_pose(&frames[0]);
    // SAFETY: NULL tracker (refused), a readable pose, no measurements.
    let status = unsafe { primm_tracker_step_with_pose(null_mut(), 1.0, &pose, null(), 0, null_mut()) };
    assert_eq!(status, PrimmStatus::NullArgument);
    destroy(faulty);
    destroy(clean);
}

#[test]
fn a_speed_held_at_its_class_s_bound_is_counted_in_the_c_counters() {
    // A car at 20 m/s whose detections run ahead faster every frame (as in the integration test
    // of the speed bound), with an ego pose: the track is held at the car's highest speed.
    let tracker = create(&imm_options()).unwrap();
    let pose = PrimmEgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 };
    let (mut x_m, mut speed_mps) = (10.0, 20.0);
    for k in 0..70 {
        if k >= 30 {
            speed_mps += 6.0;
        }
        x_m += speed_mps * 0.05;
        let mut frame = Frame::new(k as f64 * 0.05);
        frame.measurements.push(primm_core::measurement::Measurement {
            x_m,
            y_m: -3.0,
            radial_velocity_mps: speed_mps * x_m / f64::hypot(x_m, 3.0),
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: Some(2),
            ground_truth_id: Some(1),
        });
        assert_eq!(step_frame(tracker, &frame, Some(&pose)).0, PrimmStatus::Ok);
    }
    let stats = stats(tracker);
    assert!(stats.speeds_bounded > 0, "{stats:?}");
    assert_eq!(stats.frames_tracked, 70);
    destroy(tracker);
}
