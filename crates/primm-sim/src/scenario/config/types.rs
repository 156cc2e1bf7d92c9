//! The sections of the scenario configuration: what they hold and in which units. Their
//! values are in `defaults`, their checks in `validation`.

use serde::{Deserialize, Serialize};

use super::behaviour::{DriverConfig, MotionLimits, WalkerConfig};
use super::mount::RadarMount;
use super::Interval;

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
    /// Where the ego vehicle is: `"driving"` (the default: it drives the road grid) or
    /// `"roadside"` (a static sensor platform that never moves).
    pub placement: EgoPlacement,
}

/// Where the ego vehicle (the platform that carries the radars) is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EgoPlacement {
    /// It drives the road grid like a car, with the speeds and turn probabilities of `ego.*`.
    #[default]
    Driving,
    /// It stands still for the whole sequence beside a junction, outside the road and the
    /// sidewalk at the outer corner of a block (a corner chosen per sequence), its x axis
    /// pointing diagonally across the junction: a roadside sensor that sees two of the
    /// junction's arms. It takes no part in traffic; `ego.desired_speed_mps` and the turn
    /// probabilities are not used.
    Roadside,
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
    /// Hard limits of the motion of cars and of the ego vehicle. Written as fields of `[car]`
    /// itself (`max_speed_mps`, …, `stop_taper_s`); fields left out keep the cars' defaults.
    #[serde(flatten, deserialize_with = "super::behaviour::car_limits")]
    pub limits: MotionLimits,
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
    /// Constants of the steering, car-following, junction and route-planning laws
    /// (`[car.driver]`).
    pub driver: DriverConfig,
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
    /// Hard limits of the motion of pedestrians. Written as fields of `[pedestrian]` itself
    /// (`max_speed_mps`, …); fields left out keep the pedestrians' defaults (no lateral
    /// acceleration limit).
    #[serde(flatten, deserialize_with = "super::behaviour::pedestrian_limits")]
    pub limits: MotionLimits,
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
    /// Constants of the walking control, the group model and the walking decisions
    /// (`[pedestrian.walker]`).
    pub walker: WalkerConfig,
}

/// Radar sensors, scan timing and point-level measurement noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RadarConfig {
    /// The sensors; every one scans once per `scan_period_s`. Written in a file, the list
    /// replaces the whole default layout.
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
    /// What a sensor reports per detected object: `"echo"` (the default: the average of its
    /// detected reflection points, or the reflection centres of the extended-object model) or
    /// `"centre"` (an object-list radar: the object's true centre with one point's range,
    /// azimuth and Doppler noise).
    pub report: RadarReport,
}

/// What a radar reports for an object it detects.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RadarReport {
    /// The averaged echo of its visible outline (or, for vehicles measured as extended
    /// objects, each reflection centre).
    #[default]
    Echo,
    /// Its true centre, measured with the noise of one reflection point: the object list of a
    /// radar that clusters and tracks internally. Whether the object is detected at all
    /// (field of view, range, occlusion, fading, misses) is decided as for `"echo"`.
    Centre,
}

/// What the generator writes of each frame besides the measurements.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputConfig {
    /// Whether frames carry the ego pose (`ego_x`, `ego_y`, `ego_yaw`).
    pub ego_pose: bool,
    /// Whether frames and measurements carry the id of the sensor that scanned.
    pub sensor_id: bool,
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
    /// How a visible face's share of the points grows with its extent along the line of
    /// sight, dimensionless, ≥ 0: a face's weight is its length times the cosine between its
    /// outward normal and the line of sight (its apparent width: resolution cells across the
    /// beam) plus this times the cosine between the face itself and the line of sight (its
    /// depth in range: resolution cells along the beam). A radar's range cells are finer than
    /// its azimuth cells at all but short range (0.15–0.5 m against 1–2 m at 20 m for 2–6°),
    /// so such a radar sees the near side of a car ahead of it and aside as an L, its side
    /// face full of points; 0 weighs the apparent width alone.
    pub range_extent_weight: f64,
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

/// Detection-level radar output: what a radar gives before any clustering, several
/// detections per object and scan (the model of the `point_cloud` preset).
///
/// When enabled, every object in view yields its own detections instead of one measurement:
///
/// * a car `1 + Poisson(car_extra_detections_at_reference · clamp(reference_range_m / range,
///   0.5, 1.5))` detections (at most `max_detections_per_car`), each a point of its own on the
///   faces of the box turned towards the sensor, chosen in proportion to their apparent width
///   (a corner with the car reflection's `corner_probability`), or, with `wheel_probability`,
///   a point on one of the wheels on the side turned towards the sensor;
/// * a wheel point's velocity along the car's heading is the body's times `1 − u·cos φ`
///   (`u`, `φ` uniform: a point on a spoke or the rim of a rolling wheel), between 0 and twice
///   the body's speed: wheel micro-Doppler;
/// * a pedestrian 1, 2, … detections with `pedestrian_detection_count_probabilities`, points on
///   the body box with the pedestrian reflection's micro-Doppler (limbs);
/// * every point is lost to the field of view, range fading and occlusion as in the point
///   model, and measured with the radar's range, azimuth and Doppler noise;
/// * multipath ghosts: the buildings or guard rails of each block stand `wall_offset_m` from
///   the road centre lines. When the line of sight from the sensor to the mirror image of an
///   object's reflection point across a wall meets that wall, the object yields, with
///   `ghost_probability` per wall, a ghost of up to `max_ghost_detections` of its points at the
///   mirror image, with the radial velocity of the mirrored motion and its RCS lowered by
///   `ghost_rcs_drop_db`;
/// * with `class_flip_probability`, a detection (of an object or a ghost) carries the other
///   class's label.
///
/// Clutter comes from the `clutter` section as for any preset. Every draw comes from a random
/// stream of its own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PointCloudConfig {
    /// Whether objects are measured as point clouds.
    pub enabled: bool,
    /// Mean number of detections of a car beyond the first, at `reference_range_m`.
    pub car_extra_detections_at_reference: f64,
    /// Range at which `car_extra_detections_at_reference` applies, metres; the mean scales with
    /// `reference / range` within a factor 0.5 to 1.5.
    pub reference_range_m: f64,
    /// Largest number of detections of one car in one scan, before losses.
    pub max_detections_per_car: u32,
    /// Probability that a car's detection is a wheel return.
    pub wheel_probability: f64,
    /// Distance between a car's axles as a fraction of its length.
    pub wheelbase_fraction: f64,
    /// Probability that a pedestrian in view yields 1, 2, … detections in one scan (before
    /// losses); entry `k` is the probability of `k + 1` detections. The entries sum to 1; at
    /// most [`MAX_DETECTIONS_PER_OBJECT`] entries.
    pub pedestrian_detection_count_probabilities: Vec<f64>,
    /// Distance from a road's centre line to the reflecting building fronts and guard rails
    /// on both of its sides, metres; beyond the sidewalks.
    pub wall_offset_m: f64,
    /// Probability that an object whose mirror image in a wall is visible yields a ghost there
    /// in one scan.
    pub ghost_probability: f64,
    /// Largest number of detections of one ghost.
    pub max_ghost_detections: u32,
    /// How much weaker a ghost's RCS is than that of the point it mirrors, dB.
    pub ghost_rcs_drop_db: f64,
    /// Probability that a detection carries the wrong class label.
    pub class_flip_probability: f64,
}
