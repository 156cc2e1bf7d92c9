//! Radars that report several detections per object (`crate::grouping`, ARCHITECTURE.md "Point
//! clouds"): a point-cloud radar's detections become one track per object, `detections =
//! "auto"` finds out which kind of radar it has, a scan's wrong labels do not take a tracked
//! object's detections from its track, a tracked car's group takes the detections near its box
//! that move as its returns and no others, object radars are left as they are, and late frames
//! give what in-order arrival gives (faults: `point_cloud_faults.rs`).

use glam::DVec2;
use primm_core::config::Config;
use primm_core::grouping::DetectionModel;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

/// A deterministic noise source in [−0.5, 0.5).
pub(crate) struct Noise(pub(crate) u64);

impl Noise {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// The default configuration with every radar (and the radars without a mount) set to
/// `detections`.
pub(crate) fn config(detections: DetectionModel) -> Config {
    let mut config = Config::default();
    for sensor in config.frame.sensors.iter_mut() {
        sensor.detections = detections;
    }
    config.frame.unmounted_detections = detections;
    config
}

/// A car's detection by the front-left radar (id 3) at `position_m`.
pub(crate) fn car_detection(
    position_m: DVec2,
    radial_velocity_mps: f64,
    rcs_dbsm: f64,
    ground_truth_id: Option<u64>,
) -> Measurement {
    Measurement {
        x_m: position_m.x,
        y_m: position_m.y,
        radial_velocity_mps,
        rcs_dbsm,
        class: ObjectClass::Car,
        sensor_id: Some(3),
        ground_truth_id,
    }
}

/// Two cars driving side by side along x at 12 m/s, 3.5 m apart, ahead of a standing ego, seen
/// by the front-left radar (id 3) every 50 ms: `points` detections per car per scan on its rear
/// face and the near side, with ±0.1 m of noise, and one wheel return at twice the body's
/// radial velocity. With `points = 1` each car gives one detection at its centre.
pub(crate) fn cars(frames: usize, points: usize) -> Vec<Frame> {
    let mut noise = Noise(11);
    let sensor_m = DVec2::new(3.86, 0.70);
    (0..frames)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            for (id, lane_m) in [(1u64, 2.0), (2, 5.5)] {
                let centre = DVec2::new(20.0 + 12.0 * t, lane_m);
                let velocity = DVec2::new(12.0, 0.0);
                let radial = |point: DVec2| velocity.dot((point - sensor_m).normalize());
                let mut push = |point: DVec2, radial_velocity_mps: f64| {
                    let measured_m = DVec2::new(point.x + 0.2 * noise.next(), point.y + 0.2 * noise.next());
                    frame.measurements.push(car_detection(measured_m, radial_velocity_mps, 5.0, Some(id)))
                };
                if points == 1 {
                    push(centre, radial(centre));
                    continue;
                }
                for p in 0..points - 1 {
                    // Along the rear face (x = centre − 2.25 m), then the side facing the radar.
                    let share = p as f64 / (points - 1) as f64;
                    let point = if p % 2 == 0 {
                        centre + DVec2::new(-2.25, -0.9 + 1.8 * share)
                    } else {
                        centre + DVec2::new(-2.25 + 4.5 * share, -0.9)
                    };
                    push(point, radial(point));
                }
                let wheel = centre + DVec2::new(-1.4, -0.9);
                push(wheel, 2.0 * radial(wheel));
            }
            frame
        })
        .collect()
}

/// Confirmed tracks per frame over the last half of `frames`, and the tracker.
fn confirmed_per_frame(config: Config, frames: &[Frame]) -> (f64, Tracker) {
    let mut tracker = Tracker::new(config).unwrap();
    let mut confirmed = 0usize;
    for (k, frame) in frames.iter().enumerate() {
        let outputs = tracker.step(frame).unwrap();
        if k >= frames.len() / 2 {
            confirmed += outputs.iter().filter(|output| output.status.is_confirmed()).count();
        }
    }
    (confirmed as f64 / (frames.len() - frames.len() / 2) as f64, tracker)
}

