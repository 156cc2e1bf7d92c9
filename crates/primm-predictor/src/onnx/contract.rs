//! The contract between primm and a PR model file, and the rotation of a request into the
//! model's input axes.
//!
//! # Model contract
//!
//! The file written by `training/train.py` (documented in `models/pr.json`):
//!
//! | | name | shape | meaning |
//! |---|---|---|---|
//! | input 0 | `features` | `[batch, 5, 5]` f32 | `eq:pr_input` rows oldest first, rows `0..len` valid, rows `len..` zero |
//! | input 1 | `valid` | `[batch, 5]` f32 | 1 for rows `0..len`, 0 for padding |
//! | output 0 | `displacement` | `[batch, 2]` f32 | `[dx, dy]`, m, from the latest measurement to the prediction time |
//!
//! Feature normalisation is part of the graph. The batch axis must be symbolic and is bound to a
//! symbol named [`BATCH_SYMBOL`]; every other dimension must match exactly.
//!
//! # Input axes: aligned with the line of sight, or with the latest motion
//!
//! The model never sees absolute headings. Before a request goes in, its relative positions
//! are rotated into the model's input axes ([`InputRotation`]); the displacement that comes out
//! is rotated back. A model names its axes in the ONNX metadata entry [`INPUT_FRAME_KEY`]
//! ([`InputFrame`]):
//!
//! * `line_of_sight` (the shipped model): the x axis points along the latest measurement's
//!   line of sight, from the radar that took it ([`PredictionRequest::sensor_m`]) to the
//!   measured position, so that the latest radial velocity is the x component of the object's
//!   velocity. A measurement closer than [`MIN_LINE_OF_SIGHT_DISTANCE_M`] to its radar has no
//!   line of sight and goes in unrotated.
//! * `latest_motion` (models without the entry, trained before the line of sight): the x axis
//!   points along the latest motion, from the second-latest to the latest measurement. A
//!   history of one measurement, or whose last two measurements are closer than
//!   [`MIN_HEADING_DISTANCE_M`], goes in unrotated.
//!
//! The model is trained with windows without a direction in random orientations. So tracks in
//! the world frame, whose headings are arbitrary, and tracks in the vehicle frame are predicted
//! alike.

use glam::{DMat2, DVec2};
use primm_core::predictor::{PredictionRequest, MAX_HISTORY};
use std::fmt;
use std::path::PathBuf;
use tract_onnx::prelude::TractError;

/// Shortest distance between the last two measurements of a history that defines the direction
/// of its latest motion, m.
pub const MIN_HEADING_DISTANCE_M: f64 = 0.01;

/// Shortest distance from a radar to its measurement that defines a line of sight, m.
pub const MIN_LINE_OF_SIGHT_DISTANCE_M: f64 = 0.01;

/// The ONNX metadata entry (`metadata_props` key) in which a model names its [`InputFrame`].
pub const INPUT_FRAME_KEY: &str = "primm.input_frame";

/// The axes a model takes its input positions and gives its displacement in (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputFrame {
    /// x along the latest measurement's line of sight (metadata value `line_of_sight`).
    LineOfSight,
    /// x along the latest motion (metadata value `latest_motion`; also a model without the
    /// entry).
    LatestMotion,
}

impl InputFrame {
    /// The metadata value of this frame.
    pub fn name(self) -> &'static str {
        match self {
            InputFrame::LineOfSight => "line_of_sight",
            InputFrame::LatestMotion => "latest_motion",
        }
    }

    /// The frame a metadata value names, `None` for an unknown value.
    pub fn from_name(name: &str) -> Option<Self> {
        [InputFrame::LineOfSight, InputFrame::LatestMotion].into_iter().find(|frame| frame.name() == name)
    }
}

/// The rotation of a request into the model's input axes (see the module documentation):
/// `(x, y) ↦ (c·x + s·y, −s·x + c·y)` with `(c, s)` the unit direction of the axes' x axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputRotation {
    cos: f64,
    sin: f64,
}

