//! The consistency checks of a configuration: [`ScenarioConfig::validate`].

use primm_core::measurement::MAX_MEASUREMENTS_PER_FRAME;
use primm_core::readable_number::readable;

use super::behaviour::{DriverConfig, MotionLimits, WalkerConfig};
use super::mount::RadarMount;
use super::types::{RadarReport, MAX_DETECTIONS_PER_OBJECT};
use super::{ConfigError, Interval, ScenarioConfig};

impl ScenarioConfig {
    /// Checks every value; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_sequence()?;
        self.validate_road()?;
        self.validate_traffic()?;
        self.validate_car()?;
        self.validate_turn_radii()?;
        self.validate_ego()?;
        self.validate_pedestrian()?;
        validate_driver(&self.car.driver)?;
        validate_walker(&self.pedestrian.walker)?;
        self.validate_radar()?;
        self.validate_reflections()?;
        self.validate_clutter()?;
        self.validate_extended_objects()?;
        self.validate_point_cloud()
    }

    /// `sequence.*`.
    fn validate_sequence(&self) -> Result<(), ConfigError> {
        let s = &self.sequence;
        positive("sequence.duration_s", s.duration_s)?;
        non_negative("sequence.warmup_s", s.warmup_s)?;
        positive("sequence.max_step_s", s.max_step_s)?;
        if s.max_step_s > 0.1 {
            return Err(ConfigError::new("sequence.max_step_s", "must be at most 0.1 s"));
        }
        Ok(())
    }

    /// `road.*`, including a block long enough for the lanes and turn radii.
    fn validate_road(&self) -> Result<(), ConfigError> {
        let r = &self.road;
        positive("road.lane_width_m", r.lane_width_m)?;
        if r.lanes_per_direction == 0 || r.lanes_per_direction > 4 {
            return Err(ConfigError::new("road.lanes_per_direction", "must be between 1 and 4"));
        }
        positive("road.sidewalk_offset_m", r.sidewalk_offset_m)?;
        positive("road.sidewalk_width_m", r.sidewalk_width_m)?;
        if r.sidewalk_width_m / 2.0 >= r.sidewalk_offset_m {
            return Err(ConfigError::new(
                "road.sidewalk_width_m",
                "must be less than twice road.sidewalk_offset_m",
            ));
        }
        non_negative("road.stop_line_offset_m", r.stop_line_offset_m)?;
        positive("road.right_turn_radius_m", r.right_turn_radius_m)?;
        positive("road.left_turn_radius_m", r.left_turn_radius_m)?;
        probability("road.signalised_junction_fraction", r.signalised_junction_fraction)?;
        positive("road.signal_green_s", r.signal_green_s)?;
        non_negative("road.signal_clearance_s", r.signal_clearance_s)?;
        let half_road = r.lane_width_m * f64::from(r.lanes_per_direction);
        let corner_reach = half_road + r.left_turn_radius_m.max(r.right_turn_radius_m) + half_road;
        let needed = 2.0 * corner_reach + 40.0;
        if r.block_length_m < needed {
            return Err(ConfigError::new(
                "road.block_length_m",
                format!("must be at least {:.1} m for these lanes and turn radii", readable(needed)),
            ));
        }
        Ok(())
    }

    /// `traffic.*`.
    fn validate_traffic(&self) -> Result<(), ConfigError> {
        let t = &self.traffic;
        probability("traffic.pedestrian_group_probability", t.pedestrian_group_probability)?;
        probability("traffic.pedestrian_corner_spawn_probability", t.pedestrian_corner_spawn_probability)?;
        positive("traffic.corner_spawn_distance_m", t.corner_spawn_distance_m)?;
        if t.max_group_size < 2 {
            return Err(ConfigError::new("traffic.max_group_size", "must be at least 2"));
        }
        interval("traffic.group_spacing_m", t.group_spacing_m, true)?;
        positive("traffic.population_radius_m", t.population_radius_m)?;
        if t.despawn_radius_m <= t.population_radius_m {
            return Err(ConfigError::new(
                "traffic.despawn_radius_m",
                "must exceed traffic.population_radius_m",
            ));
        }
        non_negative("traffic.min_spawn_distance_m", t.min_spawn_distance_m)?;
        if t.min_spawn_distance_m >= t.population_radius_m {
            return Err(ConfigError::new(
                "traffic.min_spawn_distance_m",
                "must be less than traffic.population_radius_m",
            ));
        }
        non_negative("traffic.spawn_fov_margin_deg", t.spawn_fov_margin_deg)?;
        non_negative("traffic.spawn_range_margin_m", t.spawn_range_margin_m)?;
        Ok(())
    }

    /// `car.*`.
    fn validate_car(&self) -> Result<(), ConfigError> {
        let c = &self.car;
        interval("car.length_m", c.length_m, true)?;
        interval("car.width_m", c.width_m, true)?;
        probability("car.large_vehicle_probability", c.large_vehicle_probability)?;
        interval("car.large_length_m", c.large_length_m, true)?;
        interval("car.large_width_m", c.large_width_m, true)?;
        interval("car.desired_speed_mps", c.desired_speed_mps, true)?;
        let limits = &c.limits;
        positive("car.max_speed_mps", limits.max_speed_mps)?;
        if c.desired_speed_mps[1] > limits.max_speed_mps {
            return Err(ConfigError::new("car.desired_speed_mps", "must not exceed car.max_speed_mps"));
        }
        validate_limits("car", limits)?;
        positive("car.comfortable_acceleration_mps2", c.comfortable_acceleration_mps2)?;
        positive("car.comfortable_deceleration_mps2", c.comfortable_deceleration_mps2)?;
        if c.comfortable_acceleration_mps2 > limits.max_acceleration_mps2 {
            return Err(ConfigError::new(
                "car.comfortable_acceleration_mps2",
                "must not exceed car.max_acceleration_mps2",
            ));
        }
        if c.comfortable_deceleration_mps2 > limits.max_deceleration_mps2 {
            return Err(ConfigError::new(
                "car.comfortable_deceleration_mps2",
                "must not exceed car.max_deceleration_mps2",
            ));
        }
        positive("car.curve_lateral_acceleration_mps2", c.curve_lateral_acceleration_mps2)?;
        if limits.max_lateral_acceleration_mps2.is_some_and(|max| c.curve_lateral_acceleration_mps2 > max) {
            return Err(ConfigError::new(
                "car.curve_lateral_acceleration_mps2",
                "must not exceed car.max_lateral_acceleration_mps2",
            ));
        }
        positive("car.time_headway_s", c.time_headway_s)?;
        positive("car.standstill_gap_m", c.standstill_gap_m)?;
        probability("car.turn_left_probability", c.turn_left_probability)?;
        probability("car.turn_right_probability", c.turn_right_probability)?;
        if c.turn_left_probability + c.turn_right_probability > 1.0 {
            return Err(ConfigError::new(
                "car.turn_left_probability",
                "plus car.turn_right_probability must not exceed 1",
            ));
        }
        probability("car.lane_change_probability", c.lane_change_probability)?;
        positive("car.lane_change_duration_s", c.lane_change_duration_s)?;
        interval("car.speed_change_interval_s", c.speed_change_interval_s, true)?;
        Ok(())
    }

    /// The turn radii against the car limits: a car driving a turn at its planned speed must not
    /// need a yaw rate above `car.max_yaw_rate_radps`.
    fn validate_turn_radii(&self) -> Result<(), ConfigError> {
        let (c, road) = (&self.car, &self.road);
        for (name, r) in [
            ("road.right_turn_radius_m", road.right_turn_radius_m),
            ("road.left_turn_radius_m", road.left_turn_radius_m),
        ] {
            let v = (c.curve_lateral_acceleration_mps2 * r).sqrt();
            if v / r > c.limits.max_yaw_rate_radps {
                return Err(ConfigError::new(
                    name,
                    "is too small: the planned turn speed needs a yaw rate above car.max_yaw_rate_radps",
                ));
            }
        }
        Ok(())
    }

    /// `ego.*`.
    fn validate_ego(&self) -> Result<(), ConfigError> {
        let e = &self.ego;
        positive("ego.length_m", e.length_m)?;
        positive("ego.width_m", e.width_m)?;
        if e.rear_axle_to_centre_m.abs() >= e.length_m / 2.0 {
            return Err(ConfigError::new("ego.rear_axle_to_centre_m", "must lie inside the vehicle"));
        }
        interval("ego.desired_speed_mps", e.desired_speed_mps, true)?;
        if e.desired_speed_mps[1] > self.car.limits.max_speed_mps {
            return Err(ConfigError::new("ego.desired_speed_mps", "must not exceed car.max_speed_mps"));
        }
        probability("ego.initial_standstill_probability", e.initial_standstill_probability)?;
        let left = e.turn_left_probability.unwrap_or(0.0);
        let right = e.turn_right_probability.unwrap_or(0.0);
        probability("ego.turn_left_probability", left)?;
        probability("ego.turn_right_probability", right)?;
        if left + right > 1.0 {
            return Err(ConfigError::new(
                "ego.turn_left_probability",
                "plus ego.turn_right_probability must not exceed 1",
            ));
        }
        interval("ego.start_distance_to_junction_m", e.start_distance_to_junction_m, false)?;
        Ok(())
    }

    /// `pedestrian.*`.
    fn validate_pedestrian(&self) -> Result<(), ConfigError> {
        let p = &self.pedestrian;
        interval("pedestrian.length_m", p.length_m, true)?;
        interval("pedestrian.width_m", p.width_m, true)?;
        interval("pedestrian.desired_speed_mps", p.desired_speed_mps, true)?;
        probability("pedestrian.hurry_probability", p.hurry_probability)?;
        interval("pedestrian.hurry_speed_mps", p.hurry_speed_mps, true)?;
        let limits = &p.limits;
        positive("pedestrian.max_speed_mps", limits.max_speed_mps)?;
        if p.desired_speed_mps[1] > limits.max_speed_mps || p.hurry_speed_mps[1] > limits.max_speed_mps {
            return Err(ConfigError::new(
                "pedestrian.max_speed_mps",
                "must not be below the desired or hurry speeds",
            ));
        }
        validate_limits("pedestrian", limits)?;
        non_negative("pedestrian.heading_wander_rad", p.heading_wander_rad)?;
        positive("pedestrian.heading_wander_time_s", p.heading_wander_time_s)?;
        interval("pedestrian.leg_length_m", p.leg_length_m, true)?;
        probability("pedestrian.stop_probability", p.stop_probability)?;
        interval("pedestrian.stop_duration_s", p.stop_duration_s, true)?;
        probability("pedestrian.turn_around_probability", p.turn_around_probability)?;
        probability("pedestrian.mid_block_crossing_probability", p.mid_block_crossing_probability)?;
        if p.stop_probability + p.turn_around_probability + p.mid_block_crossing_probability > 1.0 {
            return Err(ConfigError::new(
                "pedestrian.stop_probability",
                "plus turn_around_probability plus mid_block_crossing_probability must not exceed 1",
            ));
        }
        probability("pedestrian.crosswalk_probability", p.crosswalk_probability)?;
        Ok(())
    }

    /// `radar.*`: the sensors, then the scan timing and the measurement model.
    fn validate_radar(&self) -> Result<(), ConfigError> {
        let radar = &self.radar;
        validate_sensors(&radar.sensors)?;
        positive("radar.scan_period_s", radar.scan_period_s)?;
        non_negative("radar.phase_jitter_s", radar.phase_jitter_s)?;
        non_negative("radar.scan_jitter_s", radar.scan_jitter_s)?;
        let slot = radar.scan_period_s / radar.sensors.len() as f64;
        if radar.phase_jitter_s + radar.scan_jitter_s >= slot / 2.0 {
            return Err(ConfigError::new(
                "radar.scan_jitter_s",
                format!(
                    "plus radar.phase_jitter_s must stay below half the slot between sensors ({:.4} s) so that scans stay interleaved",
                    readable(slot / 2.0)
                ),
            ));
        }
        non_negative("radar.range_noise_m", radar.range_noise_m)?;
        non_negative("radar.azimuth_noise_deg", radar.azimuth_noise_deg)?;
        non_negative("radar.doppler_noise_mps", radar.doppler_noise_mps)?;
        non_negative("radar.scan_doppler_bias_mps", radar.scan_doppler_bias_mps)?;
        probability("radar.miss_probability", radar.miss_probability)?;
        if radar.miss_probability >= 1.0 {
            return Err(ConfigError::new("radar.miss_probability", "must be below 1"));
        }
        probability("radar.occluded_point_probability", radar.occluded_point_probability)?;
        probability("radar.fade_start_fraction", radar.fade_start_fraction)?;
        Ok(())
    }

    /// `car_reflection.*` and `pedestrian_reflection.*`.
    fn validate_reflections(&self) -> Result<(), ConfigError> {
        for (prefix, refl) in
            [("car_reflection", &self.car_reflection), ("pedestrian_reflection", &self.pedestrian_reflection)]
        {
            let field = |name: &str| format!("{prefix}.{name}");
            positive(&field("mean_points_at_reference"), refl.mean_points_at_reference)?;
            positive(&field("reference_range_m"), refl.reference_range_m)?;
            if refl.max_points == 0 {
                return Err(ConfigError::new(field("max_points"), "must be at least 1"));
            }
            probability(&field("corner_probability"), refl.corner_probability)?;
            probability(&field("interior_probability"), refl.interior_probability)?;
            non_negative(&field("range_extent_weight"), refl.range_extent_weight)?;
            finite(&field("rcs_front_dbsm"), refl.rcs_front_dbsm)?;
            finite(&field("rcs_side_dbsm"), refl.rcs_side_dbsm)?;
            non_negative(&field("rcs_fluctuation_db"), refl.rcs_fluctuation_db)?;
            positive(&field("detection_range_m"), refl.detection_range_m)?;
            non_negative(&field("micro_doppler_fraction"), refl.micro_doppler_fraction)?;
        }
        Ok(())
    }

    /// `clutter.*`, including a clutter range that every sensor can reach.
    fn validate_clutter(&self) -> Result<(), ConfigError> {
        let c = &self.clutter;
        non_negative("clutter.mean_false_detections_per_scan", c.mean_false_detections_per_scan)?;
        if c.mean_false_detections_per_scan > MAX_MEASUREMENTS_PER_FRAME as f64 {
            return Err(ConfigError::new(
                "clutter.mean_false_detections_per_scan",
                format!("must not exceed the frame capacity of {MAX_MEASUREMENTS_PER_FRAME} measurements"),
            ));
        }
        positive("clutter.min_range_m", c.min_range_m)?;
        positive("clutter.max_range_m", c.max_range_m)?;
        if c.max_range_m <= c.min_range_m {
            return Err(ConfigError::new("clutter.max_range_m", "must exceed clutter.min_range_m"));
        }
        if let Some((i, sensor)) = self
            .radar
            .sensors
            .iter()
            .enumerate()
            .find(|(_, sensor)| sensor.layout.max_range_m <= c.min_range_m)
        {
            return Err(ConfigError::new(
                "clutter.min_range_m",
                format!(
                    "must be below every sensor's range (radar.sensors[{i}].max_range_m is {} m)",
                    readable(sensor.layout.max_range_m)
                ),
            ));
        }
        probability("clutter.car_fraction", c.car_fraction)?;
        finite("clutter.car_rcs_mean_dbsm", c.car_rcs_mean_dbsm)?;
        non_negative("clutter.car_rcs_std_db", c.car_rcs_std_db)?;
        finite("clutter.pedestrian_rcs_mean_dbsm", c.pedestrian_rcs_mean_dbsm)?;
        non_negative("clutter.pedestrian_rcs_std_db", c.pedestrian_rcs_std_db)?;
        probability("clutter.moving_fraction", c.moving_fraction)?;
        non_negative("clutter.moving_radial_velocity_max_mps", c.moving_radial_velocity_max_mps)?;
        probability("clutter.ghost_probability", c.ghost_probability)?;
        interval("clutter.ghost_extra_range_m", c.ghost_extra_range_m, true)?;
        non_negative("clutter.ghost_rcs_drop_db", c.ghost_rcs_drop_db)?;
        Ok(())
    }

    /// `extended_objects.*`: a count distribution that sums to 1.
    fn validate_extended_objects(&self) -> Result<(), ConfigError> {
        let e = &self.extended_objects;
        count_distribution(
            "extended_objects.detection_count_probabilities",
            &e.detection_count_probabilities,
        )?;
        probability("extended_objects.corner_probability", e.corner_probability)?;
        non_negative("extended_objects.contour_spread_m", e.contour_spread_m)?;
        if e.enabled && self.radar.report == RadarReport::Centre {
            return Err(ConfigError::new(
                "extended_objects.enabled",
                "reports reflection centres on the outline; it needs radar.report = \"echo\"",
            ));
        }
        Ok(())
    }

    /// `point_cloud.*`: counts, probabilities, and walls between the sidewalks and the blocks'
    /// centres; the model replaces the extended objects and the object-list report.
    fn validate_point_cloud(&self) -> Result<(), ConfigError> {
        let p = &self.point_cloud;
        non_negative("point_cloud.car_extra_detections_at_reference", p.car_extra_detections_at_reference)?;
        positive("point_cloud.reference_range_m", p.reference_range_m)?;
        if !(1..=MAX_POINT_CLOUD_DETECTIONS).contains(&p.max_detections_per_car) {
            return Err(ConfigError::new(
                "point_cloud.max_detections_per_car",
                format!("must lie between 1 and {MAX_POINT_CLOUD_DETECTIONS}"),
            ));
        }
        probability("point_cloud.wheel_probability", p.wheel_probability)?;
        if !(p.wheelbase_fraction > 0.0 && p.wheelbase_fraction <= 1.0) {
            return Err(ConfigError::new("point_cloud.wheelbase_fraction", "must lie in (0, 1]"));
        }
        count_distribution(
            "point_cloud.pedestrian_detection_count_probabilities",
            &p.pedestrian_detection_count_probabilities,
        )?;
        let sidewalk_edge =
            self.half_road_width_m() + self.road.sidewalk_offset_m + self.road.sidewalk_width_m / 2.0;
        if !(p.wall_offset_m > sidewalk_edge && p.wall_offset_m < self.road.block_length_m / 2.0) {
            return Err(ConfigError::new(
                "point_cloud.wall_offset_m",
                format!(
                    "must lie beyond the sidewalks ({} m) and within half a block ({} m)",
                    readable(sidewalk_edge),
                    readable(self.road.block_length_m / 2.0)
                ),
            ));
        }
        probability("point_cloud.ghost_probability", p.ghost_probability)?;
        if p.max_ghost_detections > MAX_POINT_CLOUD_DETECTIONS {
            return Err(ConfigError::new(
                "point_cloud.max_ghost_detections",
                format!("must be at most {MAX_POINT_CLOUD_DETECTIONS}"),
            ));
        }
        non_negative("point_cloud.ghost_rcs_drop_db", p.ghost_rcs_drop_db)?;
        probability("point_cloud.class_flip_probability", p.class_flip_probability)?;
        if p.enabled && (self.extended_objects.enabled || self.radar.report == RadarReport::Centre) {
            return Err(ConfigError::new(
                "point_cloud.enabled",
                "replaces the extended objects and the object list; it needs extended_objects.enabled = false \
                 and radar.report = \"echo\"",
            ));
        }
        Ok(())
    }
}

