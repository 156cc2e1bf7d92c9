//! The default configuration, section by section: the values of `config/primm.toml` (a test
//! in `primm-config` checks that the file and these agree). Values chosen on validation data
//! say so; `config/primm.toml` says how.

use super::*;

/// The transition probability between two different modes (off the diagonal) where no class
/// overrides it.
const OFF: f64 = 0.01;

/// `association.likelihood_gate_distance_m`, m (chosen on validation data; `config/primm.toml`).
const GATE_DISTANCE_M: f64 = f64::INFINITY;
/// The probability of staying in a mode (the diagonal) where no class overrides it.
const STAY: f64 = 0.97;

impl Default for Config {
    /// The values of `config/primm.toml`.
    fn default() -> Self {
        Config {
            imm: imm(),
            association: association(),
            tracker: tracker(),
            classes: ClassTable { car: car(), pedestrian: pedestrian(), two_wheeler: two_wheeler() },
            predictor: PredictorConfig::default(),
            frame: CoordinatesConfig::default(),
        }
    }
}

/// The `imm` section.
fn imm() -> ImmConfig {
    ImmConfig {
        modes: ModeSet::ALL,
        transition: [
            [STAY, OFF, OFF, OFF],
            [OFF, STAY, OFF, OFF],
            [OFF, OFF, STAY, OFF],
            [OFF, OFF, OFF, STAY],
        ],
        // PR starts at 1/13 (odds 1:12), chosen on validation data
        // (`config/primm.toml` says how).
        initial_mode_probabilities: [0.07692001, 0.30769333, 0.30769333, 0.30769333],
        likelihood_temperature: 0.1,
        mode_probability_floor: 0.001,
    }
}

/// The `association` section.
fn association() -> AssociationConfig {
    AssociationConfig {
        velocity_weight_s: 0.1,
        velocity_cap_mps: 5.0,
        // Chosen on validation data (`config/primm.toml` says how).
        cost: AssociationCost::Likelihood,
        stages: AssociationStages::ConfirmedFirst,
        likelihood_gate_chi2: 112.0,
        likelihood_gate_distance_m: GATE_DISTANCE_M,
    }
}

/// The `tracker` section: frame validation and track lifecycle.
fn tracker() -> TrackerConfig {
    TrackerConfig {
        max_frame_interval_s: 1.0,
        confirmation_hits: 3,
        tentative_max_misses: 20,
        tentative_max_coast_s: 0.3,
        confirmed_max_misses: 100,
        max_coast_s: 1.0,
        lifecycle: Lifecycle::Existence,
        initial_existence_probability: 0.2,
        confirmation_existence_probability: 0.973,
        deletion_existence_probability: 0.01299,
        existence_persistence_time_s: 40.0,
        duplicate_updates: 4,
        max_frame_delay_s: 0.15,
        replay_frames: 16,
        max_ego_speed_mps: 100.0,
        max_ego_yaw_rate_radps: 3.0,
    }
}

/// The `classes.car` section.
fn car() -> ClassConfig {
    ClassConfig {
        paper_gate_m: 8.4,
        measurement_noise_covariance_m2: diagonal(0.36, 0.36),
        initial_radial_speed_std_mps: 0.5,
        initial_tangential_speed_std_mps: 2.0,
        max_speed_mps: Some(70.0),
        likelihood_radial_velocity_std_mps: 0.5,
        existence: ExistenceConfig { detection_probability: 0.2, clutter_density_per_m2: 0.0004 },
        duplicate_distance_m: 3.0,
        duplicate_speed_difference_mps: 2.0,
        // The detection's own line of sight, chosen on validation (`config/primm.toml`).
        radial_velocity_update: RadialVelocityUpdateConfig {
            enabled: true,
            line_of_sight: RadialLineOfSight::Measured,
            ..RadialVelocityUpdateConfig::default()
        },
        extent: ExtentConfig {
            enabled: true,
            offset_scale: 0.5,
            absorb_extra_detections: true,
            ..ExtentConfig::default()
        },
        constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 1.0 },
        constant_acceleration: ConstantAccelerationConfig {
            jerk_psd_m2_per_s5: 5.0,
            initial_acceleration_std_mps2: 2.0,
        },
        coordinated_turn: CoordinatedTurnConfig {
            acceleration_psd_m2_per_s3: 0.5,
            turn_rate_psd_rad2_per_s3: 0.3,
            initial_turn_rate_std_radps: 0.3,
            max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
        },
        learned: LearnedConfig {
            process_noise_covariance_m2: diagonal(0.011, 0.011),
            measurement_noise_covariance_m2: diagonal(0.18, 0.18),
        },
        // PR all but OFF for cars, and CA entered rarely where the ego's motion is compensated:
        // chosen on validation (`config/primm.toml`).
        imm: ClassImmConfig {
            transition: Some([
                [0.52, 0.16, 0.16, 0.16],
                [0.000625, 0.9791856, 0.0100947, 0.0100947],
                [0.000625, 0.0100947, 0.9791856, 0.0100947],
                [0.000625, 0.0100947, 0.0100947, 0.9791856],
            ]),
            initial_mode_probabilities: Some([0.005182, 0.331606, 0.331606, 0.331606]),
            compensated_transition: Some([
                [0.52, 0.16, 0.16, 0.16],
                [0.000625, 0.987375, 0.002, 0.01],
                [0.000625, 0.0100947, 0.9791856, 0.0100947],
                [0.000625, 0.01, 0.002, 0.987375],
            ]),
            compensated_initial_mode_probabilities: Some([0.005182, 0.472409, 0.05, 0.472409]),
        },
    }
}