#[test]
fn a_point_cloud_radar_gives_one_track_per_car_where_each_detection_as_an_object_gives_more() {
    let frames = cars(200, 5);
    let (grouped, tracker) = confirmed_per_frame(config(DetectionModel::Points), &frames);
    assert!((grouped - 2.0).abs() < 0.05, "{grouped} confirmed tracks per frame");
    assert!(tracker.stats().detections_grouped > 200 * 2 * 3, "{:?}", tracker.stats().detections_grouped);
    let (ungrouped, _) = confirmed_per_frame(config(DetectionModel::Objects), &frames);
    assert!(ungrouped > 2.5, "{ungrouped} confirmed tracks per frame without grouping");
}

#[test]
fn a_grouped_cars_track_weighs_its_groups_by_the_group_noise_scale() {
    // The same point clouds tracked with the group's noise at its full share and at a tenth:
    // the smaller share holds the tracks' positions tighter.
    let frames = cars(100, 5);
    let spread_m2 = |scale: f64| {
        let mut config = config(DetectionModel::Points);
        config.frame.grouping.group_noise_scale = scale;
        let mut tracker = Tracker::new(config).unwrap();
        let mut last = Vec::new();
        for frame in &frames {
            last = tracker.step(frame).unwrap().to_vec();
        }
        let confirmed: Vec<f64> = last
            .iter()
            .filter(|output| output.status.is_confirmed())
            .map(|output| output.position_covariance_m2.x_axis.x + output.position_covariance_m2.y_axis.y)
            .collect();
        assert_eq!(confirmed.len(), 2, "{last:?}");
        confirmed.iter().sum::<f64>()
    };
    let (full, tenth) = (spread_m2(1.0), spread_m2(0.1));
    assert!(tenth < 0.9 * full, "position variance {tenth} m² at a tenth, {full} m² in full");
}

#[test]
fn a_scan_that_labels_a_tracked_cars_points_pedestrian_still_updates_the_cars_track() {
    // Every fourth scan after the first second, all of the first car's detections carry the
    // pedestrian label (a radar's classifier is wrong a tenth of the time, now and then for a
    // whole object).
    let mut frames = cars(200, 5);
    for frame in frames.iter_mut().skip(20).step_by(4) {
        for measurement in frame.measurements.iter_mut().filter(|m| m.ground_truth_id == Some(1)) {
            measurement.class = ObjectClass::Pedestrian;
        }
    }
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    let mut checked = 0;
    for (k, frame) in frames.iter().enumerate() {
        let outputs = tracker.step(frame).unwrap();
        if k < 20 || k % 4 != 0 {
            continue;
        }
        let updated_cars = outputs
            .iter()
            .filter(|output| output.class == ObjectClass::Car && output.status.is_confirmed())
            .filter(|output| output.measurement_index.is_some())
            .count();
        assert_eq!(updated_cars, 2, "scan {k}: {outputs:?}");
        assert!(outputs.iter().all(|output| output.class == ObjectClass::Car), "scan {k}: {outputs:?}");
        checked += 1;
    }
    assert_eq!(checked, 45);
}

