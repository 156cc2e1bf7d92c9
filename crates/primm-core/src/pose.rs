//! Poses in the plane: the ego vehicle's pose in the world (odometry) frame, and the rigid
//! transforms between the vehicle frame and the world frame that the tracker applies to
//! measurements and track states.
//!
//! Frames: the **vehicle frame** has its origin at the vehicle's reference point (the centre of
//! the rear axle, as in RadarScenes), x forward and y to the left; the **world frame** is a
//! fixed (odometry) frame in which the ego pose is given, yaw counter-clockwise from its x axis.

use crate::math::sin_cos;
use glam::{DMat2, DVec2};

/// Largest ego position magnitude accepted in a frame, m (10 000 km): far beyond any odometry
/// frame, small enough that positions keep their metre-level precision in `f64`.
pub const MAX_EGO_POSITION_M: f64 = 1.0e7;

/// Pose of the ego vehicle's reference point in the world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EgoPose {
    /// World x of the reference point, m.
    pub x_m: f64,
    /// World y of the reference point, m.
    pub y_m: f64,
    /// Heading of the vehicle's x axis, rad, counter-clockwise from the world x axis.
    pub yaw_rad: f64,
}

impl EgoPose {
    /// The reference point in the world frame, m.
    pub fn position(&self) -> DVec2 {
        DVec2::new(self.x_m, self.y_m)
    }

    /// Whether every field is finite and the position within [`MAX_EGO_POSITION_M`].
    pub fn is_valid(&self) -> bool {
        self.yaw_rad.is_finite()
            && self.x_m.abs() <= MAX_EGO_POSITION_M
            && self.y_m.abs() <= MAX_EGO_POSITION_M
    }

    /// The transform from the vehicle frame into the world frame.
    pub fn vehicle_to_world(&self) -> RigidTransform {
        RigidTransform::new(self.yaw_rad, self.position())
    }

    /// The transform from the world frame into the vehicle frame.
    pub fn world_to_vehicle(&self) -> RigidTransform {
        self.vehicle_to_world().inverse()
    }

    /// Maps a point from the vehicle frame into the world frame, m.
    pub fn point_to_world(&self, point_vehicle_m: DVec2) -> DVec2 {
        self.position() + rotate(self.yaw_rad, point_vehicle_m)
    }

    /// Maps a point from the world frame into the vehicle frame, m.
    pub fn world_to_car(&self, point_world_m: DVec2) -> DVec2 {
        rotate(-self.yaw_rad, point_world_m - self.position())
    }

    /// Rotates a world-frame direction or velocity into the vehicle's axes (no translation).
    pub fn rotate_to_car(&self, vector_world: DVec2) -> DVec2 {
        rotate(-self.yaw_rad, vector_world)
    }
}

/// `vector` rotated counter-clockwise by `angle_rad`, with the operations in the order of
/// `glam::DVec2::from_angle(angle).rotate(vector)`, so that both give the same bits.
fn rotate(angle_rad: f64, vector: DVec2) -> DVec2 {
    let (sin, cos) = sin_cos(angle_rad);
    DVec2::new(cos * vector.x - sin * vector.y, sin * vector.x + cos * vector.y)
}

/// A rotation followed by a translation in the plane: `p ↦ R p + t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTransform {
    /// The rotation `R`.
    pub rotation: DMat2,
    /// The translation `t`, m.
    pub translation_m: DVec2,
}

impl RigidTransform {
    /// The identity.
    pub const IDENTITY: RigidTransform =
        RigidTransform { rotation: DMat2::IDENTITY, translation_m: DVec2::ZERO };

    /// A rotation by `angle_rad` (counter-clockwise) followed by a translation.
    pub fn new(angle_rad: f64, translation_m: DVec2) -> Self {
        let (sin, cos) = sin_cos(angle_rad);
        RigidTransform {
            rotation: DMat2::from_cols(DVec2::new(cos, sin), DVec2::new(-sin, cos)),
            translation_m,
        }
    }

