//! Service latency: a measurement frame sent by a publisher until its track frame is received
//! by a subscriber, through a `primm serve` process, with the tracker waiting on events
//! (default) and busy-polling. Frames are sent one at a time (each after the previous answer),
//! so the figures are latencies, not queueing. Prints HdrHistogram percentiles; nothing is
//! asserted.
//!
//! `cargo bench --bench service_latency [-- FRAMES]`

#[path = "../tests/common/mod.rs"]
mod common;

use common::service::{spawn_serve, unique_prefix, TestClient};
use hdrhistogram::Histogram;
use primm::service::clock::monotonic_ns;
use primm::service::ServiceNames;
use std::time::Duration;

fn measure(mode: &str, extra: &[&str], frames: usize) {
    let prefix = unique_prefix(&format!("bench-{mode}"));
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let serve = spawn_serve(&prefix, extra);
    client.wait_for_tracker(Duration::from_secs(30));
    let scene = common::scene_frames(&common::lanes(32), 500, 0.05, 0.2, 11);
    let mut round_trip = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
    let mut tracker_internal = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3).unwrap();
    let warm_up = 200;
    let mut frame = scene[0].clone();
    for k in 0..warm_up + frames {
        let source = &scene[k % scene.len()];
        frame.timestamp_s = k as f64 * 0.05;
        frame.measurements.clone_from(&source.measurements);
        client.send(&frame, k as u64, 0);
        let (sent_ns, receive_ns, publish_ns) = client
            .next_answer(Duration::from_secs(10), |answer| {
                (answer.input_publish_time_ns, answer.receive_time_ns, answer.publish_time_ns)
            })
            .expect("the tracker answers");
        let received_ns = monotonic_ns();
        if k >= warm_up {
            round_trip.saturating_record(received_ns - sent_ns);
            tracker_internal.saturating_record(publish_ns - receive_ns);
        }
    }
    serve.signal(libc::SIGINT);
    let _ = serve.wait(Duration::from_secs(10));
    let us = |h: &Histogram<u64>, q: f64| h.value_at_quantile(q) as f64 / 1000.0;
    for (name, h) in [("send -> track frame received", &round_trip), ("tracker receive -> publish", &tracker_internal)] {
        println!(
            "{mode:<10} {name:<30} n {:>6}  p50 {:>8.1} µs  p99 {:>8.1} µs  p99.9 {:>8.1} µs  max {:>8.1} µs",
            h.len(),
            us(h, 0.5),
            us(h, 0.99),
            us(h, 0.999),
            h.max() as f64 / 1000.0
        );
    }
}

fn main() {
    let frames = std::env::args()
        .skip(1)
        .find_map(|arg| arg.parse::<usize>().ok())
        .unwrap_or(5000);
    println!("service latency, 32 objects per frame, {frames} frames after warm-up");
    measure("event", &[], frames);
    measure("busy-poll", &["--busy-poll"], frames);
}
