//! The loaded PR model: tract's plans ([`tract_engine`](super::tract_engine)) and, where the
//! [engine choice](super::engine_choice) allows it, primm's native forward pass
//! ([`native`](crate::native)), behind one `run`.

use super::contract::{
    InferenceError, InputFrame, ModelError, ModelSource, CHOLESKY_VALUES, INPUT_FRAME_KEY,
};
use super::engine_choice::EngineChoice;
use super::tract_engine::{ParsedModel, TractEngine};
use crate::native::{NativeModel, Unsupported};
use primm_config::InferenceEngine;
use primm_core::predictor::{FEATURES, MAX_HISTORY};
use std::fmt;
use std::path::Path;

/// The loaded, optimised PR model: one plan per size of
/// [`PLAN_BATCH_SIZES`](super::PLAN_BATCH_SIZES) and, where the model has the shipped
/// architecture and agrees with tract on probe inputs, its [`NativeModel`].
pub struct PrModel {
    source: ModelSource,
    /// Whether the model has the [`CHOLESKY_OUTPUT`](super::CHOLESKY_OUTPUT).
    has_uncertainty: bool,
    /// The axes the model takes its input in (its [`INPUT_FRAME_KEY`] metadata entry).
    input_frame: InputFrame,
    /// tract's plans.
    tract: TractEngine,
    /// The native forward pass, or why the model cannot have one, and the engine batches run on.
    choice: EngineChoice,
}

impl fmt::Debug for PrModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PrModel")
            .field("source", &self.source)
            .field("input_frame", &self.input_frame)
            .field("batch_sizes", &self.tract.batch_sizes())
            .field("nodes", &self.tract.nodes())
            .field("engine", &self.choice.engine())
            .field("native", &self.choice.native_status())
            .finish()
    }
}

impl PrModel {
    /// Loads `path`, checks its signature against the [model contract](super::contract), binds
    /// the batch axis to the symbol [`BATCH_SYMBOL`](super::BATCH_SYMBOL), then optimises and
    /// plans the graph once for each size of [`PLAN_BATCH_SIZES`](super::PLAN_BATCH_SIZES) and
    /// runs one trial sample. All the work of preparing the model happens here, once.
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
        let ParsedModel { proto, has_uncertainty, tract } = TractEngine::parse(bytes, &source)?;
        let input_frame = match proto.metadata_props.iter().find(|entry| entry.key == INPUT_FRAME_KEY) {
            None => InputFrame::LatestMotion,
            Some(entry) => InputFrame::from_name(&entry.value).ok_or_else(|| ModelError::InputFrame {
                model: source.clone(),
                value: entry.value.clone(),
            })?,
        };
        let native = NativeModel::from_proto(&proto, has_uncertainty);
        let mut loaded =
            PrModel { source, has_uncertainty, input_frame, tract, choice: EngineChoice::on_tract(native) };
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
        loaded.choice.probe(&mut loaded.tract, has_uncertainty).map_err(|error| ModelError::Preparation {
            model: loaded.source.clone(),
            reason: error.to_string(),
        })?;
        loaded.set_engine(InferenceEngine::Native);
        Ok(loaded)
    }

    /// The axes the model takes its input positions and gives its displacement in, as its ONNX
    /// metadata names them ([`InputFrame::LatestMotion`] for a model that names none).
    pub fn input_frame(&self) -> InputFrame {
        self.input_frame
    }

    /// Chooses the engine batches run on and returns the one in use: [`Native`] where the
    /// model has a native forward pass ([`native_unsupported`](Self::native_unsupported) says
    /// why not otherwise), else [`Tract`]. A loaded model starts on [`Native`] where it can.
    ///
    /// [`Native`]: InferenceEngine::Native
    /// [`Tract`]: InferenceEngine::Tract
    pub fn set_engine(&mut self, engine: InferenceEngine) -> InferenceEngine {
        self.choice.set(engine)
    }

    /// The engine batches run on.
    pub fn engine(&self) -> InferenceEngine {
        self.choice.engine()
    }

    /// Why this model has no native forward pass; `None` where it has one.
    pub fn native_unsupported(&self) -> Option<&Unsupported> {
        self.choice.native_unsupported()
    }

    /// Another instance of this model that shares its optimised plans and has its own
    /// execution states, for running batches on another thread at the same time. Nothing is
    /// parsed or optimised again: only tract's per-plan state is built.
    pub fn fork(&self) -> Result<Self, ModelError> {
        Ok(PrModel {
            source: self.source.clone(),
            has_uncertainty: self.has_uncertainty,
            input_frame: self.input_frame,
            tract: self.tract.fork(&self.source)?,
            choice: self.choice.clone(),
        })
    }

    /// Where the model came from.
    pub fn source(&self) -> &ModelSource {
        &self.source
    }

    /// Whether the model also estimates the covariance of its displacements
    /// ([`CHOLESKY_OUTPUT`](super::CHOLESKY_OUTPUT)).
    pub fn has_uncertainty(&self) -> bool {
        self.has_uncertainty
    }

    /// Runs one batch: `features` holds `batch × 5 × 5` values (row-major, the layout of
    /// [`PredictionRequest::features`](primm_core::predictor::PredictionRequest::features)),
    /// `valid` `batch × 5` and `displacements` receives `batch × 2` values `[dx, dy]` in
    /// metres. A batch of zero rows does nothing.
    pub fn run(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
    ) -> Result<(), InferenceError> {
        self.run_outputs(features, valid, displacements, None)
    }

    /// [`run`](Self::run), also writing the covariance output: `cholesky` receives `batch × 3`
    /// values `[l_xx, l_yx, l_yy]` in metres (see
    /// [`covariance_from_cholesky`](super::covariance_from_cholesky)). Fails with
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
        cholesky: Option<&mut [f32]>,
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
        if let Some(native) = self.choice.native_in_use() {
            if cholesky.is_some() && !native.has_uncertainty() {
                return Err(InferenceError::CholeskyShape { found: Vec::new(), batch });
            }
            native.run(features, valid, displacements, cholesky);
            return Ok(());
        }
        self.tract.run(features, valid, displacements, cholesky)
    }
}
