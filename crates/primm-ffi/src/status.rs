//! Status codes, error messages and the panic guard around every entry point.
//!
//! Every fallible function returns a [`PrimmStatus`]. The detailed message of a failure (the
//! configuration key, the model problem, the frame fault) is kept in a fixed-size buffer of the
//! calling thread and, for calls on a tracker, of the tracker, so recording it allocates
//! nothing. A panic is caught at the boundary, reported as [`PrimmStatus::Panic`] and poisons
//! the tracker it happened on.

use crate::text::{copy_to_c_buffer, FixedText};
use core::ffi::c_char;
use core::fmt;
use primm_core::tracker::StepError;
use primm_predictor::onnx::ModelError;
use std::any::Any;
use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Result of a C API call.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PrimmStatus {
    /// The call succeeded.
    Ok = 0,
    /// A pointer argument that must not be NULL was NULL (the message names it).
    NullArgument = 1,
    /// An argument has a value outside its domain, e.g. an unknown `PRIMM_METHOD_*` code.
    InvalidArgument = 2,
    /// The configuration is not UTF-8, not valid TOML for primm, or a value is out of range; the
    /// message names the offending key.
    InvalidConfig = 3,
    /// The ONNX model bytes are not a usable PR model, or the modes include PR and no model was
    /// given.
    InvalidModel = 4,
    /// The frame was rejected as a whole (timestamp not finite or not advancing, interval too
    /// long, too many measurements). The tracks are exactly as before the call.
    InvalidFrame = 5,
    /// The association solver refused the frame. The tracks are exactly as before the call.
    AssociationError = 6,
    /// The caller's buffer is smaller than the data; the count needed was written, nothing else.
    BufferTooSmall = 7,
    /// The inference thread of the PR model could not be started.
    InferenceThreadFailed = 8,
    /// A panic inside primm was caught at the boundary; the tracker is poisoned.
    Panic = 9,
    /// An earlier call on this tracker panicked; it only accepts `primm_tracker_destroy` (and
    /// the read-only `primm_tracker_last_error`).
    Poisoned = 10,
}

impl PrimmStatus {
    /// Every status, in code order.
    pub(crate) const ALL: [PrimmStatus; 11] = [
        PrimmStatus::Ok,
        PrimmStatus::NullArgument,
        PrimmStatus::InvalidArgument,
        PrimmStatus::InvalidConfig,
        PrimmStatus::InvalidModel,
        PrimmStatus::InvalidFrame,
        PrimmStatus::AssociationError,
        PrimmStatus::BufferTooSmall,
        PrimmStatus::InferenceThreadFailed,
        PrimmStatus::Panic,
        PrimmStatus::Poisoned,
    ];

    /// The status of a code, `None` for an unknown code.
    pub fn from_code(code: i32) -> Option<Self> {
        usize::try_from(code).ok().and_then(|index| Self::ALL.get(index)).copied()
    }

    /// The fixed one-line description of the status.
    pub fn message(self) -> &'static core::ffi::CStr {
        match self {
            PrimmStatus::Ok => c"success",
            PrimmStatus::NullArgument => c"a required pointer argument is NULL",
            PrimmStatus::InvalidArgument => c"an argument is out of its domain",
            PrimmStatus::InvalidConfig => c"invalid tracker configuration",
            PrimmStatus::InvalidModel => c"invalid or missing PR model",
            PrimmStatus::InvalidFrame => c"frame rejected",
            PrimmStatus::AssociationError => c"association failed",
            PrimmStatus::BufferTooSmall => c"buffer too small",
            PrimmStatus::InferenceThreadFailed => c"the inference thread could not be started",
            PrimmStatus::Panic => c"internal panic caught; the tracker is poisoned",
            PrimmStatus::Poisoned => c"the tracker is poisoned by an earlier panic",
        }
    }
}

