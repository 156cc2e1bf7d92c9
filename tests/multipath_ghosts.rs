//! Multipath ghosts (`tracker/ghosts.rs`, ARCHITECTURE.md "Point clouds"): a measurement at the
//! mirror image of a confirmed moving track in a wall along its heading, moving as that image
//! and weaker, starts no track on a point-cloud radar; a real object at the same place that
//! moves otherwise, or is as strong, is tracked, and an object radar's frames are not checked. A tentative track that a weaker
//! echo at the mirror image in a wall at any angle started ends (also when its first update
//! would confirm it, as a pedestrian's does), a standing car's image too; one
//! as strong as the object, moving otherwise, or of another class behind a standing object, is
//! tracked.

use glam::DVec2;
use primm_core::config::Config;
use primm_core::grouping::DetectionModel;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::pose::EgoPose;
use primm_core::tracker::Tracker;

/// A car driving along x at 12 m/s at y = 2 m past a standing ego, seen by the front-left radar
/// (id 3) every 50 ms, and from frame 40 (2 s) on a second object, as strong as the car, at the
/// position and velocity `second(t, centre, velocity)` gives from the time and the car's.
fn frames(second: impl Fn(f64, DVec2, DVec2) -> (DVec2, DVec2)) -> Vec<Frame> {
    car_and_second(12.0, 40, ObjectClass::Car, move |t, centre, velocity| {
        let (position, velocity) = second(t, centre, velocity);
        (position, velocity, 5.0)
    })
}

/// A car (RCS 5 dBsm) driving along x at `speed_mps` from x = 15 m at y = 2 m past a standing
/// ego, seen by the front-left radar (id 3) every 50 ms for 6 s, and from frame `from_frame` on
/// a second object of `second_class` at the position, velocity and RCS `second(t, centre,
/// velocity)` gives.
fn car_and_second(
    speed_mps: f64,
    from_frame: usize,
    second_class: ObjectClass,
    second: impl Fn(f64, DVec2, DVec2) -> (DVec2, DVec2, f64),
) -> Vec<Frame> {
    let sensor_m = DVec2::new(3.86, 0.70);
    (0..120)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            let (centre, velocity) = (DVec2::new(15.0 + speed_mps * t, 2.0), DVec2::new(speed_mps, 0.0));
            let mut push = |position: DVec2, velocity: DVec2, rcs_dbsm: f64, class: ObjectClass, id: u64| {
                frame.measurements.push(Measurement {
                    x_m: position.x,
                    y_m: position.y,
                    radial_velocity_mps: velocity.dot((position - sensor_m).normalize()),
                    rcs_dbsm,
                    class,
                    sensor_id: Some(3),
                    ground_truth_id: Some(id),
                })
            };
            push(centre, velocity, 5.0, ObjectClass::Car, 1);
            if k >= from_frame {
                let (position, velocity, rcs_dbsm) = second(t, centre, velocity);
                push(position, velocity, rcs_dbsm, second_class, 2);
            }
            frame
        })
        .collect()
}

/// The ids of the tracks confirmed at the end, and the tracker.
fn confirmed(frames: &[Frame]) -> (usize, Tracker) {
    // The check runs on point-cloud radars' frames.
    let mut config = Config::default();
    config.frame.sensors.iter_mut().for_each(|sensor| sensor.detections = DetectionModel::Points);
    let mut tracker = Tracker::new(config).unwrap();
    let mut count = 0;
    for frame in frames {
        count = tracker.step(frame).unwrap().iter().filter(|o| o.status.is_confirmed()).count();
    }
    (count, tracker)
}

#[test]
fn the_image_of_a_car_in_a_wall_along_the_road_starts_no_track() {
    // A wall at y = 10 m: the image at y = 18 m moves with the mirrored velocity (the same, the
    // wall being parallel to it), 8 dB weaker than the car.
    let mirror = |_, centre: DVec2, velocity: DVec2| {
        (DVec2::new(centre.x, 20.0 - centre.y), DVec2::new(velocity.x, -velocity.y), -3.0)
    };
    let (count, tracker) = confirmed(&car_and_second(12.0, 40, ObjectClass::Car, mirror));
    assert_eq!(count, 1);
    let stats = tracker.stats();
    assert!(stats.initiations_refused_as_ghost > 50, "{stats:?}");
}

