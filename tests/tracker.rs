//! The multi-object tracker on small hand-built scenes, and its handling of bad input.

use crate::common;

use common::{lanes, scene_frames, SceneObject};
use primm_core::config::Config;
use primm_core::measurement::{
    Frame, FrameView, Measurement, ObjectClass, UnknownClass, MAX_MEASUREMENTS_PER_FRAME,
};
use primm_core::mode::Method;
use primm_core::track::{TrackOutput, TrackStatus};
use primm_core::tracker::{StepError, Tracker, TrackerStats};
use primm_core::validation::FrameError;
use std::collections::HashMap;

fn imm_config() -> Config {
    Config::default().with_modes(Method::Imm.modes())
}

/// Runs all frames and returns, per frame, the outputs.
fn run(config: Config, frames: &[Frame]) -> Vec<Vec<TrackOutput>> {
    let mut tracker = Tracker::new(config).unwrap();
    frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect()
}

/// For each ground-truth id, the sequence of track ids that its measurements updated.
fn track_ids_by_object(outputs: &[Vec<TrackOutput>]) -> HashMap<u64, Vec<u64>> {
    let mut map: HashMap<u64, Vec<u64>> = HashMap::new();
    for frame in outputs {
        for output in frame.iter().filter(|o| o.measurement_index.is_some()) {
            if let Some(gt) = output.ground_truth_id {
                map.entry(gt).or_default().push(output.id);
            }
        }
    }
    map
}

fn distinct(ids: &[u64]) -> usize {
    let mut ids = ids.to_vec();
    ids.sort_unstable();
    ids.dedup();
    ids.len()
}

#[test]
fn two_crossing_objects_with_different_radial_velocities_keep_their_ids() {
    // Two cars cross at right angles at (30, 0) at t = 2 s.
    let objects = [
        SceneObject {
            id: 1,
            class: ObjectClass::Car,
            start: [10.0, 0.0],
            velocity: [10.0, 0.0],
            visible: (0.0, 9.0),
        },
        SceneObject {
            id: 2,
            class: ObjectClass::Car,
            start: [30.0, -16.0],
            velocity: [0.0, 8.0],
            visible: (0.0, 9.0),
        },
    ];
    let frames = scene_frames(&objects, 80, 0.05, 0.15, 1);
    for method in [Method::Imm, Method::ConstantVelocity] {
        let ids = track_ids_by_object(&run(Config::default().with_modes(method.modes()), &frames));
        assert_eq!(distinct(&ids[&1]), 1, "{method}: object 1 went through tracks {:?}", ids[&1]);
        assert_eq!(distinct(&ids[&2]), 1, "{method}: object 2 went through tracks {:?}", ids[&2]);
        assert_ne!(ids[&1][0], ids[&2][0]);
    }
}

#[test]
fn an_object_that_disappears_briefly_keeps_its_id() {
    // Hidden between 1.0 s and 1.4 s (8 frames), inside the 1 s coast time.
    let hidden = |id, start: [f64; 2], from, to| SceneObject {
        id,
        class: ObjectClass::Car,
        start,
        velocity: [6.0, 1.0],
        visible: (from, to),
    };
    let frames_a = scene_frames(&[hidden(1, [20.0, 5.0], 0.0, 1.0)], 60, 0.05, 0.1, 2);
    let frames_b = scene_frames(&[hidden(1, [20.0, 5.0], 1.4, 9.0)], 60, 0.05, 0.1, 3);
    let frames: Vec<Frame> = frames_a
        .into_iter()
        .zip(frames_b)
        .map(|(mut a, b)| {
            a.measurements.extend(b.measurements);
            a
        })
        .collect();
    let outputs = run(imm_config(), &frames);
    let ids = track_ids_by_object(&outputs);
    assert_eq!(distinct(&ids[&1]), 1, "tracks {:?}", ids[&1]);
    // While hidden the track coasts and is still reported.
    let coasting = &outputs[25];
    assert!(coasting.iter().any(|o| o.id == ids[&1][0] && o.measurement_index.is_none() && o.misses > 0));
}

