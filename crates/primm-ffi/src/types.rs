//! The `#[repr(C)]` types and the constants of the C API.
//!
//! Codes that C passes in (method, class) are plain integers with named constants rather than
//! Rust enums, so that an out-of-range value from C is an error and never undefined behaviour.

use core::ffi::c_char;
use primm_core::association::associator::AssociationStats;
use primm_core::limits::{MAX_MEASUREMENTS_PER_FRAME, MAX_TRACKS};
use primm_core::measurement::{Measurement, ObjectClass, UnknownClass};
use primm_core::mode::{Method, MODE_COUNT};
use primm_core::track::{TrackOutput, TrackStatus};
use primm_core::tracker::{StepSummary, TrackerStats};

/// Most live tracks a tracker holds (the size of a buffer that always fits
/// `primm_tracker_tracks`).
pub const PRIMM_MAX_TRACKS: usize = 512;
/// Most measurements one frame may carry; a larger frame is rejected with
/// `PRIMM_STATUS_INVALID_FRAME`.
pub const PRIMM_MAX_MEASUREMENTS_PER_FRAME: usize = 1024;
/// Number of IMM modes; mode probabilities are ordered PR, CV, CA, CT.
pub const PRIMM_MODE_COUNT: usize = 4;

/// A method code, one of the `PRIMM_METHOD_*` constants: which IMM modes the tracker runs.
pub type PrimmMethod = u32;
/// The modes the configuration names (`imm.modes`; PR, CV, CA and CT in the defaults).
pub const PRIMM_METHOD_CONFIG: PrimmMethod = 0;
/// Constant-velocity Kalman filter.
pub const PRIMM_METHOD_CV: PrimmMethod = 1;
/// Constant-acceleration Kalman filter.
pub const PRIMM_METHOD_CA: PrimmMethod = 2;
/// Coordinated-turn extended Kalman filter.
pub const PRIMM_METHOD_CT: PrimmMethod = 3;
/// The learned predictor (PR) alone; needs a model.
pub const PRIMM_METHOD_PR: PrimmMethod = 4;
/// IMM of CV, CA and CT (what `primm track --method imm` runs).
pub const PRIMM_METHOD_IMM: PrimmMethod = 5;
/// IMM of PR, CV, CA and CT; needs a model.
pub const PRIMM_METHOD_PR_IMM: PrimmMethod = 6;

/// An object class code, one of the `PRIMM_OBJECT_CLASS_*` constants.
pub type PrimmObjectClass = u8;
/// Passenger cars and large vehicles.
pub const PRIMM_OBJECT_CLASS_CAR: PrimmObjectClass = 0;
/// Pedestrians and pedestrian groups.
pub const PRIMM_OBJECT_CLASS_PEDESTRIAN: PrimmObjectClass = 1;
/// Bicycles and motorcycles; reserved, not tracked by the default configuration.
pub const PRIMM_OBJECT_CLASS_TWO_WHEELER: PrimmObjectClass = 2;

/// A track status code, one of the `PRIMM_TRACK_STATUS_*` constants.
pub type PrimmTrackStatus = u8;
/// Started by an unassigned measurement, not yet confirmed.
pub const PRIMM_TRACK_STATUS_TENTATIVE: PrimmTrackStatus = 0;
/// Confirmed (by hits or by its existence probability) and detected the last time a sensor had
/// it in view.
pub const PRIMM_TRACK_STATUS_CONFIRMED: PrimmTrackStatus = 1;
/// Confirmed, but missed the last time a sensor had it in view (its state is a prediction since).
pub const PRIMM_TRACK_STATUS_COASTING: PrimmTrackStatus = 2;

/// `ground_truth_id` value meaning "unknown".
pub const PRIMM_NO_GROUND_TRUTH_ID: i64 = -1;
/// `sensor_id` value meaning "unknown".
pub const PRIMM_NO_SENSOR_ID: i32 = -1;
/// `measurement_index` value of a track that coasted (no measurement in this frame).
pub const PRIMM_NO_MEASUREMENT_INDEX: i32 = -1;

