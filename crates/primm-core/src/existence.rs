//! A track's probability of existence: the Bayesian recursion of integrated probabilistic data
//! association (IPDA, Mušicki, Evans and Stanković, 1994), for one assigned measurement per
//! track as the tracker's optimal assignment gives it.
//!
//! Between frames an object that exists goes on existing with probability
//! `p_s = exp(−Δt / T)` (`tracker.existence_persistence_time_s` = T), so
//! `r⁻ = p_s · r`. Then, in a frame:
//!
//! * **Detected**: the track took measurement `z` with Gaussian likelihood `g(z) = N(z; p⁻, S)`
//!   (fused prior position `p⁻`, innovation covariance `S = P⁻ + R`, 1/m²). A real object's
//!   detection has density `P_D · g(z)`, a false one `λ` (the class's clutter density per scan,
//!   1/m²), so `r = r⁻ (1 − P_D + P_D g/λ) / (1 − r⁻ P_D + r⁻ P_D g/λ)`.
//! * **Missed in view**: a sensor of the frame had the track's prior position in its field of
//!   view and no measurement went to the track: `r = r⁻ (1 − P_D) / (1 − r⁻ P_D)`.
//! * **Out of view**: no sensor of the frame could see the track: `r = r⁻`. A miss there says
//!   nothing about the object.
//!
//! `P_D` is the class's detection probability times the scanning sensor's factor, `λ` the
//! class's clutter density times the sensor's factor (`frame.sensors[].detection_probability_factor`,
//! `clutter_density_factor`). Which sensors scanned in a frame is read from its measurements'
//! sensor ids; a frame whose measurements carry none, or a sensor without a configured mount,
//! is taken to see every track (the conservative reading: misses count, as with hit/miss
//! counting). A frame without any measurement names no sensor, so it counts as out of view for
//! every track.
//!
//! Everything here is a pure function of its arguments; the tracker keeps `r` in each track.

use crate::config::TrackerConfig;
use crate::math;
use crate::pose::{EgoPose, SensorMount};
use glam::{DMat2, DVec2};

/// Existence probabilities are kept inside `[MIN_EXISTENCE, MAX_EXISTENCE]`, so that a long run
/// of hits or misses can always be undone by the evidence of later frames.
pub const MIN_EXISTENCE: f64 = 1e-9;
/// See [`MIN_EXISTENCE`].
pub const MAX_EXISTENCE: f64 = 1.0 - 1e-9;

/// How confirmation and deletion are decided (`tracker.lifecycle`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Lifecycle {
    /// By the existence probability: a tentative track is confirmed once it reaches
    /// `tracker.confirmation_existence_probability`; any track is deleted once it falls below
    /// `tracker.deletion_existence_probability` (the coast-time limits still apply).
    #[default]
    Existence,
    /// By counting: `tracker.confirmation_hits` hits confirm, `*_max_misses` consecutive misses
    /// or the coast-time limits delete. The existence probability is still computed and
    /// reported.
    Counts,
}

/// Detection and clutter of one class (`classes.<class>.existence`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ExistenceConfig {
    /// Probability that a sensor whose field of view holds an object of this class reports it
    /// in a scan, dimensionless in (0, 1).
    pub detection_probability: f64,
    /// Mean number of false detections of this class per scan and square metre of a sensor's
    /// field of view, 1/m².
    pub clutter_density_per_m2: f64,
}

impl Default for ExistenceConfig {
    /// 0.9 and 1e-4 /m² (about one false detection per scan over a 120°, 100 m field of view).
    fn default() -> Self {
        ExistenceConfig { detection_probability: 0.9, clutter_density_per_m2: 1e-4 }
    }
}

/// What one frame said about one track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Evidence {
    /// The track took a measurement whose position likelihood under the track's prior is
    /// `likelihood_per_m2` (1/m²).
    Detected {
        /// `N(z; p⁻, S)`, 1/m².
        likelihood_per_m2: f64,
    },
    /// A sensor of the frame had the track in view and did not detect it.
    MissedInView,
    /// No sensor of the frame had the track in view.
    OutOfView,
}