#[test]
fn a_new_cars_group_starts_its_track_behind_its_mean_by_the_visible_arc_of_a_disc() {
    // Four points across the rear face of a car 30 m ahead, seen by the front-left radar.
    let sensor_m = DVec2::new(3.86, 0.70);
    let velocity = DVec2::new(12.0, 0.0);
    let mut frame = Frame::new(0.0);
    frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
    let points: Vec<DVec2> = [-0.9, -0.3, 0.3, 0.9].iter().map(|&y| DVec2::new(27.75, y)).collect();
    for point in &points {
        let radial_velocity_mps = velocity.dot((*point - sensor_m).normalize());
        frame.measurements.push(car_detection(*point, radial_velocity_mps, 5.0, Some(1)));
    }
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    let outputs = tracker.step(&frame).unwrap();
    assert_eq!(outputs.len(), 1, "{outputs:?}");
    let extent = Config::default().classes.get(ObjectClass::Car).extent;
    let radius_m = 0.25 * (extent.length_m + extent.width_m);
    let mean_m = points.iter().copied().sum::<DVec2>() / 4.0;
    // No heading yet: the centre lies π/4 of the disc's radius beyond the mean.
    let expected_m = mean_m + (mean_m - sensor_m).normalize() * (core::f64::consts::FRAC_PI_4 * radius_m);
    let started_m = outputs[0].position_m;
    assert!(started_m.distance(expected_m) < 1e-9, "started at {started_m}, expected {expected_m}");
}

/// Detections grouped with others over 100 scans of [`cars`] with five points per car, and,
/// from scan 40 on (the first car's track confirmed), one more detection per scan `ahead_m`
/// beyond the first car's front, on its centre line, whose radial velocity is the car's along
/// its line of sight times `sign`.
fn grouped_with_one_more(ahead_m: f64, sign: f64, owner_margin_m: f64) -> u64 {
    let sensor_m = DVec2::new(3.86, 0.70);
    let mut frames = cars(100, 5);
    for (k, frame) in frames.iter_mut().enumerate().skip(40) {
        let point = DVec2::new(20.0 + 12.0 * 0.05 * k as f64 + 2.25 + ahead_m, 2.0);
        let radial_velocity_mps = sign * DVec2::new(12.0, 0.0).dot((point - sensor_m).normalize());
        frame.measurements.push(car_detection(point, radial_velocity_mps, 5.0, None));
    }
    let mut config = config(DetectionModel::Points);
    config.frame.grouping.owner_margin_m = owner_margin_m;
    let mut tracker = Tracker::new(config).unwrap();
    for frame in &frames {
        tracker.step(frame).unwrap();
    }
    tracker.stats().detections_grouped
}

#[test]
fn a_detection_up_to_the_owner_margin_beyond_a_tracked_cars_box_joins_its_group_when_it_moves_as_a_return() {
    // 3.4 m beyond the front of the car's true box, more than the link distance from its other
    // points (its front points lie 1.1 m ahead of its centre), a return of a longer vehicle's
    // front: inside the box at the track's prior grown by the default margin, not by 2 m.
    let margin_m = Config::default().frame.grouping.owner_margin_m;
    let (joined, alone) = (grouped_with_one_more(3.4, 1.0, margin_m), grouped_with_one_more(3.4, 1.0, 2.0));
    assert!(joined >= alone + 55, "grouped {joined} with the default margin, {alone} with 2 m");
    // Moving with the mirrored radial velocity (an image of the car in a wall across the road,
    // or clutter) it is none of the car's returns: it joins no group, nearer the box too.
    for ahead_m in [0.5, 3.4] {
        let image = grouped_with_one_more(ahead_m, -1.0, margin_m);
        let ret = grouped_with_one_more(ahead_m, 1.0, margin_m);
        assert!(ret >= image + 55, "{ahead_m} m ahead: returns {ret} grouped, images {image}");
    }
}

#[test]
fn a_track_of_a_group_names_one_of_its_detections() {
    let frames = cars(60, 5);
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    for frame in &frames {
        let outputs = tracker.step(frame).unwrap();
        for output in outputs {
            if let Some(index) = output.measurement_index {
                let measurement = frame.measurements[usize::from(index)];
                assert!(measurement.position().distance(output.position_m) < 4.0, "{output:?}");
            }
        }
    }
}

