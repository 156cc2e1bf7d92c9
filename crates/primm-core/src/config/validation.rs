//! [`Config::validate`]'s checks, section by section; every error names its key.

use super::*;
use crate::readable_number::readable;
use alloc::format;

pub(super) fn invalid(key: impl Into<String>, reason: impl Into<String>) -> ConfigError {
    ConfigError::Invalid { key: key.into(), reason: reason.into() }
}

pub(super) fn positive(key: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, format!("must be a finite number > 0, got {}", readable(value))))
    }
}

/// A probability strictly between 0 and 1.
pub(super) fn open_probability(key: &str, value: f64) -> Result<(), ConfigError> {
    if value > 0.0 && value < 1.0 {
        Ok(())
    } else {
        Err(invalid(key, format!("must be a probability in (0, 1), got {}", readable(value))))
    }
}

/// Checks that a 2×2 covariance is finite, symmetric and positive definite.
pub(super) fn covariance(key: &str, value: &Covariance2) -> Result<(), ConfigError> {
    let m = to_matrix(value);
    if m.iter().any(|v| !v.is_finite()) {
        return Err(invalid(key, "entries must be finite"));
    }
    if (m[(0, 1)] - m[(1, 0)]).abs() > 1e-12 * m.abs().max().max(1.0) {
        return Err(invalid(key, "must be symmetric"));
    }
    if m[(0, 0)] <= 0.0 || m.determinant() <= 0.0 {
        return Err(invalid(key, "must be positive definite"));
    }
    Ok(())
}

/// The `imm` section: mode set, transition matrix, initial probabilities, temperature, floor.
pub(super) fn validate_imm(imm: &ImmConfig) -> Result<(), ConfigError> {
    if imm.modes.is_empty() {
        return Err(invalid("imm.modes", "at least one mode must be active"));
    }
    validate_transition("imm.transition", imm.modes, &imm.transition)?;
    validate_initial_probabilities(
        "imm.initial_mode_probabilities",
        imm.modes,
        &imm.initial_mode_probabilities,
    )?;
    positive("imm.likelihood_temperature", imm.likelihood_temperature)?;
    let floor = imm.mode_probability_floor;
    if !(floor >= 0.0 && floor < 1.0 / imm.modes.len() as f64) {
        return Err(invalid(
            "imm.mode_probability_floor",
            format!("must be in [0, 1/number of active modes), got {}", readable(floor)),
        ));
    }
    Ok(())
}

/// The section `classes.<class>.imm`: each override present is checked as its `imm` key is,
/// against the `imm` section's active modes.
pub(super) fn validate_class_imm(
    class: ObjectClass,
    imm: &ImmConfig,
    overrides: &ClassImmConfig,
) -> Result<(), ConfigError> {
    let prefix = format!("classes.{}.imm", class.name());
    if let Some(transition) = &overrides.transition {
        validate_transition(&format!("{prefix}.transition"), imm.modes, transition)?;
    }
    if let Some(initial) = &overrides.initial_mode_probabilities {
        validate_initial_probabilities(&format!("{prefix}.initial_mode_probabilities"), imm.modes, initial)?;
    }
    if let Some(transition) = &overrides.compensated_transition {
        validate_transition(&format!("{prefix}.compensated_transition"), imm.modes, transition)?;
    }
    if let Some(initial) = &overrides.compensated_initial_mode_probabilities {
        validate_initial_probabilities(
            &format!("{prefix}.compensated_initial_mode_probabilities"),
            imm.modes,
            initial,
        )?;
    }
    Ok(())
}

/// Initial mode probabilities (key `key`): probabilities with mass on the active modes.
pub(super) fn validate_initial_probabilities(
    key: &str,
    modes: ModeSet,
    initial: &[f64; MODE_COUNT],
) -> Result<(), ConfigError> {
    for (i, &p) in initial.iter().enumerate() {
        if !(0.0..=1.0).contains(&p) {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("must be a probability in [0, 1], got {}", readable(p)),
            ));
        }
    }
    if modes.iter().map(|m| initial[m.index()]).sum::<f64>() <= 0.0 {
        return Err(invalid(key, "no probability mass on the active modes"));
    }
    Ok(())
}

