//! Target `c_api_calls`: sequences of C API calls (create, step, copy the tracks, counters,
//! reset, destroy, error messages, helpers) on up to four trackers at once, with arbitrary
//! buffers, sizes, NULL pointers, poses and measurements, called as a C program calls them.
//!
//! Every tracker the API creates has a mirror: a `primm-core` tracker built from the same
//! configuration and stepped on the same frames, read through the target's own view of the
//! caller's measurements. After every call the target checks the C API against the mirror and
//! its documentation:
//!
//! * the status is the one the mirror's result maps to (never `PRIMM_STATUS_PANIC`);
//! * the tracks copied out are the mirror's outputs field for field, and a rejected frame or a
//!   buffer too small changes nothing (neither the tracks nor the caller's buffer);
//! * the counters equal the mirror's;
//! * a failed call on a tracker leaves the same non-empty message for the tracker and the
//!   thread, and the message functions follow the `snprintf` contract for every length;
//! * `primm_format_f64` writes what Rust's `{}` writes; class names and codes map both ways.
//!
//! Pointers are never dangling: a buffer is allocated with the size passed, or the pointer is
//! NULL. PR methods are created without a model (they must fail with
//! `PRIMM_STATUS_INVALID_MODEL`); the ONNX target covers model bytes.

use crate::invariant_check::assert_tracker_invariants;
use core::ffi::{c_char, CStr};
use core::ptr::{null, null_mut};
use primm_core::config::Config;
use primm_core::measurement::{FrameView, Measurement, ObjectClass, UnknownClass};
use primm_core::mode::{Method, Mode};
use primm_core::pose::EgoPose;
use primm_core::tracker::{StepError, Tracker};
use primm_ffi::*;

/// Most calls one input is turned into.
pub const MAX_CALLS: usize = 96;

/// Trackers alive at once.
const SLOTS: usize = 4;

/// Configuration texts a create call chooses from (index 4 is not UTF-8).
const CONFIGS: [&[u8]; 5] = [
    b"",
    b"[frame]\ntracking_frame = \"vehicle\"\n",
    b"[tracker]\nmax_frame_interval_s = 0.2\n",
    b"[tracker]\nmax_frame_interval_s = -1.0\n",
    b"[tracker]\nmax_frame_interval_s = \xff\n",
];

/// A tracker made by the C API and its mirror.
struct Live {
    handle: *mut PrimmTracker,
    mirror: Tracker<primm_core::predictor::NoPredictor>,
    /// The mirror's outputs of its last successful step, as the C API copies them.
    tracks: Vec<String>,
}

impl Drop for Live {
    fn drop(&mut self) {
        // SAFETY: a live handle from `primm_tracker_create`, destroyed once, here.
        unsafe { primm_tracker_destroy(self.handle) };
    }
}

/// The caller's measurements as the tracker reads them, converted by the target itself.
struct MirrorFrame<'a> {
    timestamp_s: f64,
    measurements: &'a [PrimmMeasurement],
    ego_pose: Option<EgoPose>,
}

impl FrameView for MirrorFrame<'_> {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }

    fn len(&self) -> usize {
        self.measurements.len()
    }

    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        let measurement = &self.measurements[index];
        let class = ObjectClass::from_code(measurement.class_code)
            .ok_or(UnknownClass { code: measurement.class_code })?;
        Ok(Measurement {
            x_m: measurement.x_m,
            y_m: measurement.y_m,
            radial_velocity_mps: measurement.radial_velocity_mps,
            rcs_dbsm: measurement.rcs_dbsm,
            class,
            sensor_id: u16::try_from(measurement.sensor_id).ok(),
            ground_truth_id: (measurement.ground_truth_id != PRIMM_NO_GROUND_TRUTH_ID)
                .then_some(measurement.ground_truth_id as u64),
        })
    }

    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}

/// The input, consumed from the front; reads past the end give `None`.
struct Input<'a>(&'a [u8]);

