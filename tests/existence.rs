//! The track existence probability in the tracker: it rises with detections, falls with misses
//! inside a scanning sensor's field of view, is untouched by misses outside every field of view,
//! and decides confirmation and deletion with `tracker.lifecycle = "existence"`.

use primm_core::config::{Config, Lifecycle};
use primm_core::existence::{survival_probability, updated_existence, Evidence};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::track::{TrackOutput, TrackStatus};
use primm_core::tracker::Tracker;

/// Sensor 3 (front left, boresight 25°) sees `LEFT`; sensor 1 (right side, −85°) sees `RIGHT`;
/// neither sees the other's point (default mounts, ±60°).
const LEFT: [f64; 2] = [30.0, 10.0];
const RIGHT: [f64; 2] = [20.0, -20.0];

fn config(lifecycle: Lifecycle) -> Config {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.tracker.lifecycle = lifecycle;
    // A sensor that seldom misses and confirmation and deletion thresholds of round values, so
    // that a few scans decide (the shipped values are chosen on validation data).
    config.classes.car.existence.detection_probability = 0.9;
    config.tracker.initial_existence_probability = 0.5;
    config.tracker.confirmation_existence_probability = 0.9;
    config.tracker.deletion_existence_probability = 0.05;
    config
}

fn car(position: [f64; 2], sensor: Option<u16>, ground_truth_id: u64) -> Measurement {
    Measurement {
        x_m: position[0],
        y_m: position[1],
        radial_velocity_mps: 0.0,
        rcs_dbsm: 10.0,
        class: ObjectClass::Car,
        sensor_id: sensor,
        ground_truth_id: Some(ground_truth_id),
    }
}

fn frame(t: f64, measurements: &[Measurement]) -> Frame {
    let mut frame = Frame::new(t);
    frame.measurements.extend(measurements.iter().copied());
    frame
}

fn of(outputs: &[TrackOutput], ground_truth_id: u64) -> TrackOutput {
    *outputs.iter().find(|o| o.ground_truth_id == Some(ground_truth_id)).expect("the object's track")
}

#[test]
fn detections_confirm_a_track_by_existence_and_misses_in_view_delete_it() {
    let config = config(Lifecycle::Existence);
    let mut tracker = Tracker::new(config.clone()).unwrap();
    let mut existence = Vec::new();
    let mut status = Vec::new();
    for k in 0..6 {
        let outputs = tracker.step(&frame(0.05 * k as f64, &[car(LEFT, Some(3), 1)])).unwrap();
        existence.push(of(outputs, 1).existence_probability);
        status.push(of(outputs, 1).status);
    }
    assert_eq!(existence[0], config.tracker.initial_existence_probability);
    assert!(existence.windows(2).all(|w| w[1] > w[0]), "existence rises with every detection: {existence:?}");
    let confirmed_at = status.iter().position(|s| *s == TrackStatus::Confirmed).expect("confirmed");
    assert!(existence[confirmed_at] >= config.tracker.confirmation_existence_probability);
    assert!(existence[..confirmed_at].iter().all(|&r| r < config.tracker.confirmation_existence_probability));

    // Sensor 3 keeps scanning (it sees another car) but no longer detects the first one: it
    // coasts, loses existence at every scan, and is deleted once below the threshold.
    let mut last = *existence.last().unwrap();
    let mut deleted_after = None;
    for k in 6..40 {
        let outputs =
            tracker.step(&frame(0.05 * k as f64, &[car([40.0, 30.0], Some(3), 2)])).unwrap().to_vec();
        match outputs.iter().find(|o| o.id == 1) {
            Some(track) => {
                assert!(track.existence_probability < last, "a miss in view lowers existence");
                assert_eq!(track.status, TrackStatus::Coasting);
                last = track.existence_probability;
            }
            None => {
                deleted_after = Some(k - 6);
                break;
            }
        }
    }
    let misses = deleted_after.expect("the missed track is deleted");
    assert!(last >= config.tracker.deletion_existence_probability);
    assert!((1..10).contains(&misses), "deleted after {misses} misses in view");
}

