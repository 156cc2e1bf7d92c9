//! What the tracker counts: [`TrackerStats`] since it was built, [`StepSummary`] per step, and
//! the bookkeeping that turns each rejection reason into its counter.

use crate::coordinates::CoordinateFrame;
use crate::displacement_check::DisplacementRejection;
use crate::validation::{FrameError, MeasurementRejection};

/// Counters of everything the tracker did or refused, since it was built.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TrackerStats {
    /// Frames tracked.
    pub frames_tracked: u64,
    /// Frames rejected because the timestamp was not finite.
    pub frames_rejected_non_finite_timestamp: u64,
    /// Frames rejected because time did not advance.
    pub frames_rejected_timestamp_not_increasing: u64,
    /// Frames rejected because the interval was too long.
    pub frames_rejected_interval_too_long: u64,
    /// Frames rejected because they carried too many measurements.
    pub frames_rejected_too_many_measurements: u64,
    /// Frames rejected because their ego pose was not finite or absurdly far out (only when
    /// tracking in the world frame; see [`EgoPose::is_valid`]).
    pub frames_rejected_invalid_ego_pose: u64,
    /// Frames tracked in the world frame (they carried an ego pose and the configuration asks
    /// for [`CoordinateFrame::World`]).
    pub frames_in_world_frame: u64,
    /// Frames tracked in the vehicle frame although the configuration asks for the world
    /// frame, because they carried no ego pose.
    pub frames_without_ego_pose: u64,
    /// Times the live tracks were moved between the world and the vehicle frame, because a
    /// stream started or stopped carrying ego poses.
    pub tracking_frame_changes: u64,
    /// Tracks started in the world frame by a measurement whose sensor has no configured
    /// mount: their line of sight starts at the vehicle's reference point.
    pub initiations_from_unknown_sensor: u64,
    /// Measurements tracked (accepted by validation).
    pub measurements_accepted: u64,
    /// Measurements rejected for an unknown class code.
    pub measurements_rejected_unknown_class: u64,
    /// Measurements rejected for a NaN or infinite value.
    pub measurements_rejected_non_finite: u64,
    /// Measurements rejected for an absurd magnitude.
    pub measurements_rejected_out_of_range: u64,
    /// Tracks started.
    pub tracks_initiated: u64,
    /// Tracks confirmed.
    pub tracks_confirmed: u64,
    /// Tracks deleted.
    pub tracks_deleted: u64,
    /// Unassigned measurements that could not start a track because the table was full.
    pub initiations_refused_table_full: u64,
    /// Track-frames in which the PR mode had no usable learned displacement and sat out: the
    /// predictor gave none (missed deadline, failed or hung inference) or its answer was
    /// rejected (the next two counters).
    pub learned_predictions_missing: u64,
    /// Frames in which at least one track had no usable learned displacement.
    pub frames_with_learned_predictions_missing: u64,
    /// Learned displacements rejected for a NaN or infinite component (included in
    /// `learned_predictions_missing`).
    pub learned_predictions_rejected_non_finite: u64,
    /// Learned displacements rejected as faster than `predictor.max_displacement_speed_mps`
    /// (included in `learned_predictions_missing`).
    pub learned_predictions_rejected_implausible: u64,
    /// Learned displacements rejected for a covariance that is not finite, symmetric, positive
    /// definite and of plausible size (included in `learned_predictions_missing`).
    pub learned_predictions_rejected_invalid_covariance: u64,
    /// Kalman updates refused for numerical reasons (the track coasted instead).
    pub update_failures: u64,
    /// Calls to [`Tracker::reset`].
    pub resets: u64,
    /// Frames with a measurement whose sensor has no configured mount (or no sensor id): such a
    /// radar is taken to look where its detections of the frame lie (`frame.unknown_sensor_*`),
    /// and a track there that it missed loses existence.
    pub frames_with_unknown_sensor: u64,
    /// Tracks merged into an older track of the same object (`crate::duplicates`).
    pub duplicate_tracks_merged: u64,
    /// Late frames tracked in their place (`crate::replay`): older than the newest tracked
    /// frame, within `tracker.max_frame_delay_s` and the recorded frames.
    pub late_frames_tracked: u64,
    /// Newer frames tracked again after a late frame (each late frame replays the frames it
    /// went before).
    pub frames_replayed: u64,
    /// Frames rejected because they were older than the newest tracked frame by more than the
    /// late-frame window (`tracker.max_frame_delay_s`, `tracker.replay_frames`) reaches.
    pub frames_rejected_too_late: u64,
    /// Ego poses that jumped further or turned faster than `tracker.max_ego_speed_mps` and
    /// `tracker.max_ego_yaw_rate_radps` allow since the previous frame: odometry resets, across
    /// which the tracks kept their place around the vehicle.
    pub odometry_resets: u64,
    /// Track updates in which the measurement's radial velocity was applied as a measurement of
    /// the velocity (`classes.<class>.radial_velocity_update`).
    pub radial_velocity_updates: u64,
    /// Track updates whose radial-velocity row lay beyond `radial_velocity_update.gate_std` in
    /// every mode and was left out.
    pub radial_velocity_updates_gated: u64,
    /// Track updates and initiations after which a velocity estimate was faster than the
    /// class's `max_speed_mps` and was scaled back onto it (steps with an ego pose only).
    pub speeds_bounded: u64,
    /// Updates and initiations of a class with a radial-velocity row or an extent whose
    /// measurement's sensor has no configured mount: seen from the vehicle's reference point.
    pub updates_from_unknown_sensor: u64,
    /// Unassigned measurements absorbed as extra detections of a confirmed track's extended
    /// object (`classes.<class>.extent.absorb_extra_detections`): they started no track.
    pub detections_absorbed: u64,
}

