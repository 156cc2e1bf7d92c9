//! Radar scan timing and the object-level measurement model.
//!
//! Every sensor scans once per period. The sensors' scans are staggered evenly over the period
//! (in a random order per sequence) and shifted by a per-sequence phase offset and a per-scan
//! jitter, both bounded so that consecutive frames always come from different sensors.
//!
//! A measurement is formed the way the paper builds object measurements from RadarScenes
//! (Section III-A, `eq:measurement_full`): reflection points of one object in one scan are
//! averaged. Points are drawn on the part of the object's box outline that faces the sensor,
//! dropped when outside the field of view, beyond range, faded out at long range, or hidden
//! behind another object, and perturbed by range, azimuth and Doppler noise.
//!
//! With extended objects switched on ([`ExtendedObjectConfig`]), vehicles are measured
//! differently: each detection is one reflection centre on the visible contour of the box
//! (near the point nearest to the sensor, or on a visible corner), reported on its own, and a
//! vehicle sometimes yields several detections in one scan. Pedestrians keep the averaged
//! point model.
//!
//! An object-list radar (`radar.report = "centre"`) detects objects the same way, but reports
//! each at its true centre with the noise of one point.

use glam::DVec2;
use rand::seq::SliceRandom;
use rand::Rng;
use rand_chacha::ChaCha12Rng;
use rand_distr::{Distribution, Normal, Poisson};

use super::config::{
    ExtendedObjectConfig, RadarConfig, RadarMount, RadarReport, ReflectionConfig, ScenarioConfig,
};
use super::kinematics::wrap_angle;
use super::point_cloud::{PointScan, PointTarget};
use super::world::{Agent, World};
use crate::io::{EgoPose, MeasurementOrigin, RecordedMeasurement};
use primm_core::measurement::{Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use primm_core::occlusion::ObjectBox;

/// One scheduled scan: time since the start of recording and the index of the sensor in the
/// configuration's sensor list.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scan {
    pub t: f64,
    pub sensor: usize,
}

/// Scan times of all sensors over `duration_s`, in time order.
pub(crate) fn schedule(radar: &RadarConfig, duration_s: f64, rng: &mut ChaCha12Rng) -> Vec<Scan> {
    let n = radar.sensors.len();
    let period = radar.scan_period_s;
    let slot = period / n as f64;
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(rng);
    let phase: Vec<f64> = (0..n).map(|_| symmetric(rng, radar.phase_jitter_s)).collect();
    let mut scans = Vec::new();
    let mut cycle = 0u64;
    loop {
        let base = cycle as f64 * period;
        if base >= duration_s {
            break;
        }
        for (k, &sensor) in order.iter().enumerate() {
            let t = base + (k as f64 + 0.5) * slot + phase[k] + symmetric(rng, radar.scan_jitter_s);
            if t < duration_s {
                scans.push(Scan { t, sensor });
            }
        }
        cycle += 1;
    }
    scans
}

fn symmetric(rng: &mut ChaCha12Rng, half_width: f64) -> f64 {
    if half_width > 0.0 {
        rng.random_range(-half_width..=half_width)
    } else {
        0.0
    }
}

/// World pose of a sensor: position and boresight heading.
pub(crate) fn sensor_pose(ego: &EgoPose, mount: &RadarMount) -> (DVec2, f64) {
    (ego.point_to_world(mount.layout.position()), ego.yaw_rad + mount.layout.yaw_rad)
}

/// Whether the segment from `a` to `b` passes through the box of `agent`.
pub(super) fn segment_hits_box(a: DVec2, b: DVec2, agent: &Agent) -> bool {
    ObjectBox {
        centre_m: agent.kin.position,
        heading: agent.kin.direction(),
        half_extent_m: DVec2::new(agent.length / 2.0, agent.width / 2.0),
    }
    .crossed_by(a, b)
}

/// One scan's sensor: its mount, pose and field of view, and the unit normal its noise is drawn
/// from.
pub(super) struct ScanSensor<'a> {
    pub(super) radar: &'a RadarConfig,
    pub(super) mount: &'a RadarMount,
    pub(super) origin: DVec2,
    pub(super) boresight: f64,
    pub(super) half_fov: f64,
    pub(super) unit: Normal<f64>,
}

