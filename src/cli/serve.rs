//! `primm serve`: the tracker as a shared-memory service.

use super::latency_out::{print_files, LatencyOutArgs};
use super::TrackerArgs;
use primm_config::ConfigError;
use primm_config::{InferenceConfig, Settings};
use primm_core::mode::Method;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use primm_core::tracker::Tracker;
use primm_predictor::load_predictor;
use primm_predictor::onnx::ModelError;
use primm_predictor::split::{on_inference_threads, InferenceThreadsError, SplitPredictor};
use primm_predictor::threaded::ThreadedPredictor;
use primm_record::live::FoxgloveArgs;
use primm_record::transforms::RadarPose;
use primm_record::{LiveServerError, LiveView};
use primm_service::catalog::SERVICE_PREFIX_ENV;
use primm_service::latency_files::LatencyFilesError;
use primm_service::realtime::{RealtimeRefused, RealtimeReport, RealtimeSettings, TrackerRealtimeArgs};
use primm_service::{
    ConnectError, PublishTime, ServiceNames, ShutdownFlag, TrackingLoopError, TrackingOptions,
    TrackingService, WaitMode,
};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `primm serve`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    about = "Track frames from primm/measurements and publish primm/tracks and primm/latency over shared memory",
    after_help = "\
Examples:
  primm serve --method imm                    # then: primm publish --scenario, primm subscribe
  primm serve --method pr-imm --config my.toml
  primm serve --method pr-imm --cpu-affinity 2 --inference-cpu-affinity 3 --realtime-priority 80 --lock-memory"
)]
pub struct Args {
    /// The tracker's configuration, model (run on dedicated inference threads with the
    /// configuration's `predictor.deadline_ms`), engine and tracking frame.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Tracking method: cv, ca, ct, imm, pr, pr-imm. Overrides the configuration's `imm.modes`.
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
    /// Inference threads sharing each frame's batch (1 to 8); overrides the configuration's
    /// `predictor.inference_threads`.
    #[arg(long, value_name = "COUNT")]
    pub inference_threads: Option<usize>,
    /// The time the published tracks describe: `frame` (the newest frame's time, as the step
    /// left them) or `now` (predicted from the newest frame to the publish time, so that a
    /// consumer gets them at the time they describe; costs one prediction per track after the
    /// step, and the learned mode sits the prediction out). See docs/integrating.md.
    #[arg(long, value_enum, default_value = "frame", value_name = "WHEN")]
    pub publish_time: PublishTimeArg,
    /// Predict the learned mode only when a frame arrives, not ahead of it for the next frame's
    /// guessed time once the previous answer is sent (same results; for comparison).
    #[arg(long)]
    pub no_speculation: bool,
    /// Latency files (`--latency-out DIR`).
    #[command(flatten)]
    pub latency_files: LatencyOutArgs,
    /// Real-time settings of the tracking and inference threads (docs/realtime-tuning.md).
    #[command(flatten)]
    pub realtime: TrackerRealtimeArgs,
    /// A live Foxglove view of the service's streams (`--foxglove [ADDRESS]`), served from a
    /// subscriber on a thread of its own (docs/recording.md).
    #[command(flatten)]
    pub view: FoxgloveArgs,
}

/// `--publish-time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PublishTimeArg {
    /// The newest tracked frame's time.
    Frame,
    /// The publish time.
    Now,
}

