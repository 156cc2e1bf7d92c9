//! How the learned model runs: its engine, its inference threads and the tracker's deadline for
//! its answers. The tracker itself never reads these (offline tracking runs the model
//! synchronously); the service, the C API and the command line do. In the file they are keys of
//! the `predictor` section, beside the tracker's own predictor settings.

use primm_core::config::ConfigError as InvalidValue;

/// Most inference threads `predictor.inference_threads` may ask for.
pub const MAX_INFERENCE_THREADS: usize = 8;

/// What runs the PR model's forward pass (`predictor.engine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InferenceEngine {
    /// primm's own fixed-size forward pass of the shipped architecture
    /// (`primm_predictor::native`), for models of that architecture that agree with tract on
    /// probe inputs at load; any other model runs on tract.
    #[default]
    Native,
    /// tract runs the ONNX graph.
    Tract,
}

impl InferenceEngine {
    /// The name used in configuration and on the command line (`native`, `tract`).
    pub fn name(self) -> &'static str {
        match self {
            InferenceEngine::Native => "native",
            InferenceEngine::Tract => "tract",
        }
    }
}

/// An engine name that is neither `native` nor `tract`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown engine '{text}' (expected native or tract)")]
pub struct UnknownEngine {
    /// The text that names no engine.
    pub text: String,
}

impl core::str::FromStr for InferenceEngine {
    type Err = UnknownEngine;
    /// The names of `predictor.engine`: `native`, `tract`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [InferenceEngine::Native, InferenceEngine::Tract]
            .into_iter()
            .find(|engine| engine.name() == s)
            .ok_or_else(|| UnknownEngine { text: s.into() })
    }
}

/// The learned model's runtime (`predictor.deadline_ms`, `predictor.inference_threads`,
/// `predictor.engine`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InferenceConfig {
    /// Longest wait for a frame's learned displacements, measured from the moment the batch is
    /// handed to the inference thread, ms. A frame whose batch is late is tracked without the
    /// PR mode (it sits the frame out). Applies where the model runs on inference threads
    /// (`primm serve`, the C API's threaded option); offline tracking runs it synchronously and
    /// ignores the deadline, so that its results do not depend on timing.
    pub deadline_ms: f64,
    /// Inference threads that share each frame's batch (1 to [`MAX_INFERENCE_THREADS`]);
    /// batches below 16 requests per thread use fewer.
    pub inference_threads: usize,
    /// What runs the PR model's forward pass.
    pub engine: InferenceEngine,
}

impl Default for InferenceConfig {
    fn default() -> Self {
        Self { deadline_ms: 5.0, inference_threads: 2, engine: InferenceEngine::Native }
    }
}

impl InferenceConfig {
    /// The deadline as a duration.
    pub fn deadline(&self) -> core::time::Duration {
        core::time::Duration::from_secs_f64(self.deadline_ms / 1000.0)
    }

    /// Checks every value; the error names the offending key.
    pub fn validate(&self) -> Result<(), InvalidValue> {
        let invalid =
            |key: &str, reason: &str| InvalidValue::Invalid { key: key.into(), reason: reason.into() };
        if !(self.deadline_ms.is_finite() && self.deadline_ms > 0.0) {
            return Err(invalid("predictor.deadline_ms", "must be a finite number > 0"));
        }
        if self.deadline_ms > 1000.0 {
            return Err(invalid("predictor.deadline_ms", "must be at most 1000 ms (one second)"));
        }
        if !(1..=MAX_INFERENCE_THREADS).contains(&self.inference_threads) {
            return Err(invalid("predictor.inference_threads", "must be from 1 to 8"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn engine_names_parse_and_another_name_is_refused_with_it() {
        assert_eq!("native".parse::<InferenceEngine>(), Ok(InferenceEngine::Native));
        assert_eq!("tract".parse::<InferenceEngine>(), Ok(InferenceEngine::Tract));
        let error = "onnxruntime".parse::<InferenceEngine>().unwrap_err();
        assert!(error.to_string().contains("onnxruntime"));
    }

    fn invalid_key(config: &InferenceConfig) -> String {
        match config.validate() {
            Err(InvalidValue::Invalid { key, .. }) => key,
            Ok(()) => panic!("expected an invalid-key error"),
        }
    }

    #[test]
    fn no_or_too_many_inference_threads_are_rejected() {
        for bad in [0, MAX_INFERENCE_THREADS + 1] {
            let config = InferenceConfig { inference_threads: bad, ..InferenceConfig::default() };
            assert_eq!(invalid_key(&config), "predictor.inference_threads", "threads {bad}");
        }
        let most = InferenceConfig { inference_threads: MAX_INFERENCE_THREADS, ..InferenceConfig::default() };
        assert_eq!(most.validate(), Ok(()));
    }

    #[test]
    fn a_non_positive_or_huge_deadline_is_rejected() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1000.5] {
            let config = InferenceConfig { deadline_ms: bad, ..InferenceConfig::default() };
            assert_eq!(invalid_key(&config), "predictor.deadline_ms", "deadline {bad}");
        }
        assert_eq!(InferenceConfig::default().deadline(), core::time::Duration::from_millis(5));
    }
}
