//! The PR model (paper, Section III-C) executed with tract from its ONNX file.
//!
//! [`PrModel`] loads and checks the model with a symbolic batch dimension, then optimises one
//! plan per batch size of [`PLAN_BATCH_SIZES`] and runs batches of any size through them: full
//! chunks of the largest size, the rest padded up to the next planned size. tract runs a plan
//! whose batch is a constant in about a quarter less time than the same graph with a symbolic
//! batch (it then fuses more operations into the matrix products and fixes shapes and packing
//! when the plan is made), which is more than padding to the next size costs (`docs/BENCHMARKS.md`). [`OnnxPredictor`] is a synchronous
//! [`DisplacementPredictor`] on top of it: `submit` runs the batch at once, `collect` hands the
//! results out. It is deterministic (no clock, no thread), which is what offline tracking and
//! evaluation want; [`ThreadedPredictor`](crate::threaded::ThreadedPredictor) moves it onto an
//! inference thread for real-time use.
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
//! # Input frame: aligned with the latest motion
//!
//! The model never sees absolute headings. Before a request goes in, its relative positions
//! are rotated into the frame whose x axis points along the latest motion, from the
//! second-latest to the latest measurement ([`MotionFrame`]); the displacement that comes out is
//! rotated back. A history of one measurement, or whose last two measurements are closer than
//! [`MIN_HEADING_DISTANCE_M`], has no such direction and goes in unrotated (the model is trained
//! with such windows in random orientations). So tracks in the world frame, whose headings are
//! arbitrary, and tracks in the vehicle frame are predicted alike.
//!
//! # From model output to the tracker's displacement
//!
//! The model answers `f(t)`: the displacement from a track's latest measurement to time `t`. The
//! tracker needs the displacement over its step `[step_start_s, prediction_time_s]` (see the
//! [`primm_core::predictor`] documentation): `f(t_k)` when the track was measured in the previous frame,
//! `f(t_k) − f(t_{k−1})` otherwise. [`OnnxPredictor`] evaluates both rows in the same batch, so a
//! frame in which `n` of `N` tracks coasted runs a batch of `N + n` rows.

use crate::native::{NativeModel, Unsupported};
use glam::{DMat2, DVec2};
use primm_core::config::InferenceEngine;
use primm_core::limits::MAX_TRACKS;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest, FEATURES, MAX_HISTORY};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tract_onnx::prelude::*;
use tract_onnx::tract_hir::infer::GenericFactoid;

/// Shortest distance between the last two measurements of a history that defines the direction
/// of its latest motion, m.
pub const MIN_HEADING_DISTANCE_M: f64 = 0.01;

/// The rotation of a request into the model's input frame (see the module documentation):
/// `(x, y) ↦ (c·x + s·y, −s·x + c·y)` with `(c, s)` the unit direction of the latest motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionFrame {
    cos: f64,
    sin: f64,
}

impl MotionFrame {
    /// No rotation.
    pub const IDENTITY: MotionFrame = MotionFrame { cos: 1.0, sin: 0.0 };

    /// The frame of `request`'s latest motion; [`IDENTITY`](Self::IDENTITY) without one.
    pub fn of(request: &PredictionRequest) -> Self {
        if request.len < 2 || request.len > MAX_HISTORY {
            return Self::IDENTITY;
        }
        // Positions are relative to the latest measurement, so the motion is minus the
        // second-latest row's position.
        let previous = request.features[request.len - 2];
        let motion = DVec2::new(-f64::from(previous[0]), -f64::from(previous[1]));
        let length = motion.length();
        if !(length >= MIN_HEADING_DISTANCE_M && length.is_finite()) {
            return Self::IDENTITY;
        }
        MotionFrame { cos: motion.x / length, sin: motion.y / length }
    }

    /// A position or displacement in the model's frame.
    pub fn to_model(&self, vector: DVec2) -> DVec2 {
        DVec2::new(self.cos * vector.x + self.sin * vector.y, -self.sin * vector.x + self.cos * vector.y)
    }

    /// A displacement from the model's frame back into the request's frame.
    pub fn from_model(&self, vector: DVec2) -> DVec2 {
        DVec2::new(self.cos * vector.x - self.sin * vector.y, self.sin * vector.x + self.cos * vector.y)
    }

