//! PR model inference latency with tract and with the native forward pass, per batch size.
//!
//! `cargo bench --bench inference`
//!
//! The groups `pr_model` and `onnx_predictor` run on tract, `pr_model_native` and
//! `onnx_predictor_native` the same inputs on the native forward pass
//! (`primm_predictor::native`).
//!
//! `pr_model/B` is one `PrModel::run` of B samples (the parity fixture's inputs, repeated):
//! what the inference thread spends per frame when B model rows are needed. `onnx_predictor/N`
//! is a whole frame of N tracks through `OnnxPredictor` with every other track coasting, so
//! 1.5·N model rows (see `crates/primm-predictor/src/onnx/predictor.rs`).
//!
//! Shipped model (d 32, 2 layers), tract 0.23, one thread, idle 2-core Xeon 2.5 GHz:
//! `pr_model` 121.6 µs (B = 1), 463.7 µs (16), 1.521 ms (64), 5.534 ms (256), i.e. 121.6, 29.0,
//! 23.8 and 21.6 µs per sample; `onnx_predictor` 649 µs (16 tracks), 2.19 ms (64 tracks).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use primm_config::InferenceEngine;
use primm_core::predictor::{DisplacementPredictor, HistoryEntry, PredictionRequest, FEATURES, MAX_HISTORY};
use primm_predictor::onnx::{OnnxPredictor, PrModel};
use std::hint::black_box;
use std::path::{Path, PathBuf};

fn model_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx")
}

#[derive(serde::Deserialize)]
struct Parity {
    features: Vec<[[f32; FEATURES]; MAX_HISTORY]>,
    valid: Vec<[f32; MAX_HISTORY]>,
}

fn parity_inputs(batch: usize) -> (Vec<f32>, Vec<f32>) {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr_parity.json")).unwrap();
    let parity: Parity = serde_json::from_str(&text).unwrap();
    let n = parity.features.len();
    let features = (0..batch).flat_map(|i| parity.features[i % n].as_flattened().to_vec()).collect();
    let valid = (0..batch).flat_map(|i| parity.valid[i % n].to_vec()).collect();
    (features, valid)
}

/// The group name of `base` on `engine`.
fn group_name(base: &str, engine: InferenceEngine) -> String {
    match engine {
        InferenceEngine::Tract => base.to_string(),
        InferenceEngine::Native => format!("{base}_native"),
    }
}

fn model_run(c: &mut Criterion) {
    for engine in [InferenceEngine::Tract, InferenceEngine::Native] {
        model_run_on(c, engine);
    }
}

fn model_run_on(c: &mut Criterion, engine: InferenceEngine) {
    let mut model = PrModel::load(model_path()).unwrap();
    assert_eq!(model.set_engine(engine), engine);
    let mut group = c.benchmark_group(group_name("pr_model", engine));
    for batch in [1usize, 16, 64, 256] {
        let (features, valid) = parity_inputs(batch);
        let mut out = vec![0.0f32; 2 * batch];
        group.throughput(Throughput::Elements(batch as u64));
        group.bench_with_input(BenchmarkId::from_parameter(batch), &batch, |b, _| {
            b.iter(|| model.run(black_box(&features), black_box(&valid), &mut out).unwrap())
        });
    }
    group.finish();
}

fn predictor_frame(c: &mut Criterion) {
    for engine in [InferenceEngine::Tract, InferenceEngine::Native] {
        predictor_frame_on(c, engine);
    }
}

fn predictor_frame_on(c: &mut Criterion, engine: InferenceEngine) {
    let mut predictor = OnnxPredictor::load(model_path()).unwrap();
    assert_eq!(predictor.set_engine(engine), engine);
    let mut group = c.benchmark_group(group_name("onnx_predictor", engine));
    for tracks in [16usize, 64] {
        let t = 1.0;
        let requests: Vec<PredictionRequest> = (0..tracks)
            .map(|i| {
                let history: Vec<HistoryEntry> = (0..MAX_HISTORY)
                    .map(|l| HistoryEntry {
                        x_m: 20.0 + i as f64 - 0.25 * l as f64,
                        y_m: -3.0 + 0.02 * l as f64,
                        radial_velocity_mps: -6.0,
                        rcs_dbsm: 7.0,
                        timestamp_s: t - 0.02 - 0.03 * (MAX_HISTORY - 1 - l) as f64,
                        ..Default::default()
                    })
                    .collect();
                let step_start = if i % 2 == 0 { t - 0.02 } else { t - 0.01 };
                PredictionRequest::from_history(&history, t).with_step_start(step_start)
            })
            .collect();
        let mut out = vec![None; tracks];
        group.throughput(Throughput::Elements(tracks as u64));
        group.bench_with_input(BenchmarkId::from_parameter(tracks), &tracks, |b, _| {
            b.iter(|| predictor.predict(black_box(&requests), &mut out))
        });
    }
    group.finish();
}

criterion_group!(benches, model_run, predictor_frame);
criterion_main!(benches);
