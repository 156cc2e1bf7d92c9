//! The split predictor: a frame's batch shared among several predictors (the PR model on
//! several inference threads), every result in its place, small batches kept whole, a fault
//! confined to its own part, and the same displacements as one predictor gives.

use crate::common::{anchored_requests as requests, echoed_anchor as expected};
use primm_core::predictor::{Displacement, DisplacementPredictor, HistoryEntry, PredictionRequest};
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::split::{
    on_inference_threads, InferenceThreadsError, SplitPredictor, DEFAULT_MIN_REQUESTS_PER_PART,
};
use primm_predictor::threaded::ThreadedPredictor;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A deadline for frames that must get their results: only a dead inference thread misses it.
const PATIENT: Duration = Duration::from_secs(600);

/// Answers each request with its anchor scaled by 1/1000 (so a result names its request) and
/// records the size of every batch it gets (empty ones too); panics on the batch chosen
/// (counted from 0).
struct Recorder {
    batch_sizes: Arc<Mutex<Vec<usize>>>,
    panic_on_batch: Option<usize>,
    results: Vec<Option<Displacement>>,
}

impl Recorder {
    fn new() -> (Self, Arc<Mutex<Vec<usize>>>) {
        let sizes = Arc::new(Mutex::new(Vec::new()));
        (Recorder { batch_sizes: sizes.clone(), panic_on_batch: None, results: Vec::new() }, sizes)
    }
}

impl DisplacementPredictor for Recorder {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        let batch = {
            let mut sizes = self.batch_sizes.lock().unwrap();
            sizes.push(requests.len());
            sizes.len() - 1
        };
        if self.panic_on_batch == Some(batch) {
            panic!("inference blew up (deliberately, batch {batch})");
        }
        self.results = requests.iter().map(|request| Some((request.anchor_m / 1000.0).into())).collect();
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
        for (out, result) in displacements.iter_mut().zip(&self.results) {
            *out = *result;
        }
    }
}

/// The recorded batch sizes without the threaded predictor's empty warm-up batch.
fn non_empty(sizes: &Arc<Mutex<Vec<usize>>>) -> Vec<usize> {
    sizes.lock().unwrap().iter().copied().filter(|&size| size > 0).collect()
}

#[test]
fn a_batch_of_sixty_five_is_shared_thirty_three_and_thirty_two_with_every_result_in_its_place() {
    let (first, first_sizes) = Recorder::new();
    let (second, second_sizes) = Recorder::new();
    let mut split = SplitPredictor::new(vec![first, second]).unwrap();
    let batch = requests(3, 65);
    let mut out = vec![None; batch.len()];
    split.predict(&batch, &mut out);
    assert_eq!(*first_sizes.lock().unwrap(), [33]);
    assert_eq!(*second_sizes.lock().unwrap(), [32]);
    for (i, displacement) in out.iter().enumerate() {
        assert_eq!(*displacement, expected(3, i), "request {i}");
    }
}

#[test]
fn a_batch_below_the_minimum_per_part_stays_whole_and_larger_ones_use_more_parts() {
    let recorders: Vec<_> = (0..3).map(|_| Recorder::new()).collect();
    let sizes: Vec<_> = recorders.iter().map(|(_, sizes)| sizes.clone()).collect();
    let mut split = SplitPredictor::new(recorders.into_iter().map(|(r, _)| r).collect()).unwrap();
    assert_eq!(split.min_requests_per_part(), DEFAULT_MIN_REQUESTS_PER_PART);
    let min = DEFAULT_MIN_REQUESTS_PER_PART;
    for (frame, count) in [(0, min * 2 - 1), (1, min * 2), (2, min * 3), (3, 1), (4, 0)] {
        let batch = requests(frame, count);
        let mut out = vec![None; count];
        split.predict(&batch, &mut out);
        assert!(out.iter().enumerate().all(|(i, d)| *d == expected(frame, i)), "frame {frame}");
    }
    // A part without requests this frame gets an empty submit.
    let record = |k: usize| sizes[k].lock().unwrap().clone();
    assert_eq!(record(0), [min * 2 - 1, min, min, 1, 0]);
    assert_eq!(record(1), [0, min, min, 0, 0]);
    assert_eq!(record(2), [0, 0, min, 0, 0]);
    assert_eq!(split.parts_used(min * 100), 3);
}

#[test]
fn a_split_predictor_needs_a_predictor_and_the_model_at_least_one_thread() {
    assert!(SplitPredictor::<Recorder>::new(Vec::new()).is_err());
    let model = OnnxPredictor::embedded().unwrap();
    assert!(matches!(on_inference_threads(model, 0, PATIENT), Err(InferenceThreadsError::NoThreads)));
}

