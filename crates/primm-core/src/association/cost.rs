//! The association costs: the paper's `eq:association_cost`, and a negative log-likelihood with
//! a χ² gate.

use crate::config::AssociationConfig;
use crate::extent::ExpectedReflection;
use crate::gaussian::PositionEstimate;
use crate::math;
use crate::measurement::Measurement;
use glam::{DMat2, DVec2};

/// `d = ‖z − p⁻‖ + λ_v·min(|v_r − v_r^last|, v_max)`: Euclidean distance from the track's fused
/// prior to the measurement plus the capped, weighted radial-velocity difference, in metres.
pub fn association_cost(
    prior_position_m: DVec2,
    last_radial_velocity_mps: f64,
    measurement: &Measurement,
    config: &AssociationConfig,
) -> f64 {
    let distance = (measurement.position() - prior_position_m).length();
    let velocity_difference = (measurement.radial_velocity_mps - last_radial_velocity_mps).abs();
    distance + config.velocity_weight_s * velocity_difference.min(config.velocity_cap_mps)
}

/// A track's prior prepared for the `likelihood` cost (`association.cost = "likelihood"`):
/// the inverse and log-determinant of the innovation covariance `S = P⁻ + R`, computed once per
/// track and frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LikelihoodPrior {
    mean_m: DVec2,
    innovation_covariance_m2: DMat2,
    inverse_m2: DMat2,
    log_determinant: f64,
    last_radial_velocity_mps: f64,
    inverse_velocity_variance: f64,
    gate_chi2: f64,
    x_half_window_m: f64,
}

/// An expected reflection prepared for one track's likelihood cost
/// ([`LikelihoodPrior::prepare_reflection`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PreparedReflection {
    offset_m: DVec2,
    inverse_m2: DMat2,
    log_determinant: f64,
}

impl LikelihoodPrior {
    /// The prepared prior of a track with fused prior `prior`, the class's measurement noise
    /// `measurement_noise_m2` and radial-velocity residual spread, and the χ² gate. `None` when
    /// `S` is not positive definite (the track takes no measurement this frame).
    pub fn new(
        prior: &PositionEstimate,
        measurement_noise_m2: DMat2,
        last_radial_velocity_mps: f64,
        likelihood_radial_velocity_std_mps: f64,
        gate_chi2: f64,
    ) -> Option<Self> {
        let innovation_covariance = prior.covariance + measurement_noise_m2;
        let determinant = innovation_covariance.determinant();
        let xx = innovation_covariance.x_axis.x;
        if !(determinant > 0.0 && determinant.is_finite() && xx > 0.0) {
            return None;
        }
        Some(LikelihoodPrior {
            mean_m: prior.mean,
            innovation_covariance_m2: innovation_covariance,
            inverse_m2: innovation_covariance.inverse(),
            log_determinant: math::ln(determinant),
            last_radial_velocity_mps,
            inverse_velocity_variance: 1.0 / math::square(likelihood_radial_velocity_std_mps),
            gate_chi2,
            // Within the gate, (Δx)² ≤ χ² · S_xx.
            x_half_window_m: math::sqrt(gate_chi2 * xx),
        })
    }

    /// The prior position, m.
    pub fn mean_m(&self) -> DVec2 {
        self.mean_m
    }

    /// Half width of the x-window holding every measurement the gate can let through, m.
    pub fn x_half_window_m(&self) -> f64 {
        self.x_half_window_m
    }

    /// Half width of the x-window holding every measurement the gate can let through when up
    /// to `spread_m2` is added to `S_xx`, m.
    pub fn x_half_window_with_spread_m(&self, spread_m2: f64) -> f64 {
        math::sqrt(self.gate_chi2 * (self.innovation_covariance_m2.x_axis.x + spread_m2))
    }

    /// `νᵀS⁻¹ν + (Δv_r)²/σ_v² + ln det S` for a measurement inside the gate (the first two
    /// terms at most `likelihood_gate_chi2`), `None` beyond it.
    pub fn cost(&self, measurement: &Measurement) -> Option<f64> {
        let innovation = measurement.position() - self.mean_m;
        self.gated(measurement, innovation.dot(self.inverse_m2 * innovation), self.log_determinant)
    }

    /// [`cost`](Self::cost) of an extended object whose reflection is expected at
    /// `reflection.offset_m` from the prior and spread by `reflection.covariance_m2`: the
    /// innovation `z − (p⁻ + o)` with covariance `S + C`. `None` also when `S + C` is not
    /// positive definite.
    pub fn cost_of_reflection(
        &self,
        measurement: &Measurement,
        reflection: &ExpectedReflection,
    ) -> Option<f64> {
        self.cost_of_prepared_reflection(measurement, &self.prepare_reflection(reflection)?)
    }

    /// What [`cost_of_reflection`](Self::cost_of_reflection) needs of a reflection whatever the
    /// measurement: `S + C` inverted and its log-determinant, once per track and sensor instead
    /// of once per pair. `None` when `S + C` is not positive definite.
    pub fn prepare_reflection(&self, reflection: &ExpectedReflection) -> Option<PreparedReflection> {
        let covariance = self.innovation_covariance_m2 + reflection.covariance_m2;
        let determinant = covariance.determinant();
        if !(determinant > 0.0 && determinant.is_finite()) {
            return None;
        }
        Some(PreparedReflection {
            offset_m: reflection.offset_m,
            inverse_m2: covariance.inverse(),
            log_determinant: math::ln(determinant),
        })
    }

