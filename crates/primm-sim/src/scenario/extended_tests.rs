//! Properties of the extended-object measurement model of vehicles, and the guarantee that the
//! presets without it are unchanged.

use glam::DVec2;

use super::config::{ExtendedObjectConfig, Preset, RadarMount, ScenarioConfig};
use super::kinematics::wrap_angle;
use super::{GeneratedSequence, ObjectState, ScenarioGenerator, Split};
use crate::io::{read_sequence_file, MeasurementOrigin, RecordedFrame, RecordedMeasurement};
use primm_core::measurement::ObjectClass;
use primm_core::pose::SensorMount;

/// Sequences of `config` (shortened to `duration_s`) of the evaluation split.
fn sequences(mut config: ScenarioConfig, duration_s: f64, count: u32) -> Vec<GeneratedSequence> {
    config.sequence.duration_s = duration_s;
    let generator = ScenarioGenerator::new(config).expect("valid configuration");
    (0..count).map(|index| generator.generate(Split::Evaluation, index)).collect()
}

fn mount_of(config: &ScenarioConfig, frame: &RecordedFrame) -> RadarMount {
    let id = frame.sensor_id.expect("sensor id");
    config.radar.sensors.iter().find(|s| s.layout.id == id).expect("known sensor").clone()
}

/// An object's box in the car frame of one frame: corners counter-clockwise.
struct CarFrameBox {
    centre: DVec2,
    corners: [DVec2; 4],
}

impl CarFrameBox {
    fn new(object: &ObjectState, frame: &RecordedFrame) -> Self {
        let pose = frame.ego_pose.expect("ego pose");
        let centre = pose.world_to_car(object.position);
        let direction = DVec2::from_angle(object.heading_rad - pose.yaw_rad);
        let f = direction * (object.length_m / 2.0);
        let l = direction.perp() * (object.width_m / 2.0);
        Self { centre, corners: [centre - f - l, centre + f - l, centre + f + l, centre - f + l] }
    }

    /// The faces (as segments) turned towards `sensor`.
    fn visible_faces(&self, sensor: DVec2) -> Vec<(DVec2, DVec2)> {
        (0..4)
            .map(|k| (self.corners[k], self.corners[(k + 1) % 4]))
            .filter(|(a, b)| {
                let edge = *b - *a;
                let outward = DVec2::new(edge.y, -edge.x);
                outward.dot(sensor - 0.5 * (*a + *b)) > 0.0
            })
            .collect()
    }

    /// Whether the whole box lies within the sensor's field of view (shrunk by `margin_rad`)
    /// and nearer than `range_m`.
    fn inside_view(&self, mount: &SensorMount, margin_rad: f64, range_m: f64) -> bool {
        let origin = mount.position();
        self.corners.iter().all(|corner| {
            let rel = *corner - origin;
            let azimuth = wrap_angle(rel.to_angle() - mount.yaw_rad);
            rel.length() < range_m && azimuth.abs() < mount.half_fov_rad - margin_rad
        })
    }
}

fn distance_to_segment(p: DVec2, (a, b): (DVec2, DVec2)) -> f64 {
    let edge = b - a;
    let along = ((p - a).dot(edge) / edge.length_squared()).clamp(0.0, 1.0);
    p.distance(a + edge * along)
}

/// The vehicle detections of `generated` with their frame and true object.
fn vehicle_detections(
    generated: &GeneratedSequence,
) -> impl Iterator<Item = (&RecordedFrame, &RecordedMeasurement, &ObjectState)> {
    generated.sequence.frames.iter().zip(&generated.truth).flat_map(|(frame, truth)| {
        frame.measurements.iter().filter_map(move |m| {
            let id = m.measurement.ground_truth_id?;
            let object = truth.object(id).expect("a measured object exists");
            (object.class != ObjectClass::Pedestrian).then_some((frame, m, object))
        })
    })
}

