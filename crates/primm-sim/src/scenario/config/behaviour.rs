//! How objects move: the hard motion limits shared by the object classes, and the constants of
//! the driver model (cars and the ego vehicle) and of the walker model (pedestrians). Their
//! values are in `defaults`, their checks in `validation`.

use serde::{Deserialize, Deserializer, Serialize};

use super::Interval;

/// Hard physical limits of one class of objects. Every commanded motion passes through them
/// (see the kinematics of the traffic simulation): speed, longitudinal acceleration and
/// deceleration, jerk, yaw rate, yaw acceleration and, where set, lateral acceleration.
///
/// In a scenario file the fields are written in the class's own section (`[car]`,
/// `[pedestrian]`); fields left out keep that class's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionLimits {
    /// Hard speed limit, m/s.
    pub max_speed_mps: f64,
    /// Hard limit of longitudinal acceleration, m/s².
    pub max_acceleration_mps2: f64,
    /// Hard limit of longitudinal deceleration (positive number), m/s².
    pub max_deceleration_mps2: f64,
    /// Hard limit of the rate of change of longitudinal acceleration while moving, m/s³.
    pub max_jerk_mps3: f64,
    /// Hard limit of yaw rate, rad/s.
    pub max_yaw_rate_radps: f64,
    /// Hard limit of yaw acceleration (steering speed), rad/s².
    pub max_yaw_acceleration_radps2: f64,
    /// Hard limit of lateral acceleration `speed × yaw rate`, m/s²; absent: not limited.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_lateral_acceleration_mps2: Option<f64>,
    /// Time constant with which braking fades out when coming to a stop (braking is limited
    /// to `speed / stop_taper_s`, but never below 0.3 m/s²), seconds.
    pub stop_taper_s: f64,
}

/// The fields of [`MotionLimits`] as a scenario file gives them: any subset.
#[derive(Deserialize)]
struct MotionLimitsFields {
    max_speed_mps: Option<f64>,
    max_acceleration_mps2: Option<f64>,
    max_deceleration_mps2: Option<f64>,
    max_jerk_mps3: Option<f64>,
    max_yaw_rate_radps: Option<f64>,
    max_yaw_acceleration_radps2: Option<f64>,
    max_lateral_acceleration_mps2: Option<f64>,
    stop_taper_s: Option<f64>,
}

impl MotionLimitsFields {
    /// `base` with the fields given here replaced.
    fn over(self, base: MotionLimits) -> MotionLimits {
        MotionLimits {
            max_speed_mps: self.max_speed_mps.unwrap_or(base.max_speed_mps),
            max_acceleration_mps2: self.max_acceleration_mps2.unwrap_or(base.max_acceleration_mps2),
            max_deceleration_mps2: self.max_deceleration_mps2.unwrap_or(base.max_deceleration_mps2),
            max_jerk_mps3: self.max_jerk_mps3.unwrap_or(base.max_jerk_mps3),
            max_yaw_rate_radps: self.max_yaw_rate_radps.unwrap_or(base.max_yaw_rate_radps),
            max_yaw_acceleration_radps2: self
                .max_yaw_acceleration_radps2
                .unwrap_or(base.max_yaw_acceleration_radps2),
            max_lateral_acceleration_mps2: self
                .max_lateral_acceleration_mps2
                .or(base.max_lateral_acceleration_mps2),
            stop_taper_s: self.stop_taper_s.unwrap_or(base.stop_taper_s),
        }
    }
}

/// The motion limits written in `[car]`, over the cars' defaults.
pub(super) fn car_limits<'de, D: Deserializer<'de>>(deserializer: D) -> Result<MotionLimits, D::Error> {
    MotionLimitsFields::deserialize(deserializer).map(|fields| fields.over(MotionLimits::car()))
}

/// The motion limits written in `[pedestrian]`, over the pedestrians' defaults.
pub(super) fn pedestrian_limits<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<MotionLimits, D::Error> {
    MotionLimitsFields::deserialize(deserializer).map(|fields| fields.over(MotionLimits::pedestrian()))
}