impl Input<'_> {
    fn bytes<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, tail) = self.0.split_first_chunk::<N>()?;
        self.0 = tail;
        Some(*head)
    }
    fn u8(&mut self) -> Option<u8> {
        self.bytes::<1>().map(|[byte]| byte)
    }
    fn u16(&mut self) -> Option<u16> {
        self.bytes().map(u16::from_le_bytes)
    }
    fn i16(&mut self) -> Option<i16> {
        self.bytes().map(i16::from_le_bytes)
    }
    fn i32(&mut self) -> Option<i32> {
        self.bytes().map(i32::from_le_bytes)
    }
    fn f64(&mut self) -> Option<f64> {
        self.bytes().map(f64::from_le_bytes)
    }
}

/// Per-tracker state of the sequence: the slots and each slot's clock.
struct Session {
    slots: [Option<Live>; SLOTS],
    clocks: [f64; SLOTS],
}

/// Reads calls from `data` until it ends (at most [`MAX_CALLS`]) and checks each. Each call is
/// an opcode byte (mod 9) and its operands, little-endian:
///
/// | opcode | call | operands |
/// |---|---|---|
/// | 0 | create | slot, method code (mod 8; 7 is unknown), configuration (mod 5, `CONFIGS`) |
/// | 1 | step | slot, advance in ms (255: a raw `f64` time follows), pose kind (mod 3: NULL, `i16`×3 in cm/cm/mrad, `f64`×3) and its fields, count, buffer mode (mod 4: exact, NULL, oversized beyond the frame limit, no summary), then per measurement class `u8` (bit 7: x is NaN), x and y `i16` in cm, radial velocity `i8`, sensor `u8` |
/// | 2 | copy the tracks | slot, capacity `u16`, flags (bit 0 NULL buffer, bit 1 NULL count) |
/// | 3 | counters | slot, flags (bit 0 NULL output) |
/// | 4 | reset | slot |
/// | 5 | destroy | slot |
/// | 6 | tracker message | slot, length `u16`, flags (bit 0 NULL buffer) |
/// | 7 | thread message | length `u16` |
/// | 8 | helpers | kind (mod 4: format a raw `f64` into a `u16`-long buffer, class name of a code, class of up to 8 name bytes, status message of an `i32`) and its operands |
pub fn run(data: &[u8]) {
    let mut input = Input(data);
    let mut session = Session { slots: Default::default(), clocks: [0.0; SLOTS] };
    for _ in 0..MAX_CALLS {
        let Some(opcode) = input.u8() else { break };
        let done = match opcode % 9 {
            0 => create(&mut input, &mut session),
            1 => step(&mut input, &mut session),
            2 => copy_tracks(&mut input, &mut session),
            3 => counters(&mut input, &mut session),
            4 => reset(&mut input, &mut session),
            5 => destroy(&mut input, &mut session),
            6 => tracker_message(&mut input, &mut session),
            7 => input.u16().map(|length| check_thread_message(usize::from(length))),
            _ => helpers(&mut input),
        };
        if done.is_none() {
            break;
        }
    }
}

/// The handle of `slot`, NULL when the slot is empty.
fn handle(session: &Session, slot: usize) -> *mut PrimmTracker {
    session.slots[slot].as_ref().map_or(null_mut(), |live| live.handle)
}

/// Panics on the status no call may return, and on a status outside the enum's codes.
fn assert_no_panic(status: PrimmStatus, call: &str) {
    assert_ne!(status, PrimmStatus::Panic, "{call} panicked inside primm: {}", thread_message());
    assert_ne!(status, PrimmStatus::Poisoned, "{call}: a tracker was poisoned");
}

/// The calling thread's last error message.
fn thread_message() -> String {
    let mut buffer = vec![0 as c_char; 4096];
    // SAFETY: a writable buffer of its length.
    unsafe { primm_last_error_message(buffer.as_mut_ptr(), buffer.len()) };
    // SAFETY: NUL-terminated by the call.
    unsafe { CStr::from_ptr(buffer.as_ptr()) }.to_string_lossy().into_owned()
}

