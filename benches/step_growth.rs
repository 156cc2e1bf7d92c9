//! Tracker step time against the number of objects, with and without the learned predictor.
//!
//! Each object is measured in every frame (the worst case for association and update: real
//! radar frames see only a part of the scene). Objects drive on parallel lanes 4 m apart in
//! blocks of 16 lanes, cars and pedestrians on alternate lanes, with 0.2 m Gaussian position
//! noise and frames 40 ms apart. For every method and object count the tracker first runs
//! into a steady state of confirmed tracks, then every `Tracker::step` is timed into an
//! HdrHistogram, and the stages (as the tracker reports them) are timed too.
//!
//! * `imm`: CV + CA + CT, no learned predictor.
//! * `pr-imm`: CV + CA + CT + PR, the PR model (`models/pr.onnx`, on the configuration's
//!   `predictor.engine` or `--engine native|tract`) on its inference threads (`on_inference_threads`: `predictor.inference_threads` of the default
//!   configuration, or `--inference-threads N`; deadline 50 ms so that no frame misses it and
//!   the wait is measured in full).
//!
//! Prints a table and writes `benches/results/step_growth.{md,json,svg}`. Nothing is asserted.
//!
//! `cargo bench --bench step_growth [-- --frames N] [-- --methods imm,pr-imm] [-- --counts 8,64] [-- --inference-threads N] [-- --engine native|tract] [-- --config FILE] [-- --sequence FILE] [-- --no-write]`
//!
//! `--sequence FILE` replays a measurement CSV (e.g. a generated evaluation sequence) instead of
//! the lanes, once per method.

use hdrhistogram::Histogram;
use plotters::prelude::*;
use primm_config::{InferenceConfig, InferenceEngine};
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::predictor::{DisplacementPredictor, NoPredictor};
use primm_core::stage_timing::{Stage, StageObserver};
use primm_core::tracker::Tracker;
use primm_predictor::onnx::OnnxPredictor;
use primm_predictor::split::on_inference_threads;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

const FRAME_INTERVAL_S: f64 = 0.04;
const WARM_UP_FRAMES: usize = 60;

/// Frames of `count` objects: lanes 4 m apart, 16 lanes per block, blocks 40 m apart in x.
fn scene(count: usize, frames: usize, seed: u64) -> Vec<Frame> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.2).unwrap();
    (0..frames)
        .map(|k| {
            let t = k as f64 * FRAME_INTERVAL_S;
            let mut frame = Frame::new(t);
            for i in 0..count {
                let (lane, block) = (i % 16, i / 16);
                let class = if lane % 2 == 0 { ObjectClass::Car } else { ObjectClass::Pedestrian };
                let speed = if class == ObjectClass::Car { 8.0 + (lane % 5) as f64 } else { 1.3 };
                let x = -150.0 + 40.0 * block as f64 + speed * t;
                let y = -32.0 + 4.0 * lane as f64;
                let range = (x * x + y * y).sqrt().max(1.0);
                frame.measurements.push(Measurement {
                    x_m: x + noise.sample(&mut rng),
                    y_m: y + noise.sample(&mut rng),
                    radial_velocity_mps: speed * x / range + 0.1 * noise.sample(&mut rng),
                    rcs_dbsm: if class == ObjectClass::Car { 10.0 } else { -5.0 },
                    class,
                    sensor_id: Some(0),
                    ground_truth_id: Some(i as u64),
                });
            }
            frame
        })
        .collect()
}

/// Times the stages with the monotonic clock.
struct StageClock {
    last: Instant,
    stages: [u64; Stage::TRACKER_COUNT],
}

impl StageObserver for StageClock {
    fn stage_finished(&mut self, stage: Stage) {
        let now = Instant::now();
        self.stages[stage.index()] = (now - self.last).as_nanos() as u64;
        self.last = now;
    }
}

fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, 10_000_000_000, 3).unwrap()
}

#[derive(Debug, serde::Serialize)]
struct Row {
    method: String,
    objects: usize,
    tracks: usize,
    frames: u64,
    step_p50_us: f64,
    step_p90_us: f64,
    step_p99_us: f64,
    step_max_us: f64,
    per_object_p50_us: f64,
    /// Median per stage, µs: validate, predict, learned_wait, associate, update, report.
    stage_p50_us: Vec<(String, f64)>,
    learned_predictions_missing: u64,
}

fn us(nanoseconds: u64) -> f64 {
    nanoseconds as f64 / 1000.0
}

