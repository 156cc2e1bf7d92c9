//! Scenario configuration: every parameter of the generator, with its unit in its name.
//!
//! [`ScenarioConfig::default`] is the reference configuration; [`Preset`] names it and its
//! variants: a harder configuration for robustness checks, an often-turning ego vehicle, and
//! both scenes with false detections (clutter). All structs deserialize from TOML/JSON with
//! missing fields taken from the default, and [`ScenarioConfig::validate`] checks the physical
//! and logical consistency of a configuration before it is used.

use primm_core::measurement::MAX_MEASUREMENTS_PER_FRAME;
use primm_core::readable_number::readable;
use serde::{Deserialize, Serialize};

/// A closed interval `[min, max]` from which a value is drawn uniformly.
pub type Interval = [f64; 2];

/// An invalid configuration value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid scenario configuration: `{field}` {problem}")]
pub struct ConfigError {
    /// Dotted path of the offending field, e.g. `car.max_speed_mps`.
    pub field: String,
    /// What is wrong with it.
    pub problem: String,
}

impl ConfigError {
    fn new(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Self { field: field.into(), problem: problem.into() }
    }
}

/// Why [`ScenarioConfig::from_toml_str`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScenarioTomlError {
    /// The text is not TOML, or does not describe a configuration (unknown field, wrong type).
    #[error(transparent)]
    Parse(#[from] toml::de::Error),
    /// The configuration parsed but is inconsistent.
    #[error(transparent)]
    Invalid(#[from] ConfigError),
}

/// Complete generator configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScenarioConfig {
    /// Sequence length and simulation stepping.
    pub sequence: SequenceConfig,
    /// Split sizes and seeds.
    pub splits: SplitConfig,
    /// Road grid, lanes, sidewalks and traffic signals.
    pub road: RoadConfig,
    /// Number of objects kept around the ego vehicle and where they appear.
    pub traffic: TrafficConfig,
    /// The ego vehicle.
    pub ego: EgoConfig,
    /// Cars (including large vehicles) and their driving behaviour.
    pub car: CarConfig,
    /// Pedestrians and their walking behaviour.
    pub pedestrian: PedestrianConfig,
    /// Radar sensors, scan timing and measurement noise.
    pub radar: RadarConfig,
    /// Reflection model of cars.
    pub car_reflection: ReflectionConfig,
    /// Reflection model of pedestrians.
    pub pedestrian_reflection: ReflectionConfig,
    /// False detections: clutter and multipath ghosts (off by default).
    pub clutter: ClutterConfig,
    /// Extended-object reflections of cars and two-wheelers: separate detections on the
    /// visible contour of the box instead of one averaged measurement (off by default).
    pub extended_objects: ExtendedObjectConfig,
}

/// Sequence length and simulation stepping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SequenceConfig {
    /// Recorded length of one sequence, seconds.
    pub duration_s: f64,
    /// Simulated time before recording starts, so that traffic settles (queues, signal
    /// phases), seconds.
    pub warmup_s: f64,
    /// Largest integration step of the traffic simulation, seconds.
    pub max_step_s: f64,
}

/// Split sizes and seeds. Sequence `i` of a split uses seed
/// `seed_base + split_offset + i` with split offsets `0`, `2^40` and `2 * 2^40` for train,
/// validation and evaluation, so the seed ranges of the splits are disjoint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SplitConfig {
    /// Base of all sequence seeds.
    pub seed_base: u64,
    /// Number of training sequences.
    pub train_sequences: u32,
    /// Number of validation sequences.
    pub validation_sequences: u32,
    /// Number of evaluation sequences.
    pub evaluation_sequences: u32,
}

/// Urban road grid: straight roads every `block_length_m` in both world axes, signalised
/// junctions at every crossing, sidewalks along both sides of every road. Right-hand traffic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoadConfig {
    /// Distance between the centre lines of parallel roads, metres.
    pub block_length_m: f64,
    /// Width of one lane, metres.
    pub lane_width_m: f64,
    /// Lanes per direction of travel.
    pub lanes_per_direction: u32,
    /// Distance from the road edge to the sidewalk centre line, metres.
    pub sidewalk_offset_m: f64,
    /// Width of the walkable sidewalk band around its centre line, metres.
    pub sidewalk_width_m: f64,
    /// Distance of the stop line before the junction area (the road edge of the crossing
    /// road), metres.
    pub stop_line_offset_m: f64,
    /// Radius of the path of a right turn, metres.
    pub right_turn_radius_m: f64,
    /// Radius of the path of a left turn, metres.
    pub left_turn_radius_m: f64,
    /// Fraction of junctions controlled by traffic signals; at the others vehicles give way
    /// to whoever reaches the junction first and pedestrians cross when they like.
    pub signalised_junction_fraction: f64,
    /// Green time of each signal phase, seconds.
    pub signal_green_s: f64,
    /// All-red clearance time between phases, seconds.
    pub signal_clearance_s: f64,
}

