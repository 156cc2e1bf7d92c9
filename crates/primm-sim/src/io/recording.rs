//! Recorded sequences: the in-memory form of a measurement file and of generated scenarios.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::eval::record::AssociationRecord;
use primm_core::measurement::{Frame, Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};

/// Pose of the ego vehicle's reference point (centre of the rear axle, as in RadarScenes) in a
/// fixed world frame (defined in primm-core, which transforms measurements with it).
pub use primm_core::pose::EgoPose;

/// One object-level measurement of a recorded frame, with its true position and velocity where
/// known.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RecordedMeasurement {
    /// The measurement as the tracker receives it.
    pub measurement: Measurement,
    /// True centre of the object in the car frame, metres (simulated data only).
    pub true_position: Option<DVec2>,
    /// True velocity over ground of the object's centre in the car frame's axes (x forward,
    /// y left), m/s (simulated data only).
    #[serde(default)]
    pub true_velocity: Option<DVec2>,
    /// What produced the measurement, where the data source knows it (simulation): a real
    /// object, clutter or a multipath ghost.
    #[serde(default)]
    pub origin: Option<MeasurementOrigin>,
}

/// What produced a measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeasurementOrigin {
    /// A reflection of a real object (its ground-truth id says which).
    Object,
    /// A false detection of the static world or of noise: guard rails, poles, kerbs.
    Clutter,
    /// A multipath ghost: the mirror image of a real object's reflection in a wall or guard
    /// rail, or a delayed copy of it farther along the line of sight.
    Ghost,
}

impl MeasurementOrigin {
    /// All origins.
    pub const ALL: [MeasurementOrigin; 3] =
        [MeasurementOrigin::Object, MeasurementOrigin::Clutter, MeasurementOrigin::Ghost];

    /// The origin's name in files: `object`, `clutter` or `ghost`.
    pub fn name(self) -> &'static str {
        match self {
            MeasurementOrigin::Object => "object",
            MeasurementOrigin::Clutter => "clutter",
            MeasurementOrigin::Ghost => "ghost",
        }
    }

    /// The origin called `name` ([`name`](Self::name)), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|origin| origin.name() == name)
    }
}

/// One radar scan: its index in the sequence, time, sensor, ego pose and measurements.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordedFrame {
    /// 0-based frame index within its sequence; unique in it (frames are listed in arrival order,
    /// so a late frame's index may be smaller than the one before).
    pub index: u64,
    /// Scan time, seconds since the start of the sequence.
    pub timestamp_s: f64,
    /// Radar sensor that produced the scan, if known.
    pub sensor_id: Option<u16>,
    /// Ego pose at scan time, if known.
    pub ego_pose: Option<EgoPose>,
    /// Object measurements of this scan (possibly none).
    pub measurements: Vec<RecordedMeasurement>,
}

impl RecordedFrame {
    /// The evaluation row of measurement `m` of this frame before any track is known to have
    /// taken it.
    pub fn unassigned_record(&self, m: &RecordedMeasurement) -> AssociationRecord {
        AssociationRecord {
            frame: self.index,
            timestamp_s: self.timestamp_s,
            ground_truth_id: m.measurement.ground_truth_id,
            class: m.measurement.class,
            measured: m.measurement.position(),
            true_position: m.true_position,
            true_velocity: m.true_velocity,
            origin: m.origin,
            track_id: None,
            prior: None,
            velocity: None,
            mode_probabilities: None,
            track_confirmed: Some(false),
        }
    }
}

/// A recorded frame holds more measurements than [`MAX_MEASUREMENTS_PER_FRAME`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("frame {frame} holds {count} measurements, more than the limit of {max}", max = MAX_MEASUREMENTS_PER_FRAME)]
pub struct TooManyMeasurements {
    /// Index of the offending frame.
    pub frame: u64,
    /// Number of measurements it holds.
    pub count: usize,
}

impl RecordedFrame {
    /// An empty frame.
    pub fn new(index: u64, timestamp_s: f64) -> Self {
        Self { index, timestamp_s, sensor_id: None, ego_pose: None, measurements: Vec::new() }
    }

    /// Converts into the library's fixed-capacity [`Frame`]. Ground-truth ids, classes and
    /// sensor ids and the ego pose are carried through unchanged; true positions and
    /// velocities are dropped.
    pub fn to_frame(&self) -> Result<Frame, TooManyMeasurements> {
        if self.measurements.len() > MAX_MEASUREMENTS_PER_FRAME {
            return Err(TooManyMeasurements { frame: self.index, count: self.measurements.len() });
        }
        let mut frame = Frame::new(self.timestamp_s);
        frame.measurements.extend(self.measurements.iter().map(|m| m.measurement));
        frame.ego_pose = self.ego_pose;
        Ok(frame)
    }

    /// Number of measurements of class `class`.
    pub fn count_class(&self, class: ObjectClass) -> usize {
        self.measurements.iter().filter(|m| m.measurement.class == class).count()
    }
}

/// A named sequence of recorded frames (one measurement file).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Sequence {
    /// Name of the sequence, e.g. the file stem of its CSV file.
    pub name: String,
    /// Frames in time order.
    pub frames: Vec<RecordedFrame>,
}

impl Sequence {
    /// Whether any frame carries an ego pose.
    pub fn has_ego_pose(&self) -> bool {
        self.frames.iter().any(|frame| frame.ego_pose.is_some())
    }

    /// An empty sequence called `name`.
    pub fn new(name: impl Into<String>) -> Self {
        Self { name: name.into(), frames: Vec::new() }
    }

    /// Total number of object measurements over all frames.
    pub fn measurement_count(&self) -> usize {
        self.frames.iter().map(|f| f.measurements.len()).sum()
    }

    /// Number of object measurements of class `class` over all frames.
    pub fn class_count(&self, class: ObjectClass) -> usize {
        self.frames.iter().map(|f| f.count_class(class)).sum()
    }

    /// Time between the first and the last frame, seconds (0 for fewer than two frames).
    pub fn duration_s(&self) -> f64 {
        match (self.frames.first(), self.frames.last()) {
            (Some(first), Some(last)) => last.timestamp_s - first.timestamp_s,
            _ => 0.0,
        }
    }

    /// The frames converted into library [`Frame`]s, in order.
    pub fn to_frames(&self) -> Result<Vec<Frame>, TooManyMeasurements> {
        self.frames.iter().map(RecordedFrame::to_frame).collect()
    }
}
