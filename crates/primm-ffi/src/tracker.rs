//! The tracker handle and its entry points.

use crate::status::{guard, guard_value, record_thread_error, ErrorText, Failure, PanicMessage, PrimmStatus};
use crate::text::copy_to_c_buffer;
use crate::types::{
    method_from_code, PrimmEgoPose, PrimmMeasurement, PrimmStats, PrimmStepSummary, PrimmTrack,
    PrimmTrackerOptions, PRIMM_MAX_TRACKS, PRIMM_METHOD_CONFIG,
};
use core::ffi::{c_char, CStr};
use core::fmt;
use primm_config::Settings;
use primm_core::measurement::{FrameView, Measurement, UnknownClass};
use primm_core::mode::Mode;
use primm_core::pose::EgoPose;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use primm_core::track::TrackOutput;
use primm_core::tracker::Tracker;
use primm_predictor::onnx::{ModelSource, OnnxPredictor, PrModel};
use primm_predictor::split::on_inference_threads;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

/// Name under which model bytes given to [`primm_tracker_create`] appear in model errors.
const CALLER_MODEL_NAME: &str = "(model bytes given to primm_tracker_create)";

/// An opaque tracker: the core tracker with its predictor, the output buffer of the last step
/// and the message of its last failure. Created by `primm_tracker_create`, released by
/// `primm_tracker_destroy`. One thread at a time may use a tracker.
pub struct PrimmTracker {
    pub(crate) tracker: Tracker<Box<dyn DisplacementPredictor + Send>>,
    /// [`PRIMM_MAX_TRACKS`] entries; the first `track_count` are the last step's tracks.
    tracks: Box<[PrimmTrack]>,
    track_count: usize,
    /// Room for every track predicted by `primm_tracker_predict_to`, allocated once.
    predicted: Box<[TrackOutput]>,
    last_error: ErrorText,
    /// Set when a call panicked: the tracker's state may be inconsistent.
    poisoned: bool,
}

impl fmt::Debug for PrimmTracker {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PrimmTracker")
            .field("stats", self.tracker.stats())
            .field("track_count", &self.track_count)
            .field("last_error", &self.last_error)
            .field("poisoned", &self.poisoned)
            .finish_non_exhaustive()
    }
}

impl PrimmTracker {
    /// Builds a tracker from `options`.
    ///
    /// # Safety
    /// The pointers in `options` are NULL or valid as documented on [`PrimmTrackerOptions`].
    unsafe fn new(options: &PrimmTrackerOptions) -> Result<Box<Self>, Failure> {
        let Settings { tracker: config, inference } = if options.config_toml.is_null() {
            Settings::default()
        } else {
            // SAFETY: the caller passes a NUL-terminated string.
            let text = unsafe { CStr::from_ptr(options.config_toml) };
            primm_config::settings_from_toml_str(text.to_str().map_err(Failure::ConfigNotUtf8)?)
                .map_err(Failure::Config)?
        };
        let config = match method_from_code(options.method).map_err(Failure::UnknownMethod)? {
            Some(method) => config.with_modes(method.modes()),
            None => config,
        };
        let model_bytes = match (options.model_onnx.is_null(), options.model_onnx_len) {
            (true, 0) => None,
            (true, _) => return Err(Failure::NullArgument("model_onnx")),
            // SAFETY: the caller passes `model_onnx_len` readable bytes.
            (false, len) => Some(unsafe { core::slice::from_raw_parts(options.model_onnx, len) }),
        };
        let model = match model_bytes {
            Some(bytes) => Some(
                PrModel::from_bytes(bytes, ModelSource::File(PathBuf::from(CALLER_MODEL_NAME)))
                    .map_err(Failure::Model)?,
            ),
            None => None,
        };
        let predictor: Box<dyn DisplacementPredictor + Send> = if config.imm.modes.contains(Mode::Learned) {
            let mut onnx = match model {
                Some(model) => OnnxPredictor::from_model(model),
                None if options.use_builtin_model => OnnxPredictor::embedded().map_err(Failure::Model)?,
                None => return Err(Failure::ModelRequired),
            };
            onnx.set_engine(inference.engine);
            if options.inference_thread {
                Box::new(
                    on_inference_threads(onnx, inference.inference_threads, inference.deadline())
                        .map_err(Failure::InferenceThread)?,
                )
            } else {
                Box::new(onnx)
            }
        } else {
            Box::new(NoPredictor)
        };
        let tracker = Tracker::with_predictor(config, predictor).map_err(Failure::ConfigRejected)?;
        Ok(Box::new(PrimmTracker {
            tracker,
            tracks: vec![PrimmTrack::EMPTY; PRIMM_MAX_TRACKS].into_boxed_slice(),
            track_count: 0,
            predicted: vec![TrackOutput::default(); PRIMM_MAX_TRACKS].into_boxed_slice(),
            last_error: ErrorText::new(),
            poisoned: false,
        }))
    }

