//! The reference values of every section: [`ScenarioConfig::default`] and its parts.

use super::behaviour::{DriverConfig, MotionLimits, WalkerConfig};
use super::mount::RadarMount;
use super::types::{
    CarConfig, ClutterConfig, EgoConfig, EgoPlacement, ExtendedObjectConfig, OutputConfig, PedestrianConfig,
    PointCloudConfig, RadarConfig, RadarReport, ReflectionConfig, RoadConfig, SequenceConfig, SplitConfig,
    TrafficConfig,
};
use super::ScenarioConfig;

impl Default for ScenarioConfig {
    fn default() -> Self {
        Self {
            sequence: SequenceConfig::default(),
            splits: SplitConfig::default(),
            road: RoadConfig::default(),
            traffic: TrafficConfig::default(),
            ego: EgoConfig::default(),
            car: CarConfig::default(),
            pedestrian: PedestrianConfig::default(),
            radar: RadarConfig::default(),
            car_reflection: ReflectionConfig::car(),
            pedestrian_reflection: ReflectionConfig::pedestrian(),
            clutter: ClutterConfig::default(),
            extended_objects: ExtendedObjectConfig::default(),
            output: OutputConfig::default(),
            point_cloud: PointCloudConfig::default(),
        }
    }
}

impl Default for SequenceConfig {
    fn default() -> Self {
        Self { duration_s: 7.0, warmup_s: 5.0, max_step_s: 0.02 }
    }
}

impl Default for SplitConfig {
    fn default() -> Self {
        Self {
            seed_base: 0x5052_494d_4d00,
            train_sequences: 130,
            validation_sequences: 6,
            evaluation_sequences: 22,
        }
    }
}

impl Default for RoadConfig {
    fn default() -> Self {
        Self {
            block_length_m: 110.0,
            lane_width_m: 3.5,
            lanes_per_direction: 2,
            sidewalk_offset_m: 2.5,
            sidewalk_width_m: 2.4,
            stop_line_offset_m: 3.5,
            right_turn_radius_m: 8.0,
            left_turn_radius_m: 11.0,
            signalised_junction_fraction: 0.5,
            signal_green_s: 15.0,
            signal_clearance_s: 4.0,
        }
    }
}

impl Default for TrafficConfig {
    fn default() -> Self {
        Self {
            car_count: 14,
            pedestrian_count: 12,
            pedestrian_group_probability: 0.3,
            pedestrian_corner_spawn_probability: 0.7,
            corner_spawn_distance_m: 20.0,
            max_group_size: 3,
            group_spacing_m: [0.7, 1.3],
            population_radius_m: 130.0,
            despawn_radius_m: 150.0,
            min_spawn_distance_m: 12.0,
            spawn_fov_margin_deg: 8.0,
            spawn_range_margin_m: 10.0,
        }
    }
}

impl Default for EgoConfig {
    fn default() -> Self {
        Self {
            length_m: 4.9,
            width_m: 1.9,
            rear_axle_to_centre_m: 1.35,
            desired_speed_mps: [8.0, 13.0],
            initial_standstill_probability: 0.15,
            start_distance_to_junction_m: [20.0, 80.0],
            turn_left_probability: None,
            turn_right_probability: None,
            placement: EgoPlacement::Driving,
        }
    }
}

impl Default for CarConfig {
    fn default() -> Self {
        Self {
            length_m: [3.9, 5.2],
            width_m: [1.7, 2.0],
            large_vehicle_probability: 0.15,
            large_length_m: [5.3, 7.5],
            large_width_m: [2.0, 2.4],
            desired_speed_mps: [8.0, 14.5],
            limits: MotionLimits::car(),
            comfortable_acceleration_mps2: 1.6,
            comfortable_deceleration_mps2: 2.5,
            curve_lateral_acceleration_mps2: 2.5,
            time_headway_s: 1.3,
            standstill_gap_m: 2.0,
            turn_left_probability: 0.2,
            turn_right_probability: 0.25,
            lane_change_probability: 0.35,
            lane_change_duration_s: 4.0,
            speed_change_interval_s: [4.0, 12.0],
            driver: DriverConfig::default(),
        }
    }
}

