//! False detections: clutter and multipath ghosts.
//!
//! Object lists of real automotive radars are not clean even after clustering and
//! classification. Guard rails, poles, kerbs and the edges of parked cars leave clusters that
//! pass as objects, mostly with the radial velocity of the static world; multipath propagation
//! (a reflection off the road surface, a wall or another vehicle on the way back) puts a weaker
//! copy of a real object farther away on the same line of sight. Both are added here to the
//! measurements of one scan:
//!
//! * *Ghosts*: every real object measurement of the scan is followed, with
//!   `ghost_probability`, by a ghost at the same azimuth from the sensor, `ghost_extra_range_m`
//!   farther away, with the object's class, its radial velocity plus the sensor's Doppler
//!   noise, and its RCS lowered by `ghost_rcs_drop_db`. A ghost that would lie beyond the
//!   sensor's range or outside its field of view is not reported.
//! * *Clutter*: a Poisson-distributed number of detections, spread uniformly over the area of
//!   the scanning sensor's field-of-view sector between `min_range_m` and `max_range_m` (or the
//!   sensor's range when smaller), labelled `car` with `car_fraction` and `pedestrian`
//!   otherwise, with a normally distributed RCS per label. Most are static (radial velocity
//!   zero plus the Doppler noise and the scan's compensation error); `moving_fraction` of them
//!   look moving, with a radial velocity drawn uniformly in ±`moving_radial_velocity_max_mps`.
//!
//! False detections have no ground-truth id and no true position, carry the scanning sensor's
//! id, and are inserted at random places in the scan's (already shuffled) detection list, so
//! the real measurements keep their order. A frame never holds more than
//! [`MAX_MEASUREMENTS_PER_FRAME`] measurements: false detections beyond that capacity are
//! dropped, uniform clutter before ghosts.
//!
//! All randomness comes from the caller's random stream, which the generator keeps separate
//! from the traffic, timing and measurement streams: switching clutter on or off leaves every
//! real measurement unchanged.

use glam::DVec2;
use rand::Rng;
use rand_chacha::ChaCha12Rng;
use rand_distr::{Distribution, Poisson, StandardNormal};