    /// Tracks one frame and keeps its tracks.
    fn step(&mut self, frame: &CallerFrame) -> Result<PrimmStepSummary, Failure> {
        let tracks = &mut self.tracks;
        let mut count = 0;
        let summary = self
            .tracker
            .step_into(frame, |output| {
                if let Some(slot) = tracks.get_mut(count) {
                    *slot = PrimmTrack::from(output);
                    count += 1;
                }
            })
            .map_err(Failure::Step)?;
        self.track_count = count;
        Ok(PrimmStepSummary::new(&summary, self.tracker.association_stats(), &self.tracks[..count]))
    }
}

/// A frame in caller memory, read in place: the tracker decodes each measurement when it needs
/// it, so stepping copies no frame.
struct CallerFrame {
    timestamp_s: f64,
    measurements: *const PrimmMeasurement,
    count: usize,
    ego_pose: Option<EgoPose>,
}

impl FrameView for CallerFrame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }

    fn len(&self) -> usize {
        self.count
    }

    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        assert!(index < self.count, "measurement {index} of a frame of {}", self.count);
        // SAFETY: the caller of `primm_tracker_step` passes `count` readable measurements, and
        // `index < count`.
        let measurement = unsafe { self.measurements.add(index).read() };
        measurement.to_measurement()
    }

    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}

/// Runs an entry point on the tracker behind `tracker`: NULL and poisoned trackers are refused,
/// a failure's message is recorded for the tracker and the calling thread, and a panic poisons
/// the tracker.
///
/// # Safety
/// `tracker` is NULL or a live handle from [`primm_tracker_create`], used by no other thread.
pub(crate) unsafe fn with_tracker(
    tracker: *mut PrimmTracker,
    body: impl FnOnce(&mut PrimmTracker) -> Result<(), Failure>,
) -> PrimmStatus {
    if tracker.is_null() {
        return guard(|| Err(Failure::NullArgument("tracker")));
    }
    // SAFETY: a live, exclusively used handle (caller contract).
    if unsafe { (*tracker).poisoned } {
        record_thread_error(&PrimmStatus::Poisoned.message().to_string_lossy());
        return PrimmStatus::Poisoned;
    }
    // SAFETY: as above; the reference ends with the closure.
    let result = catch_unwind(AssertUnwindSafe(|| body(unsafe { &mut *tracker })));
    // SAFETY: as above; the closure's reference is gone.
    let handle = unsafe { &mut *tracker };
    match result {
        Ok(Ok(())) => PrimmStatus::Ok,
        Ok(Err(failure)) => {
            handle.last_error.set(&failure);
            record_thread_error(&failure);
            failure.status()
        }
        Err(payload) => {
            handle.poisoned = true;
            let message = PanicMessage(payload.as_ref());
            handle.last_error.set(&message);
            record_thread_error(&message);
            PrimmStatus::Panic
        }
    }
}