/// The probability that an object survives `dt_s` seconds, `exp(−Δt/T)`.
pub fn survival_probability(dt_s: f64, tracker: &TrackerConfig) -> f64 {
    math::exp(-dt_s.max(0.0) / tracker.existence_persistence_time_s)
}

/// The existence probability after a frame: `prior` is `r⁻` (after survival), `detection`
/// the detection probability and `clutter_density_per_m2` the clutter density of the track's
/// class and the frame's sensor.
pub fn updated_existence(
    prior: f64,
    evidence: Evidence,
    detection_probability: f64,
    clutter_density_per_m2: f64,
) -> f64 {
    let r = if prior.is_nan() { MIN_EXISTENCE } else { prior.clamp(MIN_EXISTENCE, MAX_EXISTENCE) };
    let p_d = detection_probability;
    let posterior = match evidence {
        Evidence::OutOfView => r,
        Evidence::MissedInView => r * (1.0 - p_d) / (1.0 - r * p_d),
        Evidence::Detected { likelihood_per_m2 } => {
            // The likelihood ratio of "this track's object" over "clutter"; a zero clutter density
            // makes every detection conclusive.
            let ratio = if clutter_density_per_m2 > 0.0 {
                likelihood_per_m2 / clutter_density_per_m2
            } else {
                f64::INFINITY
            };
            let evidence = 1.0 - p_d + p_d * ratio;
            if evidence.is_finite() {
                r * evidence / (1.0 - r + r * evidence)
            } else {
                MAX_EXISTENCE
            }
        }
    };
    if posterior.is_nan() {
        r
    } else {
        posterior.clamp(MIN_EXISTENCE, MAX_EXISTENCE)
    }
}

/// `N(ν; 0, S)` for a 2-D innovation `ν` and innovation covariance `S`, 1/m²; 0 for a
/// covariance that is not positive definite.
pub fn gaussian_density_per_m2(innovation_m: DVec2, innovation_covariance_m2: DMat2) -> f64 {
    let determinant = innovation_covariance_m2.determinant();
    if !(determinant > 0.0 && determinant.is_finite()) {
        return 0.0;
    }
    let squared_distance = innovation_m.dot(innovation_covariance_m2.inverse() * innovation_m);
    math::exp(-0.5 * squared_distance) / (2.0 * core::f64::consts::PI * math::sqrt(determinant))
}

/// One sensor's field of view, ready to test positions of the tracking frame against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldOfView {
    /// The sensor's position in the tracking frame, m.
    origin_m: DVec2,
    /// Unit boresight direction in the tracking frame.
    boresight: DVec2,
    /// `cos` of the half opening angle.
    cos_half_angle: f64,
    /// Largest range, m.
    max_range_m: f64,
}

impl FieldOfView {
    /// The area of the field of view, m²: the sector of its opening angle out to its range.
    pub fn area_m2(&self) -> f64 {
        crate::sensor::estimates::sector_area_m2(
            math::acos(self.cos_half_angle.clamp(-1.0, 1.0)),
            self.max_range_m,
        )
    }

    /// The field of view of `mount` in the tracking frame: the world frame when `pose` is the
    /// step's ego pose, else the vehicle frame.
    pub fn of(mount: &SensorMount, pose: Option<EgoPose>) -> Self {
        let (sin, cos) = math::sin_cos(mount.yaw_rad + pose.map_or(0.0, |pose| pose.yaw_rad));
        let origin_m = match pose {
            Some(pose) => pose.point_to_world(mount.position()),
            None => mount.position(),
        };
        let half_angle = mount.half_fov_rad.clamp(0.0, core::f64::consts::PI);
        FieldOfView {
            origin_m,
            boresight: DVec2::new(cos, sin),
            cos_half_angle: math::sin_cos(half_angle).1,
            max_range_m: mount.max_range_m,
        }
    }

