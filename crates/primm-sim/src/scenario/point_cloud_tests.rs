//! Properties of the detection-level model of the `point_cloud` preset.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use glam::DVec2;

use super::config::{Preset, RadarMount, ScenarioConfig};
use super::kinematics::wrap_angle;
use super::point_cloud::walls_near;
use super::{GeneratedSequence, ObjectState, ScenarioGenerator, Split};
use crate::io::{read_sequence, write_sequence, MeasurementOrigin, RecordedFrame, RecordedMeasurement};
use primm_core::measurement::{ObjectClass, MAX_MEASUREMENTS_PER_FRAME};

/// Validation sequences of the preset, generated once for all tests.
fn sequences() -> &'static [GeneratedSequence] {
    static SEQUENCES: OnceLock<Vec<GeneratedSequence>> = OnceLock::new();
    SEQUENCES.get_or_init(|| {
        let generator = ScenarioGenerator::from_preset(Preset::PointCloud);
        (0..4).map(|index| generator.generate(Split::Validation, index)).collect()
    })
}

fn config() -> ScenarioConfig {
    Preset::PointCloud.config()
}

fn mount_of(config: &ScenarioConfig, frame: &RecordedFrame) -> RadarMount {
    let id = frame.sensor_id.expect("sensor id");
    config.radar.sensors.iter().find(|s| s.layout.id == id).expect("known sensor").clone()
}

/// Every frame with its truth.
fn frames() -> impl Iterator<Item = (&'static RecordedFrame, &'static super::TruthFrame)> {
    sequences().iter().flat_map(|g| g.sequence.frames.iter().zip(&g.truth))
}

/// The detections of real objects, grouped per frame and object, with the true object.
fn object_groups() -> Vec<(&'static RecordedFrame, &'static ObjectState, Vec<&'static RecordedMeasurement>)> {
    let mut groups = Vec::new();
    for (frame, truth) in frames() {
        let mut by_object: BTreeMap<u64, Vec<&RecordedMeasurement>> = BTreeMap::new();
        for m in &frame.measurements {
            if let Some(id) = m.measurement.ground_truth_id {
                by_object.entry(id).or_default().push(m);
            }
        }
        for (id, detections) in by_object {
            groups.push((frame, truth.object(id).expect("a detected object exists"), detections));
        }
    }
    groups
}

/// Standard deviation of the position noise of one point at `range` and `azimuth`, metres.
fn position_sigma(config: &ScenarioConfig, mount: &RadarMount, range: f64, azimuth: f64) -> f64 {
    let radar = &config.radar;
    let sigma_azimuth =
        radar.azimuth_noise_deg.to_radians() * mount.azimuth_noise_scale / azimuth.cos().max(0.5);
    radar.range_noise_m.hypot(range * sigma_azimuth) + range * mount.azimuth_bias_deg.to_radians().abs()
}

#[test]
fn cars_give_several_detections_per_scan_and_pedestrians_one_or_two() {
    let (mut cars, mut car_detections, mut pedestrians, mut pedestrian_detections) = (0, 0, 0, 0);
    let mut most_per_car = 0;
    for (_, object, detections) in object_groups() {
        if object.class == ObjectClass::Pedestrian {
            pedestrians += 1;
            pedestrian_detections += detections.len();
            assert!(detections.len() <= 2, "{} detections of a pedestrian", detections.len());
        } else {
            cars += 1;
            car_detections += detections.len();
            most_per_car = most_per_car.max(detections.len());
        }
    }
    let per_car = car_detections as f64 / cars as f64;
    let per_pedestrian = pedestrian_detections as f64 / pedestrians as f64;
    assert!(cars > 1000 && pedestrians > 300, "{cars} car scans, {pedestrians} pedestrian scans");
    assert!((3.5..=5.0).contains(&per_car), "{per_car} detections per detected car and scan");
    assert!((1.2..=1.6).contains(&per_pedestrian), "{per_pedestrian} detections per detected pedestrian");
    assert!(most_per_car <= config().point_cloud.max_detections_per_car as usize);
}

