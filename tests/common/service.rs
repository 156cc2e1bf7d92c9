//! Helpers for the service tests: unique service prefixes, frames on the wire, an in-process
//! publisher with its answer subscriber, and child processes that die with the test.
#![allow(dead_code)]

use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use primm_core::measurement::Frame;
use primm_service::catalog::{self, Ipc, ServiceNames};
use primm_service::clock::monotonic_ns;
use primm_wire::{
    MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, TrackFrame, WireMeasurement,
};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A service prefix no other test or run uses.
pub fn unique_prefix(test: &str) -> String {
    format!("primm-test-{test}-{}-{}", std::process::id(), monotonic_ns())
}

/// Writes an owned frame into a loaned sample's payload (sent without a schedule).
pub fn write_frame(
    slot: &mut std::mem::MaybeUninit<MeasurementFrame>,
    frame: &Frame,
    sequence: u64,
    flags: u32,
) {
    write_scheduled_frame(slot, frame, sequence, flags, 0);
}

/// Writes an owned frame into a loaned sample's payload, stamped with the time it was due to
/// be sent (`CLOCK_MONOTONIC` ns; 0: no schedule).
pub fn write_scheduled_frame(
    slot: &mut std::mem::MaybeUninit<MeasurementFrame>,
    frame: &Frame,
    sequence: u64,
    flags: u32,
    scheduled_time_ns: u64,
) {
    let mut writer = MeasurementFrameWriter::new(slot);
    for measurement in &frame.measurements {
        writer.push(WireMeasurement::new(measurement, None)).unwrap();
    }
    writer.finish(&MeasurementFrameHeader {
        sequence,
        source_frame: sequence,
        sensor_timestamp_s: frame.timestamp_s,
        publish_time_ns: monotonic_ns(),
        scheduled_time_ns,
        flags,
        ego: None,
    });
}

/// A boxed wire frame holding `frame`.
pub fn wire_frame(frame: &Frame, sequence: u64) -> Box<MeasurementFrame> {
    let mut boxed = MeasurementFrame::boxed_zeroed();
    // SAFETY: a `Box<MeasurementFrame>` is a valid `MaybeUninit<MeasurementFrame>` location.
    let slot =
        unsafe { &mut *(std::ptr::addr_of_mut!(*boxed).cast::<std::mem::MaybeUninit<MeasurementFrame>>()) };
    write_frame(slot, frame, sequence, 0);
    boxed
}

/// A test's end of the service: sends measurement frames, receives track frames.
pub struct TestClient {
    pub publisher: Publisher<Ipc, MeasurementFrame, ()>,
    pub notifier: Notifier<Ipc>,
    pub answers: Subscriber<Ipc, TrackFrame, ()>,
    pub listener: Listener<Ipc>,
    pub tracks: catalog::Stream<TrackFrame>,
    pub node: Node<Ipc>,
}

impl TestClient {
    pub fn new(names: &ServiceNames) -> Self {
        Self::with_node(names, catalog::create_node("primm-test").unwrap())
    }

    /// A client in the iceoryx2 domain `domain`, whatever `PRIMM_ICEORYX2_DOMAIN` says.
    pub fn in_domain(names: &ServiceNames, domain: &str) -> Self {
        let config = catalog::iceoryx2_config_in(Some(domain)).unwrap();
        Self::with_node(names, catalog::create_node_with("primm-test", &config).unwrap())
    }

    fn with_node(names: &ServiceNames, node: Node<Ipc>) -> Self {
        let measurements = catalog::measurements(&node, names).unwrap();
        let tracks = catalog::tracks(&node, names).unwrap();
        Self {
            publisher: measurements.publisher().unwrap(),
            notifier: measurements.notifier().unwrap(),
            answers: tracks.subscriber().unwrap(),
            listener: tracks.listener().unwrap(),
            tracks,
            node,
        }
    }