impl Default for PedestrianConfig {
    fn default() -> Self {
        Self {
            length_m: [0.3, 0.5],
            width_m: [0.45, 0.65],
            desired_speed_mps: [0.9, 1.7],
            hurry_probability: 0.06,
            hurry_speed_mps: [1.9, 2.4],
            limits: MotionLimits::pedestrian(),
            heading_wander_rad: 0.08,
            heading_wander_time_s: 2.0,
            leg_length_m: [6.0, 30.0],
            stop_probability: 0.15,
            stop_duration_s: [1.0, 6.0],
            turn_around_probability: 0.12,
            mid_block_crossing_probability: 0.12,
            crosswalk_probability: 0.65,
            walker: WalkerConfig::default(),
        }
    }
}

impl Default for RadarConfig {
    fn default() -> Self {
        Self {
            sensors: RadarMount::default_layout(),
            scan_period_s: 0.06,
            phase_jitter_s: 0.003,
            scan_jitter_s: 0.003,
            range_noise_m: 0.12,
            azimuth_noise_deg: 0.6,
            doppler_noise_mps: 0.08,
            scan_doppler_bias_mps: 0.03,
            miss_probability: 0.03,
            occluded_point_probability: 0.05,
            fade_start_fraction: 0.7,
            report: RadarReport::Echo,
        }
    }
}

impl Default for OutputConfig {
    /// Frames carry the ego pose and the sensor id.
    fn default() -> Self {
        Self { ego_pose: true, sensor_id: true }
    }
}

impl ReflectionConfig {
    /// Default reflection model of cars.
    pub fn car() -> Self {
        Self {
            mean_points_at_reference: 6.0,
            reference_range_m: 20.0,
            max_points: 24,
            corner_probability: 0.25,
            interior_probability: 0.3,
            range_extent_weight: 0.0,
            rcs_front_dbsm: 6.0,
            rcs_side_dbsm: 12.0,
            rcs_fluctuation_db: 4.0,
            detection_range_m: 100.0,
            micro_doppler_fraction: 0.05,
        }
    }

    /// Default reflection model of pedestrians.
    pub fn pedestrian() -> Self {
        Self {
            mean_points_at_reference: 2.0,
            reference_range_m: 20.0,
            max_points: 6,
            corner_probability: 0.0,
            interior_probability: 0.3,
            range_extent_weight: 0.0,
            rcs_front_dbsm: -6.0,
            rcs_side_dbsm: -4.0,
            rcs_fluctuation_db: 3.0,
            detection_range_m: 70.0,
            micro_doppler_fraction: 0.35,
        }
    }
}

impl Default for ReflectionConfig {
    fn default() -> Self {
        Self::car()
    }
}

impl Default for ClutterConfig {
    /// No false detections; the other values describe the clutter once it is switched on.
    fn default() -> Self {
        Self {
            mean_false_detections_per_scan: 0.0,
            min_range_m: 1.0,
            max_range_m: 80.0,
            car_fraction: 0.7,
            car_rcs_mean_dbsm: 3.0,
            car_rcs_std_db: 5.0,
            pedestrian_rcs_mean_dbsm: -8.0,
            pedestrian_rcs_std_db: 4.0,
            moving_fraction: 0.15,
            moving_radial_velocity_max_mps: 10.0,
            ghost_probability: 0.0,
            ghost_extra_range_m: [2.0, 8.0],
            ghost_rcs_drop_db: 8.0,
        }
    }
}

impl Default for ExtendedObjectConfig {
    /// Switched off; the other values describe the model once it is switched on.
    fn default() -> Self {
        Self {
            enabled: false,
            detection_count_probabilities: vec![0.8, 0.15, 0.05],
            corner_probability: 0.3,
            contour_spread_m: 0.8,
        }
    }
}

impl ExtendedObjectConfig {
    /// The model of the `extended` presets: switched on with the default values.
    pub fn vehicles() -> Self {
        Self { enabled: true, ..Self::default() }
    }

    /// Mean number of detections per vehicle and scan before losses, from
    /// `detection_count_probabilities`.
    pub fn mean_detection_count(&self) -> f64 {
        self.detection_count_probabilities.iter().enumerate().map(|(k, p)| (k + 1) as f64 * p).sum()
    }
}

impl Default for PointCloudConfig {
    /// Switched off; the other values describe the model once it is switched on.
    fn default() -> Self {
        Self {
            enabled: false,
            car_extra_detections_at_reference: 5.0,
            reference_range_m: 25.0,
            max_detections_per_car: 12,
            wheel_probability: 0.2,
            wheelbase_fraction: 0.6,
            pedestrian_detection_count_probabilities: vec![0.6, 0.4],
            wall_offset_m: 12.0,
            ghost_probability: 0.3,
            max_ghost_detections: 2,
            ghost_rcs_drop_db: 8.0,
            class_flip_probability: 0.1,
        }
    }
}