    /// A covariance from the model's frame back into the request's frame: `R Σ Rᵀ` with `R` the
    /// rotation of [`from_model`](Self::from_model).
    pub fn covariance_from_model(&self, covariance: DMat2) -> DMat2 {
        let rotation = DMat2::from_cols(DVec2::new(self.cos, self.sin), DVec2::new(-self.sin, self.cos));
        rotation * covariance * rotation.transpose()
    }
}

/// The covariance `L Lᵀ` of a model's Cholesky output `[l_xx, l_yx, l_yy]` (lower triangular,
/// m), in the model's frame.
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
    /// tract could not type the graph for a symbolic batch or optimise and plan it for the sizes
    /// of [`PLAN_BATCH_SIZES`], or a trial run with one sample failed.
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

/// The batch sizes [`PrModel`] plans for, ascending. A batch runs as chunks of the largest size,
/// and the rest is padded with empty rows up to the next size on this list: at most 7 padded
/// rows above 8, whose cost (~14 µs each) stays below what a fixed-size plan saves (about a
/// quarter of the run).
pub const PLAN_BATCH_SIZES: [usize; 11] = [1, 2, 4, 8, 16, 24, 32, 40, 48, 56, 64];

/// One optimised plan for a fixed batch size, with its execution state.
struct BatchPlan {
    batch: usize,
    plan: Arc<TypedRunnableModel>,
    state: TypedSimpleState,
}

/// Largest difference, in any output value, between [`NativeModel`] and tract on the probe
/// inputs that a model may show and still run natively, m. float32 rounding in the two
/// summation orders gives ~1e-6 m on the shipped model.
pub const MAX_PROBE_DIFFERENCE_M: f32 = 1e-4;

/// The loaded, optimised PR model: one plan per size of [`PLAN_BATCH_SIZES`] and, where the
/// model has the shipped architecture and agrees with tract on probe inputs, its
/// [`NativeModel`].
pub struct PrModel {
    source: ModelSource,
    /// Whether the model has the [`CHOLESKY_OUTPUT`].
    has_uncertainty: bool,
    /// Ascending batch sizes, as [`PLAN_BATCH_SIZES`].
    plans: Vec<BatchPlan>,
    /// The native forward pass, or why the model cannot have one.
    native: Result<Arc<NativeModel>, Unsupported>,
    /// The engine batches run on.
    engine: InferenceEngine,
}

impl fmt::Debug for PrModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PrModel")
            .field("source", &self.source)
            .field("batch_sizes", &self.plans.iter().map(|p| p.batch).collect::<Vec<_>>())
            .field("nodes", &self.plans.last().map(|p| p.plan.model().nodes().len()))
            .field("engine", &self.engine)
            .field("native", &self.native.as_ref().map(|_| ()))
            .finish()
    }
}