#[test]
fn a_car_as_strong_as_another_where_its_image_would_be_is_tracked() {
    // The same place and velocity as the image above, but as strong as the car: a second car
    // in a lane beyond it.
    let beside = |_, centre: DVec2, velocity: DVec2| {
        (DVec2::new(centre.x, 20.0 - centre.y), DVec2::new(velocity.x, -velocity.y))
    };
    let (count, tracker) = confirmed(&frames(beside));
    assert_eq!(count, 2);
    assert_eq!(tracker.stats().initiations_refused_as_ghost, 0);
}

#[test]
fn a_car_where_the_image_would_be_that_drives_the_other_way_is_tracked() {
    // At the image's place when it appears, then driving towards the ego.
    let oncoming = |t: f64, _, _| (DVec2::new(39.0 - 12.0 * (t - 2.0), 18.0), DVec2::new(-12.0, 0.0));
    let (count, tracker) = confirmed(&frames(oncoming));
    assert_eq!(count, 2);
    assert_eq!(tracker.stats().initiations_refused_as_ghost, 0);
}

#[test]
fn an_object_radars_frames_are_not_checked() {
    let mirror = |_, centre: DVec2, velocity: DVec2| {
        (DVec2::new(centre.x, 20.0 - centre.y), DVec2::new(velocity.x, -velocity.y))
    };
    let mut tracker = Tracker::new(Config::default()).unwrap();
    for frame in &frames(mirror) {
        tracker.step(frame).unwrap();
    }
    assert_eq!(tracker.stats().initiations_refused_as_ghost, 0);
    assert_eq!(tracker.tracks().iter().filter(|t| t.status.is_confirmed()).count(), 2);
}

/// A car driving along x at 8 m/s at y = 2 m towards a junction, a building front across the
/// road at x = 65 m, seen by the front-left radar (id 3) every 50 ms; from frame 60 (3 s) on a
/// second object at the position, velocity and RCS `second(t, centre, velocity)` gives.
fn junction_frames(second: impl Fn(f64, DVec2, DVec2) -> (DVec2, DVec2, f64)) -> Vec<Frame> {
    car_and_second(8.0, 60, ObjectClass::Car, second)
}

/// The image of the car in the building front at x = 65 m, with RCS `rcs_dbsm`.
fn junction_image(rcs_dbsm: f64) -> impl Fn(f64, DVec2, DVec2) -> (DVec2, DVec2, f64) {
    move |_, centre: DVec2, velocity: DVec2| {
        (DVec2::new(130.0 - centre.x, centre.y), DVec2::new(-velocity.x, velocity.y), rcs_dbsm)
    }
}

#[test]
fn a_weaker_image_of_a_car_in_a_wall_across_the_road_ends_as_a_tentative_track() {
    // 8 dB weaker than the car; the wall is across the heading, so the measurement check
    // (walls along the heading) lets it start tracks.
    let (count, tracker) = confirmed(&junction_frames(junction_image(-3.0)));
    assert_eq!(count, 1);
    let stats = tracker.stats();
    assert!(stats.tentative_tracks_ended_as_ghost > 10, "{stats:?}");
}

#[test]
fn an_oncoming_car_as_strong_as_the_image_would_be_weak_is_tracked() {
    // Where the image would be, moving as it would, but as strong as the car: a real car.
    let (count, tracker) = confirmed(&junction_frames(junction_image(5.0)));
    assert_eq!(count, 2);
    assert_eq!(tracker.stats().tentative_tracks_ended_as_ghost, 0);
}

#[test]
fn a_weak_object_where_the_image_would_be_that_moves_otherwise_is_tracked() {
    // As weak as the image, at its place, but driving away from the wall, not mirroring the car.
    let away = |t: f64, _, _| (DVec2::new(91.0 + 8.0 * (t - 3.0), 2.0), DVec2::new(8.0, 0.0), -3.0);
    let (count, tracker) = confirmed(&junction_frames(away));
    assert_eq!(count, 2);
    assert_eq!(tracker.stats().tentative_tracks_ended_as_ghost, 0);
}

