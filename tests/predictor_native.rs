//! primm's native forward pass of the PR model (`primm_predictor::native`) against tract: the
//! same answers on the shipped model, no allocation, and a fall-back to tract, with the reason,
//! for a model it does not compute exactly.

use crate::common::counting_allocator::count_allocations;
use primm_config::InferenceEngine;
use primm_core::predictor::{FEATURES, MAX_HISTORY};
use primm_predictor::native::Unsupported;
use primm_predictor::onnx::{ModelSource, PrModel, MAX_PROBE_DIFFERENCE_M};
use prost::Message;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use tract_onnx::pb::ModelProto;

fn shipped() -> PrModel {
    PrModel::embedded().expect("the shipped model loads")
}

/// `rows` histories of random length and content: positions along a random motion with noise,
/// radial velocities, RCS and times spanning what the tracker sends and more.
fn random_batch(rows: usize, seed: u64) -> (Vec<f32>, Vec<f32>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut features = vec![0.0f32; rows * MAX_HISTORY * FEATURES];
    let mut valid = vec![0.0f32; rows * MAX_HISTORY];
    for row in 0..rows {
        let len = rng.random_range(1..=MAX_HISTORY);
        let (speed, interval): (f32, f32) = (rng.random_range(0.0..50.0), rng.random_range(0.01..0.1));
        let gap: f32 = rng.random_range(0.005..0.2);
        for index in 0..len {
            let back = (len - 1 - index) as f32;
            let at = (row * MAX_HISTORY + index) * FEATURES;
            features[at] = -speed * interval * back + rng.random_range(-0.8..0.8);
            features[at + 1] = rng.random_range(-1.5..1.5);
            features[at + 2] = rng.random_range(-40.0..40.0);
            features[at + 3] = rng.random_range(-20.0..40.0);
            features[at + 4] = -(gap + interval * back);
            valid[row * MAX_HISTORY + index] = 1.0;
        }
        // Padding rows hold garbage: neither engine may read them.
        for index in len..MAX_HISTORY {
            let at = (row * MAX_HISTORY + index) * FEATURES;
            features[at..at + FEATURES].copy_from_slice(&[rng.random_range(-1e3..1e3); FEATURES]);
        }
    }
    (features, valid)
}

fn run(model: &mut PrModel, features: &[f32], valid: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let rows = valid.len() / MAX_HISTORY;
    let (mut out, mut factors) = (vec![f32::NAN; rows * 2], vec![f32::NAN; rows * 3]);
    model.run_with_uncertainty(features, valid, &mut out, &mut factors).unwrap();
    (out, factors)
}

#[test]
fn the_shipped_model_runs_natively_and_answers_as_tract_does_within_ten_micrometres() {
    let mut native = shipped();
    assert_eq!(native.engine(), InferenceEngine::Native, "{:?}", native.native_unsupported());
    let mut tract = native.fork().unwrap();
    assert_eq!(tract.set_engine(InferenceEngine::Tract), InferenceEngine::Tract);
    for (rows, seed) in [(1, 1), (7, 2), (64, 3), (200, 4)] {
        let (features, valid) = random_batch(rows, seed);
        let (native_out, native_factors) = run(&mut native, &features, &valid);
        let (tract_out, tract_factors) = run(&mut tract, &features, &valid);
        let mut largest = 0.0f32;
        for (a, b) in native_out.iter().zip(&tract_out).chain(native_factors.iter().zip(&tract_factors)) {
            assert!(a.is_finite() && b.is_finite(), "{a} {b}");
            largest = largest.max((a - b).abs());
        }
        println!("{rows} rows: largest native - tract difference {largest:e} m");
        assert!(largest <= 1e-5, "{rows} rows: {largest} m");
        // The answers are not all alike.
        let spread = native_out.iter().step_by(2).fold(0.0f32, |m, v| m.max(v.abs()));
        assert!(rows < 7 || spread > 0.1, "{spread}");
    }
}

#[test]
fn the_native_forward_pass_allocates_nothing() {
    let mut model = shipped();
    let (features, valid) = random_batch(64, 5);
    let (mut out, mut factors) = (vec![0.0f32; 128], vec![0.0f32; 192]);
    model.run_with_uncertainty(&features, &valid, &mut out, &mut factors).unwrap();
    let allocations = count_allocations(|| {
        for _ in 0..10 {
            model.run_with_uncertainty(&features, &valid, &mut out, &mut factors).unwrap();
        }
    });
    assert_eq!(allocations, 0);
    // tract, for contrast, allocates its tensors every run: the count above can see them.
    model.set_engine(InferenceEngine::Tract);
    let tract =
        count_allocations(|| model.run_with_uncertainty(&features, &valid, &mut out, &mut factors).unwrap());
    assert!(tract > 0);
}

