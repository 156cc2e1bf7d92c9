//! The fuzz targets' stand-in predictors answer as documented.

use glam::DVec2;
use primm_core::predictor::{DisplacementPredictor, HistoryEntry, PredictionRequest};
use primm_fuzz_targets::extrapolating_predictor::ExtrapolatingPredictor;
use primm_fuzz_targets::scripted_predictor::ScriptedPredictor;

fn request(positions: &[(f64, f64)]) -> PredictionRequest {
    let history: Vec<HistoryEntry> = positions
        .iter()
        .enumerate()
        .map(|(k, &(x_m, y_m))| HistoryEntry { x_m, y_m, timestamp_s: 0.05 * k as f64, ..Default::default() })
        .collect();
    PredictionRequest::from_history(&history, 0.05 * positions.len() as f64)
}

#[test]
fn scripted_predictor_answers_its_script_in_order_and_cycles() {
    let script =
        vec![Some(DVec2::new(1.0, 2.0).into()), None, Some(DVec2::new(f64::NAN, f64::INFINITY).into())];
    let mut predictor = ScriptedPredictor::new(script);
    let requests = [request(&[(0.0, 0.0)]); 4];
    let mut answers = [Some(DVec2::ZERO.into()); 4];
    predictor.predict(&requests, &mut answers);
    assert_eq!(answers[0], Some(DVec2::new(1.0, 2.0).into()));
    assert_eq!(answers[1], None);
    assert!(answers[2].is_some_and(|d| d.mean_m.x.is_nan() && d.mean_m.y == f64::INFINITY));
    assert_eq!(answers[3], Some(DVec2::new(1.0, 2.0).into()));
}

#[test]
fn scripted_predictor_with_an_empty_script_never_predicts() {
    let mut predictor = ScriptedPredictor::new(Vec::new());
    let mut answers = [Some(DVec2::ZERO.into()); 2];
    predictor.predict(&[request(&[(0.0, 0.0)]); 2], &mut answers);
    assert_eq!(answers, [None, None]);
}

#[test]
fn extrapolating_predictor_repeats_the_last_step_of_each_track() {
    let mut predictor = ExtrapolatingPredictor::default();
    let requests = [request(&[(10.0, 1.0), (10.5, 0.75)]), request(&[(3.0, 3.0)])];
    let mut answers = [None; 2];
    predictor.predict(&requests, &mut answers);
    let step = answers[0].expect("a track with two measurements gets a prediction").mean_m;
    assert!((step - DVec2::new(0.5, -0.25)).length() < 1e-6, "{step}");
    assert_eq!(answers[1], None);
}
