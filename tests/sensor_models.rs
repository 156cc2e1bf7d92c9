//! Each radar's measurement model and what the tracker learns of it (`crate::sensor`,
//! ARCHITECTURE.md "Sensors and their estimates"): `reflection = "centre"` tracks an
//! object-list radar's detections at the centre, `"auto"` moves from its prior towards the data,
//! an estimate without evidence stays at its prior, the detection and clutter estimates count
//! what they see (a car hidden behind another gives no misses), late frames leave every estimate as in-order arrival does, and bad keys are
//! refused by name.

use crate::common::invalid_key;
use glam::DVec2;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::sensor::{ReflectionModel, UNMOUNTED};
use primm_core::tracker::Tracker;

/// A deterministic noise source in [−0.5, 0.5).
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Two all-around radars 12 m to either side of a standing ego, ids 1 and 2, with the given
/// model; cars are extended objects.
fn config(reflection: ReflectionModel) -> Config {
    let mut config = Config::default();
    let template = config.frame.sensors[0];
    config.frame.sensors.clear();
    for (id, y_m) in [(1, -12.0), (2, 12.0)] {
        config.frame.sensors.push(primm_core::pose::SensorMount {
            id,
            x_m: 0.0,
            y_m,
            yaw_rad: 0.0,
            half_fov_rad: std::f64::consts::PI,
            max_range_m: 200.0,
            reflection,
            ..template
        });
    }
    assert!(config.classes.car.extent.enabled);
    config
}

/// Cars driving along the x axis at 10 m/s past the two radars, reported by the radars in turn
/// 50 ms apart at their true centres plus up to ±0.1 m of noise (an object-list radar); one
/// car per pass, `passes` passes. Also the true centre of each frame's car.
fn centre_frames(passes: usize) -> Vec<(Frame, DVec2)> {
    let mut noise = Noise(7);
    let mut frames = Vec::new();
    let mut t = 0.0;
    for pass in 0..passes {
        let y_m = if pass % 2 == 0 { 3.0 } else { -3.0 };
        for k in 0..160 {
            let centre = DVec2::new(-40.0 + 0.5 * k as f64, y_m);
            let sensor_id = 1 + (k % 2) as u16;
            let sensor = DVec2::new(0.0, if sensor_id == 1 { -12.0 } else { 12.0 });
            let velocity = DVec2::new(10.0, 0.0);
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            frame.measurements.push(Measurement {
                x_m: centre.x + 0.2 * noise.next(),
                y_m: centre.y + 0.2 * noise.next(),
                radial_velocity_mps: velocity.dot((centre - sensor).normalize()),
                rcs_dbsm: 10.0,
                class: ObjectClass::Car,
                sensor_id: Some(sensor_id),
                ground_truth_id: Some(pass as u64),
            });
            frames.push((frame, centre));
            t += 0.05;
        }
        // A gap between passes, so that the car's track ends.
        t += 5.0;
    }
    frames
}

/// The root mean square distance of the confirmed car tracks from the true centre over the
/// frames, and the tracker at the end.
fn track_centres(config: Config, frames: &[(Frame, DVec2)]) -> (f64, Tracker) {
    let mut tracker = Tracker::new(config).unwrap();
    let (mut sum, mut count) = (0.0, 0usize);
    for (frame, centre) in frames {
        let outputs = match tracker.step(frame) {
            Ok(outputs) => outputs,
            Err(_) => {
                // The gap between passes: start again.
                tracker.reset();
                tracker.step(frame).unwrap()
            }
        };
        for output in outputs.iter().filter(|o| o.status.is_confirmed()) {
            sum += output.position_m.distance_squared(*centre);
            count += 1;
        }
    }
    assert!(count > 100, "{count}");
    ((sum / count as f64).sqrt(), tracker)
}

#[test]
fn a_centre_sensor_tracks_object_list_detections_at_the_centre_where_the_outline_model_is_off() {
    let frames = centre_frames(2);
    let (centre_error, _) = track_centres(config(ReflectionModel::Centre), &frames);
    let (outline_error, _) = track_centres(config(ReflectionModel::Outline), &frames);
    assert!(centre_error < 0.35, "{centre_error}");
    assert!(outline_error > centre_error + 0.2, "outline {outline_error} centre {centre_error}");
}

#[test]
fn an_auto_sensor_moves_from_its_prior_towards_the_centre_on_object_list_data() {
    let config = config(ReflectionModel::Auto);
    let prior = config.classes.car.extent.offset_scale;
    let (_, tracker) = track_centres(config, &centre_frames(12));
    let slot = tracker.sensors().slot(Some(1));
    let estimate = tracker.sensors().get(slot).estimates[ObjectClass::Car.index()].reflection;
    assert!(estimate.samples > 50, "{estimate:?}");
    assert!(estimate.value < 0.5 * prior, "{estimate:?}");
}

