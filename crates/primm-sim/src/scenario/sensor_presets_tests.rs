//! Tests of the object-list radar (`centroid`) and static roadside sensor (`dense_static`)
//! presets.

use glam::DVec2;

use super::{GeneratedSequence, Preset, ScenarioGenerator, Split};
use crate::io::{read_sequence, write_sequence};
use primm_core::measurement::ObjectClass;
use primm_core::pose::SensorMount;

/// Validation sequence `index` of `preset`, `duration_s` long.
fn generate(preset: Preset, duration_s: f64, index: u32) -> GeneratedSequence {
    let mut config = preset.config();
    config.sequence.duration_s = duration_s;
    ScenarioGenerator::new(config).expect("a valid preset").generate(Split::Validation, index)
}

/// Range and azimuth of `point` (car frame) seen from `mount`.
fn polar(mount: &SensorMount, point: DVec2) -> (f64, f64) {
    let relative = DVec2::from_angle(-mount.yaw_rad).rotate(point - mount.position());
    (relative.length(), relative.y.atan2(relative.x))
}

#[test]
fn centroid_detections_lie_at_the_true_centre_within_the_radars_noise() {
    let config = Preset::Centroid.config();
    let radar = &config.radar;
    let generated = generate(Preset::Centroid, 3.0, 0);
    let mut range_errors = Vec::new();
    for frame in &generated.sequence.frames {
        let mount = radar.sensors.iter().find(|sensor| Some(sensor.layout.id) == frame.sensor_id).unwrap();
        for recorded in &frame.measurements {
            let Some(centre) = recorded.true_position else { continue };
            let (true_range, true_azimuth) = polar(&mount.layout, centre);
            let (range, azimuth) = polar(&mount.layout, recorded.measurement.position());
            let range_error = range - true_range;
            assert!(range_error.abs() < 5.0 * radar.range_noise_m, "range error {range_error} m");
            let azimuth_std = radar.azimuth_noise_deg.to_radians() * mount.azimuth_noise_scale
                / true_azimuth.cos().max(0.5);
            let azimuth_error = wrapped(azimuth - true_azimuth - mount.azimuth_bias_deg.to_radians());
            assert!(azimuth_error.abs() < 5.0 * azimuth_std, "azimuth error {azimuth_error} rad");
            range_errors.push(range_error);
        }
    }
    assert!(range_errors.len() > 200, "{} detections", range_errors.len());
    let mean = range_errors.iter().sum::<f64>() / range_errors.len() as f64;
    // The mean of n draws of the range noise: within 4 standard errors of zero.
    assert!(mean.abs() < 4.0 * radar.range_noise_m / (range_errors.len() as f64).sqrt(), "mean {mean} m");
}

/// `angle` wrapped into (−π, π].
fn wrapped(angle: f64) -> f64 {
    DVec2::from_angle(angle).to_angle()
}

#[test]
fn dense_static_frames_carry_no_pose_and_no_sensor_id_even_through_a_file() {
    let generated = generate(Preset::DenseStatic, 2.0, 0);
    let mut text = Vec::new();
    write_sequence(&mut text, &generated.sequence).expect("write");
    let read = read_sequence(text.as_slice(), "dense").expect("read");
    assert_eq!(read.frames.len(), generated.sequence.frames.len());
    for sequence in [&generated.sequence, &read] {
        assert!(!sequence.has_ego_pose());
        for frame in &sequence.frames {
            assert_eq!(frame.sensor_id, None);
            assert!(frame.measurements.iter().all(|m| m.measurement.sensor_id.is_none()));
        }
    }
    // The ground truth still knows the sensor, and the platform never moves.
    let first = generated.truth[0].ego.pose;
    for truth in &generated.truth {
        assert_eq!(truth.sensor_id, Preset::DenseStatic.config().radar.sensors[0].layout.id);
        assert_eq!(truth.ego.pose, first);
        assert_eq!(truth.ego.speed_mps, 0.0);
    }
}

#[test]
fn dense_static_holds_25_to_45_objects_in_view_on_average_scanned_every_50_to_80_ms() {
    let config = Preset::DenseStatic.config();
    let mount = config.radar.sensors[0].layout;
    for index in 0..3 {
        let generated = generate(Preset::DenseStatic, config.sequence.duration_s, index);
        let frames = &generated.sequence.frames;
        for pair in frames.windows(2) {
            let interval = pair[1].timestamp_s - pair[0].timestamp_s;
            assert!((0.05..=0.08).contains(&interval), "interval {interval} s");
        }
        let mut in_view = 0usize;
        for truth in &generated.truth {
            in_view += truth
                .objects
                .iter()
                .filter(|object| {
                    let (range, azimuth) = polar(&mount, truth.ego.pose.world_to_car(object.position));
                    range <= mount.max_range_m && azimuth.abs() <= mount.half_fov_rad
                })
                .count();
        }
        let mean = in_view as f64 / generated.truth.len() as f64;
        assert!((25.0..=45.0).contains(&mean), "sequence {index}: {mean} objects in view on average");
        for class in [ObjectClass::Car, ObjectClass::Pedestrian] {
            assert!(generated.sequence.class_count(class) > 500, "sequence {index}: few {class:?}");
        }
        let clutter =
            frames.iter().flat_map(|f| &f.measurements).filter(|m| m.measurement.ground_truth_id.is_none());
        let per_scan = clutter.count() as f64 / frames.len() as f64;
        assert!(per_scan > 0.1 && per_scan < 1.0, "sequence {index}: {per_scan} false detections per scan");
    }
}

#[test]
fn dense_static_car_detections_lie_closer_to_the_sensor_than_the_car_centres() {
    let config = Preset::DenseStatic.config();
    let mount = config.radar.sensors[0].layout;
    let generated = generate(Preset::DenseStatic, 3.0, 0);
    let (mut sum, mut count) = (0.0, 0usize);
    for recorded in generated.sequence.frames.iter().flat_map(|frame| &frame.measurements) {
        let Some(centre) = recorded.true_position else { continue };
        if recorded.measurement.class == ObjectClass::Car {
            sum += polar(&mount, recorded.measurement.position()).0 - polar(&mount, centre).0;
            count += 1;
        }
    }
    assert!(count > 200, "{count} car detections");
    let mean = sum / count as f64;
    assert!(mean < -0.3, "car detections lie {mean} m from the centre's range");
}

#[test]
fn a_centre_report_cannot_be_combined_with_extended_objects() {
    let mut config = Preset::Extended.config();
    config.radar.report = super::RadarReport::Centre;
    let error = config.validate().unwrap_err();
    assert_eq!(error.field, "extended_objects.enabled");
}