// The C constants are literals (cbindgen writes them into the header); they must agree with
// the core's values.
const _: () = {
    assert!(PRIMM_MAX_TRACKS == MAX_TRACKS);
    assert!(PRIMM_MAX_MEASUREMENTS_PER_FRAME == MAX_MEASUREMENTS_PER_FRAME);
    assert!(PRIMM_MODE_COUNT == MODE_COUNT);
    assert!(PRIMM_OBJECT_CLASS_CAR == ObjectClass::Car as u8);
    assert!(PRIMM_OBJECT_CLASS_PEDESTRIAN == ObjectClass::Pedestrian as u8);
    assert!(PRIMM_OBJECT_CLASS_TWO_WHEELER == ObjectClass::TwoWheeler as u8);
    assert!(PRIMM_TRACK_STATUS_TENTATIVE == TrackStatus::Tentative as u8);
    assert!(PRIMM_TRACK_STATUS_CONFIRMED == TrackStatus::Confirmed as u8);
    assert!(PRIMM_TRACK_STATUS_COASTING == TrackStatus::Coasting as u8);
};

/// The method of a code: `Ok(None)` for [`PRIMM_METHOD_CONFIG`], `Err(code)` for an unknown code.
pub(crate) fn method_from_code(code: PrimmMethod) -> Result<Option<Method>, PrimmMethod> {
    Ok(Some(match code {
        PRIMM_METHOD_CONFIG => return Ok(None),
        PRIMM_METHOD_CV => Method::ConstantVelocity,
        PRIMM_METHOD_CA => Method::ConstantAcceleration,
        PRIMM_METHOD_CT => Method::CoordinatedTurn,
        PRIMM_METHOD_PR => Method::Learned,
        PRIMM_METHOD_IMM => Method::Imm,
        PRIMM_METHOD_PR_IMM => Method::PrImm,
        other => return Err(other),
    }))
}

/// How to build a tracker; `primm_tracker_options_default` gives the defaults.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct PrimmTrackerOptions {
    /// Tracker configuration as TOML text (UTF-8, NUL-terminated; the format of
    /// `config/primm.toml`); NULL for the built-in defaults. Only read during the call.
    pub config_toml: *const c_char,
    /// Which modes to run: a `PRIMM_METHOD_*` code; `PRIMM_METHOD_CONFIG` keeps the
    /// configuration's `imm.modes`.
    pub method: PrimmMethod,
    /// ONNX bytes of a PR model (the contract of `models/pr.json`), or NULL for none. Checked
    /// whenever given; used when the modes include PR. Only read during the call.
    pub model_onnx: *const u8,
    /// Length of `model_onnx` in bytes; 0 when `model_onnx` is NULL.
    pub model_onnx_len: usize,
    /// When the modes include PR and `model_onnx` is NULL: use the model built into the library
    /// (`models/pr.onnx`) if true, fail with `PRIMM_STATUS_INVALID_MODEL` if false.
    pub use_builtin_model: bool,
    /// Run the PR model on dedicated inference threads (`predictor.inference_threads` of them,
    /// sharing each frame's batch) with the configuration's
    /// `predictor.deadline_ms`: `primm_tracker_step` then allocates nothing with any method, but
    /// whether a frame gets its learned predictions depends on timing. If false, the model runs
    /// inside `primm_tracker_step` (deterministic; the native forward pass, the default engine
    /// for the shipped model, allocates nothing per batch, tract allocates during the run).
    pub inference_thread: bool,
}

