//! `primm bench-service`: a latency benchmark of the tracking service that a benchmarker can
//! run and keep. It starts `primm serve` (this executable), sends a scene of `--objects`
//! objects on lanes at `--rate-hz` for `--duration-s`, each frame stamped with its scheduled
//! send time, and reads the answers as they come (polling every 100 µs between sends). It
//! leaves in `--latency-out DIR`:
//!
//! - the tracker's files (`primm serve --latency-out`): per stage `STAGE.hlog`, `STAGE.hgrm`,
//!   and `tracker.svg`;
//! - the client's (publisher send → answer, the same from the schedule, i.e. corrected for
//!   coordinated omission, and tracker send → answer): `.hlog`, `.hgrm`, `client.svg`;
//! - `summary.md`: settings, host, counts, percentile tables (read back from the `.hlog` files),
//!   and with `--find-max-rate` the highest rate sustained without losing a frame (doubling,
//!   then bisection, a fresh tracker per trial; `primm_publisher::load`).

mod recorder_process;
mod viewer_client;

use super::latency_out::parse_positive_seconds;
use super::TrackerArgs;
use primm_core::mode::Method;
use primm_core::stage_timing::Stage;
use primm_publisher::load::{
    highest_sustained_rate, lane_scene, latency_histogram, run_rate_trial, ClientLatency, RateSearch,
    RateTrial, RateTrialError, RateTrialOptions, LANE_SCENE_FRAMES, LANE_SCENE_FRAME_INTERVAL_S,
};
use primm_publisher::replay::Replayer;
use primm_record::live::FoxgloveArgs;
use primm_service::clock::monotonic_ns;
use primm_service::latency::summarise;
use primm_service::latency_files::{
    read_interval_log, LatencyFiles, LatencyFilesError, ReadLogError, StageDescription, OUTPUT_UNIT,
};
use primm_service::realtime::TrackerRealtimeArgs;
use primm_service::{ConnectError, ServiceNames, ShutdownFlag};
use primm_sim::io::Sequence;
use recorder_process::RecorderProcess;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use viewer_client::ViewerClient;

/// How the tracker under test runs: the options passed on to `primm serve`. Settings of the
/// tracking process (methods, engines, wait modes, scheduling) belong here.
#[derive(Debug, Clone, clap::Args)]
pub struct TrackerSettings {
    /// Tracking method: cv, ca, ct, imm, pr, pr-imm.
    #[arg(long, default_value = "imm")]
    pub method: Method,
    /// The tracker's configuration, model, engine and tracking frame.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Inference threads (default: the configuration's).
    #[arg(long, value_name = "COUNT")]
    pub inference_threads: Option<usize>,
    /// Let the tracker spin on its input instead of sleeping until notified.
    #[arg(long)]
    pub busy_poll: bool,
    /// Run the learned mode only when a frame arrives, not ahead of it (`primm serve
    /// --no-speculation`).
    #[arg(long)]
    pub no_speculation: bool,
    /// The tracker's real-time settings (docs/realtime-tuning.md); the benchmark's own client
    /// threads stay unpinned.
    #[command(flatten)]
    pub realtime: TrackerRealtimeArgs,
    /// The tracker's live Foxglove view (`--foxglove [ADDRESS]`).
    #[command(flatten)]
    pub view: FoxgloveArgs,
}

impl TrackerSettings {
    /// The `primm serve` arguments for these settings.
    pub fn serve_arguments(&self) -> Vec<OsString> {
        let mut arguments: Vec<OsString> = vec!["--method".into(), self.method.id().into()];
        arguments.extend(self.tracker.to_arguments());
        if let Some(threads) = self.inference_threads {
            arguments.extend(["--inference-threads".into(), threads.to_string().into()]);
        }
        if self.busy_poll {
            arguments.push("--busy-poll".into());
        }
        if self.no_speculation {
            arguments.push("--no-speculation".into());
        }
        arguments.extend(self.realtime.to_arguments().into_iter().map(OsString::from));
        if let Some(address) = self.view.foxglove {
            arguments.extend(["--foxglove".into(), address.to_string().into()]);
        }
        arguments
    }

