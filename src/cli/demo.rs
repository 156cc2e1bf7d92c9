//! `primm demo`: the tracker, a publisher and a subscriber as three processes talking over
//! iceoryx2, on the built-in scenario; prints tracking accuracy and latency percentiles.
//!
//! The publisher and subscriber are the `primm-publisher` and `primm-subscriber` binaries next
//! to this executable when the workspace was built (`cargo build --release --workspace`);
//! otherwise this executable runs the same code as `primm publish` / `primm subscribe`, so
//! `cargo run --release -- demo` works from a fresh checkout.

use super::latency_out::LatencyOutArgs;
use primm_core::mode::Method;
use primm_publisher::DEFAULT_SCENARIO_SEED;
use primm_record::live::FoxgloveArgs;
use primm_service::catalog;
use primm_service::{ConnectError, ServiceNames};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

#[cfg(feature = "tunnel")]
mod two_hosts;

/// Arguments of `primm demo`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    about = "Run tracker, publisher and subscriber over shared memory on a built-in scenario",
    after_help = "\
Examples:
  primm demo                                  # IMM, 20 s scenario: accuracy and latency per stage
  primm demo --method pr-imm                  # the full PR-IMM, PR on two inference threads
  primm demo --method pr-imm --latency-out lat/   # also .hlog/.hgrm per stage and SVG plots"
)]
pub struct Args {
    /// Seed of the generated scenario.
    #[arg(long, default_value_t = DEFAULT_SCENARIO_SEED)]
    pub seed: u64,
    /// Recorded duration of the scenario, s.
    #[arg(long, default_value_t = 20.0, value_name = "S")]
    pub duration_s: f64,
    /// Replay speed factor.
    #[arg(long, default_value_t = 2.0, value_name = "FACTOR")]
    pub speed: f64,
    /// Tracking method: cv, ca, ct, imm, pr, pr-imm (the last two run the PR model
    /// `models/pr.onnx` on the tracker's inference thread).
    #[arg(long, default_value = "imm")]
    pub method: Method,
    /// PR model (ONNX) for the methods pr and pr-imm, passed to `primm serve --model`; default:
    /// the model built into primm.
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Let the tracker and subscriber spin instead of sleeping.
    #[arg(long)]
    pub busy_poll: bool,
    /// Hosts to spread the processes over: 1 (everything over shared memory) or 2 (publisher
    /// and tracker on host A, subscriber on host B, each "host" its own iceoryx2 domain, joined
    /// by two `primm tunnel`s over zenoh on 127.0.0.1; needs the `tunnel` feature).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub hosts: u8,
    /// Latency files of the tracker and the subscriber (`--latency-out DIR`): `.hlog`, `.hgrm`
    /// per stage, `tracker.svg` and `subscriber.svg`.
    #[command(flatten)]
    pub latency_files: LatencyOutArgs,
    /// A live Foxglove view from the subscriber (`--foxglove [ADDRESS]`, default
    /// 127.0.0.1:8765; docs/recording.md).
    #[command(flatten)]
    pub view: FoxgloveArgs,
    /// Also record the three streams into this MCAP file (`primm record`).
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

/// Why the demo failed.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// This executable's path is unknown.
    #[error("cannot locate the primm executable: {0}")]
    Executable(std::io::Error),
    /// A process could not be started.
    #[error("cannot start {what}: {source}")]
    Spawn {
        /// Which process.
        what: &'static str,
        /// The OS error.
        source: std::io::Error,
    },
    /// The state of a started process could not be queried.
    #[error("cannot watch {what}: {source}")]
    Watch {
        /// Which process.
        what: &'static str,
        /// The OS error.
        source: std::io::Error,
    },
    /// The demo could not watch the services.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// A process did not come up or finish in time.
    #[error("{what} did not {event} within {seconds} s")]
    Timeout {
        /// Which process.
        what: &'static str,
        /// What it did not do.
        event: &'static str,
        /// The wait.
        seconds: u64,
    },
    /// A process exited with a failure, or (the tracker) before it was asked to stop.
    #[error("{what} exited ({status}){log}")]
    Exited {
        /// Which process.
        what: &'static str,
        /// Its exit status.
        status: ExitStatus,
        /// What it wrote to stderr and stdout, indented, if anything.
        log: String,
    },
    /// The subscriber never saw the end of the replay.
    #[error("the subscriber did not receive the answer to the last frame")]
    Incomplete,
    /// `--hosts 2` needs the tunnel, which this build leaves out.
    #[cfg_attr(feature = "tunnel", allow(dead_code))]
    #[error("--hosts 2 needs the tunnel, which this primm was built without; build it with `cargo build --release --features tunnel`")]
    TunnelNotBuilt,
    /// The listening tunnel named no TCP endpoint on 127.0.0.1 in its listening file.
    #[cfg_attr(not(feature = "tunnel"), allow(dead_code))]
    #[error("the tunnel of host A did not say where it listens ({0})")]
    ListeningEndpoint(String),
}