/// The tracker's last error message.
fn message_of(tracker: *mut PrimmTracker) -> String {
    let mut buffer = vec![0 as c_char; 4096];
    // SAFETY: a live tracker or NULL, a writable buffer of its length.
    unsafe { primm_tracker_last_error(tracker, buffer.as_mut_ptr(), buffer.len()) };
    // SAFETY: NUL-terminated by the call.
    unsafe { CStr::from_ptr(buffer.as_ptr()) }.to_string_lossy().into_owned()
}

/// After a failed call on a live tracker: the tracker and the thread hold the same message.
fn assert_failure_recorded(tracker: *mut PrimmTracker, call: &str) {
    let message = thread_message();
    assert!(!message.is_empty(), "{call} failed without a message");
    if !tracker.is_null() {
        assert_eq!(message_of(tracker), message, "{call}: the tracker's and the thread's messages differ");
    }
}

/// The method of a create call's code: `Ok(None)` keeps the configuration's modes.
fn method_of(code: u32) -> Result<Option<Method>, ()> {
    match code {
        0 => Ok(None),
        1 => Ok(Some(Method::ConstantVelocity)),
        2 => Ok(Some(Method::ConstantAcceleration)),
        3 => Ok(Some(Method::CoordinatedTurn)),
        4 => Ok(Some(Method::Learned)),
        5 => Ok(Some(Method::Imm)),
        6 => Ok(Some(Method::PrImm)),
        _ => Err(()),
    }
}

fn create(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let method = u32::from(input.u8()? % 8);
    let config_text = CONFIGS[usize::from(input.u8()? % CONFIGS.len() as u8)];

    // What the C API must do, from the documentation and the core.
    let expected = (|| {
        let config = if config_text.is_empty() {
            Config::default()
        } else {
            let text = core::str::from_utf8(config_text).map_err(|_| PrimmStatus::InvalidConfig)?;
            primm_config::from_toml_str(text).map_err(|_| PrimmStatus::InvalidConfig)?
        };
        let config = match method_of(method).map_err(|()| PrimmStatus::InvalidArgument)? {
            Some(method) => config.with_modes(method.modes()),
            None => config,
        };
        if config.imm.modes.contains(Mode::Learned) {
            return Err(PrimmStatus::InvalidModel);
        }
        Tracker::new(config).map_err(|_| PrimmStatus::InvalidConfig)
    })();

    let text = std::ffi::CString::new(config_text).expect("no NUL in the configuration texts");
    let options = PrimmTrackerOptions {
        config_toml: if config_text.is_empty() { null() } else { text.as_ptr() },
        method,
        use_builtin_model: false,
        ..primm_tracker_options_default()
    };
    let mut tracker = null_mut();
    // SAFETY: valid options (a NUL-terminated text or NULL, no model) and out-pointer.
    let status = unsafe { primm_tracker_create(&options, &mut tracker) };
    assert_no_panic(status, "primm_tracker_create");
    match expected {
        Ok(mirror) => {
            assert_eq!(status, PrimmStatus::Ok, "create (method {method}): {}", thread_message());
            assert!(!tracker.is_null());
            // Replacing a live tracker destroys it (Live's drop).
            session.slots[slot] = Some(Live { handle: tracker, mirror, tracks: Vec::new() });
            session.clocks[slot] = 0.0;
        }
        Err(expected) => {
            assert_eq!(status, expected, "create (method {method}, configuration {config_text:?})");
            assert!(tracker.is_null(), "a failed create leaves the handle NULL");
            assert_failure_recorded(null_mut(), "primm_tracker_create");
        }
    }
    Some(())
}

/// A measurement from 7 input bytes.
fn read_measurement(input: &mut Input) -> Option<PrimmMeasurement> {
    let class = input.u8()?;
    let x_cm = input.i16()?;
    let y_cm = input.i16()?;
    let radial = input.u8()? as i8;
    let sensor = input.u8()?;
    Some(PrimmMeasurement {
        x_m: if class & 0x80 != 0 { f64::NAN } else { f64::from(x_cm) * 0.01 },
        y_m: f64::from(y_cm) * 0.01,
        radial_velocity_mps: f64::from(radial) * 0.5,
        rcs_dbsm: 5.0,
        ground_truth_id: i64::from(sensor % 5) - 1,
        sensor_id: i32::from(sensor % 6) - 1,
        class_code: class & 0x7f,
    })
}

