//! The stages of a frame's path through primm, and an optional hook that tells a caller where
//! one tracker step is, stage by stage.
//!
//! The library never reads a clock. A caller that wants per-stage latencies passes a
//! [`StageObserver`] to [`Tracker::step_observed`](crate::tracker::Tracker::step_observed); the
//! tracker calls [`StageObserver::stage_finished`] at the end of every one of its stages
//! ([`Stage::TRACKER`]), in order, and the observer reads whatever clock it likes. The hook is
//! generic, so the plain [`Tracker::step`](crate::tracker::Tracker::step) compiles it away, and
//! it allocates nothing. The remaining stages are measured by a host (the tracking service).

/// The stages of a frame's path through primm, in report order: the tracker reports the first
/// six ([`Stage::TRACKER`]) to a [`StageObserver`]; a host measures the others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Stage {
    /// Tracker: frame and measurement validation.
    Validate = 0,
    /// Tracker: submitting the learned-predictor batch, IMM mixing and the CV/CA/CT predictions.
    Predict = 1,
    /// Tracker: waiting for the learned predictor's displacements, the PR priors and the prior
    /// fusion.
    LearnedWait = 2,
    /// Tracker: per-class gated association.
    Associate = 3,
    /// Tracker: Kalman and mode updates, coasting, initiation and deletion.
    Update = 4,
    /// Tracker: handing every live track's output to the caller's sink.
    Report = 5,
    /// Host: sending the track frame and notifying its listeners.
    Publish = 6,
    /// Host: from taking the input sample to the track frame sent.
    ReceiveToPublish = 7,
    /// Host: from the publisher's send of the input frame to the tracker's send of its track
    /// frame (same host, `CLOCK_MONOTONIC`).
    EndToEnd = 8,
    /// Host: [`EndToEnd`](Self::EndToEnd) corrected for coordinated omission: from the time
    /// the publisher was due to send the input frame (its schedule) to the tracker's send of
    /// the track frame. A publisher that falls behind its schedule (a stall anywhere upstream,
    /// or flow control holding it back) sends late, which the uncorrected latency does not see;
    /// this one does. Equal to `EndToEnd` for frames sent without a schedule.
    EndToEndCorrected = 9,
}

impl Stage {
    /// Number of stages.
    pub const COUNT: usize = 10;
    /// All stages in report order.
    pub const ALL: [Stage; Stage::COUNT] = [
        Stage::Validate,
        Stage::Predict,
        Stage::LearnedWait,
        Stage::Associate,
        Stage::Update,
        Stage::Report,
        Stage::Publish,
        Stage::ReceiveToPublish,
        Stage::EndToEnd,
        Stage::EndToEndCorrected,
    ];
    /// Number of stages of one tracker step.
    pub const TRACKER_COUNT: usize = 6;
    /// The stages of one tracker step, in the order they finish: the first
    /// [`TRACKER_COUNT`](Self::TRACKER_COUNT) of [`ALL`](Self::ALL).
    pub const TRACKER: [Stage; Stage::TRACKER_COUNT] =
        [Stage::Validate, Stage::Predict, Stage::LearnedWait, Stage::Associate, Stage::Update, Stage::Report];

    /// Index in per-stage tables.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Short name used in reports (`validate`, `predict`, `learned_wait`, `associate`, `update`,
    /// `report`, `publish`, `receive_to_publish`, `end_to_end`, `end_to_end_corrected`).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Validate => "validate",
            Stage::Predict => "predict",
            Stage::LearnedWait => "learned_wait",
            Stage::Associate => "associate",
            Stage::Update => "update",
            Stage::Report => "report",
            Stage::Publish => "publish",
            Stage::ReceiveToPublish => "receive_to_publish",
            Stage::EndToEnd => "end_to_end",
            Stage::EndToEndCorrected => "end_to_end_corrected",
        }
    }

    /// What the stage measures, one line (for the comments of latency files).
    pub fn description(self) -> &'static str {
        match self {
            Stage::Validate => "tracker: frame and measurement validation",
            Stage::Predict => "tracker: learned-predictor batch submitted, IMM mixing, CV/CA/CT predictions",
            Stage::LearnedWait => "tracker: wait for the learned displacements and PR prior fusion",
            Stage::Associate => "tracker: gated association",
            Stage::Update => "tracker: Kalman and mode updates, track management",
            Stage::Report => "tracker: track output written",
            Stage::Publish => "host: track frame sent and listeners notified",
            Stage::ReceiveToPublish => "host: input sample taken to track frame sent",
            Stage::EndToEnd => "publisher send of the input frame to tracker send of its track frame",
            Stage::EndToEndCorrected => {
                "corrected for coordinated omission: publisher's scheduled send time of the input frame to tracker send of its track frame"
            }
        }
    }
}

/// Receives a call at the end of every stage of a tracker step ([`Stage::TRACKER`]). A step
/// that fails validation ends after [`Stage::Validate`] (which is then not reported); one whose
/// association fails ends after [`Stage::LearnedWait`].
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tracker_stages_come_first_and_every_stage_sits_at_its_index() {
        assert_eq!(Stage::TRACKER[..], Stage::ALL[..Stage::TRACKER_COUNT]);
        for (index, stage) in Stage::ALL.iter().enumerate() {
            assert_eq!(stage.index(), index);
        }
    }
}