#[test]
fn an_auto_radar_turns_to_points_on_a_point_cloud_and_stays_with_objects_otherwise() {
    let (grouped, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &cars(300, 5));
    let sensor = tracker.sensors().of(Some(3));
    assert!(sensor.groups_detections(), "{:?}", sensor.points);
    assert!(sensor.points.share() > 0.6, "{:?}", sensor.points);
    assert!(grouped < 2.2, "{grouped} confirmed tracks per frame");

    let (single, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &cars(300, 1));
    let sensor = tracker.sensors().of(Some(3));
    assert!(!sensor.groups_detections(), "{:?}", sensor.points);
    assert!(sensor.points.samples > 100, "{:?}", sensor.points);
    assert!((single - 2.0).abs() < 0.05, "{single}");
}

#[test]
fn a_radar_that_has_seen_no_vehicle_follows_the_radars_that_have() {
    // Only the front-left radar (id 3) sees the cars; the left radar (id 4) sees nothing.
    let (_, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &cars(300, 5));
    let left = tracker.sensors().of(Some(4));
    assert_eq!(left.points.samples, 0);
    assert!(left.groups_detections(), "{:?}", left.points);

    let mut alone = config(DetectionModel::Auto);
    alone.frame.grouping.points_pool_scans = 0.0;
    let (_, tracker) = confirmed_per_frame(alone, &cars(300, 5));
    assert!(!tracker.sensors().of(Some(4)).groups_detections());

    let (_, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &cars(300, 1));
    assert!(!tracker.sensors().of(Some(4)).groups_detections());
}

#[test]
fn object_radars_are_tracked_exactly_as_without_a_front_end() {
    let frames = cars(120, 1);
    let mut auto = Tracker::new(config(DetectionModel::Auto)).unwrap();
    let mut objects = Tracker::new(config(DetectionModel::Objects)).unwrap();
    for frame in &frames {
        let a = auto.step(frame).unwrap().to_vec();
        let b = objects.step(frame).unwrap().to_vec();
        assert_eq!(a, b);
    }
    assert_eq!(auto.stats().detections_grouped, 0);
}

#[test]
fn late_point_cloud_frames_give_the_tracks_and_the_estimates_of_in_order_arrival() {
    let frames = cars(160, 5);
    let mut in_order = Tracker::new(config(DetectionModel::Auto)).unwrap();
    for frame in &frames {
        in_order.step(frame).unwrap();
    }
    // Every third pair of frames swapped: each of those frames arrives 50 ms late.
    let mut shuffled = Tracker::new(config(DetectionModel::Auto)).unwrap();
    let mut order: Vec<usize> = (0..frames.len()).collect();
    for pair in order.chunks_mut(6) {
        pair.swap(0, 1);
    }
    for &index in &order {
        shuffled.step(&frames[index]).unwrap();
    }
    assert!(shuffled.stats().late_frames_tracked > 20, "{:?}", shuffled.stats());
    assert_eq!(shuffled.last_outputs(), in_order.last_outputs());
    let (a, b) = (shuffled.sensors().of(Some(3)), in_order.sensors().of(Some(3)));
    assert!(b.groups_detections());
    assert_eq!(a.points, b.points);
    assert_eq!(shuffled.stats().detections_grouped, in_order.stats().detections_grouped);
}

#[test]
fn the_tracks_started_on_one_car_before_an_auto_radar_turned_to_points_end_but_one_per_car() {
    // Objects first (the first scans' clusters not heeded): every detection of the two cars
    // starts a track, several are confirmed per car; once the radar turns to points the younger
    // ones are shadowed and end.
    let frames = cars(300, 5);
    let mut tracker = Tracker::new(without_scan_evidence(config(DetectionModel::Auto))).unwrap();
    let mut most_confirmed = 0;
    for frame in &frames {
        let confirmed = tracker.step(frame).unwrap().iter().filter(|o| o.status.is_confirmed()).count();
        most_confirmed = most_confirmed.max(confirmed);
    }
    assert!(most_confirmed > 2, "{most_confirmed}");
    let survivors: Vec<_> = tracker.tracks().iter().filter(|t| t.status.is_confirmed()).collect();
    assert_eq!(survivors.len(), 2, "{survivors:?}");
    assert!(tracker.sensors().of(Some(3)).groups_detections());
}

