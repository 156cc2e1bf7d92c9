//! The shipped PR model is useful: on generated validation sequences (never seen in training),
//! its one-step displacement is far closer to the truth than a constant-velocity extrapolation
//! from the last two measurements, and closer than predicting no motion at all. Positions are
//! taken in the world frame (each frame's ego pose applied), where the tracker runs the model.

use glam::DVec2;
use primm_core::measurement::ObjectClass;
use primm_core::predictor::{DisplacementPredictor, HistoryEntry, PredictionRequest, MAX_HISTORY};
use primm_predictor::onnx::OnnxPredictor;
use primm_sim::io::Sequence;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::collections::BTreeMap;
use std::path::Path;

/// One object's measurements in time order: (history entry, true centre), in the world frame.
fn objects(sequence: &Sequence) -> BTreeMap<u64, Vec<(HistoryEntry, DVec2, ObjectClass)>> {
    let mut objects: BTreeMap<u64, Vec<_>> = BTreeMap::new();
    // The generator mounts the radars where the tracker's default configuration has them.
    let coordinates = primm_core::coordinates::CoordinatesConfig::default();
    for frame in &sequence.frames {
        let pose = frame.ego_pose.expect("generated frames carry the ego pose");
        for recorded in &frame.measurements {
            let (Some(id), Some(truth)) = (recorded.measurement.ground_truth_id, recorded.true_position)
            else {
                continue;
            };
            let m = &recorded.measurement;
            let position = pose.point_to_world(m.position());
            let mount = m
                .sensor_id
                .and_then(|id| coordinates.sensor(id))
                .map_or(DVec2::ZERO, |mount| mount.position());
            let sensor = pose.point_to_world(mount);
            objects.entry(id).or_default().push((
                HistoryEntry {
                    x_m: position.x,
                    y_m: position.y,
                    radial_velocity_mps: m.radial_velocity_mps,
                    rcs_dbsm: m.rcs_dbsm,
                    timestamp_s: frame.timestamp_s,
                    sensor_x_m: sensor.x,
                    sensor_y_m: sensor.y,
                },
                pose.point_to_world(truth),
                m.class,
            ));
        }
    }
    objects
}

#[derive(Default)]
struct Errors {
    squared: f64,
    count: u64,
}

impl Errors {
    fn push(&mut self, error: DVec2) {
        self.squared += error.length_squared();
        self.count += 1;
    }
    fn rmse(&self) -> f64 {
        (self.squared / self.count as f64).sqrt()
    }
}

#[test]
fn the_model_predicts_the_next_displacement_far_better_than_constant_velocity_from_two_measurements() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pr.onnx");
    let mut predictor = OnnxPredictor::load(&path).unwrap();
    let generator = ScenarioGenerator::from_preset(Preset::Default);
    let (mut model, mut two_point, mut still) = (Errors::default(), Errors::default(), Errors::default());
    let mut per_class: BTreeMap<&str, (Errors, Errors)> = BTreeMap::new();
    for index in 0..3 {
        let generated = generator.generate(Split::Validation, index);
        for track in objects(&generated.sequence).values() {
            let mut requests = Vec::new();
            let mut cases = Vec::new();
            // Predict measurement j+1 from the history ending at j (j >= 1, so that the
            // two-measurement extrapolation exists for every case compared).
            for j in 1..track.len() - 1 {
                let start = (j + 1).saturating_sub(MAX_HISTORY);
                let history: Vec<HistoryEntry> =
                    track[start..=j].iter().map(|(entry, _, _)| *entry).collect();
                let next_time = track[j + 1].0.timestamp_s;
                if next_time - track[j].0.timestamp_s > 0.2 {
                    continue;
                }
                requests.push(PredictionRequest::from_history(&history, next_time));
                cases.push(j);
            }
            let mut predicted = vec![None; requests.len()];
            predictor.predict(&requests, &mut predicted);
            for (&j, prediction) in cases.iter().zip(&predicted) {
                let truth = track[j + 1].1 - track[j].1;
                let (previous, latest, next) = (&track[j - 1].0, &track[j].0, &track[j + 1].0);
                let velocity = DVec2::new(latest.x_m - previous.x_m, latest.y_m - previous.y_m)
                    / (latest.timestamp_s - previous.timestamp_s);
                let extrapolated = velocity * (next.timestamp_s - latest.timestamp_s);
                let prediction = prediction.expect("every request is answered").mean_m;
                model.push(prediction - truth);
                two_point.push(extrapolated - truth);
                still.push(-truth);
                let class = if track[j].2 == ObjectClass::Car { "car" } else { "pedestrian" };
                let entry = per_class.entry(class).or_default();
                entry.0.push(prediction - truth);
                entry.1.push(-truth);
            }
        }
    }
    println!(
        "one-step displacement RMSE over {} cases: PR {:.3} m, CV from the last two measurements {:.3} m, no motion {:.3} m",
        model.count,
        model.rmse(),
        two_point.rmse(),
        still.rmse()
    );
    for (class, (pr, zero)) in &per_class {
        println!("  {class}: PR {:.3} m, no motion {:.3} m ({} cases)", pr.rmse(), zero.rmse(), pr.count);
    }
    assert!(model.count > 2_000, "only {} cases", model.count);
    assert!(model.rmse() < 0.25 * two_point.rmse(), "PR {} vs CV {}", model.rmse(), two_point.rmse());
    assert!(model.rmse() < 0.75 * still.rmse(), "PR {} vs no motion {}", model.rmse(), still.rmse());
}
