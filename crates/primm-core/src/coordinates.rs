//! Which coordinate frame the tracker keeps its tracks in, and where the radars sit on the
//! vehicle (the `frame` section of the configuration).
//!
//! Measurement positions arrive in the vehicle frame, which moves and turns with the ego
//! vehicle, while their radial velocities are ego-motion compensated: they are radial
//! velocities over ground. Tracking in the vehicle frame therefore starts a parked car ahead of
//! a moving ego with the wrong velocity and sees stationary objects sweep arcs while the ego
//! turns. When a frame carries the ego pose ([`FrameView::ego_pose`]) and the configuration
//! asks for [`CoordinateFrame::World`], the tracker maps every measurement into the world
//! (odometry) frame with that pose and keeps its tracks there; the line of sight of a radial
//! velocity then starts at the world position of the sensor that measured it.
//!
//! Naming: in primm a *frame* alone is a time sample (`Frame`, `FrameView`, the wire's
//! `MeasurementFrame` and `TrackFrame`). A coordinate frame is always called one
//! ([`CoordinateFrame`], [`CoordinatesConfig`]); poses map points with
//! [`EgoPose::point_to_world`](crate::pose::EgoPose::point_to_world) and give whole transforms
//! with [`EgoPose::vehicle_to_world`](crate::pose::EgoPose::vehicle_to_world). The
//! configuration keys keep their names (`frame.tracking_frame`, `frame.sensors`).
//!
//! [`FrameView::ego_pose`]: crate::measurement::FrameView::ego_pose

use crate::limits::MAX_SENSORS;
use crate::pose::SensorMount;
use arrayvec::ArrayVec;

/// Largest distance of a sensor mount from the vehicle's reference point, m.
pub const MAX_MOUNT_DISTANCE_M: f64 = 100.0;

/// Largest azimuth standard deviation of a sensor, rad (about 29°: beyond it a radar's
/// azimuth carries no information a tracker could use).
pub const MAX_AZIMUTH_STD_RAD: f64 = 0.5;
/// Largest off-boresight growth of a sensor's azimuth standard deviation, dimensionless (the
/// secant reaches 10 at 84°).
pub const MAX_AZIMUTH_STD_FACTOR: f64 = 10.0;

/// The coordinate frame of the tracks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum CoordinateFrame {
    /// The world (odometry) frame of the frames' ego poses; frames without a pose are tracked
    /// in the vehicle frame (see the tracker's documentation for a stream that switches).
    #[default]
    World,
    /// The vehicle frame of each frame, whatever the frames carry; line of sight from the
    /// vehicle's reference point.
    Vehicle,
}

impl CoordinateFrame {
    /// The short name used in configuration and output (`world`, `vehicle`).
    pub fn name(self) -> &'static str {
        match self {
            CoordinateFrame::World => "world",
            CoordinateFrame::Vehicle => "vehicle",
        }
    }

    /// Parses the short name; `None` for anything else.
    pub fn from_name(name: &str) -> Option<Self> {
        [CoordinateFrame::World, CoordinateFrame::Vehicle].into_iter().find(|frame| frame.name() == name)
    }
}

