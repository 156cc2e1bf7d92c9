//! The request's step start and its re-timing for the start-of-step prediction, and where the line
//! of sight of its latest measurement starts.

use primm_core::predictor::{HistoryEntry, PredictionRequest, MAX_HISTORY};

fn entries(times: &[f64]) -> Vec<HistoryEntry> {
    times
        .iter()
        .enumerate()
        .map(|(i, &t)| HistoryEntry {
            x_m: 10.0 + i as f64,
            y_m: -2.0 * i as f64,
            radial_velocity_mps: 1.5,
            rcs_dbsm: -3.0,
            timestamp_s: t,
            ..Default::default()
        })
        .collect()
}

#[test]
fn by_default_the_step_starts_at_the_latest_measurement() {
    let request = PredictionRequest::from_history(&entries(&[100.00, 100.03, 100.06]), 100.075);
    assert_eq!(request.step_start_s, 100.06);
    assert_eq!(request.anchor_time_s, 100.06);
    assert!(!request.step_starts_after_latest_measurement());
}

#[test]
fn the_step_start_is_kept_between_the_latest_measurement_and_the_prediction_time() {
    let request = PredictionRequest::from_history(&entries(&[1.0, 1.02]), 1.05);
    assert_eq!(request.with_step_start(0.5).step_start_s, request.step_start_s);
    assert_eq!(request.with_step_start(2.0).step_start_s, 1.05);
    let coasting = request.with_step_start(1.035);
    assert_eq!(coasting.step_start_s, 1.035);
    assert!(coasting.step_starts_after_latest_measurement());
    // The previous frame at the latest measurement's time: measured in the previous frame.
    assert!(!request.with_step_start(1.02).step_starts_after_latest_measurement());
}

#[test]
fn re_timing_shifts_only_the_time_feature_of_the_valid_rows() {
    let request =
        PredictionRequest::from_history(&entries(&[0.0, 0.03, 0.06, 0.09]), 0.12).with_step_start(0.105);
    let earlier = request.at_time(0.105);
    assert_eq!(earlier.prediction_time_s, 0.105);
    assert_eq!(earlier.len, request.len);
    assert_eq!(earlier.anchor_m, request.anchor_m);
    for row in 0..MAX_HISTORY {
        for feature in 0..4 {
            assert_eq!(earlier.features[row][feature], request.features[row][feature]);
        }
        if row < request.len {
            let expected = request.features[row][4] + 0.015;
            assert!((earlier.features[row][4] - expected).abs() < 1e-6, "row {row}");
        } else {
            assert_eq!(earlier.features[row], [0.0; 5]);
        }
    }
    assert_eq!(earlier.anchor_time_s, request.anchor_time_s);
}

#[test]
fn only_the_latest_five_measurements_are_used_and_positions_are_relative_to_the_latest() {
    let request = PredictionRequest::from_history(&entries(&[0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]), 0.65);
    assert_eq!(request.len, MAX_HISTORY);
    assert_eq!(request.features[MAX_HISTORY - 1][0], 0.0);
    assert_eq!(request.features[MAX_HISTORY - 1][1], 0.0);
    assert_eq!(request.features[0][0], -4.0);
    assert!((request.features[0][4] + 0.45).abs() < 1e-6);
}