    /// The inverse transform `p ↦ Rᵀ (p − t)`.
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.transpose();
        RigidTransform { rotation, translation_m: -(rotation * self.translation_m) }
    }

    /// This transform after `first`: `p ↦ self(first(p))`.
    pub fn after(&self, first: &RigidTransform) -> Self {
        RigidTransform {
            rotation: self.rotation * first.rotation,
            translation_m: self.rotation * first.translation_m + self.translation_m,
        }
    }

    /// Maps a point, m.
    pub fn apply_point(&self, point_m: DVec2) -> DVec2 {
        self.rotation * point_m + self.translation_m
    }

    /// Rotates a direction, velocity or acceleration (no translation).
    pub fn apply_vector(&self, vector: DVec2) -> DVec2 {
        self.rotation * vector
    }

    /// Rotates a 2×2 covariance: `R P Rᵀ`.
    pub fn apply_covariance(&self, covariance: DMat2) -> DMat2 {
        self.rotation * covariance * self.rotation.transpose()
    }

    /// Maps the covariance of a position and velocity `[x, y, vx, vy]`: both halves rotate
    /// with `R` (the translation leaves a covariance alone).
    pub fn apply_state_covariance(&self, covariance: glam::DMat4) -> glam::DMat4 {
        let r = self.rotation;
        let rotation = glam::DMat4::from_cols(
            glam::DVec4::new(r.x_axis.x, r.x_axis.y, 0.0, 0.0),
            glam::DVec4::new(r.y_axis.x, r.y_axis.y, 0.0, 0.0),
            glam::DVec4::new(0.0, 0.0, r.x_axis.x, r.x_axis.y),
            glam::DVec4::new(0.0, 0.0, r.y_axis.x, r.y_axis.y),
        );
        rotation * covariance * rotation.transpose()
    }
}

/// Where a radar is mounted on the vehicle, in the vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SensorMount {
    /// The sensor id frames and measurements carry.
    pub id: u16,
    /// Longitudinal position, m.
    pub x_m: f64,
    /// Lateral position (left positive), m.
    pub y_m: f64,
    /// Boresight heading, rad, counter-clockwise from the vehicle's x axis.
    pub yaw_rad: f64,
    /// Half opening angle of the field of view, rad, in (0, π] (absent: π, the sensor sees
    /// all around, so every miss counts against a track's existence).
    #[cfg_attr(feature = "serde", serde(default = "default_half_fov_rad"))]
    pub half_fov_rad: f64,
    /// Largest detection range, m (absent: 1000 m).
    #[cfg_attr(feature = "serde", serde(default = "default_max_range_m"))]
    pub max_range_m: f64,
    /// Factor on every class's `existence.detection_probability` for this sensor,
    /// dimensionless (absent: 1); the product must stay below 1.
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub detection_probability_factor: f64,
    /// Factor on every class's `existence.clutter_density_per_m2` for this sensor,
    /// dimensionless (absent: 1).
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub clutter_density_factor: f64,
    /// Standard deviation of the measured range, m (absent: 0, no noise of the sensor's own;
    /// `crate::sensor_noise`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub range_std_m: f64,
    /// Standard deviation of the measured azimuth at boresight, rad (absent: 0).
    #[cfg_attr(feature = "serde", serde(default))]
    pub azimuth_std_rad: f64,
    /// Largest growth of the azimuth's standard deviation off boresight, dimensionless, ≥ 1: it
    /// grows as 1 / cos of the angle from the boresight up to this factor (absent: 1, constant).
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub azimuth_std_max_factor: f64,
    /// Where the sensor's detections of an extended object lie: `"outline"`, `"centre"` or
    /// `"auto"` (absent: outline, the class's `extent.offset_scale`; `crate::sensor`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub reflection: crate::sensor::ReflectionModel,
    /// What one of the sensor's detections is: `"points"` (a point cloud, grouped into objects
    /// before association), `"objects"` or `"auto"` (absent: auto, decided from the data;
    /// `crate::grouping`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub detections: crate::grouping::DetectionModel,
}

/// The default of [`SensorMount::half_fov_rad`]: all around.
pub const DEFAULT_HALF_FOV_RAD: f64 = core::f64::consts::PI;
/// The default of [`SensorMount::max_range_m`], m.
pub const DEFAULT_MAX_RANGE_M: f64 = 1000.0;

#[cfg(feature = "serde")]
fn default_half_fov_rad() -> f64 {
    DEFAULT_HALF_FOV_RAD
}

#[cfg(feature = "serde")]
fn default_max_range_m() -> f64 {
    DEFAULT_MAX_RANGE_M
}

#[cfg(feature = "serde")]
fn one() -> f64 {
    1.0
}

