//! Detection-level radar output: several detections per object and scan, as a radar gives them
//! before any clustering ([`PointCloudConfig`]).
//!
//! Each object in view yields its own detections: points on the faces of a car's box turned
//! towards the sensor and on its wheels, one or two points on a pedestrian. Each point is lost
//! to the field of view, range fading and occlusion like a point of the averaged model and is
//! measured with the radar's noise on its own; nothing is averaged. A wheel point moves along
//! the car's heading at between 0 and twice the body's speed (a point on a spoke or the rim of
//! a rolling wheel), so its radial velocity differs from the body's.
//!
//! Multipath ghosts come from the walls of the road grid: the building fronts or guard rails of
//! every block stand `wall_offset_m` from the road centre lines, forming a rectangle per block.
//! A wall mirrors an object's reflection point `p` to `p'`; the radar sees the ghost at `p'`
//! when the sensor and the object are on the road side of the wall and the line of sight from
//! the sensor to `p'` meets the wall itself (not the gap of a junction), unblocked by another
//! object. The ghost moves with the mirrored velocity, which gives its radial velocity.
//!
//! Detections of objects and ghosts carry the other class's label with
//! `class_flip_probability`. Every draw comes from the point-cloud random stream.

use glam::DVec2;
use rand::Rng;
use rand_chacha::ChaCha12Rng;
use rand_distr::{Distribution, Poisson};

use super::config::{PointCloudConfig, ReflectionConfig, ScenarioConfig};
use super::kinematics::wrap_angle;
use super::radar::{
    detected, detection_count, measure_point, measure_position, reflection_point, segment_hits_box,
    ObjectTruth, ScanSensor, VisibleFaces,
};
use super::world::{Agent, World};
use crate::io::{EgoPose, MeasurementOrigin, RecordedMeasurement};
use primm_core::measurement::{Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};

/// The bounds of the range factor of a car's mean detection count.
const RANGE_FACTOR_BOUNDS: [f64; 2] = [0.5, 1.5];

/// One reflecting wall: a face of a block's building rectangle, world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Wall {
    /// One end.
    pub start: DVec2,
    /// The other end.
    pub end: DVec2,
    /// Unit normal pointing away from the block, towards the road.
    pub normal: DVec2,
}

impl Wall {
    /// Signed distance of `point` from the wall's line, positive on the road side.
    pub(crate) fn side(&self, point: DVec2) -> f64 {
        (point - self.start).dot(self.normal)
    }

    /// The mirror image of `point` across the wall's line.
    pub(crate) fn mirror(&self, point: DVec2) -> DVec2 {
        point - 2.0 * self.side(point) * self.normal
    }

    /// The mirror image of the direction or velocity `vector`.
    pub(crate) fn mirror_vector(&self, vector: DVec2) -> DVec2 {
        vector - 2.0 * vector.dot(self.normal) * self.normal
    }

    /// Where the segment from `from` (road side) to `to` (behind the wall) crosses the wall
    /// itself; `None` when it crosses the line beyond the wall's ends or not at all.
    pub(crate) fn crossing(&self, from: DVec2, to: DVec2) -> Option<DVec2> {
        let (a, b) = (self.side(from), self.side(to));
        if a <= 0.0 || b >= 0.0 {
            return None;
        }
        let point = from + (to - from) * (a / (a - b));
        let along = self.end - self.start;
        let s = (point - self.start).dot(along) / along.length_squared();
        (0.0..=1.0).contains(&s).then_some(point)
    }
}