/// Constants of the driver model of cars and the ego vehicle (`[car.driver]`): pure-pursuit
/// steering, the intelligent driver model's interactions, junction rules and route planning.
/// The defaults are the values the generator has always used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DriverConfig {
    /// Growth of the pure-pursuit look-ahead distance with speed, seconds: the look-ahead is
    /// `lookahead_per_speed_s · speed + lookahead_base_m`, clamped to
    /// [`min_lookahead_m`, `max_lookahead_m`].
    pub lookahead_per_speed_s: f64,
    /// See `lookahead_per_speed_s`, metres.
    pub lookahead_base_m: f64,
    /// Shortest pure-pursuit look-ahead distance, metres.
    pub min_lookahead_m: f64,
    /// Longest pure-pursuit look-ahead distance, metres.
    pub max_lookahead_m: f64,
    /// Drivers slow down for the curves of their route within this distance ahead, metres.
    pub curve_preview_m: f64,
    /// A new car's initial speed is capped so that it can brake comfortably for the curves
    /// within this distance ahead, metres.
    pub start_curve_preview_m: f64,
    /// Objects farther away than this are ignored by the car-following law, metres.
    pub interaction_range_m: f64,
    /// A vehicle ahead counts as in the path when its distance from the path is at most the
    /// two half widths plus this margin, metres.
    pub vehicle_lateral_margin_m: f64,
    /// The same margin for pedestrians ahead, metres.
    pub pedestrian_lateral_margin_m: f64,
    /// Drivers stop for a red signal or to give way only when stopping needs at most this
    /// many times `comfortable_deceleration_mps2` (dimensionless)…
    pub max_stop_deceleration_factor: f64,
    /// …or when they are slower than this, m/s.
    pub always_stop_below_speed_mps: f64,
    /// At a junction without signals, a vehicle within the junction area, that is within the
    /// road's half width plus this margin of the junction centre, has right of way, metres.
    pub give_way_box_margin_m: f64,
    /// A vehicle within the junction area slower than this blocks it, whatever its
    /// direction, m/s.
    pub give_way_stopped_speed_mps: f64,
    /// Crossing vehicles farther than this before their stop line are ignored at junctions
    /// without signals, metres…
    pub give_way_horizon_m: f64,
    /// …and so are those farther than this past it, metres.
    pub give_way_overshoot_m: f64,
    /// Speed floor of the arrival-time estimates at junctions without signals, m/s.
    pub min_arrival_speed_mps: f64,
    /// A lane change is `lane_change_duration_s` long at the cruise speed, but at least at
    /// this speed, m/s…
    pub lane_change_min_speed_mps: f64,
    /// …and its length is clamped to [`min_lane_change_length_m`, `max_lane_change_length_m`],
    /// metres.
    pub min_lane_change_length_m: f64,
    /// See `min_lane_change_length_m`, metres.
    pub max_lane_change_length_m: f64,
    /// A lane change starts this far ahead of where it is planned, metres.
    pub lane_change_start_m: f64,
    /// Straight road needed after a lane change before a turn starts, metres.
    pub lane_change_clearance_m: f64,
    /// A turn from the current lane is only taken when it starts at least this far ahead,
    /// metres.
    pub min_turn_entry_m: f64,
}

