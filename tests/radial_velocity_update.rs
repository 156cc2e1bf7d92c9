//! The measured radial velocity as a measurement of the velocity in the CV, CA and CT updates
//! (`classes.<class>.radial_velocity_update`): it makes velocities converge faster and truer,
//! it is counted, gated and seen from the right sensor, and switched off it changes nothing.

use crate::common::{rng, standard_normal};
use glam::DVec2;
use primm_core::config::{Config, RadialLineOfSight};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

const DT_S: f64 = 0.05;
/// Sensor 3 of the default mounts (front left, yawed 25°).
const SENSOR_3_M: DVec2 = DVec2::new(3.86, 0.70);

fn config(radial_velocity_update: bool) -> Config {
    // Point objects: the scene measures the cars' centres.
    let mut config = Config::default().with_modes(Method::Imm.modes()).with_point_objects();
    for class in ObjectClass::ALL {
        config.classes.get_mut(class).radial_velocity_update.enabled = radial_velocity_update;
    }
    config
}

/// The ego pose at `t`: 8 m/s, turning left at 0.2 rad/s.
fn ego_pose(t: f64) -> EgoPose {
    let (speed, yaw_rate) = (8.0, 0.2);
    let yaw = yaw_rate * t;
    let radius = speed / yaw_rate;
    EgoPose { x_m: radius * yaw.sin(), y_m: radius * (1.0 - yaw.cos()), yaw_rad: yaw }
}

/// World position and velocity of car `index` at `t`: cars crossing ahead at 5–9 m/s.
fn car(index: usize, t: f64) -> (DVec2, DVec2) {
    let velocity = DVec2::new(-1.0 + 0.5 * index as f64, 5.0 + index as f64);
    (DVec2::new(30.0 + 6.0 * index as f64, -25.0 - 4.0 * index as f64) + velocity * t, velocity)
}

/// Frames of four crossing cars seen by sensor `sensor_id` (mounted at sensor 3's place), with
/// 0.4 m position noise and 0.1 m/s radial-velocity noise (over ground).
fn frames(count: usize, sensor_id: Option<u16>, seed: u64) -> Vec<(Frame, Vec<DVec2>)> {
    measured_frames(count, sensor_id, seed, 0.4, |index, t, _| car(index, t))
}

/// Frames of the four cars at `detection(index, t, sensor's world position)`, the detected
/// point and the car's velocity (world frame), seen by sensor `sensor_id` with `noise_m` of
/// position noise and 0.1 m/s of radial-velocity noise along the line of sight to the detection.
fn measured_frames(
    count: usize,
    sensor_id: Option<u16>,
    seed: u64,
    noise_m: f64,
    detection: impl Fn(usize, f64, DVec2) -> (DVec2, DVec2),
) -> Vec<(Frame, Vec<DVec2>)> {
    let mut rng = rng(seed);
    (0..count)
        .map(|k| {
            let t = k as f64 * DT_S;
            let pose = ego_pose(t);
            let sensor_world = pose.point_to_world(SENSOR_3_M);
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(pose);
            let mut velocities = Vec::new();
            for index in 0..4 {
                let (position, velocity) = detection(index, t, sensor_world);
                let vehicle = pose.world_to_car(position);
                let line_of_sight = (position - sensor_world).normalize();
                frame.measurements.push(Measurement {
                    x_m: vehicle.x + noise_m * standard_normal(&mut rng),
                    y_m: vehicle.y + noise_m * standard_normal(&mut rng),
                    radial_velocity_mps: velocity.dot(line_of_sight) + 0.1 * standard_normal(&mut rng),
                    rcs_dbsm: 10.0,
                    class: ObjectClass::Car,
                    sensor_id,
                    ground_truth_id: Some(index as u64),
                });
                velocities.push(velocity);
            }
            (frame, velocities)
        })
        .collect()
}