#[test]
fn a_new_object_gets_a_new_id_and_ids_are_never_reused() {
    let objects = [
        SceneObject {
            id: 1,
            class: ObjectClass::Car,
            start: [10.0, 0.0],
            velocity: [5.0, 0.0],
            visible: (0.0, 1.0),
        },
        SceneObject {
            id: 2,
            class: ObjectClass::Car,
            start: [10.0, 0.0],
            velocity: [5.0, 0.0],
            visible: (3.0, 5.0),
        },
        SceneObject {
            id: 3,
            class: ObjectClass::Pedestrian,
            start: [15.0, 8.0],
            velocity: [0.0, -1.0],
            visible: (2.0, 5.0),
        },
    ];
    let frames = scene_frames(&objects, 100, 0.05, 0.1, 4);
    let ids = track_ids_by_object(&run(imm_config(), &frames));
    let (a, b, c) = (ids[&1][0], ids[&2][0], ids[&3][0]);
    // Object 2 reappears at the place object 1 left, long after object 1's track was deleted.
    assert!(a != b && b != c && a != c, "ids {a} {b} {c}");
    assert!(b > a && c > a, "ids grow: {a} {b} {c}");
}

#[test]
fn a_pedestrian_measurement_never_updates_a_car_track() {
    // A car and a pedestrian at nearly the same place.
    let objects = [
        SceneObject {
            id: 1,
            class: ObjectClass::Car,
            start: [20.0, 0.0],
            velocity: [2.0, 0.0],
            visible: (0.0, 3.0),
        },
        SceneObject {
            id: 2,
            class: ObjectClass::Pedestrian,
            start: [20.3, 0.2],
            velocity: [2.0, 0.1],
            visible: (0.0, 3.0),
        },
    ];
    let frames = scene_frames(&objects, 60, 0.05, 0.3, 5);
    let outputs = run(imm_config(), &frames);
    for frame in &outputs {
        for output in frame.iter().filter(|o| o.measurement_index.is_some()) {
            let expected =
                if output.ground_truth_id == Some(1) { ObjectClass::Car } else { ObjectClass::Pedestrian };
            assert_eq!(output.class, expected);
        }
    }
    let ids = track_ids_by_object(&outputs);
    assert_eq!(distinct(&ids[&1]), 1);
    assert_eq!(distinct(&ids[&2]), 1);
}

#[test]
fn tracks_are_confirmed_after_the_configured_hits_and_deleted_after_misses() {
    let mut config = imm_config();
    config.tracker.lifecycle = primm_core::config::Lifecycle::Counts;
    config.tracker.confirmation_hits = 4;
    config.tracker.confirmed_max_misses = 5;
    config.tracker.max_coast_s = 10.0;
    let objects = [SceneObject {
        id: 1,
        class: ObjectClass::Car,
        start: [20.0, 0.0],
        velocity: [3.0, 0.0],
        visible: (0.0, 1.0),
    }];
    let frames = scene_frames(&objects, 40, 0.05, 0.1, 6);
    let outputs = run(config, &frames);
    let status: Vec<TrackStatus> = outputs.iter().take(5).map(|f| f[0].status).collect();
    assert_eq!(
        status,
        [
            TrackStatus::Tentative,
            TrackStatus::Tentative,
            TrackStatus::Tentative,
            TrackStatus::Confirmed,
            TrackStatus::Confirmed
        ]
    );
    // Visible for 20 frames, then 5 misses are tolerated and the 6th deletes it.
    assert_eq!(outputs[24].len(), 1);
    assert_eq!(outputs[24][0].misses, 5);
    assert!(outputs[25].is_empty());
}

#[test]
fn the_same_frames_give_bit_identical_outputs() {
    let frames = scene_frames(&lanes(40), 200, 0.04, 0.3, 7);
    let first = run(Config::default(), &frames);
    let second = run(Config::default(), &frames);
    assert_eq!(first, second);
    assert!(first.iter().map(Vec::len).sum::<usize>() > 1000);
}

fn snapshot(tracker: &Tracker) -> Vec<(u64, [f64; 4], u32)> {
    tracker.tracks().iter().map(|t| (t.id, t.estimate.probabilities, t.hits)).collect()
}

fn warmed_up_tracker() -> (Tracker, Vec<Frame>) {
    let frames = scene_frames(&lanes(6), 30, 0.05, 0.1, 8);
    let mut tracker = Tracker::new(imm_config()).unwrap();
    for frame in &frames[..20] {
        tracker.step(frame).unwrap();
    }
    (tracker, frames)
}

#[test]
fn a_frame_with_a_non_finite_timestamp_is_rejected_and_changes_nothing() {
    let (mut tracker, frames) = warmed_up_tracker();
    let before = snapshot(&tracker);
    let mut bad = frames[20].clone();
    bad.timestamp_s = f64::NAN;
    assert!(matches!(
        tracker.step(&bad),
        Err(StepError::InvalidFrame(FrameError::NonFiniteTimestamp { .. }))
    ));
    assert_eq!(snapshot(&tracker), before);
    assert_eq!(tracker.stats().frames_rejected_non_finite_timestamp, 1);
    let summary = tracker.last_step();
    assert_eq!((summary.counts.measurements_accepted, summary.measurements_rejected()), (0, 0));
    assert_eq!(summary.counts.frames_rejected_non_finite_timestamp, 1);
    assert_eq!(summary.live_tracks, before.len());
    tracker.step(&frames[20]).unwrap();
}

