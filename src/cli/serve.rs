//! `primm serve`: the tracker as a shared-memory service.

use crate::config::{Config, ConfigError};
use crate::mode::Method;
use crate::service::catalog::SERVICE_PREFIX_ENV;
use crate::service::{ConnectError, ServiceNames, ShutdownFlag, TrackingLoopError, TrackingOptions, TrackingService, WaitMode};
use crate::tracker::Tracker;
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of `primm serve`.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Track frames from primm/measurements and publish primm/tracks and primm/latency over shared memory")]
pub struct Args {
    /// Tracker configuration (TOML); the built-in defaults when absent.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Learned displacement predictor (ONNX). Not supported by this build yet.
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Tracking method: cv, ca, ct, imm (pr and pr-imm need --model). Overrides the
    /// configuration's `imm.modes`.
    #[arg(long, default_value = "imm")]
    pub method: Method,
    /// Spin on the input instead of sleeping until a publisher notifies (lowest latency, one
    /// core busy).
    #[arg(long)]
    pub busy_poll: bool,
    /// Prefix of the service names (`PREFIX/primm/...`), to run several setups side by side.
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// Publish a latency report every this many frames (0: only at shutdown).
    #[arg(long, default_value_t = 100, value_name = "FRAMES")]
    pub latency_every: u64,
}

/// Why `primm serve` failed.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The configuration could not be loaded or is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// `--model` was given, but this build has no runtime for the learned predictor.
    #[error("--model {path}: this build has no runtime for the learned predictor yet; use --method cv, ca, ct or imm")]
    ModelNotSupported {
        /// The model path given.
        path: PathBuf,
    },
    /// The method needs the learned predictor, which needs a model.
    #[error("method '{method}' needs the learned predictor (--model), which this build does not support yet; use --method cv, ca, ct or imm")]
    MethodNeedsPredictor {
        /// The method asked for.
        method: Method,
    },
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The tracking loop failed.
    #[error(transparent)]
    Loop(#[from] TrackingLoopError),
}

/// Runs the service until SIGINT or SIGTERM, then prints the counters and the latency table.
pub fn run(args: Args) -> Result<(), ServeError> {
    let config = match &args.config {
        Some(path) => Config::from_file(path)?,
        None => Config::default(),
    };
    if let Some(path) = args.model {
        return Err(ServeError::ModelNotSupported { path });
    }
    if args.method.needs_predictor() {
        return Err(ServeError::MethodNeedsPredictor { method: args.method });
    }
    let tracker = Tracker::new(config.with_modes(args.method.modes()))?;
    let shutdown = ShutdownFlag::on_signals().map_err(ServeError::Signals)?;
    let options = TrackingOptions {
        names: ServiceNames::new(&args.service_prefix),
        wait: if args.busy_poll { WaitMode::BusyPoll } else { WaitMode::Event },
        latency_report_interval_frames: args.latency_every,
        poll_timeout: Duration::from_millis(50),
    };
    let names = options.names.clone();
    let mut service = TrackingService::new(tracker, options)?;
    tracing::info!(
        method = %args.method,
        input = %names.measurements(),
        output = %names.tracks(),
        latency = %names.latency(),
        busy_poll = args.busy_poll,
        "tracker serving"
    );
    let result = service.run(&shutdown);
    println!("{}", service.summary());
    result?;
    tracing::info!("tracker stopped");
    Ok(())
}