/// Radar 1's detection of a standing car at (`x_m`, `y_m`) with ground-truth id
/// `ground_truth_id`.
fn standing_car(x_m: f64, y_m: f64, ground_truth_id: u64) -> Measurement {
    Measurement {
        x_m,
        y_m,
        radial_velocity_mps: 0.0,
        rcs_dbsm: 10.0,
        class: ObjectClass::Car,
        sensor_id: Some(1),
        ground_truth_id: Some(ground_truth_id),
    }
}

#[test]
fn an_estimate_without_evidence_stays_at_its_prior() {
    // A standing car seen by one radar: the geometry never changes.
    let config = config(ReflectionModel::Auto);
    let prior = config.classes.car.extent.offset_scale;
    let mut tracker = Tracker::new(config).unwrap();
    let mut noise = Noise(3);
    for k in 0..400 {
        let mut frame = Frame::new(k as f64 * 0.05);
        frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
        frame.measurements.push(standing_car(20.0 + 0.1 * noise.next(), -12.0 + 0.1 * noise.next(), 1));
        tracker.step(&frame).unwrap();
    }
    let sensors = tracker.sensors();
    for slot in [sensors.slot(Some(1)), sensors.slot(Some(2)), UNMOUNTED] {
        let estimates = sensors.get(slot).estimates[ObjectClass::Car.index()];
        assert_eq!(estimates.reflection.value, prior, "slot {slot}");
        assert_eq!(estimates.reflection.samples, 0, "slot {slot}");
    }
    // Radar 2 never scanned: its detection and clutter estimates took nothing either.
    let silent = sensors.get(sensors.slot(Some(2))).estimates[ObjectClass::Car.index()];
    assert_eq!((silent.detection.samples, silent.clutter.scans), (0, 0));
}

#[test]
fn the_detection_estimate_follows_how_often_a_radar_reports_a_confirmed_car() {
    // Radar 1 scans every frame and reports the standing car in three scans of four.
    let mut config = config(ReflectionModel::Outline);
    config.frame.estimation.detection_prior_samples = 20.0;
    let mut tracker = Tracker::new(config).unwrap();
    let mut noise = Noise(5);
    for k in 0..3000 {
        let mut frame = Frame::new(k as f64 * 0.05);
        frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
        // In the fourth scan the radar reports a false detection somewhere else (never twice at
        // one place, so it confirms nothing) instead of the car.
        let (x_m, y_m, ground_truth_id) = if k % 4 == 3 {
            (-60.0 + 100.0 * noise.next(), 60.0 + 100.0 * noise.next(), 9)
        } else {
            (20.0, -5.0, 1)
        };
        frame.measurements.push(standing_car(x_m, y_m, ground_truth_id));
        tracker.step(&frame).unwrap();
    }
    let sensors = tracker.sensors();
    let detection = sensors.get(sensors.slot(Some(1))).estimates[ObjectClass::Car.index()].detection;
    let value = detection.value();
    assert!(detection.samples > 1000, "{detection:?}");
    assert!((value - 0.75).abs() < 0.08, "{value} {detection:?}");
}

/// Radar 1's detection estimate for cars after two standing cars were tracked for 3,000 scans:
/// one 20 m ahead of the radar reported in every scan, the other at `far_m` reported in every
/// scan for the first 100 and then in one of four.
fn detection_estimate_with_a_car_at(far_m: DVec2) -> f64 {
    let mut config = config(ReflectionModel::Outline);
    config.frame.estimation.detection_prior_samples = 20.0;
    let mut tracker = Tracker::new(config).unwrap();
    for k in 0..3000 {
        let mut frame = Frame::new(k as f64 * 0.05);
        frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
        let far_reported = k < 100 || k % 4 == 0;
        let cars = [(DVec2::new(20.0, -12.0), 1, true), (far_m, 2, far_reported)];
        for (position, ground_truth_id, reported) in cars {
            if reported {
                frame.measurements.push(standing_car(position.x, position.y, ground_truth_id));
            }
        }
        tracker.step(&frame).unwrap();
    }
    let confirmed = tracker.tracks().iter().filter(|track| track.status.is_confirmed()).count();
    assert_eq!(confirmed, 2, "both cars are tracked throughout");
    let sensors = tracker.sensors();
    let detection = sensors.get(sensors.slot(Some(1))).estimates[ObjectClass::Car.index()].detection;
    assert!(detection.samples > 3000, "{detection:?}");
    detection.value()
}

