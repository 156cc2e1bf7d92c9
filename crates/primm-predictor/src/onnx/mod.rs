//! The PR model (paper, Section III-C) run from its ONNX file, on tract or on primm's native
//! forward pass, one module per role:
//!
//! - [`contract`]: what a model file must be (inputs, outputs, shapes), the rotation of a
//!   request into the model's input axes ([`InputRotation`]), where a model comes from and the
//!   errors of loading and running one.
//! - [`tract_engine`]: tract's reading and checking of the file and its plans for fixed batch
//!   sizes ([`PLAN_BATCH_SIZES`]).
//! - [`native`](crate::native): primm's own fixed-size forward pass of the shipped architecture.
//! - [`engine_choice`]: which of the two runs the batches, after the probe at load that compares
//!   them ([`MAX_PROBE_DIFFERENCE_M`]).
//! - [`model`]: [`PrModel`], the loaded model that ties the engines together.
//! - [`predictor`]: [`OnnxPredictor`], the synchronous
//!   [`DisplacementPredictor`](primm_core::predictor::DisplacementPredictor) on top of it.
//!
//! Every public item of these modules is also reachable here, as `primm_predictor::onnx::NAME`.

pub mod contract;
pub mod engine_choice;
pub mod model;
pub mod predictor;
pub mod tract_engine;

pub use contract::{
    covariance_from_cholesky, InferenceError, InputFrame, InputRotation, ModelError, ModelSource,
    BATCH_SYMBOL, CHOLESKY_OUTPUT, CHOLESKY_VALUES, DISPLACEMENT_OUTPUT, FEATURES_INPUT, INPUT_FRAME_KEY,
    MIN_HEADING_DISTANCE_M, MIN_LINE_OF_SIGHT_DISTANCE_M, VALID_INPUT,
};
pub use engine_choice::MAX_PROBE_DIFFERENCE_M;
pub use model::PrModel;
pub use predictor::{OnnxPredictor, OnnxPredictorStats};
pub use tract_engine::PLAN_BATCH_SIZES;