    /// One line for the summary.
    fn describe(&self) -> String {
        let arguments: Vec<String> =
            self.serve_arguments().iter().map(|argument| argument.to_string_lossy().into_owned()).collect();
        arguments.join(" ")
    }
}

/// Arguments of `primm bench-service`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    about = "Benchmark the tracking service: latency files, plots, a summary and the highest lossless rate"
)]
pub struct Args {
    /// Frames sent per second (wall clock).
    #[arg(long, default_value_t = 100.0, value_name = "HZ", value_parser = parse_rate)]
    pub rate_hz: f64,
    /// Objects per frame (every one measured in every frame).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u16).range(1..=256))]
    pub objects: u16,
    /// How long frames are sent at `--rate-hz`, s.
    #[arg(long, default_value_t = 20.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub duration_s: f64,
    /// The tracker under test.
    #[command(flatten)]
    pub tracker: TrackerSettings,
    /// Directory of the latency files, plots and `summary.md`.
    #[arg(long, default_value = "bench-service", value_name = "DIR")]
    pub latency_out: PathBuf,
    /// Length of one interval of the `.hlog` files, s.
    #[arg(long, default_value_t = 1.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub latency_interval_s: f64,
    /// Also search for the highest rate sustained without losing a frame.
    #[arg(long)]
    pub find_max_rate: bool,
    /// Length of one trial of the search, s.
    #[arg(long, default_value_t = 10.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub trial_s: f64,
    /// First rate of the search (then doubled until frames are lost), Hz.
    #[arg(long, default_value_t = 100.0, value_name = "HZ", value_parser = parse_rate)]
    pub start_hz: f64,
    /// Bisection steps of the search after the first rate with loss.
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub steps: usize,
    /// Connect a Foxglove WebSocket client to the tracker's live view (`--foxglove`) for each
    /// trial, subscribed to every topic: the cost of a watching viewer (docs/recording.md).
    #[arg(long, requires = "foxglove")]
    pub foxglove_client: bool,
    /// Run `primm record` into this MCAP file beside the tracker during the main trial (what
    /// recording costs; its summary says whether it missed a frame).
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Highest rate the search tries, Hz.
    #[arg(long, default_value_t = 50_000.0, value_name = "HZ", value_parser = parse_rate)]
    pub max_hz: f64,
}

/// Parses a rate: a positive, finite number of Hz, at most 1 MHz.
fn parse_rate(text: &str) -> Result<f64, String> {
    let rate: f64 = text.parse().map_err(|_| format!("`{text}` is not a rate in Hz"))?;
    if rate.is_finite() && rate > 0.0 && rate <= 1.0e6 {
        Ok(rate)
    } else {
        Err(format!("`{text}`: the rate must be more than 0 and at most 1000000 Hz"))
    }
}