/// Largest number of detections of one car, or of one ghost, in one scan of the point-cloud
/// model.
const MAX_POINT_CLOUD_DETECTIONS: u32 = 64;

/// A count distribution `field`: between 1 and [`MAX_DETECTIONS_PER_OBJECT`] probabilities
/// that sum to 1.
fn count_distribution(field: &str, counts: &[f64]) -> Result<(), ConfigError> {
    if counts.is_empty() || counts.len() > MAX_DETECTIONS_PER_OBJECT {
        return Err(ConfigError::new(
            field,
            format!("must list between 1 and {MAX_DETECTIONS_PER_OBJECT} probabilities"),
        ));
    }
    for (k, &p) in counts.iter().enumerate() {
        probability(&format!("{field}[{k}]"), p)?;
    }
    let total: f64 = counts.iter().sum();
    if (total - 1.0).abs() > 1e-9 {
        return Err(ConfigError::new(field, format!("must sum to 1 (got {})", readable(total))));
    }
    Ok(())
}

/// `radar.sensors`: at least one, unique ids, finite mounts, fields of view within (0, 90)°.
fn validate_sensors(sensors: &[RadarMount]) -> Result<(), ConfigError> {
    if sensors.is_empty() {
        return Err(ConfigError::new("radar.sensors", "must list at least one sensor"));
    }
    for (i, sensor) in sensors.iter().enumerate() {
        let field = |name: &str| format!("radar.sensors[{i}].{name}");
        let layout = &sensor.layout;
        if sensors[..i].iter().any(|other| other.layout.id == layout.id) {
            return Err(ConfigError::new(field("id"), "is used by another sensor"));
        }
        finite(&field("x_m"), layout.x_m)?;
        finite(&field("y_m"), layout.y_m)?;
        finite(&field("yaw_deg"), layout.yaw_rad)?;
        if !(layout.half_fov_rad > 0.0 && layout.half_fov_rad < 90f64.to_radians()) {
            return Err(ConfigError::new(field("half_fov_deg"), "must lie in (0, 90) degrees"));
        }
        positive(&field("max_range_m"), layout.max_range_m)?;
        finite(&field("azimuth_bias_deg"), sensor.azimuth_bias_deg)?;
        positive(&field("azimuth_noise_scale"), sensor.azimuth_noise_scale)?;
    }
    Ok(())
}

