//! The threaded predictor: same results as the synchronous one, a named inference thread,
//! deadlines that cost one frame only, stale results discarded, panics contained (the
//! predictor retired).

use glam::DVec2;
use primm_core::predictor::{DisplacementPredictor, HistoryEntry, PredictionRequest};
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::threaded::{ThreadedPredictor, INFERENCE_THREAD_NAME};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Answers each request with its anchor scaled by 1/1000, so a result identifies its request.
/// Sleeps or panics on chosen batches (counted from 0) to play a slow or broken model.
struct Echo {
    batches: u64,
    slow_batches: Vec<u64>,
    slow_for: Duration,
    panic_batches: Vec<u64>,
    thread_names: Arc<std::sync::Mutex<Vec<String>>>,
}

impl Echo {
    fn new() -> Self {
        Echo {
            batches: 0,
            slow_batches: Vec::new(),
            slow_for: Duration::ZERO,
            panic_batches: Vec::new(),
            thread_names: Arc::default(),
        }
    }
}

impl DisplacementPredictor for Echo {
    fn submit(&mut self, _requests: &[PredictionRequest]) {}
    fn collect(&mut self, _displacements: &mut [Option<DVec2>]) {}
    fn predict(&mut self, requests: &[PredictionRequest], displacements: &mut [Option<DVec2>]) {
        let batch = self.batches;
        self.batches += 1;
        self.thread_names.lock().unwrap().push(std::thread::current().name().unwrap_or("").to_string());
        if self.slow_batches.contains(&batch) {
            std::thread::sleep(self.slow_for);
        }
        if self.panic_batches.contains(&batch) {
            panic!("inference blew up (deliberately, batch {batch})");
        }
        for (request, out) in requests.iter().zip(displacements.iter_mut()) {
            *out = Some(request.anchor_m / 1000.0);
        }
    }
}

fn requests(frame: usize, count: usize) -> Vec<PredictionRequest> {
    (0..count)
        .map(|i| {
            let entry = HistoryEntry {
                x_m: (frame * 100 + i) as f64,
                y_m: 1.0,
                radial_velocity_mps: 0.0,
                rcs_dbsm: 0.0,
                timestamp_s: frame as f64 * 0.02,
            };
            PredictionRequest::from_history(&[entry], frame as f64 * 0.02 + 0.02)
        })
        .collect()
}

fn expected(frame: usize, i: usize) -> Option<DVec2> {
    Some(DVec2::new((frame * 100 + i) as f64, 1.0) / 1000.0)
}

#[test]
fn results_come_back_in_order_from_the_named_inference_thread() {
    let echo = Echo::new();
    let names = echo.thread_names.clone();
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_secs(5)).unwrap();
    for frame in 0..50 {
        let batch = requests(frame, 1 + frame % 7);
        let mut out = vec![None; batch.len()];
        predictor.submit(&batch);
        predictor.collect(&mut out);
        for (i, got) in out.iter().enumerate() {
            assert_eq!(*got, expected(frame, i), "frame {frame} request {i}");
        }
    }
    assert_eq!(predictor.stats().batches_on_time, 50);
    assert_eq!(predictor.stats().deadline_misses, 0);
    let names = names.lock().unwrap();
    // The warm-up batch plus 50 frames, all on the inference thread.
    assert_eq!(names.len(), 51);
    assert!(names.iter().all(|n| n == INFERENCE_THREAD_NAME), "{names:?}");
}

#[test]
fn a_missed_deadline_costs_that_frame_only_and_its_late_results_are_discarded() {
    let mut echo = Echo::new();
    // Batch 0 is the warm-up; frame 1's batch (index 2) is slow.
    echo.slow_batches = vec![2];
    echo.slow_for = Duration::from_millis(300);
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_millis(40)).unwrap();
    let mut outcomes = Vec::new();
    for frame in 0..4 {
        let batch = requests(frame, 3);
        let mut out = vec![Some(DVec2::splat(-1.0)); 3];
        let started = std::time::Instant::now();
        predictor.submit(&batch);
        predictor.collect(&mut out);
        let waited = started.elapsed();
        outcomes.push((out, waited));
        if frame == 1 {
            // Give the slow batch time to come back, so the next frame meets it as stale.
            std::thread::sleep(Duration::from_millis(400));
        }
    }
    // Frame 0 fine; frame 1 missed its deadline: every track None, and the tracker did not wait
    // for the slow inference.
    assert_eq!(outcomes[0].0, vec![expected(0, 0), expected(0, 1), expected(0, 2)]);
    assert_eq!(outcomes[1].0, vec![None, None, None]);
    assert!(outcomes[1].1 < Duration::from_millis(250), "collect waited {:?}", outcomes[1].1);
    // Frames 2 and 3 get their own results, not frame 1's late ones.
    assert_eq!(outcomes[2].0, vec![expected(2, 0), expected(2, 1), expected(2, 2)]);
    assert_eq!(outcomes[3].0, vec![expected(3, 0), expected(3, 1), expected(3, 2)]);
    let stats = *predictor.stats();
    assert_eq!(stats.deadline_misses, 1);
    assert_eq!(stats.stale_batches_discarded, 1);
    assert_eq!(stats.batches_on_time, 3);
}