/// One object-level radar measurement, read from caller memory by `primm_tracker_step`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimmMeasurement {
    /// Longitudinal position in the vehicle frame, m.
    pub x_m: f64,
    /// Lateral position in the vehicle frame, m.
    pub y_m: f64,
    /// Ego-motion compensated radial velocity, m/s, positive moving away.
    pub radial_velocity_mps: f64,
    /// Radar cross section, dBsm.
    pub rcs_dbsm: f64,
    /// Ground-truth object id carried through to the track (evaluation only; the tracker never
    /// reads it), or `PRIMM_NO_GROUND_TRUTH_ID`. Ids are 64-bit patterns: ids of 2^63 and above
    /// appear negative.
    pub ground_truth_id: i64,
    /// Radar that produced the measurement, 0 to 65535, or `PRIMM_NO_SENSOR_ID` (any value
    /// outside 0 to 65535 means unknown).
    pub sensor_id: i32,
    /// Object class, a `PRIMM_OBJECT_CLASS_*` code; a measurement with an unknown code is
    /// rejected and counted in `measurements_rejected_unknown_class`.
    pub class_code: PrimmObjectClass,
}

impl PrimmMeasurement {
    /// The core measurement, or the unknown class code.
    pub(crate) fn to_measurement(self) -> Result<Measurement, UnknownClass> {
        let class = ObjectClass::from_code(self.class_code).ok_or(UnknownClass { code: self.class_code })?;
        Ok(Measurement {
            x_m: self.x_m,
            y_m: self.y_m,
            radial_velocity_mps: self.radial_velocity_mps,
            rcs_dbsm: self.rcs_dbsm,
            class,
            sensor_id: u16::try_from(self.sensor_id).ok(),
            ground_truth_id: (self.ground_truth_id != PRIMM_NO_GROUND_TRUTH_ID)
                .then_some(self.ground_truth_id as u64),
        })
    }
}

/// The state of one live track after a step, as copied out by `primm_tracker_tracks`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimmTrack {
    /// Track id, unique within the tracker's life.
    pub id: u64,
    /// Fused posterior position, x, m.
    pub x_m: f64,
    /// Fused posterior position, y, m.
    pub y_m: f64,
    /// Fused velocity estimate, x, m/s.
    pub velocity_x_mps: f64,
    /// Fused velocity estimate, y, m/s.
    pub velocity_y_mps: f64,
    /// Covariance of the fused position (with the spread of the mode means), xx entry, m².
    pub position_covariance_xx_m2: f64,
    /// Covariance of the fused position, xy (= yx) entry, m².
    pub position_covariance_xy_m2: f64,
    /// Covariance of the fused position, yy entry, m².
    pub position_covariance_yy_m2: f64,
    /// Fused one-step prior used for association, x, m; NaN when `has_prior_position` is false.
    pub prior_x_m: f64,
    /// Fused one-step prior used for association, y, m; NaN when `has_prior_position` is false.
    pub prior_y_m: f64,
    /// Posterior mode probabilities, order PR, CV, CA, CT (0 for modes not run).
    pub mode_probabilities: [f64; PRIMM_MODE_COUNT],
    /// Ground-truth id of the measurement that updated or started the track in this step, or
    /// `PRIMM_NO_GROUND_TRUTH_ID`.
    pub ground_truth_id: i64,
    /// Frames since the track started.
    pub age_frames: u32,
    /// Associated measurements so far.
    pub hits: u32,
    /// Consecutive frames without measurement (0 when updated in this step).
    pub misses: u32,
    /// Probability that the track's object exists, in (0, 1).
    pub existence_probability: f64,
    /// Index, in this step's measurement array, of the measurement that updated or started the
    /// track, or `PRIMM_NO_MEASUREMENT_INDEX` when the track coasted.
    pub measurement_index: i32,
    /// Object class, a `PRIMM_OBJECT_CLASS_*` code.
    pub class_code: PrimmObjectClass,
    /// Lifecycle status, a `PRIMM_TRACK_STATUS_*` code.
    pub status: PrimmTrackStatus,
    /// Whether the track has a prior (false for a track started in this step).
    pub has_prior_position: bool,
    /// Whether the step tracked in the world frame (it had an ego pose): then the position,
    /// covariance, prior and velocity above are in the vehicle frame of this step (the velocity
    /// over ground in the vehicle's axes) and the `world_*` fields hold the world-frame
    /// estimate; otherwise those are NaN.
    pub has_world_estimate: bool,
    /// Fused position in the world frame, x, m.
    pub world_x_m: f64,
    /// Fused position in the world frame, y, m.
    pub world_y_m: f64,
    /// Fused velocity over ground in the world frame, x, m/s.
    pub world_velocity_x_mps: f64,
    /// Fused velocity over ground in the world frame, y, m/s.
    pub world_velocity_y_mps: f64,
    /// Covariance of the fused `[x, y, vx, vy]`, row-major 4×4 (m², m²/s, m²/s²), in the frame
    /// of `x_m`, `y_m` and the velocity; its upper-left 2×2 block is the position covariance.
    pub state_covariance: [f64; 16],
    /// Covariance of the world-frame `[x, y, vx, vy]`, row-major 4×4; NaN unless
    /// `has_world_estimate`.
    pub world_state_covariance: [f64; 16],
    /// Time since the track's first measurement, s (at the step's newest frame, or at the
    /// requested time of `primm_tracker_predict_to`).
    pub age_s: f64,
}

