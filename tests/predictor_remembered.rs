//! A track that was not measured in the previous frame needs `f(t_{k−1})`, which the previous
//! frame's answer already told: the tracker remembers it per track and hands it back, so the
//! model runs one row for that track instead of two, and the tracks come out as when the model
//! predicts both rows (to float rounding of the time feature).

use glam::DVec2;
use primm_config::InferenceEngine;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use primm_core::track::TrackOutput;
use primm_core::tracker::Tracker;
use primm_predictor::load_predictor;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::collections::HashMap;

/// The shipped model on the native engine; records what it was asked and answered, and with
/// `forget` drops every remembered step start before the model sees the batch.
struct Recording {
    inner: Box<dyn DisplacementPredictor + Send>,
    forget: bool,
    batch: Vec<PredictionRequest>,
    /// f(t_k) answered per (anchor position and time, prediction time), as bits.
    answered: HashMap<[u64; 4], DVec2>,
    reused: usize,
    coasting: usize,
}

impl DisplacementPredictor for Recording {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.batch = requests.to_vec();
        for request in &mut self.batch {
            if request.step_starts_after_latest_measurement() {
                self.coasting += 1;
            }
            if let Some(known) = request.step_start_displacement_m {
                self.reused += 1;
                let key = key(request, request.step_start_s);
                assert_eq!(self.answered.get(&key), Some(&known), "the previous frame's answer comes back");
            }
            if self.forget {
                request.step_start_displacement_m = None;
            }
        }
        self.inner.submit(&self.batch);
    }
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        self.inner.collect(displacements);
        for (request, answer) in self.batch.iter().zip(displacements.iter()) {
            if let Some(from_latest) = answer.and_then(|answer| answer.from_latest_m) {
                let key = key(request, request.prediction_time_s);
                self.answered.insert(key, from_latest);
            }
        }
    }
}

fn key(request: &PredictionRequest, time_s: f64) -> [u64; 4] {
    let anchor = request.anchor_m;
    [anchor.x.to_bits(), anchor.y.to_bits(), request.anchor_time_s.to_bits(), time_s.to_bits()]
}

fn run(forget: bool, frames: &[Frame]) -> (Vec<Vec<TrackOutput>>, usize, usize) {
    let predictor = Recording {
        inner: Box::new(load_predictor(None, InferenceEngine::Native).unwrap()),
        forget,
        batch: Vec::new(),
        answered: HashMap::new(),
        reused: 0,
        coasting: 0,
    };
    let mut tracker =
        Tracker::with_predictor(Config::default().with_modes(Method::PrImm.modes()), predictor).unwrap();
    let outputs = frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect();
    (outputs, tracker.predictor().reused, tracker.predictor().coasting)
}

#[test]
fn coasting_tracks_reuse_the_previous_answer_and_the_tracks_come_out_as_with_two_rows() {
    // Four radars scan in turn, so most tracks coast in most frames.
    let generated = ScenarioGenerator::from_preset(Preset::ClutterTurning).generate(Split::Validation, 1);
    let frames: Vec<Frame> =
        generated.sequence.frames.iter().take(300).map(|frame| frame.to_frame().unwrap()).collect();
    let (remembered, reused, coasting) = run(false, &frames);
    let (two_rows, _, _) = run(true, &frames);
    assert!(coasting > 500, "{coasting} coasting requests");
    assert!(reused * 10 > coasting * 8, "{reused} of {coasting} coasting requests reused an answer");
    assert_eq!(remembered.len(), two_rows.len());
    for (k, (a, b)) in remembered.iter().zip(&two_rows).enumerate() {
        assert_eq!(a.len(), b.len(), "frame {k}: the same tracks");
        for (a, b) in a.iter().zip(b) {
            assert_eq!(a.id, b.id, "frame {k}");
            let difference = (a.position_m - b.position_m).length();
            assert!(difference < 1e-4, "frame {k}, track {}: {difference} m apart", a.id);
        }
    }
}
