//! Highest sustained frame rate: the fastest publish rate at which a `primm serve` process
//! loses no frame, at a given number of objects per frame.
//!
//! A trial sends frames at a fixed wall-clock rate for a fixed time (the scene of
//! `benches/service_latency.rs`: objects on lanes, 0.2 m noise, 50 ms sensor time between
//! frames, repeating every 500 frames as a new stream), reading the answers as they come. The
//! tracker's input buffer holds 64 frames, so a rate above what it sustains overflows it within
//! the trial and the tracker counts the lost frames (sequence gaps); the trial's verdict is that
//! count, read from `primm serve`'s summary at shutdown. The rate doubles from `--start-hz`
//! until a trial loses frames, then bisection narrows the boundary `--steps` times (the search
//! of `primm_publisher::load::highest_sustained_rate`, which `primm bench-service
//! --find-max-rate` runs too). The latency of the answered frames (publisher send → answer
//! received) is reported per trial, and the same from each frame's scheduled send time
//! (corrected for coordinated omission).
//!
//! Prints one line per trial and a summary table; with `--latency-out DIR`, writes the client
//! latencies of every trial as `DIR/METHOD-RATEHz/*.hlog|.hgrm|client.svg`. Asserts nothing.
//!
//! `cargo bench --bench max_rate [-- --objects 64] [--methods imm,pr-imm] [--seconds 20] [--start-hz 50] [--steps 4] [--latency-out DIR]`

#[path = "../tests/common/mod.rs"]
mod common;

use common::service::{spawn_serve, unique_prefix, TestClient};
use hdrhistogram::Histogram;
use primm_publisher::load::highest_sustained_rate;
use primm_service::clock::monotonic_ns;
use primm_service::latency_files::{LatencyFiles, StageDescription};
use primm_service::ServiceNames;
use std::time::{Duration, Instant};

/// What one trial saw.
struct Trial {
    rate_hz: f64,
    sent: u64,
    lost: u64,
    answered: u64,
    latency_ns: Histogram<u64>,
    /// From each frame's scheduled send time (corrected for coordinated omission).
    corrected_ns: Histogram<u64>,
    tracker_summary: String,
}

/// The value before `what` in the tracker's `frames: ...` summary line.
fn summary_count(summary: &str, what: &str) -> Option<u64> {
    let line = summary.lines().find(|line| line.starts_with("frames: "))?;
    let field = line.split([',', ';', ':']).find(|field| field.trim().ends_with(what))?;
    field.trim().split(' ').next()?.parse().ok()
}

fn trial(method: &str, objects: usize, rate_hz: f64, seconds: f64) -> Trial {
    let prefix = unique_prefix(&format!("max-rate-{method}"));
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let serve = spawn_serve(&prefix, &["--method", method, "--latency-every", "100"]);
    client.wait_for_tracker(Duration::from_secs(60));
    let scene = common::scene_frames(&common::lanes(objects), 500, 0.05, 0.2, 11);
    let mut latency_ns = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
    let mut corrected_ns = latency_ns.clone();
    let mut answered = 0;
    let mut read_answers = |latency_ns: &mut Histogram<u64>, corrected_ns: &mut Histogram<u64>| {
        while let Some(sample) = client.answers.receive().unwrap() {
            let now = monotonic_ns();
            latency_ns.saturating_record(now.saturating_sub(sample.input_publish_time_ns).max(1));
            corrected_ns.saturating_record(now.saturating_sub(sample.input_scheduled_time_ns).max(1));
            answered += 1;
        }
    };
    let frames = (rate_hz * seconds).ceil() as u64;
    let interval = Duration::from_secs_f64(1.0 / rate_hz);
    let start = Instant::now();
    let start_ns = monotonic_ns();
    let mut frame = scene[0].clone();
    for k in 0..frames {
        let offset = interval.mul_f64(k as f64);
        let due = start + offset;
        loop {
            read_answers(&mut latency_ns, &mut corrected_ns);
            let now = Instant::now();
            if now >= due {
                break;
            }
            std::thread::sleep((due - now).min(Duration::from_micros(500)));
        }
        let source = &scene[(k as usize) % scene.len()];
        frame.timestamp_s = k as f64 * 0.05;
        frame.measurements.clone_from(&source.measurements);
        let flags =
            if (k as usize).is_multiple_of(scene.len()) { primm_wire::FRAME_FLAG_STREAM_START } else { 0 };
        client.send_scheduled(&frame, k, flags, start_ns + offset.as_nanos() as u64);
    }
    let drain_until = Instant::now() + Duration::from_secs(2);
    while Instant::now() < drain_until {
        read_answers(&mut latency_ns, &mut corrected_ns);
        std::thread::sleep(Duration::from_millis(5));
    }
    serve.signal(libc::SIGINT);
    let (_, tracker_summary) = serve.wait(Duration::from_secs(30));
    let lost = summary_count(&tracker_summary, "lost").unwrap_or(u64::MAX);
    Trial { rate_hz, sent: frames, lost, answered, latency_ns, corrected_ns, tracker_summary }
}

