//! One track: its IMM state, the measurement history the learned predictor reads, lifecycle
//! counters; and the per-frame output record.

use crate::imm::{ImmState, ModeProbabilities};
use crate::measurement::{Measurement, ObjectClass};
use crate::pose::RigidTransform;
use crate::predictor::{HistoryEntry, RememberedDisplacement, MAX_HISTORY};
use glam::{DMat2, DMat4, DVec2};
use heapless::HistoryBuf;

/// Lifecycle status of a track.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[repr(u8)]
pub enum TrackStatus {
    /// Started by an unassigned measurement, not yet confirmed by enough hits.
    Tentative = 0,
    /// Confirmed (by `tracker.confirmation_hits` hits, or by its existence probability) and
    /// detected the last time a sensor had it in view.
    Confirmed = 1,
    /// Confirmed, but missed the last time a sensor had it in view: its state is a
    /// prediction since then. The next detection makes it [`Confirmed`](Self::Confirmed) again.
    Coasting = 2,
}

impl TrackStatus {
    /// Whether the track has been confirmed ([`Confirmed`](Self::Confirmed) or
    /// [`Coasting`](Self::Coasting)).
    pub fn is_confirmed(self) -> bool {
        matches!(self, TrackStatus::Confirmed | TrackStatus::Coasting)
    }

    /// The short name used in files (`tentative`, `confirmed`, `coasting`).
    pub fn name(self) -> &'static str {
        match self {
            TrackStatus::Tentative => "tentative",
            TrackStatus::Confirmed => "confirmed",
            TrackStatus::Coasting => "coasting",
        }
    }

    /// The status of a wire code (0, 1, 2), `None` for any other.
    pub fn from_code(code: u8) -> Option<Self> {
        [TrackStatus::Tentative, TrackStatus::Confirmed, TrackStatus::Coasting]
            .get(usize::from(code))
            .copied()
    }

    /// The status of a short name, `None` for any other.
    pub fn from_name(name: &str) -> Option<Self> {
        [TrackStatus::Tentative, TrackStatus::Confirmed, TrackStatus::Coasting]
            .into_iter()
            .find(|status| status.name() == name)
    }
}

/// A live track. A small `Copy` value; the table holds them in place.
#[derive(Debug, Clone)]
pub struct Track {
    /// Unique id, never reused within a run.
    pub id: u64,
    /// Class of the measurements the track is built from.
    pub class: ObjectClass,
    /// Lifecycle status.
    pub status: TrackStatus,
    /// IMM posterior.
    pub estimate: ImmState,
    /// The last associated measurements, oldest first: the learned predictor's input.
    pub history: HistoryBuf<HistoryEntry, MAX_HISTORY>,
    /// Radial velocity of the last associated measurement, m/s (`v_r^last` in `eq:association_cost`).
    pub last_radial_velocity_mps: f64,
    /// Time of the last associated measurement, s.
    pub last_update_s: f64,
    /// Time of the measurement that started the track, s.
    pub started_s: f64,
    /// Frames since the track started (0 in its first frame).
    pub age_frames: u32,
    /// Associated measurements, including the initiating one.
    pub hits: u32,
    /// Consecutive frames without an associated measurement.
    pub misses: u32,
    /// Probability that the track's object exists (see [`crate::existence`]).
    pub existence_probability: f64,
    /// Ground-truth id of the last associated measurement (evaluation only).
    pub ground_truth_id: Option<u64>,
    /// The older track of the same class this one has overlapped with (see
    /// [`crate::duplicates`]), and for how many consecutive updates of either of the two
    /// without one of the other in the same frame.
    pub duplicate_of: Option<u64>,
    /// See [`duplicate_of`](Self::duplicate_of).
    pub exclusive_updates: u32,
    /// The learned predictor's latest `f(t)` for this track's history, reused as `f(t_{k−1})`
    /// when the track is not measured (see [`crate::predictor`], "Which displacement").
    pub remembered_displacement: Option<RememberedDisplacement>,
    /// Where the sensor of the track's latest update was relative to the track's prior centre
    /// then, m (an extended class's; `None` before the first update): the geometry the sensors'
    /// reflection estimates compare the next update's with (`crate::sensor::estimates`).
    pub sensor_relative_m: Option<DVec2>,
    /// The slot of the sensor whose measurement started the track in the tracker's
    /// [`SensorSet`](crate::sensor::SensorSet).
    pub birth_sensor_slot: u8,
}

