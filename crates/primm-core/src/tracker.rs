//! The multi-object tracker: one [`Tracker::step`] per frame, allocating nothing.
//!
//! The step reads like the algorithm of the paper (Section III): validate, predict every
//! mode of every track (the learned predictor runs on its batch meanwhile), fuse the priors,
//! associate per class, update, coast, initiate, delete, report. Each role is a method below.
//! Every step also returns (or keeps, for [`Tracker::last_step`]) a [`StepSummary`] of what it
//! did; [`TrackerStats`] adds the summaries up since the tracker was built.
//! The tracker never reads a clock: time comes from frames, so a replay is bit-for-bit
//! repeatable.

use crate::association::assignment::AssignmentError;
use crate::association::associator::{AssociationStats, Associator};
use crate::config::{Config, ConfigError, LearnedProcessNoise};
use crate::displacement_check::{check_answer, DisplacementRejection};
use crate::duplicates::{self, DuplicateView};
use crate::existence::{self, Evidence, FieldOfView, Lifecycle};
use crate::extent::ExpectedReflection;
use crate::gaussian::RadialVelocityOutcome;
use crate::imm::ImmPrior;
use crate::limits::MAX_SENSORS;
use crate::measurement::{FrameView, Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::mode::{Mode, ModeSet};
use crate::motion::ModeModels;
use crate::pose::{EgoPose, RigidTransform};
use crate::prediction::PredictError;
use crate::predictor::{Displacement, DisplacementPredictor, NoPredictor, PredictionRequest};
use crate::recorded_frame::RecordedFrame;
use crate::replay::{Placement, ReplayRing};
use crate::stage_timing::{NoObserver, Stage, StageObserver};
use crate::track::{Track, TrackOutput, TrackStatus};
use crate::track_loops::{self, ClassImms};
use crate::track_table::{TrackTable, MAX_TRACKS};
use crate::tracking_frame::TrackingFrame;
use crate::validated_frame::ValidatedFrame;
use crate::validation::{validate_frame, validate_measurement, FrameError, MeasurementRejection};
use alloc::boxed::Box;
use alloc::vec;
use arrayvec::ArrayVec;
use glam::{DMat2, DVec2};

/// Why a step failed. The tracker's tracks are exactly as before the frame (after an
/// association failure, up to a change of their frame; see [`TrackingFrame`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The frame was rejected by validation.
    #[error("frame rejected: {0}")]
    InvalidFrame(#[from] FrameError),
    /// The assignment solver refused the problem (cannot happen with the tracker's own
    /// capacities; reported rather than panicking).
    #[error("association failed: {0}")]
    Association(#[from] AssignmentError),
}

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
    /// for [`TrackingFrame::World`]).
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
    /// Frames with a measurement whose sensor has no configured mount (or no sensor id): every
    /// track counted as in view of that sensor, so misses counted against existence.
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
    pub tracking_frame: TrackingFrame,
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
    fn add_step(&mut self, step: &StepSummary) {
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
        self.updates_from_unknown_sensor += count(step.updates_from_unknown_sensor);
        self.detections_absorbed += count(step.detections_absorbed);
    }

    /// Goes back to `before` for everything a tracked frame changes, keeping what happened
    /// since to frames that were never tracked (frame rejections), resets and the late-frame
    /// counters: used when a late frame sends the tracker back to the state before newer frames
    /// that are then tracked again (and counted again).
    fn restore_tracked_counts(&mut self, before: &TrackerStats) {
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
}

/// What happened to each measurement of the current frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum MeasurementFate {
    Rejected,
    Unassigned,
    Assigned,
}

/// What one live track did in the current frame, aligned with the track table's rows.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RowRecord {
    prior_position_m: Option<DVec2>,
    available: ModeSet,
    measurement_index: Option<u16>,
}

const EMPTY_ROW: RowRecord =
    RowRecord { prior_position_m: None, available: ModeSet::EMPTY, measurement_index: None };

/// A sensor that scanned in the current frame, in the tracking frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ScanningSensor {
    id: u16,
    field_of_view: FieldOfView,
    detection_probability_factor: f64,
    clutter_density_factor: f64,
}

/// The detection probabilities are kept below 1, so that a miss never makes existence 0.
const MAX_DETECTION_PROBABILITY: f64 = 0.999;

/// The PR-IMM multi-object tracker with a learned-displacement predictor `P`.
#[derive(Debug)]
pub struct Tracker<P: DisplacementPredictor = NoPredictor> {
    config: Config,
    /// Each class's IMM (`classes.<class>.imm` over `imm`), indexed by [`ObjectClass::index`].
    imms: ClassImms,
    models: [ModeModels; ObjectClass::COUNT],
    predictor: P,
    table: TrackTable,
    associator: Associator,
    last_timestamp_s: Option<f64>,
    stats: TrackerStats,
    /// What the latest step did.
    last_step: StepSummary,
    /// The frame the live tracks are in.
    tracks_frame: TrackingFrame,
    /// The ego pose of the current step when it tracks in the world frame, else `None`.
    step_pose: Option<EgoPose>,
    /// The ego pose of the latest step tracked in the world frame.
    last_pose: Option<EgoPose>,
    // Per-frame workspaces, allocated once.
    requests: Box<ArrayVec<PredictionRequest, MAX_TRACKS>>,
    /// The table row of each request's track (`predictor.classes` may leave tracks out).
    requested_rows: Box<ArrayVec<u16, MAX_TRACKS>>,
    /// The predictor's answers, aligned with `requests`.
    answers: Box<[Option<Displacement>; MAX_TRACKS]>,
    /// Each track's checked displacement, aligned with the table (`None`: the PR mode sits out).
    displacements: Box<[Option<Displacement>; MAX_TRACKS]>,
    /// Each track's prior of the current frame (the first `table.len()` entries).
    priors: Box<[ImmPrior]>,
    /// Interval of the current frame, s.
    dt_s: f64,
    track_to_measurement: Box<[Option<u16>; MAX_TRACKS]>,
    /// Each track's assigned measurement of the current frame (`None`: none).
    assigned_measurements: Box<[Option<Measurement>; MAX_TRACKS]>,
    /// Where the radar of each track's assigned measurement is, in the tracking frame.
    assigned_sensor_positions: Box<[DVec2; MAX_TRACKS]>,
    /// Where the radar of each measurement of the current frame is, in the tracking frame (its
    /// mount; the vehicle's reference point when it has none), and whether it had a mount.
    measurement_sensors: Box<[(DVec2, bool); MAX_MEASUREMENTS_PER_FRAME]>,
    /// Each track's update outcome of the current frame.
    update_outcomes: Box<[track_loops::UpdateOutcome; MAX_TRACKS]>,
    rows: Box<[RowRecord; MAX_TRACKS]>,
    fates: Box<[MeasurementFate; MAX_MEASUREMENTS_PER_FRAME]>,
    accepted: Box<[bool; MAX_MEASUREMENTS_PER_FRAME]>,
    /// The fields of view of the sensors that scanned in the current frame, with their
    /// detection-probability and clutter-density factors.
    scanning_sensors: Box<ArrayVec<ScanningSensor, MAX_SENSORS>>,
    /// Each live track's fused state for the duplicate check, aligned with the table.
    duplicate_views: Box<[DuplicateView; MAX_TRACKS]>,
    /// Tracks merged into an older one in the current frame, aligned with the table.
    merged: Box<[bool; MAX_TRACKS]>,
    /// The current frame as read once from the caller; validation reads only this copy.
    recorded: Box<RecordedFrame>,
    /// The current frame as validated; every later stage reads this copy.
    validated: Box<ValidatedFrame>,
    /// The recent frames and the state before each, for late frames.
    ring: ReplayRing,
    outputs: Box<ArrayVec<TrackOutput, MAX_TRACKS>>,
}

