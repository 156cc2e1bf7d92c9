//! The `predictor` section: the learned predictor's runtime and the check of its answers.

use super::*;

/// The learned predictor's runtime and the check of its answers.
///
/// * `deadline_ms` applies in the tracking service (`primm serve`): the model runs on a
///   dedicated inference thread while the tracker predicts the physics modes, and the tracker
///   waits for its batch at most this long. Offline tracking (`primm track`, `primm eval`) runs
///   the model synchronously and ignores the deadline, so that its results do not depend on
///   timing.
/// * `max_displacement_speed_mps` applies wherever the tracker runs: every displacement a
///   predictor returns is checked against it before the PR mode uses it
///   (`crates/primm-core/src/displacement_check.rs`).
/// * `process_noise` and `learned_process_noise_scale` choose the PR mode's `Q_PR`
///   (`eq:pr_cov`): the model's own covariance of each displacement, scaled, or the per-class
///   constant `classes.*.learned.process_noise_covariance_m2` of the paper.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct PredictorConfig {
    /// Longest wait for a frame's learned displacements, measured from the moment the batch is
    /// handed to the inference thread, ms. A frame whose batch is late is tracked without the
    /// PR mode (it sits the frame out; see `src/imm.rs`).
    pub deadline_ms: f64,
    /// Fastest motion a learned displacement may imply, m/s: a displacement longer than this
    /// speed times the step's duration (`prediction_time_s − step_start_s` of its request) is
    /// rejected as implausible and counted, and the PR mode sits the frame out for that track.
    pub max_displacement_speed_mps: f64,
    /// Where the PR mode's `Q_PR` comes from.
    pub process_noise: LearnedProcessNoise,
    /// Factor on the model's covariance when `process_noise` is
    /// [`Learned`](LearnedProcessNoise::Learned), dimensionless (> 0).
    pub learned_process_noise_scale: f64,
    /// Service only: inference threads that share each frame's batch (1 to
    /// [`MAX_INFERENCE_THREADS`]); batches below 16 requests per thread use fewer.
    pub inference_threads: usize,
    /// What runs the PR model's forward pass.
    pub engine: InferenceEngine,
    /// The classes whose tracks the learned model predicts when the PR mode is one of several
    /// active modes (PR-IMM). A track of another class gets no request, and the PR mode sits
    /// every step of it out exactly as after a missed deadline (see `src/imm.rs`): its prior
    /// probability is spread over the physics modes, and it keeps that probability afterwards.
    /// With PR as the only mode (the `pr` method) every class is predicted, since the tracker
    /// would otherwise have no motion model for the classes left out.
    pub classes: ClassSet,
}

/// Most inference threads `predictor.inference_threads` may ask for.
pub const MAX_INFERENCE_THREADS: usize = 8;

impl Default for PredictorConfig {
    fn default() -> Self {
        Self {
            deadline_ms: 5.0,
            max_displacement_speed_mps: 100.0,
            process_noise: LearnedProcessNoise::Constant,
            learned_process_noise_scale: 1.0,
            inference_threads: 2,
            engine: InferenceEngine::Native,
            classes: ClassSet::ALL.without(ObjectClass::Car),
        }
    }
}

/// What runs the PR model's forward pass (`predictor.engine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum InferenceEngine {
    /// primm's own fixed-size forward pass of the shipped architecture
    /// (`primm_predictor::native`), for models of that architecture that agree with tract on
    /// probe inputs at load; any other model runs on tract.
    #[default]
    Native,
    /// tract runs the ONNX graph.
    Tract,
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
        match s {
            "native" => Ok(InferenceEngine::Native),
            "tract" => Ok(InferenceEngine::Tract),
            _ => Err(UnknownEngine { text: s.into() }),
        }
    }
}

/// The source of the PR mode's process noise `Q_PR` (`eq:pr_cov`). The default configuration
/// uses [`Constant`](Self::Constant): on the validation splits it gave PR-IMM the lower error
/// (`config/primm.toml` has the figures).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LearnedProcessNoise {
    /// The model's covariance of each displacement, times `learned_process_noise_scale`: a
    /// per-track, per-step `Q_PR`. A model without an uncertainty output, or an answer without
    /// one, falls back to the constant.
    Learned,
    /// The per-class constant `classes.*.learned.process_noise_covariance_m2`, as in the paper.
    #[default]
    Constant,
}

impl PredictorConfig {
    /// Whether the learned model predicts the tracks of `class` under the active `modes` (see
    /// [`classes`](Self::classes)).
    pub fn predicts(&self, class: ObjectClass, modes: ModeSet) -> bool {
        modes.len() == 1 || self.classes.contains(class)
    }

    /// The deadline as a duration.
    pub fn deadline(&self) -> core::time::Duration {
        core::time::Duration::from_secs_f64(self.deadline_ms / 1000.0)
    }
}