use super::config::{ClutterConfig, RadarConfig};
use super::kinematics::wrap_angle;
use crate::io::{MeasurementOrigin, RecordedMeasurement};
use primm_core::measurement::{Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use primm_core::pose::SensorMount;

/// Adds the false detections of one scan of sensor `sensor_index` to `measurements`, the real
/// object measurements of that scan. `doppler_bias_mps` is the scan's ego-motion compensation
/// error, shared by the static clutter. Does nothing (and draws nothing) when `clutter` is
/// switched off.
pub(crate) fn add_false_detections(
    clutter: &ClutterConfig,
    radar: &RadarConfig,
    sensor_index: usize,
    doppler_bias_mps: f64,
    measurements: &mut Vec<RecordedMeasurement>,
    rng: &mut ChaCha12Rng,
) {
    if !clutter.is_enabled() {
        return;
    }
    let mount = &radar.sensors[sensor_index].layout;
    let mut false_detections: Vec<RecordedMeasurement> =
        measurements.iter().filter_map(|real| ghost(clutter, radar, mount, &real.measurement, rng)).collect();
    let count = clutter_count(clutter.mean_false_detections_per_scan, rng);
    false_detections
        .extend((0..count).map(|_| clutter_detection(clutter, radar, mount, doppler_bias_mps, rng)));
    false_detections.truncate(MAX_MEASUREMENTS_PER_FRAME.saturating_sub(measurements.len()));
    for detection in false_detections {
        let at = rng.random_range(0..=measurements.len());
        measurements.insert(at, detection);
    }
}

/// A Poisson-distributed count with mean `mean` (0 for a mean of 0).
fn clutter_count(mean: f64, rng: &mut ChaCha12Rng) -> usize {
    if mean <= 0.0 {
        return 0;
    }
    Poisson::new(mean).map(|poisson| poisson.sample(rng) as usize).unwrap_or(0)
}

/// A standard normal draw.
fn unit_normal(rng: &mut ChaCha12Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// A draw uniform in `[-half_width, half_width]`.
fn symmetric(rng: &mut ChaCha12Rng, half_width: f64) -> f64 {
    if half_width > 0.0 {
        rng.random_range(-half_width..=half_width)
    } else {
        0.0
    }
}

/// A false detection of `mount` at car-frame `position`, of `origin` clutter or ghost.
fn false_detection(
    mount: &SensorMount,
    position: DVec2,
    radial_velocity_mps: f64,
    rcs_dbsm: f64,
    class: ObjectClass,
    origin: MeasurementOrigin,
) -> RecordedMeasurement {
    RecordedMeasurement {
        measurement: Measurement {
            x_m: position.x,
            y_m: position.y,
            radial_velocity_mps,
            rcs_dbsm,
            class,
            sensor_id: Some(mount.id),
            ground_truth_id: None,
        },
        true_position: None,
        true_velocity: None,
        origin: Some(origin),
    }
}

/// With `ghost_probability`, the multipath ghost of the object measurement `real`; `None`
/// otherwise and when the ghost would fall outside the sensor's field of view or range.
fn ghost(
    clutter: &ClutterConfig,
    radar: &RadarConfig,
    mount: &SensorMount,
    real: &Measurement,
    rng: &mut ChaCha12Rng,
) -> Option<RecordedMeasurement> {
    if !rng.random_bool(clutter.ghost_probability) {
        return None;
    }
    let [shortest, longest] = clutter.ghost_extra_range_m;
    let extra_range = rng.random_range(shortest..=longest);
    let radial_velocity = real.radial_velocity_mps + radar.doppler_noise_mps * unit_normal(rng);
    let origin = mount.position();
    let line_of_sight = real.position() - origin;
    let range = line_of_sight.length();
    let azimuth = wrap_angle(line_of_sight.to_angle() - mount.yaw_rad);
    let ghost_range = range + extra_range;
    if range <= 0.0 || ghost_range > mount.max_range_m || azimuth.abs() > mount.half_fov_rad {
        return None;
    }
    let position = origin + line_of_sight * (ghost_range / range);
    Some(false_detection(
        mount,
        position,
        radial_velocity,
        real.rcs_dbsm - clutter.ghost_rcs_drop_db,
        real.class,
        MeasurementOrigin::Ghost,
    ))
}

/// One clutter detection of `mount`: uniform over the area of its field-of-view sector within
/// the clutter's range interval.
fn clutter_detection(
    clutter: &ClutterConfig,
    radar: &RadarConfig,
    mount: &SensorMount,
    doppler_bias_mps: f64,
    rng: &mut ChaCha12Rng,
) -> RecordedMeasurement {
    let (near, far) = clutter_ranges(clutter, mount);
    // Uniform in area: the squared range is uniform.
    let range = (near * near + rng.random::<f64>() * (far * far - near * near)).sqrt();
    let azimuth = symmetric(rng, mount.half_fov_rad);
    let position = mount.position() + DVec2::from_angle(mount.yaw_rad + azimuth) * range;
    let (class, rcs_mean, rcs_std) = if rng.random_bool(clutter.car_fraction) {
        (ObjectClass::Car, clutter.car_rcs_mean_dbsm, clutter.car_rcs_std_db)
    } else {
        (ObjectClass::Pedestrian, clutter.pedestrian_rcs_mean_dbsm, clutter.pedestrian_rcs_std_db)
    };
    let rcs = rcs_mean + rcs_std * unit_normal(rng);
    let radial_velocity = if rng.random_bool(clutter.moving_fraction) {
        symmetric(rng, clutter.moving_radial_velocity_max_mps)
    } else {
        doppler_bias_mps + radar.doppler_noise_mps * unit_normal(rng)
    };
    false_detection(mount, position, radial_velocity, rcs, class, MeasurementOrigin::Clutter)
}

/// The range interval of the clutter of `mount`, metres: the configured one, cut at the
/// sensor's range.
fn clutter_ranges(clutter: &ClutterConfig, mount: &SensorMount) -> (f64, f64) {
    (clutter.min_range_m, clutter.max_range_m.min(mount.max_range_m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{Preset, ScenarioConfig, ScenarioGenerator, Split};
    use rand::SeedableRng;

    /// The position of `m` seen from `mount`: range and azimuth from boresight.
    fn polar(mount: &SensorMount, m: &Measurement) -> (f64, f64) {
        let rel = m.position() - mount.position();
        (rel.length(), wrap_angle(rel.to_angle() - mount.yaw_rad))
    }

    /// A real object measurement of sensor `mount` at range `range` on its boresight.
    fn real_measurement(mount: &SensorMount, id: u64, range: f64) -> RecordedMeasurement {
        let position = mount.position() + DVec2::from_angle(mount.yaw_rad) * range;
        RecordedMeasurement {
            measurement: Measurement {
                x_m: position.x,
                y_m: position.y,
                radial_velocity_mps: -4.0,
                rcs_dbsm: 10.0,
                class: ObjectClass::Car,
                sensor_id: Some(mount.id),
                ground_truth_id: Some(id),
            },
            true_position: Some(position),
            true_velocity: Some(DVec2::ZERO),
            origin: Some(MeasurementOrigin::Object),
        }
    }

    /// The false detections of `scans` scans of every sensor in turn, with `real` object
    /// measurements in each scan.
    fn false_detections_of(
        clutter: &ClutterConfig,
        scans: usize,
        real: usize,
    ) -> Vec<(usize, Vec<RecordedMeasurement>)> {
        let radar = RadarConfig::default();
        let mut rng = ChaCha12Rng::seed_from_u64(17);
        (0..scans)
            .map(|scan| {
                let sensor = scan % radar.sensors.len();
                let mount = &radar.sensors[sensor].layout;
                let mut measurements: Vec<RecordedMeasurement> =
                    (0..real).map(|id| real_measurement(mount, id as u64, 10.0 + id as f64)).collect();
                add_false_detections(clutter, &radar, sensor, 0.05, &mut measurements, &mut rng);
                let false_ones =
                    measurements.into_iter().filter(|m| m.measurement.ground_truth_id.is_none()).collect();
                (sensor, false_ones)
            })
            .collect()
    }

    #[test]
    fn the_number_of_false_detections_per_scan_has_the_configured_poisson_mean() {
        for mean in [0.3, 1.5, 6.0] {
            let clutter = ClutterConfig { mean_false_detections_per_scan: mean, ..ClutterConfig::default() };
            let scans = 20_000;
            let counts: Vec<f64> =
                false_detections_of(&clutter, scans, 0).iter().map(|(_, d)| d.len() as f64).collect();
            let measured = counts.iter().sum::<f64>() / scans as f64;
            let variance = counts.iter().map(|c| (c - measured).powi(2)).sum::<f64>() / scans as f64;
            // The standard error of the mean is sqrt(mean / scans), below 0.02 here.
            assert!((measured - mean).abs() < 0.05 * mean.max(1.0), "mean {measured}, expected {mean}");
            // Poisson: the variance equals the mean.
            assert!((variance / mean - 1.0).abs() < 0.1, "variance {variance} for mean {mean}");
        }
    }

    #[test]
    fn clutter_lies_inside_the_scanning_sensors_field_of_view_and_range() {
        let clutter = ClutterConfig { mean_false_detections_per_scan: 4.0, ..ClutterConfig::default() };
        let radar = RadarConfig::default();
        let (mut near_half, mut total) = (0usize, 0usize);
        for (sensor, detections) in false_detections_of(&clutter, 4000, 0) {
            let mount = &radar.sensors[sensor].layout;
            let (near, far) = clutter_ranges(&clutter, mount);
            for detection in &detections {
                let m = &detection.measurement;
                assert_eq!(m.sensor_id, Some(mount.id));
                assert_eq!((m.ground_truth_id, detection.true_position), (None, None));
                let (range, azimuth) = polar(mount, m);
                assert!((near - 1e-9..=far + 1e-9).contains(&range), "range {range} outside [{near}, {far}]");
                assert!(azimuth.abs() <= mount.half_fov_rad + 1e-9, "azimuth {azimuth}");
                total += 1;
                near_half += usize::from(range * range < 0.5 * (near * near + far * far));
            }
        }
        // Uniform in area: half of the detections lie inside the radius that halves the sector.
        let share = near_half as f64 / total as f64;
        assert!((share - 0.5).abs() < 0.02, "share in the inner half of the area {share}");
    }

    #[test]
    fn class_mix_rcs_and_static_share_follow_the_configuration() {
        let clutter = ClutterConfig {
            mean_false_detections_per_scan: 3.0,
            car_fraction: 0.6,
            moving_fraction: 0.25,
            moving_radial_velocity_max_mps: 10.0,
            ..ClutterConfig::default()
        };
        let radar = RadarConfig::default();
        let detections: Vec<Measurement> = false_detections_of(&clutter, 10_000, 0)
            .into_iter()
            .flat_map(|(_, d)| d.into_iter().map(|r| r.measurement))
            .collect();
        let total = detections.len() as f64;
        let cars: Vec<&Measurement> = detections.iter().filter(|m| m.class == ObjectClass::Car).collect();
        let pedestrians: Vec<&Measurement> =
            detections.iter().filter(|m| m.class == ObjectClass::Pedestrian).collect();
        assert_eq!(cars.len() + pedestrians.len(), detections.len());
        let car_share = cars.len() as f64 / total;
        assert!((car_share - 0.6).abs() < 0.02, "car share {car_share}");
        let mean_rcs = |ms: &[&Measurement]| ms.iter().map(|m| m.rcs_dbsm).sum::<f64>() / ms.len() as f64;
        assert!((mean_rcs(&cars) - clutter.car_rcs_mean_dbsm).abs() < 0.3);
        assert!((mean_rcs(&pedestrians) - clutter.pedestrian_rcs_mean_dbsm).abs() < 0.3);
        // Static clutter sits within a few Doppler noise sigmas of the scan's compensation
        // error (0.05 m/s here); moving clutter is uniform over ±10 m/s, so 1 % of it falls in
        // that ±0.1 m/s window around zero too.
        let window = 0.05 + 5.0 * radar.doppler_noise_mps;
        let near_zero = detections.iter().filter(|m| m.radial_velocity_mps.abs() <= window).count() as f64;
        let expected = (1.0 - 0.25) + 0.25 * window / 10.0;
        assert!((near_zero / total - expected).abs() < 0.02, "static-looking share {}", near_zero / total);
        assert!(detections.iter().all(|m| m.radial_velocity_mps.abs() <= 10.0 + 1e-9));
        let fastest = detections.iter().map(|m| m.radial_velocity_mps.abs()).fold(0.0, f64::max);
        assert!(fastest > 9.0, "fastest moving clutter {fastest} m/s");
    }

    #[test]
    fn ghosts_lie_behind_their_objects_with_their_class_and_a_lower_rcs() {
        let clutter = ClutterConfig { ghost_probability: 0.3, ..ClutterConfig::default() };
        let radar = RadarConfig::default();
        let scans = 4000;
        let real_per_scan = 3;
        let mut ghosts = 0usize;
        for (sensor, detections) in false_detections_of(&clutter, scans, real_per_scan) {
            let mount = &radar.sensors[sensor].layout;
            for detection in &detections {
                let m = &detection.measurement;
                let (range, azimuth) = polar(mount, m);
                // The real measurements lie on the boresight at 10, 11 and 12 m.
                assert!(azimuth.abs() < 1e-9, "ghost azimuth {azimuth}");
                let [shortest, longest] = clutter.ghost_extra_range_m;
                assert!(
                    (10.0 + shortest - 1e-9..=12.0 + longest + 1e-9).contains(&range),
                    "ghost range {range}"
                );
                assert_eq!(m.class, ObjectClass::Car);
                assert_eq!(m.rcs_dbsm, 10.0 - clutter.ghost_rcs_drop_db);
                assert!((m.radial_velocity_mps + 4.0).abs() < 6.0 * radar.doppler_noise_mps);
                ghosts += 1;
            }
        }
        let share = ghosts as f64 / (scans * real_per_scan) as f64;
        assert!((share - 0.3).abs() < 0.02, "ghost share {share}");
    }

    #[test]
    fn ghosts_beyond_the_sensor_range_are_not_reported() {
        let clutter = ClutterConfig { ghost_probability: 1.0, ..ClutterConfig::default() };
        let mut radar = RadarConfig::default();
        radar.sensors.truncate(1);
        let mount = radar.sensors[0].layout;
        let mut measurements = vec![real_measurement(&mount, 1, mount.max_range_m - 0.5)];
        let mut rng = ChaCha12Rng::seed_from_u64(3);
        add_false_detections(&clutter, &radar, 0, 0.0, &mut measurements, &mut rng);
        assert_eq!(measurements.len(), 1);
    }

    #[test]
    fn false_detections_never_push_a_frame_past_its_capacity() {
        let clutter = ClutterConfig {
            mean_false_detections_per_scan: MAX_MEASUREMENTS_PER_FRAME as f64,
            ghost_probability: 1.0,
            ..ClutterConfig::default()
        };
        let radar = RadarConfig::default();
        let mut rng = ChaCha12Rng::seed_from_u64(5);
        for real in [0, 10, 200, MAX_MEASUREMENTS_PER_FRAME - 1, MAX_MEASUREMENTS_PER_FRAME] {
            let mount = &radar.sensors[1].layout;
            let original: Vec<RecordedMeasurement> =
                (0..real).map(|id| real_measurement(mount, id as u64, 5.0 + 0.2 * id as f64)).collect();
            let mut measurements = original.clone();
            add_false_detections(&clutter, &radar, 1, 0.0, &mut measurements, &mut rng);
            assert!(measurements.len() <= MAX_MEASUREMENTS_PER_FRAME, "{} measurements", measurements.len());
            // The real measurements are all kept, in their order.
            let kept: Vec<RecordedMeasurement> =
                measurements.into_iter().filter(|m| m.measurement.ground_truth_id.is_some()).collect();
            assert_eq!(kept, original);
        }
        // Through the whole generator: every frame stays within capacity and can be written.
        let mut config = ScenarioConfig::default();
        config.sequence.duration_s = 0.5;
        config.clutter = clutter;
        let generated =
            ScenarioGenerator::new(config).expect("valid configuration").generate(Split::Evaluation, 0);
        let mut full_frames = 0;
        for frame in &generated.sequence.frames {
            assert!(frame.measurements.len() <= MAX_MEASUREMENTS_PER_FRAME);
            full_frames += usize::from(frame.measurements.len() == MAX_MEASUREMENTS_PER_FRAME);
        }
        assert!(full_frames > 0, "the capacity was never reached");
        let mut csv = Vec::new();
        crate::io::write_sequence(&mut csv, &generated.sequence).expect("frames within capacity are written");
    }

    #[test]
    fn clutter_only_adds_rows_to_the_real_measurements() {
        for (clutter_preset, base_preset) in [
            (Preset::Clutter, Preset::Default),
            (Preset::ClutterTurning, Preset::Turning),
            (Preset::Robustness, Preset::Robustness),
        ] {
            let mut with_clutter = clutter_preset.config();
            with_clutter.sequence.duration_s = 2.0;
            let mut without_clutter = with_clutter.clone();
            without_clutter.clutter = ClutterConfig::default();
            // Apart from the clutter and the seeds, the clutter presets are their base presets.
            let mut base = base_preset.config();
            base.sequence.duration_s = 2.0;
            base.splits.seed_base = without_clutter.splits.seed_base;
            base.clutter = ClutterConfig::default();
            assert_eq!(without_clutter, base, "{clutter_preset} against {base_preset}");

            let seed =
                ScenarioGenerator::new(with_clutter.clone()).expect("valid").seed(Split::Evaluation, 3);
            let cluttered = ScenarioGenerator::new(with_clutter).expect("valid").generate_seeded(seed, "a");
            let clean = ScenarioGenerator::new(without_clutter).expect("valid").generate_seeded(seed, "a");
            assert_eq!(cluttered.truth, clean.truth);
            assert_eq!(cluttered.sequence.frames.len(), clean.sequence.frames.len());
            let mut false_detections = 0;
            for (noisy, frame) in cluttered.sequence.frames.iter().zip(&clean.sequence.frames) {
                assert_eq!(
                    (noisy.index, noisy.timestamp_s, noisy.sensor_id, noisy.ego_pose),
                    (frame.index, frame.timestamp_s, frame.sensor_id, frame.ego_pose)
                );
                let real: Vec<&RecordedMeasurement> =
                    noisy.measurements.iter().filter(|m| m.measurement.ground_truth_id.is_some()).collect();
                assert_eq!(real, frame.measurements.iter().collect::<Vec<_>>());
                for m in noisy.measurements.iter().filter(|m| m.measurement.ground_truth_id.is_none()) {
                    assert_eq!(m.measurement.sensor_id, noisy.sensor_id);
                    assert_eq!(m.true_position, None);
                    false_detections += 1;
                }
            }
            let per_scan = false_detections as f64 / clean.sequence.frames.len() as f64;
            let mean = clutter_preset.config().clutter.mean_false_detections_per_scan;
            assert!((per_scan - mean).abs() < 0.5, "{clutter_preset}: {per_scan} false detections per scan");
        }
    }

    #[test]
    fn switched_off_clutter_draws_nothing_and_adds_nothing() {
        let radar = RadarConfig::default();
        let mount = &radar.sensors[2].layout;
        let original = vec![real_measurement(mount, 1, 20.0), real_measurement(mount, 2, 30.0)];
        let mut measurements = original.clone();
        let mut rng = ChaCha12Rng::seed_from_u64(9);
        let untouched = rng.clone();
        add_false_detections(&ClutterConfig::default(), &radar, 2, 0.0, &mut measurements, &mut rng);
        assert_eq!(measurements, original);
        assert_eq!(rng, untouched);
    }
}