/// The `classes.pedestrian` section.
fn pedestrian() -> ClassConfig {
    ClassConfig {
        paper_gate_m: 4.2,
        measurement_noise_covariance_m2: diagonal(0.05, 0.05),
        initial_radial_speed_std_mps: 0.3,
        initial_tangential_speed_std_mps: 0.525,
        max_speed_mps: Some(12.0),
        likelihood_radial_velocity_std_mps: 0.7,
        existence: ExistenceConfig { detection_probability: 0.15, clutter_density_per_m2: 0.0004 },
        duplicate_distance_m: 0.5,
        duplicate_speed_difference_mps: 1.0,
        radial_velocity_update: RadialVelocityUpdateConfig {
            enabled: true,
            line_of_sight: RadialLineOfSight::Measured,
            ..RadialVelocityUpdateConfig::default()
        },
        // A point; the size applies only when switched on.
        extent: ExtentConfig {
            length_m: 0.6,
            width_m: 0.6,
            contour_std_m: 0.2,
            offset_scale: 0.5,
            absorb_margin_m: 0.3,
            ..ExtentConfig::default()
        },
        constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 0.25 },
        constant_acceleration: ConstantAccelerationConfig {
            jerk_psd_m2_per_s5: 1.75,
            initial_acceleration_std_mps2: 1.0,
        },
        coordinated_turn: CoordinatedTurnConfig {
            acceleration_psd_m2_per_s3: 0.25,
            turn_rate_psd_rad2_per_s3: 0.25,
            initial_turn_rate_std_radps: 0.5,
            max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
        },
        learned: LearnedConfig {
            process_noise_covariance_m2: diagonal(0.00015, 0.00015),
            measurement_noise_covariance_m2: diagonal(0.09, 0.09),
        },
        // Chosen on validation with the car's (`config/primm.toml`).
        imm: ClassImmConfig {
            transition: Some([
                [0.985, 0.005, 0.005, 0.005],
                [OFF, STAY, OFF, OFF],
                [OFF, OFF, STAY, OFF],
                [OFF, OFF, OFF, STAY],
            ]),
            initial_mode_probabilities: Some([0.04, 0.32, 0.32, 0.32]),
            ..ClassImmConfig::default()
        },
    }
}

/// The `classes.two_wheeler` section.
fn two_wheeler() -> ClassConfig {
    ClassConfig {
        paper_gate_m: 4.0,
        measurement_noise_covariance_m2: diagonal(0.16, 0.16),
        initial_radial_speed_std_mps: 0.4,
        initial_tangential_speed_std_mps: 5.0,
        max_speed_mps: Some(40.0),
        likelihood_radial_velocity_std_mps: 1.0,
        existence: ExistenceConfig { detection_probability: 0.2, clutter_density_per_m2: 0.0004 },
        duplicate_distance_m: 1.5,
        duplicate_speed_difference_mps: 2.0,
        radial_velocity_update: RadialVelocityUpdateConfig {
            enabled: true,
            ..RadialVelocityUpdateConfig::default()
        },
        extent: ExtentConfig {
            enabled: true,
            length_m: 2.0,
            width_m: 0.8,
            contour_std_m: 0.3,
            offset_scale: 0.5,
            absorb_extra_detections: true,
            ..ExtentConfig::default()
        },
        constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 3.0 },
        constant_acceleration: ConstantAccelerationConfig {
            jerk_psd_m2_per_s5: 15.0,
            initial_acceleration_std_mps2: 1.5,
        },
        coordinated_turn: CoordinatedTurnConfig {
            acceleration_psd_m2_per_s3: 1.5,
            turn_rate_psd_rad2_per_s3: 0.5,
            initial_turn_rate_std_radps: 0.4,
            max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
        },
        learned: LearnedConfig {
            process_noise_covariance_m2: diagonal(0.05, 0.05),
            measurement_noise_covariance_m2: diagonal(0.16, 0.16),
        },
        imm: ClassImmConfig::default(),
    }
}

/// A diagonal 2×2 covariance.
fn diagonal(xx: f64, yy: f64) -> Covariance2 {
    [[xx, 0.0], [0.0, yy]]
}
