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

/// Writes an owned frame into a loaned sample's payload.
pub fn write_frame(
    slot: &mut std::mem::MaybeUninit<MeasurementFrame>,
    frame: &Frame,
    sequence: u64,
    flags: u32,
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
        let node = catalog::create_node("primm-test").unwrap();
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
        let mut loan = self.publisher.loan_uninit().unwrap();
        write_frame(loan.payload_mut(), frame, sequence, flags);
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
    let child = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["serve", "--service-prefix", prefix])
        .args(if extra.contains(&"--latency-every") { &[][..] } else { &["--latency-every", "20"][..] })
        .args(extra)
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .spawn()
        .expect("primm serve starts");
    ChildGuard(child)
}