/// The `frame` section: the tracking frame and the sensors' mounting poses.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CoordinatesConfig {
    /// The frame the tracks are kept in when frames carry an ego pose.
    pub tracking_frame: CoordinateFrame,
    /// Mounting pose of every sensor, by sensor id. A measurement of a sensor not listed here
    /// (or without a sensor id) is seen from the vehicle's reference point, and counted.
    pub sensors: ArrayVec<SensorMount, MAX_SENSORS>,
    /// A radar without a configured mount is taken to look where its detections of the frame
    /// lie, seen from the vehicle's reference point: the sector around them, widened by this
    /// angle on each side, rad (absent: 0.35, 20°; π: every direction), out to the farthest
    /// detection plus `unknown_sensor_margin_m`. Tracks outside it lose no existence by not
    /// being detected in that frame.
    #[cfg_attr(feature = "serde", serde(default = "default_unknown_sensor_margin_rad"))]
    pub unknown_sensor_margin_rad: f64,
    /// See `unknown_sensor_margin_rad`, m (absent: 10).
    #[cfg_attr(feature = "serde", serde(default = "default_unknown_sensor_margin_m"))]
    pub unknown_sensor_margin_m: f64,
    /// Where the detections of radars without a configured mount lie on an extended object:
    /// `"outline"`, `"centre"` or `"auto"` (absent: outline; `crate::sensor`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub unmounted_reflection: crate::sensor::ReflectionModel,
    /// What one detection of a radar without a configured mount is: `"points"`, `"objects"` or
    /// `"auto"` (absent: auto; `crate::grouping`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub unmounted_detections: crate::grouping::DetectionModel,
    /// Whether the sensors move: `"moving"` (a frame without an ego pose is tracked in the
    /// vehicle frame), `"stationary"` (a roadside or intersection radar: such a frame is taken
    /// at the world origin, so its tracks are kept in the world frame, where radial velocities
    /// are over ground and speeds are bounded) or `"auto"` (as the data say; absent: auto;
    /// `crate::sensor::platform`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub platform: crate::sensor::platform::PlatformModel,
    /// How the detections of point-cloud radars are grouped (absent: the defaults of
    /// [`GroupingConfig`](crate::grouping::GroupingConfig)).
    #[cfg_attr(feature = "serde", serde(default))]
    pub grouping: crate::grouping::GroupingConfig,
    /// How fast the sensors' running estimates move (absent: the defaults of
    /// [`EstimationConfig`](crate::sensor::estimates::EstimationConfig)).
    #[cfg_attr(feature = "serde", serde(default))]
    pub estimation: crate::sensor::estimates::EstimationConfig,
}

/// `frame.unknown_sensor_margin_rad` when absent.
pub const DEFAULT_UNKNOWN_SENSOR_MARGIN_RAD: f64 = 0.35;
/// `frame.unknown_sensor_margin_m` when absent.
pub const DEFAULT_UNKNOWN_SENSOR_MARGIN_M: f64 = 10.0;

#[cfg(feature = "serde")]
fn default_unknown_sensor_margin_rad() -> f64 {
    DEFAULT_UNKNOWN_SENSOR_MARGIN_RAD
}

#[cfg(feature = "serde")]
fn default_unknown_sensor_margin_m() -> f64 {
    DEFAULT_UNKNOWN_SENSOR_MARGIN_M
}

impl Default for CoordinatesConfig {
    /// World frame; RadarScenes' four front and side radars (ids 1–4), as the scenario
    /// generator mounts them.
    fn default() -> Self {
        // Opening ±60° and range 100 m, as the generator's radars (`primm_sim::scenario`).
        let mount = |id, x_m, y_m, yaw_deg: f64| SensorMount {
            id,
            x_m,
            y_m,
            yaw_rad: yaw_deg.to_radians(),
            half_fov_rad: 60f64.to_radians(),
            max_range_m: 100.0,
            detection_probability_factor: 1.0,
            clutter_density_factor: 1.0,
            // The radar's own noise, chosen on validation (`config/primm.toml`).
            range_std_m: 0.12,
            azimuth_std_rad: 0.0105,
            azimuth_std_max_factor: 1.0,
            reflection: crate::sensor::ReflectionModel::Outline,
            detections: Default::default(),
        };
        let mut sensors = ArrayVec::new();
        sensors.push(mount(1, 3.66, -0.87, -85.0));
        sensors.push(mount(2, 3.86, -0.70, -25.0));
        sensors.push(mount(3, 3.86, 0.70, 25.0));
        sensors.push(mount(4, 3.66, 0.87, 85.0));
        CoordinatesConfig {
            tracking_frame: CoordinateFrame::World,
            sensors,
            unknown_sensor_margin_rad: DEFAULT_UNKNOWN_SENSOR_MARGIN_RAD,
            unknown_sensor_margin_m: DEFAULT_UNKNOWN_SENSOR_MARGIN_M,
            unmounted_reflection: crate::sensor::ReflectionModel::Outline,
            unmounted_detections: crate::grouping::DetectionModel::Auto,
            platform: crate::sensor::platform::PlatformModel::Auto,
            grouping: crate::grouping::GroupingConfig::default(),
            estimation: crate::sensor::estimates::EstimationConfig::default(),
        }
    }
}