impl SensorMount {
    /// The mounting position in the vehicle frame, m.
    pub fn position(&self) -> DVec2 {
        DVec2::new(self.x_m, self.y_m)
    }
}

/// The ego's motion as consecutive poses tell it: when the latest pose was taken and the ego's
/// motion over ground between the two latest poses (world frame, about the latest pose's
/// position). The tracker uses it where its tracks change frame: a velocity estimated in the
/// vehicle frame without poses is the object's velocity relative to the ego, and a velocity
/// over ground is not.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EgoMotion {
    /// Time of the latest pose, s.
    pub pose_time_s: Option<f64>,
    /// The ego's velocity and yaw rate from the two latest poses.
    pub latest: Option<RigidVelocity>,
}

/// The velocity field of a rigid motion in the plane: at a point `p`, `v + ω × (p − c)` with
/// `v` the velocity of the point `c` and `ω` the yaw rate (`ω × r = ω·(−r_y, r_x)`). The
/// apparent velocity of a point at rest, seen from a vehicle moving so, is minus this.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidVelocity {
    /// Velocity of the reference point, m/s.
    pub velocity_mps: DVec2,
    /// Yaw rate, rad/s.
    pub yaw_rate_radps: f64,
    /// The reference point, m.
    pub centre_m: DVec2,
}

impl RigidVelocity {
    /// The velocity of the field at `point_m`, m/s.
    pub fn at(&self, point_m: DVec2) -> DVec2 {
        self.velocity_mps + self.yaw_rate_radps * (point_m - self.centre_m).perp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const POSE: EgoPose = EgoPose { x_m: 12.0, y_m: -7.5, yaw_rad: 0.7 };

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-12 * (1.0 + a.length().max(b.length()))
    }

    #[test]
    fn a_point_goes_to_the_world_and_back() {
        let point = DVec2::new(30.0, -4.0);
        let world = POSE.point_to_world(point);
        assert!(close(POSE.world_to_car(world), point));
        // The reference point is the pose's position; the x axis points along the yaw.
        assert!(close(POSE.point_to_world(DVec2::ZERO), POSE.position()));
        let ahead = POSE.point_to_world(DVec2::X) - POSE.position();
        assert!(close(ahead, DVec2::new(0.7f64.cos(), 0.7f64.sin())));
    }

    #[test]
    fn vectors_rotate_without_translation() {
        let velocity = DVec2::new(3.0, 1.0);
        let world = POSE.vehicle_to_world().apply_vector(velocity);
        assert!((world.length() - velocity.length()).abs() < 1e-12);
        assert!(close(POSE.rotate_to_car(world), velocity));
    }

    #[test]
    fn composition_and_inverse_agree_with_applying_one_after_the_other() {
        let first = RigidTransform::new(-1.2, DVec2::new(3.0, 4.0));
        let second = RigidTransform::new(2.5, DVec2::new(-8.0, 0.5));
        let point = DVec2::new(-2.0, 9.0);
        assert!(close(second.after(&first).apply_point(point), second.apply_point(first.apply_point(point))));
        assert!(close(first.inverse().apply_point(first.apply_point(point)), point));
        assert!(close(first.after(&first.inverse()).apply_point(point), point));
    }

    #[test]
    fn a_rotated_covariance_keeps_its_eigenvalues() {
        let covariance = DMat2::from_cols(DVec2::new(4.0, 1.0), DVec2::new(1.0, 2.0));
        let rotated = RigidTransform::new(0.9, DVec2::ZERO).apply_covariance(covariance);
        assert!((rotated.determinant() - covariance.determinant()).abs() < 1e-12);
        let trace = |m: DMat2| m.x_axis.x + m.y_axis.y;
        assert!((trace(rotated) - trace(covariance)).abs() < 1e-12);
        assert!((rotated.x_axis.y - rotated.y_axis.x).abs() < 1e-12);
    }

    #[test]
    fn poses_beyond_the_limits_are_not_valid() {
        assert!(POSE.is_valid());
        assert!(!EgoPose { x_m: f64::NAN, ..POSE }.is_valid());
        assert!(!EgoPose { yaw_rad: f64::INFINITY, ..POSE }.is_valid());
        assert!(!EgoPose { y_m: 2.0 * MAX_EGO_POSITION_M, ..POSE }.is_valid());
    }
}