    /// The field of view of a radar without a configured mount, as far as its detections of
    /// one frame show it: seen from `origin_m` (the vehicle's reference point, tracking frame),
    /// the smallest sector around the detections' mean direction that holds them all, widened
    /// by `margin_rad` on each side, out to the farthest detection plus `margin_m`. `None`
    /// without detections.
    pub fn spanning(
        origin_m: DVec2,
        detections_m: impl Iterator<Item = DVec2> + Clone,
        margin_rad: f64,
        margin_m: f64,
    ) -> Option<Self> {
        let directions = detections_m.clone().filter_map(|p| (p - origin_m).try_normalize());
        let sum: DVec2 = directions.clone().sum();
        let max_range_m = detections_m
            .map(|p| p.distance(origin_m))
            .fold(None, |far: Option<f64>, r| Some(far.map_or(r, |far| far.max(r))))?;
        // Detections all around (or one on the origin): every direction.
        let (boresight, cos_half_angle) = match sum.try_normalize() {
            Some(mean) => {
                let cos_widest = directions.map(|d| d.dot(mean)).fold(1.0, f64::min);
                let half_angle =
                    (math::acos(cos_widest.clamp(-1.0, 1.0)) + margin_rad).min(core::f64::consts::PI);
                (mean, math::sin_cos(half_angle).1)
            }
            None => (DVec2::X, -1.0),
        };
        Some(FieldOfView { origin_m, boresight, cos_half_angle, max_range_m: max_range_m + margin_m })
    }

    /// The sensor's position in the tracking frame, m.
    pub fn origin_m(&self) -> DVec2 {
        self.origin_m
    }

