//! # primm-ffi: the C API of the primm tracker
//!
//! A C program (or anything that speaks the C ABI) runs the PR-IMM tracker through an opaque
//! handle. The header is `include/primm.h`, generated from this crate by cbindgen
//! (`cbindgen --config crates/primm-ffi/cbindgen.toml --crate primm-ffi --output
//! include/primm.h`; a test fails when the committed header is stale). The library is built
//! as a static library, a shared library and an rlib:
//!
//! ```text
//! cargo build --release -p primm-ffi
//! cc -O2 -Iinclude examples/c/track_csv.c target/release/libprimm_ffi.a -lpthread -ldl -lm -o track_csv
//! ./track_csv measurements.csv tracks.csv
//! ```
//!
//! `examples/c/track_csv.c` reads a measurement CSV file (`docs/scenario.md`) and writes the
//! same track CSV file as `primm track --method imm`, byte for byte. The static library links
//! with a non-executable stack and no linker warning: the workspace's `.cargo/config.toml`
//! has the assembler mark tract's assembly objects (a test checks the linked example with
//! `readelf -lW`).
//!
//! C++ programs include `include/primm.hpp`, a header-only C++17 wrapper (a move-only tracker,
//! exceptions for errors, views over caller buffers); `examples/cpp/track_csv.cpp` is the same
//! example in C++. `tools/install_c_api.sh PREFIX` installs the headers, both libraries, a CMake
//! package (`find_package(primm)`, target `primm::primm`) and pkg-config files; build lines
//! for C and C++, static and shared, are in `docs/integrating-c-cpp.md`.
//!
//! ## The calls
//!
//! * [`primm_tracker_create`] builds a tracker from [`PrimmTrackerOptions`] (NULL for the
//!   defaults): configuration TOML text, method (`PRIMM_METHOD_*`), ONNX model bytes or the
//!   built-in model, and whether the PR model runs on an inference thread.
//! * [`primm_tracker_step`] tracks one frame of [`PrimmMeasurement`]s read in place from
//!   caller memory and optionally fills a [`PrimmStepSummary`]. It allocates nothing (except
//!   inside tract when the PR model runs in the step): the tracks go to a buffer allocated
//!   with the handle.
//! * [`primm_tracker_tracks`] copies the last step's tracks ([`PrimmTrack`]) to a caller
//!   buffer; [`primm_tracker_stats`] the counters ([`PrimmStats`]); [`primm_tracker_reset`]
//!   drops every track; [`primm_tracker_destroy`] releases the handle.
//! * Every fallible call returns a [`PrimmStatus`]. [`primm_status_message`] describes a code;
//!   [`primm_last_error_message`] (per thread) and [`primm_tracker_last_error`] (per tracker)
//!   give the detailed message of the last failure: the configuration key, the model problem,
//!   the frame fault.
//! * [`primm_format_f64`] formats a double as primm's CSV files do (Rust's `{}`),
//!   [`primm_object_class_name`] and [`primm_object_class_from_name`] map class codes and names.
//!
//! ## Versions and the ABI
//!
//! * [`primm_version`] is the release version of primm (the workspace's package version,
//!   `MAJOR.MINOR.PATCH`). It names a release; it says nothing about binary compatibility.
//! * [`PRIMM_ABI_VERSION`] (a `#define` in `include/primm.h`) and [`primm_abi_version`] (what
//!   the linked library was built with) number the binary interface. It is raised by one for
//!   every change that can break a program compiled against the previous header: a field of a
//!   `#[repr(C)]` struct added, removed, reordered or retyped (so a size or offset changes); a
//!   function removed, renamed or given another signature; a constant, status code or code
//!   value given another meaning. Adding a new function, or a new status code or constant at
//!   the end of its range, keeps the ABI version: a program built against the older header
//!   never sees the new ones (every function returns only the statuses its documentation
//!   lists, plus the new ones a new function documents).
//! * The shared library carries the ABI version in its name on Linux: its soname is
//!   `libprimm_ffi.so.ABI` (set by this crate's build script), so the dynamic loader refuses a
//!   library of another ABI version instead of running with mismatched layouts.
//! * A program linked statically, or loading the library by hand, compares
//!   `primm_abi_version()` with `PRIMM_ABI_VERSION` at start-up and refuses to run when they
//!   differ (`include/primm.hpp` does it when the first tracker is created).
//!
//! ## Safety rules for callers
//!
//! * Pointers are NULL or valid for the documented number of elements, aligned, and not
//!   overlapping the library's own buffers. A NULL where one is required gives
//!   `PRIMM_STATUS_NULL_ARGUMENT`; a dangling pointer is undefined behaviour.
//! * Inputs (configuration text, model bytes, measurements) are only read during the call;
//!   outputs are written only into caller buffers. Strings returned by `primm_status_message`
//!   and `primm_object_class_name` are static.
//! * A tracker may move between threads but must not be used by two threads at once. Error
//!   messages are kept per thread and per tracker.
//! * A panic never unwinds into the caller: it becomes `PRIMM_STATUS_PANIC`, and the tracker it
//!   happened on is poisoned (every later call returns `PRIMM_STATUS_POISONED`; destroy it).
//! * Each handle is destroyed exactly once, and not used afterwards.
//!
//! ## From Rust
//!
//! The functions are ordinary `unsafe extern "C"` functions of this crate:
//!
//! ```
//! use primm_ffi::*;
//! use std::ffi::CStr;
//!
//! let mut options = primm_tracker_options_default();
//! options.method = PRIMM_METHOD_IMM; // CV + CA + CT: no PR model needed
//! let mut tracker = std::ptr::null_mut();
//! // SAFETY: `options` and `tracker` are valid for the call.
//! let status = unsafe { primm_tracker_create(&options, &mut tracker) };
//! assert_eq!(status, PrimmStatus::Ok);
//!
//! let mut tracks = vec![std::mem::MaybeUninit::<PrimmTrack>::uninit(); PRIMM_MAX_TRACKS];
//! for k in 0..3 {
//!     let frame = [PrimmMeasurement {
//!         x_m: 20.0 + 0.5 * k as f64,
//!         y_m: 1.5,
//!         radial_velocity_mps: 10.0,
//!         rcs_dbsm: 8.0,
//!         ground_truth_id: 7,
//!         sensor_id: PRIMM_NO_SENSOR_ID,
//!         class_code: PRIMM_OBJECT_CLASS_CAR,
//!     }];
//!     let mut summary = PrimmStepSummary::default();
//!     // SAFETY: a live tracker, one readable measurement, a writable summary.
//!     let status = unsafe { primm_tracker_step(tracker, 0.05 * k as f64, frame.as_ptr(), 1, &mut summary) };
//!     assert_eq!(status, PrimmStatus::Ok);
//!     assert_eq!(summary.updated_track_count, 1);
//! }
//! let mut count = 0;
//! // SAFETY: `tracks` holds PRIMM_MAX_TRACKS writable entries.
//! let status = unsafe { primm_tracker_tracks(tracker, tracks[0].as_mut_ptr(), tracks.len(), &mut count) };
//! assert_eq!((status, count), (PrimmStatus::Ok, 1));
//! // SAFETY: the call initialised the first `count` entries.
//! let track = unsafe { tracks[0].assume_init() };
//! assert_eq!((track.hits, track.ground_truth_id), (3, 7));
//!
//! // A frame that does not advance in time is rejected; the message says why.
//! // SAFETY: a live tracker; no measurements.
//! let status = unsafe { primm_tracker_step(tracker, 0.0, std::ptr::null(), 0, std::ptr::null_mut()) };
//! assert_eq!(status, PrimmStatus::InvalidFrame);
//! let mut message = [0 as std::ffi::c_char; 256];
//! // SAFETY: a live tracker; `message` holds 256 writable bytes.
//! unsafe { primm_tracker_last_error(tracker, message.as_mut_ptr(), message.len()) };
//! // SAFETY: NUL-terminated by the call.
//! let message = unsafe { CStr::from_ptr(message.as_ptr()) }.to_str()?;
//! assert!(message.contains("does not advance"), "{message}");
//!
//! // SAFETY: a live tracker, destroyed once and not used afterwards.
//! unsafe { primm_tracker_destroy(tracker) };
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod helpers;
mod platform;
mod sensor_estimates;
mod status;
mod text;
mod tracker;
mod types;
mod version;

pub use helpers::{
    primm_format_f64, primm_last_error_message, primm_object_class_from_name, primm_object_class_name,
    primm_status_message,
};
pub use platform::{primm_tracker_platform, PrimmPlatformEstimate};
pub use sensor_estimates::{
    primm_tracker_sensor_estimates, primm_tracker_sensor_points_evidence, PrimmSensorEstimates,
    PrimmSensorPointsEvidence, PRIMM_UNMOUNTED_SENSOR,
};
pub use status::PrimmStatus;
pub use tracker::{
    primm_tracker_create, primm_tracker_destroy, primm_tracker_last_error, primm_tracker_newest_timestamp,
    primm_tracker_options_default, primm_tracker_predict_to, primm_tracker_reset, primm_tracker_stats,
    primm_tracker_step, primm_tracker_step_with_pose, primm_tracker_tracks, PrimmTracker,
};
pub use types::*;
pub use version::{primm_abi_version, primm_version, PRIMM_ABI_VERSION};