/// The walls of every block that reaches within `reach` of `centre`: the building rectangles
/// `[i·B + w, (i+1)·B − w] × [j·B + w, (j+1)·B − w]` of the road grid with block length `B`
/// and wall offset `w`.
pub(crate) fn walls_near(centre: DVec2, reach: f64, block_m: f64, wall_offset_m: f64) -> Vec<Wall> {
    let range = |c: f64| ((c - reach) / block_m).floor() as i64..=((c + reach) / block_m).floor() as i64;
    let mut walls = Vec::new();
    for i in range(centre.x) {
        for j in range(centre.y) {
            let low = DVec2::new(i as f64, j as f64) * block_m + DVec2::splat(wall_offset_m);
            let high = DVec2::new((i + 1) as f64, (j + 1) as f64) * block_m - DVec2::splat(wall_offset_m);
            let corners = [low, DVec2::new(high.x, low.y), high, DVec2::new(low.x, high.y)];
            for k in 0..4 {
                let (start, end) = (corners[k], corners[(k + 1) % 4]);
                let edge = (end - start).normalize();
                // Corners run counter-clockwise: the right-hand normal points out of the block.
                walls.push(Wall { start, end, normal: DVec2::new(edge.y, -edge.x) });
            }
        }
    }
    walls
}

/// One object seen in a scan.
pub(super) struct PointTarget<'a> {
    /// Index of the object in the world's agents.
    pub index: usize,
    /// Its faces turned towards the sensor.
    pub faces: &'a VisibleFaces,
    /// Range of its centre, metres.
    pub range: f64,
    /// Largest range at which it is detected, metres.
    pub max_range: f64,
    /// Its true centre and velocity.
    pub truth: ObjectTruth,
}

/// One scan of one sensor in the point-cloud model.
pub(super) struct PointScan<'a, 'w> {
    world: &'a World<'w>,
    sensor: &'a ScanSensor<'a>,
    cfg: &'a ScenarioConfig,
    ego: &'a EgoPose,
    scan_bias: f64,
    walls: Vec<Wall>,
}

/// A detected reflection point of an object: where it is and its measured RCS.
#[derive(Debug, Clone, Copy)]
struct Reflection {
    point: DVec2,
    rcs_dbsm: f64,
}

impl<'a, 'w> PointScan<'a, 'w> {
    /// The scan of `sensor`, with the walls within its reach.
    pub(super) fn new(
        world: &'a World<'w>,
        sensor: &'a ScanSensor<'a>,
        cfg: &'a ScenarioConfig,
        ego: &'a EgoPose,
        scan_bias: f64,
    ) -> Self {
        let reach = sensor.mount.layout.max_range_m;
        let walls = walls_near(sensor.origin, reach, world.grid.block_m, cfg.point_cloud.wall_offset_m);
        Self { world, sensor, cfg, ego, scan_bias, walls }
    }

    fn model(&self) -> &PointCloudConfig {
        &self.cfg.point_cloud
    }

    /// Appends the detections of one object and of its ghosts; nothing beyond the frame
    /// capacity.
    pub(super) fn object_detections(
        &self,
        target: &PointTarget<'_>,
        out: &mut Vec<RecordedMeasurement>,
        rng: &mut ChaCha12Rng,
    ) {
        let object = &self.world.agents[target.index];
        let pedestrian = object.class == ObjectClass::Pedestrian;
        let refl = if pedestrian { &self.cfg.pedestrian_reflection } else { &self.cfg.car_reflection };
        let count = if pedestrian {
            detection_count(&self.model().pedestrian_detection_count_probabilities, rng)
        } else {
            self.car_detection_count(target.range, rng)
        };
        if rng.random_bool(self.sensor.radar.miss_probability) {
            return;
        }
        let mut reflections = Vec::with_capacity(count);
        for _ in 0..count {
            let (point, wheel_factor) = self.draw_point(object, target.faces, refl, pedestrian, rng);
            let Some((rel, range, azimuth)) =
                detected(self.world, self.sensor, target.index, point, target.max_range, rng)
            else {
                continue;
            };
            let (measured, mut vr, rcs) =
                measure_point(self.sensor, object, refl, point, rel, range, azimuth, rng);
            if let Some(factor) = wheel_factor {
                vr += object.kin.speed * (factor - 1.0) * object.kin.direction().dot(rel / range);
            }
            let class = self.label(object.class, rng);
            let truth = Some(target.truth);
            self.push(out, measured, vr, rcs, class, Some(object.id), truth, MeasurementOrigin::Object);
            reflections.push(Reflection { point, rcs_dbsm: rcs });
        }
        self.ghosts(target, &reflections, out, rng);
    }

