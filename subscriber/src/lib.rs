//! # primm-subscriber: the tracks from shared memory
//!
//! Reads `primm/tracks` and `primm/latency` (and `primm/measurements` for the ground truth),
//! shows a live view or records the track CSV format, and sums up accuracy and latency at the
//! end. The binary `primm-subscriber` and the `primm subscribe` subcommand both run [`run`];
//! [`subscribe`] returns the summary instead of printing it.
//!
//! It sleeps in an iceoryx2 `WaitSet` on the three event services (plus a 200 ms tick for the
//! view and time-outs), or spins with `--busy-poll`.
//!
//! ```no_run
//! use clap::Parser;
//!
//! #[derive(Parser)]
//! struct Cli {
//!     #[command(flatten)]
//!     args: primm_subscriber::Args,
//! }
//!
//! let cli = Cli::parse_from(["subscriber", "--frames", "100"]);
//! let summary = primm_subscriber::subscribe(&cli.args)?;
//! println!("{} track frames", summary.track_frames);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod accuracy;
mod ports;
mod summary;
pub mod track_csv;
mod viewer;

pub use summary::{LatencyRow, SubscriberSummary};

use crate::ports::Ports;
use crate::viewer::{histogram, open_csv, SubscriberLatency, Viewer};
use iceoryx2::port::ReceiveError;
use iceoryx2::prelude::{SignalHandlingMode, WaitSetBuilder};
use iceoryx2::waitset::{WaitSetAttachmentError, WaitSetCreateError, WaitSetRunError};
use primm_ipc::catalog::{self, Ipc, SERVICE_PREFIX_ENV};
use primm_ipc::clock::monotonic_ns;
use primm_ipc::latency_files::{LatencyFiles, LatencyFilesError, StageDescription};
use primm_ipc::realtime::{RealtimeArgs, RealtimeRefused, RealtimeReport};
use primm_ipc::{ConnectError, ServiceNames, ShutdownFlag};
use primm_record::live::FoxgloveArgs;
use primm_record::{LiveServerError, LiveView};
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of the subscriber.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Show or record the tracks published on primm/tracks, with accuracy and latency")]
pub struct Args {
    /// Record every track updated by a measurement to this CSV file
    /// (frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Exit after the answer to the last frame of a finite replay.
    #[arg(long)]
    pub until_end: bool,
    /// Exit after this many track frames.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Exit when no track frame arrived for this long, s.
    #[arg(long, value_name = "S")]
    pub idle_timeout_s: Option<f64>,
    /// No live view; only the summary at the end.
    #[arg(long)]
    pub quiet: bool,
    /// Also write the summary as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Do not read primm/measurements (no accuracy figures).
    #[arg(long)]
    pub no_truth: bool,
    /// Spin on the subscribers instead of sleeping in a WaitSet.
    #[arg(long)]
    pub busy_poll: bool,
    /// Prefix of the service names (`PREFIX/primm/...`).
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// Write the subscriber's latencies (publisher_to_subscriber, its coordinated-omission
    /// corrected twin, tracker_to_subscriber) into this directory: an HdrHistogram interval log
    /// (`.hlog`) and percentile distribution (`.hgrm`) each, and the plot `subscriber.svg`.
    #[arg(long, value_name = "DIR")]
    pub latency_out: Option<PathBuf>,
    /// Length of one interval of the `.hlog` files, s.
    #[arg(long, default_value_t = 1.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub latency_interval_s: f64,
    /// Real-time settings of the receiving thread (docs/realtime-tuning.md).
    #[command(flatten)]
    pub realtime: RealtimeArgs,
    /// A live Foxglove view of the streams (`--foxglove [ADDRESS]`), served from a subscriber on
    /// a thread of its own.
    #[command(flatten)]
    pub view: FoxgloveArgs,
}

/// Parses a positive, finite number of seconds (at most a day).
fn parse_positive_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.parse().map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0 {
        Ok(seconds)
    } else {
        Err(format!("`{text}`: the interval must be more than 0 and at most 86400 s"))
    }
}