/// The motion limits of one class (`prefix` is its section) other than the speed limit, which
/// the class checks first.
fn validate_limits(prefix: &str, limits: &MotionLimits) -> Result<(), ConfigError> {
    let field = |name: &str| format!("{prefix}.{name}");
    positive(&field("max_acceleration_mps2"), limits.max_acceleration_mps2)?;
    positive(&field("max_deceleration_mps2"), limits.max_deceleration_mps2)?;
    positive(&field("max_jerk_mps3"), limits.max_jerk_mps3)?;
    positive(&field("max_yaw_rate_radps"), limits.max_yaw_rate_radps)?;
    positive(&field("max_yaw_acceleration_radps2"), limits.max_yaw_acceleration_radps2)?;
    if let Some(max) = limits.max_lateral_acceleration_mps2 {
        positive(&field("max_lateral_acceleration_mps2"), max)?;
    }
    positive(&field("stop_taper_s"), limits.stop_taper_s)
}

/// `car.driver.*`.
fn validate_driver(d: &DriverConfig) -> Result<(), ConfigError> {
    let field = |name: &str| format!("car.driver.{name}");
    non_negative(&field("lookahead_per_speed_s"), d.lookahead_per_speed_s)?;
    non_negative(&field("lookahead_base_m"), d.lookahead_base_m)?;
    positive(&field("min_lookahead_m"), d.min_lookahead_m)?;
    if !(d.max_lookahead_m >= d.min_lookahead_m) {
        return Err(ConfigError::new(
            field("max_lookahead_m"),
            "must not be below car.driver.min_lookahead_m",
        ));
    }
    positive(&field("curve_preview_m"), d.curve_preview_m)?;
    positive(&field("start_curve_preview_m"), d.start_curve_preview_m)?;
    positive(&field("interaction_range_m"), d.interaction_range_m)?;
    non_negative(&field("vehicle_lateral_margin_m"), d.vehicle_lateral_margin_m)?;
    non_negative(&field("pedestrian_lateral_margin_m"), d.pedestrian_lateral_margin_m)?;
    positive(&field("max_stop_deceleration_factor"), d.max_stop_deceleration_factor)?;
    non_negative(&field("always_stop_below_speed_mps"), d.always_stop_below_speed_mps)?;
    non_negative(&field("give_way_box_margin_m"), d.give_way_box_margin_m)?;
    non_negative(&field("give_way_stopped_speed_mps"), d.give_way_stopped_speed_mps)?;
    positive(&field("give_way_horizon_m"), d.give_way_horizon_m)?;
    non_negative(&field("give_way_overshoot_m"), d.give_way_overshoot_m)?;
    positive(&field("min_arrival_speed_mps"), d.min_arrival_speed_mps)?;
    positive(&field("lane_change_min_speed_mps"), d.lane_change_min_speed_mps)?;
    positive(&field("min_lane_change_length_m"), d.min_lane_change_length_m)?;
    if !(d.max_lane_change_length_m >= d.min_lane_change_length_m) {
        return Err(ConfigError::new(
            field("max_lane_change_length_m"),
            "must not be below car.driver.min_lane_change_length_m",
        ));
    }
    non_negative(&field("lane_change_start_m"), d.lane_change_start_m)?;
    non_negative(&field("lane_change_clearance_m"), d.lane_change_clearance_m)?;
    non_negative(&field("min_turn_entry_m"), d.min_turn_entry_m)
}

