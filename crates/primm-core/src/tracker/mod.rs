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
use crate::config::{Config, ConfigError};
use crate::coordinates::CoordinateFrame;
use crate::duplicates::DuplicateView;
use crate::existence::{FieldOfView, Lifecycle};
use crate::extent::ExpectedReflection;
use crate::imm::ImmPrior;
use crate::limits::MAX_SENSORS;
use crate::measurement::{FrameView, Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::mode::ModeSet;
use crate::motion::ModeModels;
use crate::pose::{EgoMotion, EgoPose};
use crate::predictor::{Displacement, DisplacementPredictor, NoPredictor, PredictionRequest};
use crate::recorded_frame::RecordedFrame;
use crate::replay::ReplayRing;
use crate::sensor::SensorSet;
use crate::sensor_noise::MeasurementSensor;
use crate::stage_timing::{NoObserver, Stage, StageObserver};
use crate::track::{Track, TrackOutput};
use crate::track_loops::{self, ClassImms};
use crate::track_table::{TrackTable, MAX_TRACKS};
use crate::validated_frame::ValidatedFrame;
use crate::validation::FrameError;
use alloc::boxed::Box;
use alloc::vec;
use arrayvec::ArrayVec;
use glam::{DMat2, DVec2};

mod confirmed_index;
mod counters;
mod geometry;
mod ghosts;
mod grouping;
mod late_frames;
mod lifecycle;
mod output;
mod predict;
mod sensors;
mod speculation;
mod stats;
mod update;
mod validate;

use output::report;
pub use speculation::{IntervalGuess, SpeculationStats};
pub use stats::{StepSummary, TrackerStats};

/// Why a step failed. The tracker's tracks are exactly as before the frame (after an
/// association failure, up to a change of their frame; see [`CoordinateFrame`]).
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

/// A sensor that scanned in the current frame: its slot in the [`SensorSet`] and its field of
/// view in the tracking frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ScanningSensor {
    slot: usize,
    field_of_view: FieldOfView,
}

