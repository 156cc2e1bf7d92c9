//! Mixing and fusion with modes whose means disagree: the covariance must include the spread of
//! the mode means around the weighted mean, `Σ wᵢ (Pᵢ + (pᵢ − p̄)(pᵢ − p̄)ᵀ)`.
//!
//! The paper writes the spread term for input mixing (`eq:mixed_pos_cov`, Section III-D); primm
//! uses the same moment-matched covariance for the fused prior (`eq:prior_fusion`, weights `c`)
//! and the fused posterior (`eq:posterior_fusion`, weights `μ`), whose means the paper defines.
//! Every expected value below is computed in this file from plain arrays, from a hand-built
//! [`ImmState`] whose four modes sit metres apart, so that leaving out the spread term (or
//! using the wrong weights) changes the covariance by far more than the tolerance.

use glam::DVec2;
use nalgebra::{SMatrix, SVector};
use primm_core::config::Config;
use primm_core::gaussian::{Gaussian, PositionEstimate};
use primm_core::imm::{mix_positions, Imm, ImmPrior, ImmState};
use primm_core::mode::{Mode, ModeSet, MODE_COUNT};
use primm_core::motion::ModeModels;

/// A position `[x, y]` and its covariance, as plain arrays.
#[derive(Debug, Clone, Copy)]
struct PlainPosition {
    mean: [f64; 2],
    covariance: [[f64; 2]; 2],
}

/// Each mode's position in the hand-built state, in mode order (PR, CV, CA, CT): means up to
/// 9 m apart, covariances of different size and orientation.
const POSITIONS: [PlainPosition; MODE_COUNT] = [
    PlainPosition { mean: [10.0, 2.0], covariance: [[0.20, 0.03], [0.03, 0.10]] },
    PlainPosition { mean: [14.0, -1.0], covariance: [[0.50, -0.10], [-0.10, 0.40]] },
    PlainPosition { mean: [7.5, 4.0], covariance: [[1.20, 0.30], [0.30, 0.90]] },
    PlainPosition { mean: [12.0, 8.0], covariance: [[0.30, 0.00], [0.00, 0.60]] },
];

/// A Gaussian of size `N` with the given position block and other states that differ per mode
/// (velocities, accelerations, turn rate), correlated with the position.
fn gaussian<const N: usize>(position: &PlainPosition) -> Gaussian<N> {
    let mut mean = SVector::<f64, N>::from_fn(|i, _| 0.5 + i as f64);
    mean[0] = position.mean[0];
    mean[1] = position.mean[1];
    let mut covariance = SMatrix::<f64, N, N>::identity() * 2.0;
    for row in 0..2 {
        for column in 0..2 {
            covariance[(row, column)] = position.covariance[row][column];
        }
    }
    if N > 2 {
        // A position-velocity correlation, kept small enough for positive definiteness.
        covariance[(0, 2)] = 0.05;
        covariance[(2, 0)] = 0.05;
    }
    Gaussian::new(mean, covariance)
}

/// The hand-built state with `probabilities`.
fn state(probabilities: [f64; MODE_COUNT]) -> ImmState {
    ImmState {
        learned: gaussian(&POSITIONS[0]),
        constant_velocity: gaussian(&POSITIONS[1]),
        constant_acceleration: gaussian(&POSITIONS[2]),
        coordinated_turn: gaussian(&POSITIONS[3]),
        probabilities,
        learned_velocity_mps: DVec2::new(3.0, 0.0),
    }
}

/// `Σ wᵢ pᵢ` and `Σ wᵢ (Pᵢ + (pᵢ − p̄)(pᵢ − p̄)ᵀ)` over the modes with a weight (weights
/// summing to 1), written out on arrays.
fn moment_matched(positions: &[PlainPosition; MODE_COUNT], weights: &[f64; MODE_COUNT]) -> PlainPosition {
    let mut mean = [0.0; 2];
    for (position, weight) in positions.iter().zip(weights) {
        mean[0] += weight * position.mean[0];
        mean[1] += weight * position.mean[1];
    }
    let mut covariance = [[0.0; 2]; 2];
    for (position, weight) in positions.iter().zip(weights) {
        let spread = [position.mean[0] - mean[0], position.mean[1] - mean[1]];
        for row in 0..2 {
            for column in 0..2 {
                covariance[row][column] +=
                    weight * (position.covariance[row][column] + spread[row] * spread[column]);
            }
        }
    }
    PlainPosition { mean, covariance }
}