impl Tracker<NoPredictor> {
    /// A tracker without learned predictor (for methods without the PR mode).
    pub fn new(config: Config) -> Result<Self, ConfigError> {
        Self::with_predictor(config, NoPredictor)
    }
}

impl<P: DisplacementPredictor> Tracker<P> {
    /// A tracker using `predictor` for the PR mode. Validates `config`.
    pub fn with_predictor(config: Config, predictor: P) -> Result<Self, ConfigError> {
        config.validate()?;
        let ring = ReplayRing::new(config.tracker.replay_frames as usize, config.tracker.max_frame_delay_s);
        Ok(Self {
            imms: track_loops::class_imms(&config),
            models: ObjectClass::ALL.map(|class| ModeModels::from_config(config.classes.get(class))),
            config,
            predictor,
            table: TrackTable::new(),
            associator: Associator::new(),
            last_timestamp_s: None,
            stats: TrackerStats::default(),
            last_step: StepSummary::default(),
            tracks_frame: TrackingFrame::Vehicle,
            step_pose: None,
            last_pose: None,
            requests: Box::new(ArrayVec::new()),
            requested_rows: Box::new(ArrayVec::new()),
            answers: Box::new([None; MAX_TRACKS]),
            displacements: Box::new([None; MAX_TRACKS]),
            priors: vec![ImmPrior::default(); MAX_TRACKS].into_boxed_slice(),
            dt_s: 0.0,
            track_to_measurement: Box::new([None; MAX_TRACKS]),
            assigned_measurements: Box::new([None; MAX_TRACKS]),
            assigned_sensor_positions: Box::new([DVec2::ZERO; MAX_TRACKS]),
            measurement_sensors: Box::new([(DVec2::ZERO, false); MAX_MEASUREMENTS_PER_FRAME]),
            update_outcomes: Box::new([Ok(None); MAX_TRACKS]),
            rows: Box::new([EMPTY_ROW; MAX_TRACKS]),
            fates: Box::new([MeasurementFate::Rejected; MAX_MEASUREMENTS_PER_FRAME]),
            accepted: Box::new([false; MAX_MEASUREMENTS_PER_FRAME]),
            scanning_sensors: Box::new(ArrayVec::new()),
            duplicate_views: Box::new([DuplicateView::default(); MAX_TRACKS]),
            merged: Box::new([false; MAX_TRACKS]),
            recorded: Box::new(RecordedFrame::new()),
            validated: Box::new(ValidatedFrame::new()),
            ring,
            outputs: Box::new(ArrayVec::new()),
        })
    }

    /// Tracks one frame and returns the state of every live track; [`last_step`](Self::last_step)
    /// then says what the step did (the outputs borrow the tracker: read it once done with
    /// them).
    pub fn step<F: FrameView + ?Sized>(&mut self, frame: &F) -> Result<&[TrackOutput], StepError> {
        self.advance(frame, &mut NoObserver)?;
        self.outputs.clear();
        let outputs = &mut self.outputs;
        let to_vehicle = self.step_pose.map(|pose| pose.world_to_vehicle());
        let t = self.last_timestamp_s.unwrap_or(0.0);
        report(&self.table, &self.rows[..], &self.imms, to_vehicle, t, |output| outputs.push(*output));
        Ok(&self.outputs)
    }

    /// Tracks one frame and hands every live track's output to `sink`, in table order, instead
    /// of collecting them: lets a caller write them straight into their destination (e.g. a
    /// loaned shared-memory sample). Returns what the step did (its
    /// [`live_tracks`](StepSummary::live_tracks) is the number of outputs).
    pub fn step_into<F: FrameView + ?Sized>(
        &mut self,
        frame: &F,
        sink: impl FnMut(&TrackOutput),
    ) -> Result<StepSummary, StepError> {
        self.step_observed(frame, &mut NoObserver, sink)
    }

    /// [`step_into`](Self::step_into), telling `observer` when each [`Stage`] finishes, so
    /// that a caller can time the stages with its own clock.
    pub fn step_observed<F: FrameView + ?Sized, O: StageObserver>(
        &mut self,
        frame: &F,
        observer: &mut O,
        sink: impl FnMut(&TrackOutput),
    ) -> Result<StepSummary, StepError> {
        self.advance(frame, observer)?;
        let to_vehicle = self.step_pose.map(|pose| pose.world_to_vehicle());
        let t = self.last_timestamp_s.unwrap_or(0.0);
        report(&self.table, &self.rows[..], &self.imms, to_vehicle, t, sink);
        observer.stage_finished(Stage::Report);
        Ok(self.last_step)
    }

    /// Everything but the report; counts what the step did into
    /// [`last_step`](Self::last_step) and the statistics, also when it fails. Reads `frame`
    /// once, into the tracker's own copy; a late frame is tracked in its place
    /// (`crate::replay`).
    fn advance<F: FrameView + ?Sized, O: StageObserver>(
        &mut self,
        frame: &F,
        observer: &mut O,
    ) -> Result<(), StepError> {
        self.recorded.read_from(frame);
        match self.ring.place(self.recorded.timestamp_s(), self.last_timestamp_s) {
            Placement::InOrder | Placement::Duplicate => self.track_in_order(observer),
            Placement::Before(position) => self.track_late(position, observer),
            Placement::TooLate => {
                self.last_step = StepSummary::default();
                self.count_live_tracks();
                self.stats.frames_rejected_too_late += 1;
                Err(StepError::InvalidFrame(FrameError::TooLate {
                    timestamp_s: self.recorded.timestamp_s(),
                    newest_s: self.last_timestamp_s.unwrap_or(f64::NAN),
                }))
            }
        }
    }

