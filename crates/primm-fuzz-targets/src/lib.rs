//! # primm-fuzz-targets: what each fuzz target does with its input
//!
//! One function per input surface of primm, each taking the raw bytes a fuzzer produces and
//! panicking only when primm misbehaves (a panic inside primm, or a broken tracker invariant
//! after a step). The cargo-fuzz crate in `fuzz/` calls them under libFuzzer; the test suite
//! (`tests/corpus_replay.rs` of this crate) calls them on stable on every committed corpus file,
//! so that every input that ever crashed stays fixed.
//!
//! | target | input | surface |
//! |---|---|---|
//! | [`measurement_csv::run`] | bytes of a measurement CSV file | `primm_sim::io` reader, then tracking |
//! | [`tracker_steps::run`] | a frame sequence built with `arbitrary` | IMM and PR-IMM steps |
//! | [`measurement_frame_bytes::run`] | raw `MeasurementFrame` images | the service's frame path |
//! | [`config_toml::run`] | bytes of a TOML file | `primm_config`, `Config::validate`, tracker |
//! | [`ego_pose_frames::run`] | frames with ego poses (driving, jumps, yaw wrapping, raw values) | the service's frame path in the world frame |
//! | `onnx_model_bytes::run` | bytes of an ONNX file | `PrModel::from_bytes`, a prediction |
//! | `c_api_calls::run` | sequences of C API calls with their buffers and sizes | `primm-ffi` against a core mirror |
//!
//! The ONNX and C API targets need tract (primm-ffi links the PR model), whose instrumented
//! build is the bulk of the fuzz build's time; they sit behind the `onnx` and `c_api` features
//! (on by default, so the test suite replays their corpora), and the fuzz crate builds them only
//! with `--features onnx` or `--features c_api`.

#[cfg(feature = "c_api")]
pub mod c_api_calls;
pub mod config_toml;
pub mod ego_pose_frames;
pub mod extrapolating_predictor;
pub mod invariant_check;
pub mod measurement_csv;
pub mod measurement_frame_bytes;
#[cfg(feature = "onnx")]
pub mod onnx_model_bytes;
pub mod scripted_predictor;
pub mod tracker_steps;

/// A fuzz target: a function of the fuzzer's bytes that panics only on a defect.
pub type Target = fn(&[u8]);

/// Every target with its name, which is also the name of its corpus directory
/// (`fuzz/corpus/NAME/`) and of its cargo-fuzz binary.
pub const TARGETS: &[(&str, Target)] = &[
    ("measurement_csv", measurement_csv::run),
    ("tracker_steps", tracker_steps::run),
    ("measurement_frame_bytes", measurement_frame_bytes::run),
    ("config_toml", config_toml::run),
    ("ego_pose_frames", ego_pose_frames::run),
    #[cfg(feature = "onnx")]
    ("onnx_model_bytes", onnx_model_bytes::run),
    #[cfg(feature = "c_api")]
    ("c_api_calls", c_api_calls::run),
];
