//! A point-cloud radar's faults: a frame above capacity is refused and counted, a full frame is
//! grouped, and the worst valid frames (1,024 clutter points, 1,024 detections at one spot) and
//! a NaN point between two tracked cars' scans leave the tracks as the clean scans do and
//! allocate nothing.

use crate::point_clouds::{car_detection, cars, config, Noise};
use glam::DVec2;
use primm_core::grouping::DetectionModel;
use primm_core::limits::{MAX_MEASUREMENTS_PER_FRAME, MAX_TRACKS};
use primm_core::measurement::{Frame, FrameView, Measurement, ObjectClass, UnknownClass};
use primm_core::pose::EgoPose;
use primm_core::tracker::{StepError, Tracker};
use primm_core::validation::FrameError;

/// A frame that claims one measurement more than the capacity, repeating `frame`'s.
struct Flood {
    frame: Frame,
    timestamp_s: f64,
}

impl FrameView for Flood {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }
    fn len(&self) -> usize {
        MAX_MEASUREMENTS_PER_FRAME + 1
    }
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        Ok(self.frame.measurements[index % self.frame.measurements.len()])
    }
    fn ego_pose(&self) -> Option<EgoPose> {
        self.frame.ego_pose
    }
}

#[test]
fn a_frame_above_capacity_is_refused_and_counted_and_the_tracks_stay() {
    let frames = cars(40, 5);
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    for frame in &frames {
        tracker.step(frame).unwrap();
    }
    let before = format!("{:?}", tracker.tracks());
    let flood = Flood { frame: frames[39].clone(), timestamp_s: frames[39].timestamp_s + 0.05 };
    let error = tracker.step(&flood).unwrap_err();
    assert!(matches!(error, StepError::InvalidFrame(FrameError::TooManyMeasurements { .. })), "{error}");
    assert_eq!(tracker.stats().frames_rejected_too_many_measurements, 1);
    assert_eq!(format!("{:?}", tracker.tracks()), before);
}

/// A frame at `timestamp_s` seen by the front-left radar (id 3), with the pose of [`cars`], of
/// 1,024 detections made by `detection(i)`.
fn full_frame(timestamp_s: f64, mut detection: impl FnMut(usize) -> Measurement) -> Frame {
    let mut frame = Frame::new(timestamp_s);
    frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
    frame.measurements.extend((0..MAX_MEASUREMENTS_PER_FRAME).map(&mut detection));
    frame
}

#[test]
fn clutter_floods_detections_at_one_spot_and_a_nan_point_keep_the_tracks_and_allocate_nothing() {
    // Two cars tracked from a point-cloud radar; between their scans come a frame of 1,024
    // clutter points over 200 m x 200 m with any radial velocity, a frame of 1,024 detections at
    // one spot, and a scan of theirs with a NaN in one point.
    let frames = cars(200, 5);
    let mut noise = Noise(23);
    let clutter = full_frame(frames[80].timestamp_s + 0.025, |i| Measurement {
        x_m: 200.0 * noise.next(),
        y_m: 200.0 * noise.next(),
        radial_velocity_mps: 30.0 * noise.next(),
        rcs_dbsm: 10.0 * noise.next(),
        class: if i % 3 == 0 { ObjectClass::Pedestrian } else { ObjectClass::Car },
        sensor_id: Some(3),
        ground_truth_id: None,
    });
    let spot = full_frame(frames[100].timestamp_s + 0.025, |_| {
        car_detection(DVec2::new(40.0, -20.0), 0.0, 5.0, None)
    });
    let mut with_nan = frames[120].clone();
    with_nan.measurements[2].y_m = f64::NAN;
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    let mut track_of = std::collections::HashMap::new();
    for frame in &frames[..60] {
        for output in tracker.step(frame).unwrap() {
            if output.status.is_confirmed() {
                track_of.insert(output.ground_truth_id, output.id);
            }
        }
    }
    assert_eq!(track_of.len(), 2, "{track_of:?}");
    let (mut rejected_non_finite, mut last) = (0, Vec::with_capacity(MAX_TRACKS));
    let allocations = crate::common::counting_allocator::count_allocations(|| {
        for (k, frame) in frames.iter().enumerate().skip(60) {
            let frame = if k == 120 { &with_nan } else { frame };
            last.clear();
            last.extend(tracker.step(frame).expect("a scan of the cars is tracked").iter().copied());
            rejected_non_finite += tracker.last_step().counts.measurements_rejected_non_finite;
            if k == 80 {
                tracker.step(&clutter).expect("a frame of clutter is tracked");
            }
            if k == 100 {
                tracker.step(&spot).expect("a frame of detections at one spot is tracked");
                assert_eq!(
                    tracker.last_step().counts.detections_grouped,
                    MAX_MEASUREMENTS_PER_FRAME as u64 - 1
                );
            }
        }
    });
    assert_eq!(allocations, 0);
    assert_eq!(rejected_non_finite, 1);
    // The same two tracks follow their cars to the end, where the tracks of the same scans
    // without the bad frames end.
    let mut clean = Tracker::new(config(DetectionModel::Points)).unwrap();
    let mut clean_outputs = Vec::new();
    for frame in &frames {
        clean_outputs = clean.step(frame).unwrap().to_vec();
    }
    for id in [1u64, 2] {
        let output = last.iter().find(|output| output.id == track_of[&Some(id)]).expect("the track lives");
        assert!(output.status.is_confirmed(), "{output:?}");
        let clean_m = clean_outputs.iter().find(|o| o.ground_truth_id == Some(id)).unwrap().position_m;
        assert!(
            output.position_m.distance(clean_m) < 0.05,
            "car {id}: {} against {clean_m}",
            output.position_m
        );
    }
}

#[test]
fn a_full_frame_of_point_cloud_detections_is_grouped() {
    // 1,024 detections: 256 cars of four points each, on a grid 8 m apart.
    let mut frame = Frame::new(0.0);
    for car in 0..MAX_MEASUREMENTS_PER_FRAME / 4 {
        let centre = DVec2::new(10.0 + 8.0 * (car % 16) as f64, -60.0 + 8.0 * (car / 16) as f64);
        for corner in
            [DVec2::new(-1.0, -0.5), DVec2::new(-1.0, 0.5), DVec2::new(1.0, -0.5), DVec2::new(1.0, 0.5)]
        {
            let point = centre + corner;
            frame.measurements.push(Measurement {
                x_m: point.x,
                y_m: point.y,
                radial_velocity_mps: 0.0,
                rcs_dbsm: 0.0,
                class: ObjectClass::Car,
                sensor_id: None,
                ground_truth_id: None,
            });
        }
    }
    let mut tracker = Tracker::new(config(DetectionModel::Points)).unwrap();
    let outputs = tracker.step(&frame).unwrap().len();
    assert_eq!(outputs, MAX_MEASUREMENTS_PER_FRAME / 4);
    assert_eq!(tracker.last_step().counts.detections_grouped, 3 * MAX_MEASUREMENTS_PER_FRAME as u64 / 4);
}
