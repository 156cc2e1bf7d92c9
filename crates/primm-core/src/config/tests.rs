use super::*;

fn invalid_key(config: &Config) -> String {
    match config.validate() {
        Err(ConfigError::Invalid { key, .. }) => key,
        Ok(()) => panic!("expected an invalid-key error"),
    }
}

#[test]
fn the_default_configuration_is_valid() {
    Config::default().validate().unwrap();
}

#[test]
fn a_transition_row_that_does_not_sum_to_one_is_named() {
    let mut config = Config::default();
    config.imm.transition[1][1] = 0.96;
    assert_eq!(invalid_key(&config), "imm.transition[1]");
}

#[test]
fn a_negative_probability_is_named() {
    let mut config = Config::default();
    config.imm.transition[0] = [1.01, -0.01, 0.0, 0.0];
    assert_eq!(invalid_key(&config), "imm.transition[0][0]");
}

#[test]
fn a_bad_class_override_is_named_with_its_key() {
    let mut config = Config::default();
    let mut transition = config.imm.transition;
    transition[0] = [0.9, 0.2, 0.0, 0.0];
    config.classes.car.imm.transition = Some(transition);
    assert_eq!(invalid_key(&config), "classes.car.imm.transition[0]");
    let mut config = Config::default();
    config.classes.pedestrian.imm.initial_mode_probabilities = Some([-0.1, 0.5, 0.3, 0.3]);
    assert_eq!(invalid_key(&config), "classes.pedestrian.imm.initial_mode_probabilities[0]");
}

#[test]
fn class_overrides_apply_to_their_class_only() {
    let mut config = Config::default();
    for class in ObjectClass::ALL {
        config.classes.get_mut(class).imm = ClassImmConfig::default();
    }
    config.classes.car.imm.initial_mode_probabilities = Some([0.01, 0.33, 0.33, 0.33]);
    config.validate().unwrap();
    assert_eq!(config.imm_for(ObjectClass::Car).initial_mode_probabilities, [0.01, 0.33, 0.33, 0.33]);
    assert_eq!(config.imm_for(ObjectClass::Car).transition, config.imm.transition);
    assert_eq!(config.imm_for(ObjectClass::Pedestrian), config.imm);
    assert_eq!(Config::default().imm_for(ObjectClass::TwoWheeler), Config::default().imm);
    // The shipped overrides: cars' and pedestrians' own, whole.
    let shipped = Config::default();
    for class in [ObjectClass::Car, ObjectClass::Pedestrian] {
        let own = &shipped.classes.get(class).imm;
        let imm = shipped.imm_for(class);
        assert_eq!(Some(imm.transition), own.transition);
        assert_eq!(Some(imm.initial_mode_probabilities), own.initial_mode_probabilities);
        assert_eq!(imm.likelihood_temperature, shipped.imm.likelihood_temperature);
    }
}

#[test]
fn a_non_positive_temperature_is_named() {
    let mut config = Config::default();
    config.imm.likelihood_temperature = 0.0;
    assert_eq!(invalid_key(&config), "imm.likelihood_temperature");
}

#[test]
fn an_asymmetric_covariance_is_named() {
    let mut config = Config::default();
    config.classes.pedestrian.measurement_noise_covariance_m2 = [[0.09, 0.01], [0.0, 0.09]];
    assert_eq!(invalid_key(&config), "classes.pedestrian.measurement_noise_covariance_m2");
}

#[test]
fn an_indefinite_covariance_is_named() {
    let mut config = Config::default();
    config.classes.car.learned.process_noise_covariance_m2 = [[0.01, 0.5], [0.5, 0.017]];
    assert_eq!(invalid_key(&config), "classes.car.learned.process_noise_covariance_m2");
}

#[test]
fn a_floor_too_high_for_the_mode_count_is_named() {
    let mut config = Config::default();
    config.imm.mode_probability_floor = 0.3;
    assert_eq!(invalid_key(&config), "imm.mode_probability_floor");
}

#[test]
fn an_empty_mode_set_is_rejected() {
    let config = Config::default().with_modes(ModeSet::EMPTY);
    assert_eq!(invalid_key(&config), "imm.modes");
}

#[test]
fn a_non_positive_or_non_finite_displacement_speed_bound_is_rejected() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut config = Config::default();
        config.predictor.max_displacement_speed_mps = bad;
        assert_eq!(invalid_key(&config), "predictor.max_displacement_speed_mps", "bound {bad}");
    }
}
