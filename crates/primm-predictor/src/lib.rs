//! # primm-predictor: the learned PR mode on tract
//!
//! The PR mode of PR-IMM (paper, Section III-C) is a small Transformer that predicts an
//! object's next displacement from its last five radar measurements. This crate runs the ONNX
//! form of that model with tract and plugs it into `primm-core`'s tracker through the
//! [`DisplacementPredictor`] trait:
//!
//! * [`onnx::PrModel`] loads and checks a model and plans it for fixed batch sizes;
//!   [`native::NativeModel`] is primm's own fixed-size forward pass of the shipped
//!   architecture, which `PrModel` uses where the model has it and it agrees with tract;
//!   [`onnx::OnnxPredictor`] is the synchronous predictor (deterministic: offline tracking and
//!   evaluation use it).
//! * [`threaded::ThreadedPredictor`] runs any predictor on a dedicated inference thread with a
//!   per-frame deadline; the tracking thread allocates nothing (the real-time service uses it).
//! * [`split::SplitPredictor`] shares each frame's batch among several predictors;
//!   [`split::on_inference_threads`] runs the model on several inference threads at once.
//! * [`DEFAULT_MODEL_ONNX`] is the shipped model, `models/pr.onnx`, built into the binary, so
//!   nothing needs to be found on disk: [`predictor_for`] uses it unless a file is given.
//!
//! ```
//! use primm_core::config::Config;
//! use primm_core::measurement::{Frame, Measurement, ObjectClass};
//! use primm_core::mode::Method;
//! use primm_core::tracker::Tracker;
//! use primm_predictor::onnx::OnnxPredictor;
//!
//! let config = Config::default().with_modes(Method::PrImm.modes());
//! let mut tracker = Tracker::with_predictor(config, OnnxPredictor::embedded()?)?;
//! for k in 0..3 {
//!     let mut frame = Frame::new(0.05 * k as f64);
//!     frame.measurements.push(Measurement {
//!         x_m: 20.0 + 0.07 * k as f64,
//!         y_m: 1.5,
//!         radial_velocity_mps: 1.4,
//!         rcs_dbsm: -5.0,
//!         // `predictor.classes`: the model predicts pedestrians and two-wheelers by default.
//!         class: ObjectClass::Pedestrian,
//!         sensor_id: Some(0),
//!         ground_truth_id: None,
//!     });
//!     tracker.step(&frame)?;
//! }
//! assert!(tracker.predictor().stats().predictions > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod native;
pub mod onnx;
pub mod split;
pub mod threaded;

use onnx::{ModelError, OnnxPredictor};
use primm_config::InferenceEngine;
use primm_core::mode::Method;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use std::path::Path;

/// The shipped PR model (`models/pr.onnx`, written by `training/train.py` and described by
/// `models/pr.json`), embedded at build time.
pub const DEFAULT_MODEL_ONNX: &[u8] = include_bytes!("../../../models/pr.onnx");

/// The PR model from `model`, or the built-in [`DEFAULT_MODEL_ONNX`] when `model` is `None`,
/// running on `engine` where it can ([`onnx::PrModel::set_engine`]). Asking for the native
/// engine with a model that has no native forward pass logs a warning naming the reason and
/// runs the model on tract.
pub fn load_predictor(model: Option<&Path>, engine: InferenceEngine) -> Result<OnnxPredictor, ModelError> {
    let mut predictor = match model {
        Some(path) => OnnxPredictor::load(path)?,
        None => OnnxPredictor::embedded()?,
    };
    let used = predictor.set_engine(engine);
    if used != engine {
        let reason = predictor.model().native_unsupported().map(ToString::to_string).unwrap_or_default();
        tracing::warn!(model = %predictor.model().source(), %reason, "the PR model runs on tract: no native forward pass");
    }
    Ok(predictor)
}

/// The predictor a method needs: none for the physics-only methods; for PR and PR-IMM the PR
/// model from `model`, or the built-in [`DEFAULT_MODEL_ONNX`] when `model` is `None`, on
/// `engine` where it can ([`load_predictor`]), run synchronously so that offline results do not
/// depend on timing. A missing, unreadable or incompatible model file is an error naming the
/// file.
pub fn predictor_for(
    method: Method,
    model: Option<&Path>,
    engine: InferenceEngine,
) -> Result<Box<dyn DisplacementPredictor + Send>, ModelError> {
    if !method.needs_predictor() {
        return Ok(Box::new(NoPredictor));
    }
    Ok(Box::new(load_predictor(model, engine)?))
}