    /// Waits until a tracker publishes tracks.
    pub fn wait_for_tracker(&self, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        while self.tracks.publisher_count() == 0 {
            assert!(Instant::now() < deadline, "no tracker came up within {timeout:?}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Sends `frame` with `sequence` and `flags`.
    pub fn send(&self, frame: &Frame, sequence: u64, flags: u32) {
        self.send_scheduled(frame, sequence, flags, 0);
    }

    /// Sends a frame that was due at `scheduled_time_ns` (`CLOCK_MONOTONIC`; 0: no schedule).
    pub fn send_scheduled(&self, frame: &Frame, sequence: u64, flags: u32, scheduled_time_ns: u64) {
        let mut loan = self.publisher.loan_uninit().unwrap();
        write_scheduled_frame(loan.payload_mut(), frame, sequence, flags, scheduled_time_ns);
        // SAFETY: header and measurements written; the rest is plain data in shared memory.
        let sample = unsafe { loan.assume_init() };
        sample.send().unwrap();
        self.notifier.notify().unwrap();
    }

    /// Sends a frame filled by `fill` (for malformed frames).
    pub fn send_raw(&self, fill: impl FnOnce(&mut MeasurementFrame)) {
        let mut loan = self.publisher.loan_uninit().unwrap();
        // SAFETY: the payload is zeroed before a reference to it is formed; every field is
        // plain data, valid as zero.
        let frame = unsafe {
            loan.payload_mut().as_mut_ptr().write_bytes(0, 1);
            loan.payload_mut().assume_init_mut()
        };
        fill(frame);
        let sample = unsafe { loan.assume_init() };
        sample.send().unwrap();
        self.notifier.notify().unwrap();
    }

    /// [`next_answer`](Self::next_answer) spinning on the subscriber instead of sleeping on
    /// the event service (for busy-poll latency measurements).
    pub fn next_answer_spinning<R>(
        &self,
        timeout: Duration,
        read: impl FnOnce(&TrackFrame) -> R,
    ) -> Option<R> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(sample) = self.answers.receive().unwrap() {
                return Some(read(&sample));
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::hint::spin_loop();
        }
    }

    /// The next track frame, waiting up to `timeout`; calls `read` on it.
    pub fn next_answer<R>(&self, timeout: Duration, read: impl FnOnce(&TrackFrame) -> R) -> Option<R> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(sample) = self.answers.receive().unwrap() {
                return Some(read(&sample));
            }
            let now = Instant::now();
            if now >= deadline {
                return None;
            }
            let _ = self.listener.timed_wait(|_| {}, (deadline - now).min(Duration::from_millis(20)));
        }
    }
}

/// A child process killed (SIGKILL) when dropped.
pub struct ChildGuard(pub Child);