/// The default options: the built-in configuration (`config/primm.toml`) with its modes
/// (PR-IMM), the built-in PR model, inference inside `primm_tracker_step`.
#[no_mangle]
pub extern "C" fn primm_tracker_options_default() -> PrimmTrackerOptions {
    PrimmTrackerOptions {
        config_toml: core::ptr::null(),
        method: PRIMM_METHOD_CONFIG,
        model_onnx: core::ptr::null(),
        model_onnx_len: 0,
        use_builtin_model: true,
        inference_thread: false,
    }
}

/// Creates a tracker and writes its handle to `*out_tracker` (NULL on failure).
///
/// `options` may be NULL for `primm_tracker_options_default()`. The configuration text and
/// model bytes are only read during the call. Loading a PR model takes a while (the model is
/// optimised for several batch sizes); create trackers ahead of time.
///
/// Errors: `PRIMM_STATUS_NULL_ARGUMENT` (`out_tracker`, or `model_onnx` NULL with a non-zero
/// length), `PRIMM_STATUS_INVALID_ARGUMENT` (unknown method), `PRIMM_STATUS_INVALID_CONFIG`,
/// `PRIMM_STATUS_INVALID_MODEL`, `PRIMM_STATUS_INFERENCE_THREAD_FAILED`; the message
/// (`primm_last_error_message`) gives the details.
///
/// # Safety
/// `options` is NULL or points to a valid `PrimmTrackerOptions` whose pointers are NULL or
/// valid as documented there; `out_tracker` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_create(
    options: *const PrimmTrackerOptions,
    out_tracker: *mut *mut PrimmTracker,
) -> PrimmStatus {
    guard(|| {
        if out_tracker.is_null() {
            return Err(Failure::NullArgument("out_tracker"));
        }
        // SAFETY: writable (caller contract).
        unsafe { out_tracker.write(core::ptr::null_mut()) };
        let options = if options.is_null() {
            primm_tracker_options_default()
        } else {
            // SAFETY: a valid options struct (caller contract).
            unsafe { options.read() }
        };
        // SAFETY: the options' pointers are valid (caller contract).
        let tracker = unsafe { PrimmTracker::new(&options) }?;
        // SAFETY: writable (caller contract).
        unsafe { out_tracker.write(Box::into_raw(tracker)) };
        Ok(())
    })
}

/// Tracks one frame without an ego pose (in the vehicle frame): `primm_tracker_step_with_pose`
/// with a NULL pose.
///
/// # Safety
/// As `primm_tracker_step_with_pose`.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_step(
    tracker: *mut PrimmTracker,
    timestamp_s: f64,
    measurements: *const PrimmMeasurement,
    count: usize,
    out_summary: *mut PrimmStepSummary,
) -> PrimmStatus {
    // SAFETY: forwarded caller contract; a NULL pose is allowed.
    unsafe {
        primm_tracker_step_with_pose(
            tracker,
            timestamp_s,
            core::ptr::null(),
            measurements,
            count,
            out_summary,
        )
    }
}