impl InputRotation {
    /// No rotation.
    pub const IDENTITY: InputRotation = InputRotation { cos: 1.0, sin: 0.0 };

    /// The rotation of `request` into the axes of `frame`; [`IDENTITY`](Self::IDENTITY) where
    /// the request has no such direction.
    pub fn of(request: &PredictionRequest, frame: InputFrame) -> Self {
        match frame {
            InputFrame::LineOfSight => Self::onto_line_of_sight(request),
            InputFrame::LatestMotion => Self::onto_latest_motion(request),
        }
    }

    /// The rotation onto the latest measurement's line of sight, from its radar to the
    /// measured position; [`IDENTITY`](Self::IDENTITY) without one.
    pub fn onto_line_of_sight(request: &PredictionRequest) -> Self {
        Self::onto(request.anchor_m - request.sensor_m, MIN_LINE_OF_SIGHT_DISTANCE_M)
    }

    /// The rotation onto `request`'s latest motion; [`IDENTITY`](Self::IDENTITY) without one.
    pub fn onto_latest_motion(request: &PredictionRequest) -> Self {
        if request.len < 2 || request.len > MAX_HISTORY {
            return Self::IDENTITY;
        }
        // Positions are relative to the latest measurement, so the motion is minus the
        // second-latest row's position.
        let previous = request.features[request.len - 2];
        Self::onto(DVec2::new(-f64::from(previous[0]), -f64::from(previous[1])), MIN_HEADING_DISTANCE_M)
    }

    /// The rotation onto `direction`; [`IDENTITY`](Self::IDENTITY) if it is shorter than
    /// `min_length` or not finite.
    fn onto(direction: DVec2, min_length: f64) -> Self {
        let length = direction.length();
        if !(length >= min_length && length.is_finite()) {
            return Self::IDENTITY;
        }
        InputRotation { cos: direction.x / length, sin: direction.y / length }
    }

    /// A position or displacement in the model's axes.
    pub fn to_model(&self, vector: DVec2) -> DVec2 {
        DVec2::new(self.cos * vector.x + self.sin * vector.y, -self.sin * vector.x + self.cos * vector.y)
    }

    /// A displacement from the model's axes back into the request's frame.
    pub fn from_model(&self, vector: DVec2) -> DVec2 {
        DVec2::new(self.cos * vector.x - self.sin * vector.y, self.sin * vector.x + self.cos * vector.y)
    }

    /// A covariance from the model's axes back into the request's frame: `R Σ Rᵀ` with `R` the
    /// rotation of [`from_model`](Self::from_model).
    pub fn covariance_from_model(&self, covariance: DMat2) -> DMat2 {
        let rotation = DMat2::from_cols(DVec2::new(self.cos, self.sin), DVec2::new(-self.sin, self.cos));
        rotation * covariance * rotation.transpose()
    }
}

/// The covariance `L Lᵀ` of a model's Cholesky output `[l_xx, l_yx, l_yy]` (lower triangular,
/// m), in the model's axes.
pub fn covariance_from_cholesky(factor: [f32; 3]) -> DMat2 {
    let [l_xx, l_yx, l_yy] = factor.map(f64::from);
    let lower = DMat2::from_cols(DVec2::new(l_xx, l_yx), DVec2::new(0.0, l_yy));
    lower * lower.transpose()
}

/// Name of the model's first input.
pub const FEATURES_INPUT: &str = "features";
/// Name of the model's second input.
pub const VALID_INPUT: &str = "valid";
/// Name of the model's output.
pub const DISPLACEMENT_OUTPUT: &str = "displacement";
/// Name of the model's optional second output, the Cholesky factor of the displacement's
/// error covariance.
pub const CHOLESKY_OUTPUT: &str = "displacement_cholesky";
/// Values per row of [`CHOLESKY_OUTPUT`]: `[l_xx, l_yx, l_yy]`.
pub const CHOLESKY_VALUES: usize = 3;
/// Name of the symbolic batch dimension (the ONNX `dim_param` of the exported model).
pub const BATCH_SYMBOL: &str = "batch";