fn run<P: DisplacementPredictor>(
    base: &Config,
    method: Method,
    predictor: P,
    count: usize,
    frames: usize,
) -> Row {
    run_frames(base, method, predictor, count, &scene(count, WARM_UP_FRAMES + frames, 7 + count as u64))
}

/// Times every step of `scene` after the first [`WARM_UP_FRAMES`]; `count` is the number of
/// objects reported in the row.
fn run_frames<P: DisplacementPredictor>(
    base: &Config,
    method: Method,
    predictor: P,
    count: usize,
    scene: &[Frame],
) -> Row {
    let config = base.clone().with_modes(method.modes());
    let mut tracker = Tracker::with_predictor(config, predictor).unwrap();
    let mut step = histogram();
    let mut stages: Vec<Histogram<u64>> = (0..Stage::TRACKER_COUNT).map(|_| histogram()).collect();
    let mut emitted = 0usize;
    for (k, frame) in scene.iter().enumerate() {
        let mut clock = StageClock { last: Instant::now(), stages: [0; Stage::TRACKER_COUNT] };
        let start = clock.last;
        let summary = tracker.step_observed(frame, &mut clock, |_| {}).unwrap();
        let elapsed = start.elapsed().as_nanos() as u64;
        if k >= WARM_UP_FRAMES {
            step.record(elapsed.max(1)).unwrap();
            for (histogram, &value) in stages.iter_mut().zip(clock.stages.iter()) {
                histogram.record(value.max(1)).unwrap();
            }
            emitted = summary.live_tracks;
        }
    }
    Row {
        method: method.id().to_string(),
        objects: count,
        tracks: emitted,
        frames: step.len(),
        step_p50_us: us(step.value_at_quantile(0.5)),
        step_p90_us: us(step.value_at_quantile(0.9)),
        step_p99_us: us(step.value_at_quantile(0.99)),
        step_max_us: us(step.max()),
        per_object_p50_us: us(step.value_at_quantile(0.5)) / count as f64,
        stage_p50_us: Stage::TRACKER
            .iter()
            .map(|stage| (stage.name().to_string(), us(stages[stage.index()].value_at_quantile(0.5))))
            .collect(),
        learned_predictions_missing: tracker.stats().learned_predictions_missing,
    }
}

fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    let stage_names: Vec<&str> = Stage::TRACKER.iter().map(|s| s.name()).collect();
    writeln!(
        out,
        "| method | objects | tracks | frames | step p50 µs | p90 µs | p99 µs | max µs | p50 µs/object | {} (p50 µs) | PR missing |",
        stage_names.join(" | ")
    )
    .unwrap();
    writeln!(out, "|{}", "---|".repeat(10 + stage_names.len())).unwrap();
    for row in rows {
        let stages: Vec<String> = row.stage_p50_us.iter().map(|(_, v)| format!("{v:.1}")).collect();
        writeln!(
            out,
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2} | {} | {} |",
            row.method,
            row.objects,
            row.tracks,
            row.frames,
            row.step_p50_us,
            row.step_p90_us,
            row.step_p99_us,
            row.step_max_us,
            row.per_object_p50_us,
            stages.join(" | "),
            row.learned_predictions_missing
        )
        .unwrap();
    }
    out
}

fn plot(rows: &[Row], path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (720, 460)).into_drawing_area();
    root.fill(&WHITE)?;
    let max_objects = rows.iter().map(|r| r.objects).max().unwrap_or(256) as f64;
    let max_us = rows.iter().map(|r| r.step_p99_us).fold(1.0, f64::max) * 1.3;
    let mut chart = ChartBuilder::on(&root)
        .caption("Tracker step time vs objects (one frame, all objects measured)", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((6.0f64..max_objects * 1.1).log_scale(), (5.0f64..max_us).log_scale())?;
    chart
        .configure_mesh()
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .light_line_style(WHITE)
        .x_desc("objects (log)")
        .y_desc("step time, µs (log)")
        .draw()?;
    let methods: Vec<String> = {
        let mut m: Vec<String> = rows.iter().map(|r| r.method.clone()).collect();
        m.dedup();
        m
    };
    let colours = [BLUE, RED, GREEN, MAGENTA];
    for (i, method) in methods.iter().enumerate() {
        let colour = colours[i % colours.len()];
        let points: Vec<(f64, f64)> =
            rows.iter().filter(|r| &r.method == method).map(|r| (r.objects as f64, r.step_p50_us)).collect();
        let p99: Vec<(f64, f64)> =
            rows.iter().filter(|r| &r.method == method).map(|r| (r.objects as f64, r.step_p99_us)).collect();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(format!("{method} p50"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
        chart
            .draw_series(LineSeries::new(p99, colour.mix(0.5).stroke_width(1)))?
            .label(format!("{method} p99"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.mix(0.5).stroke_width(1))
            });
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.8)).draw()?;
    root.present()?;
    Ok(())
}

