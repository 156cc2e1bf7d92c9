//! With the PR model on its inference thread (or two, sharing each batch), the tracking thread
//! allocates nothing per frame. On the native forward pass (the default engine) the inference
//! thread allocates nothing either; on tract its per-run allocations happen, and are counted,
//! there.

use crate::common;
use crate::common::counting_allocator;

use counting_allocator::{allocations, count_allocations};
use primm_config::InferenceEngine;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use primm_core::tracker::Tracker;
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::split::SplitPredictor;
use primm_predictor::threaded::{ThreadedPredictor, INFERENCE_THREAD_NAME};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Counts the allocations the wrapped predictor makes (on whatever thread runs it).
struct CountingPredictor {
    inner: OnnxPredictor,
    allocations: Arc<AtomicU64>,
    batches: Arc<AtomicU64>,
    on_inference_thread: Arc<AtomicU64>,
}

impl DisplacementPredictor for CountingPredictor {
    fn submit(&mut self, _requests: &[PredictionRequest]) {}
    fn collect(&mut self, _displacements: &mut [Option<Displacement>]) {}
    fn predict(&mut self, requests: &[PredictionRequest], displacements: &mut [Option<Displacement>]) {
        let before = allocations();
        self.inner.predict(requests, displacements);
        self.allocations.fetch_add(allocations() - before, Ordering::Relaxed);
        self.batches.fetch_add(1, Ordering::Relaxed);
        if std::thread::current().name() == Some(INFERENCE_THREAD_NAME) {
            self.on_inference_thread.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// Tracks `frames` frames of 32 objects with the model on `engine`, on its inference thread;
/// returns the tracking thread's allocations, the inference thread's, and the batches run.
fn frames_on_the_inference_thread(engine: InferenceEngine, frames: usize) -> (u64, u64, u64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx");
    let inference_allocations = Arc::new(AtomicU64::new(0));
    let batches = Arc::new(AtomicU64::new(0));
    let on_inference_thread = Arc::new(AtomicU64::new(0));
    let mut inner = OnnxPredictor::load(&path).unwrap();
    assert_eq!(inner.set_engine(engine), engine);
    let counting = CountingPredictor {
        inner,
        allocations: inference_allocations.clone(),
        batches: batches.clone(),
        on_inference_thread: on_inference_thread.clone(),
    };
    // A generous deadline: this test is about allocations, every frame should get its batch.
    let predictor = ThreadedPredictor::new(counting, Duration::from_secs(10)).unwrap();
    let mut tracker = Tracker::with_predictor(Config::default(), predictor).unwrap();
    let base = common::scene_frames(&common::lanes(32), 200, 0.04, 0.2, 7);
    let mut frame: Frame = base[0].clone();
    let mut updates = 0u64;
    let warm_up_batches = batches.load(Ordering::Relaxed);
    let warm_up_allocations = inference_allocations.load(Ordering::Relaxed);
    let tracking_allocations = count_allocations(|| {
        for k in 0..frames {
            let source = &base[k % base.len()];
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&source.measurements);
            let outputs = tracker.step(&frame).expect("valid frame");
            updates += outputs.iter().filter(|o| o.measurement_index.is_some()).count() as u64;
        }
    });
    assert_eq!(updates, 32 * frames as u64);
    let stats = *tracker.predictor().stats();
    assert_eq!(stats.deadline_misses, 0);
    // The first frame has no tracks yet, so nothing to predict.
    assert_eq!(stats.batches_on_time, frames as u64 - 1);
    assert_eq!(tracker.stats().learned_predictions_missing, 0);
    let batches_run = batches.load(Ordering::Relaxed) - warm_up_batches;
    assert_eq!(batches_run, frames as u64 - 1);
    assert_eq!(on_inference_thread.load(Ordering::Relaxed), batches_run + warm_up_batches);
    let inference = inference_allocations.load(Ordering::Relaxed) - warm_up_allocations;
    println!(
        "{engine:?}: inference thread {inference} allocations over {batches_run} batches ({:.0} per batch)",
        inference as f64 / batches_run as f64
    );
    (tracking_allocations, inference, batches_run)
}

#[test]
fn two_thousand_frames_with_the_onnx_model_allocate_nothing_on_the_tracking_thread_nor_natively_on_the_inference_thread(
) {
    let (tracking, inference, _) = frames_on_the_inference_thread(InferenceEngine::Native, 2_000);
    assert_eq!(tracking, 0, "the tracking thread allocated");
    // The predictor's buffers are sized at load; the native forward pass works on the stack.
    assert_eq!(inference, 0, "the inference thread allocated on the native engine");
}

#[test]
fn on_tract_the_inference_thread_allocates_and_the_counter_sees_it_while_the_tracking_thread_does_not() {
    let (tracking, inference, batches) = frames_on_the_inference_thread(InferenceEngine::Tract, 50);
    assert_eq!(tracking, 0, "the tracking thread allocated");
    // tract allocates per run, there: the counter sees it, so the zero above is measured.
    assert!(inference >= batches, "{inference} allocations over {batches} batches");
}

#[test]
fn two_thousand_frames_with_the_model_on_two_inference_threads_allocate_nothing_on_the_tracking_thread() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx");
    let model = OnnxPredictor::load(&path).unwrap();
    let batches: [Arc<AtomicU64>; 2] = Default::default();
    let on_inference_thread = Arc::new(AtomicU64::new(0));
    let parts = [model.fork().unwrap(), model]
        .into_iter()
        .zip(&batches)
        .map(|(inner, batches)| {
            let counting = CountingPredictor {
                inner,
                allocations: Arc::default(),
                batches: batches.clone(),
                on_inference_thread: on_inference_thread.clone(),
            };
            ThreadedPredictor::new(counting, Duration::from_secs(10)).unwrap()
        })
        .collect();
    let predictor = SplitPredictor::new(parts).unwrap();
    let mut tracker = Tracker::with_predictor(Config::default(), predictor).unwrap();
    // 64 objects: every frame's batch is split in two halves of 32.
    let base = common::scene_frames(&common::lanes(64), 200, 0.04, 0.2, 7);
    let mut frame: Frame = base[0].clone();
    let frames = 2_000usize;
    let warm_up = batches.each_ref().map(|b| b.load(Ordering::Relaxed));
    let tracking_allocations = count_allocations(|| {
        for k in 0..frames {
            let source = &base[k % base.len()];
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&source.measurements);
            tracker.step(&frame).expect("valid frame");
        }
    });
    assert_eq!(tracking_allocations, 0, "the tracking thread allocated");
    for (part, (batches, warm_up)) in batches.iter().zip(warm_up).enumerate() {
        let ran = batches.load(Ordering::Relaxed) - warm_up;
        assert_eq!(ran, frames as u64 - 1, "part {part}");
        assert_eq!(tracker.predictor().parts()[part].stats().deadline_misses, 0, "part {part}");
    }
    assert_eq!(tracker.stats().learned_predictions_missing, 0);
    let total: u64 = batches.iter().map(|b| b.load(Ordering::Relaxed)).sum();
    assert_eq!(on_inference_thread.load(Ordering::Relaxed), total, "every batch ran on an inference thread");
}
