//! The `predictor` section, as far as the tracker reads it: which classes the learned model
//! predicts, the check of its answers and the PR mode's process noise. How the model runs
//! (engine, inference threads, deadline) is not the tracker's business: `primm-config` reads
//! those keys of the section beside these.

use super::*;

/// The tracker's use of the learned predictor.
///
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
    /// Fastest motion a learned displacement may imply, m/s: a displacement longer than this
    /// speed times the step's duration (`prediction_time_s − step_start_s` of its request) is
    /// rejected as implausible and counted, and the PR mode sits the frame out for that track.
    pub max_displacement_speed_mps: f64,
    /// Where the PR mode's `Q_PR` comes from.
    pub process_noise: LearnedProcessNoise,
    /// Factor on the model's covariance when `process_noise` is
    /// [`Learned`](LearnedProcessNoise::Learned), dimensionless (> 0).
    pub learned_process_noise_scale: f64,
    /// The classes whose tracks the learned model predicts when the PR mode is one of several
    /// active modes (PR-IMM). A track of another class gets no request, and the PR mode sits
    /// every step of it out exactly as after a missed deadline (see `crate::imm`): its prior
    /// probability is spread over the physics modes, and it keeps that probability afterwards.
    /// With PR as the only mode (the `pr` method) every class is predicted, since the tracker
    /// would otherwise have no motion model for the classes left out.
    pub classes: ClassSet,
}

impl Default for PredictorConfig {
    fn default() -> Self {
        Self {
            max_displacement_speed_mps: 100.0,
            process_noise: LearnedProcessNoise::Constant,
            learned_process_noise_scale: 1.0,
            classes: ClassSet::ALL.without(ObjectClass::Car),
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
}
