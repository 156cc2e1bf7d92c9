//! # primm-predictor: the learned PR mode on tract
//!
//! The PR mode of PR-IMM (paper, Section III-C) is a small Transformer that predicts an
//! object's next displacement from its last five radar measurements. This crate runs the ONNX
//! form of that model with tract and plugs it into `primm-core`'s tracker through the
//! [`DisplacementPredictor`] trait:
//!
//! * [`onnx::PrModel`] loads and checks a model and plans it for fixed batch sizes;
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
//!         x_m: 20.0 + 0.5 * k as f64,
//!         y_m: 1.5,
//!         radial_velocity_mps: 10.0,
//!         rcs_dbsm: 8.0,
//!         class: ObjectClass::Car,
//!         sensor_id: Some(0),
//!         ground_truth_id: None,
//!     });
//!     tracker.step(&frame)?;
//! }
//! assert!(tracker.predictor().stats().predictions > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod onnx;
pub mod split;
pub mod threaded;

use onnx::{ModelError, OnnxPredictor};
use primm_core::mode::Method;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use std::path::Path;

/// The shipped PR model (`models/pr.onnx`, written by `training/train.py` and described by
/// `models/pr.json`), embedded at build time.
pub const DEFAULT_MODEL_ONNX: &[u8] = include_bytes!("../../../models/pr.onnx");

/// The predictor a method needs: none for the physics-only methods; for PR and PR-IMM the PR
/// model from `model`, or the built-in [`DEFAULT_MODEL_ONNX`] when `model` is `None`, run
/// synchronously so that offline results do not depend on timing. A missing, unreadable or
/// incompatible model file is an error naming the file.
pub fn predictor_for(
    method: Method,
    model: Option<&Path>,
) -> Result<Box<dyn DisplacementPredictor + Send>, ModelError> {
    if !method.needs_predictor() {
        return Ok(Box::new(NoPredictor));
    }
    let predictor = match model {
        Some(path) => OnnxPredictor::load(path)?,
        None => OnnxPredictor::embedded()?,
    };
    Ok(Box::new(predictor))
}
