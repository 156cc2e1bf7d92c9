//! What the tracker counts: [`TrackerStats`] (generated from the list of counters in
//! `super::counters`), the totals since it was built or one step's counts; [`StepSummary`] per
//! step; and the bookkeeping that turns each rejection reason into its counter.

use super::counters::{counter_after_restore, define_tracker_stats};
use crate::coordinates::CoordinateFrame;
use crate::displacement_check::DisplacementRejection;
use crate::validation::{FrameError, MeasurementRejection};

crate::tracker_counters!(define_tracker_stats);

/// What one step did. Returned by [`Tracker::step_into`] and [`Tracker::step_observed`]; the
/// latest one is kept for [`Tracker::last_step`] (which is how [`Tracker::step`] reports it).
///
/// [`counts`](Self::counts) holds the step's own counts under the names of the totals, which
/// are their sums ([`Tracker::stats`]). For a late frame tracked in its place they are the
/// late frame's own (with `late_frames_tracked` 1 and `frames_replayed` the newer frames
/// tracked again), not the replayed frames'; the outputs are then the tracks at the newest
/// frame's time ([`Tracker::newest_timestamp_s`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StepSummary {
    /// What this step counted.
    pub counts: TrackerStats,
    /// Live tracks after the step: the number of outputs reported.
    pub live_tracks: usize,
    /// Confirmed tracks among the live ones.
    pub confirmed_tracks: usize,
    /// The frame the step tracked in.
    pub tracking_frame: CoordinateFrame,
}

impl StepSummary {
    /// Measurements of the frame rejected by validation, for any reason (unknown class code,
    /// NaN or infinite value, absurd magnitude; [`counts`](Self::counts) has each reason).
    pub fn measurements_rejected(&self) -> u64 {
        let counts = &self.counts;
        counts.measurements_rejected_unknown_class
            + counts.measurements_rejected_non_finite
            + counts.measurements_rejected_out_of_range
    }

    /// Learned displacements of the step rejected for any reason (non-finite, implausible,
    /// invalid covariance).
    pub fn learned_predictions_rejected(&self) -> u64 {
        let counts = &self.counts;
        counts.learned_predictions_rejected_non_finite
            + counts.learned_predictions_rejected_implausible
            + counts.learned_predictions_rejected_invalid_covariance
    }

    /// Whether the frame was late (older than the newest tracked frame) and tracked in its
    /// place.
    pub fn late(&self) -> bool {
        self.counts.late_frames_tracked > 0
    }

    /// Whether the frame's ego pose jumped from the previous one (an odometry reset).
    pub fn odometry_reset(&self) -> bool {
        self.counts.odometry_resets > 0
    }

    /// Whether the live tracks were moved into another frame at the start of the step.
    pub fn tracking_frame_changed(&self) -> bool {
        self.counts.tracking_frame_changes > 0
    }

    /// Whether a measurement of the frame named no configured sensor (see
    /// [`TrackerStats::frames_with_unknown_sensor`]).
    pub fn unknown_sensor(&self) -> bool {
        self.counts.frames_with_unknown_sensor > 0
    }

    /// Counts a learned displacement refused by the check of `crate::displacement_check`.
    pub(super) fn count_displacement_rejection(&mut self, reason: DisplacementRejection) {
        let counts = &mut self.counts;
        let counter = match reason {
            DisplacementRejection::NonFinite => &mut counts.learned_predictions_rejected_non_finite,
            DisplacementRejection::Implausible => &mut counts.learned_predictions_rejected_implausible,
            DisplacementRejection::InvalidCovariance => {
                &mut counts.learned_predictions_rejected_invalid_covariance
            }
        };
        *counter += 1;
    }
}

impl TrackerStats {
    /// Counts a frame refused by validation under its reason.
    pub(super) fn count_frame_rejection(&mut self, error: &FrameError) {
        let counter = match error {
            FrameError::NonFiniteTimestamp { .. } => &mut self.frames_rejected_non_finite_timestamp,
            FrameError::TimestampNotIncreasing { .. } => &mut self.frames_rejected_timestamp_not_increasing,
            FrameError::IntervalTooLong { .. } => &mut self.frames_rejected_interval_too_long,
            FrameError::TooManyMeasurements { .. } => &mut self.frames_rejected_too_many_measurements,
            FrameError::InvalidEgoPose { .. } => &mut self.frames_rejected_invalid_ego_pose,
            FrameError::TooLate { .. } => &mut self.frames_rejected_too_late,
        };
        *counter += 1;
    }

    /// Counts a measurement refused by validation under its reason.
    pub(super) fn count_measurement_rejection(&mut self, reason: MeasurementRejection) {
        let counter = match reason {
            MeasurementRejection::UnknownClass => &mut self.measurements_rejected_unknown_class,
            MeasurementRejection::NonFinite => &mut self.measurements_rejected_non_finite,
            MeasurementRejection::OutOfRange => &mut self.measurements_rejected_out_of_range,
        };
        *counter += 1;
    }
}