/// `pedestrian.walker.*`: the control and group constants, then the decisions.
fn validate_walker(w: &WalkerConfig) -> Result<(), ConfigError> {
    let field = |name: &str| format!("pedestrian.walker.{name}");
    non_negative(&field("waypoint_reach_m"), w.waypoint_reach_m)?;
    positive(&field("path_lookahead_m"), w.path_lookahead_m)?;
    positive(&field("max_lookahead_turn_rad"), w.max_lookahead_turn_rad)?;
    positive(&field("heading_gain_per_s"), w.heading_gain_per_s)?;
    positive(&field("speed_time_constant_s"), w.speed_time_constant_s)?;
    positive(&field("stop_deceleration_mps2"), w.stop_deceleration_mps2)?;
    non_negative(&field("stop_short_m"), w.stop_short_m)?;
    positive(&field("max_wander_sigmas"), w.max_wander_sigmas)?;
    positive(&field("wait_reach_m"), w.wait_reach_m)?;
    positive(&field("wait_speed_mps"), w.wait_speed_mps)?;
    non_negative(&field("passed_mark_m"), w.passed_mark_m)?;
    positive(&field("crosswalk_decision_m"), w.crosswalk_decision_m)?;
    non_negative(&field("crosswalk_green_fraction"), w.crosswalk_green_fraction)?;
    positive(&field("crosswalk_min_speed_mps"), w.crosswalk_min_speed_mps)?;
    non_negative(&field("group_position_gain_per_s"), w.group_position_gain_per_s)?;
    if !(w.group_max_speed_fraction > 0.0 && w.group_max_speed_fraction <= 1.0) {
        return Err(ConfigError::new(field("group_max_speed_fraction"), "must lie in (0, 1]"));
    }
    non_negative(&field("group_aim_ahead_m"), w.group_aim_ahead_m)?;
    non_negative(&field("group_standing_speed_mps"), w.group_standing_speed_mps)?;
    non_negative(&field("group_slot_tolerance_m"), w.group_slot_tolerance_m)?;
    validate_walker_decisions(w)
}