/// The ego vehicle's pose in the world (odometry) frame at a frame's time: the reference point
/// (centre of the rear axle) and the heading of the vehicle's x axis.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimmEgoPose {
    /// World x of the reference point, m.
    pub x_m: f64,
    /// World y of the reference point, m.
    pub y_m: f64,
    /// Heading, rad, counter-clockwise from the world x axis.
    pub yaw_rad: f64,
}

impl PrimmTrack {
    /// A zeroed entry (buffer filler).
    pub(crate) const EMPTY: PrimmTrack = PrimmTrack {
        id: 0,
        x_m: 0.0,
        y_m: 0.0,
        velocity_x_mps: 0.0,
        velocity_y_mps: 0.0,
        position_covariance_xx_m2: 0.0,
        position_covariance_xy_m2: 0.0,
        position_covariance_yy_m2: 0.0,
        prior_x_m: f64::NAN,
        prior_y_m: f64::NAN,
        mode_probabilities: [0.0; PRIMM_MODE_COUNT],
        ground_truth_id: PRIMM_NO_GROUND_TRUTH_ID,
        age_frames: 0,
        hits: 0,
        misses: 0,
        existence_probability: 0.0,
        measurement_index: PRIMM_NO_MEASUREMENT_INDEX,
        class_code: PRIMM_OBJECT_CLASS_CAR,
        status: PRIMM_TRACK_STATUS_TENTATIVE,
        has_prior_position: false,
        has_world_estimate: false,
        world_x_m: f64::NAN,
        world_y_m: f64::NAN,
        world_velocity_x_mps: f64::NAN,
        world_velocity_y_mps: f64::NAN,
        state_covariance: [0.0; 16],
        world_state_covariance: [f64::NAN; 16],
        age_s: 0.0,
    };
}

