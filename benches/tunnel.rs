//! The tunnel leg against the local shared-memory path: latency and highest sustained frame
//! rate of measurement frames (`primm/measurements`) and track frames (`primm/tracks`) at a
//! given number of objects (the `tunnel` feature).
//!
//! * `local`: publisher and subscriber in one iceoryx2 domain, shared memory only.
//! * `tunnel`: publisher on host A, subscriber on host B, two iceoryx2 domains on this machine,
//!   each with a `primm tunnel` process, joined over zenoh on 127.0.0.1 (multicast scouting off).
//!
//! A trial sends frames of the lane scene (`benches/service_latency.rs`) at a fixed wall-clock
//! rate and takes them on the far side as they come; latency is the far side's receive time
//! minus the publisher's send time (one clock: both "hosts" are this machine). The latency trial
//! runs at the radar's 20 Hz; the rate search doubles from `--start-hz` until a trial loses
//! frames, then bisects `--steps` times. Prints one line per trial and a summary table; writes
//! nothing and asserts nothing.
//!
//! A track frame is written as the tracker would leave it for `--objects` tracks (header and
//! count; the slots' contents do not change what crosses: every sample crosses whole, 94 272
//! bytes, as a measurement frame crosses as 16 456 bytes whatever its count).
//!
//! `cargo bench --features tunnel --bench tunnel [-- --objects 64] [--seconds 5] [--latency-seconds 20] [--start-hz 100] [--steps 4] [--paths local,tunnel] [--streams measurements,tracks]`

#[path = "../tests/common/mod.rs"]
mod common;

use common::service::{unique_prefix, write_frame, Iceoryx2Domain};
use common::tunnel::TwoHosts;
use hdrhistogram::Histogram;
use iceoryx2::node::Node;
use primm_core::measurement::Frame;
use primm_service::catalog::{self, Ipc, ServiceNames};
use primm_service::clock::monotonic_ns;
use primm_wire::{MeasurementFrame, TrackFrame};
use std::mem::MaybeUninit;
use std::time::{Duration, Instant};

/// A stream the benchmark sends on.
trait Payload: std::fmt::Debug + iceoryx2::prelude::ZeroCopySend + Sized + 'static {
    /// The stream's service name.
    const STREAM: &'static str;
    fn open(node: &Node<Ipc>, names: &ServiceNames) -> catalog::Stream<Self>;
    /// Writes frame `sequence` of the scene, stamped with the current time.
    fn write(slot: &mut MaybeUninit<Self>, scene: &[Frame], sequence: u64, objects: usize);
    fn publish_time_ns(&self) -> u64;
}

impl Payload for MeasurementFrame {
    const STREAM: &'static str = "measurements";
    fn open(node: &Node<Ipc>, names: &ServiceNames) -> catalog::Stream<Self> {
        catalog::measurements(node, names).unwrap()
    }
    fn write(slot: &mut MaybeUninit<Self>, scene: &[Frame], sequence: u64, _objects: usize) {
        write_frame(slot, &scene[sequence as usize % scene.len()], sequence, 0);
    }
    fn publish_time_ns(&self) -> u64 {
        self.publish_time_ns
    }
}

impl Payload for TrackFrame {
    const STREAM: &'static str = "tracks";
    fn open(node: &Node<Ipc>, names: &ServiceNames) -> catalog::Stream<Self> {
        catalog::tracks(node, names).unwrap()
    }
    fn write(slot: &mut MaybeUninit<Self>, _scene: &[Frame], sequence: u64, objects: usize) {
        // SAFETY: every field is plain data, valid as zero; the header is then set.
        let frame = unsafe {
            slot.as_mut_ptr().write_bytes(0, 1);
            slot.assume_init_mut()
        };
        frame.input_sequence = sequence;
        frame.count = objects as u32;
        frame.wire_version = primm_wire::WIRE_VERSION;
        frame.publish_time_ns = monotonic_ns();
    }
    fn publish_time_ns(&self) -> u64 {
        self.publish_time_ns
    }
}

/// Where the frames travel.
enum Path {
    Local { domain: Iceoryx2Domain, prefix: String },
    Tunnel(TwoHosts),
}

