//! Object-level radar measurements and frames (paper, Section III-A, `eq:measurement_full`).
//!
//! A measurement is the averaged reflection of one object in one radar scan:
//! position in the vehicle frame (x longitudinal, y lateral, metres), ego-motion compensated
//! radial velocity (m/s, positive moving away from the sensor) and radar cross section (dBsm).

use arrayvec::ArrayVec;

use crate::pose::EgoPose;

pub use crate::limits::MAX_MEASUREMENTS_PER_FRAME;

/// Object classes. The paper merges RadarScenes' *car* + *large vehicle* into [`ObjectClass::Car`]
/// and *pedestrian* + *pedestrian group* into [`ObjectClass::Pedestrian`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[repr(u8)]
pub enum ObjectClass {
    /// Passenger cars and large vehicles.
    Car = 0,
    /// Pedestrians and pedestrian groups.
    Pedestrian = 1,
    /// Bicycles and motorcycles; reserved, not tracked by the default configuration.
    TwoWheeler = 2,
}

impl ObjectClass {
    /// Number of enum variants (size of per-class tables).
    pub const COUNT: usize = 3;
    /// All classes, in code order.
    pub const ALL: [ObjectClass; Self::COUNT] =
        [ObjectClass::Car, ObjectClass::Pedestrian, ObjectClass::TwoWheeler];

    /// The class for a wire code, or `None` for an unknown code.
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(usize::from(code)).copied()
    }

    /// The wire code of this class.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// Index into per-class tables.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The short name used in files and configuration (`car`, `pedestrian`, `two_wheeler`).
    pub fn name(self) -> &'static str {
        match self {
            ObjectClass::Car => "car",
            ObjectClass::Pedestrian => "pedestrian",
            ObjectClass::TwoWheeler => "two_wheeler",
        }
    }

    /// Parses the short name; `None` for anything else.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|class| class.name() == name)
    }
}

impl core::fmt::Display for ObjectClass {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// A set of object classes, as a bit mask indexed by [`ObjectClass::index`]. In configuration
/// files it is a list of class names (`["pedestrian", "two_wheeler"]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ClassSet(u8);

impl ClassSet {
    /// No class.
    pub const EMPTY: ClassSet = ClassSet(0);
    /// Every class.
    pub const ALL: ClassSet = ClassSet((1 << ObjectClass::COUNT) - 1);

    /// The set of the given classes.
    pub fn of(classes: &[ObjectClass]) -> Self {
        classes.iter().fold(Self::EMPTY, |set, &class| set.with(class))
    }

    /// This set plus `class`.
    pub fn with(self, class: ObjectClass) -> Self {
        ClassSet(self.0 | (1 << class.index()))
    }

    /// This set without `class`.
    pub fn without(self, class: ObjectClass) -> Self {
        ClassSet(self.0 & !(1 << class.index()))
    }

    /// Whether `class` is in the set.
    pub fn contains(self, class: ObjectClass) -> bool {
        self.0 & (1 << class.index()) != 0
    }

    /// Number of classes in the set.
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The classes of the set in code order.
    pub fn iter(self) -> impl Iterator<Item = ObjectClass> {
        ObjectClass::ALL.into_iter().filter(move |&class| self.contains(class))
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for ClassSet {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for ClassSet {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let classes = alloc::vec::Vec::<ObjectClass>::deserialize(deserializer)?;
        Ok(ClassSet::of(&classes))
    }
}

/// One object-level radar measurement (`eq:measurement_full`) with its class.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Measurement {
    /// Longitudinal position in the vehicle frame, metres.
    pub x_m: f64,
    /// Lateral position in the vehicle frame, metres.
    pub y_m: f64,
    /// Ego-motion compensated radial velocity, m/s, positive moving away.
    pub radial_velocity_mps: f64,
    /// Radar cross section, dBsm.
    pub rcs_dbsm: f64,
    /// Object class reported by the detector.
    pub class: ObjectClass,
    /// Radar sensor that produced the measurement, if known.
    pub sensor_id: Option<u16>,
    /// Ground-truth identity, carried through for evaluation only; the tracker never reads it.
    pub ground_truth_id: Option<u64>,
}

impl Measurement {
    /// The observed position `z = [x, y]` (`eq:observation`).
    pub fn position(&self) -> glam::DVec2 {
        glam::DVec2::new(self.x_m, self.y_m)
    }
}

/// A read-only view of one frame, implemented by owned frames and by shared-memory samples so
/// that the tracker reads measurements in place.
pub trait FrameView {
    /// Frame time, seconds on the sensor clock.
    fn timestamp_s(&self) -> f64;
    /// Number of measurements the frame claims to carry.
    fn len(&self) -> usize;
    /// Whether the frame carries no measurement.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Decodes measurement `index` (`index < len()`); an unknown class code is an error.
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass>;
    /// The ego vehicle's pose in the world frame at the frame's time, if the frame carries one.
    /// With a pose the tracker keeps its tracks in the world frame (see
    /// [`CoordinateFrame`](crate::config::CoordinateFrame)).
    fn ego_pose(&self) -> Option<EgoPose> {
        None
    }
}

/// A class code that names no [`ObjectClass`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("unknown object class code {code}")]
pub struct UnknownClass {
    /// The offending code.
    pub code: u8,
}

/// An owned frame with a fixed capacity, for offline replays and tests.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Frame time, seconds.
    pub timestamp_s: f64,
    /// The frame's measurements.
    pub measurements: ArrayVec<Measurement, MAX_MEASUREMENTS_PER_FRAME>,
    /// The ego vehicle's pose in the world frame, if known.
    pub ego_pose: Option<EgoPose>,
}

impl Frame {
    /// An empty frame at `timestamp_s`.
    pub fn new(timestamp_s: f64) -> Self {
        Self { timestamp_s, measurements: ArrayVec::new(), ego_pose: None }
    }
}

impl FrameView for Frame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }
    fn len(&self) -> usize {
        self.measurements.len()
    }
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        Ok(self.measurements[index])
    }
    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}
