//! The cost of tracking late frames in their place (`primm_core::replay`), as ratios to a normal
//! step.
//!
//! A scene of `--objects` objects (default 64) on a grid of lanes, every object measured in every
//! frame, frames 15 ms apart (four radars scanning in turn every 60 ms), IMM. Three runs over the
//! same frames, each step timed into an HdrHistogram:
//!
//! * `off`: `tracker.replay_frames = 0`, frames in order: a plain step.
//! * `in order`: the default ring (16 frames, 0.15 s), frames in order: a plain step plus the
//!   copy of the live tracks into the ring.
//! * `late by D`: every `D+1`-th frame held back behind the `D` frames after it, so that it
//!   arrives `D` frames late and the tracker tracks it and replays the `D` newer frames; only the
//!   late frames' steps are recorded.
//!
//! Prints a table (percentiles in µs and the ratio of each p50 to the `off` p50) and writes
//! `benches/results/late_frames.md` at the workspace root. Nothing is asserted; timings vary on a shared machine, the
//! ratios less.
//!
//! `cargo bench -p primm-core --bench late_frames [-- --objects N] [-- --frames N] [-- --no-write]`

use hdrhistogram::Histogram;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use std::fmt::Write as _;
use std::time::Instant;

const FRAME_INTERVAL_S: f64 = 0.015;

/// `frames` frames of `count` objects on lanes 3.5 m apart (8 lanes a block), with a small
/// deterministic wobble so that the filters have something to do.
fn scene(count: usize, frames: usize) -> Vec<Frame> {
    (0..frames)
        .map(|k| {
            let t = k as f64 * FRAME_INTERVAL_S;
            let mut frame = Frame::new(t);
            for i in 0..count {
                let (lane, block) = (i % 8, i / 8);
                let class = if i % 3 == 0 { ObjectClass::Pedestrian } else { ObjectClass::Car };
                let speed = if class == ObjectClass::Car { 6.0 + lane as f64 } else { 1.2 };
                let wobble = 0.15 * ((k * 7 + i * 13) as f64 * 0.37).sin();
                let x = -100.0 + 30.0 * block as f64 + speed * t + wobble;
                let y = -14.0 + 3.5 * lane as f64 - wobble;
                let range = (x * x + y * y).sqrt().max(1.0);
                frame.measurements.push(Measurement {
                    x_m: x,
                    y_m: y,
                    radial_velocity_mps: speed * x / range,
                    rcs_dbsm: if class == ObjectClass::Car { 10.0 } else { -5.0 },
                    class,
                    sensor_id: Some(1 + (k % 4) as u16),
                    ground_truth_id: Some(i as u64),
                });
            }
            frame
        })
        .collect()
}

/// The arrival order with every `delay + 1`-th frame held back by `delay` frames, and whether
/// each arrival is a held-back frame.
fn arrival(frames: usize, delay: usize) -> Vec<(usize, bool)> {
    let mut order = Vec::with_capacity(frames);
    let mut k = 0;
    while k + delay < frames {
        order.extend((k + 1..=k + delay).map(|j| (j, false)));
        order.push((k, delay > 0));
        k += delay + 1;
    }
    order.extend((k..frames).map(|j| (j, false)));
    order
}

fn run(config: Config, frames: &[Frame], delay: usize, warm_up: usize) -> Histogram<u64> {
    let mut tracker = Tracker::new(config).unwrap();
    let mut histogram = Histogram::<u64>::new_with_bounds(1, 10_000_000_000, 3).unwrap();
    for (position, (index, late)) in arrival(frames.len(), delay).into_iter().enumerate() {
        let start = Instant::now();
        tracker.step(&frames[index]).expect("every frame is tracked");
        let elapsed = start.elapsed().as_nanos() as u64;
        let recorded = if delay > 0 { late } else { true };
        if position >= warm_up && recorded {
            histogram.record(elapsed.max(1)).unwrap();
        }
    }
    histogram
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |name: &str, default: usize| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let objects = value("--objects", 64);
    let frame_count = value("--frames", 1500);
    let write = !args.iter().any(|a| a == "--no-write");
    let frames = scene(objects, frame_count);
    let imm = Config::default().with_modes(Method::Imm.modes());
    let mut off = imm.clone();
    off.tracker.replay_frames = 0;
    let warm_up = 100;

    let mut rows = vec![("off (replay_frames = 0)".to_owned(), run(off, &frames, 0, warm_up))];
    rows.push(("in order, ring of 16".to_owned(), run(imm.clone(), &frames, 0, warm_up)));
    for delay in [1, 3, 6] {
        rows.push((format!("late by {delay} (replays {delay})"), run(imm.clone(), &frames, delay, warm_up)));
    }
    let base = rows[0].1.value_at_quantile(0.5) as f64;
    let mut table = format!(
        "IMM, {objects} objects measured every frame, frames {:.0} ms apart, {} frames.\n\n\
         | run | steps | p50 µs | p99 µs | max µs | p50 / off p50 |\n|---|---|---|---|---|---|\n",
        FRAME_INTERVAL_S * 1e3,
        frame_count
    );
    for (name, histogram) in &rows {
        let us = |q: f64| histogram.value_at_quantile(q) as f64 / 1e3;
        let _ = writeln!(
            table,
            "| {name} | {} | {:.1} | {:.1} | {:.1} | {:.2} |",
            histogram.len(),
            us(0.5),
            us(0.99),
            histogram.max() as f64 / 1e3,
            histogram.value_at_quantile(0.5) as f64 / base
        );
    }
    print!("{table}");
    if write {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../benches/results/late_frames.md");
        std::fs::write(
            &path,
            format!("# Late frames (cargo bench -p primm-core --bench late_frames)\n\n{table}"),
        )
        .expect("write the results");
        println!("wrote {}", path.display());
    }
}