impl Path {
    fn open(name: &str) -> Self {
        match name {
            "local" => Self::Local {
                domain: Iceoryx2Domain::new("bench_local"),
                prefix: unique_prefix("bench-local"),
            },
            "tunnel" => Self::Tunnel(TwoHosts::start("bench_tunnel")),
            other => panic!("unknown path '{other}' (local, tunnel)"),
        }
    }

    /// The sending and the receiving node.
    fn nodes(&self) -> (Node<Ipc>, Node<Ipc>, ServiceNames) {
        match self {
            Self::Local { domain, prefix } => {
                let config = catalog::iceoryx2_config_in(Some(domain.name())).unwrap();
                let node = |name| catalog::create_node_with(name, &config).unwrap();
                (node("sender"), node("receiver"), ServiceNames::new(prefix))
            }
            Self::Tunnel(hosts) => (hosts.node_a("sender"), hosts.node_b("receiver"), hosts.names()),
        }
    }

    fn close(self) -> Option<(String, String)> {
        match self {
            Self::Local { .. } => None,
            Self::Tunnel(hosts) => Some(hosts.stop()),
        }
    }
}

/// What one trial saw.
struct Trial {
    rate_hz: f64,
    sent: u64,
    received: u64,
    latency_ns: Histogram<u64>,
}

/// Sends `seconds` of frames of type `P` at `rate_hz` from the path's sender to its receiver,
/// after probing until a frame crosses.
fn trial<P: Payload>(path: &Path, scene: &[Frame], objects: usize, rate_hz: f64, seconds: f64) -> Trial {
    let (sender, receiver, names) = path.nodes();
    let stream_a = P::open(&sender, &names);
    let (publisher, notifier) = (stream_a.publisher().unwrap(), stream_a.notifier().unwrap());
    let stream_b = P::open(&receiver, &names);
    let subscriber = stream_b.subscriber().unwrap();
    let send = |sequence: u64| {
        let mut loan = publisher.loan_uninit().unwrap();
        P::write(loan.payload_mut(), scene, sequence, objects);
        // SAFETY: `P::write` wrote every field the receiver reads; the rest is plain data.
        unsafe { loan.assume_init() }.send().unwrap();
        notifier.notify().unwrap();
    };
    // Probe with frame 0 until one crosses (the far side's subscription has reached the
    // sender); the trial's frames are numbered from 1.
    let deadline = Instant::now() + Duration::from_secs(60);
    'probe: loop {
        assert!(Instant::now() < deadline, "no frame crossed within 60 s");
        send(0);
        let until = Instant::now() + Duration::from_millis(50);
        while Instant::now() < until {
            if subscriber.receive().unwrap().is_some() {
                break 'probe;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    }
    std::thread::sleep(Duration::from_millis(100));
    while subscriber.receive().unwrap().is_some() {}

    let mut latency_ns = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
    let mut received = 0;
    let mut take = |latency_ns: &mut Histogram<u64>| {
        while let Some(sample) = subscriber.receive().unwrap() {
            latency_ns.saturating_record(monotonic_ns().saturating_sub(sample.publish_time_ns()).max(1));
            received += 1;
        }
    };
    let frames = (rate_hz * seconds).ceil() as u64;
    let interval = Duration::from_secs_f64(1.0 / rate_hz);
    let start = Instant::now();
    for k in 0..frames {
        let due = start + interval.mul_f64(k as f64);
        loop {
            take(&mut latency_ns);
            let now = Instant::now();
            if now >= due {
                break;
            }
            // Short sleeps: the receive time is read when this loop comes round.
            std::thread::sleep((due - now).min(Duration::from_micros(50)));
        }
        send(k + 1);
    }
    let drain_until = Instant::now() + Duration::from_secs(2);
    while Instant::now() < drain_until {
        take(&mut latency_ns);
        std::thread::sleep(Duration::from_micros(50));
    }
    Trial { rate_hz, sent: frames, received, latency_ns }
}

fn argument(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1).cloned())
}

fn micros(trial: &Trial, quantile: f64) -> f64 {
    trial.latency_ns.value_at_quantile(quantile) as f64 / 1000.0
}