#[test]
fn a_remembered_answer_serves_only_the_next_step_of_the_same_history() {
    use glam::DVec2;
    use primm_core::predictor::{Displacement, RememberedDisplacement};
    let history = entries(&[1.0, 1.02]);
    // The previous frame (t = 1.05) predicted f(1.05) from this history.
    let previous = PredictionRequest::from_history(&history, 1.05).with_step_start(1.035);
    let answer = Displacement::new(DVec2::new(0.1, 0.0)).with_from_latest(DVec2::new(0.3, -0.1));
    let remembered = RememberedDisplacement::of(&previous, &answer).unwrap();
    // This frame (t = 1.08), not measured since: f(1.05) is the step start's displacement.
    let next = PredictionRequest::from_history(&history, 1.08).with_step_start(1.05);
    assert_eq!(remembered.serves(&next), Some(DVec2::new(0.3, -0.1)));
    assert_eq!(
        next.with_remembered_step_start(Some(&remembered)).step_start_displacement_m,
        Some(DVec2::new(0.3, -0.1))
    );
    assert_eq!(next.with_remembered_step_start(None).step_start_displacement_m, None);
    // Another step start, a new measurement, another position or length: not the same.
    assert_eq!(
        remembered.serves(&PredictionRequest::from_history(&history, 1.11).with_step_start(1.08)),
        None
    );
    let measured = entries(&[1.0, 1.02, 1.05]);
    assert_eq!(
        remembered.serves(&PredictionRequest::from_history(&measured, 1.08).with_step_start(1.05)),
        None
    );
    let mut moved = history.clone();
    moved[1].x_m += 0.5;
    assert_eq!(remembered.serves(&PredictionRequest::from_history(&moved, 1.08).with_step_start(1.05)), None);
    assert_eq!(
        remembered.serves(&PredictionRequest::from_history(&history[1..], 1.08).with_step_start(1.05)),
        None
    );
    // Measured in the previous frame: the step starts at the measurement, nothing to reuse.
    let fresh = PredictionRequest::from_history(&measured, 1.08).with_step_start(1.05);
    assert!(!fresh.step_starts_after_latest_measurement());
    assert_eq!(RememberedDisplacement::of(&previous, &Displacement::new(DVec2::ONE)), None);
}

/// Records every request and answers none (the PR mode sits out).
struct Recording(std::sync::Arc<std::sync::Mutex<Vec<PredictionRequest>>>);

impl primm_core::predictor::DisplacementPredictor for Recording {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.0.lock().unwrap().extend_from_slice(requests);
    }
    fn collect(&mut self, displacements: &mut [Option<primm_core::predictor::Displacement>]) {
        displacements.fill(None);
    }
}

/// The requests of a PR-IMM tracker over the first frames of a generated default sequence, and
/// the ego pose of every frame time.
fn recorded_requests(
    frame: primm_core::coordinates::CoordinateFrame,
) -> (Vec<PredictionRequest>, Vec<(f64, primm_core::pose::EgoPose)>) {
    use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
    let generated = ScenarioGenerator::from_preset(Preset::Default).generate(Split::Validation, 1);
    let mut config =
        primm_core::config::Config::default().with_modes(primm_core::mode::Method::PrImm.modes());
    config.frame.tracking_frame = frame;
    let requests = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let mut tracker =
        primm_core::tracker::Tracker::with_predictor(config, Recording(requests.clone())).unwrap();
    let mut poses = Vec::new();
    for recorded in generated.sequence.frames.iter().take(300) {
        poses.push((recorded.timestamp_s, recorded.ego_pose.expect("generated frames carry a pose")));
        tracker.step(&recorded.to_frame().unwrap()).unwrap();
    }
    let requests = requests.lock().unwrap().clone();
    (requests, poses)
}

#[test]
fn every_request_starts_its_line_of_sight_at_the_radar_of_its_latest_measurement() {
    use primm_core::coordinates::{CoordinateFrame, CoordinatesConfig};
    let mounts: Vec<glam::DVec2> =
        CoordinatesConfig::default().sensors.iter().map(|m| m.position()).collect();
    // World frame: the mount of one of the radars, mapped with the pose of the measurement's frame.
    let (requests, poses) = recorded_requests(CoordinateFrame::World);
    assert!(requests.len() > 500, "only {} requests", requests.len());
    for request in &requests {
        let (_, pose) =
            poses.iter().find(|(t, _)| *t == request.anchor_time_s).expect("a frame at the anchor time");
        let distance = mounts
            .iter()
            .map(|m| (pose.point_to_world(*m) - request.sensor_m).length())
            .fold(f64::MAX, f64::min);
        assert!(
            distance < 1e-9,
            "radar at {} is no mount of the frame at {}",
            request.sensor_m,
            request.anchor_time_s
        );
        assert!((request.anchor_m - request.sensor_m).length() > 0.5, "a measurement at its radar");
    }
    // Vehicle frame: the mount itself.
    let (requests, _) = recorded_requests(CoordinateFrame::Vehicle);
    assert!(requests.len() > 500);
    for request in &requests {
        assert!(mounts.iter().any(|m| (*m - request.sensor_m).length() < 1e-12), "{}", request.sensor_m);
    }
}