#[test]
fn a_frame_repeating_a_time_or_older_than_the_late_frame_window_is_rejected() {
    let (mut tracker, frames) = warmed_up_tracker();
    let before = snapshot(&tracker);
    let window_s = tracker.config().tracker.max_frame_delay_s;
    let newest = frames[19].timestamp_s;
    let mut repeated = frames[20].clone();
    repeated.timestamp_s = newest;
    assert!(matches!(
        tracker.step(&repeated),
        Err(StepError::InvalidFrame(FrameError::TimestampNotIncreasing { .. }))
    ));
    let old = frames.iter().rev().find(|frame| newest - frame.timestamp_s > window_s).unwrap();
    let mut too_late = frames[20].clone();
    too_late.timestamp_s = old.timestamp_s;
    assert!(matches!(tracker.step(&too_late), Err(StepError::InvalidFrame(FrameError::TooLate { .. }))));
    assert_eq!(snapshot(&tracker), before);
    assert_eq!(tracker.stats().frames_rejected_timestamp_not_increasing, 1);
    assert_eq!(tracker.stats().frames_rejected_too_late, 1);
    assert!(tracker.step(&frames[20]).is_ok());
}

#[test]
fn a_frame_after_too_long_a_gap_is_rejected_until_reset() {
    let (mut tracker, frames) = warmed_up_tracker();
    let before = snapshot(&tracker);
    let mut late = frames[20].clone();
    late.timestamp_s += 5.0;
    assert!(matches!(tracker.step(&late), Err(StepError::InvalidFrame(FrameError::IntervalTooLong { .. }))));
    assert_eq!(snapshot(&tracker), before);
    tracker.reset();
    let outputs = tracker.step(&late).unwrap();
    assert!(outputs
        .iter()
        .all(|o| o.status == TrackStatus::Tentative && o.id > before.iter().map(|b| b.0).max().unwrap()));
}

/// A frame view whose claimed length and class codes are under the test's control, as a
/// shared-memory frame from another process would be.
struct RawFrame {
    timestamp_s: f64,
    claimed_len: usize,
    measurements: Vec<(Measurement, u8)>,
}

impl FrameView for RawFrame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }
    fn len(&self) -> usize {
        self.claimed_len
    }
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        let (measurement, code) = self.measurements[index];
        ObjectClass::from_code(code)
            .map(|class| Measurement { class, ..measurement })
            .ok_or(UnknownClass { code })
    }
}

#[test]
fn a_frame_claiming_too_many_measurements_is_rejected() {
    let (mut tracker, frames) = warmed_up_tracker();
    let before = snapshot(&tracker);
    let raw = RawFrame {
        timestamp_s: frames[20].timestamp_s,
        claimed_len: MAX_MEASUREMENTS_PER_FRAME + 1,
        measurements: vec![],
    };
    assert!(matches!(
        tracker.step(&raw),
        Err(StepError::InvalidFrame(FrameError::TooManyMeasurements { .. }))
    ));
    assert_eq!(snapshot(&tracker), before);
    assert_eq!(tracker.stats().frames_rejected_too_many_measurements, 1);
}

#[test]
fn a_bad_measurement_is_rejected_alone_and_the_rest_of_the_frame_is_tracked() {
    let (mut tracker, frames) = warmed_up_tracker();
    let frame = &frames[20];
    let mut measurements: Vec<(Measurement, u8)> =
        frame.measurements.iter().map(|m| (*m, m.class.code())).collect();
    let good = measurements.len();
    let template = measurements[0].0;
    measurements.push((Measurement { x_m: f64::NAN, ..template }, 0));
    measurements.push((Measurement { radial_velocity_mps: f64::INFINITY, ..template }, 0));
    measurements.push((Measurement { y_m: 1e300, ..template }, 0));
    measurements.push((template, 77));
    let raw = RawFrame { timestamp_s: frame.timestamp_s, claimed_len: measurements.len(), measurements };
    let outputs = tracker.step(&raw).unwrap();
    let updated = outputs.iter().filter(|o| o.measurement_index.is_some()).count();
    assert_eq!(updated, good, "every good measurement updated a track, the bad ones nothing");
    assert!(outputs.iter().all(|o| o.position_m.is_finite()));
    let stats = tracker.stats();
    assert_eq!(stats.measurements_rejected_non_finite, 2);
    assert_eq!(stats.measurements_rejected_out_of_range, 1);
    assert_eq!(stats.measurements_rejected_unknown_class, 1);
    let summary = tracker.last_step();
    assert_eq!((summary.counts.measurements_accepted, summary.measurements_rejected()), (good as u64, 4));
}

