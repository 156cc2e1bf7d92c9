//! Target `onnx_model_bytes`: PR model loading on arbitrary bytes.

use primm_core::predictor::{HistoryEntry, PredictionRequest};
use primm_predictor::onnx::{ModelSource, OnnxPredictor, PrModel};
use std::path::PathBuf;

/// Loads `data` as a PR model ([`PrModel::from_bytes`]); a malformed model must be a
/// [`ModelError`](primm_predictor::onnx::ModelError), never a panic. A model that loads must
/// answer a batch of predictions (a history of three measurements and one of one) without
/// panicking; an inference error is an acceptable answer.
///
/// `PrModel::from_bytes` catches the panics tract raises on some malformed files and returns
/// them as errors. libFuzzer's panic hook would abort on such a caught panic too, so the hook is
/// silenced while the model loads; a panic that escapes `from_bytes` still reaches libFuzzer's
/// own `catch_unwind` and is reported as a crash.
pub fn run(data: &[u8]) {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let loaded = PrModel::from_bytes(data, ModelSource::File(PathBuf::from("fuzz-input.onnx")));
    std::panic::set_hook(hook);
    let Ok(model) = loaded else {
        return;
    };
    let mut predictor = OnnxPredictor::from_model(model);
    let history: Vec<HistoryEntry> = (0..3)
        .map(|k| HistoryEntry {
            x_m: 20.0 + 0.5 * k as f64,
            y_m: 1.5,
            radial_velocity_mps: 10.0,
            rcs_dbsm: 8.0,
            timestamp_s: 0.05 * k as f64,
            ..Default::default()
        })
        .collect();
    let requests = [
        PredictionRequest::from_history(&history, 0.15),
        PredictionRequest::from_history(&history[..1], 0.05),
    ];
    let mut displacements = [None; 2];
    let _ = predictor.predict_batch(&requests, &mut displacements);
}