/// The PR-IMM multi-object tracker with a learned-displacement predictor `P`.
#[derive(Debug)]
pub struct Tracker<P: DisplacementPredictor = NoPredictor> {
    config: Config,
    /// Each class's IMM (`classes.<class>.imm` over `imm`), indexed by [`ObjectClass::index`].
    imms: ClassImms,
    /// Each class's IMM in steps whose ego motion is compensated (the `compensated_*` keys of
    /// `classes.<class>.imm`); the same mode set as `imms`.
    compensated_imms: ClassImms,
    models: [ModeModels; ObjectClass::COUNT],
    predictor: P,
    table: TrackTable,
    associator: Associator,
    last_timestamp_s: Option<f64>,
    stats: TrackerStats,
    /// What the latest step did.
    last_step: StepSummary,
    /// The frame the live tracks are in.
    tracks_frame: CoordinateFrame,
    /// The ego pose of the current step when it tracks in the world frame, else `None`.
    step_pose: Option<EgoPose>,
    /// The ego pose of the latest step tracked in the world frame.
    last_pose: Option<EgoPose>,
    /// When `last_pose` was taken and the ego's velocity over ground that the poses give.
    ego_motion: EgoMotion,
    /// Every sensor: its mount, measurement model and what its data said so far.
    sensors: Box<SensorSet>,
    // Per-frame workspaces, allocated once.
    requests: Box<ArrayVec<PredictionRequest, MAX_TRACKS>>,
    /// The table row of each request's track (`predictor.classes` may leave tracks out).
    requested_rows: Box<ArrayVec<u16, MAX_TRACKS>>,
    /// Learned predictions computed between frames (`speculation`).
    speculation: speculation::Speculation,
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
    /// Where the radar of each track's assigned measurement is, in the tracking frame, and the
    /// detection's covariance from the radar's own noise.
    assigned_sensors: Box<[MeasurementSensor; MAX_TRACKS]>,
    /// The expected reflection of each track's object for its assigned measurement's radar
    /// (computed once per frame, used by the Kalman update and the existence likelihood).
    assigned_reflections: Box<[ExpectedReflection; MAX_TRACKS]>,
    /// Where the radar of each measurement of the current frame is, in the tracking frame (its
    /// mount; the vehicle's reference point when it has none), whether it had a mount, and the
    /// detection's covariance from the radar's own noise (`crate::sensor_noise`).
    measurement_sensors: Box<[MeasurementSensor; MAX_MEASUREMENTS_PER_FRAME]>,
    /// Whether each track was confirmed (or coasting) before the current frame's update.
    was_confirmed: Box<[bool; MAX_TRACKS]>,
    /// Each track's update outcome of the current frame.
    update_outcomes: Box<[track_loops::UpdateOutcome; MAX_TRACKS]>,
    rows: Box<[RowRecord; MAX_TRACKS]>,
    fates: Box<[MeasurementFate; MAX_MEASUREMENTS_PER_FRAME]>,
    accepted: Box<[bool; MAX_MEASUREMENTS_PER_FRAME]>,
    /// The fields of view of the sensors that scanned in the current frame, with their
    /// detection-probability and clutter-density factors.
    scanning_sensors: Box<ArrayVec<ScanningSensor, MAX_SENSORS>>,
    /// Where the frame's radars without a configured mount looked, as their detections show it
    /// (`None`: the frame had none).
    unknown_sensor_view: Option<FieldOfView>,
    /// Each live track's fused state for the duplicate check, aligned with the table.
    duplicate_views: Box<[DuplicateView; MAX_TRACKS]>,
    /// Tracks merged into an older one in the current frame, aligned with the table.
    merged: Box<[bool; MAX_TRACKS]>,
    /// The grouping of the current frame's point-cloud detections (`crate::grouping`).
    frame_groups: Box<crate::grouping::frame_groups::FrameGroups>,
    /// Whether the current frame's measurements are groups.
    grouped_frame: bool,
    /// The frame index of each group's representative detection (when `grouped_frame`).
    group_first_index: Box<[u16; MAX_MEASUREMENTS_PER_FRAME]>,
    /// For each group moved to its object's centre (when `grouped_frame`), the contour's
    /// covariance of one point about its centroid, m² (`grouping::contour::group_noise_m2`);
    /// `None` for the others.
    group_centre_spread: Box<[Option<glam::DMat2>; MAX_MEASUREMENTS_PER_FRAME]>,
    /// Per track: whether an older track of its class nearby took a detection on its object in
    /// the current grouped frame (`grouping`).
    shadowed: Box<[bool; MAX_TRACKS]>,
    /// Per track: whether the deletion ends it as a shadowed duplicate.
    ending: Box<[bool; MAX_TRACKS]>,
    /// The confirmed tracks indexed for the grouping's look-ups.
    confirmed: Box<confirmed_index::ConfirmedIndex>,
    /// Per track: its detections of one radar in the current frame (`learn_points`).
    owned_counts: Box<[u16; MAX_TRACKS]>,
    /// The boxes of the tracks confirmed before the current frame's update, which may hide
    /// other tracks from a sensor (`learn_sensors`).
    occluders: Box<crate::occlusion::Occluders<MAX_TRACKS>>,
    /// The current frame as read once from the caller; validation reads only this copy.
    recorded: Box<RecordedFrame>,
    /// The current frame as validated; every later stage reads this copy.
    validated: Box<ValidatedFrame>,
    /// The recent frames and the state before each, for late frames.
    ring: ReplayRing,
    outputs: Box<ArrayVec<TrackOutput, MAX_TRACKS>>,
    /// The outputs of the latest late frame right after it was tracked in its place, before
    /// the newer frames were tracked again (room reserved only when late frames are on).
    late_outputs: alloc::vec::Vec<TrackOutput>,
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
            compensated_imms: track_loops::class_compensated_imms(&config),
            models: ObjectClass::ALL.map(|class| ModeModels::from_config(config.classes.get(class))),
            sensors: Box::new(sensor_set(&config)),
            config,
            predictor,
            table: TrackTable::new(),
            associator: Associator::new(),
            last_timestamp_s: None,
            stats: TrackerStats::default(),
            last_step: StepSummary::default(),
            tracks_frame: CoordinateFrame::Vehicle,
            step_pose: None,
            last_pose: None,
            ego_motion: EgoMotion::default(),
            requests: Box::new(ArrayVec::new()),
            requested_rows: Box::new(ArrayVec::new()),
            speculation: speculation::Speculation::new(),
            answers: Box::new([None; MAX_TRACKS]),
            displacements: Box::new([None; MAX_TRACKS]),
            priors: vec![ImmPrior::default(); MAX_TRACKS].into_boxed_slice(),
            dt_s: 0.0,
            track_to_measurement: Box::new([None; MAX_TRACKS]),
            assigned_measurements: Box::new([None; MAX_TRACKS]),
            assigned_sensors: Box::new([MeasurementSensor::unknown(DVec2::ZERO, 0.0); MAX_TRACKS]),
            assigned_reflections: Box::new([ExpectedReflection::POINT; MAX_TRACKS]),
            measurement_sensors: Box::new(
                [MeasurementSensor::unknown(DVec2::ZERO, 0.0); MAX_MEASUREMENTS_PER_FRAME],
            ),
            was_confirmed: Box::new([false; MAX_TRACKS]),
            update_outcomes: Box::new([Ok(None); MAX_TRACKS]),
            rows: Box::new([EMPTY_ROW; MAX_TRACKS]),
            fates: Box::new([MeasurementFate::Rejected; MAX_MEASUREMENTS_PER_FRAME]),
            accepted: Box::new([false; MAX_MEASUREMENTS_PER_FRAME]),
            scanning_sensors: Box::new(ArrayVec::new()),
            unknown_sensor_view: None,
            duplicate_views: Box::new([DuplicateView::default(); MAX_TRACKS]),
            merged: Box::new([false; MAX_TRACKS]),
            frame_groups: Box::new(crate::grouping::frame_groups::FrameGroups::new()),
            grouped_frame: false,
            group_first_index: Box::new([0; MAX_MEASUREMENTS_PER_FRAME]),
            group_centre_spread: Box::new([None; MAX_MEASUREMENTS_PER_FRAME]),
            confirmed: Box::new(confirmed_index::ConfirmedIndex::new()),
            owned_counts: Box::new([0; MAX_TRACKS]),
            occluders: Box::default(),
            shadowed: Box::new([false; MAX_TRACKS]),
            ending: Box::new([false; MAX_TRACKS]),
            recorded: Box::new(RecordedFrame::new()),
            validated: Box::new(ValidatedFrame::new()),
            late_outputs: alloc::vec::Vec::with_capacity(if ring.is_enabled() { MAX_TRACKS } else { 0 }),
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