/// Constants of the walker model of pedestrians (`[pedestrian.walker]`): steering and speed
/// control, stopping, signalised crosswalks, walking in groups and the random decisions along
/// the way. The defaults are the values the generator has always used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WalkerConfig {
    /// A leg of the path counts as walked once its end is this close, metres.
    pub waypoint_reach_m: f64,
    /// Pedestrians steer towards the point of their path this far ahead, metres…
    pub path_lookahead_m: f64,
    /// …but not past a corner where the path turns by more than this, radians.
    pub max_lookahead_turn_rad: f64,
    /// Commanded yaw rate per radian of heading error, 1/s.
    pub heading_gain_per_s: f64,
    /// Time constant of the speed control, seconds.
    pub speed_time_constant_s: f64,
    /// Deceleration planned for stopping at a wait point, a crosswalk or the end of the
    /// path, m/s².
    pub stop_deceleration_mps2: f64,
    /// Pedestrians stop this far before a wait point or crosswalk, metres.
    pub stop_short_m: f64,
    /// The heading wander is bounded to this many `heading_wander_rad` (dimensionless).
    pub max_wander_sigmas: f64,
    /// A wait starts once the pedestrian is within this distance of its point, metres…
    pub wait_reach_m: f64,
    /// …and slower than this, m/s.
    pub wait_speed_mps: f64,
    /// A wait point or crosswalk this far behind counts as passed, metres.
    pub passed_mark_m: f64,
    /// Pedestrians decide whether to cross at a signal within this distance of the
    /// crosswalk, metres…
    pub crosswalk_decision_m: f64,
    /// …and cross when the remaining green time is at least this fraction of their crossing
    /// time (dimensionless)…
    pub crosswalk_green_fraction: f64,
    /// …with the crossing time taken at their speed, but at least this speed, m/s.
    pub crosswalk_min_speed_mps: f64,
    /// Rate at which a group member closes the gap to its place beside the leader along the
    /// walking direction, 1/s.
    pub group_position_gain_per_s: f64,
    /// A group member walks at most this fraction of `max_speed_mps` (dimensionless).
    pub group_max_speed_fraction: f64,
    /// A group member aims this far ahead of its place beside the leader, metres.
    pub group_aim_ahead_m: f64,
    /// A group member keeps its heading while its leader is slower than this, m/s…
    pub group_standing_speed_mps: f64,
    /// …and it is within this distance of its place, metres.
    pub group_slot_tolerance_m: f64,
    /// Probability that the walking speed is drawn anew for a leg.
    pub pace_change_probability: f64,
    /// Probability of a pause at the kerb before a crossing outside a crosswalk.
    pub kerb_wait_probability: f64,
    /// Duration of that pause, seconds.
    pub kerb_wait_s: Interval,
    /// A crossing outside a crosswalk ends within ± this distance along the road, metres.
    pub crossing_spread_m: f64,
    /// The end of a leg along a block lies within ± this fraction of the sidewalk's half
    /// width of its centre line (dimensionless).
    pub waypoint_jitter_fraction: f64,
    /// A walk to a corner ends within ± this distance of the corner in x and y, metres.
    pub corner_jitter_m: f64,
    /// Share of the pedestrians not crossing at a corner who turn around there; the others
    /// walk on round the corner (dimensionless).
    pub corner_turn_around_fraction: f64,
}

#[cfg(test)]
mod tests {
    use crate::scenario::{DriverConfig, MotionLimits, ScenarioConfig, ScenarioTomlError, WalkerConfig};

    #[test]
    fn a_class_section_that_names_some_limits_keeps_that_classes_other_limits() {
        let text = "[car]\nmax_speed_mps = 20.0\n[pedestrian]\nmax_speed_mps = 3.0\nstop_taper_s = 0.5\n";
        let config = ScenarioConfig::from_toml_str(text).expect("partial limits");
        assert_eq!(config.car.limits, MotionLimits { max_speed_mps: 20.0, ..MotionLimits::car() });
        assert_eq!(
            config.pedestrian.limits,
            MotionLimits { max_speed_mps: 3.0, stop_taper_s: 0.5, ..MotionLimits::pedestrian() }
        );
        assert_eq!(config.pedestrian.limits.max_lateral_acceleration_mps2, None);
        let limited = ScenarioConfig::from_toml_str("[pedestrian]\nmax_lateral_acceleration_mps2 = 4.0\n")
            .expect("a lateral limit for pedestrians");
        assert_eq!(limited.pedestrian.limits.max_lateral_acceleration_mps2, Some(4.0));
    }

    #[test]
    fn unknown_keys_are_still_rejected_next_to_the_limits_and_in_the_model_sections() {
        for text in
            ["[car]\nwheels = 4\n", "[pedestrian]\nmax_speed = 2.0\n", "[car.driver]\nlookahead_m = 3.0\n"]
        {
            let result = ScenarioConfig::from_toml_str(text);
            assert!(matches!(result, Err(ScenarioTomlError::Parse(_))), "{text}: {result:?}");
        }
    }

    #[test]
    fn the_driver_and_walker_sections_read_partially_over_their_defaults() {
        let text =
            "[car.driver]\ninteraction_range_m = 70.0\n[pedestrian.walker]\nkerb_wait_s = [1.0, 3.0]\n";
        let config = ScenarioConfig::from_toml_str(text).expect("partial model sections");
        assert_eq!(config.car.driver, DriverConfig { interaction_range_m: 70.0, ..DriverConfig::default() });
        assert_eq!(
            config.pedestrian.walker,
            WalkerConfig { kerb_wait_s: [1.0, 3.0], ..WalkerConfig::default() }
        );
        let text = toml::to_string(&config).expect("serialise");
        assert_eq!(ScenarioConfig::from_toml_str(&text).expect("parse"), config);
    }
}
