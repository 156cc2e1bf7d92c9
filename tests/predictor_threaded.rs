//! The threaded predictor: same results as the synchronous one, a named inference thread,
//! deadlines that cost one frame only, stale results discarded, panics contained (the
//! predictor retired).
//!
//! No outcome here depends on how fast the machine is. A slow inference is a batch held by a
//! gate that the test opens: a frame whose batch is held misses its deadline however short or
//! long that is, and the test knows the order of events from the gate instead of from sleeps.
//! Frames that must get their results wait [`PATIENT`], a deadline no loaded machine reaches.

use crate::common::{anchored_requests as requests, echoed_anchor as expected};
use glam::DVec2;
use primm_core::predictor::{Displacement, DisplacementPredictor, HistoryEntry, PredictionRequest};
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::threaded::{ThreadedPredictor, INFERENCE_THREAD_NAME};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A deadline for frames that must get their results: only a dead inference thread misses it.
const PATIENT: Duration = Duration::from_secs(600);

/// Answers each request with its anchor scaled by 1/1000, so a result identifies its request.
/// Holds chosen batches (counted from 0; batch 0 is the warm-up) until the test opens the gate,
/// to play a slow model, and panics on others, to play a broken one.
struct Echo {
    batches: u64,
    held_batches: Vec<u64>,
    /// One message per held batch lets it go; `None`: nothing is held.
    release: Option<Receiver<()>>,
    /// Told the index of every batch as it starts.
    started: Option<Sender<u64>>,
    panic_batches: Vec<u64>,
    thread_names: Arc<std::sync::Mutex<Vec<String>>>,
}

impl Echo {
    fn new() -> Self {
        Echo {
            batches: 0,
            held_batches: Vec::new(),
            release: None,
            started: None,
            panic_batches: Vec::new(),
            thread_names: Arc::default(),
        }
    }

    /// An echo that holds `held_batches` until [`Gate::release`], and the gate.
    fn gated(held_batches: Vec<u64>) -> (Self, Gate) {
        let (release_sender, release) = channel();
        let (started, started_receiver) = channel();
        let echo = Echo { held_batches, release: Some(release), started: Some(started), ..Echo::new() };
        (echo, Gate { release: release_sender, started: started_receiver })
    }
}

/// The test's side of a gated [`Echo`]. Bind it after the predictor, so that if an assertion
/// fails it is dropped first: the held batch then goes free instead of leaving the predictor's
/// drop waiting for it.
struct Gate {
    release: Sender<()>,
    started: Receiver<u64>,
}

impl Gate {
    /// Lets one held batch go.
    fn release(&self) {
        self.release.send(()).expect("the inference thread is alive");
    }

    /// Waits until the inference thread starts `batch`. The thread hands each finished batch
    /// back before it takes the next, so every earlier batch has then been returned.
    fn wait_until_started(&self, batch: u64) {
        while self.started.recv().expect("the inference thread is alive") < batch {}
    }
}

impl DisplacementPredictor for Echo {
    fn submit(&mut self, _requests: &[PredictionRequest]) {}
    fn collect(&mut self, _displacements: &mut [Option<Displacement>]) {}
    fn predict(&mut self, requests: &[PredictionRequest], displacements: &mut [Option<Displacement>]) {
        let batch = self.batches;
        self.batches += 1;
        self.thread_names.lock().unwrap().push(std::thread::current().name().unwrap_or("").to_string());
        if let Some(started) = &self.started {
            let _ = started.send(batch);
        }
        if self.held_batches.contains(&batch) {
            if let Some(release) = &self.release {
                // An error means the test is gone: let the batch finish.
                let _ = release.recv();
            }
        }
        if self.panic_batches.contains(&batch) {
            panic!("inference blew up (deliberately, batch {batch})");
        }
        for (request, out) in requests.iter().zip(displacements.iter_mut()) {
            *out = Some((request.anchor_m / 1000.0).into());
        }
    }
}

