//! Cars tracked as extended objects (`classes.<class>.extent`): with reflections from the point
//! of each car's box nearest to the sensor, as independent radar data has them, the tracks
//! follow the cars' centres instead of their reflections.

use crate::common::{rng, standard_normal};
use glam::DVec2;
use primm_core::config::Config;
use primm_core::extent::nearest_point_of_box;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

const DT_S: f64 = 0.03;
/// The default mounts' positions, ids 1 to 4.
const MOUNTS_M: [DVec2; 4] =
    [DVec2::new(3.66, -0.87), DVec2::new(3.86, -0.70), DVec2::new(3.86, 0.70), DVec2::new(3.66, 0.87)];

fn config(extent: bool) -> Config {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.classes.car.extent.enabled = extent;
    config
}

/// The ego pose at `t`: 6 m/s straight along x.
fn ego_pose(t: f64) -> EgoPose {
    EgoPose { x_m: 6.0 * t, y_m: 0.0, yaw_rad: 0.0 }
}

/// World centre and velocity of car `index` at `t`: cars ahead and beside the ego, each on its
/// own heading.
fn car(index: usize, t: f64) -> (DVec2, DVec2) {
    let heading = 0.9 * index as f64 - 1.2;
    let speed = 4.0 + 2.0 * index as f64;
    let velocity = DVec2::new(heading.cos(), heading.sin()) * speed;
    let start =
        [DVec2::new(25.0, -12.0), DVec2::new(35.0, 8.0), DVec2::new(20.0, 15.0), DVec2::new(45.0, -4.0)];
    (start[index] + velocity * t, velocity)
}

/// Frames of the four radars in turn, each reporting every car in its half-plane from the point
/// of the car's 4.5 × 1.8 m box nearest to it, with 0.2 m of noise; the true centres alongside.
fn frames(count: usize, seed: u64) -> Vec<(Frame, Vec<DVec2>)> {
    let mut rng = rng(seed);
    (0..count)
        .map(|k| {
            let t = k as f64 * DT_S;
            let pose = ego_pose(t);
            let sensor = k % 4;
            let sensor_world = pose.point_to_world(MOUNTS_M[sensor]);
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(pose);
            let mut centres = Vec::new();
            for index in 0..4 {
                let (centre, velocity) = car(index, t);
                centres.push(centre);
                let reflection = nearest_point_of_box(4.5, 1.8, centre, velocity.normalize(), sensor_world);
                let line_of_sight = (reflection - sensor_world).normalize();
                let vehicle = pose.world_to_car(reflection);
                frame.measurements.push(Measurement {
                    x_m: vehicle.x + 0.2 * standard_normal(&mut rng),
                    y_m: vehicle.y + 0.2 * standard_normal(&mut rng),
                    radial_velocity_mps: velocity.dot(line_of_sight) + 0.1 * standard_normal(&mut rng),
                    rcs_dbsm: 10.0,
                    class: ObjectClass::Car,
                    sensor_id: Some(sensor as u16 + 1),
                    ground_truth_id: Some(index as u64),
                });
            }
            (frame, centres)
        })
        .collect()
}

/// RMS distance of the tracks' world positions from the true centres over frames 30.., m, and
/// the most live tracks at once.
fn centre_error(tracker: &mut Tracker, frames: &[(Frame, Vec<DVec2>)]) -> (f64, usize) {
    let (mut sum, mut count, mut most) = (0.0, 0usize, 0);
    for (k, (frame, centres)) in frames.iter().enumerate() {
        let outputs = tracker.step(frame).unwrap();
        most = most.max(outputs.len());
        if k < 30 {
            continue;
        }
        for output in outputs.iter().filter(|output| output.ground_truth_id.is_some()) {
            let truth = centres[output.ground_truth_id.unwrap() as usize];
            sum += (output.world_position_m.expect("a world-frame track") - truth).length_squared();
            count += 1;
        }
    }
    assert!(count > 300, "{count} track rows");
    ((sum / count as f64).sqrt(), most)
}

#[test]
fn tracks_of_cars_follow_their_centres_not_their_reflections() {
    let frames = frames(200, 21);
    let (point, _) = centre_error(&mut Tracker::new(config(false)).unwrap(), &frames);
    let (extended, most) = centre_error(&mut Tracker::new(config(true)).unwrap(), &frames);
    println!("centre error: point model {point:.3} m, extended {extended:.3} m");
    assert!(extended < 0.6 * point, "extended {extended:.3} m, point {point:.3} m");
    assert!(most <= 5, "{most} tracks for four cars");
}

#[test]
fn a_class_without_extent_is_tracked_exactly_as_before() {
    // Enabling the extent of two-wheelers changes nothing for a scene of cars.
    let frames = frames(60, 22);
    let mut plain = Tracker::new(config(false)).unwrap();
    let mut other = config(false);
    other.classes.two_wheeler.extent.enabled = true;
    let mut with_other = Tracker::new(other).unwrap();
    for (frame, _) in &frames {
        let a = plain.step(frame).unwrap().to_vec();
        let b = with_other.step(frame).unwrap().to_vec();
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
}

#[test]
fn a_second_detection_of_a_confirmed_car_starts_no_track_when_extra_detections_are_absorbed() {
    // From frame 40 on (the cars' tracks confirmed), every third scan also reports each car's
    // left rear corner.
    let mut frames = frames(150, 23);
    for (k, (frame, _)) in frames.iter_mut().enumerate().filter(|(k, _)| *k >= 40 && k % 3 == 0) {
        let pose = ego_pose(k as f64 * DT_S);
        let extra: Vec<Measurement> = (0..4)
            .map(|index| {
                let (centre, velocity) = car(index, k as f64 * DT_S);
                let heading = velocity.normalize();
                let corner = centre - heading * 2.25 + heading.perp() * 0.9;
                let vehicle = pose.world_to_car(corner);
                Measurement { x_m: vehicle.x, y_m: vehicle.y, ..frame.measurements[index] }
            })
            .collect();
        frame.measurements.extend(extra);
    }
    let run = |absorb: bool| {
        let mut config = config(true);
        config.classes.car.extent.absorb_extra_detections = absorb;
        let mut tracker = Tracker::new(config).unwrap();
        let mut most = 0;
        for (frame, _) in &frames {
            tracker.step(frame).unwrap();
            most = most.max(tracker.last_step().live_tracks);
        }
        (most, *tracker.stats())
    };
    let (most_absorbing, absorbing) = run(true);
    let (most_plain, plain) = run(false);
    println!(
        "most live tracks: {most_absorbing} absorbing, {most_plain} without; absorbed {}",
        absorbing.detections_absorbed
    );
    assert!(absorbing.detections_absorbed > 100, "{absorbing:?}");
    assert_eq!(plain.detections_absorbed, 0);
    assert_eq!(absorbing.tracks_initiated, 4, "one track per car: {absorbing:?}");
    assert!(plain.tracks_initiated >= 8, "a second track for every car: {plain:?}");
    assert!(most_absorbing == 4 && most_absorbing < most_plain, "{most_absorbing} vs {most_plain}");
}
