//! Service latency: a measurement frame sent by a publisher until its track frame is received
//! by a subscriber, through a real `primm serve` process, with the tracker and this client
//! waiting on events (default) or both busy-polling. Frames are sent one at a time (each after
//! the previous answer), so the figures are latencies, not queueing.
//!
//! Per frame, with the same-host monotonic clock of both processes:
//! * `send -> answer`: the client's send until it holds the track frame;
//! * `send -> tracker receive` and `tracker publish -> answer`: the two IPC legs;
//! * `tracker receive -> publish`: the tracker's own compute (validate … publish);
//! * `IPC overhead`: `send -> answer` minus the tracker's compute, i.e. what shared memory,
//!   notification and wake-ups add.
//!
//! The scene (objects on lanes, 0.2 m noise, 50 ms frames) repeats every 500 frames, each
//! repetition flagged as a new stream, so the tracker holds `--objects` confirmed tracks in a
//! steady state.
//!
//! Prints HdrHistogram percentiles and writes `benches/results/service_latency.md`; nothing is
//! asserted.
//!
//! With `--latency-out DIR`, each wait mode leaves its files in `DIR/MODE/`: the tracker's
//! (`primm serve --latency-out`: per stage `.hlog`, `.hgrm`, `tracker.svg`) and this client's
//! legs (`send_to_answer`, `send_to_tracker_receive`, `tracker_receive_to_publish`,
//! `tracker_publish_to_answer`, `ipc_overhead`: `.hlog`, `.hgrm`, `client.svg`). Frames go one
//! at a time, each after the previous answer, so these are service times without queueing: a
//! stall delays the next send instead of showing in the tail (coordinated omission;
//! `primm bench-service` sends on a schedule and corrects for it).
//!
//! `cargo bench --bench service_latency [-- --frames 100000] [--objects 64] [--modes event,busy-poll] [--method imm] [--model FILE] [--inference-threads N] [--engine native|tract] [--latency-every 100] [--latency-out DIR] [--no-write]`
//!
//! `--serve-args "OPTIONS"` passes more options to `primm serve`, e.g. its real-time settings
//! (`--cpu-affinity 1 --realtime-priority 50 --lock-memory`, docs/realtime-tuning.md).
//!
//! `--model FILE` runs the tracker with that PR model instead of the built-in one, and
//! `--inference-threads N` with that many inference threads instead of the configuration's (to
//! compare side by side on one machine); their results are printed, not written.

#[path = "../tests/common/mod.rs"]
mod common;

use common::service::{spawn_serve, unique_prefix, TestClient};
use hdrhistogram::Histogram;
use primm_core::measurement::Frame;
use primm_service::clock::monotonic_ns;
use primm_service::latency_files::{LatencyFiles, StageDescription};
use primm_service::ServiceNames;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

/// File names of the legs (`--latency-out`).
const LEG_FILES: [&str; 5] = [
    "send_to_answer",
    "send_to_tracker_receive",
    "tracker_receive_to_publish",
    "tracker_publish_to_answer",
    "ipc_overhead",
];

const LEGS: [&str; 5] = [
    "send -> answer",
    "send -> tracker receive",
    "tracker receive -> publish",
    "tracker publish -> answer",
    "IPC overhead",
];

fn measure(
    mode: &str,
    method: &str,
    objects: usize,
    frames: usize,
    latency_every: &str,
    model: Option<&str>,
    inference_threads: Option<&str>,
    engine: Option<&str>,
    latency_out: Option<&Path>,
) -> Vec<Histogram<u64>> {
    let prefix = unique_prefix(&format!("bench-{mode}"));
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let busy = mode == "busy-poll";
    let directory = latency_out.map(|directory| directory.join(mode));
    let mut extra = vec!["--method", method, "--latency-every", latency_every];
    let options = [("--model", model), ("--inference-threads", inference_threads), ("--engine", engine)];
    extra.extend(options.into_iter().filter_map(|(name, value)| value.map(|value| [name, value])).flatten());
    if busy {
        extra.push("--busy-poll");
    }
    let directory_text = directory.as_ref().map(|directory| directory.display().to_string());
    if let Some(directory) = &directory_text {
        extra.extend(["--latency-out", directory.as_str()]);
    }
    // `--serve-args "…"`: more options for `primm serve` (e.g. its real-time settings).
    let serve_args = argument("--serve-args").unwrap_or_default();
    extra.extend(serve_args.split_whitespace());
    let serve = spawn_serve(&prefix, &extra);
    client.wait_for_tracker(Duration::from_secs(60));
    let scene = common::scene_frames(&common::lanes(objects), 500, 0.05, 0.2, 11);
    let mut histograms: Vec<Histogram<u64>> =
        LEGS.iter().map(|_| Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap()).collect();
    let warm_up = 500;
    let mut files = directory.as_ref().map(|directory| client_latency_files(directory, &histograms[0]));
    let mut frame = scene[0].clone();
    for k in 0..warm_up + frames {
        let source = &scene[k % scene.len()];
        frame.timestamp_s = k as f64 * 0.05;
        frame.measurements.clone_from(&source.measurements);
        // The scene repeats every 500 frames; each repetition starts a new stream, so the
        // tracker resets instead of seeing every object jump back (a burst of new tracks).
        let flags = if k % scene.len() == 0 { primm_wire::FRAME_FLAG_STREAM_START } else { 0 };
        let (sent_ns, receive_ns, publish_ns, received_ns) = send_and_wait(&client, &frame, k, flags, busy);
        if k >= warm_up {
            let values = leg_values(sent_ns, receive_ns, publish_ns, received_ns);
            for (histogram, value) in histograms.iter_mut().zip(values) {
                histogram.saturating_record(value.max(1));
            }
            if let Some(files) = &mut files {
                files
                    .write_due(received_ns, |index| &histograms[index])
                    .expect("the latency files can be written");
            }
        }
    }
    if let Some(files) = files {
        let written = files
            .finish(monotonic_ns(), |index| &histograms[index])
            .expect("the latency files can be written");
        eprintln!(
            "{mode}: wrote {} latency files in {}",
            written.len(),
            directory.as_ref().unwrap().display()
        );
    }
    serve.signal(libc::SIGINT);
    let (_, stdout) = serve.wait(Duration::from_secs(10));
    for line in
        stdout.lines().filter(|line| line.starts_with("learned predictor") || line.starts_with("frames:"))
    {
        eprintln!("{mode}: {line}");
    }
    histograms
}