/// Object population around the ego vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrafficConfig {
    /// Number of cars kept within `population_radius_m` of the ego vehicle.
    pub car_count: u32,
    /// Number of pedestrians (group members included) kept within `population_radius_m`.
    pub pedestrian_count: u32,
    /// Probability that a new pedestrian walks with companions.
    pub pedestrian_group_probability: f64,
    /// Probability that a new pedestrian appears near a street corner (within
    /// `corner_spawn_distance_m` of it) rather than anywhere along a sidewalk.
    pub pedestrian_corner_spawn_probability: f64,
    /// See `pedestrian_corner_spawn_probability`, metres.
    pub corner_spawn_distance_m: f64,
    /// Largest pedestrian group, persons (at least 2).
    pub max_group_size: u32,
    /// Lateral spacing of group members, metres.
    pub group_spacing_m: Interval,
    /// Radius around the ego vehicle within which objects are spawned, metres.
    pub population_radius_m: f64,
    /// Objects farther than this from the ego vehicle are removed, metres.
    pub despawn_radius_m: f64,
    /// Objects never appear closer than this to the ego vehicle, metres.
    pub min_spawn_distance_m: f64,
    /// After the start, objects appear only outside every sensor's field of view widened by
    /// this angle, degrees…
    pub spawn_fov_margin_deg: f64,
    /// …or beyond the sensor's range plus this margin, metres.
    pub spawn_range_margin_m: f64,
}

/// The ego vehicle. It drives with the car behaviour and limits of [`CarConfig`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EgoConfig {
    /// Length of the ego vehicle, metres.
    pub length_m: f64,
    /// Width of the ego vehicle, metres.
    pub width_m: f64,
    /// Distance from the rear axle (car-frame origin) forward to the box centre, metres.
    pub rear_axle_to_centre_m: f64,
    /// Cruise speed range of the ego vehicle, m/s.
    pub desired_speed_mps: Interval,
    /// Probability that a sequence starts with the ego vehicle at standstill.
    pub initial_standstill_probability: f64,
    /// Distance from the ego vehicle to the centre of the junction ahead at the start of
    /// recording, had it driven the warm-up at its initial speed (the start position is chosen
    /// accordingly and kept within its block), metres.
    pub start_distance_to_junction_m: Interval,
    /// Probability that the ego vehicle turns left at a junction; absent: the cars'
    /// `car.turn_left_probability`.
    pub turn_left_probability: Option<f64>,
    /// Probability that the ego vehicle turns right at a junction; absent: the cars'
    /// `car.turn_right_probability`.
    pub turn_right_probability: Option<f64>,
}

/// Cars: sizes, physical limits and driving behaviour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CarConfig {
    /// Length of passenger cars, metres.
    pub length_m: Interval,
    /// Width of passenger cars, metres.
    pub width_m: Interval,
    /// Probability that a car is a large vehicle (van, SUV with trailer).
    pub large_vehicle_probability: f64,
    /// Length of large vehicles, metres.
    pub large_length_m: Interval,
    /// Width of large vehicles, metres.
    pub large_width_m: Interval,
    /// Cruise speed range, m/s; re-drawn every `speed_change_interval_s`.
    pub desired_speed_mps: Interval,
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
    /// Hard limit of lateral acceleration `speed × yaw rate`, m/s².
    pub max_lateral_acceleration_mps2: f64,
    /// Acceleration of the car-following model, m/s².
    pub comfortable_acceleration_mps2: f64,
    /// Deceleration of the car-following model, m/s².
    pub comfortable_deceleration_mps2: f64,
    /// Lateral acceleration drivers plan for in curves, m/s².
    pub curve_lateral_acceleration_mps2: f64,
    /// Desired time gap to the vehicle ahead, seconds.
    pub time_headway_s: f64,
    /// Gap to the vehicle ahead at standstill, metres.
    pub standstill_gap_m: f64,
    /// Time constant with which braking fades out when coming to a stop, seconds.
    pub stop_taper_s: f64,
    /// Probability of turning left at a junction.
    pub turn_left_probability: f64,
    /// Probability of turning right at a junction.
    pub turn_right_probability: f64,
    /// Probability of a lane change on a block where no turn requires one.
    pub lane_change_probability: f64,
    /// Duration of a lane change at cruise speed, seconds.
    pub lane_change_duration_s: f64,
    /// Time between re-draws of the cruise speed, seconds.
    pub speed_change_interval_s: Interval,
}

