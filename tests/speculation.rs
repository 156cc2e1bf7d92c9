//! Learned predictions computed between frames (`Tracker::speculate`): the tracks are those of a
//! tracker that never speculates, bit for bit, whatever the guess of the next frame's time,
//! late frames included, with the model on the tracking thread or on inference threads; the
//! tracking thread allocates nothing; a predictor whose answers may depend on the batch is
//! never given a batch ahead.

use crate::common;
use crate::common::counting_allocator::count_allocations;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::predictor::{
    AnswerDependence, Displacement, DisplacementPredictor, HistoryEntry, PredictionRequest,
};
use primm_core::tracker::Tracker;
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::split::on_inference_threads;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::time::Duration;

fn pr_imm() -> Config {
    Config::default().with_modes(Method::PrImm.modes())
}

/// Every output of a step, written out: `{:?}` of an `f64` is its shortest exact form, so two
/// equal texts are equal bits.
fn text<P: DisplacementPredictor>(tracker: &Tracker<P>) -> String {
    format!("{:?} {:?}", tracker.last_outputs(), tracker.last_step())
}

/// Steps `plain` and `speculating` (which speculates after every step) through `frames` in
/// `order`, asserting after each frame that both give the same outputs and summary.
fn assert_same_tracks<P: DisplacementPredictor, Q: DisplacementPredictor>(
    plain: &mut Tracker<P>,
    speculating: &mut Tracker<Q>,
    frames: &[Frame],
    order: impl IntoIterator<Item = usize>,
) {
    for index in order {
        let expected =
            plain.step(&frames[index]).map(|_| ()).map_err(|error| error.to_string()).map(|()| text(plain));
        let actual = speculating
            .step(&frames[index])
            .map(|_| ())
            .map_err(|error| error.to_string())
            .map(|()| text(speculating));
        assert_eq!(actual, expected, "frame {index}");
        speculating.speculate();
    }
    assert_eq!(speculating.stats(), plain.stats());
}

/// The first `count` frames of a generated four-radar sequence (one radar per frame, ego poses,
/// pedestrians among the objects), restamped every 15 ms without the radars' scan jitter, so
/// that the next frame's time can be guessed.
fn four_radar_frames(count: usize) -> Vec<Frame> {
    let generated = ScenarioGenerator::from_preset(Preset::Default).generate(Split::Validation, 3);
    let mut frames: Vec<Frame> =
        generated.sequence.frames.iter().take(count).map(|frame| frame.to_frame().unwrap()).collect();
    for (k, frame) in frames.iter_mut().enumerate() {
        frame.timestamp_s = 0.015 * k as f64;
    }
    frames
}

#[test]
fn speculating_changes_no_output_bit_for_bit_on_a_four_radar_sequence() {
    let frames = four_radar_frames(400);
    let mut plain = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    let mut speculating = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    assert_same_tracks(&mut plain, &mut speculating, &frames, 0..frames.len());
    let stats = *speculating.speculation_stats();
    assert!(plain.predictor().stats().predictions > 500, "{:?}", plain.predictor().stats());
    // A steady frame rate: nearly every request is answered by the batch computed ahead.
    assert!(stats.requests_served > 10 * stats.requests_recomputed, "{stats:?}");
    assert!(stats.batches > 300, "{stats:?}");
}

#[test]
fn with_late_frames_and_irregular_intervals_the_answers_not_foreseen_are_predicted_in_the_frame() {
    let mut frames = four_radar_frames(300);
    // Every third interval lengthened by a varying amount: the guesses of the next time around
    // those frames are wrong, the others right.
    let mut shift = 0.0;
    for (k, frame) in frames.iter_mut().enumerate() {
        if k % 3 == 0 {
            shift += 0.001 * (k % 5) as f64;
        }
        frame.timestamp_s += shift;
    }
    // Every ninth frame overtaken by the two after it: those are late, tracked in their place.
    let mut order: Vec<usize> = (0..frames.len()).collect();
    for k in (4..frames.len() - 2).step_by(9) {
        order.swap(k, k + 2);
    }
    let mut plain = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    let mut speculating = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    assert_same_tracks(&mut plain, &mut speculating, &frames, order);
    assert!(plain.stats().late_frames_tracked > 10, "{:?}", plain.stats());
    let stats = *speculating.speculation_stats();
    assert!(stats.requests_recomputed > 0, "{stats:?}");
    assert!(stats.requests_served > 0, "{stats:?}");
}

#[test]
fn with_frame_times_that_cannot_be_guessed_speculation_backs_off_and_changes_nothing() {
    let mut frames = four_radar_frames(200);
    // Every interval lengthened by a different amount, as radars with scan jitter do.
    let mut shift = 0.0;
    for (k, frame) in frames.iter_mut().enumerate() {
        shift += 0.0005 * ((k * 7) % 11) as f64 + 0.0001 * (k % 3) as f64;
        frame.timestamp_s += shift;
    }
    let mut plain = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    let mut speculating = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    assert_same_tracks(&mut plain, &mut speculating, &frames, 0..frames.len());
    let stats = *speculating.speculation_stats();
    assert!(stats.skipped_after_misses > 100, "{stats:?}");
    // Backed off, it still tries one frame in sixteen.
    assert!(stats.batches > 5, "{stats:?}");
}