impl Track {
    /// A new tentative track from its first measurement and timestamp, with existence
    /// probability `existence_probability`.
    pub fn new(
        id: u64,
        measurement: &Measurement,
        sensor_m: DVec2,
        timestamp_s: f64,
        estimate: ImmState,
        existence_probability: f64,
    ) -> Self {
        let mut track = Track {
            id,
            class: measurement.class,
            status: TrackStatus::Tentative,
            estimate,
            history: HistoryBuf::new(),
            last_radial_velocity_mps: measurement.radial_velocity_mps,
            last_update_s: timestamp_s,
            started_s: timestamp_s,
            age_frames: 0,
            hits: 1,
            misses: 0,
            existence_probability,
            ground_truth_id: measurement.ground_truth_id,
            duplicate_of: None,
            exclusive_updates: 0,
            remembered_displacement: None,
            sensor_relative_m: None,
            birth_sensor_slot: crate::sensor::UNMOUNTED as u8,
        };
        track.history.write(HistoryEntry::from_measurement(measurement, sensor_m, timestamp_s));
        track
    }

    /// Moves the track into another frame: its state (see [`ImmState::transformed`]) and the
    /// positions of its measurement history. The remembered learned displacement is dropped:
    /// it was predicted in the old frame.
    pub fn transform(&mut self, transform: &RigidTransform) {
        self.estimate = self.estimate.transformed(transform);
        self.remembered_displacement = None;
        self.sensor_relative_m = self.sensor_relative_m.map(|offset| transform.apply_vector(offset));
        let mut entries = [HistoryEntry::default(); MAX_HISTORY];
        let mut len = 0;
        for entry in self.history.oldest_ordered() {
            let position = transform.apply_point(DVec2::new(entry.x_m, entry.y_m));
            let sensor = transform.apply_point(DVec2::new(entry.sensor_x_m, entry.sensor_y_m));
            entries[len] = HistoryEntry {
                x_m: position.x,
                y_m: position.y,
                sensor_x_m: sensor.x,
                sensor_y_m: sensor.y,
                ..*entry
            };
            len += 1;
        }
        self.history.clear();
        for entry in &entries[..len] {
            self.history.write(*entry);
        }
    }

    /// Adds the velocity field `field` times `sign` to every mode's velocity: the same motion
    /// seen against another reference (the ego's motion, where the track changes between the
    /// vehicle and the world frame). Only where the CV velocity it leads to is no faster than
    /// `max_speed_mps` (no object moves faster; far from a turning ego the field's rotation term
    /// grows without bound); otherwise the track is left as it was. Returns whether it was
    /// applied.
    pub fn add_velocity_field(
        &mut self,
        field: &crate::pose::RigidVelocity,
        sign: f64,
        max_speed_mps: f64,
    ) -> bool {
        let cv = &self.estimate.constant_velocity.mean;
        let position = DVec2::new(cv[0], cv[1]);
        let plausible = (DVec2::new(cv[2], cv[3]) + sign * field.at(position)).length() <= max_speed_mps;
        if plausible {
            self.estimate.add_velocity_field(field, sign);
            self.remembered_displacement = None;
        }
        plausible
    }

    /// Records an associated measurement taken by the radar at `sensor_m` (a coasting track is
    /// confirmed again; confirming a tentative one is the lifecycle's decision).
    pub fn record_hit(&mut self, measurement: &Measurement, sensor_m: DVec2, timestamp_s: f64) {
        self.history.write(HistoryEntry::from_measurement(measurement, sensor_m, timestamp_s));
        self.last_radial_velocity_mps = measurement.radial_velocity_mps;
        self.last_update_s = timestamp_s;
        self.hits = self.hits.saturating_add(1);
        self.misses = 0;
        self.ground_truth_id = measurement.ground_truth_id;
        if self.status == TrackStatus::Coasting {
            self.status = TrackStatus::Confirmed;
        }
    }