impl PrModel {
    /// Loads `path`, checks its signature against the [model contract](self), binds the batch
    /// axis to the symbol [`BATCH_SYMBOL`], then optimises and plans the graph once for each
    /// size of [`PLAN_BATCH_SIZES`] and runs one trial sample. All the work of preparing the
    /// model happens here, once.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, ModelError> {
        let path = path.as_ref().to_path_buf();
        match std::fs::metadata(&path) {
            Ok(meta) if meta.is_file() => {}
            Ok(_) => {
                let source = std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file");
                return Err(ModelError::Unreadable { path, source });
            }
            Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
                return Err(ModelError::NotFound { path })
            }
            Err(source) => return Err(ModelError::Unreadable { path, source }),
        }
        let bytes =
            std::fs::read(&path).map_err(|source| ModelError::Unreadable { path: path.clone(), source })?;
        Self::from_bytes(&bytes, ModelSource::File(path))
    }

    /// The default model built into the binary ([`crate::DEFAULT_MODEL_ONNX`]), prepared as
    /// [`load`](Self::load) prepares a file.
    pub fn embedded() -> Result<Self, ModelError> {
        Self::from_bytes(crate::DEFAULT_MODEL_ONNX, ModelSource::Embedded)
    }

    /// Prepares a model from the bytes of an ONNX file, as [`load`](Self::load) does;
    /// `source` names it in errors.
    ///
    /// tract itself may panic on some malformed files (fuzzing found a graph output naming a
    /// tensor no node produces); such a panic is caught and reported as
    /// [`ModelError::NotOnnx`], so a bad model file is always an error, never a crash.
    pub fn from_bytes(bytes: &[u8], source: ModelSource) -> Result<Self, ModelError> {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| Self::prepare(bytes, source.clone())))
            .unwrap_or_else(|panic| {
                let message = panic
                    .downcast_ref::<&str>()
                    .map(|text| text.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "no message".to_string());
                Err(ModelError::NotOnnx {
                    model: source,
                    reason: format!("tract panicked reading it: {message}"),
                })
            })
    }

    fn prepare(bytes: &[u8], source: ModelSource) -> Result<Self, ModelError> {
        let onnx = tract_onnx::onnx();
        let not_onnx =
            |error: TractError| ModelError::NotOnnx { model: source.clone(), reason: format!("{error:#}") };
        let proto = onnx.proto_model_for_read(&mut &bytes[..]).map_err(not_onnx)?;
        let mut model = onnx.model_for_proto_model(&proto).map_err(not_onnx)?;
        let has_uncertainty = check_signature(&source, &model)?;
        let batch = model.symbols.sym(BATCH_SYMBOL).to_dim();
        let prepare = |error: TractError| ModelError::Preparation {
            model: source.clone(),
            reason: format!("{error:#}"),
        };
        model
            .set_input_fact(0, f32::fact([batch.clone(), MAX_HISTORY.to_dim(), FEATURES.to_dim()]).into())
            .map_err(prepare)?;
        model.set_input_fact(1, f32::fact([batch, MAX_HISTORY.to_dim()]).into()).map_err(prepare)?;
        let typed = model.into_typed().map_err(prepare)?;
        check_output(&source, &typed, 0, DISPLACEMENT_OUTPUT, 2)?;
        if has_uncertainty {
            check_output(&source, &typed, 1, CHOLESKY_OUTPUT, CHOLESKY_VALUES)?;
        }
        let symbol = typed.symbols.sym(BATCH_SYMBOL);
        let mut plans = Vec::with_capacity(PLAN_BATCH_SIZES.len());
        for batch in PLAN_BATCH_SIZES {
            let values = std::collections::HashMap::from([(symbol.clone(), (batch as i64).to_dim())]);
            let plan = typed
                .clone()
                .set_symbols(&values)
                .and_then(|fixed| fixed.into_optimized())
                .and_then(|optimized| optimized.into_runnable())
                .map_err(prepare)?;
            let state = plan.spawn().map_err(prepare)?;
            plans.push(BatchPlan { batch, plan, state });
        }
        let native = NativeModel::from_proto(&proto, has_uncertainty).map(Arc::new);
        let mut loaded = PrModel { source, has_uncertainty, plans, native, engine: InferenceEngine::Tract };
        // A trial run: a model that loads but cannot run fails here, at start-up.
        let mut out = [0.0f32; 2];
        let mut factor = [0.0f32; CHOLESKY_VALUES];
        let mut features = [0.0f32; MAX_HISTORY * FEATURES];
        features[4] = -0.05;
        let mut valid = [0.0f32; MAX_HISTORY];
        valid[0] = 1.0;
        let trial = if has_uncertainty {
            loaded.run_with_uncertainty(&features, &valid, &mut out, &mut factor)
        } else {
            loaded.run(&features, &valid, &mut out)
        };
        trial.map_err(|error| ModelError::Preparation {
            model: loaded.source.clone(),
            reason: error.to_string(),
        })?;
        if let Ok(native) = loaded.native.clone() {
            let difference = loaded.probe_difference(&native).map_err(|error| ModelError::Preparation {
                model: loaded.source.clone(),
                reason: error.to_string(),
            })?;
            if difference > MAX_PROBE_DIFFERENCE_M {
                loaded.native = Err(Unsupported::Disagrees {
                    difference_m: difference,
                    tolerance_m: MAX_PROBE_DIFFERENCE_M,
                });
            }
        }
        loaded.set_engine(InferenceEngine::Native);
        Ok(loaded)
    }

    /// The largest difference between tract's and `native`'s outputs on the probe batch
    /// ([`probe_batch`]), m; infinite where either answer is not finite.
    fn probe_difference(&mut self, native: &NativeModel) -> Result<f32, InferenceError> {
        let (features, valid) = probe_batch();
        let rows = valid.len() / MAX_HISTORY;
        let (mut tract_out, mut native_out) = (vec![0.0f32; rows * 2], vec![0.0f32; rows * 2]);
        let (mut tract_factor, mut native_factor) =
            (vec![0.0f32; rows * CHOLESKY_VALUES], vec![0.0f32; rows * CHOLESKY_VALUES]);
        self.engine = InferenceEngine::Tract;
        let cholesky = self.has_uncertainty.then_some(&mut tract_factor[..]);
        self.run_outputs(&features, &valid, &mut tract_out, cholesky)?;
        native.run(
            &features,
            &valid,
            &mut native_out,
            self.has_uncertainty.then_some(&mut native_factor[..]),
        );
        Ok(tract_out
            .iter()
            .zip(&native_out)
            .chain(tract_factor.iter().zip(&native_factor))
            .map(|(a, b)| if a.is_finite() && b.is_finite() { (a - b).abs() } else { f32::INFINITY })
            .fold(0.0f32, f32::max))
    }

    /// Chooses the engine batches run on and returns the one in use: [`Native`] where the
    /// model has a native forward pass ([`native_unsupported`](Self::native_unsupported) says
    /// why not otherwise), else [`Tract`]. A loaded model starts on [`Native`] where it can.
    ///
    /// [`Native`]: InferenceEngine::Native
    /// [`Tract`]: InferenceEngine::Tract
    pub fn set_engine(&mut self, engine: InferenceEngine) -> InferenceEngine {
        self.engine = match engine {
            InferenceEngine::Native if self.native.is_ok() => InferenceEngine::Native,
            _ => InferenceEngine::Tract,
        };
        self.engine
    }

    /// The engine batches run on.
    pub fn engine(&self) -> InferenceEngine {
        self.engine
    }

    /// Why this model has no native forward pass; `None` where it has one.
    pub fn native_unsupported(&self) -> Option<&Unsupported> {
        self.native.as_ref().err()
    }

    /// Another instance of this model that shares its optimised plans and has its own
    /// execution states, for running batches on another thread at the same time. Nothing is
    /// parsed or optimised again: only tract's per-plan state is built.
    pub fn fork(&self) -> Result<Self, ModelError> {
        let mut plans = Vec::with_capacity(self.plans.len());
        for plan in &self.plans {
            let state = plan.plan.spawn().map_err(|error| ModelError::Preparation {
                model: self.source.clone(),
                reason: format!("{error:#}"),
            })?;
            plans.push(BatchPlan { batch: plan.batch, plan: Arc::clone(&plan.plan), state });
        }
        Ok(PrModel {
            source: self.source.clone(),
            has_uncertainty: self.has_uncertainty,
            plans,
            native: self.native.clone(),
            engine: self.engine,
        })
    }

    /// Where the model came from.
    pub fn source(&self) -> &ModelSource {
        &self.source
    }

    /// Whether the model also estimates the covariance of its displacements
    /// ([`CHOLESKY_OUTPUT`]).
    pub fn has_uncertainty(&self) -> bool {
        self.has_uncertainty
    }

    /// Runs one batch: `features` holds `batch × 5 × 5` values (row-major, the layout of
    /// [`PredictionRequest::features`]), `valid` `batch × 5` and `displacements` receives
    /// `batch × 2` values `[dx, dy]` in metres. A batch of zero rows does nothing.
    pub fn run(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
    ) -> Result<(), InferenceError> {
        self.run_outputs(features, valid, displacements, None)
    }

    /// [`run`](Self::run), also writing the covariance output: `cholesky` receives `batch × 3`
    /// values `[l_xx, l_yx, l_yy]` in metres (see [`covariance_from_cholesky`]). Fails with
    /// [`InferenceError::CholeskyShape`] on a model without that output.
    pub fn run_with_uncertainty(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        cholesky: &mut [f32],
    ) -> Result<(), InferenceError> {
        self.run_outputs(features, valid, displacements, Some(cholesky))
    }

    fn run_outputs(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        mut cholesky: Option<&mut [f32]>,
    ) -> Result<(), InferenceError> {
        let batch = valid.len() / MAX_HISTORY;
        let cholesky_ok = cholesky.as_ref().is_none_or(|values| values.len() == batch * CHOLESKY_VALUES);
        if valid.len() != batch * MAX_HISTORY
            || features.len() != batch * MAX_HISTORY * FEATURES
            || displacements.len() != batch * 2
            || !cholesky_ok
        {
            return Err(InferenceError::InconsistentBuffers {
                features: features.len(),
                valid: valid.len(),
                outputs: displacements.len(),
            });
        }
        if batch == 0 {
            return Ok(());
        }
        if let (InferenceEngine::Native, Ok(native)) = (self.engine, &self.native) {
            if cholesky.is_some() && !native.has_uncertainty() {
                return Err(InferenceError::CholeskyShape { found: Vec::new(), batch });
            }
            native.run(features, valid, displacements, cholesky);
            return Ok(());
        }
        let mut done = 0;
        while done < batch {
            let rows = self.run_chunk(
                &features[done * MAX_HISTORY * FEATURES..],
                &valid[done * MAX_HISTORY..],
                &mut displacements[done * 2..],
                cholesky.as_deref_mut().map(|values| &mut values[done * CHOLESKY_VALUES..]),
            )?;
            done += rows;
        }
        Ok(())
    }

    /// Runs the first rows of `valid` (at most the largest planned batch) through the smallest
    /// plan that holds them, padded with empty rows; returns how many rows it ran.
    fn run_chunk(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        cholesky: Option<&mut [f32]>,
    ) -> Result<usize, InferenceError> {
        let remaining = valid.len() / MAX_HISTORY;
        let index = self.plans.iter().position(|p| p.batch >= remaining).unwrap_or(self.plans.len() - 1);
        let plan = &mut self.plans[index];
        let (size, rows) = (plan.batch, remaining.min(plan.batch));
        let features = padded_tensor(&[size, MAX_HISTORY, FEATURES], features)?;
        let valid = padded_tensor(&[size, MAX_HISTORY], valid)?;
        let outputs = plan.state.run(tvec!(features.into_tvalue(), valid.into_tvalue()))?;
        let output = outputs.first().ok_or(InferenceError::NoOutput)?;
        if output.shape() != [size, 2] {
            return Err(InferenceError::OutputShape { found: output.shape().to_vec(), batch: size });
        }
        let view = output.try_as_plain_ram()?;
        displacements[..rows * 2].copy_from_slice(&view.as_slice::<f32>()?[..rows * 2]);
        if let Some(cholesky) = cholesky {
            let output = outputs
                .get(1)
                .filter(|output| output.shape() == [size, CHOLESKY_VALUES])
                .ok_or_else(|| InferenceError::CholeskyShape {
                    found: outputs.get(1).map(|output| output.shape().to_vec()).unwrap_or_default(),
                    batch: size,
                })?;
            let view = output.try_as_plain_ram()?;
            let values = rows * CHOLESKY_VALUES;
            cholesky[..values].copy_from_slice(&view.as_slice::<f32>()?[..values]);
        }
        Ok(rows)
    }
}