#[test]
fn on_two_inference_threads_with_speculation_the_tracks_are_those_of_the_synchronous_model_bit_for_bit() {
    let frames = common::scene_frames(&common::lanes(64), 150, 0.05, 0.2, 5);
    let model = OnnxPredictor::embedded().unwrap();
    let threaded = on_inference_threads(model, 2, Duration::from_secs(60)).unwrap();
    let mut plain = Tracker::with_predictor(pr_imm(), OnnxPredictor::embedded().unwrap()).unwrap();
    let mut speculating = Tracker::with_predictor(pr_imm(), threaded).unwrap();
    assert_same_tracks(&mut plain, &mut speculating, &frames, 0..frames.len());
    let stats = *speculating.speculation_stats();
    // 32 pedestrians a frame; from the third frame on every request is foreseen.
    assert!(stats.requests_served >= 32 * 140, "{stats:?}");
    let parts = speculating.predictor().parts();
    assert!(parts.iter().all(|part| part.stats().deadline_misses == 0));
    assert!(parts.iter().all(|part| part.last_timeline().is_some()));
}

#[test]
fn two_thousand_speculating_frames_on_two_inference_threads_allocate_nothing_on_the_tracking_thread() {
    let model = OnnxPredictor::embedded().unwrap();
    let predictor = on_inference_threads(model, 2, Duration::from_secs(10)).unwrap();
    let mut tracker = Tracker::with_predictor(pr_imm(), predictor).unwrap();
    let base = common::scene_frames(&common::lanes(64), 200, 0.04, 0.2, 7);
    let mut frame: Frame = base[0].clone();
    let allocations = count_allocations(|| {
        for k in 0..2_000 {
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&base[k % base.len()].measurements);
            tracker.step(&frame).expect("valid frame");
            tracker.speculate();
        }
    });
    assert_eq!(allocations, 0, "the tracking thread allocated");
    let stats = *tracker.speculation_stats();
    assert!(stats.requests_served > 32 * 1_900, "{stats:?}");
}

/// Answers every request with no displacement, counting its batches; keeps the default
/// answer dependence (the batch).
struct ZeroAnswer {
    batches: usize,
}

impl DisplacementPredictor for ZeroAnswer {
    fn submit(&mut self, _requests: &[PredictionRequest]) {
        self.batches += 1;
    }
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(Some(Displacement::new(glam::DVec2::new(0.0, 0.0))));
    }
}

#[test]
fn a_predictor_whose_answers_may_depend_on_the_batch_is_never_given_a_batch_ahead() {
    let frames = common::scene_frames(&common::lanes(8), 20, 0.05, 0.2, 5);
    let mut tracker = Tracker::with_predictor(pr_imm(), ZeroAnswer { batches: 0 }).unwrap();
    assert_eq!(tracker.predictor().answer_dependence(), AnswerDependence::Batch);
    for frame in &frames {
        tracker.step(frame).unwrap();
        tracker.speculate();
    }
    assert_eq!(tracker.speculation_stats().batches, 0);
    // One batch per frame with tracks: the frame's own.
    assert_eq!(tracker.predictor().batches, frames.len() - 1);
}

/// Three measurements 50 ms apart, the latest at 0.15 s.
fn history() -> [HistoryEntry; 3] {
    std::array::from_fn(|i| HistoryEntry {
        x_m: 10.0 + 0.07 * i as f64,
        y_m: 2.0,
        radial_velocity_mps: 1.4,
        rcs_dbsm: -5.0,
        timestamp_s: 0.05 * (i + 1) as f64,
        sensor_x_m: 0.0,
        sensor_y_m: 0.0,
    })
}

#[test]
fn a_guessed_time_a_few_bits_off_has_the_same_model_input_and_a_wrong_one_does_not() {
    let step_start = 0.05 * 3.0;
    let actual = PredictionRequest::from_history(&history(), 0.05 * 4.0).with_step_start(step_start);
    // The guess from the last interval, rounded differently from the frame's own time.
    let guessed_time = step_start + (step_start - 0.05 * 2.0);
    let guessed = PredictionRequest::from_history(&history(), guessed_time).with_step_start(step_start);
    assert_ne!(actual.prediction_time_s.to_bits(), guessed.prediction_time_s.to_bits());
    assert!(guessed.same_model_input(&actual));
    assert!(!guessed.same_bits(&actual));
    assert!(AnswerDependence::ModelInput.serves(&guessed, &actual));
    assert!(!AnswerDependence::Request.serves(&guessed, &actual));
    assert!(!AnswerDependence::Batch.serves(&actual, &actual));
    assert!(AnswerDependence::Request.serves(&actual, &actual));
    let wrong = PredictionRequest::from_history(&history(), 0.21).with_step_start(step_start);
    assert!(!wrong.same_model_input(&actual));
    let mut remembered = actual;
    remembered.step_start_displacement_m = Some(glam::DVec2::new(0.1, 0.0));
    assert!(!remembered.same_model_input(&actual));
}