    /// Records a frame without associated measurement.
    pub fn record_miss(&mut self) {
        self.misses = self.misses.saturating_add(1);
    }
}

impl HistoryEntry {
    /// The history entry of a measurement taken at `timestamp_s` by the radar at `sensor_m`.
    pub fn from_measurement(measurement: &Measurement, sensor_m: DVec2, timestamp_s: f64) -> Self {
        HistoryEntry {
            x_m: measurement.x_m,
            y_m: measurement.y_m,
            radial_velocity_mps: measurement.radial_velocity_mps,
            rcs_dbsm: measurement.rcs_dbsm,
            timestamp_s,
            sensor_x_m: sensor_m.x,
            sensor_y_m: sensor_m.y,
        }
    }
}

/// What the tracker reports for every live track after a frame. The default is an empty
/// record (id 0, zeros), for buffers filled by [`Tracker::predict_to`](crate::tracker::Tracker::predict_to).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TrackOutput {
    /// Track id.
    pub id: u64,
    /// Object class.
    pub class: ObjectClass,
    /// Lifecycle status.
    pub status: TrackStatus,
    /// Fused posterior position (`eq:posterior_fusion`), m.
    pub position_m: DVec2,
    /// Covariance of the fused position (with the spread of the mode means), m²: the upper-left
    /// block of [`state_covariance`](Self::state_covariance).
    pub position_covariance_m2: DMat2,
    /// Fused velocity estimate, m/s.
    pub velocity_mps: DVec2,
    /// Covariance of the fused position and velocity `[x, y, vx, vy]` (m², m²/s, m²/s²), in the
    /// frame of `position_m` and `velocity_mps`, with the spread of the mode means (see
    /// [`Imm::fuse_position_velocity`](crate::imm::Imm::fuse_position_velocity)).
    pub state_covariance: DMat4,
    /// Fused one-step prior used for association (`eq:prior_fusion`), m; `None` for a track
    /// started in this frame.
    pub prior_position_m: Option<DVec2>,
    /// Fused position in the world frame, m, when the frame was tracked in the world frame
    /// (then `position_m` and `prior_position_m` are in the vehicle frame of this frame, and
    /// `velocity_mps` is the velocity over ground in the vehicle's axes).
    pub world_position_m: Option<DVec2>,
    /// Fused velocity over ground in the world frame, m/s, when the frame was tracked in the
    /// world frame.
    pub world_velocity_mps: Option<DVec2>,
    /// Covariance of `[x, y, vx, vy]` in the world frame, when the frame was tracked in the
    /// world frame.
    pub world_state_covariance: Option<DMat4>,
    /// Posterior mode probabilities, order PR, CV, CA, CT (inactive modes 0).
    pub mode_probabilities: ModeProbabilities,
    /// Frames since the track started.
    pub age_frames: u32,
    /// Time since the track's first measurement, s (at the time of the outputs: the newest
    /// tracked frame's, or the requested time of a prediction).
    pub age_s: f64,
    /// Associated measurements so far.
    pub hits: u32,
    /// Consecutive frames without measurement (0 when updated in this frame).
    pub misses: u32,
    /// Probability that the track's object exists (see [`crate::existence`]).
    pub existence_probability: f64,
    /// Ground-truth id of the measurement that updated or started the track in this frame.
    pub ground_truth_id: Option<u64>,
    /// Index in this frame of the measurement that updated or started the track; `None` when
    /// the track coasted.
    pub measurement_index: Option<u16>,
}

impl Default for TrackOutput {
    fn default() -> Self {
        TrackOutput {
            id: 0,
            class: ObjectClass::Car,
            status: TrackStatus::Tentative,
            position_m: DVec2::ZERO,
            position_covariance_m2: DMat2::ZERO,
            velocity_mps: DVec2::ZERO,
            state_covariance: DMat4::ZERO,
            prior_position_m: None,
            world_position_m: None,
            world_velocity_mps: None,
            world_state_covariance: None,
            mode_probabilities: [0.0; crate::mode::MODE_COUNT],
            age_frames: 0,
            age_s: 0.0,
            hits: 0,
            misses: 0,
            existence_probability: 0.0,
            ground_truth_id: None,
            measurement_index: None,
        }
    }
}