    /// Tracks the recorded frame after the newest one, first saving the state before it in the
    /// ring (and recording the frame there once tracked).
    fn track_in_order<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        if !self.ring.is_enabled() {
            return self.track_recorded(observer);
        }
        let slot = self.ring.spare();
        self.save_state(slot);
        let result = self.track_recorded(observer);
        if result.is_ok() {
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            self.ring.insert(slot, self.ring.len());
            self.ring.trim(self.recorded_newest_s());
        }
        result
    }

    /// Tracks a late recorded frame in its place, before the recorded frame at `position`:
    /// back to the state before that frame, the late frame, then every newer recorded frame
    /// again. The frame is checked against its place first, so that a frame refused there
    /// changes nothing.
    fn track_late<O: StageObserver>(&mut self, position: usize, observer: &mut O) -> Result<(), StepError> {
        let newer = self.ring.slot_at(position);
        let newest_s = self.last_timestamp_s;
        self.last_step = StepSummary::default();
        self.last_timestamp_s = self.ring.slot(newer).before.last_timestamp_s;
        let check = self.validate();
        self.last_timestamp_s = newest_s;
        if let Err(error) = check {
            self.count_live_tracks();
            return Err(error);
        }
        self.restore_state(newer);
        let late = self.ring.spare();
        self.ring.copy_snapshot(newer, late);
        let result = self.track_recorded(observer);
        let mut summary = self.last_step;
        let mut next = position;
        if result.is_ok() {
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(late).frame);
            self.ring.insert(late, position);
            self.stats.late_frames_tracked += 1;
            next += 1;
        }
        while next < self.ring.len() {
            let slot = self.ring.slot_at(next);
            self.save_state(slot);
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            let replayed = self.track_recorded(observer);
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            if replayed.is_ok() {
                summary.replayed_frames += 1;
                next += 1;
            } else {
                // Cannot happen for a frame tracked before (its interval only shrank); it is
                // dropped from the ring rather than tracked half.
                self.ring.remove(next);
            }
        }
        self.ring.trim(self.recorded_newest_s());
        self.stats.frames_replayed += summary.replayed_frames as u64;
        summary.late = true;
        self.last_step = summary;
        self.count_live_tracks();
        result
    }

    /// The newest tracked frame's time, s (0 before the first).
    fn recorded_newest_s(&self) -> f64 {
        self.last_timestamp_s.unwrap_or(0.0)
    }

    /// Saves the state before the next frame into ring slot `slot`.
    fn save_state(&mut self, slot: usize) {
        let before = &mut self.ring.slot_mut(slot).before;
        before.next_id = self.table.save(&mut before.tracks);
        before.last_timestamp_s = self.last_timestamp_s;
        before.tracks_frame = self.tracks_frame;
        before.last_pose = self.last_pose;
        before.stats = self.stats;
    }

    /// Puts the tracker back into the state saved in ring slot `slot`.
    fn restore_state(&mut self, slot: usize) {
        let before = &self.ring.slot(slot).before;
        self.table.restore(&before.tracks, before.next_id);
        self.last_timestamp_s = before.last_timestamp_s;
        self.tracks_frame = before.tracks_frame;
        self.last_pose = before.last_pose;
        self.stats.restore_tracked_counts(&before.stats);
    }

    /// Tracks the recorded frame; counts what it did into [`last_step`](Self::last_step) and
    /// the statistics, also when it fails.
    fn track_recorded<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        self.last_step = StepSummary::default();
        let result = self.run_stages(observer);
        self.count_live_tracks();
        self.stats.add_step(&self.last_step);
        result
    }

    /// The live and confirmed tracks into [`last_step`](Self::last_step).
    fn count_live_tracks(&mut self) {
        self.last_step.live_tracks = self.table.len();
        self.last_step.confirmed_tracks =
            self.table.tracks().iter().filter(|track| track.status.is_confirmed()).count();
    }

    /// The stages of a step up to the report, on the recorded frame.
    fn run_stages<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        let dt_s = self.validate()?;
        observer.stage_finished(Stage::Validate);
        // From here on only the validated copy is read.
        let t = self.validated.timestamp_s();
        self.enter_tracking_frame(self.validated.ego_pose(), dt_s);
        if let Some(vehicle_to_world) = self.step_pose.map(|pose| pose.vehicle_to_world()) {
            self.validated.move_positions(&vehicle_to_world);
        }
        self.find_scanning_sensors();
        self.request_learned_predictions(t);
        self.predict_physics(dt_s);
        self.predict_existence(dt_s);
        observer.stage_finished(Stage::Predict);
        self.fuse_priors();
        observer.stage_finished(Stage::LearnedWait);
        self.associate()?;
        observer.stage_finished(Stage::Associate);
        self.update(t);
        self.coast();
        self.initiate(t);
        self.delete(t);
        self.merge_duplicates();
        observer.stage_finished(Stage::Update);
        self.last_timestamp_s = Some(t);
        self.stats.frames_tracked += 1;
        Ok(())
    }

    /// Decides the frame of this step from the frame's ego pose and the configuration, and
    /// moves the live tracks into it if they are in the other one: into the world frame with
    /// this frame's pose (the tracks' vehicle frame is taken as this frame's, which is off by
    /// the ego motion since the last frame), back into the vehicle frame of the last pose.
    fn enter_tracking_frame(&mut self, pose: Option<EgoPose>, dt_s: f64) {
        let world = self.config.frame.tracking_frame == TrackingFrame::World;
        self.step_pose = pose.filter(|_| world);
        self.follow_odometry_reset(dt_s);
        let step_frame = if self.step_pose.is_some() { TrackingFrame::World } else { TrackingFrame::Vehicle };
        self.last_step.tracking_frame = step_frame;
        if world && pose.is_none() {
            self.stats.frames_without_ego_pose += 1;
        }
        if step_frame == TrackingFrame::World {
            self.stats.frames_in_world_frame += 1;
        }
        if step_frame != self.tracks_frame && !self.table.is_empty() {
            let transform = match (step_frame, self.step_pose, self.last_pose) {
                (TrackingFrame::World, Some(pose), _) => Some(pose.vehicle_to_world()),
                (TrackingFrame::Vehicle, _, Some(last)) => Some(last.world_to_vehicle()),
                _ => None,
            };
            if let Some(transform) = transform {
                self.table.tracks_mut().iter_mut().for_each(|track| track.transform(&transform));
                self.last_step.tracking_frame_changed = true;
            }
        }
        self.tracks_frame = step_frame;
        if self.step_pose.is_some() {
            self.last_pose = self.step_pose;
        }
    }

    /// Moves the live world-frame tracks across an odometry reset: when this frame's pose is
    /// further from the last one, or turned further, than `tracker.max_ego_speed_mps` and
    /// `tracker.max_ego_yaw_rate_radps` allow over `dt_s` (plus 1 m and 0.1 rad), the vehicle
    /// cannot have moved so; the world frame did. The tracks keep their place around the
    /// vehicle: into its frame with the last pose, back out with this one.
    fn follow_odometry_reset(&mut self, dt_s: f64) {
        let (Some(pose), Some(last)) = (self.step_pose, self.last_pose) else { return };
        if self.tracks_frame != TrackingFrame::World {
            return;
        }
        let tracker = &self.config.tracker;
        let moved_m = pose.position().distance(last.position());
        let turned_rad = crate::math::wrap_angle(pose.yaw_rad - last.yaw_rad).abs();
        let jumped = moved_m > tracker.max_ego_speed_mps * dt_s + 1.0
            || turned_rad > tracker.max_ego_yaw_rate_radps * dt_s + 0.1;
        if !jumped {
            return;
        }
        self.last_step.odometry_reset = true;
        let (to_vehicle, to_world) = (last.world_to_vehicle(), pose.vehicle_to_world());
        for track in self.table.tracks_mut() {
            track.transform(&to_vehicle);
            track.transform(&to_world);
        }
    }

    /// Frame checks, then per-measurement checks; counts every rejection. Reads the recorded
    /// copy of the frame into [`ValidatedFrame`] and checks that.
    fn validate(&mut self) -> Result<f64, StepError> {
        let frame = &*self.recorded;
        self.validated.read_header(frame);
        if self.config.frame.tracking_frame == TrackingFrame::World {
            if let Some(pose) = self.validated.ego_pose().filter(|pose| !pose.is_valid()) {
                self.stats.frames_rejected_invalid_ego_pose += 1;
                return Err(StepError::InvalidFrame(FrameError::InvalidEgoPose {
                    x_m: pose.x_m,
                    y_m: pose.y_m,
                    yaw_rad: pose.yaw_rad,
                }));
            }
        }
        let dt_s = validate_frame(&*self.validated, self.last_timestamp_s, &self.config.tracker)
            .inspect_err(|error| {
                let counter = match error {
                    FrameError::NonFiniteTimestamp { .. } => {
                        &mut self.stats.frames_rejected_non_finite_timestamp
                    }
                    FrameError::TimestampNotIncreasing { .. } => {
                        &mut self.stats.frames_rejected_timestamp_not_increasing
                    }
                    FrameError::IntervalTooLong { .. } => &mut self.stats.frames_rejected_interval_too_long,
                    FrameError::TooManyMeasurements { .. } => {
                        &mut self.stats.frames_rejected_too_many_measurements
                    }
                    FrameError::InvalidEgoPose { .. } => &mut self.stats.frames_rejected_invalid_ego_pose,
                    FrameError::TooLate { .. } => &mut self.stats.frames_rejected_too_late,
                };
                *counter += 1;
            })?;
        for index in 0..self.validated.len() {
            let verdict = validate_measurement(&*self.recorded, index);
            self.validated.set(index, verdict.ok());
            self.accepted[index] = verdict.is_ok();
            self.fates[index] =
                if verdict.is_ok() { MeasurementFate::Unassigned } else { MeasurementFate::Rejected };
            let rejections = match verdict {
                Ok(_) => {
                    self.last_step.measurements_accepted += 1;
                    continue;
                }
                Err(MeasurementRejection::UnknownClass) => {
                    &mut self.stats.measurements_rejected_unknown_class
                }
                Err(MeasurementRejection::NonFinite) => &mut self.stats.measurements_rejected_non_finite,
                Err(MeasurementRejection::OutOfRange) => &mut self.stats.measurements_rejected_out_of_range,
            };
            *rejections += 1;
            self.last_step.measurements_rejected += 1;
        }
        Ok(dt_s)
    }

    /// Hands the history (`eq:pr_input`) of every track of a class in `predictor.classes` to
    /// the learned predictor.
    fn request_learned_predictions(&mut self, t: f64) {
        self.requests.clear();
        self.requested_rows.clear();
        let modes = self.config.imm.modes;
        if !modes.contains(Mode::Learned) {
            return;
        }
        for (row, track) in self.table.tracks().iter().enumerate() {
            if !self.config.predictor.predicts(track.class, modes) {
                continue;
            }
            let (older, newer) = track.history.as_slices();
            let mut window = [Default::default(); crate::predictor::MAX_HISTORY];
            let len = older.len() + newer.len();
            window[..older.len()].copy_from_slice(older);
            window[older.len()..len].copy_from_slice(newer);
            let step_start = self.last_timestamp_s.unwrap_or(t);
            self.requests
                .push(PredictionRequest::from_history(&window[..len], t).with_step_start(step_start));
            // The table holds at most MAX_TRACKS (512) rows, so the row fits in u16.
            self.requested_rows.push(row as u16);
        }
        self.predictor.submit(&self.requests);
    }

    /// Mixing and the CV, CA and CT predictions, while the predictor works.
    fn predict_physics(&mut self, dt_s: f64) {
        self.dt_s = dt_s;
        track_loops::predict_physics(
            &self.imms,
            &self.models,
            self.table.tracks(),
            dt_s,
            &mut self.priors[..],
        );
    }

    /// Every track's object may have ceased to exist since the last frame: `r⁻ = p_s · r`.
    fn predict_existence(&mut self, dt_s: f64) {
        let survival = existence::survival_probability(dt_s, &self.config.tracker);
        for track in self.table.tracks_mut() {
            track.existence_probability *= survival;
        }
    }

    /// The sensors that scanned in this frame, as its measurements name them, with their fields
    /// of view in the tracking frame. A measurement without a sensor id or of a sensor without a
    /// configured mount marks the frame (every track then counts as in view).
    fn find_scanning_sensors(&mut self) {
        self.scanning_sensors.clear();
        for index in 0..self.validated.len() {
            let Some(measurement) = self.validated.accepted(index) else { continue };
            let mount = measurement.sensor_id.and_then(|id| self.config.frame.sensor(id));
            let Some(mount) = mount else {
                self.last_step.unknown_sensor = true;
                continue;
            };
            if self.scanning_sensors.iter().any(|sensor| sensor.id == mount.id) {
                continue;
            }
            // There are at most MAX_SENSORS configured mounts, so this never overflows.
            let _ = self.scanning_sensors.try_push(ScanningSensor {
                id: mount.id,
                field_of_view: FieldOfView::of(mount, self.step_pose),
                detection_probability_factor: mount.detection_probability_factor,
                clutter_density_factor: mount.clutter_density_factor,
            });
        }
    }

    /// The detection probability and clutter density of `class` for the sensor `sensor_id`
    /// (the class's own for a sensor without a configured mount).
    fn detection_and_clutter(&self, class: ObjectClass, sensor_id: Option<u16>) -> (f64, f64) {
        let existence = &self.config.classes.get(class).existence;
        let (detection, clutter) = match sensor_id.and_then(|id| self.config.frame.sensor(id)) {
            Some(mount) => (mount.detection_probability_factor, mount.clutter_density_factor),
            None => (1.0, 1.0),
        };
        (
            (existence.detection_probability * detection).min(MAX_DETECTION_PROBABILITY),
            existence.clutter_density_per_m2 * clutter,
        )
    }

    /// Collects and checks the displacements (`displacement_check.rs`) and hands each to its
    /// track's row (a track without a request gets none); the PR priors and the fused priors
    /// (`eq:prior_fusion`).
    fn fuse_priors(&mut self) {
        let count = self.table.len();
        let displacements = &mut self.displacements[..count];
        displacements.fill(None);
        if !self.requests.is_empty() {
            let answers = &mut self.answers[..self.requests.len()];
            self.predictor.collect(answers);
            let predictor = &self.config.predictor;
            for (displacement, request) in answers.iter_mut().zip(self.requests.iter()) {
                let Some(answer) = displacement.as_mut() else { continue };
                let counter = match check_answer(request, answer, predictor.max_displacement_speed_mps) {
                    Ok(()) => {
                        answer.covariance_m2 = match predictor.process_noise {
                            LearnedProcessNoise::Learned => {
                                answer.covariance_m2.map(|q| q * predictor.learned_process_noise_scale)
                            }
                            LearnedProcessNoise::Constant => None,
                        };
                        continue;
                    }
                    Err(DisplacementRejection::NonFinite) => {
                        &mut self.last_step.predictions_rejected_non_finite
                    }
                    Err(DisplacementRejection::Implausible) => {
                        &mut self.last_step.predictions_rejected_implausible
                    }
                    Err(DisplacementRejection::InvalidCovariance) => {
                        &mut self.last_step.predictions_rejected_invalid_covariance
                    }
                };
                *counter += 1;
                *displacement = None;
            }
            self.last_step.predictions_missing = answers.iter().filter(|d| d.is_none()).count();
            for (answer, &row) in answers.iter().zip(self.requested_rows.iter()) {
                displacements[usize::from(row)] = *answer;
            }
        }
        track_loops::complete_priors(
            &self.imms,
            &self.models,
            self.table.tracks(),
            self.dt_s,
            displacements,
            &mut self.priors[..],
        );
    }

    /// Per-class gated optimal assignment (`eq:association_cost`).
    fn associate(&mut self) -> Result<(), StepError> {
        self.locate_measurement_sensors();
        self.associator.associate(
            self.table.tracks(),
            &self.priors[..self.table.len()],
            &*self.validated,
            &self.accepted[..self.validated.len()],
            &self.measurement_sensors[..self.validated.len()],
            &self.config,
            &mut self.track_to_measurement[..],
        )?;
        Ok(())
    }

    /// Where the radar of every accepted measurement is, in the tracking frame: its mount,
    /// mapped into the world in a world-frame step; without a configured mount the vehicle's
    /// reference point (flagged, and counted where a row or an extent uses it).
    fn locate_measurement_sensors(&mut self) {
        for index in 0..self.validated.len() {
            let Some(measurement) = self.validated.accepted(index) else { continue };
            let mount =
                measurement.sensor_id.and_then(|id| self.config.frame.sensor(id)).map(|m| m.position());
            let in_vehicle = mount.unwrap_or(DVec2::ZERO);
            let position = match self.step_pose {
                Some(pose) => pose.car_to_world(in_vehicle),
                None => in_vehicle,
            };
            self.measurement_sensors[index] = (position, mount.is_some());
        }
    }

    /// Whether a confirmed track among the first `tracks` (those with a prior this frame) of the
    /// measurement's class, tracked as an extended object that absorbs extra detections, has
    /// `measurement` on its object ([`crate::extent::lies_on_object`], at the track's prior).
    fn absorbed_by_a_track(&self, measurement: &Measurement, tracks: usize) -> bool {
        let extent = &self.config.classes.get(measurement.class).extent;
        if !(extent.enabled && extent.absorb_extra_detections) {
            return false;
        }
        self.table.tracks()[..tracks].iter().zip(&self.priors[..tracks]).any(|(track, prior)| {
            track.class == measurement.class
                && track.status.is_confirmed()
                && crate::extent::lies_on_object(
                    extent,
                    prior.fused.mean,
                    prior.fused_velocity_mps(),
                    measurement.position(),
                )
        })
    }

    /// The expected reflection of track `i`'s object for a sensor at `sensor_m` (a point class:
    /// none).
    fn expected_reflection(&self, i: usize, sensor_m: DVec2) -> ExpectedReflection {
        let class = self.table.tracks()[i].class;
        let models = &self.models[class.index()];
        match models.extent {
            Some(_) => {
                let prior = &self.priors[i];
                models.expected_reflection(&prior.object_prior(), sensor_m)
            }
            None => ExpectedReflection::POINT,
        }
    }

    /// Kalman and mode-probability update of every assigned track.
    fn update(&mut self, t: f64) {
        let count = self.table.len();
        for i in 0..count {
            // An accepted measurement always reads back; if one did not, the track coasts rather
            // than keep a stale state.
            self.assigned_measurements[i] =
                self.track_to_measurement[i].and_then(|index| self.validated.accepted(usize::from(index)));
            let (Some(index), Some(measurement)) =
                (self.track_to_measurement[i], self.assigned_measurements[i])
            else {
                self.track_to_measurement[i] = None;
                continue;
            };
            let (sensor_m, mounted) = self.measurement_sensors[usize::from(index)];
            self.assigned_sensor_positions[i] = sensor_m;
            let models = &self.models[measurement.class.index()];
            if !mounted && (models.radial_velocity_update.enabled || models.extent.is_some()) {
                self.last_step.updates_from_unknown_sensor += 1;
            }
        }
        track_loops::update(
            &self.imms,
            &self.models,
            self.table.tracks_mut(),
            &self.priors[..count],
            &self.assigned_measurements[..count],
            &self.assigned_sensor_positions[..count],
            // Radial velocities are over ground: they measure the velocity of world-frame
            // tracks, not of vehicle-frame tracks of an ego whose motion is unknown.
            self.step_pose.is_some(),
            &mut self.update_outcomes[..count],
        );
        for i in 0..count {
            let (Some(index), Some(measurement)) =
                (self.track_to_measurement[i], self.assigned_measurements[i])
            else {
                continue;
            };
            if let Ok(radial_velocity) = self.update_outcomes[i] {
                match radial_velocity {
                    Some(RadialVelocityOutcome::Applied) => self.last_step.radial_velocity_rows_applied += 1,
                    Some(RadialVelocityOutcome::Gated) => self.last_step.radial_velocity_rows_gated += 1,
                    Some(RadialVelocityOutcome::NoLineOfSight) | None => {}
                }
                let class = self.table.tracks()[i].class;
                let (detection, clutter) = self.detection_and_clutter(class, measurement.sensor_id);
                let reflection = self.expected_reflection(i, self.assigned_sensor_positions[i]);
                let prior = &self.priors[i].fused;
                let likelihood = existence::gaussian_density_per_m2(
                    measurement.position() - reflection.offset_m - prior.mean,
                    prior.covariance
                        + covariance(&self.config.classes.get(class).measurement_noise_covariance_m2)
                        + reflection.covariance_m2,
                );
                let tracker = &self.config.tracker;
                let track = &mut self.table.tracks_mut()[i];
                track.existence_probability = existence::updated_existence(
                    track.existence_probability,
                    Evidence::Detected { likelihood_per_m2: likelihood },
                    detection,
                    clutter,
                );
                track.record_hit(&measurement, t);
                if track.status == TrackStatus::Tentative && confirms(track, tracker) {
                    track.status = TrackStatus::Confirmed;
                    self.last_step.newly_confirmed += 1;
                }
                self.last_step.assigned += 1;
                self.fates[usize::from(index)] = MeasurementFate::Assigned;
            } else {
                // Numerically unusable: the track coasts and the measurement is free to start a
                // track of its own.
                self.last_step.update_failures += 1;
                self.track_to_measurement[i] = None;
            }
        }
    }

    /// Tracks without a measurement keep their priors, and lose existence if a sensor of the
    /// frame had them in view (a confirmed one then coasts); every existing track's frame
    /// record.
    fn coast(&mut self) {
        for i in 0..self.table.len() {
            let measurement_index = self.track_to_measurement[i];
            if measurement_index.is_none() {
                let track = &self.table.tracks()[i];
                let mut existence_probability = track.existence_probability;
                let mut missed = false;
                let prior_m = self.priors[i].fused.mean;
                for sensor in self.scanning_sensors.iter().filter(|s| s.field_of_view.contains(prior_m)) {
                    let (detection, clutter) = self.detection_and_clutter(track.class, Some(sensor.id));
                    existence_probability = existence::updated_existence(
                        existence_probability,
                        Evidence::MissedInView,
                        detection,
                        clutter,
                    );
                    missed = true;
                }
                if self.last_step.unknown_sensor {
                    let (detection, clutter) = self.detection_and_clutter(track.class, None);
                    existence_probability = existence::updated_existence(
                        existence_probability,
                        Evidence::MissedInView,
                        detection,
                        clutter,
                    );
                    missed = true;
                }
                self.last_step.missed_in_view += usize::from(missed);
                let track = &mut self.table.tracks_mut()[i];
                track.estimate = self.imms[track.class.index()].coast(&self.priors[i]);
                track.record_miss();
                track.existence_probability = existence_probability;
                if missed && track.status == TrackStatus::Confirmed {
                    track.status = TrackStatus::Coasting;
                }
            }
            let track = &mut self.table.tracks_mut()[i];
            track.age_frames = track.age_frames.saturating_add(1);
            self.rows[i] = RowRecord {
                prior_position_m: Some(self.priors[i].fused.mean),
                available: self.priors[i].available,
                measurement_index,
            };
        }
    }

    /// Every accepted, unassigned measurement starts a tentative track, except one that a
    /// confirmed track of an extended class absorbs as a second detection of its object.
    fn initiate(&mut self, t: f64) {
        let initial_existence = self.config.tracker.initial_existence_probability;
        let tracks_before = self.table.len();
        for index in 0..self.validated.len() {
            if self.fates[index] != MeasurementFate::Unassigned {
                continue;
            }
            let Some(measurement) = self.validated.accepted(index) else { continue };
            if self.absorbed_by_a_track(&measurement, tracks_before) {
                self.last_step.detections_absorbed += 1;
                continue;
            }
            let sensor_position_m = self.sensor_position(&measurement);
            let models = &self.models[measurement.class.index()];
            // An extended object starts at the centre behind its reflection (no heading yet:
            // the disc model of `crate::extent`), its position spread by the reflection's.
            let (mut centre, mut reflection) = (measurement, ExpectedReflection::POINT);
            if models.extent.is_some() {
                let (sensor_m, mounted) = self.measurement_sensors[index];
                let standing =
                    crate::extent::ObjectPrior { centre_m: measurement.position(), ..Default::default() };
                reflection = models.expected_reflection(&standing, sensor_m);
                (centre.x_m, centre.y_m) =
                    (measurement.x_m - reflection.offset_m.x, measurement.y_m - reflection.offset_m.y);
                if !mounted {
                    self.last_step.updates_from_unknown_sensor += 1;
                }
            }
            let mut estimate = self.imms[measurement.class.index()].initiate_seen_from(
                &self.models[measurement.class.index()],
                &centre,
                sensor_position_m,
            );
            estimate.add_position_covariance(&crate::gaussian::to_nalgebra(&reflection.covariance_m2));
            let tracker = &self.config.tracker;
            match self.table.insert(|id| Track::new(id, &measurement, t, estimate, initial_existence)) {
                Ok(track) => {
                    self.last_step.initiated += 1;
                    // A confirmation threshold of one hit (or an initial existence at the
                    // threshold) confirms at once.
                    if confirms(track, tracker) {
                        track.status = TrackStatus::Confirmed;
                        self.last_step.newly_confirmed += 1;
                    }
                    self.rows[self.table.len() - 1] = RowRecord {
                        prior_position_m: None,
                        available: self.config.imm.modes,
                        measurement_index: Some(index as u16),
                    };
                    self.fates[index] = MeasurementFate::Assigned;
                }
                Err(_) => self.last_step.initiations_refused_table_full += 1,
            }
        }
    }

    /// Removes tentative tracks after `tentative_max_coast_s` without update, confirmed ones
    /// after `max_coast_s`; and by the lifecycle: tracks whose existence probability fell below
    /// `deletion_existence_probability`, or (counting) tentative tracks after
    /// `tentative_max_misses` misses and confirmed ones after `confirmed_max_misses`.
    fn delete(&mut self, t: f64) {
        let lifecycle = &self.config.tracker;
        let deleted = retain_with_rows(&mut self.table, &mut self.rows[..], |_, track| {
            let (max_misses, max_coast_s) = if track.status.is_confirmed() {
                (lifecycle.confirmed_max_misses, lifecycle.max_coast_s)
            } else {
                (lifecycle.tentative_max_misses, lifecycle.tentative_max_coast_s)
            };
            let alive = match lifecycle.lifecycle {
                Lifecycle::Counts => track.misses <= max_misses,
                Lifecycle::Existence => {
                    track.existence_probability >= lifecycle.deletion_existence_probability
                }
            };
            alive && t - track.last_update_s <= max_coast_s
        });
        self.last_step.deleted = deleted;
    }

    /// Merges each track that has shadowed an older track of its class for
    /// `tracker.duplicate_updates` exclusive updates into that track (`crate::duplicates`).
    fn merge_duplicates(&mut self) {
        if !duplicates::enabled(&self.config) {
            return;
        }
        let count = self.table.len();
        for (i, track) in self.table.tracks().iter().enumerate() {
            let imm = &self.imms[track.class.index()];
            let available = self.rows[i].available;
            self.duplicate_views[i] = DuplicateView {
                position_m: imm.fuse_posterior(&track.estimate, available).mean,
                velocity_mps: imm.fuse_velocity(&track.estimate, available),
                updated: self.rows[i].measurement_index.is_some(),
            };
        }
        self.merged[..count].fill(false);
        let needed = self.config.tracker.duplicate_updates;
        for younger in 0..count {
            let partner = self.older_overlapping_track(younger);
            let views = &self.duplicate_views;
            let track = &mut self.table.tracks_mut()[younger];
            let Some(older) = partner else {
                track.duplicate_of = None;
                track.exclusive_updates = 0;
                continue;
            };
            let older_id = self.table.tracks()[older].id;
            let track = &mut self.table.tracks_mut()[younger];
            if track.duplicate_of != Some(older_id) {
                track.duplicate_of = Some(older_id);
                track.exclusive_updates = 0;
            }
            track.exclusive_updates = duplicates::next_exclusive_updates(
                track.exclusive_updates,
                views[younger].updated,
                views[older].updated,
            );
            if track.exclusive_updates >= needed && !self.merged[older] {
                self.merge_into(younger, older);
            }
        }
        let merged = &self.merged;
        let removed = retain_with_rows(&mut self.table, &mut self.rows[..], |index, _| !merged[index]);
        self.last_step.duplicates_merged = removed;
    }

    /// The nearest older track (more frames, or as many and a smaller id) of `index`'s class that
    /// overlaps it, not already merged away.
    fn older_overlapping_track(&self, index: usize) -> Option<usize> {
        let tracks = self.table.tracks();
        let track = &tracks[index];
        let section = self.config.classes.get(track.class);
        let view = &self.duplicate_views[index];
        let older = |other: &crate::track::Track| {
            (other.age_frames, core::cmp::Reverse(other.id))
                > (track.age_frames, core::cmp::Reverse(track.id))
        };
        (0..tracks.len())
            .filter(|&j| j != index && !self.merged[j] && tracks[j].class == track.class && older(&tracks[j]))
            .filter(|&j| {
                duplicates::overlap(
                    view,
                    &self.duplicate_views[j],
                    section.duplicate_distance_m,
                    section.duplicate_speed_difference_mps,
                )
            })
            .min_by(|&a, &b| {
                let distance =
                    |j: usize| view.position_m.distance_squared(self.duplicate_views[j].position_m);
                distance(a).total_cmp(&distance(b))
            })
    }

    /// Merges track `younger` into `older`: the older keeps its id, age, hits and status (the
    /// better of the two), and takes the younger's state if that was updated more recently.
    fn merge_into(&mut self, younger: usize, older: usize) {
        let source = self.table.tracks()[younger].clone();
        let target = &mut self.table.tracks_mut()[older];
        if source.last_update_s > target.last_update_s {
            target.estimate = source.estimate;
            target.history = source.history;
            target.last_radial_velocity_mps = source.last_radial_velocity_mps;
            target.last_update_s = source.last_update_s;
            target.misses = source.misses;
            target.ground_truth_id = source.ground_truth_id;
            if target.status == TrackStatus::Coasting {
                target.status = TrackStatus::Confirmed;
            }
            self.rows[older] = self.rows[younger];
        }
        target.existence_probability = target.existence_probability.max(source.existence_probability);
        if source.status.is_confirmed() && !target.status.is_confirmed() {
            target.status = source.status;
        }
        self.merged[younger] = true;
    }

    /// Where the radar that measured `measurement` is, in the tracking frame: the world
    /// position of its mount in a world-frame step (the vehicle's reference point, counted, for
    /// a sensor without a configured mount), the vehicle frame's origin otherwise.
    fn sensor_position(&mut self, measurement: &Measurement) -> DVec2 {
        let Some(pose) = self.step_pose else { return DVec2::ZERO };
        match measurement.sensor_id.and_then(|id| self.config.frame.sensor(id)) {
            Some(mount) => pose.car_to_world(mount.position()),
            None => {
                self.last_step.initiations_from_unknown_sensor += 1;
                pose.position()
            }
        }
    }

    /// Removes every track and forgets the last timestamp, e.g. after a gap in the stream that
    /// [`FrameError::IntervalTooLong`] reported. Ids keep counting; statistics are kept;
    /// [`last_step`](Self::last_step) is cleared.
    pub fn reset(&mut self) {
        self.table.clear();
        self.ring.clear();
        self.last_timestamp_s = None;
        self.last_pose = None;
        self.step_pose = None;
        self.last_step = StepSummary::default();
        self.stats.resets += 1;
    }

    /// What the associator did in the last association: allowed pairs, clusters paired
    /// directly, clusters handed to the optimal solver and the largest and smallest of those.
    pub fn association_stats(&self) -> &AssociationStats {
        self.associator.stats()
    }

    /// Writes every live track's fused prediction to time `timestamp_s` into `out`, in table
    /// order, without changing any state (see [`crate::prediction`]); returns how many were
    /// written (the live tracks, at most `out.len()`). Positions and velocities are given in
    /// the vehicle frame of the newest frame's ego pose (world-frame tracking; the ego motion
    /// since is not known to the tracker) with the world-frame values beside; use
    /// [`predict_to_with_pose`](Self::predict_to_with_pose) with the ego pose at
    /// `timestamp_s` to have them in the vehicle frame of that time.
    pub fn predict_to(&self, timestamp_s: f64, out: &mut [TrackOutput]) -> Result<usize, PredictError> {
        self.predict_to_with_pose(timestamp_s, None, out)
    }

    /// [`predict_to`](Self::predict_to) with the ego pose at `timestamp_s`, if known: the
    /// vehicle-frame outputs of world-frame tracks are then in the vehicle frame of that pose.
    pub fn predict_to_with_pose(
        &self,
        timestamp_s: f64,
        ego_pose: Option<EgoPose>,
        out: &mut [TrackOutput],
    ) -> Result<usize, PredictError> {
        if !timestamp_s.is_finite() {
            return Err(PredictError::NonFiniteTime { timestamp_s });
        }
        let Some(newest_s) = self.last_timestamp_s else { return Ok(0) };
        let dt_s = timestamp_s - newest_s;
        if dt_s < 0.0 {
            return Err(PredictError::BeforeNewestFrame { timestamp_s, newest_s });
        }
        let max_s = self.config.tracker.max_frame_interval_s;
        if dt_s > max_s {
            return Err(PredictError::TooFarAhead { timestamp_s, ahead_s: dt_s, max_s });
        }
        let world = self.tracks_frame == TrackingFrame::World;
        let to_vehicle = if world {
            ego_pose.filter(|pose| pose.is_valid()).or(self.last_pose).map(|pose| pose.world_to_vehicle())
        } else {
            None
        };
        let survival = existence::survival_probability(dt_s, &self.config.tracker);
        let mut written = 0;
        for (track, slot) in self.table.tracks().iter().zip(out.iter_mut()) {
            let class = track.class.index();
            let (imm, models) = (&self.imms[class], &self.models[class]);
            let mut prior = ImmPrior::default();
            imm.predict_physics_into(models, &track.estimate, dt_s, &mut prior);
            imm.complete_prior_in_place(models, &mut prior, dt_s, None);
            let estimate = imm.fuse_position_velocity(&prior.state, prior.available);
            let position = DVec2::new(estimate.mean.x, estimate.mean.y);
            let velocity = DVec2::new(estimate.mean.z, estimate.mean.w);
            let position_covariance = prior.fused.covariance;
            let (position_m, position_covariance_m2, velocity_mps, state_covariance) = match to_vehicle {
                Some(to_vehicle) => (
                    to_vehicle.apply_point(position),
                    to_vehicle.apply_covariance(position_covariance),
                    to_vehicle.apply_vector(velocity),
                    to_vehicle.apply_state_covariance(estimate.covariance),
                ),
                None => (position, position_covariance, velocity, estimate.covariance),
            };
            *slot = TrackOutput {
                id: track.id,
                class: track.class,
                status: track.status,
                position_m,
                position_covariance_m2,
                velocity_mps,
                state_covariance,
                prior_position_m: None,
                world_position_m: to_vehicle.map(|_| position),
                world_velocity_mps: to_vehicle.map(|_| velocity),
                world_state_covariance: to_vehicle.map(|_| estimate.covariance),
                mode_probabilities: prior.state.probabilities,
                age_frames: track.age_frames,
                age_s: timestamp_s - track.started_s,
                hits: track.hits,
                misses: track.misses,
                existence_probability: track.existence_probability * survival,
                ground_truth_id: None,
                measurement_index: None,
            };
            written += 1;
        }
        Ok(written)
    }

    /// The outputs of the last successful [`step`](Self::step) (not of
    /// [`step_into`](Self::step_into), which hands them to its sink instead).
    pub fn last_outputs(&self) -> &[TrackOutput] {
        &self.outputs
    }

    /// The newest tracked frame's time, s: the time of the latest outputs (after a late frame
    /// too); `None` before the first frame and after a [`reset`](Self::reset).
    pub fn newest_timestamp_s(&self) -> Option<f64> {
        self.last_timestamp_s
    }

    /// The counters.
    pub fn stats(&self) -> &TrackerStats {
        &self.stats
    }

    /// What the latest step did. After a failed step: what it counted before it failed (a frame
    /// rejected by validation counts no measurement) and the unchanged tracks.
    pub fn last_step(&self) -> &StepSummary {
        &self.last_step
    }

    /// The live tracks.
    pub fn tracks(&self) -> &[Track] {
        self.table.tracks()
    }

    /// The configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The predictor.
    pub fn predictor(&self) -> &P {
        &self.predictor
    }

    /// The predictor, mutable.
    pub fn predictor_mut(&mut self) -> &mut P {
        &mut self.predictor
    }
}