/// Tracks one frame: `count` measurements at `measurements` (NULL allowed when `count` is 0),
/// taken at `timestamp_s` (seconds; a frame older than the newest tracked one by at most
/// `tracker.max_frame_delay_s` is tracked in its place, see `late_frame` of the summary; an older
/// one is rejected), with the ego
/// vehicle's pose `*ego_pose` at that time, or NULL when unknown. With a pose (and the
/// configuration's `frame.tracking_frame` "world", the default) the tracker keeps its tracks in
/// the world frame and reports them in the vehicle frame of this step with their world estimate
/// beside (`PrimmTrack::has_world_estimate`); a pose that is not finite or absurdly far out
/// rejects the frame (`PRIMM_STATUS_INVALID_FRAME`). The measurements are read in place during
/// the call. Writes what the step did to `*out_summary` unless it is
/// NULL (zeroed on failure).
///
/// Allocates nothing, unless the PR model runs inside the step (`inference_thread` false) on
/// tract (`predictor.engine = "tract"`, or a model the native forward pass does not cover),
/// which allocates during inference; the native forward pass, the default engine for the
/// shipped model, allocates nothing per batch.
///
/// A rejected frame (`PRIMM_STATUS_INVALID_FRAME`: timestamp not finite or not advancing,
/// interval too long, more than `PRIMM_MAX_MEASUREMENTS_PER_FRAME` measurements) leaves the
/// tracks and the output of the previous step unchanged. Single measurements with an unknown
/// class or NaN, infinite or absurd values are left out and counted; the rest of the frame is
/// tracked.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `ego_pose` is NULL or points to a
/// readable `PrimmEgoPose`; `measurements` is NULL or points to `count` readable, aligned
/// `PrimmMeasurement`s; `out_summary` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_step_with_pose(
    tracker: *mut PrimmTracker,
    timestamp_s: f64,
    ego_pose: *const PrimmEgoPose,
    measurements: *const PrimmMeasurement,
    count: usize,
    out_summary: *mut PrimmStepSummary,
) -> PrimmStatus {
    if !out_summary.is_null() {
        // SAFETY: writable (caller contract).
        unsafe { out_summary.write(PrimmStepSummary::default()) };
    }
    let body = |handle: &mut PrimmTracker| {
        if measurements.is_null() && count > 0 {
            return Err(Failure::NullArgument("measurements"));
        }
        // SAFETY: NULL or readable (caller contract).
        let ego_pose = unsafe { ego_pose.as_ref() }.map(|pose| EgoPose {
            x_m: pose.x_m,
            y_m: pose.y_m,
            yaw_rad: pose.yaw_rad,
        });
        let summary = handle.step(&CallerFrame { timestamp_s, measurements, count, ego_pose })?;
        if !out_summary.is_null() {
            // SAFETY: writable (caller contract).
            unsafe { out_summary.write(summary) };
        }
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Copies the tracks of the last successful step (every live track, in table order) to `out`,
/// which holds `capacity` entries, and writes their number to `*out_count`.
///
/// When `capacity` is smaller than the number of tracks, returns `PRIMM_STATUS_BUFFER_TOO_SMALL`
/// with `*out_count` set to the number needed and nothing copied; `out` may be NULL when
/// `capacity` is 0 (a query of the count). A buffer of `PRIMM_MAX_TRACKS` entries always fits.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out` is NULL or points to
/// `capacity` writable `PrimmTrack`s; `out_count` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_tracks(
    tracker: *mut PrimmTracker,
    out: *mut PrimmTrack,
    capacity: usize,
    out_count: *mut usize,
) -> PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out_count.is_null() {
            return Err(Failure::NullArgument("out_count"));
        }
        if out.is_null() && capacity > 0 {
            return Err(Failure::NullArgument("out"));
        }
        let needed = handle.track_count;
        // SAFETY: writable (caller contract).
        unsafe { out_count.write(needed) };
        if needed > capacity {
            return Err(Failure::BufferTooSmall { needed, capacity });
        }
        if needed > 0 {
            // SAFETY: `out` holds `capacity >= needed` entries (caller contract) and does not
            // overlap the handle's buffer.
            unsafe { core::ptr::copy_nonoverlapping(handle.tracks.as_ptr(), out, needed) };
        }
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Writes the tracker's counters since it was built to `*out`.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_stats(
    tracker: *mut PrimmTracker,
    out: *mut PrimmStats,
) -> PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out.is_null() {
            return Err(Failure::NullArgument("out"));
        }
        // SAFETY: writable (caller contract).
        unsafe { out.write(PrimmStats::from(handle.tracker.stats())) };
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Drops every track and forgets the last timestamp, e.g. before replaying another recording
/// or after `PRIMM_STATUS_INVALID_FRAME` for a too long interval. Counters are kept; `resets`
/// counts the call.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_reset(tracker: *mut PrimmTracker) -> PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        handle.tracker.reset();
        handle.track_count = 0;
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Writes every live track's fused prediction to time `timestamp_s` (seconds, on the clock of
/// the frames; not before the newest tracked frame, at most `tracker.max_frame_interval_s`
/// after it) into `out`, which holds `capacity` entries, and their number to `*out_count`,
/// without changing any state: for a consumer that runs at its own cycle. The learned mode
/// sits the prediction out (it would need a model inference); the existence probability decays
/// over the interval. With `ego_pose` (the vehicle's pose at `timestamp_s`, NULL when unknown)
/// the vehicle-frame values of world-frame tracks are given in the vehicle frame of that pose;
/// without, in that of the newest frame's pose. Buffer rules as `primm_tracker_tracks`; a time
/// out of range is `PRIMM_STATUS_INVALID_ARGUMENT` with the reason in the last error. Before the
/// first frame, and after a reset, there is no track: `*out_count` is 0. Allocates nothing.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `ego_pose` is NULL or readable;
/// `out` is NULL or points to `capacity` writable `PrimmTrack`s; `out_count` is NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_predict_to(
    tracker: *mut PrimmTracker,
    timestamp_s: f64,
    ego_pose: *const PrimmEgoPose,
    out: *mut PrimmTrack,
    capacity: usize,
    out_count: *mut usize,
) -> PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out_count.is_null() {
            return Err(Failure::NullArgument("out_count"));
        }
        if out.is_null() && capacity > 0 {
            return Err(Failure::NullArgument("out"));
        }
        let needed = handle.tracker.tracks().len();
        // SAFETY: writable (caller contract).
        unsafe { out_count.write(needed) };
        if needed > capacity {
            return Err(Failure::BufferTooSmall { needed, capacity });
        }
        // SAFETY: NULL or readable (caller contract).
        let ego_pose = unsafe { ego_pose.as_ref() }.map(|pose| EgoPose {
            x_m: pose.x_m,
            y_m: pose.y_m,
            yaw_rad: pose.yaw_rad,
        });
        let predicted = &mut handle.predicted[..];
        let count = handle
            .tracker
            .predict_to_with_pose(timestamp_s, ego_pose, predicted)
            .map_err(Failure::Predict)?;
        for (index, output) in predicted[..count].iter().enumerate() {
            // SAFETY: `out` holds `capacity >= needed >= count` entries (caller contract).
            unsafe { out.add(index).write(PrimmTrack::from(output)) };
        }
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Writes the time of the newest tracked frame (the time of the tracks `primm_tracker_tracks`
/// copies, also after a late frame) to `*out_timestamp_s`, or NaN before the first frame and
/// after a reset.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out_timestamp_s` is NULL or
/// writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_newest_timestamp(
    tracker: *mut PrimmTracker,
    out_timestamp_s: *mut f64,
) -> PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out_timestamp_s.is_null() {
            return Err(Failure::NullArgument("out_timestamp_s"));
        }
        // SAFETY: writable (caller contract).
        unsafe { out_timestamp_s.write(handle.tracker.newest_timestamp_s().unwrap_or(f64::NAN)) };
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Destroys a tracker (stops its inference thread, if any). NULL is ignored.
///
/// # Safety
/// `tracker` is NULL or a live handle from `primm_tracker_create`, not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_destroy(tracker: *mut PrimmTracker) {
    if tracker.is_null() {
        return;
    }
    guard_value((), || {
        // SAFETY: a live handle made by `Box::into_raw` (caller contract).
        drop(unsafe { Box::from_raw(tracker) });
    });
}

/// Copies the message of the last failed call on this tracker into `buf` (`len` bytes,
/// NUL-terminated, cut if too short; nothing written when `buf` is NULL or `len` is 0) and
/// returns the message's full length in bytes without the NUL, like `snprintf`. An empty
/// message when no call on the tracker has failed, or when `tracker` is NULL.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `buf` is NULL or points to `len`
/// writable bytes.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_last_error(
    tracker: *const PrimmTracker,
    buf: *mut c_char,
    len: usize,
) -> usize {
    guard_value(0, || {
        // SAFETY: a live handle or NULL (caller contract).
        let text = unsafe { tracker.as_ref() }.map_or("", |handle| handle.last_error.as_str());
        // SAFETY: `buf` holds `len` bytes (caller contract).
        unsafe { copy_to_c_buffer(text, buf, len) }
    })
}

#[cfg(test)]
mod tests;
