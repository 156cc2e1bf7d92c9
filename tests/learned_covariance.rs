//! The PR mode's per-track `Q_PR` from the predictor's own covariance (`eq:pr_cov`), the
//! constant of the paper as the alternative, and the check of covariances a predictor returns.

use crate::common;

use glam::{DMat2, DVec2};
use primm_core::config::{Config, LearnedProcessNoise};
use primm_core::gaussian::to_nalgebra;
use primm_core::imm::{Imm, ImmState};
use primm_core::mode::{Method, Mode};
use primm_core::motion::{ModeModels, PredictContext};
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use primm_core::tracker::Tracker;

/// The lane scene's exact displacements, each with the same covariance.
struct OracleWithCovariance {
    oracle: common::LaneOracle,
    covariance_m2: DMat2,
    requests: Vec<PredictionRequest>,
}

impl DisplacementPredictor for OracleWithCovariance {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.requests = requests.to_vec();
    }
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        self.oracle.predict(&self.requests, displacements);
        for answer in displacements.iter_mut().flatten() {
            answer.covariance_m2 = Some(self.covariance_m2);
        }
    }
}

fn isotropic(variance_m2: f64) -> DMat2 {
    DMat2::from_diagonal(DVec2::splat(variance_m2))
}

/// Mean PR mode probability of the confirmed tracks over the last half of a 200-frame run of
/// the lane scene, and the tracker's count of answers rejected for their covariance.
fn mean_learned_probability(config: Config, covariance_m2: DMat2) -> (f64, u64) {
    let objects = common::lanes(16);
    let predictor = OracleWithCovariance {
        oracle: common::LaneOracle { objects: objects.clone() },
        covariance_m2,
        requests: Vec::new(),
    };
    let mut tracker = Tracker::with_predictor(config, predictor).unwrap();
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, frame) in common::scene_frames(&objects, 200, 0.05, 0.3, 17).iter().enumerate() {
        tracker.step(frame).unwrap();
        if k >= 100 {
            for track in tracker.tracks() {
                sum += track.estimate.probabilities[Mode::Learned.index()];
                count += 1;
            }
        }
    }
    assert!(count > 1000, "the scene is tracked");
    (sum / count as f64, tracker.stats().learned_predictions_rejected_invalid_covariance)
}

#[test]
fn the_pr_prior_grows_by_the_predictors_covariance_when_it_gives_one_and_by_the_constant_otherwise() {
    let config = Config::default();
    let models = ModeModels::from_config(&config.classes.car);
    let imm = Imm::new(&config.imm);
    let mut state = ImmState::default();
    state.learned.covariance = to_nalgebra(&isotropic(0.2));
    state.probabilities = [0.25; 4];
    let learned_q = DMat2::from_cols(DVec2::new(0.03, 0.01), DVec2::new(0.01, 0.05));
    let context = |covariance| PredictContext {
        dt_s: 0.05,
        displacement_m: Some(DVec2::new(0.5, 0.0)),
        displacement_covariance_m2: covariance,
    };
    let with = imm.predict(&models, &state, &context(Some(to_nalgebra(&learned_q))));
    let without = imm.predict(&models, &state, &context(None));
    // Same mixed starting point; only Q_PR differs.
    let difference = with.state.learned.covariance - without.state.learned.covariance;
    let expected = to_nalgebra(&learned_q) - models.learned.process_noise_m2;
    assert!((difference - expected).abs().max() < 1e-12, "{difference} vs {expected}");
    assert_eq!(with.state.learned.mean, without.state.learned.mean);
}

#[test]
fn a_confident_predictor_keeps_more_pr_weight_than_an_unsure_one_and_the_constant_ignores_both() {
    let mut learned = Config::default().with_modes(Method::PrImm.modes());
    learned.predictor.process_noise = LearnedProcessNoise::Learned;
    learned.predictor.learned_process_noise_scale = 1.0;
    let (confident, _) = mean_learned_probability(learned.clone(), isotropic(1e-3));
    let (unsure, _) = mean_learned_probability(learned.clone(), isotropic(4.0));
    assert!(confident > unsure + 0.05, "confident {confident} vs unsure {unsure}");

    // The scale multiplies the covariance: an unsure answer scaled down is a confident one.
    let mut scaled = learned.clone();
    scaled.predictor.learned_process_noise_scale = 1e-3 / 4.0;
    let (scaled_unsure, _) = mean_learned_probability(scaled, isotropic(4.0));
    assert!((scaled_unsure - confident).abs() < 1e-9, "{scaled_unsure} vs {confident}");

    let mut constant = learned;
    constant.predictor.process_noise = LearnedProcessNoise::Constant;
    let (a, _) = mean_learned_probability(constant.clone(), isotropic(1e-3));
    let (b, _) = mean_learned_probability(constant, isotropic(4.0));
    assert_eq!(a, b, "with the constant Q_PR the predictor's covariance plays no part");
}

#[test]
fn answers_with_a_broken_covariance_are_rejected_counted_and_the_pr_mode_sits_out() {
    let config = Config::default().with_modes(Method::PrImm.modes());
    let indefinite = DMat2::from_cols(DVec2::new(1.0, 2.0), DVec2::new(2.0, 1.0));
    let (probability, rejected) = mean_learned_probability(config.clone(), indefinite);
    assert!(rejected > 1000, "{rejected} rejections");
    // Sitting out every frame, PR keeps only what the transition matrix and the floor give it.
    let (healthy, none_rejected) = mean_learned_probability(config, isotropic(1e-3));
    assert_eq!(none_rejected, 0);
    assert!(probability < healthy, "{probability} vs {healthy}");
}