#[test]
fn car_detections_are_single_points_spread_over_the_outline_not_averages() {
    let config = config();
    let (mut checked, mut spread_over_a_metre, mut groups) = (0usize, 0usize, 0usize);
    for (frame, object, detections) in object_groups() {
        if object.class == ObjectClass::Pedestrian || detections.len() < 3 {
            continue;
        }
        let mount = mount_of(&config, frame);
        let pose = frame.ego_pose.expect("ego pose");
        let centre = pose.world_to_car(object.position);
        let direction = DVec2::from_angle(object.heading_rad - pose.yaw_rad);
        let half = DVec2::new(object.length_m, object.width_m) / 2.0;
        for m in &detections {
            let measured = m.measurement.position();
            let rel = measured - mount.layout.position();
            let azimuth = wrap_angle(rel.to_angle() - mount.layout.yaw_rad);
            let local =
                DVec2::new((measured - centre).dot(direction), (measured - centre).dot(direction.perp()));
            // Distance from the box outline: outside, or inside up to the nearer face.
            let outside = (local.abs() - half).max(DVec2::ZERO).length();
            let inside = (half - local.abs()).min_element().max(0.0);
            let tolerance = 5.0 * position_sigma(&config, &mount, rel.length(), azimuth);
            assert!(outside.max(inside) <= tolerance, "{measured:?} is off the outline of {object:?}");
            checked += 1;
        }
        let spread = detections
            .iter()
            .flat_map(|a| {
                detections.iter().map(move |b| a.measurement.position().distance(b.measurement.position()))
            })
            .fold(0.0, f64::max);
        groups += 1;
        spread_over_a_metre += usize::from(spread > 1.0);
    }
    assert!(checked > 3000, "{checked} detections checked");
    let share = spread_over_a_metre as f64 / groups as f64;
    assert!(share > 0.8, "only {share} of the cars' point sets spread over more than a metre");
}

#[test]
fn wheel_returns_move_between_standstill_and_twice_the_car_speed() {
    let config = config();
    let radar = &config.radar;
    // The Doppler noise, the scan's compensation error and the yaw rate's share over a lever
    // mis-measured by the position noise.
    let noise = 6.0 * radar.doppler_noise_mps.hypot(radar.scan_doppler_bias_mps) + 0.1;
    let mut fractions = Vec::new();
    let mut body = 0usize;
    for (frame, object, detections) in object_groups() {
        if object.class == ObjectClass::Pedestrian || object.speed_mps < 4.0 {
            continue;
        }
        let pose = frame.ego_pose.expect("ego pose");
        let mount = mount_of(&config, frame);
        let velocity = pose.rotate_to_car(object.velocity());
        let heading = velocity.normalize();
        let centre = pose.world_to_car(object.position);
        for m in detections {
            let measured = m.measurement.position();
            let line_of_sight = (measured - mount.layout.position()).normalize();
            let along = object.speed_mps * heading.dot(line_of_sight);
            if along.abs() < 3.0 {
                continue;
            }
            let rigid = (velocity + (measured - centre).perp() * object.yaw_rate_radps).dot(line_of_sight);
            let residual = m.measurement.radial_velocity_mps - rigid;
            // A wheel point moves at (1 − u·cos φ) times the body's speed: the residual is
            // (factor − 1) times the body's radial velocity, factor in [0, 2].
            let fraction = residual / along;
            assert!(
                fraction.abs() <= 1.0 + noise / along.abs(),
                "residual {residual} m/s against {along} m/s"
            );
            if residual.abs() > noise {
                fractions.push(fraction);
            } else {
                body += 1;
            }
        }
    }
    let total = fractions.len() + body;
    let wheel_like = fractions.len() as f64 / total as f64;
    // A fifth of the detections are wheel returns; those near the body's speed hide in the noise.
    assert!(
        total > 2000 && (0.08..=0.2).contains(&wheel_like),
        "{} of {total} off the body's",
        fractions.len()
    );
    let slowest = fractions.iter().copied().fold(f64::INFINITY, f64::min);
    let fastest = fractions.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        slowest < -0.8 && fastest > 0.8,
        "wheel points between {slowest} and {fastest} of the body's speed"
    );
}