/// Keeps the tracks for which `keep(index, track)` holds and moves their frame records along,
/// so that `rows` stays aligned with the table; returns how many were removed.
fn retain_with_rows(
    table: &mut TrackTable,
    rows: &mut [RowRecord],
    mut keep: impl FnMut(usize, &Track) -> bool,
) -> usize {
    let (mut read, mut write) = (0, 0);
    table.retain(|track| {
        let kept = keep(read, track);
        if kept {
            rows[write] = rows[read];
            write += 1;
        }
        read += 1;
        kept
    })
}

/// Whether a tentative `track` has earned confirmation under the configured lifecycle.
fn confirms(track: &Track, tracker: &crate::config::TrackerConfig) -> bool {
    match tracker.lifecycle {
        Lifecycle::Counts => track.hits >= tracker.confirmation_hits,
        Lifecycle::Existence => track.existence_probability >= tracker.confirmation_existence_probability,
    }
}

/// A configuration covariance as a matrix, m².
fn covariance(value: &crate::config::Covariance2) -> DMat2 {
    let [[xx, xy], [yx, yy]] = *value;
    DMat2::from_cols(DVec2::new(xx, yx), DVec2::new(xy, yy))
}

/// The output record of every live track, handed to `sink`. Tracks in the world frame are
/// reported in the vehicle frame of the current frame (`world_to_vehicle`) with their world
/// position and velocity beside.
fn report(
    table: &TrackTable,
    rows: &[RowRecord],
    imms: &ClassImms,
    world_to_vehicle: Option<RigidTransform>,
    timestamp_s: f64,
    mut sink: impl FnMut(&TrackOutput),
) {
    for (track, row) in table.tracks().iter().zip(rows.iter()) {
        let imm = &imms[track.class.index()];
        let fused = imm.fuse_posterior(&track.estimate, row.available);
        let velocity = imm.fuse_velocity(&track.estimate, row.available);
        let state_covariance = imm.fuse_position_velocity(&track.estimate, row.available).covariance;
        let (position_m, position_covariance_m2, velocity_mps, prior_position_m, vehicle_state_covariance) =
            match world_to_vehicle {
                Some(to_vehicle) => (
                    to_vehicle.apply_point(fused.mean),
                    to_vehicle.apply_covariance(fused.covariance),
                    to_vehicle.apply_vector(velocity),
                    row.prior_position_m.map(|prior| to_vehicle.apply_point(prior)),
                    to_vehicle.apply_state_covariance(state_covariance),
                ),
                None => (fused.mean, fused.covariance, velocity, row.prior_position_m, state_covariance),
            };
        sink(&TrackOutput {
            id: track.id,
            class: track.class,
            status: track.status,
            position_m,
            position_covariance_m2,
            velocity_mps,
            prior_position_m,
            world_position_m: world_to_vehicle.map(|_| fused.mean),
            world_velocity_mps: world_to_vehicle.map(|_| velocity),
            state_covariance: vehicle_state_covariance,
            world_state_covariance: world_to_vehicle.map(|_| state_covariance),
            mode_probabilities: track.estimate.probabilities,
            age_frames: track.age_frames,
            age_s: timestamp_s - track.started_s,
            hits: track.hits,
            misses: track.misses,
            existence_probability: track.existence_probability,
            ground_truth_id: row.measurement_index.and(track.ground_truth_id),
            measurement_index: row.measurement_index,
        });
    }
}