/// Pedestrians: sizes, physical limits and walking behaviour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PedestrianConfig {
    /// Depth of the body box (along the walking direction), metres.
    pub length_m: Interval,
    /// Width of the body box (shoulders), metres.
    pub width_m: Interval,
    /// Preferred walking speed, m/s.
    pub desired_speed_mps: Interval,
    /// Probability that a walking leg is run or hurried instead of walked.
    pub hurry_probability: f64,
    /// Speed of a hurried leg, m/s.
    pub hurry_speed_mps: Interval,
    /// Hard speed limit, m/s.
    pub max_speed_mps: f64,
    /// Hard limit of acceleration, m/s².
    pub max_acceleration_mps2: f64,
    /// Hard limit of deceleration (positive number), m/s².
    pub max_deceleration_mps2: f64,
    /// Hard limit of the rate of change of acceleration while moving, m/s³.
    pub max_jerk_mps3: f64,
    /// Hard limit of yaw rate, rad/s.
    pub max_yaw_rate_radps: f64,
    /// Hard limit of yaw acceleration, rad/s².
    pub max_yaw_acceleration_radps2: f64,
    /// Standard deviation of the random heading wander around the planned path, radians.
    pub heading_wander_rad: f64,
    /// Correlation time of the heading wander, seconds.
    pub heading_wander_time_s: f64,
    /// Length of a walking leg between decisions, metres.
    pub leg_length_m: Interval,
    /// Probability of stopping at a decision point.
    pub stop_probability: f64,
    /// Duration of a stop, seconds.
    pub stop_duration_s: Interval,
    /// Probability of turning around at a decision point.
    pub turn_around_probability: f64,
    /// Probability of crossing the road outside a crosswalk at a decision point mid-block.
    pub mid_block_crossing_probability: f64,
    /// Probability of crossing a road on the crosswalk at a corner (otherwise the pedestrian
    /// follows the sidewalk around the corner or turns around).
    pub crosswalk_probability: f64,
}

/// Mounting of one radar on the ego vehicle, in the car frame (origin at the rear axle).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RadarMount {
    /// Sensor id written to every frame of this sensor.
    pub id: u16,
    /// Longitudinal mounting position, metres.
    pub x_m: f64,
    /// Lateral mounting position (left positive), metres.
    pub y_m: f64,
    /// Boresight direction, degrees, counter-clockwise from the car's x axis.
    pub yaw_deg: f64,
    /// Half opening angle of the field of view, degrees.
    pub half_fov_deg: f64,
    /// Largest detection range, metres.
    pub max_range_m: f64,
    /// Residual azimuth misalignment of this sensor, degrees.
    pub azimuth_bias_deg: f64,
    /// Factor on the azimuth noise of this sensor.
    pub azimuth_noise_scale: f64,
}

/// Radar sensors, scan timing and point-level measurement noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RadarConfig {
    /// The sensors; every one scans once per `scan_period_s`.
    pub sensors: Vec<RadarMount>,
    /// Scan period of each sensor, seconds.
    pub scan_period_s: f64,
    /// Per-sequence random offset of each sensor's phase from the evenly staggered schedule
    /// (uniform in ±value), seconds.
    pub phase_jitter_s: f64,
    /// Per-scan random timing jitter (uniform in ±value), seconds.
    pub scan_jitter_s: f64,
    /// Standard deviation of the range noise of one reflection point, metres.
    pub range_noise_m: f64,
    /// Standard deviation of the azimuth noise of one point at boresight, degrees; grows with
    /// `1 / cos(azimuth)` off boresight.
    pub azimuth_noise_deg: f64,
    /// Standard deviation of the Doppler noise of one point, m/s.
    pub doppler_noise_mps: f64,
    /// Standard deviation of the ego-motion compensation error shared by all points of a scan,
    /// m/s.
    pub scan_doppler_bias_mps: f64,
    /// Probability that an otherwise detectable object yields no measurement in a scan.
    pub miss_probability: f64,
    /// Probability that a reflection point hidden behind another object is still detected
    /// (propagation under or through vehicles).
    pub occluded_point_probability: f64,
    /// Fraction of a class's detection range beyond which point detection probability fades
    /// linearly to zero.
    pub fade_start_fraction: f64,
}

/// Reflection model of one object class.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReflectionConfig {
    /// Mean number of reflection points at `reference_range_m`.
    pub mean_points_at_reference: f64,
    /// Range at which `mean_points_at_reference` applies; the mean scales with
    /// `reference / range`, metres.
    pub reference_range_m: f64,
    /// Largest number of reflection points per object and scan.
    pub max_points: u32,
    /// Probability that a point sits on a corner of the outline (strong corner reflectors).
    pub corner_probability: f64,
    /// Probability that a point comes from inside the outline (wheel houses, underbody, the
    /// far side seen under the vehicle) instead of from the visible outline.
    pub interior_probability: f64,
    /// Mean RCS of one point seen head-on or from behind, dBsm.
    pub rcs_front_dbsm: f64,
    /// Mean RCS of one point seen from the side, dBsm.
    pub rcs_side_dbsm: f64,
    /// Standard deviation of the RCS fluctuation of one point, dB.
    pub rcs_fluctuation_db: f64,
    /// Range beyond which the class is never detected, metres.
    pub detection_range_m: f64,
    /// Standard deviation of the extra Doppler spread of a point caused by moving limbs or
    /// wheels, as a fraction of the object's speed.
    pub micro_doppler_fraction: f64,
}

