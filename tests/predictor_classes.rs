//! `predictor.classes`: the learned model predicts only the tracks of the classes named there.
//! A class left out gets no request, and its PR mode sits every step out exactly as after a
//! missed deadline; the tracks of the classes that keep PR come out bit for bit as before, on a
//! generated validation sequence with clutter and a turning ego vehicle, where car and
//! pedestrian tracks share every frame. The PR method alone ignores the list.

use primm_config::InferenceEngine;
use primm_core::config::Config;
use primm_core::measurement::{ClassSet, Frame, ObjectClass};
use primm_core::mode::Method;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use primm_core::track::TrackOutput;
use primm_core::tracker::Tracker;
use primm_predictor::load_predictor;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::collections::HashMap;

/// The shipped model on the native engine, counting the requests it is handed.
struct Counting {
    inner: Box<dyn DisplacementPredictor + Send>,
    requests: usize,
}

impl DisplacementPredictor for Counting {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.requests += requests.len();
        self.inner.submit(requests);
    }
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        self.inner.collect(displacements);
    }
}

/// A predictor whose every batch misses its deadline: it never answers.
struct AlwaysLate;

impl DisplacementPredictor for AlwaysLate {
    fn submit(&mut self, _requests: &[PredictionRequest]) {}
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
    }
}

/// The first frames of a generated validation sequence (clutter, turning ego vehicle).
fn frames() -> Vec<Frame> {
    let generated = ScenarioGenerator::from_preset(Preset::ClutterTurning).generate(Split::Validation, 0);
    generated.sequence.frames.iter().take(400).map(|frame| frame.to_frame().unwrap()).collect()
}

fn config(method: Method, classes: ClassSet) -> Config {
    let mut config = Config::default().with_modes(method.modes());
    config.predictor.classes = classes;
    config
}

/// Every frame's outputs of a tracker with `config` and the shipped model, and the number of
/// requests handed to the model.
fn run(config: Config, frames: &[Frame]) -> (Vec<Vec<TrackOutput>>, usize) {
    let mut tracker = Tracker::with_predictor(config, model()).unwrap();
    let outputs = frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect();
    (outputs, tracker.predictor().requests)
}

fn model() -> Counting {
    Counting { inner: Box::new(load_predictor(None, InferenceEngine::Native).unwrap()), requests: 0 }
}

/// The outputs of one class per frame, as text (equal exactly when every bit agrees), with each
/// track id replaced by its order of first appearance among that class's tracks: ids are
/// counted over all classes, so a class whose tracks change shifts the ids of the others.
fn of_class(outputs: &[Vec<TrackOutput>], class: ObjectClass) -> (String, usize) {
    let mut renumbered: HashMap<u64, u64> = HashMap::new();
    let mut count = 0;
    let frames: Vec<Vec<TrackOutput>> = outputs
        .iter()
        .map(|frame| {
            frame
                .iter()
                .filter(|output| output.class == class)
                .map(|output| {
                    let next = renumbered.len() as u64 + 1;
                    let mut output = *output;
                    output.id = *renumbered.entry(output.id).or_insert(next);
                    count += 1;
                    output
                })
                .collect()
        })
        .collect();
    (format!("{frames:?}"), count)
}

#[test]
fn leaving_cars_out_leaves_every_pedestrian_track_bit_for_bit_as_it_was() {
    let frames = frames();
    let (with_all, requests_all) = run(config(Method::PrImm, ClassSet::ALL), &frames);
    let without = ClassSet::ALL.without(ObjectClass::Car);
    let (without_cars, requests_without_cars) = run(config(Method::PrImm, without), &frames);

    let (pedestrians_all, pedestrian_outputs) = of_class(&with_all, ObjectClass::Pedestrian);
    let (pedestrians_without_cars, _) = of_class(&without_cars, ObjectClass::Pedestrian);
    assert!(
        pedestrian_outputs > 100,
        "only {pedestrian_outputs} pedestrian outputs: the test would prove little"
    );
    assert!(pedestrians_all == pedestrians_without_cars, "a pedestrian track changed when cars lost PR");

    // The switch did something: cars were predicted before and not after, and their tracks differ.
    let car_outputs = with_all.iter().flatten().filter(|o| o.class == ObjectClass::Car).count();
    assert!(car_outputs > 100, "only {car_outputs} car outputs");
    assert!(
        requests_without_cars < requests_all,
        "requests {requests_all} with cars vs {requests_without_cars} without"
    );
    assert!(
        of_class(&with_all, ObjectClass::Car).0 != of_class(&without_cars, ObjectClass::Car).0,
        "car tracks came out the same with and without their learned predictions"
    );
}

#[test]
fn a_class_left_out_is_tracked_exactly_as_after_a_missed_deadline() {
    let frames = frames();
    // Every class left out, the model loaded: the same as a model that misses every deadline.
    let (outputs_left_out, requests) = run(config(Method::PrImm, ClassSet::EMPTY), &frames);
    let mut late = Tracker::with_predictor(config(Method::PrImm, ClassSet::ALL), AlwaysLate).unwrap();
    let outputs_late: Vec<Vec<TrackOutput>> =
        frames.iter().map(|frame| late.step(frame).unwrap().to_vec()).collect();
    assert_eq!(requests, 0, "a left-out class was still requested");
    assert!(outputs_left_out.iter().map(Vec::len).sum::<usize>() > 200);
    assert!(
        format!("{outputs_left_out:?}") == format!("{outputs_late:?}"),
        "leaving every class out differs from missing every deadline"
    );
    // A tracker left without PR counts no missing prediction (nothing was asked for).
    let mut tracker = Tracker::with_predictor(config(Method::PrImm, ClassSet::EMPTY), model()).unwrap();
    for frame in &frames[..50] {
        tracker.step(frame).unwrap();
    }
    assert_eq!(tracker.stats().learned_predictions_missing, 0);
}

#[test]
fn the_pr_method_alone_predicts_every_class_whatever_the_list() {
    let frames = &frames()[..150];
    let (with_list, requests) = run(config(Method::Learned, ClassSet::EMPTY), frames);
    let (with_all, _) = run(config(Method::Learned, ClassSet::ALL), frames);
    assert!(requests > 0);
    assert!(format!("{with_list:?}") == format!("{with_all:?}"));
}