#[test]
fn a_fork_keeps_its_models_engine_and_either_can_change_it_alone() {
    let mut model = shipped();
    model.set_engine(InferenceEngine::Tract);
    let mut fork = model.fork().unwrap();
    assert_eq!(fork.engine(), InferenceEngine::Tract);
    assert_eq!(fork.set_engine(InferenceEngine::Native), InferenceEngine::Native);
    assert_eq!(model.engine(), InferenceEngine::Tract);
}

/// The shipped model's file with `edit` applied.
fn edited(edit: impl FnOnce(&mut ModelProto)) -> PrModel {
    let mut proto = ModelProto::decode(primm_predictor::DEFAULT_MODEL_ONNX).unwrap();
    edit(&mut proto);
    let bytes = proto.encode_to_vec();
    PrModel::from_bytes(&bytes, ModelSource::File(PathBuf::from("edited.onnx")))
        .expect("tract loads the edited model")
}

fn initializer<'a>(proto: &'a mut ModelProto, name: &str) -> &'a mut tract_onnx::pb::TensorProto {
    let graph = proto.graph.as_mut().unwrap();
    graph.initializer.iter_mut().find(|tensor| tensor.name == name).unwrap()
}

/// Sets value `index` of a float initializer stored as raw little-endian bytes.
fn set_value(tensor: &mut tract_onnx::pb::TensorProto, index: usize, value: f32) {
    assert!(!tensor.raw_data.is_empty(), "the exporter writes raw data");
    tensor.raw_data[4 * index..4 * index + 4].copy_from_slice(&value.to_le_bytes());
}

#[test]
fn a_model_whose_heads_share_channels_runs_on_tract_and_says_why() {
    // Head 0's block of the stacked queries reading channel 8, which is head 1's.
    let mut model = edited(|proto| {
        let tensor = initializer(proto, "layers.0.attention.query_heads.weight_t");
        set_value(tensor, 8, 0.5);
    });
    assert_eq!(model.engine(), InferenceEngine::Tract);
    assert!(
        matches!(model.native_unsupported(), Some(Unsupported::HeadsNotSeparated { name }) if name.contains("layers.0.attention.query_heads")),
        "{:?}",
        model.native_unsupported()
    );
    assert_eq!(model.set_engine(InferenceEngine::Native), InferenceEngine::Tract);
    assert_answers_on_tract(&mut model, 6);
}

#[test]
fn a_model_whose_arithmetic_differs_behind_the_same_weights_runs_on_tract() {
    // A LayerNorm epsilon of 0.5 instead of 1e-5: same names and shapes, other answers.
    let mut model = edited(|proto| {
        let graph = proto.graph.as_mut().unwrap();
        let norm = graph.node.iter_mut().find(|node| node.op_type == "LayerNormalization").unwrap();
        let epsilon = norm.attribute.iter_mut().find(|attribute| attribute.name == "epsilon").unwrap();
        epsilon.f = 0.5;
    });
    assert_eq!(model.engine(), InferenceEngine::Tract);
    match model.native_unsupported() {
        Some(Unsupported::Disagrees { difference_m, tolerance_m }) => {
            assert!(*difference_m > MAX_PROBE_DIFFERENCE_M && *tolerance_m == MAX_PROBE_DIFFERENCE_M);
        }
        other => panic!("{other:?}"),
    }
    assert_answers_on_tract(&mut model, 7);
}

/// The model, refused a native forward pass, still answers finite displacements on tract.
fn assert_answers_on_tract(model: &mut PrModel, seed: u64) {
    assert_eq!(model.engine(), InferenceEngine::Tract);
    let (features, valid) = random_batch(3, seed);
    let (out, _) = run(model, &features, &valid);
    assert!(out.iter().all(|v| v.is_finite()));
}

#[test]
fn a_model_without_the_covariance_output_runs_natively_too() {
    let mut model = edited(|proto| {
        proto.graph.as_mut().unwrap().output.truncate(1);
    });
    assert!(!model.has_uncertainty());
    assert_eq!(model.engine(), InferenceEngine::Native, "{:?}", model.native_unsupported());
    let (features, valid) = random_batch(20, 8);
    let mut native_out = vec![0.0f32; 40];
    model.run(&features, &valid, &mut native_out).unwrap();
    model.set_engine(InferenceEngine::Tract);
    let mut tract_out = vec![0.0f32; 40];
    model.run(&features, &valid, &mut tract_out).unwrap();
    for (a, b) in native_out.iter().zip(&tract_out) {
        assert!((a - b).abs() <= 1e-5, "{a} vs {b}");
    }
    // Asking for the covariance of a model without one is an error on either engine.
    let mut factors = vec![0.0f32; 60];
    for engine in [InferenceEngine::Native, InferenceEngine::Tract] {
        model.set_engine(engine);
        assert!(
            model.run_with_uncertainty(&features, &valid, &mut native_out, &mut factors).is_err(),
            "{engine:?}"
        );
    }
}