/// Why the subscriber failed.
#[derive(Debug, thiserror::Error)]
pub enum SubscribeError {
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The WaitSet could not be created.
    #[error("cannot create the WaitSet: {0}")]
    WaitSetCreate(WaitSetCreateError),
    /// A listener could not be attached to the WaitSet.
    #[error("cannot attach to the WaitSet: {0}")]
    WaitSetAttach(WaitSetAttachmentError),
    /// Waiting in the WaitSet failed.
    #[error("cannot wait in the WaitSet: {0}")]
    WaitSetRun(WaitSetRunError),
    /// Receiving a sample failed.
    #[error("cannot receive: {0}")]
    Receive(ReceiveError),
    /// The latency files could not be written.
    #[error(transparent)]
    LatencyFiles(#[from] LatencyFilesError),
    /// The CSV or JSON output could not be written.
    #[error("cannot write {path}: {source}")]
    Output {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A real-time setting could not be applied and `--require-realtime` was given.
    #[error(transparent)]
    Realtime(#[from] RealtimeRefused),
    /// The live Foxglove view could not start.
    #[error(transparent)]
    Foxglove(#[from] LiveServerError),
}
/// Runs the subscriber until a stop condition or SIGINT/SIGTERM; prints the summary.
pub fn run(args: Args) -> Result<(), SubscribeError> {
    let summary = subscribe(&args)?;
    print!("{}", summary.text());
    if !summary.latency_files.is_empty() {
        println!("latency files:");
        for file in &summary.latency_files {
            println!("  {}", file.display());
        }
    }
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&summary).expect("the summary serialises");
        std::fs::write(path, json).map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    }
    Ok(())
}

/// Receives until a stop condition; returns what was seen.
pub fn subscribe(args: &Args) -> Result<SubscriberSummary, SubscribeError> {
    let shutdown = ShutdownFlag::on_signals().map_err(SubscribeError::Signals)?;
    let names = ServiceNames::new(&args.service_prefix);
    let node = catalog::create_node("primm-subscriber")?;
    let ports = Ports::open(&node, &names, !args.no_truth)?;
    let view = match args.view.foxglove {
        Some(address) => Some(LiveView::start(address, &names, Vec::new())?),
        None => None,
    };
    if let Some(view) = &view {
        eprintln!("Foxglove live view on ws://{}", view.local_address());
    }
    tracing::info!(service = %names.tracks(), "subscribed");
    let mut viewer = Viewer::new(args, ports.truth.is_some(), open_csv(args)?);
    if let Some(directory) = &args.latency_out {
        let stages: Vec<StageDescription> = SubscriberLatency::ALL
            .iter()
            .map(|latency| StageDescription::new(latency.name(), latency.description()))
            .collect();
        viewer.files = Some(LatencyFiles::create(
            directory,
            "subscriber",
            &stages,
            &histogram(),
            Duration::from_secs_f64(args.latency_interval_s),
            monotonic_ns(),
        )?);
    }
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Ipc>()
        .map_err(SubscribeError::WaitSetCreate)?;
    let mut guards = Vec::new();
    let mut tick = None;
    if !args.busy_poll {
        guards = ports.attach(&waitset)?;
        // For the view and time-outs.
        tick =
            Some(waitset.attach_interval(Duration::from_millis(200)).map_err(SubscribeError::WaitSetAttach)?);
    }
    let idle_timeout = args.idle_timeout_s.map(Duration::from_secs_f64);
    let realtime = args.realtime.settings();
    let mut report = RealtimeReport::default();
    realtime.apply_to_current_thread("receiving thread", &mut report);
    realtime.lock_memory_now(&mut report);
    report.finish(realtime.require_realtime)?;
    loop {
        if args.busy_poll {
            std::hint::spin_loop();
        } else {
            ports.wait(&waitset)?;
        }
        let done = ports.receive(&mut viewer, args)?;
        viewer.report_progress(args);
        if done
            || shutdown.is_requested()
            || idle_timeout.is_some_and(|timeout| viewer.last_frame_at.elapsed() >= timeout)
        {
            break;
        }
    }
    ports.take_late_latency_report(&mut viewer)?;
    drop(tick);
    drop(guards);
    drop(view);
    viewer.finish()
}