/// Why `primm serve` failed.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The configuration could not be loaded or is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The configuration is invalid for the tracker.
    #[error(transparent)]
    Tracker(#[from] primm_core::config::ConfigError),
    /// `--model` was given for a method that does not use the learned predictor.
    #[error("--model {path}: method '{method}' does not use the learned predictor; use --method pr or pr-imm, or leave out --model")]
    ModelWithoutPredictor {
        /// The model path given.
        path: PathBuf,
        /// The method asked for.
        method: Method,
    },
    /// The learned predictor's model could not be loaded.
    #[error("method '{method}': {source}")]
    Model {
        /// The method asked for.
        method: Method,
        /// What went wrong with the model file.
        source: ModelError,
    },
    /// The inference threads could not be started.
    #[error("cannot start the inference threads: {0}")]
    InferenceThread(InferenceThreadsError),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The tracking loop failed.
    #[error(transparent)]
    Loop(#[from] TrackingLoopError),
    /// The latency files could not be written.
    #[error(transparent)]
    LatencyFiles(#[from] LatencyFilesError),
    /// A real-time setting could not be applied and `--require-realtime` was given.
    #[error(transparent)]
    Realtime(#[from] RealtimeRefused),
    /// The live Foxglove view could not start.
    #[error(transparent)]
    Foxglove(#[from] LiveServerError),
}

/// Runs the service until SIGINT or SIGTERM, then prints the counters and the latency table.
pub fn run(args: Args) -> Result<(), ServeError> {
    let mut settings = args.tracker.load_settings()?;
    if let (Some(path), false) = (&args.tracker.model, args.method.needs_predictor()) {
        return Err(ServeError::ModelWithoutPredictor { path: path.clone(), method: args.method });
    }
    settings.tracker = settings.tracker.with_modes(args.method.modes());
    if let Some(threads) = args.inference_threads {
        settings.inference.inference_threads = threads;
    }
    // Checked before the model and its threads are set up, so a bad value is named, not spawned.
    settings.validate()?;
    let Settings { tracker: config, inference } = settings;
    let radars: Vec<RadarPose> = config.frame.sensors.iter().map(RadarPose::from).collect();
    let realtime = args.realtime.settings();
    let mut report = RealtimeReport::default();
    if args.method.needs_predictor() {
        let predictor = learned_predictor(args.tracker.model.as_deref(), &inference, args.method)?;
        for (index, part) in predictor.parts().iter().enumerate() {
            if let Some(thread) = part.inference_thread() {
                realtime.apply_to_inference_thread(thread, index, &mut report);
            }
        }
        serve(Tracker::with_predictor(config, predictor)?, &args, &realtime, report, radars)
    } else {
        if realtime.inference_cpu_affinity.is_some() {
            tracing::warn!(method = %args.method, "--inference-cpu-affinity ignored: the method runs no inference thread");
        }
        serve(Tracker::with_predictor(config, NoPredictor)?, &args, &realtime, report, radars)
    }
}

/// The PR model on its own inference thread, built on the calling (tracking) thread so that the
/// hand-over allocates nothing from the first frame on.
fn learned_predictor(
    path: Option<&Path>,
    inference: &InferenceConfig,
    method: Method,
) -> Result<SplitPredictor<ThreadedPredictor>, ServeError> {
    let model =
        load_predictor(path, inference.engine).map_err(|source| ServeError::Model { method, source })?;
    tracing::info!(
        model = %model.model().source(),
        engine = ?model.model().engine(),
        deadline_ms = inference.deadline_ms,
        inference_threads = inference.inference_threads,
        "learned predictor loaded"
    );
    on_inference_threads(model, inference.inference_threads, inference.deadline())
        .map_err(ServeError::InferenceThread)
}

/// Serves with `tracker` until SIGINT or SIGTERM. The tracking thread's real-time settings
/// and the memory lock are applied once the service is built (its allocations made); the live
/// view's thread, if asked for, starts before and is left out of them.
fn serve<P: DisplacementPredictor>(
    tracker: Tracker<P>,
    args: &Args,
    realtime: &RealtimeSettings,
    mut report: RealtimeReport,
    radars: Vec<RadarPose>,
) -> Result<(), ServeError> {
    let shutdown = ShutdownFlag::on_signals().map_err(ServeError::Signals)?;
    let options = TrackingOptions {
        names: ServiceNames::new(&args.service_prefix),
        wait: if args.busy_poll { WaitMode::BusyPoll } else { WaitMode::Event },
        latency_report_interval_frames: args.latency_every,
        poll_timeout: Duration::from_millis(50),
        publish_time: match args.publish_time {
            PublishTimeArg::Frame => PublishTime::Frame,
            PublishTimeArg::Now => PublishTime::Now,
        },
        speculate: !args.no_speculation,
    };
    let names = options.names.clone();
    let mut service = TrackingService::new(tracker, options)?;
    if let Some(directory) = args.latency_files.directory() {
        service.write_latency_files(directory, args.latency_files.interval())?;
    }
    let view = match args.view.foxglove {
        Some(address) => Some(LiveView::start(address, &names, radars)?),
        None => None,
    };
    if let Some(view) = &view {
        println!("Foxglove live view on ws://{}", view.local_address());
    }
    realtime.apply_to_current_thread("tracking thread", &mut report);
    realtime.lock_memory_now(&mut report);
    report.finish(realtime.require_realtime)?;
    tracing::info!(
        method = %args.method,
        input = %names.measurements(),
        output = %names.tracks(),
        latency = %names.latency(),
        busy_poll = args.busy_poll,
        "tracker serving"
    );
    let result = service.run(&shutdown);
    drop(view);
    println!("{}", service.summary());
    let files = service.finish_latency_files();
    result?;
    print_files("latency files", &files?);
    tracing::info!("tracker stopped");
    Ok(())
}
