//! Choosing the learned predictor for a method on the command line.

use crate::mode::Method;
use crate::predictor::onnx::OnnxPredictor;
use crate::predictor::{DisplacementPredictor, NoPredictor};
use std::path::Path;

/// The default model file, relative to the working directory (written by `training/train.py`
/// next to its description `models/pr.json`).
pub const DEFAULT_MODEL_PATH: &str = "models/pr.onnx";

/// The predictor a method needs: none for the physics-only methods, the PR model (`model`, or
/// [`DEFAULT_MODEL_PATH`]) run synchronously otherwise, so offline results do not depend on
/// timing. A missing, unreadable or incompatible model is an error naming the file.
pub fn predictor_for(
    method: Method,
    model: Option<&Path>,
) -> Result<Box<dyn DisplacementPredictor + Send>, String> {
    if !method.needs_predictor() {
        return Ok(Box::new(NoPredictor));
    }
    let path = model.unwrap_or(Path::new(DEFAULT_MODEL_PATH));
    let predictor = OnnxPredictor::load(path).map_err(|error| format!("method {method}: {error}"))?;
    Ok(Box::new(predictor))
}