impl<'a> ScanSensor<'a> {
    /// The sensor `mount` of `radar` on the ego vehicle at `ego`.
    fn new(radar: &'a RadarConfig, mount: &'a RadarMount, ego: &EgoPose) -> Self {
        let (origin, boresight) = sensor_pose(ego, mount);
        Self {
            radar,
            mount,
            origin,
            boresight,
            half_fov: mount.layout.half_fov_rad,
            unit: Normal::new(0.0, 1.0).expect("unit normal"),
        }
    }
}

/// The box faces of an object turned towards the sensor, weighted by their apparent width
/// (and their depth in range, [`ReflectionConfig::range_extent_weight`]).
pub(super) struct VisibleFaces {
    corners: [DVec2; 4],
    faces: [(usize, f64); 4],
    total: f64,
}

/// The sums of the detected reflection points of one object in one scan.
#[derive(Default)]
struct Echo {
    sum_position: DVec2,
    sum_vr: f64,
    sum_rcs: f64,
    count: u32,
}

/// The object measurements of one scan and the scan's ego-motion compensation error.
pub(crate) struct ScanMeasurements {
    /// One measurement per detected object, in random order.
    pub measurements: Vec<RecordedMeasurement>,
    /// Ego-motion compensation error of the radial velocities of this scan, m/s.
    pub doppler_bias_mps: f64,
}

/// The random streams of the measurement models.
pub(crate) struct ScanRandom {
    /// The point model's, the scan's Doppler bias and the order of the detections.
    pub sensor: ChaCha12Rng,
    /// The extended-object detections of vehicles.
    pub extended: ChaCha12Rng,
    /// The point-cloud detections ([`super::point_cloud`]).
    pub point_cloud: ChaCha12Rng,
}

/// Produces the object measurements of one scan of sensor `sensor_index`. The point model draws
/// from `random.sensor`; the extended-object detections of vehicles, when switched on, from
/// `random.extended` alone, and the point-cloud detections from `random.point_cloud` alone.
pub(crate) fn scan(
    world: &World<'_>,
    cfg: &ScenarioConfig,
    sensor_index: usize,
    random: &mut ScanRandom,
) -> ScanMeasurements {
    let ScanRandom { sensor: rng, extended: extended_rng, point_cloud: point_rng } = random;
    let radar = &cfg.radar;
    let mount = &radar.sensors[sensor_index];
    let ego = world.ego_pose();
    let sensor = ScanSensor::new(radar, mount, &ego);
    let origin = sensor.origin;
    let scan_bias = radar.scan_doppler_bias_mps * sensor.unit.sample(rng);
    let mut out = Vec::new();
    let point_scan = cfg.point_cloud.enabled.then(|| PointScan::new(world, &sensor, cfg, &ego, scan_bias));

    for (index, object) in world.agents.iter().enumerate() {
        if object.is_ego {
            continue;
        }
        let refl: &ReflectionConfig = match object.class {
            ObjectClass::Pedestrian => &cfg.pedestrian_reflection,
            _ => &cfg.car_reflection,
        };
        let max_range = mount.layout.max_range_m.min(refl.detection_range_m);
        let Some(range) = range_if_in_view(&sensor, object, max_range) else { continue };
        let Some(faces) = visible_faces(object, origin, refl.range_extent_weight) else { continue };
        let truth = ObjectTruth {
            position: ego.world_to_car(object.kin.position),
            velocity: ego.rotate_to_car(object.kin.velocity()),
        };
        if let Some(point_scan) = &point_scan {
            let target = PointTarget { index, faces: &faces, range, max_range, truth };
            point_scan.object_detections(&target, &mut out, point_rng);
            continue;
        }
        if cfg.extended_objects.enabled && object.class != ObjectClass::Pedestrian {
            let target = ExtendedTarget { index, faces: &faces, truth, max_range };
            extended_detections(
                world,
                &sensor,
                refl,
                &cfg.extended_objects,
                &target,
                &ego,
                scan_bias,
                &mut out,
                extended_rng,
            );
            continue;
        }
        let echo = object_echo(world, &sensor, refl, index, &faces, range, max_range, rng);
        if echo.count == 0 || rng.random_bool(radar.miss_probability) {
            continue;
        }
        let n = f64::from(echo.count);
        let (measured, vr, rcs) = match radar.report {
            RadarReport::Echo => (echo.sum_position / n, echo.sum_vr / n, echo.sum_rcs / n),
            RadarReport::Centre => measure_centre(&sensor, object, refl, rng),
        };
        let position = ego.world_to_car(measured);
        out.push(RecordedMeasurement {
            measurement: Measurement {
                x_m: position.x,
                y_m: position.y,
                radial_velocity_mps: vr + scan_bias,
                rcs_dbsm: rcs,
                class: object.class,
                sensor_id: Some(mount.layout.id),
                ground_truth_id: Some(object.id),
            },
            true_position: Some(truth.position),
            true_velocity: Some(truth.velocity),
            origin: Some(MeasurementOrigin::Object),
        });
    }
    // Detection lists carry no meaningful order.
    out.shuffle(rng);
    ScanMeasurements { measurements: out, doppler_bias_mps: scan_bias }
}