/// What one step did: the per-frame counterpart of [`TrackerStats`]. Returned by
/// [`Tracker::step_into`] and [`Tracker::step_observed`]; the latest one is kept for
/// [`Tracker::last_step`] (which is how [`Tracker::step`] reports it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StepSummary {
    /// Measurements of the frame accepted by validation.
    pub measurements_accepted: usize,
    /// Measurements of the frame rejected by validation (unknown class code, NaN or infinite
    /// value, absurd magnitude; [`TrackerStats`] counts each reason).
    pub measurements_rejected: usize,
    /// Existing tracks updated by a measurement of the frame.
    pub assigned: usize,
    /// Tracks started by an unassigned measurement.
    pub initiated: usize,
    /// Unassigned measurements that could not start a track because the table was full.
    pub initiations_refused_table_full: usize,
    /// Tracks confirmed in this step (a track started and confirmed at once included).
    pub newly_confirmed: usize,
    /// Kalman updates refused for numerical reasons (the track coasted instead).
    pub update_failures: usize,
    /// Tracks deleted.
    pub deleted: usize,
    /// Tracks for which the PR mode had no usable learned displacement and sat out (none given,
    /// or rejected: the next three counts). Tracks of a class outside `predictor.classes` are
    /// never requested and not counted here.
    pub predictions_missing: usize,
    /// Learned displacements rejected for a NaN or infinite component.
    pub predictions_rejected_non_finite: usize,
    /// Learned displacements rejected as faster than `predictor.max_displacement_speed_mps`.
    pub predictions_rejected_implausible: usize,
    /// Learned displacements rejected for an invalid covariance.
    pub predictions_rejected_invalid_covariance: usize,
    /// Live tracks after the step: the number of outputs reported.
    pub live_tracks: usize,
    /// Confirmed tracks among the live ones.
    pub confirmed_tracks: usize,
    /// The frame the step tracked in.
    pub tracking_frame: CoordinateFrame,
    /// Whether the live tracks were moved into another frame at the start of the step.
    pub tracking_frame_changed: bool,
    /// Tracks started by a measurement whose sensor has no configured mount (world frame only).
    pub initiations_from_unknown_sensor: usize,
    /// Tracks without a measurement that a sensor of the frame had in view (their existence
    /// fell); the others without one were out of every scanning sensor's view.
    pub missed_in_view: usize,
    /// Whether a measurement of the frame named no configured sensor (see
    /// [`TrackerStats::frames_with_unknown_sensor`]).
    pub unknown_sensor: bool,
    /// Tracks merged into an older track of the same object.
    pub duplicates_merged: usize,
    /// Whether the frame was late (older than the newest tracked frame) and tracked in its
    /// place. The outputs are then the tracks at the newest frame's time, after the newer
    /// frames were tracked again ([`Tracker::newest_timestamp_s`]); this summary's counts are
    /// the late frame's own, except `live_tracks` and `confirmed_tracks`.
    pub late: bool,
    /// Newer frames tracked again after this late frame.
    pub replayed_frames: usize,
    /// Whether the frame's ego pose jumped from the previous one (an odometry reset).
    pub odometry_reset: bool,
    /// Track updates with the radial-velocity row applied.
    pub radial_velocity_rows_applied: usize,
    /// Track updates whose radial-velocity row was gated out.
    pub radial_velocity_rows_gated: usize,
    /// Track updates and initiations after which a velocity was scaled back onto the class's
    /// highest speed.
    pub speeds_bounded: usize,
    /// Updates and initiations seen from the vehicle's reference point (no configured mount)
    /// by a class with a radial-velocity row or an extent.
    pub updates_from_unknown_sensor: usize,
    /// Unassigned measurements absorbed as extra detections of a confirmed extended track's
    /// object (they started no track).
    pub detections_absorbed: usize,
}