impl From<&TrackOutput> for PrimmTrack {
    fn from(output: &TrackOutput) -> Self {
        let covariance = output.position_covariance_m2;
        let prior = output.prior_position_m;
        let world = output.world_position_m.zip(output.world_velocity_mps);
        PrimmTrack {
            id: output.id,
            x_m: output.position_m.x,
            y_m: output.position_m.y,
            velocity_x_mps: output.velocity_mps.x,
            velocity_y_mps: output.velocity_mps.y,
            position_covariance_xx_m2: covariance.x_axis.x,
            position_covariance_xy_m2: covariance.y_axis.x,
            position_covariance_yy_m2: covariance.y_axis.y,
            prior_x_m: prior.map_or(f64::NAN, |p| p.x),
            prior_y_m: prior.map_or(f64::NAN, |p| p.y),
            mode_probabilities: output.mode_probabilities,
            ground_truth_id: output.ground_truth_id.map_or(PRIMM_NO_GROUND_TRUTH_ID, |id| id as i64),
            age_frames: output.age_frames,
            hits: output.hits,
            misses: output.misses,
            existence_probability: output.existence_probability,
            measurement_index: output.measurement_index.map_or(PRIMM_NO_MEASUREMENT_INDEX, i32::from),
            class_code: output.class.code(),
            status: output.status as u8,
            has_prior_position: prior.is_some(),
            has_world_estimate: world.is_some(),
            world_x_m: world.map_or(f64::NAN, |(p, _)| p.x),
            world_y_m: world.map_or(f64::NAN, |(p, _)| p.y),
            world_velocity_x_mps: world.map_or(f64::NAN, |(_, v)| v.x),
            world_velocity_y_mps: world.map_or(f64::NAN, |(_, v)| v.y),
            state_covariance: row_major(&output.state_covariance),
            world_state_covariance: match (world, output.world_state_covariance) {
                (Some(_), Some(covariance)) => row_major(&covariance),
                _ => [f64::NAN; 16],
            },
            age_s: output.age_s,
        }
    }
}

/// What one successful `primm_tracker_step` did.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PrimmStepSummary {
    /// Live tracks after the step: the count `primm_tracker_tracks` copies.
    pub track_count: usize,
    /// Tracks updated or started by a measurement of this frame.
    pub updated_track_count: usize,
    /// Measurements of this frame accepted by validation.
    pub measurements_accepted: usize,
    /// Measurements of this frame rejected (unknown class, non-finite or absurd values).
    pub measurements_rejected: usize,
    /// Tracks started in this step.
    pub tracks_initiated: usize,
    /// Tracks deleted in this step.
    pub tracks_deleted: usize,
    /// Association clusters of this step handed to the optimal assignment solver (a cluster of
    /// one track and one measurement is paired directly and not counted).
    pub solved_clusters: usize,
    /// Tracks of the smallest cluster solved in this step (0 if none was).
    pub smallest_solved_cluster_tracks: usize,
    /// Measurements of the smallest cluster solved in this step (0 if none was).
    pub smallest_solved_cluster_measurements: usize,
    /// Tracks of the largest cluster solved in this step (0 if none was).
    pub largest_solved_cluster_tracks: usize,
    /// Measurements of the largest cluster solved in this step (0 if none was).
    pub largest_solved_cluster_measurements: usize,
    /// Newer frames tracked again because this frame was late (0 for a frame in order).
    pub frames_replayed: usize,
    /// Whether the frame was late (older than the newest frame tracked before it, within
    /// `tracker.max_frame_delay_s`) and was tracked in its place. The tracks are then those at
    /// the newest frame's time (`primm_tracker_newest_timestamp`), and their
    /// `measurement_index` refers to the newest frame's measurements.
    pub late_frame: bool,
    /// Whether the frame's ego pose jumped from the previous one (an odometry reset; the tracks
    /// kept their place around the vehicle).
    pub odometry_reset: bool,
}

impl PrimmStepSummary {
    /// The C form of the tracker's summary of a step whose association did `association` and
    /// whose tracks are `tracks`.
    pub(crate) fn new(summary: &StepSummary, association: &AssociationStats, tracks: &[PrimmTrack]) -> Self {
        let count = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
        let counts = &summary.counts;
        PrimmStepSummary {
            track_count: tracks.len(),
            updated_track_count: tracks
                .iter()
                .filter(|t| t.measurement_index != PRIMM_NO_MEASUREMENT_INDEX)
                .count(),
            measurements_accepted: count(counts.measurements_accepted),
            measurements_rejected: count(summary.measurements_rejected()),
            tracks_initiated: count(counts.tracks_initiated),
            tracks_deleted: count(counts.tracks_deleted),
            solved_clusters: association.solved_clusters,
            smallest_solved_cluster_tracks: association.smallest_solved_cluster.0,
            smallest_solved_cluster_measurements: association.smallest_solved_cluster.1,
            largest_solved_cluster_tracks: association.largest_cluster.0,
            largest_solved_cluster_measurements: association.largest_cluster.1,
            frames_replayed: count(counts.frames_replayed),
            late_frame: summary.late(),
            odometry_reset: summary.odometry_reset(),
        }
    }
}