#[test]
fn a_car_hidden_behind_another_confirmed_car_gives_no_misses_to_the_detection_estimate() {
    // Radar 1 stands at (0, −12) and looks along x: a car 40 m ahead is behind the one 20 m
    // ahead, and its misses are not the radar's; its detections still count.
    let hidden = detection_estimate_with_a_car_at(DVec2::new(40.0, -12.0));
    assert!(hidden > 0.95, "{hidden}");
    // The same car in clear view, 12 m to the side: its misses count, and the estimate falls
    // towards (1 + 1/4) / 2.
    let in_clear_view = detection_estimate_with_a_car_at(DVec2::new(40.0, 0.0));
    assert!((in_clear_view - 0.625).abs() < 0.08, "{in_clear_view}");
}

#[test]
fn clutter_that_never_confirms_raises_the_clutter_estimate_above_its_prior() {
    let config = config(ReflectionModel::Outline);
    let prior = config.classes.car.existence.clutter_density_per_m2;
    let mut tracker = Tracker::new(config).unwrap();
    let mut noise = Noise(11);
    for k in 0..2000 {
        let mut frame = Frame::new(k as f64 * 0.05);
        frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
        // Ten false detections a scan, scattered over 200 m, never twice at one place.
        for _ in 0..10 {
            frame.measurements.push(Measurement {
                x_m: 200.0 * noise.next(),
                y_m: 200.0 * noise.next(),
                radial_velocity_mps: 0.0,
                rcs_dbsm: 0.0,
                class: ObjectClass::Car,
                sensor_id: Some(1),
                ground_truth_id: None,
            });
        }
        tracker.step(&frame).unwrap();
    }
    let sensors = tracker.sensors();
    let clutter = sensors.get(sensors.slot(Some(1))).estimates[ObjectClass::Car.index()].clutter;
    let value = clutter.value_per_m2();
    // Ten per scan over a 200 m all-around field of view: 10 / (π · 200²) ≈ 8e-5 /m² of clutter
    // that the sensor's field holds; the estimate sees those whose tracks ended unconfirmed.
    assert!(clutter.scans == 2000, "{clutter:?}");
    assert!(value > 0.3 * 10.0 / (std::f64::consts::PI * 200.0 * 200.0), "{value} (prior {prior})");
    assert!(value < 2.0 * 10.0 / (std::f64::consts::PI * 200.0 * 200.0), "{value}");
}

#[test]
fn late_frames_leave_every_estimate_as_in_order_arrival_does() {
    let mut config = config(ReflectionModel::Auto);
    config.tracker.max_frame_delay_s = 0.2;
    config.tracker.replay_frames = 8;
    let frames: Vec<Frame> = centre_frames(1).into_iter().map(|(frame, _)| frame).collect();
    let mut in_order = Tracker::new(config.clone()).unwrap();
    for frame in &frames {
        in_order.step(frame).unwrap();
    }
    // Every tenth pair of neighbouring frames arrives swapped.
    let mut shuffled = frames.clone();
    for k in (10..shuffled.len() - 1).step_by(10) {
        shuffled.swap(k, k + 1);
    }
    let mut late = Tracker::new(config).unwrap();
    for frame in &shuffled {
        late.step(frame).unwrap();
    }
    assert!(late.stats().frames_replayed > 0);
    assert_eq!(late.sensors(), in_order.sensors());
}

#[test]
fn bad_sensor_model_keys_are_refused_by_name() {
    let text = primm_config::DEFAULT_CONFIG_TOML.replacen(
        "range_std_m = 0.12",
        "range_std_m = 0.12\nreflection = \"sideways\"",
        1,
    );
    let error = primm_config::from_toml_str(&text).unwrap_err().to_string();
    assert!(error.contains("sideways") && error.contains("outline"), "{error}");
    for (prior, window) in [(0.0, 400.0), (50.0, f64::NAN), (-1.0, 400.0)] {
        let mut config = Config::default();
        config.frame.estimation.reflection_prior_samples = prior;
        config.frame.estimation.reflection_window_samples = window;
        assert_eq!(invalid_key(Tracker::new(config)), "frame.estimation");
    }
    let mut twice = Config::default();
    let first = twice.frame.sensors[0];
    twice.frame.sensors.push(first);
    assert_eq!(invalid_key(Tracker::new(twice)), "frame.sensors");
}

#[test]
fn the_object_list_sensor_file_is_the_shipped_configuration_with_every_radar_at_the_centre() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/sensors/object_list.toml");
    let object_list = primm_config::from_file(&path).unwrap();
    let mut expected = Config::default();
    expected.frame.unmounted_reflection = ReflectionModel::Centre;
    expected.frame.unmounted_detections = primm_core::grouping::DetectionModel::Objects;
    for mount in expected.frame.sensors.iter_mut() {
        mount.reflection = ReflectionModel::Centre;
        mount.detections = primm_core::grouping::DetectionModel::Objects;
    }
    assert_eq!(object_list, expected);
}
