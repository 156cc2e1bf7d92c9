//! One PR-IMM frame on one time line: the tracking thread's stages and, for each inference
//! thread, its batch handed over, taken up, finished and collected, in microseconds from the
//! frame's arrival (median and p99 over the frames), once with the learned mode predicted when
//! the frame arrives and once with it predicted ahead, between frames (`Tracker::speculate`).
//!
//! The frames are the service benchmark's lane scene (`primm bench-service`: half cars, half
//! pedestrians, every object measured every frame), stepped at a fixed rate on this thread with
//! the PR model on its inference threads (the service's deadline, 5 ms); the thread sleeps
//! between frames as the service's does.
//!
//! `cargo bench --bench pr_frame_timeline [-- OBJECTS [THREADS [RATE_HZ [FRAMES]]]]` (defaults:
//! 64 objects, 2 inference threads, 200 Hz, 500 frames). Nothing is asserted; the output is for
//! reading (`docs/results/pr_frame_timeline.csv` keeps one run).

use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::stage_timing::{Stage, StageObserver};
use primm_core::tracker::Tracker;
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::split::{on_inference_threads, SplitPredictor};
use primm_predictor::threaded::ThreadedPredictor;
use primm_publisher::load::{lane_scene, LANE_SCENE_FRAME_INTERVAL_S};
use std::time::{Duration, Instant};

/// The tracking thread's stages, in the order they finish.
const STAGES: [(Stage, &str); 6] = [
    (Stage::Validate, "validate"),
    (Stage::Predict, "physics predict (batch handed over before)"),
    (Stage::LearnedWait, "learned wait (batch collected)"),
    (Stage::Associate, "associate"),
    (Stage::Update, "update"),
    (Stage::Report, "report = publish"),
];

/// When each stage of the current frame finished.
#[derive(Default)]
struct Stamps {
    finished: [Option<Instant>; STAGES.len()],
}

impl StageObserver for Stamps {
    fn stage_finished(&mut self, stage: Stage) {
        if let Some(index) = STAGES.iter().position(|(s, _)| *s == stage) {
            self.finished[index] = Some(Instant::now());
        }
    }
}

/// Microseconds from `origin` to `at` (negative when `at` is earlier).
fn micros(origin: Instant, at: Instant) -> f64 {
    if at >= origin {
        at.duration_since(origin).as_secs_f64() * 1e6
    } else {
        -(origin.duration_since(at).as_secs_f64() * 1e6)
    }
}

/// The events of one frame: (label, µs from arrival).
type Events = Vec<(String, f64)>;

/// Steps `frames` at `rate_hz`, speculating after each step if asked; the events per frame
/// after the first 20.
fn run(frames: &[Frame], threads: usize, rate_hz: f64, speculate: bool) -> Vec<Events> {
    let model = OnnxPredictor::embedded().expect("the built-in model loads");
    let predictor = on_inference_threads(model, threads, Duration::from_millis(5)).expect("threads start");
    let config = Config::default().with_modes(Method::PrImm.modes());
    let mut tracker: Tracker<SplitPredictor<ThreadedPredictor>> =
        Tracker::with_predictor(config, predictor).expect("valid configuration");
    let period = Duration::from_secs_f64(1.0 / rate_hz);
    let mut all = Vec::new();
    for (index, frame) in frames.iter().enumerate() {
        let arrival = Instant::now();
        let mut stamps = Stamps::default();
        tracker.step_observed(frame, &mut stamps, |_| {}).expect("valid frame");
        if speculate {
            tracker.speculate();
        }
        let speculated = Instant::now();
        let mut events: Events = STAGES
            .iter()
            .zip(stamps.finished)
            .filter_map(|((_, name), at)| Some((format!("tracking: {name}"), micros(arrival, at?))))
            .collect();
        if speculate {
            events.push(("tracking: next batch handed over (speculate)".into(), micros(arrival, speculated)));
        }
        for (part, predictor) in tracker.predictor().parts().iter().enumerate() {
            // Only a batch collected in this frame belongs to it.
            let Some(timeline) = predictor.last_timeline().filter(|t| t.collected >= arrival) else {
                continue;
            };
            let thread = format!("inference {} ({} requests)", part + 1, timeline.requests);
            events.push((format!("{thread}: handed over"), micros(arrival, timeline.submitted)));
            events.push((format!("{thread}: taken up"), micros(arrival, timeline.started)));
            events.push((format!("{thread}: finished"), micros(arrival, timeline.finished)));
            events.push((format!("{thread}: collected"), micros(arrival, timeline.collected)));
        }
        if index >= 20 {
            all.push(events);
        }
        if let Some(rest) = period.checked_sub(arrival.elapsed()) {
            std::thread::sleep(rest);
        }
    }
    all
}

/// The `q` quantile of `values` (sorted in place).
fn quantile(values: &mut [f64], q: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    values[rank - 1]
}

/// Prints one CSV row per event label: how many frames had it, median and p99 µs.
fn print_table(mode: &str, frames: &[Events]) {
    let mut labels: Vec<String> = Vec::new();
    for events in frames {
        for (label, _) in events {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
    }
    for label in labels {
        let mut values: Vec<f64> = frames
            .iter()
            .flat_map(|events| events.iter().filter(|(l, _)| *l == label).map(|(_, v)| *v))
            .collect();
        let count = values.len();
        let median = quantile(&mut values, 0.5);
        let p99 = quantile(&mut values, 0.99);
        println!("{mode},\"{label}\",{count},{median:.1},{p99:.1}");
    }
}

fn main() {
    // `cargo bench` passes `--bench`; positional arguments follow.
    let positional: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let number = |index: usize, default: f64| -> f64 {
        positional.get(index).map(|text| text.parse().expect("a number")).unwrap_or(default)
    };
    let objects = number(0, 64.0) as usize;
    let threads = number(1, 2.0) as usize;
    let rate_hz = number(2, 200.0);
    let count = number(3, 500.0) as usize;
    let scene = lane_scene(objects, count, LANE_SCENE_FRAME_INTERVAL_S, 0.2, 11);
    let frames = scene.to_frames().expect("frames fit");
    println!("# {objects} objects, {threads} inference threads, {rate_hz} Hz, {count} frames");
    println!("mode,event,frames,median_us,p99_us");
    for (mode, speculate) in [("in frame", false), ("ahead", true)] {
        print_table(mode, &run(&frames, threads, rate_hz, speculate));
    }
}