#[test]
fn with_both_buffers_held_by_a_stalled_inference_frames_go_without_and_recover() {
    let mut echo = Echo::new();
    echo.slow_batches = vec![1];
    echo.slow_for = Duration::from_millis(300);
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_millis(10)).unwrap();
    // Frame 0: slow batch, deadline missed. Frame 1: the second buffer is sent and waits in the
    // queue behind the slow one: missed too. Frame 2: no free buffer, nothing submitted.
    for frame in 0..3 {
        let batch = requests(frame, 2);
        let mut out = vec![Some(DVec2::ZERO); 2];
        predictor.predict(&batch, &mut out);
        assert_eq!(out, vec![None, None], "frame {frame}");
    }
    assert_eq!(predictor.stats().frames_without_free_buffer, 1);
    std::thread::sleep(Duration::from_millis(400));
    let batch = requests(3, 2);
    let mut out = vec![None; 2];
    predictor.set_deadline(Duration::from_secs(5));
    predictor.predict(&batch, &mut out);
    assert_eq!(out, vec![expected(3, 0), expected(3, 1)]);
}

#[test]
fn a_panicking_inference_retires_the_predictor_and_later_frames_go_without() {
    let mut echo = Echo::new();
    echo.panic_batches = vec![2];
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_secs(5)).unwrap();
    let mut results = Vec::new();
    for frame in 0..4 {
        let batch = requests(frame, 2);
        let mut out = vec![Some(DVec2::ZERO); 2];
        predictor.predict(&batch, &mut out);
        results.push(out);
    }
    assert!(results[0].iter().all(Option::is_some));
    for frame in 1..4 {
        assert_eq!(results[frame], vec![None, None], "frame {frame}");
    }
    assert_eq!(predictor.stats().inference_panics, 1);
    assert_eq!(predictor.stats().frames_without_inference_thread, 2);
}

#[test]
fn a_batch_larger_than_the_buffers_goes_without() {
    let mut predictor = ThreadedPredictor::with_capacity(Echo::new(), Duration::from_secs(5), 4).unwrap();
    let mut out = vec![Some(DVec2::ZERO); 5];
    predictor.predict(&requests(0, 5), &mut out);
    assert!(out.iter().all(Option::is_none));
    assert_eq!(predictor.stats().frames_too_large, 1);
    let mut out = vec![None; 4];
    predictor.predict(&requests(1, 4), &mut out);
    assert!(out.iter().all(Option::is_some));
}

#[test]
fn dropping_the_predictor_stops_its_thread() {
    struct Counted(Arc<AtomicU64>);
    impl Drop for Counted {
        fn drop(&mut self) {
            self.0.fetch_add(1, Ordering::SeqCst);
        }
    }
    struct Holder(Echo, #[allow(dead_code)] Counted);
    impl DisplacementPredictor for Holder {
        fn submit(&mut self, r: &[PredictionRequest]) {
            self.0.submit(r)
        }
        fn collect(&mut self, d: &mut [Option<DVec2>]) {
            self.0.collect(d)
        }
        fn predict(&mut self, r: &[PredictionRequest], d: &mut [Option<DVec2>]) {
            self.0.predict(r, d)
        }
    }
    let dropped = Arc::new(AtomicU64::new(0));
    let predictor =
        ThreadedPredictor::new(Holder(Echo::new(), Counted(dropped.clone())), Duration::from_secs(1))
            .unwrap();
    drop(predictor);
    // The inference thread was joined, so the predictor it owned is gone.
    assert_eq!(dropped.load(Ordering::SeqCst), 1);
}

#[test]
fn the_threaded_onnx_predictor_gives_the_synchronous_results() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx");
    let mut synchronous = OnnxPredictor::load(&path).unwrap();
    let mut threaded =
        ThreadedPredictor::new(OnnxPredictor::load(&path).unwrap(), Duration::from_secs(5)).unwrap();
    for frame in 0..20 {
        let t = frame as f64 * 0.015;
        let batch: Vec<PredictionRequest> = (0..(5 + frame % 11))
            .map(|i| {
                let history: Vec<HistoryEntry> = (0..(1 + i % 5))
                    .map(|l| HistoryEntry {
                        x_m: 20.0 - 0.3 * l as f64 + i as f64,
                        y_m: 2.0 + 0.05 * l as f64,
                        radial_velocity_mps: -5.0 + i as f64 * 0.1,
                        rcs_dbsm: 8.0,
                        timestamp_s: t - 0.03 * (5 - l) as f64,
                    })
                    .collect();
                PredictionRequest::from_history(&history, t).with_step_start(t - 0.015)
            })
            .collect();
        let mut a = vec![None; batch.len()];
        let mut b = vec![None; batch.len()];
        synchronous.predict(&batch, &mut a);
        threaded.predict(&batch, &mut b);
        assert!(a.iter().all(Option::is_some));
        assert_eq!(a, b, "frame {frame}");
    }
}
