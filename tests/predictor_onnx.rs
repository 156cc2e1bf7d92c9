//! The shipped PR model on tract and on the native forward pass: parity with PyTorch, masking,
//! the step displacement of coasting tracks, and clear start-up errors for unusable model files.

use glam::DVec2;
use primm_config::InferenceEngine;
use primm_core::predictor::{
    DisplacementPredictor, HistoryEntry, PredictionRequest, RememberedDisplacement, FEATURES, MAX_HISTORY,
};
use primm_predictor::onnx::{InputFrame, InputRotation, ModelError, OnnxPredictor, PrModel};
use std::path::{Path, PathBuf};

fn repo_path(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn model() -> PrModel {
    PrModel::load(repo_path("models/pr.onnx")).expect("the shipped model loads")
}

/// Both engines; the shipped model has a native forward pass.
const ENGINES: [InferenceEngine; 2] = [InferenceEngine::Tract, InferenceEngine::Native];

fn model_on(engine: InferenceEngine) -> PrModel {
    let mut model = model();
    assert_eq!(model.set_engine(engine), engine, "{:?}", model.native_unsupported());
    model
}

#[derive(serde::Deserialize)]
struct Parity {
    features: Vec<[[f32; FEATURES]; MAX_HISTORY]>,
    valid: Vec<[f32; MAX_HISTORY]>,
    length: Vec<usize>,
    displacement: Vec<[f32; 2]>,
    /// PyTorch's covariance output, for a model that has one.
    #[serde(default)]
    cholesky: Option<Vec<[f32; 3]>>,
}

fn parity() -> Parity {
    let text = std::fs::read_to_string(repo_path("models/pr_parity.json")).expect("parity fixture");
    serde_json::from_str(&text).expect("parity fixture parses")
}

fn flatten(
    features: &[[[f32; FEATURES]; MAX_HISTORY]],
    valid: &[[f32; MAX_HISTORY]],
) -> (Vec<f32>, Vec<f32>) {
    (features.iter().flatten().flatten().copied().collect(), valid.iter().flatten().copied().collect())
}

#[test]
fn both_engines_match_pytorch_on_the_parity_fixture_within_a_tenth_of_a_millimetre() {
    let parity = parity();
    assert_eq!(parity.features.len(), 64);
    // Every history length is represented.
    for length in 1..=MAX_HISTORY {
        assert!(parity.length.contains(&length), "no sample of length {length}");
    }
    let (features, valid) = flatten(&parity.features, &parity.valid);
    for engine in ENGINES {
        let mut out = vec![0.0f32; 2 * parity.features.len()];
        model_on(engine).run(&features, &valid, &mut out).unwrap();
        let mut max_difference = 0.0f32;
        for (got, want) in out.chunks(2).zip(&parity.displacement) {
            max_difference = max_difference.max((got[0] - want[0]).abs()).max((got[1] - want[1]).abs());
        }
        println!("max abs difference {engine:?} vs PyTorch: {max_difference:e} m");
        assert!(max_difference <= 1e-4, "{engine:?}: max abs difference {max_difference} m");
    }
    // The outputs are not trivial: displacements of different samples differ.
    let spread = parity.displacement.iter().map(|d| d[0]).fold(f32::NEG_INFINITY, f32::max)
        - parity.displacement.iter().map(|d| d[0]).fold(f32::INFINITY, f32::min);
    assert!(spread > 0.05, "outputs hardly vary: {spread} m");
}

#[test]
fn both_engines_match_pytorch_on_the_covariance_output_within_a_tenth_of_a_millimetre() {
    let parity = parity();
    let expected = parity.cholesky.expect("the parity fixture has the covariance output");
    let (features, valid) = flatten(&parity.features, &parity.valid);
    for engine in ENGINES {
        let mut model = model_on(engine);
        // The shipped model estimates its uncertainty, and the fixture has PyTorch's answers.
        assert!(model.has_uncertainty(), "the shipped model has the displacement_cholesky output");
        let mut out = vec![0.0f32; 2 * parity.features.len()];
        let mut factors = vec![0.0f32; 3 * parity.features.len()];
        model.run_with_uncertainty(&features, &valid, &mut out, &mut factors).unwrap();
        let mut max_difference = 0.0f32;
        for (got, want) in factors.chunks(3).zip(&expected) {
            for axis in 0..3 {
                max_difference = max_difference.max((got[axis] - want[axis]).abs());
            }
            // Positive diagonal: a valid Cholesky factor.
            assert!(got[0] > 0.0 && got[2] > 0.0, "{got:?}");
        }
        println!("max abs difference of the Cholesky factors {engine:?} vs PyTorch: {max_difference:e} m");
        assert!(max_difference <= 1e-4, "{engine:?}: max abs difference {max_difference} m");
    }
    // The model's confidence varies between inputs.
    let smallest = expected.iter().map(|f| f[0]).fold(f32::INFINITY, f32::min);
    let largest = expected.iter().map(|f| f[0]).fold(f32::NEG_INFINITY, f32::max);
    assert!(largest > 1.5 * smallest, "the uncertainty hardly varies: {smallest} .. {largest} m");
}

#[test]
fn each_sample_gets_the_same_output_alone_as_in_a_batch_and_padded_rows_are_ignored() {
    for engine in ENGINES {
        each_sample_alone_as_in_a_batch(model_on(engine));
    }
}

fn each_sample_alone_as_in_a_batch(mut model: PrModel) {
    let parity = parity();
    let (features, valid) = flatten(&parity.features, &parity.valid);
    let mut batched = vec![0.0f32; 2 * parity.features.len()];
    model.run(&features, &valid, &mut batched).unwrap();
    for (i, (sample, mask)) in parity.features.iter().zip(&parity.valid).enumerate() {
        // Garbage in the padded rows must not change anything: the attention mask hides them.
        let mut noisy = *sample;
        for (row, &v) in noisy.iter_mut().zip(mask) {
            if v == 0.0 {
                *row = [37.0, -12.0, 5.5, 20.0, -0.4];
            }
        }
        let mut alone = [0.0f32; 2];
        model.run(noisy.as_flattened(), mask, &mut alone).unwrap();
        for axis in 0..2 {
            assert!(
                (alone[axis] - batched[2 * i + axis]).abs() <= 1e-5,
                "sample {i} axis {axis}: alone {} batched {}",
                alone[axis],
                batched[2 * i + axis]
            );
        }
    }
}

#[test]
fn batches_of_any_size_run_in_planned_chunks_and_every_row_gets_its_own_output() {
    let parity = parity();
    // The chunks and padding are tract's.
    let mut model = model_on(InferenceEngine::Tract);
    let (features, valid) = flatten(&parity.features, &parity.valid);
    let mut reference = vec![0.0f32; 2 * parity.features.len()];
    model.run(&features, &valid, &mut reference).unwrap();
    let samples = parity.features.len();
    // Sizes on, between and above the planned ones: padded remainders, several full chunks.
    for batch in [1, 3, 9, 33, 57, 63, 64, 65, 100, 129, 200] {
        // Sample `(i * 7) % samples` in row `i`: neighbouring rows differ from the fixture's order.
        let pick = |i: usize| (i * 7) % samples;
        let mut batch_features = Vec::with_capacity(batch * MAX_HISTORY * FEATURES);
        let mut batch_valid = Vec::with_capacity(batch * MAX_HISTORY);
        for i in 0..batch {
            batch_features.extend_from_slice(parity.features[pick(i)].as_flattened());
            batch_valid.extend_from_slice(&parity.valid[pick(i)]);
        }
        let mut out = vec![f32::NAN; 2 * batch];
        model.run(&batch_features, &batch_valid, &mut out).unwrap();
        for i in 0..batch {
            for axis in 0..2 {
                let (got, want) = (out[2 * i + axis], reference[2 * pick(i) + axis]);
                assert!((got - want).abs() <= 1e-5, "batch {batch} row {i} axis {axis}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn the_valid_rows_matter() {
    // Changing a valid row changes the prediction (the model reads its input).
    let parity = parity();
    let mut model = model();
    let index = parity.length.iter().position(|&l| l == MAX_HISTORY).unwrap();
    let sample = parity.features[index];
    let mask = parity.valid[index];
    let mut base = [0.0f32; 2];
    model.run(sample.as_flattened(), &mask, &mut base).unwrap();
    let mut moved = sample;
    moved[0][0] -= 2.0; // the oldest measurement 2 m further back along x
    let mut out = [0.0f32; 2];
    model.run(moved.as_flattened(), &mask, &mut out).unwrap();
    // The change is small for the shipped model, whose latest radial velocity along its line of
    // sight carries most of the motion, but far above the engines' rounding (1e-6 m).
    let change = (out[0] - base[0]).hypot(out[1] - base[1]);
    assert!(change > 1e-4, "prediction ignores the history: {base:?} vs {out:?}");
    // The latest row's radial velocity (x is its line of sight) moves the x displacement.
    let mut faster = sample;
    faster[MAX_HISTORY - 1][2] += 2.0;
    model.run(faster.as_flattened(), &mask, &mut out).unwrap();
    assert!(out[0] - base[0] > 1e-3, "2 m/s more along the line of sight: {base:?} vs {out:?}");
}

fn history(points: &[(f64, f64, f64)]) -> Vec<HistoryEntry> {
    points
        .iter()
        .map(|&(t, x, y)| HistoryEntry {
            x_m: x,
            y_m: y,
            radial_velocity_mps: -3.0,
            rcs_dbsm: 5.0,
            timestamp_s: t,
            ..Default::default()
        })
        .collect()
}

/// The model's displacement for one request, with the request rotated into the model's input
/// axes and the output rotated back, as `OnnxPredictor` does.
fn run_one(model: &mut PrModel, request: &PredictionRequest) -> DVec2 {
    let rotation = InputRotation::of(request, model.input_frame());
    let mut features = request.features;
    for row in &mut features[..request.len] {
        let position = rotation.to_model(DVec2::new(f64::from(row[0]), f64::from(row[1])));
        row[0] = position.x as f32;
        row[1] = position.y as f32;
    }
    let mut valid = [0.0f32; MAX_HISTORY];
    valid[..request.len].fill(1.0);
    let mut out = [0.0f32; 2];
    model.run(features.as_flattened(), &valid, &mut out).unwrap();
    rotation.from_model(DVec2::new(f64::from(out[0]), f64::from(out[1])))
}

#[test]
fn a_rotated_history_gets_the_rotated_displacement() {
    let mut predictor = OnnxPredictor::load(repo_path("models/pr.onnx")).unwrap();
    let points = [(0.00, 20.0, 3.0), (0.03, 19.7, 3.2), (0.06, 19.4, 3.5), (0.09, 19.1, 3.9)];
    let predict = |predictor: &mut OnnxPredictor, angle: f64| {
        let rotation = DVec2::from_angle(angle);
        let rotated: Vec<(f64, f64, f64)> = points
            .iter()
            .map(|&(t, x, y)| {
                let p = rotation.rotate(DVec2::new(x, y));
                (t, p.x, p.y)
            })
            .collect();
        let mut out = [None];
        predictor.predict(&[PredictionRequest::from_history(&history(&rotated), 0.105)], &mut out);
        out[0].unwrap()
    };
    let answer = predict(&mut predictor, 0.0);
    let base = answer.mean_m;
    let base_covariance = answer.covariance_m2.expect("the shipped model gives a covariance");
    assert!(base.length() > 1e-3, "the model predicts motion: {base}");
    for angle in [0.4, 1.9, -2.6, std::f64::consts::PI] {
        let expected = DVec2::from_angle(angle).rotate(base);
        let answer = predict(&mut predictor, angle);
        let got = answer.mean_m;
        assert!((got - expected).length() < 1e-4, "at {angle} rad: {got} vs {expected}");
        // The covariance turns with the history: R Σ Rᵀ.
        let rotation = glam::DMat2::from_angle(angle);
        let expected_covariance = rotation * base_covariance * rotation.transpose();
        let covariance = answer.covariance_m2.unwrap();
        let difference = covariance.abs_diff_eq(expected_covariance, 1e-5);
        assert!(difference, "at {angle} rad: {covariance} vs {expected_covariance}");
    }
    // One measurement has a line of sight but no direction of motion; a measurement at its
    // radar has neither.
    let single = PredictionRequest::from_history(&history(&points[..1]), 0.03);
    assert_ne!(InputRotation::of(&single, InputFrame::LineOfSight), InputRotation::IDENTITY);
    assert_eq!(InputRotation::of(&single, InputFrame::LatestMotion), InputRotation::IDENTITY);
    let at_radar = PredictionRequest { sensor_m: single.anchor_m, ..single };
    assert_eq!(InputRotation::of(&at_radar, InputFrame::LineOfSight), InputRotation::IDENTITY);
}

#[test]
fn the_shipped_model_takes_its_input_along_the_line_of_sight() {
    assert_eq!(model().input_frame(), InputFrame::LineOfSight);
}

#[test]
fn the_line_of_sight_runs_from_the_radar_to_the_latest_measurement() {
    let mut entries = history(&[(0.00, 20.0, 3.0), (0.05, 20.0, 3.5)]);
    // The latest measurement seen by a radar 4 m ahead of it along +y: the line of sight
    // points along −y whatever the motion (+y here).
    (entries[1].sensor_x_m, entries[1].sensor_y_m) = (20.0, 7.5);
    let request = PredictionRequest::from_history(&entries, 0.1);
    assert_eq!(request.sensor_m, DVec2::new(20.0, 7.5));
    let along = InputRotation::of(&request, InputFrame::LineOfSight);
    assert!((along.to_model(DVec2::new(0.0, -1.0)) - DVec2::X).length() < 1e-12);
    let motion = InputRotation::of(&request, InputFrame::LatestMotion);
    assert!((motion.to_model(DVec2::new(0.0, 1.0)) - DVec2::X).length() < 1e-12);
}

/// The answer of a contract fixture (`0.1 ·` the sum of all features on both axes, in its
/// input axes) for `request`, rotated back from `rotation`.
fn fixture_answer(request: &PredictionRequest, rotation: InputRotation) -> DVec2 {
    let mut sum = 0.0;
    for row in &request.features[..request.len] {
        let position = rotation.to_model(DVec2::new(f64::from(row[0]), f64::from(row[1])));
        sum += position.x + position.y + f64::from(row[2]) + f64::from(row[3]) + f64::from(row[4]);
    }
    rotation.from_model(DVec2::splat(0.1 * sum))
}

#[test]
fn a_request_goes_into_the_input_axes_its_model_names() {
    let mut entries = history(&[(0.00, 20.0, 3.0), (0.05, 20.4, 3.2), (0.10, 20.8, 3.5)]);
    (entries[2].sensor_x_m, entries[2].sensor_y_m) = (3.8, 0.7);
    let request = PredictionRequest::from_history(&entries, 0.15);
    for (file, frame) in [
        ("pr_line_of_sight.onnx", InputFrame::LineOfSight),
        ("pr_latest_motion.onnx", InputFrame::LatestMotion),
    ] {
        let mut predictor = OnnxPredictor::load(repo_path(&format!("tests/fixtures/{file}"))).unwrap();
        assert_eq!(predictor.model().input_frame(), frame, "{file}");
        let mut out = [None];
        predictor.predict(&[request], &mut out);
        let got = out[0].expect("the fixture answers").mean_m;
        let expected = fixture_answer(&request, InputRotation::of(&request, frame));
        assert!((got - expected).length() < 1e-4, "{file}: {got} vs {expected}");
        let other = match frame {
            InputFrame::LineOfSight => InputFrame::LatestMotion,
            InputFrame::LatestMotion => InputFrame::LineOfSight,
        };
        let wrong = fixture_answer(&request, InputRotation::of(&request, other));
        assert!((got - wrong).length() > 1e-2, "{file}: the axes make a difference ({got} vs {wrong})");
    }
}

#[test]
fn a_model_naming_an_unknown_input_frame_is_rejected() {
    let error = PrModel::load(repo_path("tests/fixtures/pr_unknown_input_frame.onnx")).unwrap_err();
    let ModelError::InputFrame { value, .. } = &error else { panic!("{error:?}") };
    assert_eq!(value, "sideways");
    let message = error.to_string();
    assert!(
        message.contains("pr_unknown_input_frame.onnx") && message.contains("primm.input_frame"),
        "{message}"
    );
}

#[test]
fn a_track_measured_in_the_previous_frame_gets_the_model_output_and_a_coasting_track_the_difference() {
    let mut model = model();
    let mut predictor = OnnxPredictor::load(repo_path("models/pr.onnx")).unwrap();
    let entries = history(&[(0.00, 20.0, 3.0), (0.03, 19.7, 3.0), (0.06, 19.4, 3.01), (0.09, 19.1, 3.0)]);
    // Measured in the previous frame (t = 0.09), predicting at t = 0.105.
    let fresh = PredictionRequest::from_history(&entries, 0.105).with_step_start(0.09);
    // Last measured at 0.09, previous frame at 0.12, predicting at 0.135.
    let coasting = PredictionRequest::from_history(&entries, 0.135).with_step_start(0.12);
    assert!(!fresh.step_starts_after_latest_measurement());
    assert!(coasting.step_starts_after_latest_measurement());
    let mut out = [None; 2];
    predictor.predict(&[fresh, coasting], &mut out);
    let fresh_expected = run_one(&mut model, &fresh);
    let coasting_expected = run_one(&mut model, &coasting) - run_one(&mut model, &coasting.at_time(0.12));
    assert!((out[0].unwrap().mean_m - fresh_expected).length() < 1e-6);
    assert!((out[1].unwrap().mean_m - coasting_expected).length() < 1e-6);
    // Telescoping: the coasted steps add up to the displacement from the latest measurement.
    let to_first_frame = PredictionRequest::from_history(&entries, 0.12).with_step_start(0.09);
    let mut first = [None];
    predictor.predict(&[to_first_frame], &mut first);
    let total = first[0].unwrap().mean_m + out[1].unwrap().mean_m;
    let direct = run_one(&mut model, &PredictionRequest::from_history(&entries, 0.135));
    assert!((total - direct).length() < 1e-4, "{total} vs {direct}");
    assert_eq!(predictor.stats().rows, 3 + 1);
}

#[test]
fn a_coasting_track_with_the_previous_frames_answer_runs_one_row_and_gets_the_same_displacement() {
    let mut predictor = OnnxPredictor::load(repo_path("models/pr.onnx")).unwrap();
    let entries = history(&[(0.00, 20.0, 3.0), (0.03, 19.7, 3.0), (0.06, 19.4, 3.01), (0.09, 19.1, 3.0)]);
    // Frame at 0.12: measured at 0.09, so one row, and the answer tells f(0.12).
    let first = PredictionRequest::from_history(&entries, 0.12).with_step_start(0.09);
    let mut out = [None];
    predictor.predict(&[first], &mut out);
    let first_answer = out[0].unwrap();
    assert_eq!(first_answer.from_latest_m, Some(first_answer.mean_m));
    let remembered = RememberedDisplacement::of(&first, &first_answer).unwrap();
    // Frame at 0.135, still not measured: with and without the remembered f(0.12).
    let coasting = PredictionRequest::from_history(&entries, 0.135).with_step_start(0.12);
    let mut without = [None];
    predictor.predict(&[coasting], &mut without);
    assert_eq!(predictor.stats().rows, 1 + 2);
    let mut with = [None];
    predictor.predict(&[coasting.with_remembered_step_start(Some(&remembered))], &mut with);
    assert_eq!(predictor.stats().rows, 1 + 2 + 1);
    let (without, with) = (without[0].unwrap(), with[0].unwrap());
    assert!((without.mean_m - with.mean_m).length() < 1e-5, "{} vs {}", without.mean_m, with.mean_m);
    assert_eq!(without.from_latest_m, with.from_latest_m);
    // A non-finite remembered value is not used: both rows run again.
    let mut broken = coasting;
    broken.step_start_displacement_m = Some(DVec2::new(f64::NAN, 0.0));
    let mut again = [None];
    predictor.predict(&[broken], &mut again);
    assert_eq!(predictor.stats().rows, 1 + 2 + 1 + 2);
    assert!((again[0].unwrap().mean_m - without.mean_m).length() < 1e-9);
}

#[test]
fn unusable_requests_get_none_and_the_rest_of_the_batch_is_predicted() {
    let mut predictor = OnnxPredictor::load(repo_path("models/pr.onnx")).unwrap();
    let entries = history(&[(0.0, 10.0, 1.0), (0.03, 10.1, 1.0)]);
    let good = PredictionRequest::from_history(&entries, 0.05);
    let empty = PredictionRequest::default();
    let mut broken = good;
    broken.features[0][2] = f32::NAN;
    let mut out = [Some(DVec2::ZERO.into()); 3];
    predictor.predict(&[good, empty, broken], &mut out);
    assert!(out[0].is_some());
    assert_eq!(out[1], None);
    assert_eq!(out[2], None);
    assert_eq!(predictor.stats().invalid_requests, 2);
    assert_eq!(predictor.stats().predictions, 1);
}

#[test]
fn a_missing_model_file_is_a_start_up_error_naming_the_file() {
    let path = repo_path("models/does_not_exist.onnx");
    let error = PrModel::load(&path).unwrap_err();
    assert!(matches!(error, ModelError::NotFound { .. }), "{error:?}");
    assert!(error.to_string().contains("does_not_exist.onnx"), "{error}");
}

#[test]
fn a_file_of_garbage_is_a_start_up_error_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("primm-onnx-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("garbage.onnx");
    std::fs::write(&path, b"\x08\x07this is not a protobuf model \xff\xfe\x00\x01 at all").unwrap();
    let error = PrModel::load(&path).unwrap_err();
    std::fs::remove_dir_all(&dir).ok();
    assert!(matches!(error, ModelError::NotOnnx { .. }), "{error:?}");
    assert!(error.to_string().contains("garbage.onnx"), "{error}");
}

#[test]
fn a_model_whose_output_names_no_tensor_is_an_error_and_not_a_panic() {
    // Found by the onnx_model_bytes fuzz target: tract 0.23 panicked ("no entry found for key")
    // on a graph output that no node produces.
    let bytes = std::fs::read(repo_path("fuzz/corpus/onnx_model_bytes/output_names_no_tensor.onnx")).unwrap();
    let source = primm_predictor::onnx::ModelSource::File(PathBuf::from("output_names_no_tensor.onnx"));
    let error = PrModel::from_bytes(&bytes, source).unwrap_err();
    assert!(matches!(error, ModelError::NotOnnx { .. }), "{error:?}");
    assert!(error.to_string().contains("output_names_no_tensor.onnx"), "{error}");
}

#[test]
fn a_directory_is_not_a_model() {
    let error = PrModel::load(repo_path("models")).unwrap_err();
    assert!(matches!(error, ModelError::Unreadable { .. }), "{error:?}");
}

#[test]
fn a_model_with_four_history_rows_is_rejected_with_the_shapes() {
    let error = PrModel::load(repo_path("tests/fixtures/pr_wrong_feature_shape.onnx")).unwrap_err();
    let message = error.to_string();
    let ModelError::Shape { name, .. } = &error else { panic!("{error:?}") };
    assert_eq!(name, "features");
    assert!(message.contains("pr_wrong_feature_shape.onnx"), "{message}");
    assert!(message.contains("[batch, 4, 5]"), "{message}");
    assert!(message.contains("[batch, 5, 5]"), "{message}");
}

#[test]
fn a_model_without_a_symbolic_batch_axis_is_rejected() {
    let error = PrModel::load(repo_path("tests/fixtures/pr_fixed_batch.onnx")).unwrap_err();
    let ModelError::Shape { name, found, .. } = &error else { panic!("{error:?}") };
    assert_eq!(name, "features");
    assert!(found.contains("[1, 5, 5]"), "{found}");
}

#[test]
fn a_model_with_the_wrong_output_shape_is_rejected() {
    let error = PrModel::load(repo_path("tests/fixtures/pr_wrong_output_shape.onnx")).unwrap_err();
    let ModelError::Shape { name, found, .. } = &error else { panic!("{error:?}") };
    assert_eq!(name, "displacement");
    assert!(found.contains('3'), "{found}");
    assert!(error.to_string().contains("pr_wrong_output_shape.onnx"));
}

#[test]
fn a_model_without_the_valid_input_is_rejected() {
    let error = PrModel::load(repo_path("tests/fixtures/pr_missing_valid_input.onnx")).unwrap_err();
    let ModelError::Signature { found, .. } = &error else { panic!("{error:?}") };
    assert!(found.contains("features"), "{found}");
    assert!(error.to_string().contains("pr_missing_valid_input.onnx"));
}

#[test]
fn the_model_is_loaded_for_learned_methods_only_and_is_built_in_when_no_file_is_given() {
    use primm_core::mode::Method;
    use primm_predictor::predictor_for;
    assert!(predictor_for(Method::Imm, Some(Path::new("/nonexistent.onnx")), InferenceEngine::Native).is_ok());
    let error =
        predictor_for(Method::PrImm, Some(Path::new("/nonexistent/pr.onnx")), InferenceEngine::Native)
            .err()
            .unwrap();
    assert!(error.to_string().contains("/nonexistent/pr.onnx"), "{error}");
    assert!(
        predictor_for(Method::Learned, Some(&repo_path("models/pr.onnx")), InferenceEngine::Native).is_ok()
    );
    assert!(predictor_for(Method::Learned, None, InferenceEngine::Native).is_ok());
}

#[test]
fn the_built_in_model_is_the_shipped_file_byte_for_byte() {
    let shipped = std::fs::read(repo_path("models/pr.onnx")).unwrap();
    assert_eq!(primm_predictor::DEFAULT_MODEL_ONNX, shipped.as_slice());
    let model = PrModel::embedded().unwrap();
    assert_eq!(model.source().to_string(), "models/pr.onnx (built in)");
}