impl PointCloudConfig {
    /// The model of the `point_cloud` preset: switched on with the default values.
    pub fn detections() -> Self {
        Self { enabled: true, ..Self::default() }
    }
}

impl ClutterConfig {
    /// The clutter of the `clutter` and `clutter_turning` presets: 1.5 false detections per
    /// scan, mostly static, 15 % moving-looking, and a ghost behind 3 % of the object
    /// measurements.
    pub fn urban() -> Self {
        Self { mean_false_detections_per_scan: 1.5, ghost_probability: 0.03, ..Self::default() }
    }

    /// Whether this configuration adds any false detection.
    pub fn is_enabled(&self) -> bool {
        self.mean_false_detections_per_scan > 0.0 || self.ghost_probability > 0.0
    }
}

impl MotionLimits {
    /// The default limits of cars and the ego vehicle.
    pub fn car() -> Self {
        Self {
            max_speed_mps: 16.7,
            max_acceleration_mps2: 3.0,
            max_deceleration_mps2: 7.0,
            max_jerk_mps3: 6.0,
            max_yaw_rate_radps: 0.7,
            max_yaw_acceleration_radps2: 1.2,
            max_lateral_acceleration_mps2: Some(3.5),
            stop_taper_s: 0.8,
        }
    }

    /// The default limits of pedestrians: no lateral acceleration limit.
    pub fn pedestrian() -> Self {
        Self {
            max_speed_mps: 2.5,
            max_acceleration_mps2: 1.5,
            max_deceleration_mps2: 2.0,
            max_jerk_mps3: 6.0,
            max_yaw_rate_radps: 2.5,
            max_yaw_acceleration_radps2: 8.0,
            max_lateral_acceleration_mps2: None,
            stop_taper_s: 0.3,
        }
    }
}

impl Default for DriverConfig {
    fn default() -> Self {
        Self {
            lookahead_per_speed_s: 0.7,
            lookahead_base_m: 2.5,
            min_lookahead_m: 3.5,
            max_lookahead_m: 18.0,
            curve_preview_m: 60.0,
            start_curve_preview_m: 250.0,
            interaction_range_m: 55.0,
            vehicle_lateral_margin_m: 0.3,
            pedestrian_lateral_margin_m: 0.9,
            max_stop_deceleration_factor: 1.6,
            always_stop_below_speed_mps: 0.5,
            give_way_box_margin_m: 1.0,
            give_way_stopped_speed_mps: 0.5,
            give_way_horizon_m: 30.0,
            give_way_overshoot_m: 1.0,
            min_arrival_speed_mps: 1.0,
            lane_change_min_speed_mps: 5.0,
            min_lane_change_length_m: 15.0,
            max_lane_change_length_m: 60.0,
            lane_change_start_m: 8.0,
            lane_change_clearance_m: 5.0,
            min_turn_entry_m: 1.0,
        }
    }
}

impl Default for WalkerConfig {
    fn default() -> Self {
        Self {
            waypoint_reach_m: 0.35,
            path_lookahead_m: 1.2,
            max_lookahead_turn_rad: 1.7,
            heading_gain_per_s: 3.0,
            speed_time_constant_s: 0.4,
            stop_deceleration_mps2: 0.8,
            stop_short_m: 0.1,
            max_wander_sigmas: 3.0,
            wait_reach_m: 0.35,
            wait_speed_mps: 0.15,
            passed_mark_m: 0.5,
            crosswalk_decision_m: 3.0,
            crosswalk_green_fraction: 0.6,
            crosswalk_min_speed_mps: 0.5,
            group_position_gain_per_s: 0.8,
            group_max_speed_fraction: 0.95,
            group_aim_ahead_m: 1.0,
            group_standing_speed_mps: 0.2,
            group_slot_tolerance_m: 0.5,
            pace_change_probability: 0.3,
            kerb_wait_probability: 0.5,
            kerb_wait_s: [0.5, 2.0],
            crossing_spread_m: 1.0,
            waypoint_jitter_fraction: 0.7,
            corner_jitter_m: 0.3,
            corner_turn_around_fraction: 0.25,
        }
    }
}