/// Where a PR model comes from: a file, or the default model built into the binary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ModelSource {
    /// An ONNX file.
    File(PathBuf),
    /// The default model, `models/pr.onnx`, embedded at build time ([`crate::DEFAULT_MODEL_ONNX`]).
    Embedded,
}

impl fmt::Display for ModelSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelSource::File(path) => write!(f, "{}", path.display()),
            ModelSource::Embedded => f.write_str("models/pr.onnx (built in)"),
        }
    }
}

/// Why a PR model could not be loaded. Every variant names the model's source.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file does not exist.
    #[error("PR model {path}: file not found")]
    NotFound {
        /// The model file.
        path: PathBuf,
    },
    /// The file exists but could not be read.
    #[error("PR model {path}: cannot read the file: {source}")]
    Unreadable {
        /// The model file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not an ONNX model tract can parse (e.g. truncated or not ONNX at all).
    #[error("PR model {model}: not a valid ONNX model: {reason}")]
    NotOnnx {
        /// The model.
        model: ModelSource,
        /// tract's description of the problem.
        reason: String,
    },
    /// The model's inputs are not `features` and `valid` (in this order), or its outputs are
    /// not `displacement`, optionally followed by `displacement_cholesky`.
    #[error("PR model {model}: expected {expected}, found {found}")]
    Signature {
        /// The model.
        model: ModelSource,
        /// What the model should have.
        expected: String,
        /// What it has.
        found: String,
    },
    /// An input or output has the wrong element type or shape.
    #[error("PR model {model}: `{name}` has {found}, expected {expected}")]
    Shape {
        /// The model.
        model: ModelSource,
        /// The input or output.
        name: String,
        /// The required type and shape.
        expected: String,
        /// The declared or inferred type and shape.
        found: String,
    },
    /// The model's [`INPUT_FRAME_KEY`] metadata entry names no [`InputFrame`].
    #[error("PR model {model}: metadata entry {INPUT_FRAME_KEY} = `{value}` names no input frame (expected `line_of_sight` or `latest_motion`)")]
    InputFrame {
        /// The model.
        model: ModelSource,
        /// The entry's value.
        value: String,
    },
    /// tract could not type the graph for a symbolic batch or optimise and plan it for the sizes
    /// of [`PLAN_BATCH_SIZES`](super::PLAN_BATCH_SIZES), or a trial run with one sample failed.
    #[error("PR model {model}: cannot be prepared for inference: {reason}")]
    Preparation {
        /// The model.
        model: ModelSource,
        /// tract's description of the problem.
        reason: String,
    },
}

/// A failed inference run (the model itself loaded fine).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InferenceError {
    /// The feature, validity and output buffers do not describe the same batch size.
    #[error(
        "PR inference failed: inconsistent buffers: {features} feature values, {valid} valid values, {outputs} output values"
    )]
    InconsistentBuffers {
        /// Number of feature values given.
        features: usize,
        /// Number of validity values given.
        valid: usize,
        /// Number of output slots given.
        outputs: usize,
    },
    /// tract failed to build an input tensor or to run the plan.
    #[error("PR inference failed: {reason}")]
    Runtime {
        /// tract's description of the problem.
        reason: String,
    },
    /// The model returned no output tensor.
    #[error("PR inference failed: the model returned no output")]
    NoOutput,
    /// The output tensor does not have the shape `[batch, 2]`.
    #[error("PR inference failed: output shape {found:?}, expected [{batch}, 2]")]
    OutputShape {
        /// The shape the model returned.
        found: Vec<usize>,
        /// The batch size of the run.
        batch: usize,
    },
    /// The covariance output is missing or does not have the shape `[batch, 3]`.
    #[error("PR inference failed: covariance output shape {found:?}, expected [{batch}, 3]")]
    CholeskyShape {
        /// The shape the model returned (empty when the output is missing).
        found: Vec<usize>,
        /// The batch size of the run.
        batch: usize,
    },
}

impl From<TractError> for InferenceError {
    fn from(error: TractError) -> Self {
        InferenceError::Runtime { reason: format!("{error:#}") }
    }
}