/// The tracks the C API copies out of `tracker`, as text (NaN priors compare unequal).
fn copied_tracks(tracker: *mut PrimmTracker) -> Vec<String> {
    let mut tracks = Vec::<PrimmTrack>::with_capacity(PRIMM_MAX_TRACKS);
    let mut count = 0;
    // SAFETY: a live tracker; `tracks` has room for PRIMM_MAX_TRACKS entries; a writable count.
    let status = unsafe { primm_tracker_tracks(tracker, tracks.as_mut_ptr(), PRIMM_MAX_TRACKS, &mut count) };
    assert_eq!(status, PrimmStatus::Ok, "copying the tracks into a full-size buffer");
    assert!(count <= PRIMM_MAX_TRACKS);
    // SAFETY: the call initialised the first `count` entries.
    unsafe { tracks.set_len(count) };
    tracks.iter().map(|track| format!("{track:?}")).collect()
}

fn step(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let advance_ms = input.u8()?;
    let timestamp_s =
        if advance_ms == 255 { input.f64()? } else { session.clocks[slot] + f64::from(advance_ms) * 1e-3 };
    let pose = read_pose(input)?;
    let count = usize::from(input.u8()?);
    let mode = input.u8()? % 4;
    let measurements = read_measurements(input, count, mode == 2)?;
    let (pointer, length) =
        if mode == 1 { (null(), count) } else { (measurements.as_ptr(), measurements.len()) };
    let mut summary = PrimmStepSummary { track_count: usize::MAX, ..Default::default() };
    let summary_pointer: *mut PrimmStepSummary = if mode == 3 { null_mut() } else { &mut summary };
    let tracker = handle(session, slot);
    let pose_pointer = pose.as_ref().map_or(null(), |pose| pose as *const PrimmEgoPose);
    // SAFETY: a live tracker or NULL; a readable pose or NULL; `length` readable measurements
    // at `pointer`, or NULL; a writable summary or NULL.
    let status = unsafe {
        primm_tracker_step_with_pose(tracker, timestamp_s, pose_pointer, pointer, length, summary_pointer)
    };
    assert_no_panic(status, "primm_tracker_step_with_pose");
    if mode != 3 && status != PrimmStatus::Ok {
        assert_eq!(summary, PrimmStepSummary::default(), "a failed step zeroes the summary");
    }
    let Some(live) = session.slots[slot].as_mut() else {
        assert_eq!(status, PrimmStatus::NullArgument, "a step on NULL");
        assert_failure_recorded(null_mut(), "step on NULL");
        return Some(());
    };
    if pointer.is_null() && length > 0 {
        assert_eq!(status, PrimmStatus::NullArgument, "NULL measurements with a count");
        assert_failure_recorded(tracker, "step with NULL measurements");
        assert_eq!(copied_tracks(tracker), live.tracks, "a refused step changed the tracks");
        return Some(());
    }
    let frame = MirrorFrame {
        timestamp_s,
        measurements: &measurements,
        ego_pose: pose.map(|pose| EgoPose { x_m: pose.x_m, y_m: pose.y_m, yaw_rad: pose.yaw_rad }),
    };
    let expected = match live.mirror.step(&frame) {
        Ok(outputs) => {
            live.tracks = outputs.iter().map(|output| format!("{:?}", PrimmTrack::from(output))).collect();
            PrimmStatus::Ok
        }
        Err(StepError::InvalidFrame(_)) => PrimmStatus::InvalidFrame,
        Err(StepError::Association(_)) => PrimmStatus::AssociationError,
    };
    assert_tracker_invariants(&live.mirror, "C API mirror");
    assert_eq!(status, expected, "step at {timestamp_s} s: {}", thread_message());
    if status == PrimmStatus::Ok {
        session.clocks[slot] = timestamp_s;
        if mode != 3 {
            assert_eq!(summary.track_count, live.tracks.len());
        }
    } else {
        assert_failure_recorded(tracker, "primm_tracker_step_with_pose");
    }
    assert_eq!(copied_tracks(tracker), live.tracks, "tracks after a step with status {status:?}");
    Some(())
}

