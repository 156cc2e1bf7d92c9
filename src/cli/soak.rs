//! `primm soak`: runs the full tracker over a long synthetic scene and checks it after every
//! frame.
//!
//! The scene (`soak/scene.rs`) keeps a fixed number of objects in view forever, with objects
//! leaving and new ones arriving, missed detections and clutter. After every frame the soak
//! checks `primm_core::invariants::check_tracker` and the state bounds of `soak/bounds.rs`
//! (positions, velocities, covariance traces, live-track count). At the end it prints frames,
//! objects, the resident set size at start and end, step-latency percentiles of the first and
//! the last tenth of the run, tracks started and deleted, and the violations found; any
//! violation makes the command fail.
//!
//! With `--method pr` or `pr-imm` the learned predictor runs synchronously by default, so every
//! frame goes through the model and the PR mode's path is exercised on every frame whatever the
//! machine's load; `--inference-thread` runs it on the inference thread with the
//! configuration's deadline instead, as `primm serve` does.
//!
//! The resident set size is read from `/proc/self/statm` (Linux only; elsewhere it is reported
//! as unavailable).

mod bounds;
mod scene;

use super::TrackerArgs;
use bounds::check_bounds;
use clap::Args as ClapArgs;
use hdrhistogram::Histogram;
use primm_core::invariants::check_tracker;
use primm_core::limits::MAX_TRACKS;
use primm_core::mode::Method;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::Tracker;
use primm_predictor::load_predictor;
use primm_predictor::onnx::ModelError;
use primm_predictor::split::{on_inference_threads, InferenceThreadsError};
use scene::SoakScene;
use std::time::Instant;

/// Violations printed in full; the rest are only counted.
const VIOLATIONS_SHOWN: usize = 10;

/// Arguments of `primm soak`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Run the tracker over a long synthetic scene, checking its invariants and bounds after every frame"
)]
pub struct Args {
    /// Method: cv, ca, ct, pr, imm or pr-imm.
    #[arg(long, default_value = "imm")]
    pub method: Method,
    /// Frames to run.
    #[arg(long, default_value_t = 1_000_000)]
    pub frames: u64,
    /// Objects kept in view (1 to 256).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u16).range(1..=256))]
    pub objects: u16,
    /// Seed of the scene.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The tracker's configuration, model, engine and tracking frame.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Run the learned predictor on the inference threads with the configuration's deadline
    /// and `predictor.inference_threads` (as `primm serve`) instead of synchronously.
    #[arg(long)]
    pub inference_thread: bool,
    /// Print a progress line on stderr every this many frames (0: never).
    #[arg(long, default_value_t = 100_000, value_name = "FRAMES")]
    pub progress_every: u64,
}

/// Why `primm soak` failed.
#[derive(Debug, thiserror::Error)]
pub enum SoakError {
    /// The configuration file could not be read or is invalid.
    #[error(transparent)]
    Config(#[from] primm_config::ConfigError),
    /// The configuration is invalid for the tracker.
    #[error(transparent)]
    Tracker(#[from] primm_core::config::ConfigError),
    /// The learned predictor's model could not be loaded.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The inference threads could not be started.
    #[error("cannot start the inference threads: {0}")]
    InferenceThread(InferenceThreadsError),
    /// The soak ran to the end but found violations (the report was printed).
    #[error("{count} violations of the tracker's invariants or state bounds")]
    Violations {
        /// Violations found.
        count: u64,
    },
}

/// What a soak found.
#[derive(Debug, Default)]
struct SoakOutcome {
    frames: u64,
    violations: u64,
    rejected_frames: u64,
    max_live_tracks: usize,
    first_tenth: Option<Histogram<u64>>,
    last_tenth: Option<Histogram<u64>>,
    rss_start_bytes: Option<u64>,
    rss_end_bytes: Option<u64>,
}

/// Runs the soak and prints its report; fails when any violation was found.
pub fn run(args: &Args) -> Result<(), SoakError> {
    let settings = args.tracker.load_settings()?;
    let config = settings.tracker.with_modes(args.method.modes());
    if !args.method.needs_predictor() {
        return soak(Tracker::new(config)?, args);
    }
    let model = load_predictor(args.tracker.model.as_deref(), settings.inference.engine)?;
    if args.inference_thread {
        let deadline = settings.inference.deadline();
        let threads = settings.inference.inference_threads;
        let predictor = on_inference_threads(model, threads, deadline).map_err(SoakError::InferenceThread)?;
        soak(Tracker::with_predictor(config, predictor)?, args)
    } else {
        soak(Tracker::with_predictor(config, model)?, args)
    }
}

/// Steps `tracker` over the scene, checks it after every frame, prints the report.
fn soak<P: DisplacementPredictor>(mut tracker: Tracker<P>, args: &Args) -> Result<(), SoakError> {
    let objects = usize::from(args.objects);
    let mut scene = SoakScene::new(objects, args.seed, tracker.config());
    let modes = tracker.config().imm.modes;
    let max_tracks = (3 * objects + 64).min(MAX_TRACKS);
    let tenth = (args.frames / 10).max(1);
    let mut outcome = SoakOutcome {
        first_tenth: Some(new_histogram()),
        last_tenth: Some(new_histogram()),
        rss_start_bytes: resident_set_bytes(),
        ..Default::default()
    };
    let started = Instant::now();
    for frame_index in 0..args.frames {
        let frame = scene.next_frame();
        let step_started = Instant::now();
        let stepped = tracker.step(&frame).map(|outputs| outputs.len());
        let step_ns = step_started.elapsed().as_nanos().min(u128::from(u64::MAX)) as u64;
        let histogram = if frame_index < tenth {
            outcome.first_tenth.as_mut()
        } else if frame_index >= args.frames.saturating_sub(tenth) {
            outcome.last_tenth.as_mut()
        } else {
            None
        };
        if let Some(histogram) = histogram {
            histogram.saturating_record(step_ns.max(1));
        }
        outcome.frames += 1;
        if let Err(error) = stepped {
            outcome.rejected_frames += 1;
            violation(&mut outcome, frame_index, &error);
        }
        if let Err(error) = check_tracker(&tracker) {
            violation(&mut outcome, frame_index, &error);
        }
        if let Err(error) = check_bounds(tracker.tracks(), modes, max_tracks) {
            violation(&mut outcome, frame_index, &error);
        }
        outcome.max_live_tracks = outcome.max_live_tracks.max(tracker.tracks().len());
        if args.progress_every > 0 && (frame_index + 1) % args.progress_every == 0 {
            eprintln!(
                "soak: {} frames, {} live tracks, {} violations, {:.0} s",
                frame_index + 1,
                tracker.tracks().len(),
                outcome.violations,
                started.elapsed().as_secs_f64()
            );
        }
    }
    outcome.rss_end_bytes = resident_set_bytes();
    print_report(args, &tracker, &scene, &outcome, max_tracks, started.elapsed().as_secs_f64());
    match outcome.violations {
        0 => Ok(()),
        count => Err(SoakError::Violations { count }),
    }
}

/// Counts a violation and prints the first few.
fn violation(outcome: &mut SoakOutcome, frame_index: u64, error: &dyn std::fmt::Display) {
    outcome.violations += 1;
    if outcome.violations as usize <= VIOLATIONS_SHOWN {
        eprintln!("soak: frame {frame_index}: {error}");
    }
}

/// A histogram of step times from 1 ns to 60 s, 3 significant digits.
fn new_histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, 60_000_000_000, 3).expect("constant, valid histogram bounds")
}