/// False detections added to the object list of every scan: clutter spread over the scanning
/// sensor's field of view (guard rails, poles, kerbs, edges of parked cars that survive
/// clustering and classification) and multipath ghosts behind real objects. False detections
/// carry no ground-truth id and no true position. The default adds none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClutterConfig {
    /// Mean of the Poisson-distributed number of clutter detections per scan of one sensor
    /// (0: no clutter), at most `MAX_MEASUREMENTS_PER_FRAME`.
    pub mean_false_detections_per_scan: f64,
    /// Clutter is spread uniformly over the area of the field-of-view sector between this
    /// range and `max_range_m`, metres.
    pub min_range_m: f64,
    /// Farthest clutter range; the scanning sensor's `max_range_m` when that is smaller,
    /// metres.
    pub max_range_m: f64,
    /// Share of clutter detections labelled `car`; the rest are labelled `pedestrian`.
    pub car_fraction: f64,
    /// Mean RCS of a clutter detection labelled `car`, dBsm.
    pub car_rcs_mean_dbsm: f64,
    /// Standard deviation of the RCS of a clutter detection labelled `car`, dB.
    pub car_rcs_std_db: f64,
    /// Mean RCS of a clutter detection labelled `pedestrian`, dBsm.
    pub pedestrian_rcs_mean_dbsm: f64,
    /// Standard deviation of the RCS of a clutter detection labelled `pedestrian`, dB.
    pub pedestrian_rcs_std_db: f64,
    /// Share of clutter detections that look moving: their radial velocity is drawn uniformly
    /// in ±`moving_radial_velocity_max_mps`. The others are static: radial velocity zero plus
    /// the sensor's Doppler noise and the scan's ego-motion compensation error.
    pub moving_fraction: f64,
    /// See `moving_fraction`, m/s.
    pub moving_radial_velocity_max_mps: f64,
    /// Probability that a real object measurement of a scan is accompanied by a multipath
    /// ghost: same azimuth, farther away, same class, similar radial velocity, weaker.
    pub ghost_probability: f64,
    /// How much farther from the sensor a ghost lies than the object measurement, metres.
    pub ghost_extra_range_m: Interval,
    /// How much weaker a ghost's RCS is than the object measurement's, dB.
    pub ghost_rcs_drop_db: f64,
}

/// Extended-object reflections of vehicles (cars, large vehicles and two-wheelers; pedestrians
/// keep the averaged point model of [`ReflectionConfig`]).
///
/// When enabled, a vehicle in view yields one or more separate detections per scan instead of
/// the mean of its reflection points. Each detection is one reflection centre on the visible
/// contour of the vehicle's box (the faces turned towards the sensor, oriented along the
/// vehicle's heading): with `corner_probability` a visible corner, chosen uniformly; otherwise
/// a point at arc length `s_near + contour_spread_m · N(0, 1)` along the visible contour,
/// where `s_near` is the point of the contour nearest to the sensor, clamped to the contour's
/// ends. The number of detections of a scan is drawn from `detection_count_probabilities`. The
/// range, azimuth and Doppler noise, misalignment, occlusion, range fading, random misses,
/// RCS and micro-Doppler are those of the point model (`radar` and `car_reflection`); every
/// draw comes from a random stream of its own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExtendedObjectConfig {
    /// Whether vehicles are measured as extended objects.
    pub enabled: bool,
    /// Probability that a vehicle in view yields 1, 2, 3, … detections in one scan (before
    /// occlusion, fading and random misses); entry `k` is the probability of `k + 1`
    /// detections. The entries must sum to 1; at most [`MAX_DETECTIONS_PER_OBJECT`] entries.
    pub detection_count_probabilities: Vec<f64>,
    /// Probability that a detection sits on a visible corner of the box (strong corner
    /// reflectors: bumper corners, wheel arches seen at an angle).
    pub corner_probability: f64,
    /// Standard deviation of a detection's position along the visible contour around the
    /// contour point nearest to the sensor, metres.
    pub contour_spread_m: f64,
}

/// Largest number of detections one vehicle may yield in one scan.
pub const MAX_DETECTIONS_PER_OBJECT: usize = 8;