#[test]
fn the_weaker_image_of_a_standing_car_ends_as_a_tentative_track() {
    // A car standing at (15, 2), its image in a wall at y = 10 m, standing too, 8 dB weaker.
    let image = |_, centre: DVec2, _| (DVec2::new(centre.x, 20.0 - centre.y), DVec2::ZERO, -3.0);
    let (count, tracker) = confirmed(&car_and_second(0.0, 40, ObjectClass::Car, image));
    assert_eq!(count, 1);
    let stats = tracker.stats();
    assert!(stats.tentative_tracks_ended_as_ghost > 10, "{stats:?}");
}

#[test]
fn a_pedestrian_standing_behind_a_standing_car_is_tracked() {
    // 10 dB weaker than the car, farther from the radar, waiting on the pavement 8 m behind it
    // and seen in every third scan only: where a standing car's image could be, but of another
    // class.
    let mut frames = car_and_second(0.0, 40, ObjectClass::Pedestrian, |_, _, _| {
        (DVec2::new(15.0, 10.0), DVec2::ZERO, -5.0)
    });
    for (k, frame) in frames.iter_mut().enumerate() {
        if k % 3 != 0 {
            frame.measurements.retain(|m| m.class == ObjectClass::Car);
        }
    }
    let (count, tracker) = confirmed(&frames);
    assert_eq!(count, 2);
    assert_eq!(tracker.stats().tentative_tracks_ended_as_ghost, 0);
}

/// A pedestrian (−5 dBsm) walking along x at 1.5 m/s at y = 2 m towards a building front
/// across the pavement at x = 35 m, seen by the front-left radar (id 3) every 50 ms for 6 s, and
/// from frame `image_from` on its image in the front, 8 dB weaker, listed before the pedestrian
/// in each frame when `image_first`. Asserts that no track beyond the front is ever confirmed;
/// returns the tracker.
fn pedestrian_and_image(image_from: usize, image_first: bool) -> Tracker {
    let sensor_m = DVec2::new(3.86, 0.70);
    let frames: Vec<Frame> = (0..120)
        .map(|k| {
            let t = 0.05 * k as f64;
            let mut frame = Frame::new(t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            let centre = DVec2::new(20.0 + 1.5 * t, 2.0);
            let image = DVec2::new(70.0 - centre.x, centre.y);
            let mut push = |position: DVec2, velocity: DVec2, rcs_dbsm: f64, id: Option<u64>| {
                frame.measurements.push(Measurement {
                    x_m: position.x,
                    y_m: position.y,
                    radial_velocity_mps: velocity.dot((position - sensor_m).normalize()),
                    rcs_dbsm,
                    class: ObjectClass::Pedestrian,
                    sensor_id: Some(3),
                    ground_truth_id: id,
                })
            };
            let with_image = k >= image_from;
            if with_image && image_first {
                push(image, DVec2::new(-1.5, 0.0), -13.0, None);
            }
            push(centre, DVec2::new(1.5, 0.0), -5.0, Some(1));
            if with_image && !image_first {
                push(image, DVec2::new(-1.5, 0.0), -13.0, None);
            }
            frame
        })
        .collect();
    let mut config = Config::default();
    config.frame.sensors.iter_mut().for_each(|sensor| sensor.detections = DetectionModel::Points);
    let mut tracker = Tracker::new(config).unwrap();
    for frame in &frames {
        let outputs = tracker.step(frame).unwrap();
        let confirmed: Vec<_> =
            outputs.iter().filter(|o| o.status.is_confirmed()).map(|o| (o.id, o.position_m)).collect();
        assert!(
            confirmed.iter().all(|(_, position)| position.x < 35.0),
            "t = {}: {confirmed:?}",
            frame.timestamp_s
        );
    }
    assert_eq!(tracker.tracks().iter().filter(|t| t.status.is_confirmed()).count(), 1);
    tracker
}

#[test]
fn a_pedestrians_image_ends_even_when_its_first_update_would_confirm_it() {
    // A pedestrian's small spread makes a second detection at the predicted place strong
    // evidence, so the image's track would be confirmed on its first update.
    let tracker = pedestrian_and_image(40, false);
    assert!(tracker.stats().tentative_tracks_ended_as_ghost > 10, "{:?}", tracker.stats());
}

#[test]
fn an_image_that_appears_with_its_object_and_starts_its_track_first_ends() {
    // From the first scan on, the image listed first: its track is started before the
    // pedestrian's, in the same frame.
    let tracker = pedestrian_and_image(0, true);
    assert!(tracker.stats().tentative_tracks_ended_as_ghost > 10, "{:?}", tracker.stats());
}