/// A transition matrix (key `key`, e.g. `imm.transition`): probabilities, rows summing to 1,
/// and mass on the active modes in the row of every active mode.
pub(super) fn validate_transition(
    key: &str,
    modes: ModeSet,
    transition: &[[f64; MODE_COUNT]; MODE_COUNT],
) -> Result<(), ConfigError> {
    for (i, row) in transition.iter().enumerate() {
        for (j, &p) in row.iter().enumerate() {
            if !(0.0..=1.0).contains(&p) {
                return Err(invalid(
                    format!("{key}[{i}][{j}]"),
                    format!("must be a probability in [0, 1], got {}", readable(p)),
                ));
            }
        }
        let sum: f64 = row.iter().sum();
        if (sum - 1.0).abs() > 1e-9 {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("row must sum to 1, sums to {}", readable(sum)),
            ));
        }
    }
    for mode in modes.iter() {
        let i = mode.index();
        let active_sum: f64 = modes.iter().map(|to| transition[i][to.index()]).sum();
        if active_sum <= 0.0 {
            return Err(invalid(format!("{key}[{i}]"), "row has no probability mass on the active modes"));
        }
    }
    Ok(())
}

/// The `association` section.
pub(super) fn validate_association(association: &AssociationConfig) -> Result<(), ConfigError> {
    if !(association.velocity_weight_s.is_finite() && association.velocity_weight_s >= 0.0) {
        return Err(invalid("association.velocity_weight_s", "must be a finite number >= 0"));
    }
    if !(association.velocity_cap_mps.is_finite() && association.velocity_cap_mps >= 0.0) {
        return Err(invalid("association.velocity_cap_mps", "must be a finite number >= 0"));
    }
    positive("association.likelihood_gate_chi2", association.likelihood_gate_chi2)?;
    if !(association.likelihood_gate_distance_m > 0.0) {
        return Err(invalid("association.likelihood_gate_distance_m", "must be a number > 0"));
    }
    Ok(())
}

/// The `tracker` and `predictor` sections.
pub(super) fn validate_tracker_and_predictor(
    tracker: &TrackerConfig,
    predictor: &PredictorConfig,
) -> Result<(), ConfigError> {
    positive("tracker.max_frame_interval_s", tracker.max_frame_interval_s)?;
    positive("predictor.max_displacement_speed_mps", predictor.max_displacement_speed_mps)?;
    positive("predictor.learned_process_noise_scale", predictor.learned_process_noise_scale)?;
    positive("tracker.max_coast_s", tracker.max_coast_s)?;
    positive("tracker.tentative_max_coast_s", tracker.tentative_max_coast_s)?;
    if tracker.confirmation_hits == 0 {
        return Err(invalid("tracker.confirmation_hits", "must be at least 1"));
    }
    open_probability("tracker.initial_existence_probability", tracker.initial_existence_probability)?;
    open_probability(
        "tracker.confirmation_existence_probability",
        tracker.confirmation_existence_probability,
    )?;
    let deletion = tracker.deletion_existence_probability;
    if !(deletion >= 0.0 && deletion < tracker.confirmation_existence_probability) {
        return Err(invalid(
            "tracker.deletion_existence_probability",
            format!("must be in [0, tracker.confirmation_existence_probability), got {}", readable(deletion)),
        ));
    }
    positive("tracker.existence_persistence_time_s", tracker.existence_persistence_time_s)?;
    if !(tracker.max_frame_delay_s >= 0.0 && tracker.max_frame_delay_s <= tracker.max_frame_interval_s) {
        return Err(invalid(
            "tracker.max_frame_delay_s",
            format!(
                "must be in [0, tracker.max_frame_interval_s], got {}",
                readable(tracker.max_frame_delay_s)
            ),
        ));
    }
    if tracker.replay_frames as usize > crate::limits::MAX_REPLAY_FRAMES {
        return Err(invalid("tracker.replay_frames", "must be at most 64"));
    }
    positive("tracker.max_ego_speed_mps", tracker.max_ego_speed_mps)?;
    positive("tracker.max_ego_yaw_rate_radps", tracker.max_ego_yaw_rate_radps)?;
    Ok(())
}