/// Rows of the probe batch: every history length, at several speeds, headings, ranges of
/// radial velocity and RCS, and measurement intervals.
const PROBE_ROWS: usize = 60;

/// The inputs [`PrModel`] compares tract and the native forward pass on: deterministic,
/// spanning what the tracker sends (history lengths 1 to 5, speeds to ~40 m/s, intervals of
/// 15 to 80 ms) and beyond it.
fn probe_batch() -> (Vec<f32>, Vec<f32>) {
    let mut features = vec![0.0f32; PROBE_ROWS * MAX_HISTORY * FEATURES];
    let mut valid = vec![0.0f32; PROBE_ROWS * MAX_HISTORY];
    // A small linear congruential generator: the probe must not depend on a crate's stream.
    let mut state = 0x2545_f491_u32;
    let mut uniform = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for row in 0..PROBE_ROWS {
        let len = 1 + row % MAX_HISTORY;
        let speed = 40.0 * uniform();
        let heading = std::f32::consts::TAU * uniform();
        let interval = 0.015 + 0.065 * uniform();
        let radial = 60.0 * uniform() - 30.0;
        let rcs = 40.0 * uniform() - 10.0;
        let prediction_gap = interval * (0.5 + uniform());
        for index in 0..len {
            let steps_back = (len - 1 - index) as f32;
            let base = (row * MAX_HISTORY + index) * FEATURES;
            let back = speed * interval * steps_back;
            features[base] = -back * heading.cos() + (uniform() - 0.5) * 0.6;
            features[base + 1] = -back * heading.sin() + (uniform() - 0.5) * 0.6;
            features[base + 2] = radial + (uniform() - 0.5);
            features[base + 3] = rcs + 4.0 * (uniform() - 0.5);
            features[base + 4] = -(prediction_gap + interval * steps_back);
            valid[row * MAX_HISTORY + index] = 1.0;
        }
    }
    (features, valid)
}