/// Why the benchmark failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchServiceError {
    /// This executable's path is unknown.
    #[error("cannot locate the primm executable: {0}")]
    Executable(std::io::Error),
    /// `primm serve` could not be started or watched.
    #[error("cannot run the tracker (primm serve): {0}")]
    Spawn(std::io::Error),
    /// The tracker exited before it was asked to stop, or failed.
    #[error("the tracker (primm serve) exited ({status}):\n{output}")]
    TrackerExited {
        /// Its exit status.
        status: ExitStatus,
        /// What it printed.
        output: String,
    },
    /// The tracker did not come up or stop in time.
    #[error("the tracker (primm serve) did not {event} within {seconds} s")]
    TrackerTimeout {
        /// What it did not do.
        event: &'static str,
        /// The wait.
        seconds: u64,
    },
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// A trial failed.
    #[error(transparent)]
    Trial(#[from] RateTrialError),
    /// The client's latency files could not be written.
    #[error(transparent)]
    LatencyFiles(#[from] LatencyFilesError),
    /// The tracker's latency files could not be read back.
    #[error(transparent)]
    ReadLog(#[from] ReadLogError),
    /// The Foxglove client or the recorder failed.
    #[error("{0}")]
    Watcher(String),
    /// The summary could not be written.
    #[error("cannot write {path}: {source}")]
    Summary {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// How long the tracker may take to come up (loading a model included) and to stop.
const TRACKER_START_TIMEOUT: Duration = Duration::from_secs(60);
const TRACKER_STOP_TIMEOUT: Duration = Duration::from_secs(30);

/// Longest wait for the last answers after a trial's last frame.
const DRAIN: Duration = Duration::from_secs(2);

/// A running `primm serve`.
struct TrackerProcess {
    child: Child,
}

impl TrackerProcess {
    /// Starts `primm serve` under `prefix` with `settings`, and `latency_out` if given.
    fn start(
        exe: &Path,
        prefix: &str,
        settings: &TrackerSettings,
        latency_out: Option<(&Path, f64)>,
    ) -> Result<Self, BenchServiceError> {
        let mut command = Command::new(exe);
        command
            .args(["serve", "--service-prefix", prefix, "--latency-every", "100"])
            .args(settings.serve_arguments())
            .env("RUST_LOG", std::env::var("RUST_LOG").unwrap_or_else(|_| "error".to_owned()))
            .stdout(Stdio::piped());
        if let Some((directory, interval_s)) = latency_out {
            command
                .arg("--latency-out")
                .arg(directory)
                .args(["--latency-interval-s", &interval_s.to_string()]);
        }
        let child = command.spawn().map_err(BenchServiceError::Spawn)?;
        Ok(Self { child })
    }

    /// Waits until the tracker serves (`replayer` sees its track stream); fails when it exits.
    fn wait_until_serving(
        &mut self,
        replayer: &Replayer,
        shutdown: &ShutdownFlag,
    ) -> Result<(), BenchServiceError> {
        let deadline = Instant::now() + TRACKER_START_TIMEOUT;
        while !replayer.wait_for_tracker(Duration::from_millis(100), shutdown) {
            if let Some(status) = self.child.try_wait().map_err(BenchServiceError::Spawn)? {
                return Err(BenchServiceError::TrackerExited { status, output: self.output() });
            }
            if Instant::now() >= deadline || shutdown.is_requested() {
                return Err(BenchServiceError::TrackerTimeout {
                    event: "come up",
                    seconds: TRACKER_START_TIMEOUT.as_secs(),
                });
            }
        }
        Ok(())
    }

    /// What it printed on stdout (read once it has exited).
    fn output(&mut self) -> String {
        let mut text = String::new();
        if let Some(mut pipe) = self.child.stdout.take() {
            use std::io::Read;
            let _ = pipe.read_to_string(&mut text);
        }
        text
    }

    /// Stops it (SIGINT) and returns what it printed: its counters, latency table and files.
    fn stop(mut self) -> Result<String, BenchServiceError> {
        if let Some(status) = self.child.try_wait().map_err(BenchServiceError::Spawn)? {
            return Err(BenchServiceError::TrackerExited { status, output: self.output() });
        }
        // SAFETY: sending a signal to our own child by its pid has no memory-safety concerns.
        unsafe {
            libc::kill(self.child.id() as libc::pid_t, libc::SIGINT);
        }
        let deadline = Instant::now() + TRACKER_STOP_TIMEOUT;
        loop {
            if let Some(status) = self.child.try_wait().map_err(BenchServiceError::Spawn)? {
                let output = self.output();
                return if status.success() {
                    Ok(output)
                } else {
                    Err(BenchServiceError::TrackerExited { status, output })
                };
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                return Err(BenchServiceError::TrackerTimeout {
                    event: "stop",
                    seconds: TRACKER_STOP_TIMEOUT.as_secs(),
                });
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for TrackerProcess {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// One trial against a fresh tracker: what the client saw and what the tracker printed.
struct TrialRun {
    trial: RateTrial,
    tracker_output: String,
}

/// Runs one trial at `rate_hz` for `duration` against a fresh `primm serve`; with `files`,
/// the tracker writes its latency files there and the client its own.
fn run_trial(
    exe: &Path,
    args: &Args,
    scene: &Sequence,
    rate_hz: f64,
    duration: Duration,
    files: Option<&Path>,
    shutdown: &ShutdownFlag,
) -> Result<TrialRun, BenchServiceError> {
    let prefix = format!("primm-bench-{}-{}", std::process::id(), monotonic_ns());
    let names = ServiceNames::new(&prefix);
    let mut replayer = Replayer::new(&names, true)?;
    let mut tracker = TrackerProcess::start(
        exe,
        &prefix,
        &args.tracker,
        files.map(|directory| (directory, args.latency_interval_s)),
    )?;
    tracker.wait_until_serving(&replayer, shutdown)?;
    let recorder = match args.record.as_deref().filter(|_| files.is_some()) {
        Some(path) => Some(
            RecorderProcess::start(exe, &prefix, path, || replayer.track_subscribers())
                .map_err(BenchServiceError::Watcher)?,
        ),
        None => None,
    };
    let viewer = match args.tracker.view.foxglove.filter(|_| args.foxglove_client) {
        Some(address) => Some(ViewerClient::start(address).map_err(BenchServiceError::Watcher)?),
        None => None,
    };
    let interval = Duration::from_secs_f64(args.latency_interval_s);
    let mut client_files = match files {
        Some(directory) => {
            let stages: Vec<StageDescription> = ClientLatency::ALL
                .iter()
                .map(|latency| StageDescription::new(latency.name(), latency.description()))
                .collect();
            Some(LatencyFiles::create(
                directory,
                "client",
                &stages,
                &latency_histogram(),
                interval,
                monotonic_ns(),
            )?)
        }
        None => None,
    };
    let mut file_error = None;
    let options = RateTrialOptions { rate_hz, duration, drain: DRAIN };
    let trial = run_rate_trial(&mut replayer, scene, &options, shutdown, |now_ns, latencies| {
        if let Some(files) = &mut client_files {
            if let Err(error) = files.write_due(now_ns, |index| &latencies[index]) {
                file_error = Some(error);
                client_files = None;
            }
        }
    })?;
    if let Some(viewer) = viewer {
        let received = viewer.finish().map_err(BenchServiceError::Watcher)?;
        println!("Foxglove client received {received} messages");
    }
    if let Some(recorder) = recorder {
        print!("{}", recorder.finish().map_err(BenchServiceError::Watcher)?);
    }
    let tracker_output = tracker.stop()?;
    if let Some(error) = file_error {
        return Err(error.into());
    }
    if let Some(files) = client_files {
        files.finish(monotonic_ns(), |index| &trial.latencies[index])?;
    }
    Ok(TrialRun { trial, tracker_output })
}

/// Runs the benchmark.
pub fn run(args: &Args) -> Result<(), BenchServiceError> {
    let exe = std::env::current_exe().map_err(BenchServiceError::Executable)?;
    let shutdown = ShutdownFlag::on_signals().map_err(BenchServiceError::Signals)?;
    let scene =
        lane_scene(usize::from(args.objects), LANE_SCENE_FRAMES, LANE_SCENE_FRAME_INTERVAL_S, 0.2, 11);
    let directory = &args.latency_out;
    std::fs::create_dir_all(directory)
        .map_err(|source| BenchServiceError::Summary { path: directory.clone(), source })?;
    println!(
        "primm bench-service: {} objects at {} Hz for {} s, tracker `primm serve {}`; files in {}",
        args.objects,
        args.rate_hz,
        args.duration_s,
        args.tracker.describe(),
        directory.display()
    );
    let main = run_trial(
        &exe,
        args,
        &scene,
        args.rate_hz,
        Duration::from_secs_f64(args.duration_s),
        Some(directory),
        &shutdown,
    )?;
    println!(
        "sent {}, answered {}, lost {}, send failures {}, sent late {}",
        main.trial.sent,
        main.trial.answered,
        main.trial.lost(),
        main.trial.send_failures,
        main.trial.late_sends
    );
    let search = if args.find_max_rate && !shutdown.is_requested() {
        let trial_length = Duration::from_secs_f64(args.trial_s);
        Some(highest_sustained_rate(args.start_hz, args.max_hz, args.steps, |rate| {
            let run = run_trial(&exe, args, &scene, rate, trial_length, None, &shutdown)?;
            // The verdict of `benches/max_rate.rs`: every frame sent, and none of them lost by
            // the tracker (sequence gaps: dropped from its full input buffer). Answers the
            // client itself missed are reported, not counted against the tracker.
            let lossless = run.trial.send_failures == 0 && tracker_lost(&run.tracker_output) == Some(0);
            println!(
                "trial {rate:.0} Hz: sent {}, answered {}, lost by the tracker {} -> {}",
                run.trial.sent,
                run.trial.answered,
                tracker_lost(&run.tracker_output).map_or("?".to_owned(), |lost| lost.to_string()),
                if lossless { "no loss" } else { "loss" }
            );
            Ok::<bool, BenchServiceError>(lossless)
        })?)
    } else {
        None
    };
    let summary = summary_text(args, &main, search.as_ref())?;
    let path = directory.join("summary.md");
    std::fs::write(&path, &summary)
        .map_err(|source| BenchServiceError::Summary { path: path.clone(), source })?;
    println!("\n{summary}");
    println!("wrote {}", path.display());
    Ok(())
}

/// Frames the tracker counted as lost, from its `frames: …` summary line.
fn tracker_lost(output: &str) -> Option<u64> {
    let line = output.lines().find(|line| line.starts_with("frames: "))?;
    let field = line.split([',', ';', ':']).find(|field| field.trim().ends_with("lost"))?;
    field.split_whitespace().next()?.parse().ok()
}

/// A markdown table of percentiles (µs) of the histograms in `rows`.
fn markdown_table(rows: &[(String, hdrhistogram::Histogram<u64>)]) -> String {
    let mut table = format!(
        "| latency | count | p50 {OUTPUT_UNIT} | p90 {OUTPUT_UNIT} | p99 {OUTPUT_UNIT} | p99.9 {OUTPUT_UNIT} | max {OUTPUT_UNIT} |\n|---|---|---|---|---|---|---|\n"
    );
    let us = |ns: u64| ns as f64 / 1000.0;
    for (name, histogram) in rows.iter().filter(|(_, histogram)| !histogram.is_empty()) {
        let row = summarise(name, histogram);
        let _ = writeln!(
            table,
            "| {name} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
            row.count,
            us(row.p50_ns),
            us(row.p90_ns),
            us(row.p99_ns),
            us(row.p999_ns),
            us(row.max_ns)
        );
    }
    table
}

/// The one-page summary (markdown).
fn summary_text(
    args: &Args,
    main: &TrialRun,
    search: Option<&RateSearch>,
) -> Result<String, BenchServiceError> {
    let directory = &args.latency_out;
    let mut text = String::from("# primm bench-service\n\n");
    let command: Vec<String> = std::env::args().collect();
    let _ = writeln!(text, "Command: `{}`\n", command.join(" "));
    let cores = std::thread::available_parallelism().map_or(0, |cores| cores.get());
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
    let _ = writeln!(
        text,
        "Host: {cores} logical CPUs, Linux {}. Tracker: `primm serve {}`. Load: {} objects on lanes, \
         every one measured in each frame, {} Hz for {} s, each frame stamped with its scheduled send time.\n",
        kernel.trim(),
        args.tracker.describe(),
        args.objects,
        args.rate_hz,
        args.duration_s
    );
    let trial = &main.trial;
    let _ = writeln!(
        text,
        "Frames: {} sent, {} answered, {} lost (client), {} lost (tracker), {} send failures, {} sent more than one \
         interval late, {} rejected.\n",
        trial.sent,
        trial.answered,
        trial.lost(),
        tracker_lost(&main.tracker_output).map_or("?".to_owned(), |lost| lost.to_string()),
        trial.send_failures,
        trial.late_sends,
        trial.rejected
    );
    // The tracker's percentiles, read back from the files it wrote.
    let mut tracker_rows = Vec::new();
    for stage in Stage::ALL {
        let path = directory.join(format!("{}.hlog", stage.name()));
        tracker_rows.push((stage.name().to_owned(), read_interval_log(&path)?));
    }
    let _ = writeln!(text, "## Tracker (from its `.hlog` files)\n\n{}", markdown_table(&tracker_rows));
    let client_rows: Vec<(String, hdrhistogram::Histogram<u64>)> = ClientLatency::ALL
        .iter()
        .map(|&latency| (latency.name().to_owned(), trial.latencies[latency as usize].clone()))
        .collect();
    let _ = writeln!(text, "## Client\n\n{}", markdown_table(&client_rows));
    let _ = writeln!(
        text,
        "Rows ending in `_corrected` are measured from each frame's scheduled send time instead of its actual \
         send: corrected for coordinated omission, so that a stall that delays sends shows in the tail.\n"
    );
    if let Some(search) = search {
        let show = |rate: Option<f64>| rate.map_or("none".to_owned(), |rate| format!("{rate:.0} Hz"));
        let _ = writeln!(
            text,
            "## Highest sustained rate\n\nWithout losing a frame ({} s trials, a fresh tracker each, {} trials): \
             **{}**; lowest rate with loss: {}.\n",
            args.trial_s,
            search.trials,
            show(search.highest_lossless_hz),
            show(search.lowest_lossy_hz)
        );
    }
    let _ = writeln!(
        text,
        "## Files\n\nPer latency `NAME.hlog` (HdrHistogram interval log, V2 compressed, {} s intervals) and \
         `NAME.hgrm` (percentile distribution); values written as text are in µs.\n\n\
         ![tracker stages by percentile](tracker.svg)\n\n![client latencies by percentile](client.svg)\n",
        args.latency_interval_s
    );
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_config::InferenceEngine;

    #[test]
    fn the_tracker_loss_count_is_read_from_its_summary_line() {
        let output =
            "frames: 2000 received, 1990 tracked, 0 rejected, 7 lost; resets: 4 (stream start 4)\nstage ...";
        assert_eq!(tracker_lost(output), Some(7));
        assert_eq!(tracker_lost("no summary"), None);
    }

    #[test]
    fn tracker_settings_become_serve_arguments() {
        let settings = TrackerSettings {
            method: Method::PrImm,
            tracker: TrackerArgs { engine: Some(InferenceEngine::Tract), ..TrackerArgs::default() },
            inference_threads: Some(2),
            busy_poll: true,
            no_speculation: true,
            realtime: TrackerRealtimeArgs::default(),
            view: FoxgloveArgs::default(),
        };
        let arguments: Vec<String> = settings
            .serve_arguments()
            .iter()
            .map(|argument| argument.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            arguments,
            [
                "--method",
                "pr-imm",
                "--engine",
                "tract",
                "--inference-threads",
                "2",
                "--busy-poll",
                "--no-speculation"
            ]
        );
    }

    #[test]
    fn real_time_settings_are_passed_on_to_the_tracker() {
        let settings = TrackerSettings {
            method: Method::Imm,
            tracker: TrackerArgs::default(),
            inference_threads: None,
            busy_poll: false,
            no_speculation: false,
            realtime: TrackerRealtimeArgs {
                thread: primm_service::realtime::RealtimeArgs {
                    cpu_affinity: Some("1".parse().unwrap()),
                    realtime_priority: Some(50),
                    lock_memory: true,
                    require_realtime: true,
                },
                inference_cpu_affinity: Some("0-1".parse().unwrap()),
            },
            view: FoxgloveArgs { foxglove: Some("127.0.0.1:8765".parse().unwrap()) },
        };
        let arguments: Vec<String> = settings
            .serve_arguments()
            .iter()
            .map(|argument| argument.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            arguments,
            [
                "--method",
                "imm",
                "--cpu-affinity",
                "1",
                "--inference-cpu-affinity",
                "0,1",
                "--realtime-priority",
                "50",
                "--lock-memory",
                "--require-realtime",
                "--foxglove",
                "127.0.0.1:8765"
            ]
        );
    }
}