#[test]
fn ghosts_lie_behind_a_wall_mirror_a_real_object_and_are_marked() {
    let config = config();
    let block = config.road.block_length_m;
    let wall_offset = config.point_cloud.wall_offset_m;
    let (mut ghosts, mut scans) = (0usize, 0usize);
    for (frame, truth) in frames() {
        scans += 1;
        let mount = mount_of(&config, frame);
        let pose = frame.ego_pose.expect("ego pose");
        let sensor = pose.point_to_world(mount.layout.position());
        let walls = walls_near(sensor, mount.layout.max_range_m, block, wall_offset);
        for m in frame.measurements.iter().filter(|m| m.origin == Some(MeasurementOrigin::Ghost)) {
            assert_eq!((m.measurement.ground_truth_id, m.true_position), (None, None));
            let ghost = pose.point_to_world(m.measurement.position());
            let rel = m.measurement.position() - mount.layout.position();
            let sigma = position_sigma(
                &config,
                &mount,
                rel.length(),
                wrap_angle(rel.to_angle() - mount.layout.yaw_rad),
            );
            let line_of_sight = (ghost - sensor).normalize();
            // A wall with the sensor in front, the ghost behind, and a real object (partly) in
            // front whose mirror image lies at the ghost, moving with the ghost's radial
            // velocity.
            let explained = walls.iter().any(|wall| {
                wall.side(sensor) > 0.0
                    && wall.side(ghost) < 4.0 * sigma
                    && truth.objects.iter().any(|object| {
                        let reach = 0.5 * object.length_m.hypot(object.width_m);
                        let velocity = wall.mirror_vector(object.velocity());
                        // Doppler noise, the rotation over the lever of the mirrored point,
                        // and the direction from the sensor to a point anywhere on the
                        // mirrored box or to the noisy ghost.
                        let vr_tolerance = 0.5
                            + object.yaw_rate_radps.abs() * reach
                            + object.speed_mps * (reach + 4.0 * sigma) / rel.length();
                        // Some of the object's box lies on the road side.
                        wall.side(object.position) > -reach
                            && wall.mirror(object.position).distance(ghost) < reach + 4.0 * sigma
                            && (velocity.dot(line_of_sight) - m.measurement.radial_velocity_mps).abs()
                                < vr_tolerance
                    })
            });
            assert!(explained, "ghost at {ghost:?} (frame {}) mirrors no object behind a wall", frame.index);
            ghosts += 1;
        }
        for m in &frame.measurements {
            let real = m.measurement.ground_truth_id.is_some();
            assert_eq!(m.origin == Some(MeasurementOrigin::Object), real);
            assert!(m.origin.is_some());
        }
    }
    let per_scan = ghosts as f64 / scans as f64;
    assert!((0.1..=3.0).contains(&per_scan), "{per_scan} ghost detections per scan");
}

#[test]
fn about_a_tenth_of_the_labels_are_wrong_and_about_three_clutter_points_come_per_scan() {
    let (mut detections, mut flipped) = (0usize, 0usize);
    for (_, object, group) in object_groups() {
        for m in group {
            detections += 1;
            flipped += usize::from(m.measurement.class != object.class);
        }
    }
    let share = flipped as f64 / detections as f64;
    assert!((0.085..=0.115).contains(&share), "{share} of the labels flipped");
    let frames: Vec<_> = frames().collect();
    let clutter = frames
        .iter()
        .flat_map(|(f, _)| &f.measurements)
        .filter(|m| m.origin == Some(MeasurementOrigin::Clutter))
        .count();
    let per_scan = clutter as f64 / frames.len() as f64;
    assert!((2.7..=3.3).contains(&per_scan), "{per_scan} clutter points per scan");
}

#[test]
fn pedestrians_walk_in_groups_side_by_side() {
    let (mut walking, mut beside_another) = (0usize, 0usize);
    for (_, truth) in frames() {
        let pedestrians: Vec<&ObjectState> = truth
            .objects
            .iter()
            .filter(|o| o.class == ObjectClass::Pedestrian && o.speed_mps > 0.5)
            .collect();
        for a in &pedestrians {
            walking += 1;
            let heading = DVec2::from_angle(a.heading_rad);
            beside_another += usize::from(pedestrians.iter().any(|b| {
                let offset = b.position - a.position;
                b.id != a.id
                    && (0.5..=1.4).contains(&offset.dot(heading.perp()).abs())
                    && offset.dot(heading).abs() < 0.8
                    && (b.velocity() - a.velocity()).length() < 0.5
            }));
        }
    }
    let share = beside_another as f64 / walking as f64;
    assert!(share > 0.25, "{share} of the walking pedestrians walk beside another");
}

#[test]
fn frames_stay_well_within_the_frame_capacity_and_survive_a_file() {
    let largest = frames().map(|(f, _)| f.measurements.len()).max().expect("frames");
    // Half the capacity: the model never comes near truncating a frame.
    assert!(largest <= MAX_MEASUREMENTS_PER_FRAME / 2, "{largest} detections in one frame");
    assert!(largest > 20, "{largest} detections in the largest frame");
    let generated = &sequences()[0];
    let mut text = Vec::new();
    write_sequence(&mut text, &generated.sequence).expect("write");
    let read = read_sequence(text.as_slice(), &generated.sequence.name).expect("read");
    assert_eq!(read, generated.sequence);
}