/// A zero tensor of `shape` whose leading values are copied from `values` (as many as fit):
/// the rows of a chunk, followed by empty padding rows.
fn padded_tensor(shape: &[usize], values: &[f32]) -> TractResult<Tensor> {
    let mut tensor = Tensor::zero::<f32>(shape)?;
    let mut view = tensor.try_as_plain_ram_mut()?;
    let slots = view.as_slice_mut::<f32>()?;
    let count = slots.len().min(values.len());
    slots[..count].copy_from_slice(&values[..count]);
    Ok(tensor)
}

/// Formats an inference-time shape, `?` for an unknown dimension, `..` for an unknown rank.
fn describe(fact: &InferenceFact) -> String {
    let dims: Vec<String> = fact.shape.dims().map(|d| d.to_string()).collect();
    let open = if fact.shape.is_open() { ", .." } else { "" };
    format!("type {:?}, shape [{}{open}]", fact.datum_type, dims.join(", "))
}

/// Checks the inputs and outputs by name and the inputs' shapes; returns whether the model has
/// the covariance output.
fn check_signature(source: &ModelSource, model: &InferenceModel) -> Result<bool, ModelError> {
    // An outlet's ONNX tensor name where tract kept it, else the name of the node producing it.
    let names = |outlets: &[OutletId]| -> Vec<String> {
        outlets
            .iter()
            .map(|outlet| {
                model
                    .outlet_label(*outlet)
                    .map_or_else(|| model.node(outlet.node).name.clone(), str::to_string)
            })
            .collect()
    };
    let inputs = names(model.input_outlets().unwrap_or(&[]));
    if inputs != [FEATURES_INPUT, VALID_INPUT] {
        return Err(ModelError::Signature {
            model: source.clone(),
            expected: format!("inputs [{FEATURES_INPUT}, {VALID_INPUT}]"),
            found: format!("inputs {inputs:?}"),
        });
    }
    let outputs = names(model.output_outlets().unwrap_or(&[]));
    let has_uncertainty = match outputs.len() {
        1 => false,
        2 if outputs[1] == CHOLESKY_OUTPUT => true,
        _ => {
            return Err(ModelError::Signature {
                model: source.clone(),
                expected: format!(
                    "outputs [{DISPLACEMENT_OUTPUT}] or [{DISPLACEMENT_OUTPUT}, {CHOLESKY_OUTPUT}]"
                ),
                found: format!("outputs {outputs:?}"),
            });
        }
    };
    for (index, (name, fixed)) in
        [(FEATURES_INPUT, &[MAX_HISTORY, FEATURES][..]), (VALID_INPUT, &[MAX_HISTORY][..])]
            .into_iter()
            .enumerate()
    {
        let fact = model
            .input_fact(index)
            .map_err(|e| ModelError::NotOnnx { model: source.clone(), reason: format!("{e:#}") })?;
        let expected_dims: Vec<String> =
            std::iter::once(BATCH_SYMBOL.to_string()).chain(fixed.iter().map(|d| d.to_string())).collect();
        let dims: Vec<&GenericFactoid<TDim>> = fact.shape.dims().collect();
        let type_ok = matches!(fact.datum_type, GenericFactoid::Only(DatumType::F32) | GenericFactoid::Any);
        let rank_ok = !fact.shape.is_open() && dims.len() == 1 + fixed.len();
        let dims_ok = rank_ok
            && fixed.iter().zip(&dims[1..]).all(|(want, got)| **got == GenericFactoid::Only(want.to_dim()))
            && !matches!(dims[0], GenericFactoid::Only(d) if d.to_i64().is_ok());
        if !(type_ok && dims_ok) {
            return Err(ModelError::Shape {
                model: source.clone(),
                name: name.to_string(),
                expected: format!(
                    "type F32, shape [{}] with a symbolic batch axis",
                    expected_dims.join(", ")
                ),
                found: describe(fact),
            });
        }
    }
    Ok(has_uncertainty)
}