/// How long a child asked to stop (SIGINT) may take before it is killed.
const STOP_GRACE: Duration = Duration::from_secs(5);

/// A child process, its stderr in a file. Dropping it stops it (SIGINT, then SIGKILL after
/// [`STOP_GRACE`]) unless it has exited; with the demo killed outright, the kernel sends it
/// SIGTERM (Linux), so that it still shuts down cleanly.
struct Managed {
    what: &'static str,
    child: Child,
    stderr_path: PathBuf,
}

impl Managed {
    /// Starts `command` with its stderr written to `stderr_path`.
    fn spawn(what: &'static str, command: &mut Command, stderr_path: PathBuf) -> Result<Self, DemoError> {
        let stderr =
            std::fs::File::create(&stderr_path).map_err(|source| DemoError::Spawn { what, source })?;
        command.stderr(stderr);
        stop_with_parent(command);
        let child = command.spawn().map_err(|source| DemoError::Spawn { what, source })?;
        Ok(Self { what, child, stderr_path })
    }

    /// Its exit status, if it has exited.
    fn exited(&mut self) -> Result<Option<ExitStatus>, DemoError> {
        self.child.try_wait().map_err(|source| DemoError::Watch { what: self.what, source })
    }

    /// What it wrote to stdout (if captured; read once it has exited) and stderr.
    fn output(&mut self) -> (String, String) {
        let mut stdout = String::new();
        if let Some(mut pipe) = self.child.stdout.take() {
            use std::io::Read;
            let _ = pipe.read_to_string(&mut stdout);
        }
        let stderr = std::fs::read_to_string(&self.stderr_path).unwrap_or_default();
        (stdout, stderr)
    }

    /// The error for an exit with `status`, with everything the process printed.
    fn exited_error(&mut self, status: ExitStatus) -> DemoError {
        let (stdout, stderr) = self.output();
        let printed: Vec<&str> =
            stderr.lines().chain(stdout.lines()).filter(|line| !line.trim().is_empty()).collect();
        let log = if printed.is_empty() { String::new() } else { format!(":\n  {}", printed.join("\n  ")) };
        DemoError::Exited { what: self.what, status, log }
    }

    /// Waits up to `timeout` for exit.
    fn wait(&mut self, timeout: Duration) -> Result<Option<ExitStatus>, DemoError> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.exited()? {
                return Ok(Some(status));
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            std::thread::sleep(POLL_INTERVAL);
        }
    }

    fn interrupt(&self) {
        // SAFETY: sending a signal to our own child by its pid has no memory-safety concerns.
        unsafe {
            libc::kill(self.child.id() as libc::pid_t, libc::SIGINT);
        }
    }
}

impl Drop for Managed {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            self.interrupt();
            if !matches!(self.wait(STOP_GRACE), Ok(Some(_))) {
                let _ = self.child.kill();
                let _ = self.child.wait();
            }
        }
        let _ = std::fs::remove_file(&self.stderr_path);
    }
}

