//! Properties of the scenario generator: determinism, splits, physical plausibility, timing,
//! the measurement model, events and the CSV round trip.

use std::collections::{HashMap, HashSet};
use std::sync::OnceLock;

use glam::DVec2;
use primm_core::measurement::ObjectClass;
use primm_sim::io::{read_sequence, write_sequence, RecordedFrame, Sequence};
use primm_sim::scenario::{
    count_events, GeneratedSequence, ObjectState, Preset, RadarMount, ScenarioConfig, ScenarioGenerator,
    ScenarioTomlError, Split, SplitSummary, TruthFrame, SPLIT_SEED_STRIDE,
};

/// The default evaluation split, generated once and shared by the tests that inspect it.
fn evaluation_split() -> &'static [GeneratedSequence] {
    static SPLIT: OnceLock<Vec<GeneratedSequence>> = OnceLock::new();
    SPLIT.get_or_init(|| {
        ScenarioGenerator::from_preset(Preset::Default).split_sequences(Split::Evaluation).collect()
    })
}

fn short_generator(preset: Preset, duration_s: f64) -> ScenarioGenerator {
    let mut config = preset.config();
    config.sequence.duration_s = duration_s;
    ScenarioGenerator::new(config).expect("valid configuration")
}

fn mount_of(config: &ScenarioConfig, sensor_id: u16) -> &RadarMount {
    config.radar.sensors.iter().find(|s| s.layout.id == sensor_id).expect("known sensor")
}

/// Mean and standard deviation.
fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

#[test]
fn same_seed_reproduces_the_sequence_exactly() {
    let generator = short_generator(Preset::Default, 2.0);
    let a = generator.generate(Split::Validation, 2);
    let b = generator.generate(Split::Validation, 2);
    assert_eq!(a, b);
    let c = generator.generate_seeded(a.seed, &a.sequence.name);
    assert_eq!(a.sequence, c.sequence);
    assert_eq!(a.truth, c.truth);
    assert!(a.sequence.measurement_count() > 0);
}

#[test]
fn different_seeds_give_different_sequences() {
    let generator = short_generator(Preset::Default, 2.0);
    let a = generator.generate(Split::Train, 0);
    let b = generator.generate(Split::Train, 1);
    assert_ne!(a.seed, b.seed);
    assert_ne!(a.sequence.frames, b.sequence.frames);
    let pose = |g: &GeneratedSequence| g.sequence.frames[0].ego_pose.expect("ego pose");
    assert_ne!(pose(&a), pose(&b));
    let timestamps =
        |g: &GeneratedSequence| g.sequence.frames.iter().map(|f| f.timestamp_s).collect::<Vec<_>>();
    assert_ne!(timestamps(&a), timestamps(&b));
}

#[test]
fn split_seed_ranges_are_disjoint_and_sized_like_table_one() {
    let generator = ScenarioGenerator::from_preset(Preset::Default);
    assert_eq!(generator.sequence_count(Split::Train), 130);
    assert_eq!(generator.sequence_count(Split::Validation), 6);
    assert_eq!(generator.sequence_count(Split::Evaluation), 22);
    let base = generator.config().splits.seed_base;
    let mut seen = HashSet::new();
    for (k, split) in Split::ALL.into_iter().enumerate() {
        for index in 0..generator.sequence_count(split) {
            let seed = generator.seed(split, index);
            assert_eq!(
                seed.wrapping_sub(base) / SPLIT_SEED_STRIDE,
                k as u64,
                "{split} seed out of its range"
            );
            assert!(seen.insert(seed), "seed {seed} used twice");
        }
    }
    assert_eq!(seen.len(), 158);
}

/// Per-object consecutive truth states, for finite-difference checks.
fn tracks(truth: &[TruthFrame]) -> HashMap<u64, Vec<(f64, ObjectState)>> {
    let mut tracks: HashMap<u64, Vec<(f64, ObjectState)>> = HashMap::new();
    for frame in truth {
        for object in &frame.objects {
            tracks.entry(object.id).or_default().push((frame.timestamp_s, *object));
        }
    }
    tracks
}