/// Sends frame number `k` and waits for its answer (spinning with `busy`); the send, the
/// tracker's receive and publish, and the client's receive times, ns.
fn send_and_wait(
    client: &TestClient,
    frame: &Frame,
    k: usize,
    flags: u32,
    busy: bool,
) -> (u64, u64, u64, u64) {
    client.send(frame, k as u64, flags);
    let read = |answer: &primm_wire::TrackFrame| {
        (answer.input_publish_time_ns, answer.receive_time_ns, answer.publish_time_ns)
    };
    let answer = if busy {
        client.next_answer_spinning(Duration::from_secs(10), read)
    } else {
        client.next_answer(Duration::from_secs(10), read)
    };
    let (sent_ns, receive_ns, publish_ns) = answer.expect("the tracker answers");
    (sent_ns, receive_ns, publish_ns, monotonic_ns())
}

/// The client's latency files of the legs (`--latency-out`), in `directory`.
fn client_latency_files(directory: &Path, first: &Histogram<u64>) -> LatencyFiles {
    let stages: Vec<StageDescription> =
        LEGS.iter().zip(LEG_FILES).map(|(leg, file)| StageDescription::new(file, *leg)).collect();
    LatencyFiles::create(directory, "client", &stages, first, Duration::from_secs(1), monotonic_ns())
        .expect("the latency files can be created")
}

/// Each leg's latency of one frame, ns, in the order of [`LEGS`]: from the send, the tracker's
/// receive and publish times and the client's receive time.
fn leg_values(sent_ns: u64, receive_ns: u64, publish_ns: u64, received_ns: u64) -> [u64; 5] {
    let round_trip = received_ns.saturating_sub(sent_ns);
    let compute = publish_ns.saturating_sub(receive_ns);
    [
        round_trip,
        receive_ns.saturating_sub(sent_ns),
        compute,
        received_ns.saturating_sub(publish_ns),
        round_trip.saturating_sub(compute),
    ]
}

fn argument(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1).cloned())
}

fn main() {
    let frames: usize = argument("--frames").and_then(|v| v.parse().ok()).unwrap_or(100_000);
    let objects: usize = argument("--objects").and_then(|v| v.parse().ok()).unwrap_or(64);
    let method = argument("--method").unwrap_or_else(|| "imm".into());
    let modes = argument("--modes").unwrap_or_else(|| "event,busy-poll".into());
    // The tracker's latency report (every 100 frames by default) costs ~0.1 ms of percentile
    // computation on the tracking thread; `--latency-every 0` leaves it out.
    let latency_every = argument("--latency-every").unwrap_or_else(|| "100".into());
    let model = argument("--model");
    let inference_threads = argument("--inference-threads");
    let engine = argument("--engine");
    let latency_out = argument("--latency-out").map(std::path::PathBuf::from);
    let us = |h: &Histogram<u64>, q: f64| h.value_at_quantile(q) as f64 / 1000.0;
    let mut table = String::new();
    writeln!(table, "| wait mode | leg | frames | p50 µs | p90 µs | p99 µs | p99.9 µs | max µs |").unwrap();
    writeln!(table, "|---|---|---|---|---|---|---|---|").unwrap();
    for mode in modes.split(',') {
        let histograms = measure(
            mode,
            &method,
            objects,
            frames,
            &latency_every,
            model.as_deref(),
            inference_threads.as_deref(),
            engine.as_deref(),
            latency_out.as_deref(),
        );
        for (leg, h) in LEGS.iter().zip(&histograms) {
            writeln!(
                table,
                "| {mode} | {leg} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
                h.len(),
                us(h, 0.5),
                us(h, 0.9),
                us(h, 0.99),
                us(h, 0.999),
                h.max() as f64 / 1000.0
            )
            .unwrap();
        }
    }
    let model_option = model.as_ref().map_or(String::new(), |file| format!(" --model {file}"))
        + &inference_threads.as_ref().map_or(String::new(), |n| format!(" --inference-threads {n}"))
        + &engine.as_ref().map_or(String::new(), |e| format!(" --engine {e}"));
    let heading = format!(
        "Service latency through `primm serve --method {method}{model_option} --latency-every {latency_every}`, {objects} objects per frame, {frames} frames per wait mode after 500 warm-up frames, one frame in flight.\n\n"
    );
    println!("{heading}{table}");
    if model.is_none()
        && inference_threads.is_none()
        && engine.is_none()
        && !std::env::args().any(|a| a == "--no-write")
    {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/results");
        std::fs::create_dir_all(&dir).unwrap();
        let suffix = if latency_every == "0" { "_no_reports" } else { "" };
        let name = if method == "imm" {
            format!("service_latency{suffix}.md")
        } else {
            format!("service_latency_{method}{suffix}.md")
        };
        std::fs::write(dir.join(&name), heading + &table).unwrap();
        eprintln!("wrote {}", dir.join(name).display());
    }
}
