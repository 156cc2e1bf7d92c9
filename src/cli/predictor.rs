//! Choosing the learned predictor for a method on the command line.

use crate::mode::Method;
use crate::predictor::{DisplacementPredictor, NoPredictor};
use std::path::Path;

/// The default model file, relative to the working directory.
pub const DEFAULT_MODEL_PATH: &str = "models/pr.onnx";

/// The predictor a method needs: none for the physics-only methods, the ONNX model otherwise.
pub fn predictor_for(method: Method, model: Option<&Path>) -> Result<Box<dyn DisplacementPredictor + Send>, String> {
    if !method.needs_predictor() {
        return Ok(Box::new(NoPredictor));
    }
    let path = model.unwrap_or(Path::new(DEFAULT_MODEL_PATH));
    Err(format!(
        "method {method} needs the learned predictor, but this build has no ONNX runtime for {}",
        path.display()
    ))
}