impl CoordinatesConfig {
    /// The mount of sensor `id`, if configured.
    pub fn sensor(&self, id: u16) -> Option<&SensorMount> {
        self.sensors.iter().find(|mount| mount.id == id)
    }

    /// The first problem of the section, as (key, reason).
    pub(crate) fn problem(&self) -> Option<(&'static str, &'static str)> {
        if !(0.0..=core::f64::consts::PI).contains(&self.unknown_sensor_margin_rad) {
            return Some(("frame.unknown_sensor_margin_rad", "must lie in [0, pi]"));
        }
        if !(self.unknown_sensor_margin_m.is_finite() && self.unknown_sensor_margin_m >= 0.0) {
            return Some(("frame.unknown_sensor_margin_m", "must be a finite number >= 0"));
        }
        if let Some(problem) = self.estimation.problem() {
            return Some(problem);
        }
        if let Some(problem) = self.grouping.problem() {
            return Some(problem);
        }
        for (index, mount) in self.sensors.iter().enumerate() {
            if !(mount.x_m.is_finite() && mount.y_m.is_finite() && mount.yaw_rad.is_finite()) {
                return Some(("frame.sensors", "every x_m, y_m and yaw_rad must be finite"));
            }
            if mount.x_m * mount.x_m + mount.y_m * mount.y_m > MAX_MOUNT_DISTANCE_M * MAX_MOUNT_DISTANCE_M {
                return Some((
                    "frame.sensors",
                    "a sensor is mounted more than 100 m from the reference point",
                ));
            }
            if !(mount.half_fov_rad > 0.0 && mount.half_fov_rad <= core::f64::consts::PI) {
                return Some(("frame.sensors", "every half_fov_rad must lie in (0, pi]"));
            }
            if !(mount.max_range_m > 0.0 && mount.max_range_m.is_finite()) {
                return Some(("frame.sensors", "every max_range_m must be a finite number > 0"));
            }
            if !(mount.detection_probability_factor > 0.0 && mount.detection_probability_factor.is_finite()) {
                return Some((
                    "frame.sensors",
                    "every detection_probability_factor must be a finite number > 0",
                ));
            }
            if !(mount.clutter_density_factor >= 0.0 && mount.clutter_density_factor.is_finite()) {
                return Some(("frame.sensors", "every clutter_density_factor must be a finite number >= 0"));
            }
            if !(mount.range_std_m >= 0.0 && mount.range_std_m.is_finite()) {
                return Some(("frame.sensors", "every range_std_m must be a finite number >= 0"));
            }
            if !(mount.azimuth_std_rad >= 0.0 && mount.azimuth_std_rad <= MAX_AZIMUTH_STD_RAD) {
                return Some(("frame.sensors", "every azimuth_std_rad must lie in [0, 0.5]"));
            }
            if !(mount.azimuth_std_max_factor >= 1.0
                && mount.azimuth_std_max_factor <= MAX_AZIMUTH_STD_FACTOR)
            {
                return Some(("frame.sensors", "every azimuth_std_max_factor must lie in [1, 10]"));
            }
            if self.sensors[..index].iter().any(|other| other.id == mount.id) {
                return Some(("frame.sensors", "sensor ids must be unique"));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_mounts_are_valid_and_found_by_id() {
        let config = CoordinatesConfig::default();
        assert_eq!(config.problem(), None);
        assert_eq!(config.sensor(3).map(|mount| mount.y_m), Some(0.70));
        assert_eq!(config.sensor(0), None);
    }

    #[test]
    fn duplicate_ids_and_non_finite_mounts_are_problems() {
        let mut config = CoordinatesConfig::default();
        config.sensors[1].id = 1;
        assert_eq!(config.problem().map(|p| p.1), Some("sensor ids must be unique"));
        let mut config = CoordinatesConfig::default();
        config.sensors[0].yaw_rad = f64::NAN;
        assert!(config.problem().is_some());
        let mut config = CoordinatesConfig::default();
        config.sensors[0].x_m = 1e3;
        assert!(config.problem().is_some());
    }
}
