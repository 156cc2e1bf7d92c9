//! Tracks predicted to a requested time, for a consumer running at its own cycle (a planner
//! asking for the objects at its own time), without changing any state.
//!
//! Each track's IMM is predicted from its posterior over the physics modes (mixing, the CV, CA
//! and CT predictions, the fused prior of `eq:prior_fusion`); the learned mode sits out, as it
//! does after a missed inference deadline, because it needs a model inference of its own. The
//! existence probability decays by the survival probability over the interval. Nothing is
//! allocated; the tracker is borrowed immutably.

use crate::readable_number::readable;

/// Why a prediction to a time was refused; nothing was written.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// The requested time is NaN or infinite.
    #[error("prediction time {} is not finite", readable(.timestamp_s))]
    NonFiniteTime {
        /// The requested time, s.
        timestamp_s: f64,
    },
    /// The requested time lies before the newest tracked frame: the tracker predicts forward
    /// only.
    #[error("prediction time {} s lies before the newest tracked frame at {} s", readable(.timestamp_s), readable(.newest_s))]
    BeforeNewestFrame {
        /// The requested time, s.
        timestamp_s: f64,
        /// The newest tracked frame's time, s.
        newest_s: f64,
    },
    /// The requested time lies further ahead of the newest tracked frame than
    /// `tracker.max_frame_interval_s`, beyond which the tracker would not bridge a gap either.
    #[error(
        "prediction time {} s lies {} s after the newest tracked frame, more than tracker.max_frame_interval_s ({} s)",
        readable(.timestamp_s),
        readable(.ahead_s),
        readable(.max_s)
    )]
    TooFarAhead {
        /// The requested time, s.
        timestamp_s: f64,
        /// How far ahead of the newest frame, s.
        ahead_s: f64,
        /// The configured limit, s.
        max_s: f64,
    },
}