fn argument(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1).cloned())
}

fn main() {
    let frames: usize = argument("--frames").and_then(|v| v.parse().ok()).unwrap_or(1000);
    let methods: Vec<Method> = argument("--methods")
        .unwrap_or_else(|| "imm,pr-imm".into())
        .split(',')
        .map(|m| m.parse().expect("a method id"))
        .collect();
    let counts: Vec<usize> = argument("--counts")
        .unwrap_or_else(|| "8,32,64,128,256".into())
        .split(',')
        .map(|c| c.parse().expect("an object count"))
        .collect();
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx");
    let inference_threads: usize = argument("--inference-threads")
        .and_then(|v| v.parse().ok())
        .unwrap_or(InferenceConfig::default().inference_threads);
    let engine: InferenceEngine = argument("--engine")
        .map_or(InferenceConfig::default().engine, |name| name.parse().expect("--engine native|tract"));
    // `--config FILE`: another tracker configuration (e.g. the previous lifecycle and association
    // settings, to measure what existence and staged association cost).
    let base = argument("--config").map_or_else(Config::default, |path| {
        primm_config::from_file(Path::new(&path)).expect("--config names a valid configuration")
    });
    // `--sequence FILE`: a measurement CSV (e.g. a generated evaluation sequence) instead of the
    // lanes; its frames are replayed once (the first WARM_UP_FRAMES untimed) and the row's
    // object count is the number of distinct ground-truth objects in it.
    let sequence = argument("--sequence").map(|path| read_sequence(&path));
    let counts = match &sequence {
        Some((_, objects)) => vec![*objects],
        None => counts,
    };
    let mut rows = Vec::new();
    for &method in &methods {
        for &count in &counts {
            let measure = |predictor: Box<dyn DisplacementPredictor>| match &sequence {
                Some((scene, objects)) => run_frames(&base, method, predictor, *objects, scene),
                None => run(&base, method, predictor, count, frames),
            };
            let row = if method.needs_predictor() {
                let mut onnx = OnnxPredictor::load(&model).expect("models/pr.onnx loads");
                assert_eq!(onnx.set_engine(engine), engine);
                let threaded =
                    on_inference_threads(onnx, inference_threads, Duration::from_millis(50)).unwrap();
                measure(Box::new(threaded))
            } else {
                measure(Box::new(NoPredictor))
            };
            eprintln!(
                "{} {:>3} objects: step p50 {:.1} µs, p99 {:.1} µs",
                row.method, count, row.step_p50_us, row.step_p99_us
            );
            rows.push(row);
        }
    }
    let text = table(&rows);
    println!("{text}");
    if !std::env::args().any(|a| a == "--no-write") {
        let header = format!(
            "Tracker step time vs objects (`cargo bench --bench step_growth`), {frames} timed frames per row after {WARM_UP_FRAMES} warm-up frames; PR on {inference_threads} inference thread(s), engine {engine:?}.\n\n"
        );
        write_results(&rows, &(header + &text));
    }
}

/// The frames of a measurement CSV and the number of distinct ground-truth objects in it.
fn read_sequence(path: &str) -> (Vec<Frame>, usize) {
    let sequence =
        primm_sim::io::read_sequence_file(Path::new(path)).expect("--sequence names a measurement CSV");
    let frames: Vec<Frame> =
        sequence.frames.iter().map(|frame| frame.to_frame().expect("a frame within the limits")).collect();
    let objects: std::collections::BTreeSet<u64> =
        frames.iter().flat_map(|frame| frame.measurements.iter().filter_map(|m| m.ground_truth_id)).collect();
    eprintln!("{path}: {} frames, {} objects", frames.len(), objects.len());
    (frames, objects.len())
}

/// Writes the table (`markdown`), the rows as JSON and the plot into `benches/results`.
fn write_results(rows: &[Row], markdown: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/results");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("step_growth.md"), markdown).unwrap();
    std::fs::write(dir.join("step_growth.json"), serde_json::to_string_pretty(rows).unwrap()).unwrap();
    if let Err(error) = plot(rows, &dir.join("step_growth.svg")) {
        eprintln!("cannot draw the plot: {error}");
    }
    eprintln!("wrote {}", dir.join("step_growth.{md,json,svg}").display());
}