/// Checks that output `index`, called `name`, is F32 of shape `[batch, columns]`.
fn check_output(
    source: &ModelSource,
    model: &TypedModel,
    index: usize,
    name: &str,
    columns: usize,
) -> Result<(), ModelError> {
    let fact = model
        .output_fact(index)
        .map_err(|e| ModelError::Preparation { model: source.clone(), reason: format!("{e:#}") })?;
    let dims = fact.shape.dims();
    let ok = fact.datum_type == DatumType::F32
        && dims.len() == 2
        && dims[1] == columns.to_dim()
        && dims[0] == model.symbols.sym(BATCH_SYMBOL).to_dim();
    if ok {
        return Ok(());
    }
    Err(ModelError::Shape {
        model: source.clone(),
        name: name.to_string(),
        expected: format!("type F32, shape [{BATCH_SYMBOL}, {columns}]"),
        found: format!(
            "type {:?}, shape [{}]",
            fact.datum_type,
            dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")
        ),
    })
}

/// Counters of an [`OnnxPredictor`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct OnnxPredictorStats {
    /// Batches run (non-empty ones).
    pub batches: u64,
    /// Model rows run (requests plus the extra rows for tracks that coasted).
    pub rows: u64,
    /// Requests answered with a displacement.
    pub predictions: u64,
    /// Requests refused before inference (history length outside `1..=5`, non-finite values).
    pub invalid_requests: u64,
    /// Requests whose model output was not finite.
    pub non_finite_outputs: u64,
    /// Batches whose inference failed (every request of the batch went without).
    pub failed_batches: u64,
}

