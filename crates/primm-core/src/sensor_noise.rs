//! A radar's own measurement noise, in its polar coordinates.
//!
//! A radar measures a detection's range and azimuth from its own mount. Its range error is
//! about constant (the range resolution), while its azimuth error is an angle: the position
//! error across the line of sight grows with the range, and for an antenna array it also grows
//! off boresight, as the array's effective aperture shrinks with the cosine of the angle (the
//! "secant law" of phased arrays). A fixed Cartesian covariance, as a class's
//! `measurement_noise_covariance_m2` is, fits one range only: it trusts a far detection too much
//! (the track's velocity chases detections metres apart across the line of sight) and a near one
//! too little.
//!
//! Each configured sensor may therefore give `range_std_m`, `azimuth_std_rad` (at boresight) and
//! `azimuth_std_max_factor` ([`SensorMount`]). The covariance of a detection at range `r` and
//! off-boresight angle `α` is
//!
//! ```text
//! N = σ_r² û ûᵀ + (r σ_θ(α))² ŵ ŵᵀ,   σ_θ(α) = azimuth_std_rad · min(1 / cos α, azimuth_std_max_factor)
//! ```
//!
//! with `û` the unit line of sight from the sensor to the detection and `ŵ ⟂ û`
//! (`1 / cos α` taken as the factor's bound beyond 90°). It is added to the class's covariance,
//! which then stands for what the sensor does not explain: where on the object the reflection
//! lies. Every consumer of a detection's covariance uses the sum: the likelihood association
//! cost, the Kalman update of every mode, the existence update, a new track's initial spread and
//! the noise of the radial-velocity row's measured direction. A sensor without these keys (or a
//! detection of a sensor that is not configured) adds nothing, as before.

use crate::math;
use crate::pose::{EgoPose, SensorMount};
use glam::{DMat2, DVec2};

/// A sensor's polar noise, placed in the tracking frame: what the covariance of one of its
/// detections needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// Range standard deviation, m.
    range_std_m: f64,
    /// Azimuth standard deviation at boresight, rad.
    azimuth_std_rad: f64,
    /// Bound on the off-boresight growth of the azimuth standard deviation, dimensionless, ≥ 1.
    azimuth_std_max_factor: f64,
    /// Unit boresight in the tracking frame.
    boresight: DVec2,
}

impl SensorNoise {
    /// No noise of the sensor's own (a sensor without noise keys, or an unknown sensor).
    pub const NONE: SensorNoise = SensorNoise {
        range_std_m: 0.0,
        azimuth_std_rad: 0.0,
        azimuth_std_max_factor: 1.0,
        boresight: DVec2::X,
    };

    /// The noise of `mount` with its boresight in the tracking frame: the world frame when
    /// `pose` is the step's ego pose, else the vehicle frame.
    pub fn of(mount: &SensorMount, pose: Option<EgoPose>) -> Self {
        let (sin, cos) = math::sin_cos(mount.yaw_rad + pose.map_or(0.0, |pose| pose.yaw_rad));
        SensorNoise {
            range_std_m: mount.range_std_m,
            azimuth_std_rad: mount.azimuth_std_rad,
            azimuth_std_max_factor: mount.azimuth_std_max_factor,
            boresight: DVec2::new(cos, sin),
        }
    }

    /// Whether the sensor adds nothing.
    pub fn is_none(&self) -> bool {
        self.range_std_m == 0.0 && self.azimuth_std_rad == 0.0
    }

    /// The covariance of a detection at `offset_m` from the sensor (tracking frame), m². At the
    /// sensor itself (no direction) the range variance in every direction.
    pub fn covariance_m2(&self, offset_m: DVec2) -> DMat2 {
        if self.is_none() {
            return DMat2::ZERO;
        }
        let range_variance = math::square(self.range_std_m);
        let range = offset_m.length();
        if !(range > 1e-6) {
            return DMat2::from_diagonal(DVec2::splat(range_variance));
        }
        let along = offset_m / range;
        let cos_off_boresight = along.dot(self.boresight);
        let factor = if cos_off_boresight * self.azimuth_std_max_factor > 1.0 {
            1.0 / cos_off_boresight
        } else {
            self.azimuth_std_max_factor
        };
        let across_variance = math::square(range * self.azimuth_std_rad * factor);
        let across = along.perp();
        outer(along) * range_variance + outer(across) * across_variance
    }
}

fn outer(v: DVec2) -> DMat2 {
    DMat2::from_cols(v * v.x, v * v.y)
}

/// Where the radar of one measurement is and how noisy the detection is, in the tracking frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementSensor {
    /// The radar's position, m: its mount, or the vehicle's reference point for a sensor that
    /// is not configured.
    pub position_m: DVec2,
    /// Whether the sensor is configured (else `position_m` is the reference point).
    pub mounted: bool,
    /// The detection's covariance from the sensor's own noise ([`SensorNoise`]), m²; zero for a
    /// sensor without noise keys.
    pub noise_m2: DMat2,
    /// The sensor's slot in the tracker's [`SensorSet`](crate::sensor::SensorSet).
    pub slot: u8,
    /// The scale of the expected outline offset for this measurement's class under the
    /// sensor's measurement model, dimensionless in [0, 1] (`crate::sensor`).
    pub reflection_scale: f64,
}