/// `Σ wᵢ Pᵢ`: the covariance without the spread term.
fn without_spread(positions: &[PlainPosition; MODE_COUNT], weights: &[f64; MODE_COUNT]) -> [[f64; 2]; 2] {
    let mut covariance = [[0.0; 2]; 2];
    for (position, weight) in positions.iter().zip(weights) {
        for row in 0..2 {
            for column in 0..2 {
                covariance[row][column] += weight * position.covariance[row][column];
            }
        }
    }
    covariance
}

/// `weights` kept on `modes` and divided by their sum.
fn restricted(weights: &[f64; MODE_COUNT], modes: ModeSet) -> [f64; MODE_COUNT] {
    let sum: f64 = Mode::ALL.iter().filter(|m| modes.contains(**m)).map(|m| weights[m.index()]).sum();
    let mut result = [0.0; MODE_COUNT];
    for mode in Mode::ALL.iter().filter(|m| modes.contains(**m)) {
        result[mode.index()] = weights[mode.index()] / sum;
    }
    result
}

fn assert_close(actual: &PositionEstimate, expected: &PlainPosition, what: &str) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    let mean_agrees = close(actual.mean.x, expected.mean[0]) && close(actual.mean.y, expected.mean[1]);
    let c = &actual.covariance;
    let covariance_agrees = close(c.x_axis.x, expected.covariance[0][0])
        && close(c.y_axis.x, expected.covariance[0][1])
        && close(c.x_axis.y, expected.covariance[1][0])
        && close(c.y_axis.y, expected.covariance[1][1]);
    assert!(mean_agrees && covariance_agrees, "{what}: got {actual:?}, the formula gives {expected:?}");
}

/// The spread term of these weights adds more than 0.1 m² to the variance along x or y, ten
/// orders of magnitude above the tolerance: a test that passes with it would fail without it.
fn assert_spread_matters(weights: &[f64; MODE_COUNT]) {
    let with = moment_matched(&POSITIONS, weights).covariance;
    let without = without_spread(&POSITIONS, weights);
    let added = (with[0][0] - without[0][0]).max(with[1][1] - without[1][1]);
    assert!(added > 0.1, "the spread adds only {added} m²: the modes do not disagree enough");
}

fn plain(estimate: &PositionEstimate) -> PlainPosition {
    PlainPosition {
        mean: [estimate.mean.x, estimate.mean.y],
        covariance: [
            [estimate.covariance.x_axis.x, estimate.covariance.y_axis.x],
            [estimate.covariance.x_axis.y, estimate.covariance.y_axis.y],
        ],
    }
}

#[test]
fn mixed_position_covariance_includes_the_spread_of_disagreeing_means() {
    let state = state([0.25; MODE_COUNT]);
    for weights in [[0.1, 0.2, 0.3, 0.4], [0.7, 0.1, 0.1, 0.1], [0.05, 0.45, 0.45, 0.05]] {
        assert_spread_matters(&weights);
        let mixed = mix_positions(&state, ModeSet::ALL, &weights);
        assert_close(&mixed, &moment_matched(&POSITIONS, &weights), &format!("weights {weights:?}"));
    }
    // Over three modes, the fourth mode's position must not enter.
    let modes = ModeSet::ALL.without(Mode::Learned);
    let weights = restricted(&[0.0, 0.2, 0.3, 0.5], modes);
    let mixed = mix_positions(&state, modes, &weights);
    assert_close(&mixed, &moment_matched(&POSITIONS, &weights), "without PR");
}