/// An ego pose: none, a plausible one, or any eight bytes per value.
fn read_pose(input: &mut Input) -> Option<Option<PrimmEgoPose>> {
    Some(match input.u8()? % 3 {
        0 => None,
        1 => Some(PrimmEgoPose {
            x_m: f64::from(input.i16()?) * 0.01,
            y_m: f64::from(input.i16()?) * 0.01,
            yaw_rad: f64::from(input.i16()?) * 1e-3,
        }),
        _ => Some(PrimmEgoPose { x_m: input.f64()?, y_m: input.f64()?, yaw_rad: input.f64()? }),
    })
}

/// `count` measurements; with `too_many`, padded to more than a frame may carry (the frame is
/// then rejected as a whole).
fn read_measurements(input: &mut Input, count: usize, too_many: bool) -> Option<Vec<PrimmMeasurement>> {
    let mut measurements = Vec::with_capacity(count);
    for _ in 0..count {
        measurements.push(read_measurement(input)?);
    }
    if too_many {
        // More than a frame may carry: rejected as a whole.
        let filler = measurements.last().copied().unwrap_or(PrimmMeasurement {
            x_m: 10.0,
            y_m: 0.0,
            radial_velocity_mps: 0.0,
            rcs_dbsm: 0.0,
            ground_truth_id: -1,
            sensor_id: -1,
            class_code: 0,
        });
        measurements.resize(PRIMM_MAX_MEASUREMENTS_PER_FRAME + 1 + count, filler);
    }
    Some(measurements)
}

fn copy_tracks(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let capacity = usize::from(input.u16()? % 600);
    let flags = input.u8()?;
    let tracker = handle(session, slot);
    // A buffer of `capacity` entries filled with a marker that no copy leaves behind.
    // SAFETY: every field of PrimmTrack is a number or a bool, for which zero bytes are valid.
    let marker = PrimmTrack { id: u64::MAX, ..unsafe { core::mem::zeroed() } };
    let mut buffer = vec![marker; capacity];
    let out = if flags & 1 != 0 { null_mut() } else { buffer.as_mut_ptr() };
    let mut count = usize::MAX;
    let count_pointer: *mut usize = if flags & 2 != 0 { null_mut() } else { &mut count };
    // SAFETY: a live tracker or NULL; `out` is NULL or holds `capacity` entries; the count is
    // writable or NULL.
    let status = unsafe { primm_tracker_tracks(tracker, out, capacity, count_pointer) };
    assert_no_panic(status, "primm_tracker_tracks");
    let Some(live) = session.slots[slot].as_ref() else {
        assert_eq!(status, PrimmStatus::NullArgument);
        return Some(());
    };
    let needed = live.tracks.len();
    if count_pointer.is_null() || (out.is_null() && capacity > 0) {
        assert_eq!(status, PrimmStatus::NullArgument);
        assert_failure_recorded(tracker, "primm_tracker_tracks with NULL");
    } else if needed > capacity {
        assert_eq!(status, PrimmStatus::BufferTooSmall);
        assert_eq!(count, needed, "the count needed is written");
        assert_failure_recorded(tracker, "primm_tracker_tracks into a small buffer");
    } else {
        assert_eq!(status, PrimmStatus::Ok);
        assert_eq!(count, needed);
        let copied: Vec<String> = buffer[..count].iter().map(|track| format!("{track:?}")).collect();
        assert_eq!(copied, live.tracks);
        assert!(buffer[count..].iter().all(|track| track.id == u64::MAX), "written beyond the tracks");
        return Some(());
    }
    assert!(buffer.iter().all(|track| track.id == u64::MAX), "a refused copy wrote into the buffer");
    Some(())
}