/// The PR model as a synchronous [`DisplacementPredictor`].
#[derive(Debug)]
pub struct OnnxPredictor {
    model: PrModel,
    features: Vec<f32>,
    valid: Vec<f32>,
    output: Vec<f32>,
    /// The covariance output of the last batch (empty for a model without one).
    cholesky: Vec<f32>,
    /// Model row of each request (`None`: refused), of its step-start row if it has one, and
    /// the request's input frame.
    rows: Vec<(Option<usize>, Option<usize>, MotionFrame)>,
    results: Vec<Option<Displacement>>,
    stats: OnnxPredictorStats,
    last_error: Option<InferenceError>,
}

impl OnnxPredictor {
    /// Loads the model (see [`PrModel::load`]); the working buffers are sized for
    /// [`MAX_TRACKS`] requests with a step-start row each.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, ModelError> {
        Ok(Self::from_model(PrModel::load(path)?))
    }

    /// The default model built into the binary (see [`PrModel::embedded`]).
    pub fn embedded() -> Result<Self, ModelError> {
        Ok(Self::from_model(PrModel::embedded()?))
    }

    /// Wraps an already loaded model.
    pub fn from_model(model: PrModel) -> Self {
        let rows = 2 * MAX_TRACKS;
        OnnxPredictor {
            model,
            features: Vec::with_capacity(rows * MAX_HISTORY * FEATURES),
            valid: Vec::with_capacity(rows * MAX_HISTORY),
            output: Vec::with_capacity(rows * 2),
            cholesky: Vec::with_capacity(rows * CHOLESKY_VALUES),
            rows: Vec::with_capacity(MAX_TRACKS),
            results: Vec::with_capacity(MAX_TRACKS),
            stats: OnnxPredictorStats::default(),
            last_error: None,
        }
    }

    /// A second predictor on the same model (see [`PrModel::fork`]), with its own buffers and
    /// zeroed counters.
    pub fn fork(&self) -> Result<Self, ModelError> {
        Ok(Self::from_model(self.model.fork()?))
    }

    /// Chooses the model's engine ([`PrModel::set_engine`]); returns the one in use.
    pub fn set_engine(&mut self, engine: InferenceEngine) -> InferenceEngine {
        self.model.set_engine(engine)
    }

    /// The model.
    pub fn model(&self) -> &PrModel {
        &self.model
    }

    /// The counters.
    pub fn stats(&self) -> &OnnxPredictorStats {
        &self.stats
    }

    /// The error of the last failed batch, if any batch failed.
    pub fn last_error(&self) -> Option<&InferenceError> {
        self.last_error.as_ref()
    }

    /// Runs the model on `requests` and writes each request's step displacement (see the
    /// [module documentation](self)) to `displacements` (same length): `None` for a refused
    /// request or a non-finite output. On an inference failure every entry is `None` and the
    /// error is returned.
    ///
    /// With a model that estimates its uncertainty, each displacement carries the covariance
    /// of the model's answer at the prediction time, rotated back like the displacement. For
    /// a track that coasted (the displacement is the difference of two answers) that is the
    /// covariance of the displacement from the latest measurement, which bounds the one of the
    /// step from above: the two answers' errors are strongly correlated and no model output
    /// describes their difference.
    pub fn predict_batch(
        &mut self,
        requests: &[PredictionRequest],
        displacements: &mut [Option<Displacement>],
    ) -> Result<(), InferenceError> {
        displacements.fill(None);
        self.features.clear();
        self.valid.clear();
        self.rows.clear();
        let mut row_count = 0;
        for request in requests {
            let frame = MotionFrame::of(request);
            let row = push_row(request, &frame, &mut self.features, &mut self.valid).then(|| {
                row_count += 1;
                row_count - 1
            });
            self.stats.invalid_requests += u64::from(row.is_none());
            self.rows.push((row, None, frame));
        }
        for (request, rows) in requests.iter().zip(self.rows.iter_mut()) {
            if rows.0.is_some() && request.step_starts_after_latest_measurement() {
                let shifted = request.at_time(request.step_start_s);
                if push_row(&shifted, &rows.2, &mut self.features, &mut self.valid) {
                    rows.1 = Some(row_count);
                    row_count += 1;
                } else {
                    rows.0 = None;
                    self.stats.invalid_requests += 1;
                }
            }
        }
        if row_count == 0 {
            return Ok(());
        }
        self.output.clear();
        self.output.resize(row_count * 2, 0.0);
        self.cholesky.clear();
        self.stats.batches += 1;
        self.stats.rows += row_count as u64;
        let run = if self.model.has_uncertainty() {
            self.cholesky.resize(row_count * CHOLESKY_VALUES, 0.0);
            self.model.run_with_uncertainty(&self.features, &self.valid, &mut self.output, &mut self.cholesky)
        } else {
            self.model.run(&self.features, &self.valid, &mut self.output)
        };
        if let Err(error) = run {
            self.stats.failed_batches += 1;
            self.last_error = Some(error.clone());
            return Err(error);
        }
        let at =
            |row: usize| DVec2::new(f64::from(self.output[2 * row]), f64::from(self.output[2 * row + 1]));
        let covariance_at = |row: usize| {
            let values = self.cholesky.get(CHOLESKY_VALUES * row..CHOLESKY_VALUES * (row + 1))?;
            Some(covariance_from_cholesky([values[0], values[1], values[2]]))
        };
        for (out, &(row, start_row, frame)) in displacements.iter_mut().zip(&self.rows) {
            let Some(row) = row else { continue };
            let displacement = frame.from_model(match start_row {
                Some(start_row) => at(row) - at(start_row),
                None => at(row),
            });
            if displacement.is_finite() {
                *out = Some(Displacement {
                    mean_m: displacement,
                    covariance_m2: covariance_at(row)
                        .map(|covariance| frame.covariance_from_model(covariance)),
                });
                self.stats.predictions += 1;
            } else {
                self.stats.non_finite_outputs += 1;
            }
        }
        Ok(())
    }
}