#[test]
fn misses_outside_every_scanning_sensors_view_only_apply_survival() {
    let config = config(Lifecycle::Existence);
    let mut tracker = Tracker::new(config.clone()).unwrap();
    for k in 0..4 {
        tracker.step(&frame(0.05 * k as f64, &[car(LEFT, Some(3), 1)])).unwrap();
    }
    let mut expected = tracker.tracks()[0].existence_probability;
    // Only sensor 1 scans now; it cannot see the first car.
    for k in 4..12 {
        let outputs = tracker.step(&frame(0.05 * k as f64, &[car(RIGHT, Some(1), 2)])).unwrap();
        expected *= survival_probability(0.05, &config.tracker);
        let track = of(outputs, 2).id; // the second car's track exists too
        assert_ne!(track, 1);
        let first = outputs.iter().find(|o| o.id == 1).expect("the unseen track lives on");
        assert!(
            (first.existence_probability - expected).abs() < 1e-12,
            "{} vs {expected}",
            first.existence_probability
        );
        assert_eq!(first.status, TrackStatus::Confirmed, "out of view is not coasting");
    }
    assert_eq!(tracker.last_step().counts.tracks_missed_in_view, 0, "the first track was out of view");
}

#[test]
fn a_coasting_track_is_confirmed_again_by_its_next_detection() {
    let mut tracker = Tracker::new(config(Lifecycle::Counts)).unwrap();
    for k in 0..4 {
        tracker.step(&frame(0.05 * k as f64, &[car(LEFT, Some(3), 1)])).unwrap();
    }
    let coasting = tracker.step(&frame(0.2, &[car([40.0, 30.0], Some(3), 2)])).unwrap();
    assert_eq!(coasting.iter().find(|o| o.id == 1).unwrap().status, TrackStatus::Coasting);
    assert_eq!(tracker.last_step().counts.tracks_missed_in_view, 1);
    let back = tracker.step(&frame(0.25, &[car(LEFT, Some(3), 1)])).unwrap();
    assert_eq!(of(back, 1).status, TrackStatus::Confirmed);
}

#[test]
fn a_measurement_of_an_unknown_sensor_counts_a_miss_within_its_sector_and_is_counted() {
    // With a margin of pi an unknown radar looks everywhere: the far measurement's radar counts
    // the first track as seen and missed. With the shipped margin it looks only around its
    // detection, which lies on the other side, and the first track keeps its existence.
    for (everywhere, missed) in [(true, true), (false, false)] {
        let mut config = config(Lifecycle::Counts);
        if everywhere {
            config.frame.unknown_sensor_margin_rad = std::f64::consts::PI;
        }
        let mut tracker = Tracker::new(config.clone()).unwrap();
        tracker.step(&frame(0.0, &[car(LEFT, Some(3), 1)])).unwrap();
        let before = tracker.tracks()[0].existence_probability;
        // A far measurement without a sensor id.
        tracker.step(&frame(0.05, &[car(RIGHT, None, 2)])).unwrap();
        let survived = before * survival_probability(0.05, &config.tracker);
        let detection = config.classes.car.existence.detection_probability;
        let expected = if missed {
            updated_existence(survived, Evidence::MissedInView, detection, 1e-4)
        } else {
            survived
        };
        let first = tracker.tracks().iter().find(|t| t.id == 1).unwrap();
        assert!((first.existence_probability - expected).abs() < 1e-12, "everywhere: {everywhere}");
        assert_eq!(tracker.last_step().counts.tracks_missed_in_view, u64::from(missed));
        assert_eq!(tracker.stats().frames_with_unknown_sensor, 1);
    }
    let config = config(Lifecycle::Counts);
    let mut tracker = Tracker::new(config.clone()).unwrap();
    tracker.step(&frame(0.0, &[car(LEFT, Some(3), 1)])).unwrap();
    tracker.step(&frame(0.05, &[car(RIGHT, None, 2)])).unwrap();
    // A frame without measurements names no sensor: nothing is counted against anyone.
    let quiet = tracker.tracks().iter().find(|t| t.id == 1).unwrap().existence_probability;
    tracker.step(&frame(0.1, &[])).unwrap();
    let after = tracker.tracks().iter().find(|t| t.id == 1).unwrap().existence_probability;
    assert!((after - quiet * survival_probability(0.05, &config.tracker)).abs() < 1e-12);
}

#[test]
fn counting_confirms_by_hits_whatever_the_existence() {
    let mut config = config(Lifecycle::Counts);
    config.tracker.confirmation_existence_probability = 0.999_999;
    let mut tracker = Tracker::new(config.clone()).unwrap();
    let mut statuses = Vec::new();
    for k in 0..4 {
        let outputs = tracker.step(&frame(0.05 * k as f64, &[car(LEFT, Some(3), 1)])).unwrap();
        statuses.push(of(outputs, 1).status);
    }
    let hits = config.tracker.confirmation_hits as usize;
    assert_eq!(statuses[hits - 2], TrackStatus::Tentative);
    assert_eq!(statuses[hits - 1], TrackStatus::Confirmed);
}