fn check_kinematics(preset: Preset, sequences: u32) -> [f64; 2] {
    let generator = short_generator(preset, 5.0);
    let cfg = generator.config().clone();
    let mut fastest = [0.0f64; 2];
    let mut states = 0usize;
    for index in 0..sequences {
        let generated = generator.generate(Split::Train, index);
        for (id, track) in tracks(&generated.truth) {
            for (t, o) in &track {
                let (max_speed, max_accel, max_decel, max_yaw) = match o.class {
                    ObjectClass::Pedestrian => (
                        cfg.pedestrian.limits.max_speed_mps,
                        cfg.pedestrian.limits.max_acceleration_mps2,
                        cfg.pedestrian.limits.max_deceleration_mps2,
                        cfg.pedestrian.limits.max_yaw_rate_radps,
                    ),
                    _ => (
                        cfg.car.limits.max_speed_mps,
                        cfg.car.limits.max_acceleration_mps2,
                        cfg.car.limits.max_deceleration_mps2,
                        cfg.car.limits.max_yaw_rate_radps,
                    ),
                };
                let ctx = format!("{preset} object {id} ({}) at t = {t}", o.class);
                assert!(
                    o.speed_mps >= 0.0 && o.speed_mps <= max_speed + 1e-9,
                    "{ctx}: speed {}",
                    o.speed_mps
                );
                assert!(
                    o.acceleration_mps2 <= max_accel + 1e-9,
                    "{ctx}: acceleration {}",
                    o.acceleration_mps2
                );
                assert!(
                    o.acceleration_mps2 >= -max_decel - 1e-9,
                    "{ctx}: deceleration {}",
                    o.acceleration_mps2
                );
                assert!(o.yaw_rate_radps.abs() <= max_yaw + 1e-9, "{ctx}: yaw rate {}", o.yaw_rate_radps);
                if o.class == ObjectClass::Car {
                    let lateral = o.speed_mps * o.yaw_rate_radps.abs();
                    assert!(
                        lateral <= cfg.car.limits.max_lateral_acceleration_mps2.expect("a car limit") + 1e-6,
                        "{ctx}: lateral acceleration {lateral}"
                    );
                }
                fastest[o.class.index().min(1)] = fastest[o.class.index().min(1)].max(o.speed_mps);
                states += 1;
            }
            // The reported state must be the one that moves the object.
            for pair in track.windows(2) {
                let ((t0, a), (t1, b)) = (pair[0], pair[1]);
                let dt = t1 - t0;
                let moved = a.position.distance(b.position);
                let expected = 0.5 * (a.speed_mps + b.speed_mps) * dt;
                assert!(
                    (moved - expected).abs() <= 0.02 * expected + 0.01,
                    "{preset} object {id}: moved {moved} m in {dt} s, speeds {} -> {}",
                    a.speed_mps,
                    b.speed_mps
                );
                let max_jerk = if a.class == ObjectClass::Pedestrian {
                    cfg.pedestrian.limits.max_jerk_mps3
                } else {
                    cfg.car.limits.max_jerk_mps3
                };
                let limit_speed = if a.class == ObjectClass::Pedestrian {
                    cfg.pedestrian.limits.max_speed_mps
                } else {
                    cfg.car.limits.max_speed_mps
                };
                let cruising = a.speed_mps > 0.0 && b.speed_mps > 0.0 && b.speed_mps < limit_speed;
                if cruising {
                    let jerk = (b.acceleration_mps2 - a.acceleration_mps2).abs() / dt;
                    assert!(jerk <= max_jerk + 1e-6, "{preset} object {id}: jerk {jerk} at t = {t1}");
                }
            }
        }
    }
    assert!(states > 10_000, "too few object states checked: {states}");
    fastest
}

#[test]
fn kinematic_limits_hold_over_many_sequences() {
    let default = check_kinematics(Preset::Default, 10);
    let cfg = ScenarioConfig::default();
    // Objects really move: cars reach urban speeds, pedestrians walk.
    assert!(default[0] > 0.6 * cfg.car.desired_speed_mps[1], "fastest car {}", default[0]);
    assert!(default[1] > cfg.pedestrian.desired_speed_mps[0], "fastest pedestrian {}", default[1]);
    let robust = check_kinematics(Preset::Robustness, 6);
    assert!(
        robust[0] > default[0],
        "robustness cars ({}) should outpace default cars ({})",
        robust[0],
        default[0]
    );
}