/// Asks the kernel to send `command`'s process SIGTERM when the demo dies (Linux), so that a
/// demo killed with SIGKILL leaves no orphans; they stop as on Ctrl-C and clean up.
fn stop_with_parent(command: &mut Command) {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::process::CommandExt;
        // SAFETY: the closure runs in the child between fork and exec and calls only prctl,
        // which is async-signal-safe.
        unsafe {
            command.pre_exec(|| {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) == -1 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = command;
}

/// How often the demo looks at its children.
const POLL_INTERVAL: Duration = Duration::from_millis(20);

/// A command running `binary` next to `exe` if it exists, else `exe subcommand`.
fn companion(exe: &Path, binary: &str, subcommand: &str) -> Command {
    let sibling = exe.with_file_name(format!("{binary}{}", std::env::consts::EXE_SUFFIX));
    if sibling.is_file() {
        Command::new(sibling)
    } else {
        let mut command = Command::new(exe);
        command.arg(subcommand);
        command
    }
}

/// Runs the demo.
pub fn run(args: Args) -> Result<(), DemoError> {
    if args.hosts == 2 {
        #[cfg(feature = "tunnel")]
        return two_hosts::run(args);
        #[cfg(not(feature = "tunnel"))]
        return Err(DemoError::TunnelNotBuilt);
    }
    let exe = std::env::current_exe().map_err(DemoError::Executable)?;
    let prefix = format!("primm-demo-{}", std::process::id());
    let names = ServiceNames::new(&prefix);
    let files = std::env::temp_dir();
    let summary_path: PathBuf = files.join(format!("{prefix}-summary.json"));

    println!(
        "primm demo: {:.0} s scenario (seed {}) replayed at {}x; tracker method {}; services under '{prefix}/'",
        args.duration_s, args.seed, args.speed, args.method
    );
    let mut tracker = spawn_tracker(&exe, &prefix, None, &args, files.join(format!("{prefix}-tracker.log")))?;
    let mut subscriber = spawn_subscriber(
        &exe,
        &prefix,
        None,
        &summary_path,
        &args,
        files.join(format!("{prefix}-subscriber.log")),
    )?;
    let mut recorder = match &args.record {
        Some(path) => {
            Some(spawn_recorder(&exe, &prefix, path, files.join(format!("{prefix}-recorder.log")))?)
        }
        None => None,
    };
    // Start the publisher once the tracker serves and the subscriber (and the recorder) listen,
    // so that no frame and no answer is missed.
    wait_until_connected(&names, &mut tracker, &mut subscriber)?;
    if let Some(recorder) = recorder.as_mut() {
        wait_for_recorder(&names, recorder)?;
    }
    let publisher =
        spawn_publisher(&exe, &prefix, None, &args, files.join(format!("{prefix}-publisher.log")))?;
    let replay_s = args.duration_s / args.speed.max(1e-3);
    let outputs = wait_for_the_end(publisher, subscriber, tracker, replay_s);
    let complete = stream_end_seen(&summary_path);
    let _ = std::fs::remove_file(&summary_path);
    let outputs = outputs?;

    if let Some(recorder) = recorder.as_mut() {
        println!("\n== recorder (primm record) ==\n{}", finish_recorder(recorder)?);
    }
    println!("\n== subscriber (primm-subscriber) ==\n{}", outputs.subscriber);
    println!("== tracker (primm serve) ==\n{}", outputs.tracker);
    if !outputs.logs.is_empty() {
        println!("== logs ==\n{}", outputs.logs);
    }
    if !complete {
        return Err(DemoError::Incomplete);
    }
    print_latency_files(&args);
    println!("demo finished: every frame tracked and answered over shared memory");
    Ok(())
}

/// Says where the latency files are, with `--latency-out`.
fn print_latency_files(args: &Args) {
    if let Some(directory) = args.latency_files.directory() {
        println!(
            "latency files in {}: per stage STAGE.hlog (HdrHistogram interval log) and STAGE.hgrm (percentile \
             distribution), values in µs; plots tracker.svg and subscriber.svg (latency by percentile); \
             compare runs with `primm latency-plot DIR1/end_to_end.hlog DIR2/end_to_end.hlog --output FILE.svg`",
            directory.display()
        );
    }
}

/// Passes `--latency-out DIR` on to a child.
fn pass_latency_files(command: &mut Command, args: &Args) {
    if let Some(directory) = args.latency_files.directory() {
        command
            .arg("--latency-out")
            .arg(directory)
            .args(["--latency-interval-s", &args.latency_files.latency_interval_s.to_string()]);
    }
}

/// Runs `command` in the iceoryx2 domain `domain` (see [`catalog::ICEORYX2_DOMAIN_ENV`]), or in
/// the demo's own when `None`.
fn in_domain(command: &mut Command, domain: Option<&str>) {
    if let Some(domain) = domain {
        command.env(catalog::ICEORYX2_DOMAIN_ENV, domain);
    }
}

/// Logs of the child processes: warnings only, unless `RUST_LOG` says otherwise.
fn quiet_logs(command: &mut Command) {
    command.env("RUST_LOG", std::env::var("RUST_LOG").unwrap_or_else(|_| "warn".to_owned()));
}

/// Starts `primm serve` under `prefix`, its output captured.
fn spawn_tracker(
    exe: &Path,
    prefix: &str,
    domain: Option<&str>,
    args: &Args,
    stderr_path: PathBuf,
) -> Result<Managed, DemoError> {
    let mut command = Command::new(exe);
    in_domain(&mut command, domain);
    command
        .args(["serve", "--service-prefix", prefix, "--method", args.method.id(), "--latency-every", "50"])
        .stdout(Stdio::piped());
    if let Some(model) = &args.model {
        command.arg("--model").arg(model);
    }
    if args.busy_poll {
        command.arg("--busy-poll");
    }
    pass_latency_files(&mut command, args);
    quiet_logs(&mut command);
    Managed::spawn("the tracker (primm serve)", &mut command, stderr_path)
}

/// Starts the subscriber under `prefix` until the end of the replay, its output captured and
/// its JSON summary written to `summary_path`.
fn spawn_subscriber(
    exe: &Path,
    prefix: &str,
    domain: Option<&str>,
    summary_path: &Path,
    args: &Args,
    stderr_path: PathBuf,
) -> Result<Managed, DemoError> {
    let mut command = companion(exe, "primm-subscriber", "subscribe");
    in_domain(&mut command, domain);
    command
        .args(["--service-prefix", prefix, "--until-end", "--quiet", "--idle-timeout-s", "60", "--json"])
        .arg(summary_path)
        .stdout(Stdio::piped());
    if args.busy_poll {
        command.arg("--busy-poll");
    }
    if let Some(address) = args.view.foxglove {
        command.arg("--foxglove").arg(address.to_string());
    }
    pass_latency_files(&mut command, args);
    quiet_logs(&mut command);
    Managed::spawn("the subscriber", &mut command, stderr_path)
}

/// Starts `primm record` under `prefix` until the end of the replay, into `path`.
fn spawn_recorder(exe: &Path, prefix: &str, path: &Path, stderr_path: PathBuf) -> Result<Managed, DemoError> {
    let mut command = Command::new(exe);
    command
        .args(["record", "--service-prefix", prefix, "--until-end", "--output"])
        .arg(path)
        .stdout(Stdio::piped());
    quiet_logs(&mut command);
    Managed::spawn("the recorder (primm record)", &mut command, stderr_path)
}

/// Waits up to [`READY_TIMEOUT`] until the recorder subscribes too (a second subscriber of the
/// tracks besides the subscriber).
fn wait_for_recorder(names: &ServiceNames, recorder: &mut Managed) -> Result<(), DemoError> {
    let node = catalog::create_node("primm-demo")?;
    let tracks = catalog::tracks(&node, names)?;
    let deadline = Instant::now() + READY_TIMEOUT;
    while tracks.subscriber_count() < 2 {
        if let Some(status) = recorder.exited()? {
            return Err(recorder.exited_error(status));
        }
        if Instant::now() >= deadline {
            return Err(DemoError::Timeout {
                what: recorder.what,
                event: "come up",
                seconds: READY_TIMEOUT.as_secs(),
            });
        }
        std::thread::sleep(POLL_INTERVAL);
    }
    Ok(())
}

/// Waits for the recorder to write the end of the replay and close its file; its summary.
fn finish_recorder(recorder: &mut Managed) -> Result<String, DemoError> {
    match recorder.wait(STOP_GRACE)? {
        Some(status) if status.success() => Ok(recorder.output().0),
        Some(status) => Err(recorder.exited_error(status)),
        None => {
            Err(DemoError::Timeout { what: recorder.what, event: "finish", seconds: STOP_GRACE.as_secs() })
        }
    }
}

/// Starts the publisher replaying the built-in scenario under `prefix`.
fn spawn_publisher(
    exe: &Path,
    prefix: &str,
    domain: Option<&str>,
    args: &Args,
    stderr_path: PathBuf,
) -> Result<Managed, DemoError> {
    let mut command = companion(exe, "primm-publisher", "publish");
    in_domain(&mut command, domain);
    command.args([
        "--service-prefix",
        prefix,
        "--scenario",
        "--seed",
        &args.seed.to_string(),
        "--duration-s",
        &args.duration_s.to_string(),
        "--speed",
        &args.speed.to_string(),
    ]);
    command.stdout(Stdio::null());
    quiet_logs(&mut command);
    Managed::spawn("the publisher", &mut command, stderr_path)
}

/// How long the tracker and the subscriber may take to come up.
const READY_TIMEOUT: Duration = Duration::from_secs(30);

/// Waits up to [`READY_TIMEOUT`] until the tracker publishes and the subscriber subscribes to
/// the tracks of `names`; fails at once, with its status and output, if either exits meanwhile.
fn wait_until_connected(
    names: &ServiceNames,
    tracker: &mut Managed,
    subscriber: &mut Managed,
) -> Result<(), DemoError> {
    let node = catalog::create_node("primm-demo")?;
    let tracks = catalog::tracks(&node, names)?;
    wait_for_ports(&tracks, &tracks, tracker, subscriber)
}

/// Waits up to [`READY_TIMEOUT`] until `tracker` publishes on `tracker_side` and `subscriber`
/// subscribes on `subscriber_side` (the same stream, seen from the domain each runs in).
fn wait_for_ports(
    tracker_side: &catalog::Stream<primm_wire::TrackFrame>,
    subscriber_side: &catalog::Stream<primm_wire::TrackFrame>,
    tracker: &mut Managed,
    subscriber: &mut Managed,
) -> Result<(), DemoError> {
    let ready_deadline = Instant::now() + READY_TIMEOUT;
    while tracker_side.publisher_count() == 0 || subscriber_side.subscriber_count() == 0 {
        for child in [&mut *tracker, &mut *subscriber] {
            if let Some(status) = child.exited()? {
                return Err(child.exited_error(status));
            }
        }
        if Instant::now() >= ready_deadline {
            let what = if tracker_side.publisher_count() == 0 { tracker.what } else { subscriber.what };
            return Err(DemoError::Timeout { what, event: "come up", seconds: READY_TIMEOUT.as_secs() });
        }
        std::thread::sleep(POLL_INTERVAL);
    }
    Ok(())
}

/// What the children printed in a successful demo.
struct Outputs {
    /// The subscriber's summary.
    subscriber: String,
    /// The tracker's counters and latency table.
    tracker: String,
    /// Their logs (stderr), labelled, if any.
    logs: String,
}

/// Watches the three children until the publisher has finished its replay and the subscriber
/// has seen its end (at most `replay_s` plus a minute), then stops the tracker. Fails at once
/// when a child fails, or when the tracker exits before it is asked to.
fn wait_for_the_end(
    mut publisher: Managed,
    mut subscriber: Managed,
    mut tracker: Managed,
    replay_s: f64,
) -> Result<Outputs, DemoError> {
    let limit = Duration::from_secs_f64(replay_s + 60.0);
    let deadline = Instant::now() + limit;
    let (mut publisher_done, mut subscriber_done) = (false, false);
    while !(publisher_done && subscriber_done) {
        if let Some(status) = tracker.exited()? {
            return Err(tracker.exited_error(status));
        }
        for (child, done) in [(&mut publisher, &mut publisher_done), (&mut subscriber, &mut subscriber_done)]
        {
            if *done {
                continue;
            }
            if let Some(status) = child.exited()? {
                if !status.success() {
                    return Err(child.exited_error(status));
                }
                *done = true;
            }
        }
        if Instant::now() >= deadline {
            let what = if publisher_done { subscriber.what } else { publisher.what };
            return Err(DemoError::Timeout { what, event: "finish", seconds: limit.as_secs() });
        }
        std::thread::sleep(POLL_INTERVAL);
    }
    tracker.interrupt();
    match tracker.wait(STOP_GRACE)? {
        Some(status) if status.success() => {}
        Some(status) => return Err(tracker.exited_error(status)),
        None => {
            return Err(DemoError::Timeout {
                what: tracker.what,
                event: "stop",
                seconds: STOP_GRACE.as_secs(),
            })
        }
    }
    let (subscriber_output, subscriber_log) = subscriber.output();
    let (tracker_output, tracker_log) = tracker.output();
    let (_, publisher_log) = publisher.output();
    let logs =
        [(tracker.what, tracker_log), (publisher.what, publisher_log), (subscriber.what, subscriber_log)]
            .iter()
            .filter(|(_, log)| !log.trim().is_empty())
            .map(|(what, log)| format!("{what}:\n{}", log.trim_end()))
            .collect::<Vec<_>>()
            .join("\n");
    Ok(Outputs { subscriber: subscriber_output, tracker: tracker_output, logs })
}

/// Whether the subscriber's JSON summary at `path` says it saw the end of the stream.
fn stream_end_seen(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|json| json.get("stream_end_seen").and_then(serde_json::Value::as_bool))
        .unwrap_or(false)
}