// cbindgen reads this struct as written, so each counter is spelled out here; the conversion
// below is generated from the list, so a counter added there and missing here (or the
// reverse) does not compile. Such a change changes this struct's size: raise
// `PRIMM_ABI_VERSION` and regenerate the header.
/// The tracker's counters since it was built: `TrackerStats` of primm-core, field for field,
/// in the order of primm-core's list of counters (`tracker_counters!`), which documents each.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PrimmStats {
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
    /// Frames rejected because their ego pose was not finite or absurdly far out (only
    /// when tracking in the world frame).
    pub frames_rejected_invalid_ego_pose: u64,
    /// Frames tracked in the world frame (they carried an ego pose and the configuration
    /// asks for the world frame).
    pub frames_in_world_frame: u64,
    /// Frames tracked in the vehicle frame although the configuration asks for the world
    /// frame, because they carried no ego pose.
    pub frames_without_ego_pose: u64,
    /// Times the live tracks were moved between the world and the vehicle frame, because
    /// a stream started or stopped carrying ego poses.
    pub tracking_frame_changes: u64,
    /// Tracks started in the world frame by a measurement whose sensor has no configured
    /// mount: their line of sight starts at the vehicle's reference point.
    pub initiations_from_unknown_sensor: u64,
    /// Unassigned measurements that started no track as the mirror image of a confirmed
    /// track in a wall along its heading (multipath ghosts).
    pub initiations_refused_as_ghost: u64,
    /// Tentative tracks ended as multipath ghosts: their measurement, or their fused state,
    /// was the mirror image of a confirmed track.
    pub tentative_tracks_ended_as_ghost: u64,
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
    /// Tracks confirmed (a track started and confirmed at once included).
    pub tracks_confirmed: u64,
    /// Tracks deleted.
    pub tracks_deleted: u64,
    /// Unassigned measurements that could not start a track because the table was full.
    pub initiations_refused_table_full: u64,
    /// Track-frames in which the PR mode had no usable learned displacement and sat out:
    /// the predictor gave none (missed deadline, failed or hung inference) or its answer
    /// was rejected (the three `learned_predictions_rejected_*` counters). Tracks of a
    /// class outside `predictor.classes` are never requested and not counted.
    pub learned_predictions_missing: u64,
    /// Frames in which at least one track had no usable learned displacement.
    pub frames_with_learned_predictions_missing: u64,
    /// Learned displacements rejected for a NaN or infinite component (included in
    /// `learned_predictions_missing`).
    pub learned_predictions_rejected_non_finite: u64,
    /// Learned displacements rejected as faster than
    /// `predictor.max_displacement_speed_mps` (included in `learned_predictions_missing`).
    pub learned_predictions_rejected_implausible: u64,
    /// Learned displacements rejected for a covariance that is not finite, symmetric,
    /// positive definite and of plausible size (included in
    /// `learned_predictions_missing`).
    pub learned_predictions_rejected_invalid_covariance: u64,
    /// Kalman updates refused for numerical reasons (the track coasted instead).
    pub update_failures: u64,
    /// Calls to `primm_tracker_reset`.
    pub resets: u64,
    /// Frames with a measurement whose sensor has no configured mount (or no sensor id):
    /// such a radar is taken to look where its detections of the frame lie
    /// (`frame.unknown_sensor_*`), and a track there that it missed loses existence.
    pub frames_with_unknown_sensor: u64,
    /// Tracks merged into an older track of the same object.
    pub duplicate_tracks_merged: u64,
    /// Late frames tracked in their place: older than the newest
    /// tracked frame, within `tracker.max_frame_delay_s` and the recorded frames.
    pub late_frames_tracked: u64,
    /// Newer frames tracked again after a late frame (each late frame replays the frames
    /// it went before).
    pub frames_replayed: u64,
    /// Frames rejected because they were older than the newest tracked frame by more
    /// than the late-frame window (`tracker.max_frame_delay_s`, `tracker.replay_frames`)
    /// reaches.
    pub frames_rejected_too_late: u64,
    /// Ego poses that jumped further or turned faster than `tracker.max_ego_speed_mps`
    /// and `tracker.max_ego_yaw_rate_radps` allow since the previous frame: odometry
    /// resets, across which the tracks kept their place around the vehicle.
    pub odometry_resets: u64,
    /// Track updates in which the measurement's radial velocity was applied as a
    /// measurement of the velocity (`classes.<class>.radial_velocity_update`).
    pub radial_velocity_updates: u64,
    /// Track updates whose radial-velocity row lay beyond
    /// `radial_velocity_update.gate_std` in every mode and was left out.
    pub radial_velocity_updates_gated: u64,
    /// Track updates and initiations after which a velocity estimate was faster than the
    /// class's `max_speed_mps` and was scaled back onto it (steps with an ego pose only).
    pub speeds_bounded: u64,
    /// Updates and initiations of a class with a radial-velocity row or an extent whose
    /// measurement's sensor has no configured mount: seen from the vehicle's reference
    /// point.
    pub updates_from_unknown_sensor: u64,
    /// Unassigned measurements absorbed as extra detections of a confirmed track's
    /// extended object (`classes.<class>.extent.absorb_extra_detections`): they started
    /// no track.
    pub detections_absorbed: u64,
    /// Detections of point-cloud radars that joined another detection's group.
    pub detections_grouped: u64,
    /// Existing tracks updated by an assigned measurement.
    pub tracks_updated: u64,
    /// Tracks without a measurement while a sensor of the frame had them in view (their
    /// existence fell); tracks out of every scanning sensor's view are not counted.
    pub tracks_missed_in_view: u64,
}