#[test]
fn frames_are_irregular_positive_steps_from_interleaved_sensors() {
    let generated = &evaluation_split()[0];
    let cfg = ScenarioConfig::default();
    let frames = &generated.sequence.frames;
    let dts: Vec<f64> = frames.windows(2).map(|p| p[1].timestamp_s - p[0].timestamp_s).collect();
    assert!(dts.iter().all(|&dt| dt > 0.0), "non-positive time step");
    let (mean, std) = mean_std(&dts);
    let slot = cfg.radar.scan_period_s / cfg.radar.sensors.len() as f64;
    assert!((mean - slot).abs() < 0.001, "mean frame interval {mean} s");
    assert!(std > 0.001, "frame intervals too regular: std {std} s");
    for pair in frames.windows(2) {
        assert_ne!(pair[0].sensor_id, pair[1].sensor_id, "consecutive frames from one sensor");
    }
    let sensors: HashSet<u16> = frames.iter().filter_map(|f| f.sensor_id).collect();
    assert_eq!(sensors.len(), cfg.radar.sensors.len());
    for &sensor in &sensors {
        let times: Vec<f64> =
            frames.iter().filter(|f| f.sensor_id == Some(sensor)).map(|f| f.timestamp_s).collect();
        let (period, _) = mean_std(&times.windows(2).map(|p| p[1] - p[0]).collect::<Vec<_>>());
        assert!((period - cfg.radar.scan_period_s).abs() < 0.002, "sensor {sensor} period {period}");
    }
    // Frame indices are 0-based and consecutive; truth is aligned.
    for (i, (frame, truth)) in frames.iter().zip(&generated.truth).enumerate() {
        assert_eq!(frame.index, i as u64);
        assert_eq!(frame.timestamp_s, truth.timestamp_s);
    }
}

/// Measurement position error in the sensor's polar frame: (along line of sight, across,
/// range of the true position), for the measurements of real objects (false detections have
/// no true position).
fn polar_errors(cfg: &ScenarioConfig, frame: &RecordedFrame) -> Vec<(ObjectClass, u16, f64, f64, f64)> {
    let sensor_id = frame.sensor_id.expect("sensor id");
    let mount = mount_of(cfg, sensor_id);
    let origin = mount.layout.position();
    frame
        .measurements
        .iter()
        .filter(|m| m.measurement.ground_truth_id.is_some())
        .map(|m| {
            let truth = m.true_position.expect("true position");
            let los = (truth - origin).normalize();
            let error = m.measurement.position() - truth;
            (m.measurement.class, sensor_id, error.dot(los), los.perp_dot(error), (truth - origin).length())
        })
        .collect()
}

