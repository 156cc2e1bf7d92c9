//! `primm demo`: the tracker, a publisher and a subscriber as three processes talking over
//! iceoryx2, on the built-in scenario; prints tracking accuracy and latency percentiles.
//!
//! The publisher and subscriber are the `primm-publisher` and `primm-subscriber` binaries next
//! to this executable when the workspace was built (`cargo build --release --workspace`);
//! otherwise this executable runs the same code as `primm publish` / `primm subscribe`, so
//! `cargo run --release -- demo` works from a fresh checkout.

use primm_core::mode::Method;
use primm_publisher::DEFAULT_SCENARIO_SEED;
use primm_service::catalog;
use primm_service::{ConnectError, ServiceNames};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Arguments of `primm demo`.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Run tracker, publisher and subscriber over shared memory on a built-in scenario")]
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
    /// Let the tracker and subscriber spin instead of sleeping.
    #[arg(long)]
    pub busy_poll: bool,
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
    /// A process failed.
    #[error("{what} failed ({status}){output}")]
    Failed {
        /// Which process.
        what: &'static str,
        /// Its exit status.
        status: ExitStatus,
        /// What it printed, if captured.
        output: String,
    },
    /// The subscriber never saw the end of the replay.
    #[error("the subscriber did not receive the answer to the last frame")]
    Incomplete,
}

/// A child process killed when dropped, unless it was waited for.
struct Managed {
    what: &'static str,
    child: Child,
}

impl Managed {
    fn spawn(what: &'static str, command: &mut Command) -> Result<Self, DemoError> {
        let child = command.spawn().map_err(|source| DemoError::Spawn { what, source })?;
        Ok(Self { what, child })
    }

    fn is_running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }

    /// Waits for exit; captured stdout is returned.
    fn wait(mut self, timeout: Duration) -> Result<(ExitStatus, String), DemoError> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) =
                self.child.try_wait().map_err(|source| DemoError::Spawn { what: self.what, source })?
            {
                let mut output = String::new();
                if let Some(mut stdout) = self.child.stdout.take() {
                    use std::io::Read;
                    let _ = stdout.read_to_string(&mut output);
                }
                return Ok((status, output));
            }
            if Instant::now() >= deadline {
                return Err(DemoError::Timeout {
                    what: self.what,
                    event: "finish",
                    seconds: timeout.as_secs(),
                });
            }
            std::thread::sleep(Duration::from_millis(20));
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
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

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
    let exe = std::env::current_exe().map_err(DemoError::Executable)?;
    let prefix = format!("primm-demo-{}", std::process::id());
    let names = ServiceNames::new(&prefix);
    let summary_path: PathBuf = std::env::temp_dir().join(format!("{prefix}-summary.json"));

    println!(
        "primm demo: {:.0} s scenario (seed {}) replayed at {}x; tracker method {}; services under '{prefix}/'",
        args.duration_s, args.seed, args.speed, args.method
    );
    let mut tracker = spawn_tracker(&exe, &prefix, &args)?;
    let mut subscriber = spawn_subscriber(&exe, &prefix, &summary_path, &args)?;
    // Start the publisher once the tracker serves and the subscriber listens, so that no frame
    // and no answer is missed.
    wait_until_connected(&names, &mut tracker, &mut subscriber)?;
    let publisher = spawn_publisher(&exe, &prefix, &args)?;
    let replay_s = args.duration_s / args.speed.max(1e-3);
    let (subscriber_output, tracker_output) = wait_for_the_end(publisher, subscriber, tracker, replay_s)?;

    println!("\n== subscriber (primm-subscriber) ==\n{subscriber_output}");
    println!("== tracker (primm serve) ==\n{tracker_output}");
    let complete = stream_end_seen(&summary_path);
    let _ = std::fs::remove_file(&summary_path);
    if !complete {
        return Err(DemoError::Incomplete);
    }
    println!("demo finished: every frame tracked and answered over shared memory");
    Ok(())
}