#[test]
fn detections_lie_on_the_visible_contour_of_the_box() {
    let config = Preset::Extended.config();
    let radar = config.radar.clone();
    let mut checked = 0usize;
    let mut nearer_than_centre = 0usize;
    let mut on_corner = 0usize;
    for generated in sequences(config.clone(), 5.0, 6) {
        for (frame, m, object) in vehicle_detections(&generated) {
            let mount = mount_of(&config, frame);
            let sensor = mount.layout.position();
            let body = CarFrameBox::new(object, frame);
            assert_eq!(m.true_position, Some(body.centre), "the truth stays the object centre");
            let measured = m.measurement.position();
            let range = measured.distance(sensor);
            let azimuth = wrap_angle((measured - sensor).to_angle() - mount.layout.yaw_rad);
            // Noise of one point: range noise, azimuth noise growing off boresight, and the
            // sensor's misalignment.
            let sigma_azimuth =
                radar.azimuth_noise_deg.to_radians() * mount.azimuth_noise_scale / azimuth.cos().max(0.5);
            let sigma = radar.range_noise_m.hypot(range * sigma_azimuth);
            let tolerance = 5.0 * sigma + range * mount.azimuth_bias_deg.to_radians().abs() + 1e-9;
            let faces = body.visible_faces(sensor);
            assert!(!faces.is_empty());
            let to_visible =
                faces.iter().map(|face| distance_to_segment(measured, *face)).fold(f64::INFINITY, f64::min);
            assert!(
                to_visible <= tolerance,
                "detection {measured:?} is {to_visible} m from the visible contour (tolerance {tolerance}) of {object:?}"
            );
            checked += 1;
            nearer_than_centre += usize::from(range < body.centre.distance(sensor));
            on_corner +=
                usize::from(body.corners.iter().any(|corner| corner.distance(measured) <= 2.0 * sigma));
        }
    }
    assert!(checked > 1500, "only {checked} vehicle detections");
    // The visible side faces the sensor: detections are nearer than the centre.
    assert!(nearer_than_centre as f64 > 0.9 * checked as f64, "{nearer_than_centre} of {checked}");
    // Corners are favoured: far more detections sit at a corner than a uniform spread along
    // the contour would put there.
    let corner_share = on_corner as f64 / checked as f64;
    assert!(corner_share > 0.3, "corner share {corner_share}");
}

#[test]
fn radial_velocity_and_true_velocity_are_those_of_the_rigid_body() {
    let config = Preset::ExtendedTurning.config();
    let mut residuals = Vec::new();
    for generated in sequences(config.clone(), 4.0, 3) {
        for (frame, m, object) in vehicle_detections(&generated) {
            let pose = frame.ego_pose.expect("ego pose");
            let velocity = pose.rotate_to_car(object.velocity());
            let true_velocity = m.true_velocity.expect("true velocity");
            assert!(true_velocity.distance(velocity) < 1e-9, "{true_velocity:?} against {velocity:?}");
            let mount = mount_of(&config, frame);
            let measured = m.measurement.position();
            let line_of_sight = (measured - mount.layout.position()).normalize();
            let lever = measured - m.true_position.expect("true position");
            let point_velocity = velocity + lever.perp() * object.yaw_rate_radps;
            residuals.push(m.measurement.radial_velocity_mps - point_velocity.dot(line_of_sight));
        }
    }
    let n = residuals.len() as f64;
    let mean = residuals.iter().sum::<f64>() / n;
    let std = (residuals.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / n).sqrt();
    assert!(residuals.len() > 1000);
    assert!(mean.abs() < 0.1, "radial velocity bias {mean}");
    assert!(std < 0.6 && std > 0.01, "radial velocity residual std {std}");
}