    /// The number of detections of a car at `range` before losses.
    fn car_detection_count(&self, range: f64, rng: &mut ChaCha12Rng) -> usize {
        let model = self.model();
        let factor =
            (model.reference_range_m / range.max(1.0)).clamp(RANGE_FACTOR_BOUNDS[0], RANGE_FACTOR_BOUNDS[1]);
        let mean = model.car_extra_detections_at_reference * factor;
        let extra = if mean > 0.0 { Poisson::new(mean).map_or(0.0, |d| d.sample(rng)) as usize } else { 0 };
        (1 + extra).min(model.max_detections_per_car as usize)
    }

    /// A reflection point of `object` and, for a wheel return, the factor of the body's speed
    /// at which that point moves along the heading.
    fn draw_point(
        &self,
        object: &Agent,
        faces: &VisibleFaces,
        refl: &ReflectionConfig,
        pedestrian: bool,
        rng: &mut ChaCha12Rng,
    ) -> (DVec2, Option<f64>) {
        if pedestrian || !rng.random_bool(self.model().wheel_probability) {
            return (reflection_point(object, faces, refl, rng), None);
        }
        let heading = object.kin.direction();
        let side =
            if (self.sensor.origin - object.kin.position).dot(heading.perp()) >= 0.0 { 1.0 } else { -1.0 };
        let axle =
            if rng.random_bool(0.5) { 0.5 } else { -0.5 } * self.model().wheelbase_fraction * object.length;
        let point = object.kin.position + heading * axle + heading.perp() * (side * object.width / 2.0);
        // A point at a fraction u of the radius, at angle φ from the contact point: its speed
        // along the heading is the body's times 1 − u·cos φ.
        let radius_fraction: f64 = rng.random();
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        (point, Some(1.0 - radius_fraction * angle.cos()))
    }

    /// `class`, or with the flip probability the other class's label.
    fn label(&self, class: ObjectClass, rng: &mut ChaCha12Rng) -> ObjectClass {
        if !rng.random_bool(self.model().class_flip_probability) {
            return class;
        }
        match class {
            ObjectClass::Pedestrian => ObjectClass::Car,
            _ => ObjectClass::Pedestrian,
        }
    }

    /// Appends the multipath ghosts of one object: per wall whose mirror image of the object's
    /// first reflection the sensor sees, with the ghost probability, the mirror images of up to
    /// `max_ghost_detections` of its reflections.
    fn ghosts(
        &self,
        target: &PointTarget<'_>,
        reflections: &[Reflection],
        out: &mut Vec<RecordedMeasurement>,
        rng: &mut ChaCha12Rng,
    ) {
        let Some(first) = reflections.first() else { return };
        let object = &self.world.agents[target.index];
        let limit = self.model().max_ghost_detections as usize;
        for wall in &self.walls {
            if self.ghost_seen(target, wall, first.point).is_none()
                || !rng.random_bool(self.model().ghost_probability)
            {
                continue;
            }
            for reflection in reflections.iter().take(limit) {
                let Some((rel, range, azimuth)) = self.ghost_seen(target, wall, reflection.point) else {
                    continue;
                };
                let measured = measure_position(self.sensor, range, azimuth, rng);
                let lever = reflection.point - object.kin.position;
                let velocity = object.kin.velocity() + lever.perp() * object.kin.yaw_rate;
                let vr = wall.mirror_vector(velocity).dot(rel / range)
                    + self.sensor.radar.doppler_noise_mps * self.sensor.unit.sample(rng);
                let rcs = reflection.rcs_dbsm - self.model().ghost_rcs_drop_db;
                let class = self.label(object.class, rng);
                self.push(out, measured, vr, rcs, class, None, None, MeasurementOrigin::Ghost);
            }
        }
    }

