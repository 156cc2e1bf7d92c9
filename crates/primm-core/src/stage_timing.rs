//! An optional hook that tells a caller where one tracker step is, stage by stage.
//!
//! The library never reads a clock. A caller that wants per-stage latencies passes a
//! [`StageObserver`] to [`Tracker::step_observed`](crate::tracker::Tracker::step_observed); the
//! tracker calls [`StageObserver::stage_finished`] at the end of every stage, in order, and the
//! observer reads whatever clock it likes. The hook is generic, so the plain
//! [`Tracker::step`](crate::tracker::Tracker::step) compiles it away, and it allocates nothing.

/// The stages of one tracker step, in the order they finish.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Stage {
    /// Frame and measurement validation.
    Validate = 0,
    /// Submitting the learned-predictor batch, IMM mixing and the CV/CA/CT predictions.
    Predict = 1,
    /// Waiting for the learned predictor's displacements, the PR priors and the prior fusion.
    LearnedWait = 2,
    /// Per-class gated association.
    Associate = 3,
    /// Kalman and mode updates, coasting, initiation and deletion.
    Update = 4,
    /// Handing every live track's output to the caller's sink.
    Report = 5,
}

impl Stage {
    /// Number of stages.
    pub const COUNT: usize = 6;
    /// All stages in order.
    pub const ALL: [Stage; Stage::COUNT] =
        [Stage::Validate, Stage::Predict, Stage::LearnedWait, Stage::Associate, Stage::Update, Stage::Report];

    /// Index in per-stage tables.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Short name used in reports (`validate`, `predict`, `learned_wait`, `associate`, `update`,
    /// `report`).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Validate => "validate",
            Stage::Predict => "predict",
            Stage::LearnedWait => "learned_wait",
            Stage::Associate => "associate",
            Stage::Update => "update",
            Stage::Report => "report",
        }
    }
}

/// Receives a call at the end of every stage of a tracker step. A step that fails validation
/// ends after [`Stage::Validate`] (which is then not reported); one whose association fails ends
/// after [`Stage::LearnedWait`].
pub trait StageObserver {
    /// `stage` has just finished.
    fn stage_finished(&mut self, stage: Stage);
}

/// An observer that ignores every stage.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl StageObserver for NoObserver {
    #[inline(always)]
    fn stage_finished(&mut self, _stage: Stage) {}
}