/// Logs of the child processes: warnings only, unless `RUST_LOG` says otherwise.
fn quiet_logs(command: &mut Command) {
    command.env("RUST_LOG", std::env::var("RUST_LOG").unwrap_or_else(|_| "warn".to_owned()));
}

/// Starts `primm serve` under `prefix`, its output captured.
fn spawn_tracker(exe: &Path, prefix: &str, args: &Args) -> Result<Managed, DemoError> {
    let mut command = Command::new(exe);
    command
        .args(["serve", "--service-prefix", prefix, "--method", args.method.id(), "--latency-every", "50"])
        .stdout(Stdio::piped());
    if args.busy_poll {
        command.arg("--busy-poll");
    }
    quiet_logs(&mut command);
    Managed::spawn("the tracker (primm serve)", &mut command)
}

/// Starts the subscriber under `prefix` until the end of the replay, its output captured and
/// its JSON summary written to `summary_path`.
fn spawn_subscriber(
    exe: &Path,
    prefix: &str,
    summary_path: &Path,
    args: &Args,
) -> Result<Managed, DemoError> {
    let mut command = companion(exe, "primm-subscriber", "subscribe");
    command
        .args(["--service-prefix", prefix, "--until-end", "--quiet", "--idle-timeout-s", "60", "--json"])
        .arg(summary_path)
        .stdout(Stdio::piped());
    if args.busy_poll {
        command.arg("--busy-poll");
    }
    quiet_logs(&mut command);
    Managed::spawn("the subscriber", &mut command)
}

/// Starts the publisher replaying the built-in scenario under `prefix`.
fn spawn_publisher(exe: &Path, prefix: &str, args: &Args) -> Result<Managed, DemoError> {
    let mut command = companion(exe, "primm-publisher", "publish");
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
    quiet_logs(&mut command);
    Managed::spawn("the publisher", &mut command)
}

/// Waits up to 30 s until the tracker publishes and the subscriber subscribes to the tracks of
/// `names`.
fn wait_until_connected(
    names: &ServiceNames,
    tracker: &mut Managed,
    subscriber: &mut Managed,
) -> Result<(), DemoError> {
    let node = catalog::create_node("primm-demo")?;
    let tracks = catalog::tracks(&node, names)?;
    let ready_deadline = Instant::now() + Duration::from_secs(30);
    while tracks.publisher_count() == 0 || tracks.subscriber_count() == 0 {
        if !tracker.is_running() || !subscriber.is_running() || Instant::now() >= ready_deadline {
            let what = if !tracker.is_running() { tracker.what } else { subscriber.what };
            return Err(DemoError::Timeout { what, event: "come up", seconds: 30 });
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Ok(())
}

/// Waits for the publisher to finish its replay (`replay_s` plus a minute), the subscriber to see
/// its end, and the tracker to stop when interrupted. Returns the subscriber's and the tracker's
/// output.
fn wait_for_the_end(
    publisher: Managed,
    subscriber: Managed,
    tracker: Managed,
    replay_s: f64,
) -> Result<(String, String), DemoError> {
    let (status, _) = publisher.wait(Duration::from_secs_f64(replay_s + 60.0))?;
    if !status.success() {
        return Err(DemoError::Failed { what: "the publisher", status, output: String::new() });
    }
    let (status, subscriber_output) = subscriber.wait(Duration::from_secs(60))?;
    if !status.success() {
        return Err(DemoError::Failed {
            what: "the subscriber",
            status,
            output: format!(":\n{subscriber_output}"),
        });
    }
    tracker.interrupt();
    let (status, tracker_output) = tracker.wait(Duration::from_secs(10))?;
    if !status.success() {
        return Err(DemoError::Failed {
            what: "the tracker",
            status,
            output: format!(":\n{tracker_output}"),
        });
    }
    Ok((subscriber_output, tracker_output))
}

/// Whether the subscriber's JSON summary at `path` says it saw the end of the stream.
fn stream_end_seen(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|json| json.get("stream_end_seen").and_then(serde_json::Value::as_bool))
        .unwrap_or(false)
}