    /// The stages of a step up to the report, on the recorded frame.
    fn run_stages<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        let dt_s = self.validate()?;
        observer.stage_finished(Stage::Validate);
        // From here on only the validated copy is read.
        let t = self.validated.timestamp_s();
        // Sensors that stand still: a frame without a pose is at the world origin.
        let stationary = self.config.frame.platform.stationary(self.sensors.platform());
        let pose = self.validated.ego_pose().or(stationary.then(EgoPose::default));
        self.enter_tracking_frame(pose, dt_s, t);
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
        self.group_detections();
        self.associate()?;
        observer.stage_finished(Stage::Associate);
        self.update(t);
        self.coast();
        self.learn_sensors();
        self.initiate(t);
        self.end_shadowed_and_ghost_tracks();
        self.delete(t);
        self.merge_duplicates();
        self.name_groups_by_representative();
        observer.stage_finished(Stage::Update);
        self.last_timestamp_s = Some(t);
        self.last_step.counts.frames_tracked += 1;
        Ok(())
    }

    /// Removes every track and forgets the last timestamp, e.g. after a gap in the stream that
    /// [`FrameError::IntervalTooLong`] reported. Ids keep counting; statistics are kept;
    /// [`last_step`](Self::last_step) is cleared.
    pub fn reset(&mut self) {
        self.table.clear();
        self.ring.clear();
        self.last_timestamp_s = None;
        self.last_pose = None;
        self.ego_motion = EgoMotion::default();
        self.step_pose = None;
        self.last_step = StepSummary::default();
        self.stats.resets += 1;
    }

    /// Puts every sensor's estimates back at their priors (the configured values), e.g. before
    /// tracking a recording of another vehicle. [`reset`](Self::reset) keeps them: a gap in the
    /// stream does not change the radars.
    pub fn forget_sensors(&mut self) {
        *self.sensors = sensor_set(&self.config);
        self.ring.clear();
    }

    /// What the associator did in the last association: allowed pairs, clusters paired
    /// directly, clusters handed to the optimal solver and the largest and smallest of those.
    pub fn association_stats(&self) -> &AssociationStats {
        self.associator.stats()
    }

    /// The outputs of the last successful [`step`](Self::step) (not of
    /// [`step_into`](Self::step_into), which hands them to its sink instead).
    pub fn last_outputs(&self) -> &[TrackOutput] {
        &self.outputs
    }

    /// When the last step tracked a late frame in its place ([`StepSummary::late`]): the
    /// outputs of every live track right after that frame, at its time and with
    /// `measurement_index` into its measurements, as in-order arrival gives them after it
    /// (before the newer frames were tracked again). Empty after any other step, and when the
    /// late frame itself was refused.
    pub fn late_frame_outputs(&self) -> &[TrackOutput] {
        if self.last_step.late() {
            &self.late_outputs
        } else {
            &[]
        }
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

    /// Every sensor with what its data said so far (`crate::sensor`).
    pub fn sensors(&self) -> &SensorSet {
        &self.sensors
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

/// The sensors of `config` at their priors.
fn sensor_set(config: &Config) -> SensorSet {
    let classes = ObjectClass::ALL.map(|class| {
        let section = config.classes.get(class);
        (&section.extent, &section.existence)
    });
    SensorSet::new(&config.frame, &classes)
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

/// The IMMs of a step: those for ego-motion-compensated steps when the step has an ego pose
/// (tracked in the world frame), else the plain ones. The two share their mode set, so fusion
/// and the report may use either.
#[inline]
pub(super) fn step_imms<'a>(
    compensated: bool,
    imms: &'a ClassImms,
    compensated_imms: &'a ClassImms,
) -> &'a ClassImms {
    if compensated {
        compensated_imms
    } else {
        imms
    }
}