/// `config` with an `auto` radar's first scans not heeded: it starts as objects whatever they
/// show.
fn without_scan_evidence(mut config: Config) -> Config {
    config.frame.grouping.points_scan_share = 1.0;
    config
}

#[test]
fn an_auto_radar_whose_first_scans_show_point_clouds_groups_them_from_the_start() {
    // The cars' four face detections link into clusters of four in the first scan.
    let frames = cars(300, 5);
    let most_confirmed = |config: Config| {
        let mut tracker = Tracker::new(config).unwrap();
        frames
            .iter()
            .map(|frame| tracker.step(frame).unwrap().iter().filter(|o| o.status.is_confirmed()).count())
            .max()
    };
    let (auto, points, objects_first) = (
        most_confirmed(config(DetectionModel::Auto)),
        most_confirmed(config(DetectionModel::Points)),
        most_confirmed(without_scan_evidence(config(DetectionModel::Auto))),
    );
    assert!(auto <= points && auto < objects_first, "{auto:?} {points:?} {objects_first:?}");
    let mut tracker = Tracker::new(config(DetectionModel::Auto)).unwrap();
    for (k, frame) in frames.iter().enumerate() {
        tracker.step(frame).unwrap();
        if k == 0 {
            let sensor = tracker.sensors().of(Some(3));
            assert!(sensor.groups_detections(), "{:?}", sensor.points);
            // Ten vehicle detections, the wheel returns (twice the body's radial velocity) apart.
            assert_eq!(sensor.points.scan_detections, 10);
            assert!(sensor.points.scan_clustered >= 6, "{:?}", sensor.points);
        }
    }
    let sensor = tracker.sensors().of(Some(3));
    assert!(sensor.groups_detections() && sensor.points.samples > 100, "{:?}", sensor.points);
    assert_eq!(sensor.points.switches, 1, "{:?}", sensor.points);
}

#[test]
fn an_auto_radar_whose_first_scans_give_objects_one_or_two_detections_starts_with_objects() {
    // Two cars side by side, one detection each, and a second detection on the first car now
    // and then (a radar that reflects on the outline): pairs, no cluster of three.
    let mut frames = cars(300, 1);
    for (k, frame) in frames.iter_mut().enumerate().filter(|(k, _)| k % 3 == 0) {
        let mut second = frame.measurements[0];
        second.x_m -= 1.5;
        second.y_m += 0.2 * (k % 2) as f64;
        frame.measurements.push(second);
    }
    let mut tracker = Tracker::new(config(DetectionModel::Auto)).unwrap();
    for frame in &frames[..10] {
        tracker.step(frame).unwrap();
        let sensor = tracker.sensors().of(Some(3));
        assert!(!sensor.groups_detections(), "{:?}", sensor.points);
    }
    let sensor = tracker.sensors().of(Some(3));
    // Counted until the radar's first track scan.
    assert_eq!(sensor.points.scan_clustered, 0, "{:?}", sensor.points);
    assert!(sensor.points.scan_detections >= 4 && sensor.points.samples > 0, "{:?}", sensor.points);
}

#[test]
fn the_point_cloud_sensor_file_is_the_shipped_configuration_with_every_radar_delivering_points() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/sensors/point_cloud.toml");
    assert_eq!(primm_config::from_file(&path).unwrap(), config(DetectionModel::Points));
}