/// The random decisions of `pedestrian.walker.*`.
fn validate_walker_decisions(w: &WalkerConfig) -> Result<(), ConfigError> {
    let field = |name: &str| format!("pedestrian.walker.{name}");
    probability(&field("pace_change_probability"), w.pace_change_probability)?;
    probability(&field("kerb_wait_probability"), w.kerb_wait_probability)?;
    interval(&field("kerb_wait_s"), w.kerb_wait_s, true)?;
    non_negative(&field("crossing_spread_m"), w.crossing_spread_m)?;
    probability(&field("waypoint_jitter_fraction"), w.waypoint_jitter_fraction)?;
    non_negative(&field("corner_jitter_m"), w.corner_jitter_m)?;
    probability(&field("corner_turn_around_fraction"), w.corner_turn_around_fraction)
}

fn finite(field: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ConfigError::new(field, "must be a finite number"))
    }
}

fn positive(field: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(field, format!("must be a positive number (got {})", readable(value))))
    }
}

fn non_negative(field: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(field, format!("must be a non-negative number (got {})", readable(value))))
    }
}

fn probability(field: &str, value: f64) -> Result<(), ConfigError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(ConfigError::new(field, format!("must be a probability in [0, 1] (got {})", readable(value))))
    }
}

fn interval(field: &str, value: Interval, strictly_positive: bool) -> Result<(), ConfigError> {
    let [lo, hi] = value;
    if !(lo.is_finite() && hi.is_finite()) || lo > hi {
        return Err(ConfigError::new(
            field,
            format!(
                "must be an interval [min, max] with min <= max (got [{}, {}])",
                readable(lo),
                readable(hi)
            ),
        ));
    }
    if strictly_positive && lo <= 0.0 {
        return Err(ConfigError::new(
            field,
            format!("must be positive (got [{}, {}])", readable(lo), readable(hi)),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{ClutterConfig, ExtendedObjectConfig, Preset};

    #[test]
    fn point_cloud_validation_names_the_offending_field() {
        /// Makes one field of the valid point-cloud preset invalid.
        type Spoil = fn(&mut ScenarioConfig);
        let cases: [(&str, Spoil); 12] = [
            ("point_cloud.car_extra_detections_at_reference", |c| {
                c.point_cloud.car_extra_detections_at_reference = -1.0
            }),
            ("point_cloud.reference_range_m", |c| c.point_cloud.reference_range_m = 0.0),
            ("point_cloud.max_detections_per_car", |c| c.point_cloud.max_detections_per_car = 0),
            ("point_cloud.wheel_probability", |c| c.point_cloud.wheel_probability = f64::NAN),
            ("point_cloud.wheelbase_fraction", |c| c.point_cloud.wheelbase_fraction = 1.5),
            ("point_cloud.pedestrian_detection_count_probabilities", |c| {
                c.point_cloud.pedestrian_detection_count_probabilities = vec![0.5]
            }),
            // Inside the sidewalks, or beyond the middle of a block.
            ("point_cloud.wall_offset_m", |c| c.point_cloud.wall_offset_m = 9.0),
            ("point_cloud.wall_offset_m", |c| c.point_cloud.wall_offset_m = 50.0),
            ("point_cloud.ghost_probability", |c| c.point_cloud.ghost_probability = 2.0),
            ("point_cloud.max_ghost_detections", |c| c.point_cloud.max_ghost_detections = 65),
            ("point_cloud.class_flip_probability", |c| c.point_cloud.class_flip_probability = -0.1),
            ("point_cloud.enabled", |c| c.extended_objects = ExtendedObjectConfig::vehicles()),
        ];
        for (field, spoil) in cases {
            let mut config = Preset::PointCloud.config();
            spoil(&mut config);
            assert_eq!(config.validate().unwrap_err().field, field);
        }
    }

    #[test]
    fn extended_object_validation_names_the_offending_field() {
        /// Makes one field of a valid extended-object section invalid.
        type Spoil = fn(&mut ExtendedObjectConfig);
        let cases: [(&str, Spoil); 7] = [
            ("extended_objects.detection_count_probabilities", |e| e.detection_count_probabilities.clear()),
            ("extended_objects.detection_count_probabilities", |e| {
                e.detection_count_probabilities = vec![0.1; MAX_DETECTIONS_PER_OBJECT + 2]
            }),
            ("extended_objects.detection_count_probabilities", |e| {
                e.detection_count_probabilities = vec![0.5, 0.4]
            }),
            ("extended_objects.detection_count_probabilities[0]", |e| {
                e.detection_count_probabilities = vec![1.5, -0.5]
            }),
            ("extended_objects.corner_probability", |e| e.corner_probability = 1.5),
            ("extended_objects.contour_spread_m", |e| e.contour_spread_m = -0.1),
            ("extended_objects.contour_spread_m", |e| e.contour_spread_m = f64::NAN),
        ];
        for (field, spoil) in cases {
            let mut config = ScenarioConfig::extended(Preset::Default);
            spoil(&mut config.extended_objects);
            assert_eq!(config.validate().unwrap_err().field, field);
        }
        let parsed =
            ScenarioConfig::from_toml_str("[extended_objects]\nenabled = true\n").expect("a partial section");
        assert_eq!(parsed.extended_objects, ExtendedObjectConfig::vehicles());
        let error =
            ScenarioConfig::from_toml_str("[extended_objects]\ncorner_probability = 2.0\n").unwrap_err();
        assert!(error.to_string().contains("extended_objects.corner_probability"), "{error}");
    }

    #[test]
    fn clutter_validation_names_the_offending_field() {
        /// Makes one field of a valid clutter section invalid.
        type Spoil = fn(&mut ClutterConfig);
        let cases: [(&str, Spoil); 15] = [
            ("clutter.mean_false_detections_per_scan", |c| c.mean_false_detections_per_scan = -1.0),
            ("clutter.mean_false_detections_per_scan", |c| c.mean_false_detections_per_scan = 2000.0),
            ("clutter.mean_false_detections_per_scan", |c| c.mean_false_detections_per_scan = f64::NAN),
            ("clutter.min_range_m", |c| c.min_range_m = 0.0),
            ("clutter.min_range_m", |c| {
                c.min_range_m = 150.0;
                c.max_range_m = 200.0;
            }),
            ("clutter.max_range_m", |c| c.max_range_m = 0.5),
            ("clutter.car_fraction", |c| c.car_fraction = 1.2),
            ("clutter.car_rcs_mean_dbsm", |c| c.car_rcs_mean_dbsm = f64::INFINITY),
            ("clutter.car_rcs_std_db", |c| c.car_rcs_std_db = -1.0),
            ("clutter.pedestrian_rcs_std_db", |c| c.pedestrian_rcs_std_db = f64::NAN),
            ("clutter.moving_fraction", |c| c.moving_fraction = -0.1),
            ("clutter.moving_radial_velocity_max_mps", |c| c.moving_radial_velocity_max_mps = -3.0),
            ("clutter.ghost_probability", |c| c.ghost_probability = 2.0),
            ("clutter.ghost_extra_range_m", |c| c.ghost_extra_range_m = [5.0, 1.0]),
            ("clutter.ghost_rcs_drop_db", |c| c.ghost_rcs_drop_db = -6.0),
        ];
        for (field, spoil) in cases {
            let mut config = ScenarioConfig::clutter();
            spoil(&mut config.clutter);
            assert_eq!(config.validate().unwrap_err().field, field);
        }
        let error = ScenarioConfig::from_toml_str("[clutter]\nghost_probability = 1.5\n").unwrap_err();
        assert!(error.to_string().contains("clutter.ghost_probability"), "{error}");
        let parsed = ScenarioConfig::from_toml_str("[clutter]\nmean_false_detections_per_scan = 2.5\n")
            .expect("a partial clutter section");
        assert_eq!(parsed.clutter.mean_false_detections_per_scan, 2.5);
        assert_eq!(parsed.clutter.ghost_extra_range_m, ClutterConfig::default().ghost_extra_range_m);
    }

    #[test]
    fn limit_and_model_validation_names_the_offending_field() {
        /// Makes one field of a valid configuration invalid.
        type Spoil = fn(&mut ScenarioConfig);
        let cases: [(&str, Spoil); 8] = [
            ("car.max_jerk_mps3", |c| c.car.limits.max_jerk_mps3 = 0.0),
            ("car.max_lateral_acceleration_mps2", |c| {
                c.car.limits.max_lateral_acceleration_mps2 = Some(-1.0)
            }),
            ("pedestrian.stop_taper_s", |c| c.pedestrian.limits.stop_taper_s = f64::NAN),
            ("car.driver.max_lookahead_m", |c| c.car.driver.max_lookahead_m = 1.0),
            ("car.driver.max_lane_change_length_m", |c| c.car.driver.max_lane_change_length_m = 10.0),
            ("car.driver.interaction_range_m", |c| c.car.driver.interaction_range_m = 0.0),
            ("pedestrian.walker.group_max_speed_fraction", |c| {
                c.pedestrian.walker.group_max_speed_fraction = 1.5
            }),
            ("pedestrian.walker.kerb_wait_s", |c| c.pedestrian.walker.kerb_wait_s = [2.0, 1.0]),
        ];
        for (field, spoil) in cases {
            let mut config = ScenarioConfig::default();
            spoil(&mut config);
            assert_eq!(config.validate().unwrap_err().field, field);
        }
        let mut unlimited = ScenarioConfig::default();
        unlimited.car.limits.max_lateral_acceleration_mps2 = None;
        unlimited.validate().expect("cars without a lateral limit");
    }
}
