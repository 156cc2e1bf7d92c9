//! # primm-publisher: measurement frames onto shared memory
//!
//! Replays measurement CSV files, or a freshly generated scenario, onto `primm/measurements`
//! as `primm::MeasurementFrame` samples written in place. The binary `primm-publisher` and the
//! `primm publish` subcommand both run [`run`]; [`replay::Replayer`] is the loop itself, for
//! programs that feed their own sequences; [`load`] sends a scene at a fixed rate with every
//! frame's scheduled send time and finds the highest rate a tracker sustains without loss.
//!
//! ```no_run
//! use primm_publisher::replay::{Pacing, ReplayOptions, Replayer};
//! use primm_ipc::{ServiceNames, ShutdownFlag};
//!
//! let sequence = primm_publisher::builtin_scenario(7, Some(2.0))?;
//! let mut replayer = Replayer::new(&ServiceNames::new(""), false)?;
//! let options = ReplayOptions { pacing: Pacing::AsFastAsPossible, ..ReplayOptions::default() };
//! let summary = replayer.replay(&[sequence], &options, &ShutdownFlag::default())?;
//! println!("{} frames sent", summary.frames_sent);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod load;
pub mod replay;

use crate::replay::{Pacing, ReplayError, ReplayOptions, Replayer};
use primm_core::readable_number::readable;
use primm_ipc::catalog::SERVICE_PREFIX_ENV;
use primm_ipc::realtime::{RealtimeArgs, RealtimeRefused, RealtimeReport};
use primm_ipc::{ConnectError, ServiceNames, ShutdownFlag};
use primm_sim::io::{read_dataset_dir, read_sequence_file, CsvError, Sequence};
use primm_sim::scenario::{ConfigError as ScenarioConfigError, Preset, ScenarioGenerator};
use std::path::PathBuf;
use std::time::Duration;

/// Seed of the built-in scenario.
pub const DEFAULT_SCENARIO_SEED: u64 = 7;

/// Arguments of the publisher.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Replay radar measurement frames onto primm/measurements over shared memory")]
pub struct Args {
    /// Measurement CSV file, or a directory of them (replayed in file-name order, each one a new
    /// stream).
    #[arg(long, value_name = "PATH", required_unless_present = "scenario", conflicts_with = "scenario")]
    pub input: Option<PathBuf>,
    /// Generate the built-in radar scenario in memory instead of reading files.
    #[arg(long)]
    pub scenario: bool,
    /// Seed of the generated scenario.
    #[arg(long, default_value_t = DEFAULT_SCENARIO_SEED, requires = "scenario")]
    pub seed: u64,
    /// Duration of the generated scenario, s (default: the generator's).
    #[arg(long, value_name = "S", requires = "scenario")]
    pub duration_s: Option<f64>,
    /// Replay at the recorded speed times this factor.
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub speed: f64,
    /// Send frames back to back instead of at the recorded times.
    #[arg(long)]
    pub as_fast_as_possible: bool,
    /// Never have more than N frames unanswered by the tracker (flow control; N ≤ 16 is
    /// lossless).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_in_flight: Option<u64>,
    /// Start again from the beginning after the last frame, until interrupted.
    #[arg(long = "loop")]
    pub repeat: bool,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Wait this long for a tracker to serve before sending (0: send at once).
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    pub wait_for_tracker_s: f64,
    /// Stay connected this long after the last frame (or until SIGINT/SIGTERM), s. iceoryx2
    /// discards the frames of a publisher that disconnects before a subscriber took them, so a
    /// tracker that is behind loses the replay's last frames unless the publisher lingers.
    #[arg(long, default_value_t = 0.0, value_name = "S")]
    pub linger_s: f64,
    /// Prefix of the service names (`PREFIX/primm/...`).
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// Real-time settings of the replay thread (docs/realtime-tuning.md).
    #[command(flatten)]
    pub realtime: RealtimeArgs,
}