#[test]
fn results_come_back_in_order_from_the_named_inference_thread() {
    let echo = Echo::new();
    let names = echo.thread_names.clone();
    let mut predictor = ThreadedPredictor::new(echo, PATIENT).unwrap();
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
    // Batch 0 is the warm-up; frame 1's batch (index 2) is held.
    let (echo, gate) = Echo::gated(vec![2]);
    let mut predictor = ThreadedPredictor::new(echo, PATIENT).unwrap();
    let gate = gate;
    let mut outcomes = Vec::new();
    for frame in 0..4 {
        let batch = requests(frame, 3);
        let mut out = vec![Some(DVec2::splat(-1.0).into()); 3];
        if frame == 1 {
            predictor.set_deadline(Duration::from_millis(40));
        }
        let started = Instant::now();
        predictor.submit(&batch);
        predictor.collect(&mut out);
        // Printed, not asserted: how long collect waited depends on the machine.
        println!("frame {frame}: collect returned after {:?}", started.elapsed());
        outcomes.push(out);
        if frame == 1 {
            // Frame 1's collect has returned while its batch is still held: the tracker did not
            // wait for the slow inference. Let the batch go; it comes back late, as stale.
            gate.release();
            predictor.set_deadline(PATIENT);
        }
    }
    // Frame 0 fine; frame 1 missed its deadline: every track None.
    assert_eq!(outcomes[0], vec![expected(0, 0), expected(0, 1), expected(0, 2)]);
    assert_eq!(outcomes[1], vec![None, None, None]);
    // Frames 2 and 3 get their own results, not frame 1's late ones, which the inference thread
    // returned before frame 2's.
    assert_eq!(outcomes[2], vec![expected(2, 0), expected(2, 1), expected(2, 2)]);
    assert_eq!(outcomes[3], vec![expected(3, 0), expected(3, 1), expected(3, 2)]);
    let stats = *predictor.stats();
    assert_eq!(stats.deadline_misses, 1);
    assert_eq!(stats.stale_batches_discarded, 1);
    assert_eq!(stats.batches_on_time, 3);
}

#[test]
fn with_both_buffers_held_by_a_stalled_inference_frames_go_without_and_recover() {
    // Frame 0's batch (index 1) is held.
    let (echo, gate) = Echo::gated(vec![1]);
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_millis(10)).unwrap();
    let gate = gate;
    // Frame 0: held batch, deadline missed. Frame 1: the second buffer is sent and waits in the
    // queue behind the held one: missed too. Frame 2: no free buffer, nothing submitted.
    for frame in 0..3 {
        let batch = requests(frame, 2);
        let mut out = vec![Some(DVec2::ZERO.into()); 2];
        predictor.predict(&batch, &mut out);
        assert_eq!(out, vec![None, None], "frame {frame}");
    }
    let stats = *predictor.stats();
    assert_eq!((stats.deadline_misses, stats.frames_without_free_buffer), (2, 1));
    // Let the held batch go and wait until frame 1's batch starts: frame 0's buffer is back.
    gate.release();
    gate.wait_until_started(2);
    let batch = requests(3, 2);
    let mut out = vec![None; 2];
    predictor.set_deadline(PATIENT);
    predictor.predict(&batch, &mut out);
    assert_eq!(out, vec![expected(3, 0), expected(3, 1)]);
    assert_eq!(predictor.stats().stale_batches_discarded, 2);
}

#[test]
fn the_first_collect_that_has_to_wait_allocates_nothing() {
    // Frame 0's batch (index 1) is held, so its collect blocks until the deadline: the first
    // blocking wait of this thread on the return channel, whose one-off allocations the
    // predictor made while it was built.
    let (echo, gate) = Echo::gated(vec![1]);
    let mut predictor = ThreadedPredictor::new(echo, Duration::from_millis(20)).unwrap();
    let gate = gate;
    let batch = requests(0, 3);
    let mut out = vec![None; 3];
    let allocations = crate::common::counting_allocator::count_allocations(|| {
        predictor.submit(&batch);
        predictor.collect(&mut out);
    });
    assert_eq!(predictor.stats().deadline_misses, 1);
    assert_eq!(allocations, 0);
    gate.release();
}

#[test]
fn a_panicking_inference_retires_the_predictor_and_later_frames_go_without() {
    let mut echo = Echo::new();
    echo.panic_batches = vec![2];
    let mut predictor = ThreadedPredictor::new(echo, PATIENT).unwrap();
    let mut results = Vec::new();
    for frame in 0..4 {
        let batch = requests(frame, 2);
        let mut out = vec![Some(DVec2::ZERO.into()); 2];
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
    let mut predictor = ThreadedPredictor::with_capacity(Echo::new(), PATIENT, 4).unwrap();
    let mut out = vec![Some(DVec2::ZERO.into()); 5];
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
        fn collect(&mut self, d: &mut [Option<Displacement>]) {
            self.0.collect(d)
        }
        fn predict(&mut self, r: &[PredictionRequest], d: &mut [Option<Displacement>]) {
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
    let mut threaded = ThreadedPredictor::new(OnnxPredictor::load(&path).unwrap(), PATIENT).unwrap();
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
                        ..Default::default()
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