/// RMS error of the world velocities of the tracks over frames 10.. (after the start), m/s.
fn velocity_rmse(tracker: &mut Tracker, frames: &[(Frame, Vec<DVec2>)]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, (frame, velocities)) in frames.iter().enumerate() {
        let outputs = tracker.step(frame).unwrap();
        if k < 10 {
            continue;
        }
        for output in outputs.iter().filter(|output| output.ground_truth_id.is_some()) {
            let truth = velocities[output.ground_truth_id.unwrap() as usize];
            sum += (output.world_velocity_mps.expect("a world-frame track") - truth).length_squared();
            count += 1;
        }
    }
    assert!(count > 100, "{count} track rows");
    (sum / count as f64).sqrt()
}

#[test]
fn the_radial_velocity_row_brings_track_velocities_closer_to_the_truth() {
    let frames = frames(80, Some(3), 11);
    let without = velocity_rmse(&mut Tracker::new(config(false)).unwrap(), &frames);
    let mut tracker = Tracker::new(config(true)).unwrap();
    let with = velocity_rmse(&mut tracker, &frames);
    println!("velocity RMSE without the row {without:.3} m/s, with it {with:.3} m/s");
    assert!(with < 0.8 * without, "with {with:.3} m/s, without {without:.3} m/s");
    let stats = tracker.stats();
    assert!(stats.radial_velocity_updates > 250, "{stats:?}");
    assert_eq!(stats.updates_from_unknown_sensor, 0);
}

#[test]
fn switched_off_the_row_is_never_applied_nor_counted() {
    let frames = frames(40, Some(3), 12);
    let mut tracker = Tracker::new(config(false)).unwrap();
    for (frame, _) in &frames {
        tracker.step(frame).unwrap();
        assert_eq!(tracker.last_step().counts.radial_velocity_updates, 0);
    }
    let stats = tracker.stats();
    assert_eq!(
        (
            stats.radial_velocity_updates,
            stats.radial_velocity_updates_gated,
            stats.updates_from_unknown_sensor
        ),
        (0, 0, 0)
    );
}

#[test]
fn a_radial_velocity_the_track_cannot_explain_is_gated_and_counted() {
    let mut frames = frames(40, Some(3), 13);
    // The paper's association cost caps the radial-velocity difference, so the frame below is
    // still associated (the likelihood cost would start new tracks instead).
    let mut config = config(true);
    config.association.cost = primm_core::config::AssociationCost::Paper;
    let mut tracker = Tracker::new(config).unwrap();
    for (frame, _) in &frames[..30] {
        tracker.step(frame).unwrap();
    }
    let before = *tracker.stats();
    // Every radial velocity of frame 30 off by 40 m/s (an aliased Doppler).
    for measurement in frames[30].0.measurements.iter_mut() {
        measurement.radial_velocity_mps += 40.0;
    }
    let velocity = |track: &primm_core::track::Track| {
        let mean = &track.estimate.constant_velocity.mean;
        DVec2::new(mean[2], mean[3])
    };
    let velocities: Vec<DVec2> = tracker.tracks().iter().map(velocity).collect();
    assert_eq!(velocities.len(), 4);
    tracker.step(&frames[30].0).unwrap();
    let gated = tracker.stats().radial_velocity_updates_gated - before.radial_velocity_updates_gated;
    assert_eq!(gated, 4, "{:?}", tracker.last_step());
    for (track, before) in tracker.tracks().iter().zip(&velocities) {
        let change = velocity(track) - *before;
        assert!(change.length() < 3.0, "the aliased radial velocity moved a track's velocity by {change}");
    }
}

#[test]
fn measurements_of_a_sensor_without_mount_are_seen_from_the_reference_point_and_counted() {
    let frames = frames(30, None, 14);
    let mut tracker = Tracker::new(config(true)).unwrap();
    for (frame, _) in &frames {
        tracker.step(frame).unwrap();
    }
    let stats = tracker.stats();
    assert!(stats.radial_velocity_updates > 50, "{stats:?}");
    assert_eq!(stats.updates_from_unknown_sensor, stats.radial_velocity_updates);
}