/// The true centre and velocity over ground of an object in the car frame of the scan.
#[derive(Debug, Clone, Copy)]
pub(super) struct ObjectTruth {
    /// Centre of the box, metres.
    pub(super) position: DVec2,
    /// Velocity of the centre over ground, in the car's axes, m/s.
    pub(super) velocity: DVec2,
}

/// A vehicle measured as an extended object in one scan.
struct ExtendedTarget<'a> {
    /// Index of the vehicle in the world's agents.
    index: usize,
    /// Its faces turned towards the sensor.
    faces: &'a VisibleFaces,
    /// Its true centre and velocity.
    truth: ObjectTruth,
    /// Largest range at which it is detected, metres.
    max_range: f64,
}

/// The part of a box outline that faces the sensor: a chain of one or two faces, as the
/// corners along it (two or three) and the arc length of the outline point nearest to the
/// sensor.
#[derive(Debug, Clone, Copy)]
struct VisibleContour {
    corners: [DVec2; 3],
    corner_count: usize,
    /// Arc length from the first corner to each corner, metres.
    arc: [f64; 3],
    /// Arc length of the contour point nearest to the sensor, metres.
    nearest_arc: f64,
}

impl VisibleContour {
    /// The contour of the visible `faces` seen from `origin`; `None` when no face is visible.
    fn new(faces: &VisibleFaces, origin: DVec2) -> Option<Self> {
        let visible = |k: usize| faces.faces[k % 4].1 > 0.0;
        // The visible faces of a box form one chain; it starts at the visible face whose
        // predecessor is hidden.
        let first = (0..4).find(|&k| visible(k) && !visible(k + 3))?;
        let face_count = if visible(first + 1) { 2 } else { 1 };
        let mut corners = [DVec2::ZERO; 3];
        for (j, corner) in corners.iter_mut().enumerate().take(face_count + 1) {
            *corner = faces.corners[(first + j) % 4];
        }
        let mut arc = [0.0; 3];
        let mut nearest = (f64::INFINITY, 0.0);
        for j in 0..face_count {
            let (a, b) = (corners[j], corners[j + 1]);
            let length = a.distance(b);
            arc[j + 1] = arc[j] + length;
            let along = if length > 0.0 {
                ((origin - a).dot(b - a) / (length * length)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let distance = origin.distance(a + (b - a) * along);
            if distance < nearest.0 {
                nearest = (distance, arc[j] + along * length);
            }
        }
        Some(Self { corners, corner_count: face_count + 1, arc, nearest_arc: nearest.1 })
    }

    /// Length of the contour, metres.
    fn length(&self) -> f64 {
        self.arc[self.corner_count - 1]
    }

    /// The contour point at arc length `s` (clamped to the contour).
    fn point_at(&self, s: f64) -> DVec2 {
        let s = s.clamp(0.0, self.length());
        for j in 0..self.corner_count - 1 {
            let length = self.arc[j + 1] - self.arc[j];
            if s <= self.arc[j + 1] || j + 2 == self.corner_count {
                let along = if length > 0.0 { ((s - self.arc[j]) / length).clamp(0.0, 1.0) } else { 0.0 };
                return self.corners[j] + (self.corners[j + 1] - self.corners[j]) * along;
            }
        }
        self.corners[0]
    }

    /// Draws one reflection centre: a visible corner with `corner_probability`, otherwise a
    /// point `contour_spread_m · N(0, 1)` along the contour from the point nearest to the
    /// sensor, clamped to the contour's ends.
    fn reflection_centre(
        &self,
        extended: &ExtendedObjectConfig,
        unit: &Normal<f64>,
        rng: &mut ChaCha12Rng,
    ) -> DVec2 {
        if rng.random_bool(extended.corner_probability) {
            self.corners[rng.random_range(0..self.corner_count)]
        } else {
            self.point_at(self.nearest_arc + extended.contour_spread_m * unit.sample(rng))
        }
    }
}

/// The number of detections of one vehicle in one scan, drawn from `probabilities` (entry `k`:
/// probability of `k + 1` detections; they sum to 1).
pub(super) fn detection_count(probabilities: &[f64], rng: &mut ChaCha12Rng) -> usize {
    let mut pick: f64 = rng.random();
    for (k, p) in probabilities.iter().enumerate() {
        if pick < *p {
            return k + 1;
        }
        pick -= p;
    }
    probabilities.len()
}

/// Appends the detections of one vehicle measured as an extended object: the object is missed
/// with `radar.miss_probability`; otherwise [`detection_count`] reflection centres are drawn on
/// its visible contour, each kept when the sensor sees it ([`detected`]) and measured with the
/// point noise ([`measure_point`]) as a measurement of its own. Detections beyond the frame
/// capacity are dropped. Every draw comes from `rng`.
#[allow(clippy::too_many_arguments)]
fn extended_detections(
    world: &World<'_>,
    sensor: &ScanSensor<'_>,
    refl: &ReflectionConfig,
    extended: &ExtendedObjectConfig,
    target: &ExtendedTarget<'_>,
    ego: &EgoPose,
    scan_bias: f64,
    out: &mut Vec<RecordedMeasurement>,
    rng: &mut ChaCha12Rng,
) {
    let count = detection_count(&extended.detection_count_probabilities, rng);
    if rng.random_bool(sensor.radar.miss_probability) {
        return;
    }
    let Some(contour) = VisibleContour::new(target.faces, sensor.origin) else { return };
    let object = &world.agents[target.index];
    for _ in 0..count {
        let point = contour.reflection_centre(extended, &sensor.unit, rng);
        let Some((point_rel, point_range, azimuth)) =
            detected(world, sensor, target.index, point, target.max_range, rng)
        else {
            continue;
        };
        let (measured, vr, rcs) =
            measure_point(sensor, object, refl, point, point_rel, point_range, azimuth, rng);
        if out.len() >= MAX_MEASUREMENTS_PER_FRAME {
            continue;
        }
        let position = ego.world_to_car(measured);
        out.push(RecordedMeasurement {
            measurement: Measurement {
                x_m: position.x,
                y_m: position.y,
                radial_velocity_mps: vr + scan_bias,
                rcs_dbsm: rcs,
                class: object.class,
                sensor_id: Some(sensor.mount.layout.id),
                ground_truth_id: Some(object.id),
            },
            true_position: Some(target.truth.position),
            true_velocity: Some(target.truth.velocity),
            origin: Some(MeasurementOrigin::Object),
        });
    }
}

/// The range to `object`'s centre when some of its box may lie within `max_range` and the field
/// of view; `None` otherwise (also for an object closer than 0.5 m).
fn range_if_in_view(sensor: &ScanSensor<'_>, object: &Agent, max_range: f64) -> Option<f64> {
    let radius = 0.5 * object.length.hypot(object.width);
    let rel = object.kin.position - sensor.origin;
    let range = rel.length();
    if range - radius > max_range || range < 0.5 {
        return None;
    }
    let bearing = wrap_angle(rel.to_angle() - sensor.boresight);
    if bearing.abs() - (radius / range).min(1.0).asin() > sensor.half_fov {
        return None;
    }
    Some(range)
}

/// The faces of `object`'s box turned towards `origin`, each weighted by its apparent width
/// plus `range_extent_weight` times its depth along the line of sight
/// ([`ReflectionConfig::range_extent_weight`]); `None` when none is.
fn visible_faces(object: &Agent, origin: DVec2, range_extent_weight: f64) -> Option<VisibleFaces> {
    let corners = object.corners();
    let mut faces: [(usize, f64); 4] = [(0, 0.0); 4];
    let mut total = 0.0;
    for k in 0..4 {
        let a = corners[k];
        let b = corners[(k + 1) % 4];
        let edge = b - a;
        let outward = DVec2::new(edge.y, -edge.x).normalize_or_zero();
        let mid = 0.5 * (a + b);
        let to_sensor = (origin - mid).normalize_or_zero();
        let facing = outward.dot(to_sensor);
        let depth = range_extent_weight * edge.normalize_or_zero().dot(to_sensor).abs();
        let weight = if facing > 0.0 { edge.length() * (facing + depth) } else { 0.0 };
        faces[k] = (k, weight);
        total += weight;
    }
    (total > 0.0).then_some(VisibleFaces { corners, faces, total })
}

/// Draws the candidate reflection points of object `index` (more for near objects) and sums
/// the measured ones.
fn object_echo(
    world: &World<'_>,
    sensor: &ScanSensor<'_>,
    refl: &ReflectionConfig,
    index: usize,
    faces: &VisibleFaces,
    range: f64,
    max_range: f64,
    rng: &mut ChaCha12Rng,
) -> Echo {
    let object = &world.agents[index];
    let scale = (refl.reference_range_m / range.max(1.0)).clamp(0.3, 3.0);
    let mean = (refl.mean_points_at_reference * scale - 1.0).max(0.0);
    let extra = if mean > 0.0 { Poisson::new(mean).map(|d| d.sample(rng) as u32).unwrap_or(0) } else { 0 };
    let candidates = (1 + extra).min(refl.max_points);

    let mut echo = Echo::default();
    for _ in 0..candidates {
        let point = reflection_point(object, faces, refl, rng);
        let Some((point_rel, point_range, azimuth)) = detected(world, sensor, index, point, max_range, rng)
        else {
            continue;
        };
        let (measured, vr, rcs) =
            measure_point(sensor, object, refl, point, point_rel, point_range, azimuth, rng);
        echo.sum_position += measured;
        echo.sum_vr += vr;
        echo.sum_rcs += rcs;
        echo.count += 1;
    }
    echo
}

/// A reflection point: on a visible face (sometimes a corner), or sometimes inside the box.
pub(super) fn reflection_point(
    object: &Agent,
    faces: &VisibleFaces,
    refl: &ReflectionConfig,
    rng: &mut ChaCha12Rng,
) -> DVec2 {
    // Pick a face, then a point on it (sometimes a corner).
    let mut pick = rng.random::<f64>() * faces.total;
    let mut face = faces.faces[3].0;
    for &(k, w) in &faces.faces {
        if pick < w {
            face = k;
            break;
        }
        pick -= w;
    }
    let a = faces.corners[face];
    let b = faces.corners[(face + 1) % 4];
    if rng.random_bool(refl.interior_probability) {
        let heading = object.kin.direction();
        let along = (rng.random::<f64>() - 0.5) * object.length;
        let across = (rng.random::<f64>() - 0.5) * object.width;
        object.kin.position + heading * along + heading.perp() * across
    } else {
        let u = if rng.random_bool(refl.corner_probability) {
            if rng.random_bool(0.5) {
                0.0
            } else {
                1.0
            }
        } else {
            rng.random::<f64>()
        };
        a + (b - a) * u
    }
}

/// Whether the sensor sees `point` of object `index`: within range and field of view, not
/// faded out at long range, and not hidden behind another object (or seen despite it). Returns
/// the point relative to the sensor, its range and its azimuth.
pub(super) fn detected(
    world: &World<'_>,
    sensor: &ScanSensor<'_>,
    index: usize,
    point: DVec2,
    max_range: f64,
    rng: &mut ChaCha12Rng,
) -> Option<(DVec2, f64, f64)> {
    let radar = sensor.radar;
    let point_rel = point - sensor.origin;
    let point_range = point_rel.length();
    let azimuth = wrap_angle(point_rel.to_angle() - sensor.boresight);
    if point_range > max_range || azimuth.abs() > sensor.half_fov {
        return None;
    }
    let fade_start = radar.fade_start_fraction * max_range;
    if point_range > fade_start {
        let keep = 1.0 - (point_range - fade_start) / (max_range - fade_start).max(1e-6);
        if !rng.random_bool(keep.clamp(0.0, 1.0)) {
            return None;
        }
    }
    let hidden = world
        .agents
        .iter()
        .enumerate()
        .any(|(j, other)| j != index && !other.is_ego && segment_hits_box(sensor.origin, point, other));
    if hidden && !rng.random_bool(radar.occluded_point_probability) {
        return None;
    }
    Some((point_rel, point_range, azimuth))
}

/// What an object-list radar (`radar.report = "centre"`) reports of a detected object: its true
/// centre, measured like one reflection point there ([`measure_point`]: range, azimuth and
/// Doppler noise, the mount's misalignment, micro-Doppler and RCS).
fn measure_centre(
    sensor: &ScanSensor<'_>,
    object: &Agent,
    refl: &ReflectionConfig,
    rng: &mut ChaCha12Rng,
) -> (DVec2, f64, f64) {
    let centre = object.kin.position;
    let rel = centre - sensor.origin;
    let range = rel.length().max(1e-6);
    let azimuth = wrap_angle(rel.to_angle() - sensor.boresight);
    measure_point(sensor, object, refl, centre, rel, range, azimuth, rng)
}

/// The measured position (world frame) of a point at `point_range` and `azimuth` from the
/// sensor: range and azimuth noise in the sensor's polar frame, and the mount's misalignment.
pub(super) fn measure_position(
    sensor: &ScanSensor<'_>,
    point_range: f64,
    azimuth: f64,
    rng: &mut ChaCha12Rng,
) -> DVec2 {
    let (radar, mount, unit) = (sensor.radar, sensor.mount, &sensor.unit);
    let sigma_az = radar.azimuth_noise_deg.to_radians() * mount.azimuth_noise_scale / azimuth.cos().max(0.5);
    let measured_range = point_range + radar.range_noise_m * unit.sample(rng);
    let measured_az = azimuth + mount.azimuth_bias_deg.to_radians() + sigma_az * unit.sample(rng);
    sensor.origin + DVec2::from_angle(sensor.boresight + measured_az) * measured_range
}

/// The measured position, radial velocity and RCS of a detected reflection point.
#[allow(clippy::too_many_arguments)]
pub(super) fn measure_point(
    sensor: &ScanSensor<'_>,
    object: &Agent,
    refl: &ReflectionConfig,
    point: DVec2,
    point_rel: DVec2,
    point_range: f64,
    azimuth: f64,
    rng: &mut ChaCha12Rng,
) -> (DVec2, f64, f64) {
    let (radar, unit) = (sensor.radar, &sensor.unit);
    let measured = measure_position(sensor, point_range, azimuth, rng);

    // Doppler: velocity of the reflecting point along the line of sight.
    let line_of_sight = point_rel / point_range;
    let lever = point - object.kin.position;
    let point_velocity = object.kin.velocity() + DVec2::new(-lever.y, lever.x) * object.kin.yaw_rate;
    let micro = refl.micro_doppler_fraction * object.kin.speed * unit.sample(rng);
    let vr = point_velocity.dot(line_of_sight) + radar.doppler_noise_mps * unit.sample(rng) + micro;

    // RCS: side views reflect more than head-on views; each point fluctuates.
    let aspect = object.kin.direction().perp_dot(-line_of_sight).abs();
    let rcs = refl.rcs_front_dbsm
        + (refl.rcs_side_dbsm - refl.rcs_front_dbsm) * aspect
        + refl.rcs_fluctuation_db * unit.sample(rng);
    (measured, vr, rcs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn schedule_interleaves_sensors() {
        let radar = RadarConfig::default();
        let mut rng = ChaCha12Rng::seed_from_u64(3);
        let scans = schedule(&radar, 5.0, &mut rng);
        let expected = (5.0 / radar.scan_period_s * radar.sensors.len() as f64).round() as usize;
        assert!(scans.len().abs_diff(expected) <= radar.sensors.len());
        for pair in scans.windows(2) {
            assert!(pair[1].t > pair[0].t);
            assert_ne!(pair[1].sensor, pair[0].sensor);
        }
        for sensor in 0..radar.sensors.len() {
            let times: Vec<f64> = scans.iter().filter(|s| s.sensor == sensor).map(|s| s.t).collect();
            for pair in times.windows(2) {
                let gap = pair[1] - pair[0];
                assert!((gap - radar.scan_period_s).abs() <= 2.0 * radar.scan_jitter_s + 1e-12);
            }
        }
    }
}