/// `PrimmStats` from `TrackerStats`, one field per counter of the list.
macro_rules! primm_stats_from_tracker_stats {
    ($( $(#[$doc:meta])* $name:ident : $kind:ident, )*) => {
        impl From<&TrackerStats> for PrimmStats {
            fn from(stats: &TrackerStats) -> Self {
                PrimmStats { $( $name: stats.$name, )* }
            }
        }
    };
}

primm_core::tracker_counters!(primm_stats_from_tracker_stats);

/// A 4×4 matrix as 16 values, row-major.
fn row_major(matrix: &glam::DMat4) -> [f64; 16] {
    matrix.transpose().to_cols_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_c_counters_are_the_core_s_in_the_order_of_its_list() {
        const COUNT: usize = TrackerStats::COUNT;
        assert_eq!(core::mem::size_of::<PrimmStats>(), COUNT * core::mem::size_of::<u64>());
        let values: [u64; COUNT] = core::array::from_fn(|index| 1000 + index as u64);
        let stats = TrackerStats::from_values(values);
        let names: [&str; COUNT] = TrackerStats::NAMES;
        assert_eq!(stats.named_values().map(|(name, _)| name), names);
        assert_eq!(stats.named_values().map(|(_, value)| value), values);
        let c_stats = PrimmStats::from(&stats);
        // SAFETY: `PrimmStats` is `repr(C)` and holds `COUNT` `u64` fields (size checked above),
        // so it has the layout of `[u64; COUNT]`.
        let c_values: [u64; COUNT] = unsafe { core::mem::transmute(c_stats) };
        assert_eq!(c_values, values);
        assert_eq!(c_stats.speeds_bounded, stats.speeds_bounded);
    }
}