impl TrackerStats {
    /// Adds one step's counts (the rejected measurements are counted per reason where they are
    /// rejected).
    pub(super) fn add_step(&mut self, step: &StepSummary) {
        let count = |n: usize| n as u64;
        self.measurements_accepted += count(step.measurements_accepted);
        self.tracks_initiated += count(step.initiated);
        self.tracks_confirmed += count(step.newly_confirmed);
        self.tracks_deleted += count(step.deleted);
        self.initiations_refused_table_full += count(step.initiations_refused_table_full);
        self.learned_predictions_missing += count(step.predictions_missing);
        self.frames_with_learned_predictions_missing += u64::from(step.predictions_missing > 0);
        self.learned_predictions_rejected_non_finite += count(step.predictions_rejected_non_finite);
        self.learned_predictions_rejected_implausible += count(step.predictions_rejected_implausible);
        self.learned_predictions_rejected_invalid_covariance +=
            count(step.predictions_rejected_invalid_covariance);
        self.update_failures += count(step.update_failures);
        self.initiations_from_unknown_sensor += count(step.initiations_from_unknown_sensor);
        self.tracking_frame_changes += u64::from(step.tracking_frame_changed);
        self.frames_with_unknown_sensor += u64::from(step.unknown_sensor);
        self.duplicate_tracks_merged += count(step.duplicates_merged);
        self.odometry_resets += u64::from(step.odometry_reset);
        self.radial_velocity_updates += count(step.radial_velocity_rows_applied);
        self.radial_velocity_updates_gated += count(step.radial_velocity_rows_gated);
        self.speeds_bounded += count(step.speeds_bounded);
        self.updates_from_unknown_sensor += count(step.updates_from_unknown_sensor);
        self.detections_absorbed += count(step.detections_absorbed);
    }

    /// Goes back to `before` for everything a tracked frame changes, keeping what happened
    /// since to frames that were never tracked (frame rejections), resets and the late-frame
    /// counters: used when a late frame sends the tracker back to the state before newer frames
    /// that are then tracked again (and counted again).
    pub(super) fn restore_tracked_counts(&mut self, before: &TrackerStats) {
        let now = *self;
        *self = TrackerStats {
            frames_rejected_non_finite_timestamp: now.frames_rejected_non_finite_timestamp,
            frames_rejected_timestamp_not_increasing: now.frames_rejected_timestamp_not_increasing,
            frames_rejected_interval_too_long: now.frames_rejected_interval_too_long,
            frames_rejected_too_many_measurements: now.frames_rejected_too_many_measurements,
            frames_rejected_invalid_ego_pose: now.frames_rejected_invalid_ego_pose,
            frames_rejected_too_late: now.frames_rejected_too_late,
            late_frames_tracked: now.late_frames_tracked,
            frames_replayed: now.frames_replayed,
            resets: now.resets,
            ..*before
        };
    }

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

impl StepSummary {
    /// Counts a learned displacement refused by the check of `crate::displacement_check`.
    pub(super) fn count_displacement_rejection(&mut self, reason: DisplacementRejection) {
        let counter = match reason {
            DisplacementRejection::NonFinite => &mut self.predictions_rejected_non_finite,
            DisplacementRejection::Implausible => &mut self.predictions_rejected_implausible,
            DisplacementRejection::InvalidCovariance => &mut self.predictions_rejected_invalid_covariance,
        };
        *counter += 1;
    }
}