#[test]
fn bad_point_cloud_keys_are_refused_by_name() {
    let text = primm_config::DEFAULT_CONFIG_TOML.replacen(
        "range_std_m = 0.12",
        "range_std_m = 0.12\ndetections = \"cloud\"",
        1,
    );
    let error = primm_config::from_toml_str(&text).unwrap_err().to_string();
    assert!(error.contains("cloud") && error.contains("points"), "{error}");
    let refused = |change: fn(&mut Config)| {
        let mut config = Config::default();
        change(&mut config);
        match Tracker::new(config) {
            Err(primm_core::config::ConfigError::Invalid { key, .. }) => key,
            other => panic!("expected an invalid key, got {other:?}"),
        }
    };
    assert_eq!(refused(|c| c.frame.grouping.link_distance_m = -1.0), "frame.grouping.link_distance_m");
    assert_eq!(refused(|c| c.frame.grouping.owner_margin_m = f64::NAN), "frame.grouping.owner_margin_m");
    assert_eq!(
        refused(|c| c.frame.grouping.points_share_threshold = 1.0),
        "frame.grouping.points_share_threshold"
    );
    assert_eq!(
        refused(|c| c.frame.grouping.points_fallback_share = 0.3),
        "frame.grouping.points_fallback_share"
    );
    assert_eq!(refused(|c| c.frame.grouping.points_prior_scans = 0.0), "frame.grouping");
    assert_eq!(
        refused(|c| c.frame.grouping.points_evidence_margin_m = -0.5),
        "frame.grouping.points_evidence_margin_m"
    );
    assert_eq!(refused(|c| c.frame.grouping.points_pool_scans = -1.0), "frame.grouping.points_pool_scans");
    assert_eq!(refused(|c| c.frame.grouping.points_scan_share = 0.0), "frame.grouping.points_scan_share");
    assert_eq!(
        refused(|c| c.frame.grouping.points_scan_prior_detections = f64::NAN),
        "frame.grouping.points_scan_prior_detections"
    );
    assert_eq!(refused(|c| c.frame.grouping.group_noise_scale = 0.0), "frame.grouping.group_noise_scale");
    assert_eq!(refused(|c| c.frame.grouping.group_noise_scale = 1.5), "frame.grouping.group_noise_scale");
    assert_eq!(
        refused(|c| c.frame.grouping.pedestrian_link_scale = 0.0),
        "frame.grouping.pedestrian_link_scale"
    );
}

/// Vehicles driving along x at `speed_mps` in the near lane of [`cars`], one behind the other
/// (`(offset_m, length_m)`: the centre's offset along x and the length), seen by the front-left
/// radar: per scan and vehicle a detection on its rear face and four along the side facing the
/// radar, spread over its length.
fn side_on(frames: usize, vehicles: &[(f64, f64)], speed_mps: f64) -> Vec<Frame> {
    let mut noise = Noise(5);
    let sensor_m = DVec2::new(3.86, 0.70);
    let velocity = DVec2::new(speed_mps, 0.0);
    (0..frames)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            for (id, &(offset_m, length_m)) in vehicles.iter().enumerate() {
                let centre = DVec2::new(20.0 + offset_m + speed_mps * t, 2.0);
                let half_m = 0.5 * length_m;
                let mut points = [centre + DVec2::new(-half_m, 0.3 * noise.next()); 5];
                for (p, point) in points.iter_mut().skip(1).enumerate() {
                    let along_m = -half_m + length_m * (p as f64 + 0.5 + 0.5 * noise.next()) / 4.0;
                    *point = centre + DVec2::new(along_m, -0.9);
                }
                for point in points {
                    let measured_m = DVec2::new(point.x + 0.2 * noise.next(), point.y + 0.2 * noise.next());
                    let radial_velocity_mps = velocity.dot((point - sensor_m).normalize());
                    frame.measurements.push(car_detection(
                        measured_m,
                        radial_velocity_mps,
                        10.0,
                        Some(id as u64 + 1),
                    ));
                }
            }
            frame
        })
        .collect()
}