#[test]
fn a_full_table_refuses_new_tracks_and_keeps_the_old_ones() {
    use primm_core::track_table::MAX_TRACKS;
    // An object list: 1 km out, the link distance of a point cloud's grouping (22 m there)
    // would join the measurements below, 20 m apart, into groups.
    let mut config = imm_config();
    config.frame.unmounted_detections = primm_core::grouping::DetectionModel::Objects;
    let mut tracker = Tracker::new(config).unwrap();
    // Frames of 256 far-apart measurements (half the table), shifted each frame so nothing
    // associates: the table fills up in two frames, then refuses.
    const PER_FRAME: usize = MAX_TRACKS / 2;
    let frame_at = |k: usize| {
        let mut frame = Frame::new(k as f64 * 0.05);
        for j in 0..PER_FRAME {
            frame.measurements.push(common::measurement(
                1000.0 * k as f64 + 20.0 * (j % 16) as f64,
                20.0 * (j / 16) as f64,
                0.0,
            ));
        }
        frame
    };
    tracker.step(&frame_at(0)).unwrap();
    tracker.step(&frame_at(1)).unwrap();
    let full: Vec<u64> = tracker.tracks().iter().map(|t| t.id).collect();
    assert_eq!(full.len(), MAX_TRACKS);
    tracker.step(&frame_at(2)).unwrap();
    assert_eq!(tracker.stats().initiations_refused_table_full, PER_FRAME as u64);
    assert_eq!(tracker.last_step().counts.initiations_refused_table_full, PER_FRAME as u64);
    // Nothing was evicted to make room: the surviving tracks are old ones.
    assert!(tracker.tracks().iter().all(|t| full.contains(&t.id)));
}

#[test]
fn every_accepted_measurement_updates_or_starts_exactly_one_track() {
    let frames = scene_frames(&lanes(30), 100, 0.05, 0.3, 9);
    for (frame, outputs) in frames.iter().zip(run(Config::default(), &frames)) {
        let mut used: Vec<u16> = outputs.iter().filter_map(|o| o.measurement_index).collect();
        used.sort_unstable();
        let expected: Vec<u16> = (0..frame.measurements.len() as u16).collect();
        assert_eq!(used, expected);
    }
}

#[test]
fn each_step_summarises_its_frame_and_the_summaries_add_up_to_the_statistics() {
    let mut frames = scene_frames(&lanes(30), 100, 0.05, 0.3, 9);
    // Then nothing: every track coasts until it is deleted.
    let last_s = frames.last().unwrap().timestamp_s;
    frames.extend((1..=40).map(|k| Frame::new(last_s + 0.05 * k as f64)));
    let mut tracker = Tracker::new(Config::default()).unwrap();
    let mut into = Tracker::new(Config::default()).unwrap();
    let mut sums = TrackerStats::default();
    for frame in &frames {
        let outputs = tracker.step(frame).unwrap().to_vec();
        let summary = *tracker.last_step();
        assert_eq!(summary.live_tracks, outputs.len());
        assert_eq!(summary.confirmed_tracks, outputs.iter().filter(|o| o.status.is_confirmed()).count());
        assert_eq!(
            summary.counts.tracks_updated + summary.counts.tracks_initiated,
            outputs.iter().filter(|o| o.measurement_index.is_some()).count() as u64
        );
        assert_eq!(
            (summary.counts.measurements_accepted, summary.measurements_rejected()),
            (frame.measurements.len() as u64, 0)
        );
        assert_eq!(summary.counts.frames_tracked, 1);
        let mut sunk = 0;
        assert_eq!(into.step_into(frame, |_| sunk += 1).unwrap(), summary);
        assert_eq!(sunk, summary.live_tracks);
        sums.add(&summary.counts);
    }
    // Every counter, by the same name: the totals are the steps' counts added up.
    assert_eq!(&sums, tracker.stats());
    assert!(
        sums.tracks_initiated > 0 && sums.tracks_deleted == sums.tracks_initiated,
        "every track started was deleted"
    );
    tracker.reset();
    assert_eq!(tracker.last_step().live_tracks, 0);
}