#[test]
fn several_detections_of_one_vehicle_arrive_at_the_configured_rate() {
    // No losses: every reflection centre of a vehicle wholly inside the field of view is
    // detected, so the counts per vehicle and scan follow the configured distribution.
    let mut config = ScenarioConfig::extended(Preset::Default);
    config.extended_objects.detection_count_probabilities = vec![0.6, 0.3, 0.1];
    config.radar.miss_probability = 0.0;
    config.radar.occluded_point_probability = 1.0;
    config.radar.fade_start_fraction = 1.0;
    let mut histogram = [0usize; 4];
    for generated in sequences(config.clone(), 7.0, 6) {
        for (frame, truth) in generated.sequence.frames.iter().zip(&generated.truth) {
            let mount = mount_of(&config, frame);
            for object in truth.objects.iter().filter(|o| o.class != ObjectClass::Pedestrian) {
                if !CarFrameBox::new(object, frame).inside_view(&mount.layout, 2f64.to_radians(), 90.0) {
                    continue;
                }
                let count = frame
                    .measurements
                    .iter()
                    .filter(|m| m.measurement.ground_truth_id == Some(object.id))
                    .count();
                histogram[count.min(3)] += 1;
            }
        }
    }
    let total: usize = histogram.iter().sum();
    assert!(total > 1500, "only {total} vehicle scans: {histogram:?}");
    assert_eq!(histogram[0], 0, "a vehicle wholly in view without losses is always detected");
    for (k, expected) in [0.6, 0.3, 0.1].into_iter().enumerate() {
        let share = histogram[k + 1] as f64 / total as f64;
        assert!((share - expected).abs() < 0.035, "{} detections: share {share}, expected {expected}", k + 1);
    }

    // The preset itself: several detections now and then, pedestrians always one.
    let config = Preset::Extended.config();
    let (mut scans, mut multiple) = (0usize, 0usize);
    for generated in sequences(config, 4.0, 2) {
        for frame in &generated.sequence.frames {
            let mut ids: Vec<(u64, ObjectClass)> = frame
                .measurements
                .iter()
                .filter_map(|m| m.measurement.ground_truth_id.map(|id| (id, m.measurement.class)))
                .collect();
            ids.sort_unstable_by_key(|(id, _)| *id);
            for chunk in ids.chunk_by(|a, b| a.0 == b.0) {
                if chunk[0].1 == ObjectClass::Pedestrian {
                    assert_eq!(chunk.len(), 1);
                } else {
                    scans += 1;
                    multiple += usize::from(chunk.len() > 1);
                }
            }
        }
    }
    let share = multiple as f64 / scans as f64;
    assert!((0.05..0.25).contains(&share), "{multiple} of {scans} vehicle scans with several detections");
}

#[test]
fn extended_vehicles_leave_traffic_and_timing_as_they_are() {
    for (extended, base) in
        [(Preset::Extended, Preset::Default), (Preset::ExtendedClutterTurning, Preset::ClutterTurning)]
    {
        let mut with = extended.config();
        with.sequence.duration_s = 2.0;
        let mut without = with.clone();
        without.extended_objects = ExtendedObjectConfig::default();
        let mut reference = base.config();
        reference.sequence.duration_s = 2.0;
        reference.splits.seed_base = with.splits.seed_base;
        assert_eq!(without, reference);
        let seed = 77;
        let a = ScenarioGenerator::new(with).expect("valid").generate_seeded(seed, "a");
        let b = ScenarioGenerator::new(without).expect("valid").generate_seeded(seed, "a");
        assert_eq!(a.truth, b.truth);
        let timing = |g: &GeneratedSequence| -> Vec<(u64, f64, Option<u16>)> {
            g.sequence.frames.iter().map(|f| (f.index, f.timestamp_s, f.sensor_id)).collect()
        };
        assert_eq!(timing(&a), timing(&b));
        assert_ne!(a.sequence, b.sequence);
    }
}

/// The presets without extended objects generate exactly what they generated before the model
/// existed: the fixtures were written by `primm generate --split evaluation --sequences 1
/// --duration-s 1.5 --preset P` before extended objects, true velocities and origins were
/// added, so they hold no velocity and no origin columns.
#[test]
fn presets_without_extended_objects_are_unchanged() {
    let directory = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/presets");
    for preset in
        [Preset::Default, Preset::Robustness, Preset::Turning, Preset::Clutter, Preset::ClutterTurning]
    {
        let path = directory.join(format!("{}.csv", preset.name()));
        let expected = read_sequence_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut generated = sequences(preset.config(), 1.5, 1).remove(0).sequence;
        for measurement in generated.frames.iter_mut().flat_map(|f| f.measurements.iter_mut()) {
            let real = measurement.measurement.ground_truth_id.is_some();
            assert_eq!(measurement.true_velocity.is_some(), real, "{preset}");
            assert_eq!(measurement.origin == Some(MeasurementOrigin::Object), real, "{preset}");
            assert!(measurement.origin.is_some(), "{preset}: every generated row says where it came from");
            measurement.true_velocity = None;
            measurement.origin = None;
        }
        assert_eq!(generated.frames, expected.frames, "{preset} changed");
        assert!(expected.measurement_count() > 20, "{preset}: a fixture with too few measurements");
    }
}