/// Why the publisher failed.
#[derive(Debug, thiserror::Error)]
pub enum PublishError {
    /// The measurement files could not be read.
    #[error(transparent)]
    Csv(#[from] CsvError),
    /// The scenario configuration is invalid.
    #[error("cannot generate the scenario: {0}")]
    Scenario(#[from] ScenarioConfigError),
    /// The input holds no frame.
    #[error("the input holds no frame")]
    Empty,
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// No tracker served within the wait.
    #[error(
        "no tracker is serving '{service}' after {} s (start `primm serve` first)",
        readable(.waited_s)
    )]
    NoTracker {
        /// The track service waited for.
        service: String,
        /// Seconds waited.
        waited_s: f64,
    },
    /// The replay failed.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// A real-time setting could not be applied and `--require-realtime` was given.
    #[error(transparent)]
    Realtime(#[from] RealtimeRefused),
}

/// The built-in scenario: the default generator preset with `seed`.
pub fn builtin_scenario(seed: u64, duration_s: Option<f64>) -> Result<Sequence, ScenarioConfigError> {
    let mut config = Preset::Default.config();
    if let Some(duration_s) = duration_s {
        config.sequence.duration_s = duration_s;
    }
    let generator = ScenarioGenerator::new(config)?;
    Ok(generator.generate_seeded(seed, &format!("scenario-{seed}")).sequence)
}

/// Runs the publisher until the replay ends or SIGINT/SIGTERM.
pub fn run(args: Args) -> Result<(), PublishError> {
    let sequences = match (&args.input, args.scenario) {
        (Some(path), _) if path.is_dir() => read_dataset_dir(path)?,
        (Some(path), _) => vec![read_sequence_file(path)?],
        (None, _) => vec![builtin_scenario(args.seed, args.duration_s)?],
    };
    if sequences.iter().all(|sequence| sequence.frames.is_empty()) {
        return Err(PublishError::Empty);
    }
    let shutdown = ShutdownFlag::on_signals().map_err(PublishError::Signals)?;
    let names = ServiceNames::new(&args.service_prefix);
    let mut replayer = Replayer::new(&names, args.max_in_flight.is_some())?;
    if args.wait_for_tracker_s > 0.0 {
        let wait = Duration::from_secs_f64(args.wait_for_tracker_s);
        if !replayer.wait_for_tracker(wait, &shutdown) {
            if shutdown.is_requested() {
                return Ok(());
            }
            return Err(PublishError::NoTracker {
                service: names.tracks(),
                waited_s: args.wait_for_tracker_s,
            });
        }
    }
    let options = ReplayOptions {
        pacing: if args.as_fast_as_possible {
            Pacing::AsFastAsPossible
        } else {
            Pacing::Recorded { speed: args.speed }
        },
        repeat: args.repeat,
        frame_limit: args.frames,
        max_in_flight: args.max_in_flight,
        answer_timeout: Duration::from_secs(5),
    };
    let realtime = args.realtime.settings();
    let mut report = RealtimeReport::default();
    realtime.apply_to_current_thread("replay thread", &mut report);
    realtime.lock_memory_now(&mut report);
    report.finish(realtime.require_realtime)?;
    let frames: usize = sequences.iter().map(|sequence| sequence.frames.len()).sum();
    tracing::info!(
        sequences = sequences.len(),
        frames,
        service = %names.measurements(),
        "replaying"
    );
    let summary = replayer.replay(&sequences, &options, &shutdown)?;
    if args.max_in_flight.is_some() && !summary.interrupted {
        replayer.wait_all_answered(Duration::from_secs(5), &shutdown)?;
    }
    tracing::info!(
        frames_sent = summary.frames_sent,
        frames_dropped = summary.frames_dropped,
        frames_without_receiver = summary.frames_without_receiver,
        measurements_sent = summary.measurements_sent,
        passes = summary.passes,
        interrupted = summary.interrupted,
        "replay finished"
    );
    if args.linger_s > 0.0 && !summary.interrupted {
        let until = std::time::Instant::now() + Duration::from_secs_f64(args.linger_s);
        while std::time::Instant::now() < until && !shutdown.is_requested() {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    Ok(())
}