impl MeasurementSensor {
    /// A measurement of a sensor that is not configured, seen from the reference point
    /// `position_m`, its detections on the outline scaled by `reflection_scale`.
    pub const fn unknown(position_m: DVec2, reflection_scale: f64) -> Self {
        MeasurementSensor {
            position_m,
            mounted: false,
            noise_m2: DMat2::ZERO,
            slot: crate::sensor::UNMOUNTED as u8,
            reflection_scale,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coordinates::CoordinatesConfig;

    fn mount(range_std_m: f64, azimuth_std_rad: f64, max_factor: f64) -> SensorMount {
        SensorMount {
            range_std_m,
            azimuth_std_rad,
            azimuth_std_max_factor: max_factor,
            yaw_rad: 0.0,
            ..CoordinatesConfig::default().sensors[0]
        }
    }

    #[test]
    fn the_noise_across_the_line_of_sight_grows_with_the_range() {
        let noise = SensorNoise::of(&mount(0.1, 0.01, 1.0), None);
        let near = noise.covariance_m2(DVec2::new(10.0, 0.0));
        let far = noise.covariance_m2(DVec2::new(50.0, 0.0));
        assert!((near.x_axis.x - 0.01).abs() < 1e-15 && (far.x_axis.x - 0.01).abs() < 1e-15);
        assert!((near.y_axis.y - 0.01).abs() < 1e-12, "{near:?}");
        assert!((far.y_axis.y - 0.25).abs() < 1e-12, "{far:?}");
        assert!(near.x_axis.y.abs() < 1e-15);
    }

    #[test]
    fn the_covariance_is_polar_along_any_line_of_sight() {
        let noise = SensorNoise::of(&mount(0.2, 0.02, 1.0), None);
        let offset = DVec2::new(30.0, 40.0);
        let covariance = noise.covariance_m2(offset);
        let along = offset.normalize();
        let across = along.perp();
        assert!((along.dot(covariance * along) - 0.04).abs() < 1e-12);
        assert!((across.dot(covariance * across) - 1.0).abs() < 1e-12);
        assert!(along.dot(covariance * across).abs() < 1e-12);
    }

    #[test]
    fn the_azimuth_noise_grows_off_boresight_up_to_its_bound() {
        let noise = SensorNoise::of(&mount(0.0, 0.01, 2.0), None);
        let across_std = |angle: f64| {
            let offset = DVec2::new(angle.cos(), angle.sin()) * 20.0;
            let across = offset.normalize().perp();
            across.dot(noise.covariance_m2(offset) * across).sqrt() / 20.0
        };
        assert!((across_std(0.0) - 0.01).abs() < 1e-12);
        assert!((across_std(45f64.to_radians()) - 0.01 * 2f64.sqrt()).abs() < 1e-12);
        assert!((across_std(75f64.to_radians()) - 0.02).abs() < 1e-12);
        assert!((across_std(170f64.to_radians()) - 0.02).abs() < 1e-12);
    }

    #[test]
    fn the_boresight_turns_with_the_ego_pose() {
        let noise =
            SensorNoise::of(&mount(0.0, 0.01, 2.0), Some(EgoPose { x_m: 5.0, y_m: 1.0, yaw_rad: 1.0 }));
        // Along the turned boresight the factor is one.
        let offset = DVec2::new(1f64.cos(), 1f64.sin()) * 10.0;
        let across = offset.normalize().perp();
        assert!((across.dot(noise.covariance_m2(offset) * across) - 0.01).abs() < 1e-12);
    }

    proptest::proptest! {
        #[test]
        fn the_covariance_is_finite_symmetric_and_positive_semidefinite(
            range_std in 0.0f64..2.0,
            azimuth_std in 0.0f64..0.5,
            factor in 1.0f64..10.0,
            yaw in -7.0f64..7.0,
            x in -1000.0f64..1000.0,
            y in -1000.0f64..1000.0,
        ) {
            let noise = SensorNoise::of(
                &SensorMount { yaw_rad: yaw, ..mount(range_std, azimuth_std, factor) },
                None,
            );
            let c = noise.covariance_m2(DVec2::new(x, y));
            proptest::prop_assert!(c.to_cols_array().iter().all(|v| v.is_finite()));
            proptest::prop_assert!((c.x_axis.y - c.y_axis.x).abs() <= 1e-12 * (1.0 + c.x_axis.y.abs()));
            proptest::prop_assert!(c.x_axis.x >= 0.0 && c.y_axis.y >= 0.0);
            proptest::prop_assert!(c.determinant() >= -1e-9 * (1.0 + c.x_axis.x * c.y_axis.y));
            // Never more than the bounded growth allows across the line of sight.
            let range = DVec2::new(x, y).length();
            let bound = range_std * range_std + (range * azimuth_std * factor).powi(2);
            proptest::prop_assert!(c.x_axis.x + c.y_axis.y <= bound * (1.0 + 1e-9) + 1e-12);
        }
    }

    #[test]
    fn a_sensor_without_noise_keys_adds_nothing() {
        let noise = SensorNoise::of(&mount(0.0, 0.0, 1.0), None);
        assert!(noise.is_none());
        assert_eq!(noise.covariance_m2(DVec2::new(10.0, 3.0)), DMat2::ZERO);
        assert_eq!(SensorNoise::NONE.covariance_m2(DVec2::new(10.0, 3.0)), DMat2::ZERO);
    }
}