/// The section `classes.<class>`.
pub(super) fn validate_class(class: ObjectClass, section: &ClassConfig) -> Result<(), ConfigError> {
    let key = |name: &str| format!("classes.{}.{}", class.name(), name);
    positive(&key("paper_gate_m"), section.paper_gate_m)?;
    covariance(&key("measurement_noise_covariance_m2"), &section.measurement_noise_covariance_m2)?;
    positive(&key("initial_radial_speed_std_mps"), section.initial_radial_speed_std_mps)?;
    positive(&key("initial_tangential_speed_std_mps"), section.initial_tangential_speed_std_mps)?;
    section.max_speed_mps.map_or(Ok(()), |speed| positive(&key("max_speed_mps"), speed))?;
    positive(&key("likelihood_radial_velocity_std_mps"), section.likelihood_radial_velocity_std_mps)?;
    positive(&key("duplicate_distance_m"), section.duplicate_distance_m)?;
    positive(&key("duplicate_speed_difference_mps"), section.duplicate_speed_difference_mps)?;
    positive(&key("radial_velocity_update.std_mps"), section.radial_velocity_update.std_mps)?;
    positive(&key("radial_velocity_update.gate_std"), section.radial_velocity_update.gate_std)?;
    let extent = &section.extent;
    positive(&key("extent.length_m"), extent.length_m)?;
    positive(&key("extent.width_m"), extent.width_m)?;
    if extent.width_m > extent.length_m || extent.length_m > 50.0 {
        return Err(invalid(
            key("extent.width_m"),
            format!(
                "must be at most extent.length_m, itself at most 50 m; got {} x {} m",
                readable(extent.length_m),
                readable(extent.width_m)
            ),
        ));
    }
    positive(&key("extent.contour_std_m"), extent.contour_std_m)?;
    positive(&key("extent.min_heading_speed_mps"), extent.min_heading_speed_mps)?;
    if !(extent.offset_scale > 0.0 && extent.offset_scale <= 1.0) {
        return Err(invalid(
            key("extent.offset_scale"),
            format!("must be in (0, 1], got {}", readable(extent.offset_scale)),
        ));
    }
    if !(extent.absorb_margin_m >= 0.0 && extent.absorb_margin_m <= 10.0) {
        return Err(invalid(
            key("extent.absorb_margin_m"),
            format!("must be in [0, 10] m, got {}", readable(extent.absorb_margin_m)),
        ));
    }
    open_probability(&key("existence.detection_probability"), section.existence.detection_probability)?;
    let clutter = section.existence.clutter_density_per_m2;
    if !(clutter.is_finite() && clutter >= 0.0) {
        return Err(invalid(
            key("existence.clutter_density_per_m2"),
            format!("must be a finite number >= 0, got {}", readable(clutter)),
        ));
    }
    positive(
        &key("constant_velocity.acceleration_psd_m2_per_s3"),
        section.constant_velocity.acceleration_psd_m2_per_s3,
    )?;
    positive(
        &key("constant_acceleration.jerk_psd_m2_per_s5"),
        section.constant_acceleration.jerk_psd_m2_per_s5,
    )?;
    positive(
        &key("constant_acceleration.initial_acceleration_std_mps2"),
        section.constant_acceleration.initial_acceleration_std_mps2,
    )?;
    positive(
        &key("coordinated_turn.acceleration_psd_m2_per_s3"),
        section.coordinated_turn.acceleration_psd_m2_per_s3,
    )?;
    positive(
        &key("coordinated_turn.turn_rate_psd_rad2_per_s3"),
        section.coordinated_turn.turn_rate_psd_rad2_per_s3,
    )?;
    positive(
        &key("coordinated_turn.initial_turn_rate_std_radps"),
        section.coordinated_turn.initial_turn_rate_std_radps,
    )?;
    positive(&key("coordinated_turn.max_turn_rate_radps"), section.coordinated_turn.max_turn_rate_radps)?;
    covariance(&key("learned.process_noise_covariance_m2"), &section.learned.process_noise_covariance_m2)?;
    covariance(
        &key("learned.measurement_noise_covariance_m2"),
        &section.learned.measurement_noise_covariance_m2,
    )?;
    Ok(())
}