#[test]
fn a_lorry_tracked_at_both_ends_as_objects_keeps_one_track_once_its_radar_groups() {
    // 7.5 m long, 3 m more than the car class's box: tracked as objects (as an `auto` radar
    // does first), its detections start tracks at its rear and its front, whose boxes overlap.
    let lorry = side_on(200, &[(0.0, 7.5)], 8.0);
    let (as_objects, _) = confirmed_per_frame(config(DetectionModel::Objects), &lorry);
    assert!(as_objects > 2.5, "{as_objects} confirmed tracks per frame as objects");
    let (auto, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &lorry);
    assert!(tracker.sensors().of(Some(3)).groups_detections());
    assert!((auto - 1.0).abs() < 0.05, "{auto} confirmed tracks per frame");
}

/// Six cars queued nose to tail, 0.7 m between bumpers, driving along −x at 4 m/s in the near
/// lane of [`cars`] towards and past the front-left radar, which reports each as an object at
/// the point of its outline nearest to the radar (with ±0.1 m of noise).
fn queue_passing(frames: usize) -> Vec<Frame> {
    let mut noise = Noise(17);
    let sensor_m = DVec2::new(3.86, 0.70);
    let velocity = DVec2::new(-4.0, 0.0);
    (0..frames)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            for id in 0..6u64 {
                let centre = DVec2::new(22.0 + 5.2 * id as f64 - 4.0 * t, 2.0);
                let nearest =
                    centre + (sensor_m - centre).clamp(DVec2::new(-2.25, -0.9), DVec2::new(2.25, 0.9));
                let measured_m = DVec2::new(nearest.x + 0.2 * noise.next(), nearest.y + 0.2 * noise.next());
                let radial_velocity_mps = velocity.dot((nearest - sensor_m).normalize());
                frame.measurements.push(car_detection(measured_m, radial_velocity_mps, 10.0, Some(id + 1)));
            }
            frame
        })
        .collect()
}

#[test]
fn a_queue_of_cars_an_object_list_reports_nose_to_tail_keeps_an_auto_radar_with_objects() {
    // As the queue passes the radar, a car's rear corner lies within the evidence margin of the
    // box of the car behind it, whose front corner the radar reports.
    let frames = queue_passing(300);
    let (_, tracker) = confirmed_per_frame(config(DetectionModel::Auto), &frames);
    let sensor = tracker.sensors().of(Some(3));
    assert!(sensor.points.samples > 300, "{:?}", sensor.points);
    assert!(!sensor.groups_detections(), "{:?}", sensor.points);
    assert!(sensor.points.share() < 0.15, "{:?}", sensor.points);
}

#[test]
fn a_car_that_appears_in_the_next_lane_beyond_a_tracked_car_moving_alike_starts_its_track() {
    // The second car, in a lane 5.5 m beyond the first (beyond its owner margin) and 1.5 m
    // ahead, appears after 1 s where an image of the first in a wall between the lanes would
    // stand, moving as such an image would; it is as strong as the first, so it is no image.
    let sensor_m = DVec2::new(3.86, 0.70);
    let mut frames = cars(300, 5);
    for (k, frame) in frames.iter_mut().enumerate() {
        frame.measurements.retain(|measurement| k >= 20 || measurement.ground_truth_id != Some(2));
        for measurement in frame.measurements.iter_mut().filter(|m| m.ground_truth_id == Some(2)) {
            measurement.x_m += 1.5;
            measurement.y_m += 2.0;
            let line_of_sight = (measurement.position() - sensor_m).normalize();
            measurement.radial_velocity_mps = 12.0 * line_of_sight.x;
        }
    }
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    let mut last = Vec::new();
    for frame in &frames {
        last = tracker.step(frame).unwrap().to_vec();
    }
    assert_eq!(tracker.stats().initiations_refused_as_ghost, 0);
    let confirmed: Vec<_> = last.iter().filter(|output| output.status.is_confirmed()).collect();
    assert_eq!(confirmed.len(), 2, "{confirmed:?}");
    assert!(confirmed.iter().any(|output| output.ground_truth_id == Some(2)), "{confirmed:?}");
}