/// Why a call failed, with everything its message needs. Building one allocates nothing for
/// the failures a step can have.
#[derive(Debug)]
pub(crate) enum Failure {
    /// A pointer argument, named, was NULL.
    NullArgument(&'static str),
    /// An unknown method code.
    UnknownMethod(u32),
    /// The configuration text is not UTF-8.
    ConfigNotUtf8(core::str::Utf8Error),
    /// The configuration text was rejected by the TOML reader or by validation.
    Config(primm_config::ConfigError),
    /// The configuration with the chosen method was rejected by the tracker.
    ConfigRejected(primm_core::config::ConfigError),
    /// The modes include PR, and neither model bytes nor the built-in model were asked for.
    ModelRequired,
    /// The model could not be loaded.
    Model(ModelError),
    /// The inference thread could not be started.
    InferenceThread(primm_predictor::split::InferenceThreadsError),
    /// The tracker rejected the frame.
    Step(StepError),
    /// The caller's buffer holds `capacity` entries, `needed` are required.
    BufferTooSmall { needed: usize, capacity: usize },
    /// The tracker refused to predict to the requested time.
    Predict(primm_core::prediction::PredictError),
    /// No sensor of the configuration has this id.
    UnknownSensor(i32),
    /// An unknown object class code.
    UnknownClass(u8),
}

impl Failure {
    /// The status code of the failure.
    pub(crate) fn status(&self) -> PrimmStatus {
        match self {
            Failure::NullArgument(_) => PrimmStatus::NullArgument,
            Failure::UnknownMethod(_) => PrimmStatus::InvalidArgument,
            Failure::ConfigNotUtf8(_) | Failure::Config(_) | Failure::ConfigRejected(_) => {
                PrimmStatus::InvalidConfig
            }
            Failure::ModelRequired | Failure::Model(_) => PrimmStatus::InvalidModel,
            Failure::InferenceThread(_) => PrimmStatus::InferenceThreadFailed,
            Failure::Step(StepError::InvalidFrame(_)) => PrimmStatus::InvalidFrame,
            Failure::Step(StepError::Association(_)) => PrimmStatus::AssociationError,
            Failure::BufferTooSmall { .. } => PrimmStatus::BufferTooSmall,
            Failure::Predict(_) | Failure::UnknownSensor(_) | Failure::UnknownClass(_) => {
                PrimmStatus::InvalidArgument
            }
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::NullArgument(name) => write!(f, "argument `{name}` is NULL"),
            Failure::UnknownMethod(code) => write!(
                f,
                "unknown method code {code} (expected PRIMM_METHOD_CONFIG (0) to PRIMM_METHOD_PR_IMM (6))"
            ),
            Failure::ConfigNotUtf8(error) => write!(f, "the configuration text is not UTF-8: {error}"),
            Failure::Config(error) => write!(f, "{error}"),
            Failure::ConfigRejected(error) => write!(f, "{error}"),
            Failure::ModelRequired => f.write_str(
                "the modes include PR but no model was given: pass ONNX model bytes or set use_builtin_model",
            ),
            Failure::Model(error) => write!(f, "{error}"),
            Failure::InferenceThread(error) => write!(f, "cannot start the PR inference thread: {error}"),
            Failure::Step(error) => write!(f, "{error}"),
            Failure::BufferTooSmall { needed, capacity } => {
                write!(f, "the buffer holds {capacity} entries, {needed} are needed")
            }
            Failure::Predict(error) => write!(f, "{error}"),
            Failure::UnknownSensor(id) => write!(
                f,
                "no sensor of the configuration has id {id} (frame.sensors; -1 asks for the radars without a mount)"
            ),
            Failure::UnknownClass(code) => write!(f, "unknown object class code {code} (expected 0, 1 or 2)"),
        }
    }
}

/// The message of a caught panic.
pub(crate) struct PanicMessage<'a>(pub(crate) &'a (dyn Any + Send));

impl fmt::Display for PanicMessage<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let detail = if let Some(text) = self.0.downcast_ref::<&str>() {
            text
        } else if let Some(text) = self.0.downcast_ref::<String>() {
            text.as_str()
        } else {
            "(no message)"
        };
        write!(f, "panic inside primm: {detail}")
    }
}

/// Capacity of an error message buffer, bytes; longer messages are cut at a character boundary.
pub(crate) const ERROR_TEXT_CAPACITY: usize = 1024;

/// An error message buffer.
pub(crate) type ErrorText = FixedText<ERROR_TEXT_CAPACITY>;

thread_local! {
    /// The message of the most recent failed call on this thread.
    static LAST_ERROR: RefCell<ErrorText> = const { RefCell::new(FixedText::new()) };
}

/// Records `message` as the calling thread's last error.
pub(crate) fn record_thread_error(message: &dyn fmt::Display) {
    let _ = LAST_ERROR.try_with(|text| {
        if let Ok(mut text) = text.try_borrow_mut() {
            text.set(message);
        }
    });
}

/// Copies the calling thread's last error message into `buf` (see [`copy_to_c_buffer`]).
///
/// # Safety
/// `buf` is NULL or points to `len` writable bytes.
pub(crate) unsafe fn copy_thread_error(buf: *mut c_char, len: usize) -> usize {
    LAST_ERROR
        .try_with(|text| match text.try_borrow() {
            // SAFETY: forwarded from the caller.
            Ok(text) => unsafe { copy_to_c_buffer(text.as_str(), buf, len) },
            // SAFETY: as above.
            Err(_) => unsafe { copy_to_c_buffer("", buf, len) },
        })
        // SAFETY: as above.
        .unwrap_or_else(|_| unsafe { copy_to_c_buffer("", buf, len) })
}

/// Runs a fallible entry point: catches panics, records the message of a failure for the
/// calling thread and returns the status.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Failure>) -> PrimmStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => PrimmStatus::Ok,
        Ok(Err(failure)) => {
            record_thread_error(&failure);
            failure.status()
        }
        Err(payload) => {
            record_thread_error(&PanicMessage(payload.as_ref()));
            PrimmStatus::Panic
        }
    }
}

/// Runs an infallible entry point with panics caught; `fallback` is returned after a panic.
pub(crate) fn guard_value<T>(fallback: T, body: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(value) => value,
        Err(payload) => {
            record_thread_error(&PanicMessage(payload.as_ref()));
            fallback
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_status_code_maps_back_to_its_status_and_has_a_message() {
        for (code, status) in PrimmStatus::ALL.iter().enumerate() {
            assert_eq!(*status as i32, code as i32);
            assert_eq!(PrimmStatus::from_code(code as i32), Some(*status));
            assert!(!status.message().to_bytes().is_empty());
        }
        assert_eq!(PrimmStatus::from_code(-1), None);
        assert_eq!(PrimmStatus::from_code(PrimmStatus::ALL.len() as i32), None);
    }

    #[test]
    fn a_panic_in_an_entry_point_becomes_the_panic_status_with_its_message() {
        let status = guard(|| panic!("deliberate test panic"));
        assert_eq!(status, PrimmStatus::Panic);
        let mut buf = [0 as c_char; 128];
        // SAFETY: `buf` holds 128 writable bytes.
        let len = unsafe { copy_thread_error(buf.as_mut_ptr(), buf.len()) };
        // SAFETY: `copy_thread_error` NUL-terminated the buffer.
        let text = unsafe { core::ffi::CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
        assert_eq!(text, "panic inside primm: deliberate test panic");
        assert_eq!(len, text.len());
        assert_eq!(guard_value(7, || -> i32 { panic!("again") }), 7);
    }
}
