//! The association cost of `eq:association_cost`.

use crate::config::AssociationConfig;
use crate::measurement::Measurement;
use glam::DVec2;

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

#[cfg(test)]
mod tests {
    use super::*;
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
        let config = AssociationConfig { velocity_weight_s: 0.1, velocity_cap_mps: 5.0 };
        let cost = association_cost(DVec2::new(0.0, 0.0), 2.0, &measurement(3.0, 4.0, 4.5), &config);
        assert!((cost - (5.0 + 0.1 * 2.5)).abs() < 1e-12);
    }

    #[test]
    fn the_velocity_difference_is_capped() {
        let config = AssociationConfig { velocity_weight_s: 0.1, velocity_cap_mps: 5.0 };
        let cost = association_cost(DVec2::new(1.0, 1.0), -20.0, &measurement(1.0, 1.0, 20.0), &config);
        assert!((cost - 0.5).abs() < 1e-12);
    }
}