#[test]
fn each_mode_starts_its_prediction_from_the_mix_of_eq_mixed_pos_cov() {
    // With Δt = 0 every physics prediction is the identity (F = I, Q = 0) and PR's prediction
    // waits for its displacement, so after the first half of the prediction each mode's
    // position is exactly its mixed starting point `p̄_j`, `P̄ᵖ_j` (eq:mixed_pos,
    // eq:mixed_pos_cov) with β from eq:mixing_prob.
    let config = Config::default();
    let models = ModeModels::from_config(&config.classes.car);
    let imm = Imm::new(&config.imm);
    let mu = [0.1, 0.2, 0.3, 0.4];
    let posterior = state(mu);
    let mut prior = ImmPrior::default();
    imm.predict_physics_into(&models, &posterior, 0.0, &mut prior);
    let pi = imm.transition();
    for to in Mode::ALL {
        let c: f64 = Mode::ALL.iter().map(|from| pi[from.index()][to.index()] * mu[from.index()]).sum();
        let beta: [f64; MODE_COUNT] = std::array::from_fn(|from| pi[from][to.index()] * mu[from] / c);
        assert_spread_matters(&beta);
        let expected = moment_matched(&POSITIONS, &beta);
        assert_close(&prior.state.position(to), &expected, &format!("mixed start of {to:?}"));
        // The mode kept its own other states: the mixing wrote the position only.
        let velocity = prior.state.velocity(to);
        let own = posterior.velocity(to);
        if to != Mode::Learned {
            assert!((velocity - own).length() < 1e-12, "{to:?}: velocity {velocity} vs own {own}");
        }
    }
}

#[test]
fn the_fused_prior_covariance_includes_the_spread_of_the_mode_priors() {
    let config = Config::default();
    let models = ModeModels::from_config(&config.classes.car);
    let imm = Imm::new(&config.imm);
    let c = [0.1, 0.2, 0.3, 0.4];
    let displacement = DVec2::new(1.5, -0.5);
    let q_pr = models.learned.process_noise_m2;
    for with_displacement in [true, false] {
        // A prior whose physics modes are already predicted (the hand-built positions) and whose
        // PR mode waits at its starting point.
        let mut prior = ImmPrior { state: state(c), available: ModeSet::ALL, ..ImmPrior::default() };
        let given = with_displacement.then_some(displacement.into());
        imm.complete_prior_in_place(&models, &mut prior, 0.05, given);

        let mut positions = POSITIONS;
        let mut modes = ModeSet::ALL;
        // eq:pr_cov: Q_PR widens PR's prior in any case; eq:pr_prior: the displacement, when
        // there is one, moves its mean, otherwise PR sits the fusion out.
        let pr = &mut positions[Mode::Learned.index()];
        for row in 0..2 {
            for column in 0..2 {
                pr.covariance[row][column] += q_pr[(row, column)];
            }
        }
        if with_displacement {
            pr.mean = [pr.mean[0] + displacement.x, pr.mean[1] + displacement.y];
        } else {
            modes = modes.without(Mode::Learned);
        }
        assert_eq!(prior.available, modes);
        let weights = restricted(&c, modes);
        assert_spread_matters(&weights);
        let expected = moment_matched(&positions, &weights);
        assert_close(&prior.fused, &expected, &format!("fused prior, displacement {given:?}"));
        // Sitting out, the PR mode takes the fused prior of the others as its own.
        let pr_prior = if with_displacement { &positions[0] } else { &expected };
        assert_close(&prior.state.position(Mode::Learned), pr_prior, "PR prior");
        // The fused prior is the spread-aware moment match, not a plain weighted covariance.
        let fused = plain(&prior.fused);
        assert!(fused.covariance[0][0] > without_spread(&positions, &weights)[0][0] + 1.0);
    }
}

#[test]
fn the_fused_posterior_covariance_includes_the_spread_of_the_mode_posteriors() {
    let config = Config::default();
    let imm = Imm::new(&config.imm);
    for mu in [[0.1, 0.2, 0.3, 0.4], [0.4, 0.3, 0.2, 0.1], [0.01, 0.01, 0.97, 0.01]] {
        let posterior = state(mu);
        for modes in [ModeSet::ALL, ModeSet::ALL.without(Mode::Learned)] {
            let weights = restricted(&mu, modes);
            let fused = imm.fuse_posterior(&posterior, modes);
            assert_close(&fused, &moment_matched(&POSITIONS, &weights), &format!("μ {mu:?} over {modes:?}"));
        }
    }
    // With the weights spread out, the disagreement dominates the fused covariance.
    assert_spread_matters(&[0.1, 0.2, 0.3, 0.4]);
}