/// The resident set size from `/proc/self/statm` (Linux); `None` elsewhere.
fn resident_set_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions; it only reads a system constant.
    let page_size = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    u64::try_from(page_size).ok().map(|size| pages * size)
}

/// Prints the report on stdout.
fn print_report<P: DisplacementPredictor>(
    args: &Args,
    tracker: &Tracker<P>,
    scene: &SoakScene,
    outcome: &SoakOutcome,
    max_tracks: usize,
    elapsed_s: f64,
) {
    let stats = tracker.stats();
    let mib = |bytes: Option<u64>| match bytes {
        Some(bytes) => format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0)),
        None => "unavailable".to_string(),
    };
    let percentiles = |histogram: &Option<Histogram<u64>>| match histogram {
        Some(h) if !h.is_empty() => format!(
            "p50 {:.1} µs, p90 {:.1} µs, p99 {:.1} µs, max {:.1} µs ({} frames)",
            h.value_at_quantile(0.5) as f64 / 1000.0,
            h.value_at_quantile(0.9) as f64 / 1000.0,
            h.value_at_quantile(0.99) as f64 / 1000.0,
            h.max() as f64 / 1000.0,
            h.len()
        ),
        _ => "no frames".to_string(),
    };
    println!("soak report");
    println!("  method: {} ({})", args.method, predictor_mode(args));
    println!("  frames: {} ({} rejected), seed {}", outcome.frames, outcome.rejected_frames, args.seed);
    println!(
        "  objects in view: {} ({} replaced after leaving the scene)",
        scene.object_count(),
        scene.objects_replaced()
    );
    println!(
        "  resident set: {} at start, {} at end",
        mib(outcome.rss_start_bytes),
        mib(outcome.rss_end_bytes)
    );
    println!("  step latency, first 10 %: {}", percentiles(&outcome.first_tenth));
    println!("  step latency, last 10 %: {}", percentiles(&outcome.last_tenth));
    println!(
        "  tracks: {} started, {} deleted, {} live at the end, at most {} live (bound {})",
        stats.tracks_initiated,
        stats.tracks_deleted,
        tracker.tracks().len(),
        outcome.max_live_tracks,
        max_tracks
    );
    println!(
        "  learned predictions: {} missing, {} rejected non-finite, {} rejected implausible, {} rejected for their covariance",
        stats.learned_predictions_missing,
        stats.learned_predictions_rejected_non_finite,
        stats.learned_predictions_rejected_implausible,
        stats.learned_predictions_rejected_invalid_covariance
    );
    if let Some(report) = tracker.predictor().report() {
        println!("  {report}");
    }
    println!("  wall time: {elapsed_s:.1} s");
    println!("  invariant violations: {}", outcome.violations);
}

/// How the learned predictor runs, in words.
fn predictor_mode(args: &Args) -> &'static str {
    match (args.method.needs_predictor(), args.inference_thread) {
        (false, _) => "no learned predictor",
        (true, false) => "learned predictor synchronous",
        (true, true) => "learned predictor on the inference threads",
    }
}