// ------------------------------------------------------------------------------------------------
// Defaults

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
            max_speed_mps: 16.7,
            max_acceleration_mps2: 3.0,
            max_deceleration_mps2: 7.0,
            max_jerk_mps3: 6.0,
            max_yaw_rate_radps: 0.7,
            max_yaw_acceleration_radps2: 1.2,
            max_lateral_acceleration_mps2: 3.5,
            comfortable_acceleration_mps2: 1.6,
            comfortable_deceleration_mps2: 2.5,
            curve_lateral_acceleration_mps2: 2.5,
            time_headway_s: 1.3,
            standstill_gap_m: 2.0,
            stop_taper_s: 0.8,
            turn_left_probability: 0.2,
            turn_right_probability: 0.25,
            lane_change_probability: 0.35,
            lane_change_duration_s: 4.0,
            speed_change_interval_s: [4.0, 12.0],
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
            max_speed_mps: 2.5,
            max_acceleration_mps2: 1.5,
            max_deceleration_mps2: 2.0,
            max_jerk_mps3: 6.0,
            max_yaw_rate_radps: 2.5,
            max_yaw_acceleration_radps2: 8.0,
            heading_wander_rad: 0.08,
            heading_wander_time_s: 2.0,
            leg_length_m: [6.0, 30.0],
            stop_probability: 0.15,
            stop_duration_s: [1.0, 6.0],
            turn_around_probability: 0.12,
            mid_block_crossing_probability: 0.12,
            crosswalk_probability: 0.65,
        }
    }
}

impl RadarMount {
    /// The four-sensor layout used by default, modelled on RadarScenes: two front sensors
    /// turned 25° outwards and two side sensors turned 85° outwards, all on the front bumper.
    pub fn default_layout() -> Vec<RadarMount> {
        let mount = |id, x_m, y_m, yaw_deg, azimuth_bias_deg, azimuth_noise_scale| RadarMount {
            id,
            x_m,
            y_m,
            yaw_deg,
            half_fov_deg: 60.0,
            max_range_m: 100.0,
            azimuth_bias_deg,
            azimuth_noise_scale,
        };
        vec![
            mount(1, 3.66, -0.87, -85.0, 0.25, 1.2),
            mount(2, 3.86, -0.70, -25.0, -0.1, 1.0),
            mount(3, 3.86, 0.70, 25.0, 0.15, 0.9),
            mount(4, 3.66, 0.87, 85.0, -0.3, 1.3),
        ]
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
        }
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

// ------------------------------------------------------------------------------------------------
// Presets

/// Named configurations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// The reference configuration ([`ScenarioConfig::default`]).
    Default,
    /// A harder configuration for robustness checks: faster and more aggressive cars, more
    /// erratic and faster pedestrians, denser traffic, noisier sensors with more misses, and
    /// more false detections than [`Preset::Clutter`].
    Robustness,
    /// The default scene seen from an ego vehicle that turns at most junctions of a denser
    /// road grid, at town speeds: ego yaw rates up to about 0.5 rad/s.
    Turning,
    /// The default scene with false detections ([`ClutterConfig::urban`]): about 1.5 per scan,
    /// mostly static, some moving-looking, a few multipath ghosts.
    Clutter,
    /// The [`Preset::Turning`] scene with the false detections of [`Preset::Clutter`].
    ClutterTurning,
    /// The default scene with vehicles measured as extended objects
    /// ([`ExtendedObjectConfig::vehicles`]): detections from the visible contour and corners of
    /// each vehicle's box, now and then several per vehicle and scan.
    Extended,
    /// The [`Preset::Turning`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedTurning,
    /// The [`Preset::Clutter`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedClutter,
    /// The [`Preset::ClutterTurning`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedClutterTurning,
}

impl Preset {
    /// All presets.
    pub const ALL: [Preset; 9] = [
        Preset::Default,
        Preset::Robustness,
        Preset::Turning,
        Preset::Clutter,
        Preset::ClutterTurning,
        Preset::Extended,
        Preset::ExtendedTurning,
        Preset::ExtendedClutter,
        Preset::ExtendedClutterTurning,
    ];

    /// The preset's name (`default`, `robustness`, `turning`, `clutter`, `clutter_turning`,
    /// `extended`, `extended_turning`, `extended_clutter`, `extended_clutter_turning`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Default => "default",
            Preset::Robustness => "robustness",
            Preset::Turning => "turning",
            Preset::Clutter => "clutter",
            Preset::ClutterTurning => "clutter_turning",
            Preset::Extended => "extended",
            Preset::ExtendedTurning => "extended_turning",
            Preset::ExtendedClutter => "extended_clutter",
            Preset::ExtendedClutterTurning => "extended_clutter_turning",
        }
    }

    /// The preset called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The configuration of this preset.
    pub fn config(self) -> ScenarioConfig {
        match self {
            Preset::Default => ScenarioConfig::default(),
            Preset::Robustness => ScenarioConfig::robustness(),
            Preset::Turning => ScenarioConfig::turning(),
            Preset::Clutter => ScenarioConfig::clutter(),
            Preset::ClutterTurning => ScenarioConfig::clutter_turning(),
            Preset::Extended => ScenarioConfig::extended(Preset::Default),
            Preset::ExtendedTurning => ScenarioConfig::extended(Preset::Turning),
            Preset::ExtendedClutter => ScenarioConfig::extended(Preset::Clutter),
            Preset::ExtendedClutterTurning => ScenarioConfig::extended(Preset::ClutterTurning),
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| {
            let names: Vec<String> = Self::ALL.iter().map(|p| format!("`{}`", p.name())).collect();
            format!("unknown preset `{s}` (expected one of {})", names.join(", "))
        })
    }
}

