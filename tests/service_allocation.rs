//! The tracking thread of the service allocates nothing per frame of its own: 1 000 frames of
//! 64 objects go through iceoryx2 in and out (receive in place, track, write into a loaned
//! sample, send, notify, latency histograms and reports) while a counting allocator watches that
//! thread.
//!
//! iceoryx2 0.10's `Publisher::loan_uninit` itself allocates one small reference-counted handle
//! (48 bytes) per loaned sample; no public API avoids it. The bound below therefore allows at
//! most one allocation per loaned sample (track frames and latency reports) and nothing else:
//! a single allocation per frame anywhere else in the loop doubles the count and fails the test.
//!
//! With the learned predictor (PR-IMM) the PR model runs on its own inference thread; tract's
//! allocations happen there, and the hand-over from the tracking thread allocates nothing.
//!
//! `cargo test --test integration service_allocation:: -- --nocapture` prints the counts.

use crate::common;
use crate::common::counting_allocator;

use common::service::{unique_prefix, TestClient};
use counting_allocator::allocations;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use primm_core::tracker::Tracker;
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::threaded::ThreadedPredictor;
use primm_service::{ServiceNames, TrackingOptions, TrackingService, WaitMode};
use std::sync::mpsc;
use std::time::Duration;

const WARM_UP_FRAMES: u64 = 150;
const COUNTED_FRAMES: u64 = 1000;

fn run(wait: WaitMode, method: Method) {
    let names = ServiceNames::new(&unique_prefix("allocation"));
    let base = common::scene_frames(&common::lanes(64), 500, 0.04, 0.2, 21);
    let client = TestClient::new(&names);

    let (ready_tx, ready_rx) = mpsc::channel();
    let tracker_names = names.clone();
    let tracking = std::thread::spawn(move || {
        // Built on the tracking thread, as `primm serve` does.
        let predictor: Box<dyn DisplacementPredictor + Send> = if method.needs_predictor() {
            let model = OnnxPredictor::load("models/pr.onnx").unwrap();
            Box::new(ThreadedPredictor::new(model, Duration::from_secs(1)).unwrap())
        } else {
            Box::new(NoPredictor)
        };
        let tracker =
            Tracker::with_predictor(Config::default().with_modes(method.modes()), predictor).unwrap();
        let options = TrackingOptions {
            names: tracker_names,
            wait,
            latency_report_interval_frames: 100,
            poll_timeout: Duration::from_millis(20),
            ..TrackingOptions::default()
        };
        let mut service = TrackingService::new(tracker, options).unwrap();
        ready_tx.send(()).unwrap();
        while service.counters().frames_received < WARM_UP_FRAMES {
            service.poll(Duration::from_millis(20)).unwrap();
        }
        let reports_before = service.counters().latency_reports;
        let before = allocations();
        while service.counters().frames_received < WARM_UP_FRAMES + COUNTED_FRAMES {
            service.poll(Duration::from_millis(20)).unwrap();
        }
        let counted = allocations() - before;
        let loans = COUNTED_FRAMES + service.counters().latency_reports - reports_before;
        let stats = service.tracker().stats();
        (counted, loans, *service.counters(), stats.measurements_accepted, stats.learned_predictions_missing)
    });
    ready_rx.recv().unwrap();
    client.wait_for_tracker(Duration::from_secs(10));

    let mut frame: Frame = base[0].clone();
    let mut updated_tracks = 0u64;
    for k in 0..WARM_UP_FRAMES + COUNTED_FRAMES {
        let source = &base[k as usize % base.len()];
        frame.timestamp_s = k as f64 * 0.04;
        frame.measurements.clone_from(&source.measurements);
        client.send(&frame, k, 0);
        let (sequence, updated) = client
            .next_answer(Duration::from_secs(10), |answer| {
                (
                    answer.input_sequence,
                    answer.valid_tracks().iter().filter(|t| t.measurement_index().is_some()).count(),
                )
            })
            .expect("the tracker answers every frame");
        assert_eq!(sequence, k);
        updated_tracks += updated as u64;
    }
    let (counted, loans, counters, accepted, learned_missing) = tracking.join().unwrap();
    println!(
        "{method} {wait:?}: the tracking thread allocated {counted} times in {COUNTED_FRAMES} frames ({loans} loaned samples)"
    );
    assert!(
        counted <= loans,
        "the tracking thread allocated {counted} times in {COUNTED_FRAMES} frames with {loans} loaned samples"
    );
    assert_eq!(counters.frames_tracked, WARM_UP_FRAMES + COUNTED_FRAMES);
    assert_eq!(counters.frames_rejected, 0);
    assert!(counters.latency_reports >= 10, "{counters:?}");
    assert_eq!(accepted, 64 * (WARM_UP_FRAMES + COUNTED_FRAMES));
    assert_eq!(updated_tracks, 64 * (WARM_UP_FRAMES + COUNTED_FRAMES));
    if method.needs_predictor() {
        assert_eq!(learned_missing, 0, "every track got its learned displacement");
    }
}

#[test]
fn the_event_driven_tracking_loop_allocates_nothing_beyond_the_sample_loans() {
    run(WaitMode::Event, Method::Imm);
}

#[test]
fn the_busy_polling_tracking_loop_allocates_nothing_beyond_the_sample_loans() {
    run(WaitMode::BusyPoll, Method::Imm);
}

#[test]
fn with_the_learned_predictor_the_tracking_loop_allocates_nothing_beyond_the_sample_loans() {
    run(WaitMode::Event, Method::PrImm);
}