/// Appends the model rows of one request, its positions rotated into `frame`; `false` (nothing
/// appended) if the request is unusable.
fn push_row(
    request: &PredictionRequest,
    frame: &MotionFrame,
    features: &mut Vec<f32>,
    valid: &mut Vec<f32>,
) -> bool {
    let len = request.len;
    if !(1..=MAX_HISTORY).contains(&len) || !request.features[..len].iter().flatten().all(|v| v.is_finite()) {
        return false;
    }
    for (index, row) in request.features.iter().enumerate() {
        if index < len {
            let position = frame.to_model(DVec2::new(f64::from(row[0]), f64::from(row[1])));
            features.extend_from_slice(&[position.x as f32, position.y as f32, row[2], row[3], row[4]]);
            valid.push(1.0);
        } else {
            features.extend_from_slice(&[0.0; FEATURES]);
            valid.push(0.0);
        }
    }
    true
}

impl DisplacementPredictor for OnnxPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        let mut results = std::mem::take(&mut self.results);
        results.clear();
        results.resize(requests.len(), None);
        // A failed batch leaves every entry `None`; the error is counted and kept.
        let _ = self.predict_batch(requests, &mut results);
        self.results = results;
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
        for (out, result) in displacements.iter_mut().zip(&self.results) {
            *out = *result;
        }
    }

    fn report(&self) -> Option<String> {
        let s = &self.stats;
        Some(format!(
            "learned predictor ({}): {} batches, {} rows, {} predictions, {} invalid requests, {} non-finite outputs, {} failed batches",
            self.model.source(),
            s.batches,
            s.rows,
            s.predictions,
            s.invalid_requests,
            s.non_finite_outputs,
            s.failed_batches
        ))
    }
}