#[test]
fn without_a_pose_the_row_is_left_out_since_the_ego_motion_is_unknown() {
    let mut frames = frames(30, Some(3), 15);
    let mut tracker = Tracker::new(config(true)).unwrap();
    for (frame, _) in frames.iter_mut() {
        frame.ego_pose = None;
        tracker.step(frame).unwrap();
    }
    assert_eq!(tracker.stats().radial_velocity_updates, 0);
    assert!(tracker.stats().measurements_accepted > 100);
}

/// Frames of four crossing cars, near the sensor, as extended objects: each detection lies halfway between
/// the car's centre and the point of its 4.5 × 1.8 m box nearest to the sensor (the default
/// `offset_scale`), with 0.2 m of position noise, and its radial velocity is measured along
/// the line of sight to that detection (0.1 m/s noise).
fn extended_frames(count: usize, seed: u64) -> Vec<(Frame, Vec<DVec2>)> {
    measured_frames(count, Some(3), seed, 0.2, |index, t, sensor_world| {
        // The crossing cars of `car`, 20 m nearer: 8–20 m from the sensor.
        let (far, velocity) = car(index, t);
        let centre = far - DVec2::new(20.0, -16.0);
        let nearest =
            primm_core::extent::nearest_point_of_box(4.5, 1.8, centre, velocity.normalize(), sensor_world);
        (centre + 0.5 * (nearest - centre), velocity)
    })
}

#[test]
fn for_extended_cars_the_detections_own_line_of_sight_gives_truer_velocities_than_the_centres() {
    let frames = extended_frames(80, 16);
    let tracker_along = |line_of_sight: RadialLineOfSight| {
        let mut config = Config::default().with_modes(Method::Imm.modes());
        config.classes.get_mut(ObjectClass::Car).radial_velocity_update.line_of_sight = line_of_sight;
        Tracker::new(config).unwrap()
    };
    let centre = velocity_rmse(&mut tracker_along(RadialLineOfSight::Predicted), &frames);
    let detection = velocity_rmse(&mut tracker_along(RadialLineOfSight::Measured), &frames);
    println!(
        "velocity RMSE along the centre's line of sight {centre:.3} m/s, the detection's {detection:.3} m/s"
    );
    assert!(detection < 0.9 * centre, "detection's {detection:.3} m/s, centre's {centre:.3} m/s");
}

#[test]
fn the_line_of_sight_key_reads_all_three_directions_and_a_file_without_it_keeps_the_shipped_one() {
    // The shipped file, with the car's key replaced (its first occurrence is in the car section).
    let shipped = primm_config::DEFAULT_CONFIG_TOML;
    let key = "line_of_sight = \"measured\"\n";
    assert!(shipped.contains(key));
    let read = |replacement: &str| {
        primm_config::from_toml_str(&shipped.replacen(key, replacement, 1))
            .map(|config| config.classes.get(ObjectClass::Car).radial_velocity_update.line_of_sight)
    };
    assert_eq!(read(key).unwrap(), RadialLineOfSight::Measured);
    // A file is laid over the shipped one: leaving the key out keeps the shipped direction.
    assert_eq!(read("").unwrap(), RadialLineOfSight::Measured);
    assert_eq!(read("line_of_sight = \"predicted\"\n").unwrap(), RadialLineOfSight::Predicted);
    assert_eq!(read("line_of_sight = \"reflection\"\n").unwrap(), RadialLineOfSight::Reflection);
    assert!(read("line_of_sight = \"centre\"\n").is_err());
}

#[test]
fn for_a_point_class_the_reflection_line_of_sight_is_the_predicted_one() {
    let frames = frames(40, Some(3), 17);
    let tracker_along = |line_of_sight: RadialLineOfSight| {
        let mut config = config(true);
        config.classes.get_mut(ObjectClass::Car).radial_velocity_update.line_of_sight = line_of_sight;
        Tracker::new(config).unwrap()
    };
    let (mut predicted, mut reflection) =
        (tracker_along(RadialLineOfSight::Predicted), tracker_along(RadialLineOfSight::Reflection));
    for (frame, _) in &frames {
        assert_eq!(predicted.step(frame).unwrap(), reflection.step(frame).unwrap());
    }
    assert!(predicted.stats().radial_velocity_updates > 100);
}