impl ScenarioConfig {
    /// The ego-turning preset: see [`Preset::Turning`].
    pub fn turning() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x5455_524e_494e;
        config.road.block_length_m = 90.0;
        config.ego.desired_speed_mps = [6.0, 10.0];
        config.ego.start_distance_to_junction_m = [15.0, 40.0];
        config.ego.turn_left_probability = Some(0.45);
        config.ego.turn_right_probability = Some(0.45);
        config
    }

    /// The clutter preset: see [`Preset::Clutter`].
    pub fn clutter() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x434c_5554_5452;
        config.clutter = ClutterConfig::urban();
        config
    }

    /// The ego-turning clutter preset: see [`Preset::ClutterTurning`].
    pub fn clutter_turning() -> Self {
        let mut config = Self::turning();
        config.splits.seed_base = 0x434c_5455_524e;
        config.clutter = ClutterConfig::urban();
        config
    }

    /// The `base` preset's scene with vehicles measured as extended objects
    /// ([`ExtendedObjectConfig::vehicles`]) and a seed base of its own (see
    /// [`Preset::Extended`]). With the same seed, traffic, scan timing and the ego vehicle are
    /// those of `base`; the clutter presets' false detections come from their own stream too.
    pub fn extended(base: Preset) -> Self {
        let mut config = base.config();
        // A seed base per extended preset: "EXT" and the base preset's own seed base.
        config.splits.seed_base = config.splits.seed_base.wrapping_add(0x4558_5400_0000_0000);
        config.extended_objects = ExtendedObjectConfig::vehicles();
        config
    }

    /// The robustness preset: see [`Preset::Robustness`].
    pub fn robustness() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x524f_4255_5354;
        config.road.block_length_m = 90.0;
        config.road.signal_green_s = 12.0;
        config.traffic.car_count = 20;
        config.traffic.pedestrian_count = 24;
        config.traffic.pedestrian_group_probability = 0.4;
        config.ego.desired_speed_mps = [10.0, 16.0];
        let car = &mut config.car;
        car.desired_speed_mps = [11.0, 19.5];
        car.max_speed_mps = 22.0;
        car.max_acceleration_mps2 = 3.5;
        car.max_deceleration_mps2 = 8.0;
        car.max_jerk_mps3 = 9.0;
        car.max_yaw_rate_radps = 0.8;
        car.max_yaw_acceleration_radps2 = 1.6;
        car.max_lateral_acceleration_mps2 = 4.5;
        car.comfortable_acceleration_mps2 = 2.4;
        car.comfortable_deceleration_mps2 = 3.5;
        car.curve_lateral_acceleration_mps2 = 3.5;
        car.time_headway_s = 0.9;
        car.turn_left_probability = 0.25;
        car.turn_right_probability = 0.3;
        car.lane_change_probability = 0.7;
        car.lane_change_duration_s = 2.5;
        car.speed_change_interval_s = [2.0, 6.0];
        let ped = &mut config.pedestrian;
        ped.desired_speed_mps = [1.0, 2.0];
        ped.hurry_probability = 0.25;
        ped.hurry_speed_mps = [2.2, 3.4];
        ped.max_speed_mps = 3.5;
        ped.max_acceleration_mps2 = 2.5;
        ped.max_deceleration_mps2 = 3.0;
        ped.max_jerk_mps3 = 10.0;
        ped.max_yaw_rate_radps = 3.5;
        ped.max_yaw_acceleration_radps2 = 12.0;
        ped.heading_wander_rad = 0.25;
        ped.heading_wander_time_s = 1.0;
        ped.leg_length_m = [3.0, 15.0];
        ped.stop_probability = 0.25;
        ped.stop_duration_s = [0.5, 4.0];
        ped.turn_around_probability = 0.25;
        ped.mid_block_crossing_probability = 0.3;
        let radar = &mut config.radar;
        radar.phase_jitter_s = 0.003;
        radar.scan_jitter_s = 0.004;
        radar.range_noise_m = 0.25;
        radar.azimuth_noise_deg = 1.2;
        radar.doppler_noise_mps = 0.2;
        radar.scan_doppler_bias_mps = 0.08;
        radar.miss_probability = 0.08;
        radar.occluded_point_probability = 0.1;
        for sensor in &mut radar.sensors {
            sensor.azimuth_bias_deg *= 2.0;
        }
        config.car_reflection.rcs_fluctuation_db = 6.0;
        config.pedestrian_reflection.rcs_fluctuation_db = 5.0;
        config.pedestrian_reflection.micro_doppler_fraction = 0.5;
        config.clutter = ClutterConfig {
            mean_false_detections_per_scan: 2.0,
            moving_fraction: 0.2,
            ghost_probability: 0.05,
            ..ClutterConfig::urban()
        };
        config
    }

    /// Parses a configuration from TOML; missing fields take their default values. The result
    /// is validated.
    pub fn from_toml_str(text: &str) -> Result<Self, ScenarioTomlError> {
        let config: Self = toml::from_str(text)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks every value; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_sequence()?;
        self.validate_road()?;
        self.validate_traffic()?;
        self.validate_car()?;
        self.validate_turn_radii()?;
        self.validate_ego()?;
        self.validate_pedestrian()?;
        self.validate_radar()?;
        self.validate_reflections()?;
        self.validate_clutter()?;
        self.validate_extended_objects()
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
        positive("car.max_speed_mps", c.max_speed_mps)?;
        if c.desired_speed_mps[1] > c.max_speed_mps {
            return Err(ConfigError::new("car.desired_speed_mps", "must not exceed car.max_speed_mps"));
        }
        positive("car.max_acceleration_mps2", c.max_acceleration_mps2)?;
        positive("car.max_deceleration_mps2", c.max_deceleration_mps2)?;
        positive("car.max_jerk_mps3", c.max_jerk_mps3)?;
        positive("car.max_yaw_rate_radps", c.max_yaw_rate_radps)?;
        positive("car.max_yaw_acceleration_radps2", c.max_yaw_acceleration_radps2)?;
        positive("car.max_lateral_acceleration_mps2", c.max_lateral_acceleration_mps2)?;
        positive("car.comfortable_acceleration_mps2", c.comfortable_acceleration_mps2)?;
        positive("car.comfortable_deceleration_mps2", c.comfortable_deceleration_mps2)?;
        if c.comfortable_acceleration_mps2 > c.max_acceleration_mps2 {
            return Err(ConfigError::new(
                "car.comfortable_acceleration_mps2",
                "must not exceed car.max_acceleration_mps2",
            ));
        }
        if c.comfortable_deceleration_mps2 > c.max_deceleration_mps2 {
            return Err(ConfigError::new(
                "car.comfortable_deceleration_mps2",
                "must not exceed car.max_deceleration_mps2",
            ));
        }
        positive("car.curve_lateral_acceleration_mps2", c.curve_lateral_acceleration_mps2)?;
        if c.curve_lateral_acceleration_mps2 > c.max_lateral_acceleration_mps2 {
            return Err(ConfigError::new(
                "car.curve_lateral_acceleration_mps2",
                "must not exceed car.max_lateral_acceleration_mps2",
            ));
        }
        positive("car.time_headway_s", c.time_headway_s)?;
        positive("car.standstill_gap_m", c.standstill_gap_m)?;
        positive("car.stop_taper_s", c.stop_taper_s)?;
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
            if v / r > c.max_yaw_rate_radps {
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
        if e.desired_speed_mps[1] > self.car.max_speed_mps {
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
        positive("pedestrian.max_speed_mps", p.max_speed_mps)?;
        if p.desired_speed_mps[1] > p.max_speed_mps || p.hurry_speed_mps[1] > p.max_speed_mps {
            return Err(ConfigError::new(
                "pedestrian.max_speed_mps",
                "must not be below the desired or hurry speeds",
            ));
        }
        positive("pedestrian.max_acceleration_mps2", p.max_acceleration_mps2)?;
        positive("pedestrian.max_deceleration_mps2", p.max_deceleration_mps2)?;
        positive("pedestrian.max_jerk_mps3", p.max_jerk_mps3)?;
        positive("pedestrian.max_yaw_rate_radps", p.max_yaw_rate_radps)?;
        positive("pedestrian.max_yaw_acceleration_radps2", p.max_yaw_acceleration_radps2)?;
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
        if let Some((i, sensor)) =
            self.radar.sensors.iter().enumerate().find(|(_, sensor)| sensor.max_range_m <= c.min_range_m)
        {
            return Err(ConfigError::new(
                "clutter.min_range_m",
                format!(
                    "must be below every sensor's range (radar.sensors[{i}].max_range_m is {} m)",
                    readable(sensor.max_range_m)
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
        let counts = &e.detection_count_probabilities;
        if counts.is_empty() || counts.len() > MAX_DETECTIONS_PER_OBJECT {
            return Err(ConfigError::new(
                "extended_objects.detection_count_probabilities",
                format!("must list between 1 and {MAX_DETECTIONS_PER_OBJECT} probabilities"),
            ));
        }
        for (k, &p) in counts.iter().enumerate() {
            probability(&format!("extended_objects.detection_count_probabilities[{k}]"), p)?;
        }
        let total: f64 = counts.iter().sum();
        if (total - 1.0).abs() > 1e-9 {
            return Err(ConfigError::new(
                "extended_objects.detection_count_probabilities",
                format!("must sum to 1 (got {})", readable(total)),
            ));
        }
        probability("extended_objects.corner_probability", e.corner_probability)?;
        non_negative("extended_objects.contour_spread_m", e.contour_spread_m)?;
        Ok(())
    }

    /// Width of one side of the carriageway (all lanes of one direction), metres.
    pub fn half_road_width_m(&self) -> f64 {
        self.road.lane_width_m * f64::from(self.road.lanes_per_direction)
    }
}

/// `radar.sensors`: at least one, unique ids, finite mounts, fields of view within (0, 90)°.
fn validate_sensors(sensors: &[RadarMount]) -> Result<(), ConfigError> {
    if sensors.is_empty() {
        return Err(ConfigError::new("radar.sensors", "must list at least one sensor"));
    }
    for (i, sensor) in sensors.iter().enumerate() {
        let field = |name: &str| format!("radar.sensors[{i}].{name}");
        if sensors[..i].iter().any(|other| other.id == sensor.id) {
            return Err(ConfigError::new(field("id"), "is used by another sensor"));
        }
        finite(&field("x_m"), sensor.x_m)?;
        finite(&field("y_m"), sensor.y_m)?;
        finite(&field("yaw_deg"), sensor.yaw_deg)?;
        if !(sensor.half_fov_deg > 0.0 && sensor.half_fov_deg < 90.0) {
            return Err(ConfigError::new(field("half_fov_deg"), "must lie in (0, 90) degrees"));
        }
        positive(&field("max_range_m"), sensor.max_range_m)?;
        finite(&field("azimuth_bias_deg"), sensor.azimuth_bias_deg)?;
        positive(&field("azimuth_noise_scale"), sensor.azimuth_noise_scale)?;
    }
    Ok(())
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

    #[test]
    fn every_preset_is_valid_and_found_by_its_name() {
        for preset in Preset::ALL {
            preset.config().validate().unwrap_or_else(|error| panic!("{preset}: {error}"));
            assert_eq!(Preset::from_name(preset.name()), Some(preset));
            assert_eq!(preset.name().parse::<Preset>(), Ok(preset));
        }
        let error = "clutter-free".parse::<Preset>().unwrap_err();
        for preset in Preset::ALL {
            assert!(error.contains(&format!("`{}`", preset.name())), "{error}");
        }
    }

    #[test]
    fn every_preset_has_its_own_seed_base() {
        for (i, a) in Preset::ALL.into_iter().enumerate() {
            for b in &Preset::ALL[..i] {
                assert_ne!(a.config().splits.seed_base, b.config().splits.seed_base, "{a} and {b}");
            }
        }
    }

    #[test]
    fn only_the_clutter_and_robustness_presets_add_false_detections() {
        for preset in Preset::ALL {
            let clutter = preset.config().clutter;
            let expected = matches!(
                preset,
                Preset::Clutter
                    | Preset::ClutterTurning
                    | Preset::Robustness
                    | Preset::ExtendedClutter
                    | Preset::ExtendedClutterTurning
            );
            assert_eq!(clutter.is_enabled(), expected, "{preset}");
        }
        assert_eq!(ScenarioConfig::default().clutter, ClutterConfig::default());
        let robust = Preset::Robustness.config().clutter.mean_false_detections_per_scan;
        assert!(robust > Preset::Clutter.config().clutter.mean_false_detections_per_scan);
    }

    #[test]
    fn the_extended_presets_are_their_base_presets_with_extended_vehicles() {
        let pairs = [
            (Preset::Extended, Preset::Default),
            (Preset::ExtendedTurning, Preset::Turning),
            (Preset::ExtendedClutter, Preset::Clutter),
            (Preset::ExtendedClutterTurning, Preset::ClutterTurning),
        ];
        for preset in Preset::ALL {
            let extended = pairs.iter().any(|(p, _)| *p == preset);
            assert_eq!(preset.config().extended_objects.enabled, extended, "{preset}");
        }
        for (extended, base) in pairs {
            let mut config = extended.config();
            assert_eq!(config.extended_objects, ExtendedObjectConfig::vehicles());
            assert_ne!(config.splits.seed_base, base.config().splits.seed_base);
            config.extended_objects = ExtendedObjectConfig::default();
            config.splits.seed_base = base.config().splits.seed_base;
            assert_eq!(config, base.config(), "{extended} against {base}");
        }
        assert!((ExtendedObjectConfig::vehicles().mean_detection_count() - 1.25).abs() < 1e-12);
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
            ("clutter.mean_false_detections_per_scan", |c| c.mean_false_detections_per_scan = 1000.0),
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
}