fn argument(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1).cloned())
}

fn report(method: &str, trial: &Trial, latency_out: Option<&str>) {
    let ms = |h: &Histogram<u64>, q: f64| h.value_at_quantile(q) as f64 / 1.0e6;
    println!(
        "{method} {:.0} Hz: {} sent, {} lost, {} answers read; send -> answer p50 {:.2} ms, p99 {:.2} ms, max {:.2} ms; \
         from schedule (corrected) p99 {:.2} ms, max {:.2} ms",
        trial.rate_hz,
        trial.sent,
        trial.lost,
        trial.answered,
        ms(&trial.latency_ns, 0.5),
        ms(&trial.latency_ns, 0.99),
        trial.latency_ns.max() as f64 / 1.0e6,
        ms(&trial.corrected_ns, 0.99),
        trial.corrected_ns.max() as f64 / 1.0e6
    );
    if let Some(directory) = latency_out {
        let directory = std::path::Path::new(directory).join(format!("{method}-{:.0}Hz", trial.rate_hz));
        let stages = [
            StageDescription::new("publisher_to_subscriber", "publisher send to receive of the answer"),
            StageDescription::new(
                "publisher_to_subscriber_corrected",
                "corrected for coordinated omission: scheduled send to receive of the answer",
            ),
        ];
        let histograms = [&trial.latency_ns, &trial.corrected_ns];
        let written = LatencyFiles::create(
            &directory,
            "client",
            &stages,
            &trial.latency_ns,
            Duration::from_secs(3600),
            0,
        )
        .and_then(|files| files.finish(1, |index| histograms[index]));
        if let Err(error) = written {
            eprintln!("cannot write the latency files of this trial: {error}");
        }
    }
    if let Some(line) = trial.tracker_summary.lines().find(|line| line.starts_with("learned predictor")) {
        println!("    {line}");
    }
}

fn main() {
    let objects: usize = argument("--objects").and_then(|v| v.parse().ok()).unwrap_or(64);
    let seconds: f64 = argument("--seconds").and_then(|v| v.parse().ok()).unwrap_or(20.0);
    let start_hz: f64 = argument("--start-hz").and_then(|v| v.parse().ok()).unwrap_or(50.0);
    let steps: usize = argument("--steps").and_then(|v| v.parse().ok()).unwrap_or(4);
    let methods = argument("--methods").unwrap_or_else(|| "imm,pr-imm".into());
    let latency_out = argument("--latency-out");
    let mut results = Vec::new();
    for method in methods.split(',') {
        let search = highest_sustained_rate::<std::convert::Infallible>(start_hz, 100_000.0, steps, |rate| {
            let outcome = trial(method, objects, rate, seconds);
            report(method, &outcome, latency_out.as_deref());
            Ok(outcome.lost == 0)
        })
        .unwrap_or_else(|never| match never {});
        results.push((method.to_owned(), search.highest_lossless_hz, search.lowest_lossy_hz));
    }
    println!("\n| method | objects | trial s | highest rate without loss, Hz | lowest rate with loss, Hz |");
    println!("|---|---|---|---|---|");
    let show = |rate: Option<f64>| rate.map_or("-".to_owned(), |r| format!("{r:.0}"));
    for (method, good, bad) in results {
        println!("| {method} | {objects} | {seconds} | {} | {} |", show(good), show(bad));
    }
}