impl ChildGuard {
    /// The lines the child prints on its (piped) stdout, read on a thread of their own.
    pub fn stdout_lines(&mut self) -> std::sync::mpsc::Receiver<String> {
        use std::io::BufRead;
        let stdout = self.0.stdout.take().expect("the child's stdout is piped");
        let (line_tx, line_rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(stdout).lines() {
                if line_tx.send(line.unwrap()).is_err() {
                    break;
                }
            }
        });
        line_rx
    }

    pub fn pid(&self) -> i32 {
        self.0.id() as i32
    }

    pub fn signal(&self, signal: i32) {
        unsafe {
            libc::kill(self.pid(), signal);
        }
    }

    /// Waits up to `timeout` for exit; returns status and captured stdout.
    pub fn wait(mut self, timeout: Duration) -> (std::process::ExitStatus, String) {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.0.try_wait().unwrap() {
                let mut output = String::new();
                if let Some(mut stdout) = self.0.stdout.take() {
                    use std::io::Read;
                    stdout.read_to_string(&mut output).unwrap();
                }
                return (status, output);
            }
            assert!(Instant::now() < deadline, "process did not exit within {timeout:?}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    pub fn is_running(&mut self) -> bool {
        matches!(self.0.try_wait(), Ok(None))
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if matches!(self.0.try_wait(), Ok(None)) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
}

/// `primm serve` under `prefix`, stdout captured.
pub fn spawn_serve(prefix: &str, extra: &[&str]) -> ChildGuard {
    spawn_serve_with(Command::new(env!("CARGO_BIN_EXE_primm")), prefix, extra)
}

/// `primm serve` as [`spawn_serve`] starts it, from `command` (e.g. with a domain in its
/// environment).
fn spawn_serve_with(mut command: Command, prefix: &str, extra: &[&str]) -> ChildGuard {
    let child = command
        .args(["serve", "--service-prefix", prefix])
        .args(if extra.contains(&"--latency-every") { &[][..] } else { &["--latency-every", "20"][..] })
        .args(extra)
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .spawn()
        .expect("primm serve starts");
    ChildGuard(child)
}

/// A private iceoryx2 domain for the processes of one test (`PRIMM_ICEORYX2_DOMAIN`): every file
/// iceoryx2 creates for them, in `/dev/shm` and under its directory in `/tmp`, starts with its
/// name, so a test can count exactly its own resources while other tests run. Dropping it
/// removes whatever the domain still holds (declare it before the test's `ChildGuard`s so that
/// the processes are gone first).
pub struct Iceoryx2Domain {
    name: String,
}

/// Where iceoryx2 keeps the shared-memory segments and its own files.
const ICEORYX2_LOCATIONS: [&str; 2] = ["/dev/shm", "/tmp/iceoryx2"];

impl Iceoryx2Domain {
    pub fn new(test: &str) -> Self {
        let stamp = monotonic_ns() % 1_000_000_000_000;
        Self { name: format!("primm_{test}_{}_{stamp}_", std::process::id()) }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// Every file of the domain, except its node counter (`…_node.<version>.global_mgmt`), which
    /// iceoryx2 creates once per domain and never removes.
    pub fn resources(&self) -> Vec<std::path::PathBuf> {
        self.all_files()
            .into_iter()
            .filter(|path| !path.to_string_lossy().ends_with(".global_mgmt"))
            .collect()
    }

    /// The domain's node counter files (at most one per iceoryx2 version).
    pub fn node_counters(&self) -> usize {
        self.all_files().len() - self.resources().len()
    }

    fn all_files(&self) -> Vec<std::path::PathBuf> {
        let mut found = Vec::new();
        let mut pending: Vec<std::path::PathBuf> = ICEORYX2_LOCATIONS.iter().map(Into::into).collect();
        while let Some(directory) = pending.pop() {
            let Ok(entries) = std::fs::read_dir(&directory) else { continue };
            for entry in entries.flatten() {
                let path = entry.path();
                if entry.file_type().is_ok_and(|kind| kind.is_dir()) {
                    pending.push(path);
                } else if entry.file_name().to_string_lossy().starts_with(&self.name) {
                    found.push(path);
                }
            }
        }
        found.sort();
        found
    }

    /// Processes running in this domain (by their environment), other than this one.
    pub fn processes(&self) -> usize {
        let marker = format!("PRIMM_ICEORYX2_DOMAIN={}", self.name);
        let Ok(entries) = std::fs::read_dir("/proc") else { return 0 };
        entries
            .flatten()
            .filter(|entry| entry.file_name().to_string_lossy().chars().all(|c| c.is_ascii_digit()))
            .filter_map(|entry| std::fs::read(entry.path().join("environ")).ok())
            .filter(|environment| {
                environment.split(|&byte| byte == 0).any(|variable| variable == marker.as_bytes())
            })
            .count()
    }

    /// A `primm` command in this domain, its logs at `log_level`.
    pub fn primm(&self, log_level: &str) -> Command {
        let mut command = Command::new(env!("CARGO_BIN_EXE_primm"));
        command.env("PRIMM_ICEORYX2_DOMAIN", &self.name).env("RUST_LOG", log_level);
        command
    }
}

impl Drop for Iceoryx2Domain {
    fn drop(&mut self) {
        self.remove_files();
    }
}

impl Iceoryx2Domain {
    /// Removes every file of the domain.
    pub fn remove_files(&self) {
        for path in self.all_files() {
            let _ = std::fs::remove_file(&path);
            // Node directories are named by the node's id and hold only its tag files.
            if let Some(parent) = path.parent() {
                if parent.parent().is_some_and(|p| p.ends_with("nodes")) {
                    let _ = std::fs::remove_dir(parent);
                }
            }
        }
    }
}

/// A test's client and its processes in a private iceoryx2 domain, for tests that kill
/// processes. A process killed while it creates a shared-memory resource leaves it half made,
/// and iceoryx2 0.10's clean-up of dead nodes (every node's drop runs it) waits on such a
/// resource without limit: in a domain of its own, that can stall no other test. Declare it
/// before the test's [`ChildGuard`]s: when it is dropped, the processes are gone, and it removes
/// the domain's files before its client's node, so that the node's clean-up finds nothing to
/// wait on.
pub struct PrivateService {
    pub domain: Iceoryx2Domain,
    client: std::mem::ManuallyDrop<TestClient>,
}

impl PrivateService {
    pub fn new(test: &str, names: &ServiceNames) -> Self {
        let domain = Iceoryx2Domain::new(test);
        let client = std::mem::ManuallyDrop::new(TestClient::in_domain(names, domain.name()));
        Self { domain, client }
    }

    pub fn client(&self) -> &TestClient {
        &self.client
    }

    /// `primm serve` in the domain, as [`spawn_serve`] starts it.
    pub fn serve(&self, prefix: &str, extra: &[&str]) -> ChildGuard {
        let mut command = Command::new(env!("CARGO_BIN_EXE_primm"));
        command.env("PRIMM_ICEORYX2_DOMAIN", self.domain.name());
        spawn_serve_with(command, prefix, extra)
    }
}

impl Drop for PrivateService {
    fn drop(&mut self) {
        self.domain.remove_files();
        // SAFETY: the client is dropped here only, once.
        unsafe { std::mem::ManuallyDrop::drop(&mut self.client) };
    }
}

/// Waits until `condition` holds, polling; panics with `what` after `timeout` (a guard against a
/// hang, not a timing assertion).
pub fn wait_until(what: &str, timeout: Duration, mut condition: impl FnMut() -> bool) {
    let deadline = Instant::now() + timeout;
    while !condition() {
        assert!(Instant::now() < deadline, "{what} (waited {timeout:?})");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The lines a child writes to a pipe (stdout or stderr), collected by a thread so that the
/// child never blocks on a full pipe.
pub struct LineCollector {
    lines: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

impl LineCollector {
    pub fn new(pipe: impl std::io::Read + Send + 'static) -> Self {
        use std::io::BufRead;
        let lines = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = lines.clone();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(pipe).lines() {
                let Ok(line) = line else { break };
                sink.lock().unwrap().push(line);
            }
        });
        Self { lines }
    }

    /// Everything collected so far.
    pub fn text(&self) -> String {
        self.lines.lock().unwrap().join("\n")
    }

    /// Waits until a line contains `needle` (panics after `timeout`, a guard against a hang).
    pub fn wait_for(&self, needle: &str, timeout: Duration) {
        wait_until(&format!("no line contains '{needle}' in:\n{}", self.text()), timeout, || {
            self.lines.lock().unwrap().iter().any(|line| line.contains(needle))
        });
    }
}

/// `command` started with its stderr collected.
pub fn spawn_collecting_stderr(command: &mut Command) -> (ChildGuard, LineCollector) {
    let mut child = command.stderr(Stdio::piped()).spawn().expect("the process starts");
    let stderr = LineCollector::new(child.stderr.take().unwrap());
    (ChildGuard(child), stderr)
}