    /// [`cost_of_reflection`](Self::cost_of_reflection) with the reflection prepared: the same
    /// value, bit for bit.
    pub fn cost_of_prepared_reflection(
        &self,
        measurement: &Measurement,
        reflection: &PreparedReflection,
    ) -> Option<f64> {
        let innovation = measurement.position() - self.mean_m - reflection.offset_m;
        self.gated(
            measurement,
            innovation.dot(reflection.inverse_m2 * innovation),
            reflection.log_determinant,
        )
    }

    /// The cost from the squared position distance: the radial-velocity term added, gated.
    fn gated(&self, measurement: &Measurement, position_distance: f64, log_determinant: f64) -> Option<f64> {
        let velocity_difference = measurement.radial_velocity_mps - self.last_radial_velocity_mps;
        let squared_distance =
            position_distance + math::square(velocity_difference) * self.inverse_velocity_variance;
        (squared_distance <= self.gate_chi2).then_some(squared_distance + log_determinant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::measurement::ObjectClass;

    fn measurement(x: f64, y: f64, radial_velocity: f64) -> Measurement {
        Measurement {
            x_m: x,
            y_m: y,
            radial_velocity_mps: radial_velocity,
            rcs_dbsm: 0.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: None,
        }
    }

    #[test]
    fn cost_is_distance_plus_weighted_velocity_difference() {
        let config = AssociationConfig {
            velocity_weight_s: 0.1,
            velocity_cap_mps: 5.0,
            ..Config::default().association
        };
        let cost = association_cost(DVec2::new(0.0, 0.0), 2.0, &measurement(3.0, 4.0, 4.5), &config);
        assert!((cost - (5.0 + 0.1 * 2.5)).abs() < 1e-12);
    }

    #[test]
    fn the_velocity_difference_is_capped() {
        let config = AssociationConfig {
            velocity_weight_s: 0.1,
            velocity_cap_mps: 5.0,
            ..Config::default().association
        };
        let cost = association_cost(DVec2::new(1.0, 1.0), -20.0, &measurement(1.0, 1.0, 20.0), &config);
        assert!((cost - 0.5).abs() < 1e-12);
    }

    fn prior(covariance: DMat2) -> PositionEstimate {
        PositionEstimate { mean: DVec2::new(10.0, -2.0), covariance }
    }

    #[test]
    fn the_likelihood_cost_is_the_mahalanobis_distance_plus_the_log_determinant() {
        let p = DMat2::from_cols(DVec2::new(0.5, 0.1), DVec2::new(0.1, 0.3));
        let r = DMat2::from_diagonal(DVec2::new(0.2, 0.2));
        let prepared = LikelihoodPrior::new(&prior(p), r, 3.0, 0.5, 16.27).unwrap();
        let m = measurement(10.6, -2.4, 3.4);
        let s = p + r;
        let nu = DVec2::new(0.6, -0.4);
        let expected = nu.dot(s.inverse() * nu) + (0.4f64 / 0.5).powi(2) + s.determinant().ln();
        assert!((prepared.cost(&m).unwrap() - expected).abs() < 1e-12);
    }

    #[test]
    fn the_likelihood_gate_refuses_what_lies_beyond_it_and_the_window_covers_the_gate() {
        let p = DMat2::from_diagonal(DVec2::new(1.0, 4.0));
        let prepared = LikelihoodPrior::new(&prior(p), DMat2::ZERO, 0.0, 1.0, 9.0).unwrap();
        assert!((prepared.x_half_window_m() - 3.0).abs() < 1e-12);
        assert!(prepared.cost(&measurement(12.9, -2.0, 0.0)).is_some());
        assert!(prepared.cost(&measurement(13.1, -2.0, 0.0)).is_none());
        // Along y the spread is twice as wide; the radial velocity adds to the distance.
        assert!(prepared.cost(&measurement(10.0, 3.9, 0.0)).is_some());
        assert!(prepared.cost(&measurement(10.0, 3.9, 1.0)).is_none());
    }

    #[test]
    fn an_innovation_covariance_that_is_not_positive_definite_gives_no_prepared_prior() {
        assert!(LikelihoodPrior::new(&prior(DMat2::ZERO), DMat2::ZERO, 0.0, 1.0, 9.0).is_none());
        let nan = DMat2::from_diagonal(DVec2::new(f64::NAN, 1.0));
        assert!(LikelihoodPrior::new(&prior(nan), DMat2::ZERO, 0.0, 1.0, 9.0).is_none());
    }

    #[test]
    fn the_cost_of_a_reflection_scores_the_offset_point_with_the_spread_added() {
        let p = DMat2::from_cols(DVec2::new(0.5, 0.1), DVec2::new(0.1, 0.3));
        let r = DMat2::from_diagonal(DVec2::new(0.2, 0.2));
        let prepared = LikelihoodPrior::new(&prior(p), r, 3.0, 0.5, 16.27).unwrap();
        let reflection = ExpectedReflection {
            offset_m: DVec2::new(-1.5, 0.4),
            covariance_m2: DMat2::from_diagonal(DVec2::new(0.0, 0.25)),
        };
        let m = measurement(9.1, -1.7, 3.4);
        let s = p + r + reflection.covariance_m2;
        let nu = DVec2::new(9.1 - 8.5, -1.7 + 1.6);
        let expected = nu.dot(s.inverse() * nu) + (0.4f64 / 0.5).powi(2) + s.determinant().ln();
        assert!((prepared.cost_of_reflection(&m, &reflection).unwrap() - expected).abs() < 1e-12);
        // A point reflection is the plain cost.
        let point = prepared.cost_of_reflection(&m, &ExpectedReflection::POINT).unwrap();
        assert!((point - prepared.cost(&m).unwrap()).abs() < 1e-12);
        assert!(prepared.x_half_window_with_spread_m(0.0) == prepared.x_half_window_m());
    }
}