    /// Whether the sensor sees the mirror image of `point` of the target in `wall`: sensor and
    /// point on the road side, the line of sight to the image through the wall itself, within
    /// range and field of view, and no other object on the way to the wall. Returns the image
    /// relative to the sensor, its range and azimuth.
    fn ghost_seen(&self, target: &PointTarget<'_>, wall: &Wall, point: DVec2) -> Option<(DVec2, f64, f64)> {
        let origin = self.sensor.origin;
        if wall.side(point) <= 0.0 {
            return None;
        }
        let image = wall.mirror(point);
        let bounce = wall.crossing(origin, image)?;
        let rel = image - origin;
        let range = rel.length();
        let azimuth = wrap_angle(rel.to_angle() - self.sensor.boresight);
        if range > target.max_range || azimuth.abs() > self.sensor.half_fov {
            return None;
        }
        let blocked =
            self.world.agents.iter().enumerate().any(|(j, other)| {
                j != target.index && !other.is_ego && segment_hits_box(origin, bounce, other)
            });
        (!blocked).then_some((rel, range, azimuth))
    }

    /// Appends one detection (world-frame `measured`), unless the frame is full.
    #[allow(clippy::too_many_arguments)]
    fn push(
        &self,
        out: &mut Vec<RecordedMeasurement>,
        measured: DVec2,
        radial_velocity_mps: f64,
        rcs_dbsm: f64,
        class: ObjectClass,
        ground_truth_id: Option<u64>,
        truth: Option<ObjectTruth>,
        origin: MeasurementOrigin,
    ) {
        if out.len() >= MAX_MEASUREMENTS_PER_FRAME {
            return;
        }
        let position = self.ego.world_to_car(measured);
        out.push(RecordedMeasurement {
            measurement: Measurement {
                x_m: position.x,
                y_m: position.y,
                radial_velocity_mps: radial_velocity_mps + self.scan_bias,
                rcs_dbsm,
                class,
                sensor_id: Some(self.sensor.mount.layout.id),
                ground_truth_id,
            },
            true_position: truth.map(|t| t.position),
            true_velocity: truth.map(|t| t.velocity),
            origin: Some(origin),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_mirrors_points_and_velocities_and_is_crossed_only_between_its_ends() {
        // The wall y = 12 from x = 12 to x = 98, its road side below (normal −y).
        let walls = walls_near(DVec2::new(50.0, 0.0), 1.0, 110.0, 12.0);
        let wall =
            walls.iter().find(|w| (w.start.y - 12.0).abs() < 1e-9 && (w.end.y - 12.0).abs() < 1e-9).unwrap();
        assert!((wall.normal - DVec2::new(0.0, -1.0)).length() < 1e-12, "{wall:?}");
        assert!(wall.side(DVec2::new(50.0, 2.0)) > 0.0);
        assert!((wall.mirror(DVec2::new(50.0, 2.0)) - DVec2::new(50.0, 22.0)).length() < 1e-12);
        assert!((wall.mirror_vector(DVec2::new(3.0, 1.0)) - DVec2::new(3.0, -1.0)).length() < 1e-12);
        let crossing = wall.crossing(DVec2::new(40.0, 2.0), DVec2::new(60.0, 22.0)).unwrap();
        assert!((crossing - DVec2::new(50.0, 12.0)).length() < 1e-9);
        // Through the junction gap beyond the wall's end: no crossing.
        assert_eq!(wall.crossing(DVec2::new(0.0, 2.0), DVec2::new(4.0, 22.0)), None);
        // From behind the wall: no crossing.
        assert_eq!(wall.crossing(DVec2::new(50.0, 22.0), DVec2::new(50.0, 2.0)), None);
    }

    #[test]
    fn the_walls_near_a_point_are_four_per_block_around_it() {
        let walls = walls_near(DVec2::new(5.0, 5.0), 100.0, 110.0, 12.0);
        // Blocks −1..=0 in x and y: four blocks.
        assert_eq!(walls.len(), 16);
        for wall in &walls {
            // Every wall's road side holds the road centre lines it faces: the block's centre
            // lies behind it.
            let i = (wall.start.x.min(wall.end.x) / 110.0).floor();
            let j = (wall.start.y.min(wall.end.y) / 110.0).floor();
            let block_centre = DVec2::new(i + 0.5, j + 0.5) * 110.0;
            assert!(wall.side(block_centre) < 0.0, "{wall:?}");
            assert!((wall.start.distance(wall.end) - (110.0 - 24.0)).abs() < 1e-9);
        }
    }
}