fn report(path: &str, trial: &Trial) {
    println!(
        "{path} {:.0} Hz: {} sent, {} received, {} lost; send -> receive p50 {:.1} µs, p90 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        trial.rate_hz,
        trial.sent,
        trial.received,
        trial.sent.saturating_sub(trial.received),
        micros(trial, 0.5),
        micros(trial, 0.9),
        micros(trial, 0.99),
        trial.latency_ns.max() as f64 / 1000.0
    );
}

fn main() {
    let objects: usize = argument("--objects").and_then(|v| v.parse().ok()).unwrap_or(64);
    let seconds: f64 = argument("--seconds").and_then(|v| v.parse().ok()).unwrap_or(5.0);
    let latency_seconds: f64 = argument("--latency-seconds").and_then(|v| v.parse().ok()).unwrap_or(20.0);
    let start_hz: f64 = argument("--start-hz").and_then(|v| v.parse().ok()).unwrap_or(100.0);
    let steps: usize = argument("--steps").and_then(|v| v.parse().ok()).unwrap_or(4);
    let paths = argument("--paths").unwrap_or_else(|| "local,tunnel".into());
    let streams = argument("--streams").unwrap_or_else(|| "measurements,tracks".into());
    let scene = common::scene_frames(&common::lanes(objects), 500, 0.05, 0.2, 11);
    println!(
        "{objects} objects; on the wire a measurement frame is {} bytes, a track frame {} bytes",
        std::mem::size_of::<MeasurementFrame>(),
        std::mem::size_of::<TrackFrame>()
    );
    let mut rows = Vec::new();
    for name in paths.split(',') {
        let path = Path::open(name);
        for stream in streams.split(',') {
            let row = match stream {
                "measurements" => search::<MeasurementFrame>(
                    &path,
                    name,
                    &scene,
                    objects,
                    seconds,
                    latency_seconds,
                    start_hz,
                    steps,
                ),
                "tracks" => search::<TrackFrame>(
                    &path,
                    name,
                    &scene,
                    objects,
                    seconds,
                    latency_seconds,
                    start_hz,
                    steps,
                ),
                other => panic!("unknown stream '{other}' (measurements, tracks)"),
            };
            rows.push(row);
        }
        if let Some((report_a, report_b)) = path.close() {
            println!("host A's tunnel:\n{report_a}host B's tunnel:\n{report_b}");
        }
    }
    println!("\n| path | stream | objects | p50 µs at 20 Hz | p90 µs | p99 µs | highest rate without loss, Hz | lowest rate with loss, Hz |");
    println!("|---|---|---|---|---|---|---|---|");
    let show = |rate: Option<f64>| rate.map_or("-".to_owned(), |r| format!("{r:.0}"));
    for (name, stream, trial, good, bad) in rows {
        println!(
            "| {name} | {stream} | {objects} | {:.1} | {:.1} | {:.1} | {} | {} |",
            micros(&trial, 0.5),
            micros(&trial, 0.9),
            micros(&trial, 0.99),
            show(good),
            show(bad)
        );
    }
}

/// The latency trial at 20 Hz, then the rate search, on stream `P`.
fn search<P: Payload>(
    path: &Path,
    name: &str,
    scene: &[Frame],
    objects: usize,
    seconds: f64,
    latency_seconds: f64,
    start_hz: f64,
    steps: usize,
) -> (String, &'static str, Trial, Option<f64>, Option<f64>) {
    let label = format!("{name} {}", P::STREAM);
    let at_radar_rate = trial::<P>(path, scene, objects, 20.0, latency_seconds);
    report(&label, &at_radar_rate);
    let (mut good, mut bad): (Option<f64>, Option<f64>) = (None, None);
    let mut rate = start_hz;
    while bad.is_none() && rate <= 200_000.0 {
        let outcome = trial::<P>(path, scene, objects, rate, seconds);
        report(&label, &outcome);
        if outcome.received == outcome.sent {
            good = Some(rate);
            rate *= 2.0;
        } else {
            bad = Some(rate);
        }
    }
    for _ in 0..steps {
        let (Some(low), Some(high)) = (good, bad) else { break };
        let rate = (low + high) / 2.0;
        let outcome = trial::<P>(path, scene, objects, rate, seconds);
        report(&label, &outcome);
        if outcome.received == outcome.sent {
            good = Some(rate);
        } else {
            bad = Some(rate);
        }
    }
    (name.to_owned(), P::STREAM, at_radar_rate, good, bad)
}