    /// Whether `position_m` (tracking frame) lies within range and opening angle.
    pub fn contains(&self, position_m: DVec2) -> bool {
        let relative = position_m - self.origin_m;
        let range = relative.length();
        if !(range <= self.max_range_m) {
            return false;
        }
        // The angle to the boresight is within the half opening angle.
        relative.dot(self.boresight) >= range * self.cos_half_angle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mount(yaw_rad: f64) -> SensorMount {
        SensorMount {
            id: 1,
            x_m: 3.0,
            y_m: 0.5,
            yaw_rad,
            half_fov_rad: 60f64.to_radians(),
            max_range_m: 100.0,
            detection_probability_factor: 1.0,
            clutter_density_factor: 1.0,
            range_std_m: 0.0,
            azimuth_std_rad: 0.0,
            azimuth_std_max_factor: 1.0,
            reflection: crate::sensor::ReflectionModel::Outline,
            detections: Default::default(),
        }
    }

    #[test]
    fn a_miss_in_view_lowers_existence_and_one_out_of_view_keeps_it() {
        let missed = updated_existence(0.8, Evidence::MissedInView, 0.9, 1e-4);
        assert!((missed - 0.8 * 0.1 / (1.0 - 0.8 * 0.9)).abs() < 1e-12);
        assert_eq!(updated_existence(0.8, Evidence::OutOfView, 0.9, 1e-4), 0.8);
    }

    #[test]
    fn a_detection_near_the_prior_raises_existence_and_one_like_clutter_lowers_it() {
        let likely = updated_existence(0.5, Evidence::Detected { likelihood_per_m2: 0.1 }, 0.9, 1e-4);
        assert!(likely > 0.99, "{likely}");
        // A likelihood no better than the clutter density is evidence of a miss (1 − P_D + P_D).
        let doubtful = updated_existence(0.5, Evidence::Detected { likelihood_per_m2: 1e-5 }, 0.9, 1e-4);
        assert!(doubtful < 0.5, "{doubtful}");
        // Without clutter, any detection is conclusive.
        let certain = updated_existence(0.5, Evidence::Detected { likelihood_per_m2: 1e-30 }, 0.9, 0.0);
        assert_eq!(certain, MAX_EXISTENCE);
    }

    #[test]
    fn existence_stays_within_its_bounds_and_never_becomes_nan() {
        let mut r = 0.5;
        for _ in 0..10_000 {
            r = updated_existence(r, Evidence::MissedInView, 0.999_999, 1e-4);
        }
        assert_eq!(r, MIN_EXISTENCE);
        let recovered = updated_existence(r, Evidence::Detected { likelihood_per_m2: 1e3 }, 0.9, 1e-6);
        assert!(recovered > r);
        assert_eq!(updated_existence(f64::NAN, Evidence::OutOfView, 0.9, 1e-4), MIN_EXISTENCE);
        let inf = updated_existence(0.5, Evidence::Detected { likelihood_per_m2: f64::INFINITY }, 0.9, 1e-4);
        assert_eq!(inf, MAX_EXISTENCE);
    }

    #[test]
    fn the_density_is_the_bivariate_normal_density() {
        let covariance = DMat2::from_cols(DVec2::new(2.0, 0.5), DVec2::new(0.5, 1.0));
        let innovation = DVec2::new(0.7, -0.3);
        let determinant: f64 = 2.0 * 1.0 - 0.25;
        let inverse = DMat2::from_cols(DVec2::new(1.0, -0.5), DVec2::new(-0.5, 2.0)) / determinant;
        let expected = (-0.5 * innovation.dot(inverse * innovation)).exp()
            / (2.0 * core::f64::consts::PI * determinant.sqrt());
        assert!((gaussian_density_per_m2(innovation, covariance) - expected).abs() < 1e-15);
        assert_eq!(gaussian_density_per_m2(innovation, DMat2::ZERO), 0.0);
    }

    #[test]
    fn a_field_of_view_holds_what_lies_within_its_angle_and_range() {
        let front = FieldOfView::of(&mount(0.0), None);
        assert!(front.contains(DVec2::new(50.0, 0.5)));
        assert!(front.contains(DVec2::new(3.0 + 10.0, 0.5 + 17.0))); // 59.5° off boresight
        assert!(!front.contains(DVec2::new(3.0 + 10.0, 0.5 + 17.5))); // 60.3°
        assert!(!front.contains(DVec2::new(104.0, 0.5)));
        assert!(!front.contains(DVec2::new(-10.0, 0.0)));
        // A turned ego turns the field of view with it.
        let pose = EgoPose { x_m: 100.0, y_m: -20.0, yaw_rad: core::f64::consts::FRAC_PI_2 };
        let turned = FieldOfView::of(&mount(0.0), Some(pose));
        assert!(turned.contains(pose.point_to_world(DVec2::new(40.0, 0.0))));
        assert!(!turned.contains(DVec2::new(140.0, -20.0)));
    }

    #[test]
    fn an_unknown_radars_view_is_the_sector_its_detections_span_widened_by_the_margins() {
        let origin = DVec2::new(10.0, -5.0);
        // Detections 20° either side of +x, out to 50 m.
        let detections = [20f64, -20.0, 5.0].map(|deg| {
            let (sin, cos) = deg.to_radians().sin_cos();
            origin + DVec2::new(cos, sin) * if deg == 5.0 { 50.0 } else { 30.0 }
        });
        let view = FieldOfView::spanning(origin, detections.iter().copied(), 0.1, 5.0).unwrap();
        let at = |deg: f64, range: f64| {
            let (sin, cos) = deg.to_radians().sin_cos();
            view.contains(origin + DVec2::new(cos, sin) * range)
        };
        for detection in detections {
            assert!(view.contains(detection));
        }
        // The mean direction is 1.74° (the third detection pulls it); the widest detection lies
        // 21.74° from it, so with the margin of 5.73° the sector runs from −25.7° to 29.2°.
        assert!(at(29.0, 20.0) && at(-25.5, 20.0));
        assert!(!at(29.5, 20.0) && !at(-26.0, 20.0) && !at(180.0, 20.0));
        assert!(at(0.0, 54.9) && !at(0.0, 55.1));
        // Detections all around: every direction, out to the farthest.
        let around = [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y].map(|d| origin + d * 10.0);
        let view = FieldOfView::spanning(origin, around.iter().copied(), 0.0, 0.0).unwrap();
        assert!(view.contains(origin + DVec2::new(-7.0, 7.0)) && !view.contains(origin + DVec2::X * 10.5));
        assert!(FieldOfView::spanning(origin, core::iter::empty(), 0.1, 5.0).is_none());
    }

    #[test]
    fn survival_decays_with_the_interval() {
        let tracker =
            TrackerConfig { existence_persistence_time_s: 2.0, ..crate::config::Config::default().tracker };
        assert!((survival_probability(0.1, &tracker) - (-0.05f64).exp()).abs() < 1e-15);
        assert_eq!(survival_probability(-1.0, &tracker), 1.0);
    }
}