#[test]
fn measurement_errors_depend_on_size_aspect_and_sensor() {
    let cfg = ScenarioConfig::default();
    let mut by_class: HashMap<ObjectClass, (Vec<f64>, Vec<f64>)> = HashMap::new();
    let mut ped_angle_by_sensor: HashMap<u16, Vec<f64>> = HashMap::new();
    let mut ped_cross_near = Vec::new();
    let mut ped_cross_far = Vec::new();
    for generated in evaluation_split() {
        for frame in &generated.sequence.frames {
            for (class, sensor, along, across, range) in polar_errors(&cfg, frame) {
                let entry = by_class.entry(class).or_default();
                entry.0.push(along);
                entry.1.push(across);
                if class == ObjectClass::Pedestrian {
                    ped_angle_by_sensor.entry(sensor).or_default().push((across / range).atan().to_degrees());
                    if range < 20.0 {
                        ped_cross_near.push(across);
                    } else if range > 40.0 {
                        ped_cross_far.push(across);
                    }
                }
            }
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let (car_along, car_across) = &by_class[&ObjectClass::Car];
    let (ped_along, ped_across) = &by_class[&ObjectClass::Pedestrian];
    let car_rms = rms(car_along).hypot(rms(car_across));
    let ped_rms = rms(ped_along).hypot(rms(ped_across));
    assert!(ped_rms > 0.1, "pedestrian errors vanish: {ped_rms}");
    assert!(car_rms > 1.5 * ped_rms, "car error {car_rms} not larger than pedestrian error {ped_rms}");
    // Reflections come from the faces turned to the sensor: the centroid is pulled towards it,
    // more so for long objects. The error is therefore not zero-mean along the line of sight.
    let (car_bias, _) = mean_std(car_along);
    let (ped_bias, _) = mean_std(ped_along);
    assert!(car_bias < -0.3, "car line-of-sight bias {car_bias}");
    assert!(car_bias < ped_bias, "car bias {car_bias} should exceed pedestrian bias {ped_bias}");
    // Across the line of sight the error is roughly centred, but it widens with range
    // (azimuth noise).
    let (car_cross_mean, car_cross_std) = mean_std(car_across);
    assert!(
        car_cross_mean.abs() < 0.25 * car_cross_std,
        "cross-range mean {car_cross_mean} vs std {car_cross_std}"
    );
    let (_, near) = mean_std(&ped_cross_near);
    let (_, far) = mean_std(&ped_cross_far);
    assert!(far > 1.3 * near, "cross-range spread near {near} vs far {far}");
    // Sensors differ (mounting misalignment): their mean angular errors are not all equal.
    let means: Vec<f64> = ped_angle_by_sensor.values().map(|v| mean_std(v).0).collect();
    let spread =
        means.iter().cloned().fold(f64::MIN, f64::max) - means.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread > 0.2, "per-sensor mean azimuth errors too similar: {means:?}");
}

#[test]
fn radial_velocity_is_the_projected_true_velocity() {
    let cfg = ScenarioConfig::default();
    let mut residuals = Vec::new();
    let mut moving_away = (0usize, 0usize);
    let mut expected_all = Vec::new();
    for generated in evaluation_split() {
        for (frame, truth) in generated.sequence.frames.iter().zip(&generated.truth) {
            let pose = frame.ego_pose.expect("ego pose");
            let mount = mount_of(&cfg, frame.sensor_id.expect("sensor id"));
            let origin = mount.layout.position();
            for m in &frame.measurements {
                let id = m.measurement.ground_truth_id.expect("ground-truth id");
                let object = truth.object(id).expect("measured object exists");
                let velocity_car = pose.rotate_to_car(object.velocity());
                let los = (m.true_position.expect("true position") - origin).normalize();
                let expected = velocity_car.dot(los);
                if m.measurement.class == ObjectClass::Car {
                    residuals.push(m.measurement.radial_velocity_mps - expected);
                    expected_all.push(expected);
                }
                if expected > 2.0 {
                    moving_away.0 += 1;
                    moving_away.1 += usize::from(m.measurement.radial_velocity_mps > 0.0);
                }
            }
        }
    }
    let (mean, std) = mean_std(&residuals);
    let (_, spread) = mean_std(&expected_all);
    assert!(mean.abs() < 0.1, "radial velocity bias {mean}");
    assert!(std < 0.5, "radial velocity residual std {std}");
    assert!(std > 0.01, "radial velocity has no noise");
    assert!(spread > 3.0 * std, "radial velocities barely vary ({spread})");
    assert!(moving_away.0 > 100);
    assert!(moving_away.1 as f64 > 0.97 * moving_away.0 as f64, "sign convention: {moving_away:?}");
}

#[test]
fn every_class_appears_in_every_split_kind() {
    let mut summary = SplitSummary::new(Split::Evaluation);
    for generated in evaluation_split() {
        summary.add_generated(generated);
        assert!(generated.sequence.measurement_count() > 0, "{} has no measurement", generated.sequence.name);
        for frame in &generated.sequence.frames {
            for m in &frame.measurements {
                assert!(matches!(m.measurement.class, ObjectClass::Car | ObjectClass::Pedestrian));
                assert_eq!(m.measurement.sensor_id, frame.sensor_id);
            }
        }
    }
    assert_eq!(summary.sequences, 22);
    assert!(summary.car_object_frames > 1000, "{summary:?}");
    assert!(summary.pedestrian_object_frames > 1000, "{summary:?}");
    let total = summary.object_frames();
    assert!((15_000..=25_000).contains(&total), "evaluation split has {total} object measurements");
    let frames: usize = evaluation_split().iter().map(|g| g.sequence.frames.len()).sum();
    assert_eq!(summary.frames, frames);
    // The robustness preset also produces both classes.
    let robust = short_generator(Preset::Robustness, 3.0).generate(Split::Evaluation, 0);
    assert!(robust.sequence.class_count(ObjectClass::Car) > 0);
    assert!(robust.sequence.class_count(ObjectClass::Pedestrian) > 0);
}

#[test]
fn close_proximity_and_crossing_occur_in_the_evaluation_split() {
    let mut close_sequences = 0;
    let mut crossing_sequences = 0;
    let mut total = primm_sim::scenario::EventCounts::default();
    for generated in evaluation_split() {
        let events = count_events(generated);
        close_sequences += usize::from(events.close_proximity_frames > 0);
        crossing_sequences += usize::from(events.crossing_frames > 0);
        total += events;
    }
    assert!(close_sequences >= 11, "close proximity in only {close_sequences} of 22 sequences");
    assert!(crossing_sequences >= 3, "crossing in only {crossing_sequences} of 22 sequences");
    assert!(total.close_proximity_frames > 500 && total.crossing_frames > 50, "{total:?}");
}

#[test]
fn objects_enter_and_leave_the_field_of_view() {
    let mut entering = 0;
    let mut leaving = 0;
    for generated in evaluation_split() {
        let frames = &generated.sequence.frames;
        let last = frames.len() - 1;
        let mut seen: HashMap<u64, (usize, usize)> = HashMap::new();
        for (i, frame) in frames.iter().enumerate() {
            for m in &frame.measurements {
                let id = m.measurement.ground_truth_id.expect("id");
                seen.entry(id).and_modify(|e| e.1 = i).or_insert((i, i));
            }
        }
        for (id, (first, final_seen)) in seen {
            // Existing before its first detection / after its last one, but not detected then.
            let existed_before = generated.truth[..first].iter().any(|t| t.object(id).is_some());
            let exists_after = generated.truth[final_seen + 1..].iter().any(|t| t.object(id).is_some());
            entering += usize::from(first > 50 && existed_before);
            leaving += usize::from(final_seen + 50 < last && exists_after);
        }
    }
    assert!(entering >= 20, "only {entering} objects entered the field of view");
    assert!(leaving >= 20, "only {leaving} objects left the field of view");
}

/// Whether the segment from `a` to `b` crosses the box of `o`.
fn blocks(a: DVec2, b: DVec2, o: &ObjectState) -> bool {
    let dir = DVec2::from_angle(o.heading_rad);
    let local = |p: DVec2| DVec2::new((p - o.position).dot(dir), (p - o.position).dot(dir.perp()));
    let (la, lb) = (local(a), local(b));
    (0..=200).any(|k| {
        let p = la + (lb - la) * (k as f64 / 200.0);
        p.x.abs() <= o.length_m / 2.0 && p.y.abs() <= o.width_m / 2.0
    })
}

#[test]
fn hidden_objects_are_missed_more_often_than_visible_ones() {
    let cfg = ScenarioConfig::default();
    let (mut visible, mut visible_hit, mut hidden, mut hidden_hit) = (0usize, 0usize, 0usize, 0usize);
    for generated in evaluation_split().iter().take(8) {
        for (frame, truth) in generated.sequence.frames.iter().zip(&generated.truth) {
            let pose = frame.ego_pose.expect("pose");
            let mount = mount_of(&cfg, frame.sensor_id.expect("sensor"));
            let origin = pose.point_to_world(mount.layout.position());
            let boresight = pose.yaw_rad + mount.layout.yaw_rad;
            let measured: HashSet<u64> =
                frame.measurements.iter().filter_map(|m| m.measurement.ground_truth_id).collect();
            for object in &truth.objects {
                let rel = object.position - origin;
                let azimuth = (rel.to_angle() - boresight + std::f64::consts::PI)
                    .rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                if rel.length() > 40.0 || azimuth.abs() > mount.layout.half_fov_rad - 10f64.to_radians() {
                    continue;
                }
                let occluded = truth.objects.iter().any(|other| {
                    other.id != object.id
                        && other.position.distance(origin) < rel.length()
                        && blocks(origin, object.position, other)
                });
                let hit = measured.contains(&object.id);
                if occluded {
                    hidden += 1;
                    hidden_hit += usize::from(hit);
                } else {
                    visible += 1;
                    visible_hit += usize::from(hit);
                }
            }
        }
    }
    let visible_rate = visible_hit as f64 / visible as f64;
    let hidden_rate = hidden_hit as f64 / hidden.max(1) as f64;
    assert!(hidden > 50, "too few occlusions ({hidden})");
    assert!(visible_rate > 0.9 && visible_rate < 1.0, "visible detection rate {visible_rate}");
    assert!(hidden_rate < visible_rate - 0.2, "hidden {hidden_rate} vs visible {visible_rate}");
}

#[test]
fn robustness_preset_is_selectable_and_harder() {
    assert_eq!(Preset::from_name("robustness"), Some(Preset::Robustness));
    assert_eq!(Preset::from_name("default"), Some(Preset::Default));
    assert_eq!(Preset::from_name("nope"), None);
    let robust = Preset::Robustness.config();
    robust.validate().expect("robustness preset is valid");
    assert_ne!(robust, ScenarioConfig::default());
    let cfg = ScenarioConfig::default();
    let ped_error = |generated: &GeneratedSequence, cfg: &ScenarioConfig| {
        let errors: Vec<f64> = generated
            .sequence
            .frames
            .iter()
            .flat_map(|f| polar_errors(cfg, f))
            .filter(|e| e.0 == ObjectClass::Pedestrian)
            .map(|e| e.3)
            .collect();
        mean_std(&errors).1
    };
    let default_gen = short_generator(Preset::Default, 5.0);
    let robust_gen = short_generator(Preset::Robustness, 5.0);
    let mut default_std = 0.0;
    let mut robust_std = 0.0;
    for index in 0..3 {
        default_std += ped_error(&default_gen.generate(Split::Evaluation, index), &cfg);
        robust_std += ped_error(&robust_gen.generate(Split::Evaluation, index), &robust);
    }
    assert!(
        robust_std > 1.3 * default_std,
        "robustness cross-range error {robust_std} vs default {default_std}"
    );
}

#[test]
fn configuration_is_validated_and_serialisable() {
    let cfg = ScenarioConfig::default();
    cfg.validate().expect("default is valid");
    let text = toml::to_string(&cfg).expect("serialise");
    assert_eq!(ScenarioConfig::from_toml_str(&text).expect("parse"), cfg);
    let partial = ScenarioConfig::from_toml_str("[sequence]\nduration_s = 3.5\n").expect("partial config");
    assert_eq!(partial.sequence.duration_s, 3.5);
    assert_eq!(partial.car, cfg.car);

    let mut bad = cfg.clone();
    bad.car.limits.max_speed_mps = 5.0;
    assert_eq!(bad.validate().unwrap_err().field, "car.desired_speed_mps");
    let mut bad = cfg.clone();
    bad.radar.scan_jitter_s = 0.01;
    assert_eq!(bad.validate().unwrap_err().field, "radar.scan_jitter_s");
    let mut bad = cfg.clone();
    bad.radar.sensors[1].layout.id = bad.radar.sensors[0].layout.id;
    assert_eq!(bad.validate().unwrap_err().field, "radar.sensors[1].id");
    let mut bad = cfg.clone();
    bad.pedestrian.stop_probability = 1.5;
    assert_eq!(bad.validate().unwrap_err().field, "pedestrian.stop_probability");
    let mut bad = cfg;
    bad.road.block_length_m = 40.0;
    assert_eq!(bad.validate().unwrap_err().field, "road.block_length_m");
    assert!(ScenarioGenerator::new(bad).is_err());
    assert!(matches!(ScenarioConfig::from_toml_str("[car]\nwheels = 4\n"), Err(ScenarioTomlError::Parse(_))));
    match ScenarioConfig::from_toml_str("[road]\nblock_length_m = 40.0\n") {
        Err(ScenarioTomlError::Invalid(error)) => assert_eq!(error.field, "road.block_length_m"),
        other => panic!("expected an invalid configuration, got {other:?}"),
    }
}

#[test]
fn csv_round_trip_of_a_generated_sequence_is_exact() {
    let generated = &evaluation_split()[5];
    let mut sequence: Sequence = generated.sequence.clone();
    // Make sure an empty frame is part of the round trip.
    if !sequence.frames.iter().any(|f| f.measurements.is_empty()) {
        sequence.frames[3].measurements.clear();
    }
    let mut bytes = Vec::new();
    write_sequence(&mut bytes, &sequence).expect("write");
    let back = read_sequence(bytes.as_slice(), &sequence.name).expect("read");
    assert_eq!(back, sequence);
    // The true velocities travel with every real measurement.
    let measurements = back.frames.iter().flat_map(|f| &f.measurements);
    assert!(measurements.clone().count() > 100);
    assert!(measurements.clone().all(|m| m.true_velocity.is_some()));
    assert!(measurements.clone().any(|m| m.true_velocity.is_some_and(|v| v.length() > 5.0)));
    // Conversion to library frames keeps ground-truth ids and classes.
    for (recorded, frame) in back.frames.iter().zip(back.to_frames().expect("frames")) {
        assert_eq!(frame.timestamp_s, recorded.timestamp_s);
        let ids: Vec<_> = frame.measurements.iter().map(|m| (m.ground_truth_id, m.class)).collect();
        let expected: Vec<_> = recorded
            .measurements
            .iter()
            .map(|m| (m.measurement.ground_truth_id, m.measurement.class))
            .collect();
        assert_eq!(ids, expected);
    }
}

#[test]
fn split_summary_counts_match_the_sequences() {
    let generator = short_generator(Preset::Default, 1.5);
    let mut summary = SplitSummary::new(Split::Validation);
    let (mut frames, mut cars, mut peds) = (0, 0, 0);
    for generated in generator.split_sequences(Split::Validation) {
        frames += generated.sequence.frames.len();
        for frame in &generated.sequence.frames {
            cars += frame.measurements.iter().filter(|m| m.measurement.class == ObjectClass::Car).count();
            peds +=
                frame.measurements.iter().filter(|m| m.measurement.class == ObjectClass::Pedestrian).count();
        }
        summary.add_generated(&generated);
    }
    assert_eq!(summary.sequences, 6);
    assert_eq!(
        (summary.frames, summary.car_object_frames, summary.pedestrian_object_frames),
        (frames, cars, peds)
    );
    let table = primm_sim::scenario::format_table(&[summary]);
    assert!(table.contains("Validation"));
    assert!(table.lines().next().unwrap().contains("Pedestrian object frames"));
}

#[test]
fn the_turning_preset_turns_the_ego_often_and_up_to_half_a_radian_per_second() {
    use primm_sim::eval::ego_motion::{ego_yaw_rates, TURNING_YAW_RATE_RADPS};
    assert_eq!(Preset::from_name("turning"), Some(Preset::Turning));
    Preset::Turning.config().validate().expect("turning preset is valid");
    // Share of frames with |yaw rate| above the turning threshold, and the largest |yaw rate|.
    let turning = |preset: Preset| {
        let generator = short_generator(preset, 7.0);
        let (mut turning, mut frames, mut largest) = (0usize, 0usize, 0.0f64);
        for index in 0..4 {
            let rates = ego_yaw_rates(&generator.generate(Split::Validation, index).sequence);
            frames += rates.len();
            turning += rates.values().filter(|rate| rate.abs() > TURNING_YAW_RATE_RADPS).count();
            largest = rates.values().fold(largest, |m, rate| m.max(rate.abs()));
        }
        (turning as f64 / frames as f64, largest)
    };
    let (default_share, _) = turning(Preset::Default);
    let (turning_share, largest) = turning(Preset::Turning);
    assert!(turning_share > 2.0 * default_share, "turning share {turning_share} vs default {default_share}");
    assert!(turning_share > 0.15, "turning share {turning_share}");
    assert!((0.3..1.0).contains(&largest), "largest ego yaw rate {largest} rad/s");
}