fn counters(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let null_output = input.u8()? & 1 != 0;
    let tracker = handle(session, slot);
    let mut stats = PrimmStats { frames_tracked: u64::MAX, ..Default::default() };
    let out: *mut PrimmStats = if null_output { null_mut() } else { &mut stats };
    // SAFETY: a live tracker or NULL; a writable struct or NULL.
    let status = unsafe { primm_tracker_stats(tracker, out) };
    assert_no_panic(status, "primm_tracker_stats");
    match session.slots[slot].as_ref() {
        None => assert_eq!(status, PrimmStatus::NullArgument),
        Some(_) if null_output => {
            assert_eq!(status, PrimmStatus::NullArgument);
            assert_failure_recorded(tracker, "primm_tracker_stats with NULL");
        }
        Some(live) => {
            assert_eq!(status, PrimmStatus::Ok);
            assert_eq!(stats, PrimmStats::from(live.mirror.stats()), "the counters differ from the mirror's");
        }
    }
    Some(())
}

fn reset(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let tracker = handle(session, slot);
    // SAFETY: a live tracker or NULL.
    let status = unsafe { primm_tracker_reset(tracker) };
    assert_no_panic(status, "primm_tracker_reset");
    match session.slots[slot].as_mut() {
        None => assert_eq!(status, PrimmStatus::NullArgument),
        Some(live) => {
            assert_eq!(status, PrimmStatus::Ok);
            live.mirror.reset();
            live.tracks.clear();
            session.clocks[slot] = 0.0;
            assert!(copied_tracks(tracker).is_empty(), "tracks after a reset");
        }
    }
    Some(())
}

fn destroy(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    match session.slots[slot].take() {
        // Live's drop calls primm_tracker_destroy.
        Some(live) => drop(live),
        // SAFETY: NULL is ignored.
        None => unsafe { primm_tracker_destroy(null_mut()) },
    }
    Some(())
}

/// Checks the `snprintf` contract of a message function: `read(buffer, length)` returns the
/// full length of `full` and writes a NUL-terminated prefix of it that fits.
fn check_message_copy(
    full: &str,
    length: usize,
    null_buffer: bool,
    read: impl Fn(*mut c_char, usize) -> usize,
) {
    let mut buffer = vec![0x55 as c_char; length];
    let pointer = if null_buffer { null_mut() } else { buffer.as_mut_ptr() };
    let returned = read(pointer, length);
    assert_eq!(returned, full.len(), "the full length of {full:?}");
    if null_buffer || length == 0 {
        assert!(buffer.iter().all(|&byte| byte == 0x55), "nothing is written without a buffer");
        return;
    }
    let end = buffer.iter().position(|&byte| byte == 0).expect("NUL-terminated within the length");
    let written: Vec<u8> = buffer[..end].iter().map(|&byte| byte as u8).collect();
    assert!(full.as_bytes().starts_with(&written), "{written:?} is not a prefix of {full:?}");
    assert!(written.len() == full.len() || written.len() + 4 > length - 1, "cut too short");
}

fn tracker_message(input: &mut Input, session: &mut Session) -> Option<()> {
    let slot = usize::from(input.u8()?) % SLOTS;
    let length = usize::from(input.u16()?);
    let null_buffer = input.u8()? & 1 != 0;
    let tracker = handle(session, slot);
    let full = message_of(tracker);
    if tracker.is_null() {
        assert!(full.is_empty(), "NULL has no message");
    }
    check_message_copy(&full, length, null_buffer, |buffer, length| {
        // SAFETY: a live tracker or NULL; `buffer` holds `length` bytes or is NULL.
        unsafe { primm_tracker_last_error(tracker, buffer, length) }
    });
    Some(())
}

fn check_thread_message(length: usize) {
    let full = thread_message();
    check_message_copy(&full, length, false, |buffer, length| {
        // SAFETY: `buffer` holds `length` bytes.
        unsafe { primm_last_error_message(buffer, length) }
    });
}