#[test]
fn a_panicking_part_costs_only_its_own_tracks_and_the_other_part_keeps_answering() {
    let (healthy, healthy_sizes) = Recorder::new();
    let (mut broken, broken_sizes) = Recorder::new();
    // Batch 0 is the threaded predictor's warm-up; the first frame is batch 1.
    broken.panic_on_batch = Some(1);
    let parts = vec![
        ThreadedPredictor::new(healthy, PATIENT).unwrap(),
        ThreadedPredictor::new(broken, PATIENT).unwrap(),
    ];
    let mut split = SplitPredictor::new(parts).unwrap();
    for frame in 0..3 {
        let batch = requests(frame, 64);
        let mut out = vec![None; 64];
        split.predict(&batch, &mut out);
        for (i, displacement) in out.iter().enumerate() {
            let want = if i < 32 { expected(frame, i) } else { None };
            assert_eq!(*displacement, want, "frame {frame}, request {i}");
        }
    }
    assert_eq!(non_empty(&healthy_sizes), [32, 32, 32]);
    assert_eq!(non_empty(&broken_sizes), [32], "the broken part is retired after its panic");
    assert_eq!(split.parts()[0].stats().batches_on_time, 3);
    assert_eq!(split.parts()[1].stats().inference_panics, 1);
    assert_eq!(split.parts()[1].stats().frames_without_inference_thread, 2);
    let report = split.report().unwrap();
    assert!(report.contains("split over 2 parts") && report.contains("1 inference panics"), "{report}");
}

/// Tracks with histories of every length, moving at different speeds and headings.
fn model_requests(count: usize) -> Vec<PredictionRequest> {
    (0..count)
        .map(|i| {
            let heading = i as f64 * 0.37;
            let speed = 1.0 + (i % 9) as f64 * 2.0;
            let length = 1 + i % 5;
            let history: Vec<HistoryEntry> = (0..length)
                .map(|k| {
                    let t = k as f64 * 0.05;
                    HistoryEntry {
                        x_m: 10.0 + i as f64 + speed * t * heading.cos(),
                        y_m: -5.0 + speed * t * heading.sin(),
                        radial_velocity_mps: speed * 0.8,
                        rcs_dbsm: 5.0 + (i % 3) as f64,
                        timestamp_s: t,
                        ..Default::default()
                    }
                })
                .collect();
            PredictionRequest::from_history(&history, (length - 1) as f64 * 0.05 + 0.05)
        })
        .collect()
}

#[test]
fn the_model_on_two_inference_threads_answers_as_it_does_on_one() {
    let batch = model_requests(64);
    let mut single = OnnxPredictor::embedded().unwrap();
    let mut want = vec![None; batch.len()];
    single.predict(&batch, &mut want);
    let mut split = on_inference_threads(OnnxPredictor::embedded().unwrap(), 2, PATIENT).unwrap();
    assert_eq!(split.parts().len(), 2);
    for _ in 0..3 {
        let mut got = vec![None; batch.len()];
        split.predict(&batch, &mut got);
        for (i, (got, want)) in got.iter().zip(&want).enumerate() {
            let (got, want) = (got.expect("an answer"), want.expect("an answer"));
            // Half batches run through smaller plans: the same arithmetic up to rounding.
            assert!((got.mean_m - want.mean_m).length() < 1e-5, "request {i}: {got:?} vs {want:?}");
            let (got_cov, want_cov) = (got.covariance_m2.unwrap(), want.covariance_m2.unwrap());
            assert!((got_cov - want_cov).to_cols_array().iter().all(|d| d.abs() < 1e-5), "request {i}");
        }
    }
    assert!(split.parts().iter().all(|part| part.stats().batches_on_time == 3));
}

#[test]
fn a_forked_model_answers_exactly_like_its_original() {
    let mut original = OnnxPredictor::embedded().unwrap();
    let mut fork = original.fork().unwrap();
    for count in [1, 7, 32, 64] {
        let batch = model_requests(count);
        let (mut a, mut b) = (vec![None; count], vec![None; count]);
        original.predict(&batch, &mut a);
        fork.predict(&batch, &mut b);
        assert_eq!(a, b, "batch of {count}");
        assert!(a.iter().all(Option::is_some));
    }
    assert_eq!(fork.model().source(), original.model().source());
    assert_eq!(fork.stats().batches, 4, "the fork counts its own batches");
}
