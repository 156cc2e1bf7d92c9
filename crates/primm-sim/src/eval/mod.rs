//! Offline evaluation of tracker output (paper, Section IV-A "Evaluation Metrics" and the result
//! tables `tab:prior_rmse`, `tab:scenario_rmse`, `tab:overall_mot`, `tab:scenario_mot`, plus the
//! mean mode probabilities of `fig:mode_probability`).
//!
//! The input is one [`AssociationRecord`] per ground-truth object frame (one measurement) and per
//! method. From those rows the module derives
//!
//! * one-step prior RMSE ([`rmse`]),
//! * identity metrics IDSW and IDF1 ([`identity`]),
//! * identity, false-track and fragmentation counts on the rows of confirmed tracks only, with
//!   clutter (rows without a ground-truth id) scored strictly ([`confirmed`]),
//! * motion-scenario labels for the scenario-wise RMSE table ([`scenario`]),
//! * the close-proximity and crossing-motion subsets of the scenario-wise tracking table
//!   ([`interaction`]) and the seeded measurement removal for its missed-detection rows
//!   ([`dropout`]),
//! * mean IMM mode probabilities ([`modes`]),
//! * the ego vehicle's motion (straight or turning) of each frame, for Tables II and IV split
//!   by it ([`ego_motion`]),
//! * the true reflection offset, detection probability and clutter density of each simulated
//!   sensor and class, the reference of the tracker's estimates of them ([`sensor_truth`]),
//! * velocity RMSE of the tracks and speed and heading errors of confirmed tracks, where the
//!   data carry true velocities ([`velocity`]),
//!
//! and assembles them into plain-text tables ([`report`]), a typed JSON document ([`document`])
//! and SVG figures ([`plots`]). [`evaluate()`] runs every method on a data set ([`evaluate`]).
//! The exact definitions, thresholds and units are documented in `docs/evaluation-metrics.md`.
//!
//! Nothing here is on the tracker's real-time path; clarity wins over speed.

pub mod confirmed;
pub mod document;
pub mod dropout;
pub mod ego_motion;
pub mod evaluate;
pub mod identity;
pub mod interaction;
pub mod modes;
pub mod plots;
pub mod record;
pub mod report;
pub mod rmse;
pub mod scenario;
pub mod sensor_estimates;
pub mod sensor_truth;
pub mod velocity;

pub use confirmed::{
    confirmed_track_counts, tracks_born_of_clutter, tracks_born_of_ghosts, ConfirmedTrackCounts,
    UnknownTrackStatus,
};
pub use document::ReportDocument;
pub use dropout::{sequence_seed, DropoutMask};
pub use evaluate::{
    evaluate, EvaluateError, Evaluation, EvaluationDocument, EvaluationSettings, Progress, Truth,
    DEFAULT_MISS_SEED,
};
pub use identity::{
    id_switch_rows, id_switches, identity_counts, identity_counts_subset, max_total_overlap, IdentityCounts,
};
pub use interaction::{interaction_flags, InteractionFlags, InteractionRules};
pub use modes::{ModeProbabilityAccumulator, MODE_NAMES};
pub use plots::{TrajectoryPanel, TrajectoryPlotOptions, TrajectoryPoint};
pub use record::{
    counts_as_confirmed, ground_truth_frame_rows, object_classes, object_frame_rows, AssociationRecord,
    EvalError, Method,
};
pub use report::{EvaluationReport, MethodEvaluator, MethodResult};
pub use rmse::RmseAccumulator;
pub use scenario::{classify_sequence, MotionCategory, MotionFeatures, MotionScenario, ScenarioRules};
pub use sensor_estimates::{
    compare_estimates_of_split, format_estimate_comparison, EstimateComparison, EstimateComparisonError,
    EstimatedQuantity,
};
pub use sensor_truth::{
    format_sensor_truth, sensor_truth_of_split, SensorClassTruth, SensorTruthAccumulator, UnknownSensor,
};
pub use velocity::{SpeedHeadingAccumulator, VelocityRmseAccumulator, HEADING_MIN_TRUE_SPEED_MPS};