fn helpers(input: &mut Input) -> Option<()> {
    match input.u8()? % 4 {
        0 => {
            let value = input.f64()?;
            let length = usize::from(input.u16()? % 400);
            let full = format!("{value}");
            check_message_copy(&full, length, false, |buffer, length| {
                // SAFETY: `buffer` holds `length` bytes.
                unsafe { primm_format_f64(value, buffer, length) }
            });
        }
        1 => {
            let code = input.u8()?;
            let name = primm_object_class_name(code);
            match ObjectClass::from_code(code) {
                Some(class) => {
                    assert!(!name.is_null());
                    // SAFETY: a static NUL-terminated string.
                    let name = unsafe { CStr::from_ptr(name) }.to_str().expect("an ASCII name");
                    assert_eq!(ObjectClass::from_name(name), Some(class));
                    let text = std::ffi::CString::new(name).unwrap();
                    // SAFETY: NUL-terminated.
                    assert_eq!(unsafe { primm_object_class_from_name(text.as_ptr()) }, i32::from(code));
                }
                None => assert!(name.is_null(), "unknown code {code} has a name"),
            }
        }
        2 => {
            let bytes: [u8; 8] = input.bytes()?;
            let end = bytes.iter().position(|&byte| byte == 0).unwrap_or(bytes.len());
            let text = std::ffi::CString::new(&bytes[..end]).expect("cut at the first NUL");
            // SAFETY: NUL-terminated.
            let code = unsafe { primm_object_class_from_name(text.as_ptr()) };
            let expected = core::str::from_utf8(&bytes[..end])
                .ok()
                .and_then(ObjectClass::from_label)
                .map_or(-1, |class| i32::from(class.code()));
            assert_eq!(code, expected, "class of {text:?}");
        }
        _ => {
            let code = input.i32()?;
            let message = primm_status_message(code);
            assert!(!message.is_null());
            // SAFETY: a static NUL-terminated string.
            let message = unsafe { CStr::from_ptr(message) }.to_str().expect("an ASCII message");
            assert_eq!(message == "unknown status", PrimmStatus::from_code(code).is_none(), "status {code}");
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sequence_of_every_call_runs_and_matches_the_mirror() {
        let measurement = |class: u8, x_cm: i16, y_cm: i16| {
            let mut bytes = vec![class];
            bytes.extend_from_slice(&x_cm.to_le_bytes());
            bytes.extend_from_slice(&y_cm.to_le_bytes());
            bytes.extend_from_slice(&[10, 1]);
            bytes
        };
        let mut data = vec![0, 0, 5, 0]; // create an IMM tracker in slot 0
        data.extend([0, 1, 4, 0]); // create a PR-IMM tracker: no model, refused
        data.extend([0, 2, 7, 0]); // an unknown method code
        data.extend([0, 3, 5, 3]); // an invalid configuration value
        for k in 0..6i16 {
            data.extend([1, 0, 50, 0, 2, 0]); // step slot 0, 50 ms later, no pose, 2 measurements
            data.extend(measurement(0, 2000 + 50 * k, 200));
            data.extend(measurement(1, 800, -300 + 5 * k));
        }
        data.extend([1, 0, 0, 0, 1, 0]); // a frame that does not advance
        data.extend(measurement(0, 2000, 200));
        data.extend([1, 0, 50, 2]); // a raw NaN pose
        data.extend(f64::NAN.to_le_bytes());
        data.extend([0u8; 16]);
        data.extend([0, 0]); // no measurements, exact buffer
        data.extend([1, 0, 50, 0, 1, 1]); // NULL measurements with a count
        data.extend(measurement(0, 2000, 200));
        data.extend([1, 0, 50, 0, 0, 2]); // oversized frame
        data.extend([2, 0, 1, 0, 0]); // copy into a buffer of one
        data.extend([2, 0, 0, 2, 2]); // NULL count
        data.extend([3, 0, 0, 3, 0, 1]); // counters, then NULL output
        data.extend([6, 0, 7, 0, 0, 7, 3, 0]); // messages cut at 7 and 3 bytes
        data.extend([8, 0]);
        data.extend(0.1f64.to_le_bytes());
        data.extend([3, 0]); // format 0.1 into 3 bytes
        data.extend([8, 1, 1, 8, 2]);
        data.extend(*b"two_whee");
        data.extend([8, 3, 42, 0, 0, 0]);
        data.extend([4, 0, 5, 0, 5, 1, 1, 1, 0, 0, 0, 0]); // reset, destroy, destroy NULL, step NULL
        run(&data);
    }
}
