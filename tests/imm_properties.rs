//! Property tests of the position-space IMM: covariances stay symmetric positive semi-definite,
//! mode probabilities stay normalised above the floor, mixing and the position write-back do
//! what `eq:mixed_pos` … `eq:reconstructed_cov` say.

use crate::common;

use glam::{DMat2, DVec2};
use nalgebra::{Matrix2, SMatrix, SVector};
use primm_core::config::Config;
use primm_core::gaussian::index::{OTHERS, X, Y};
use primm_core::gaussian::{replace_position, Gaussian, PositionEstimate};
use primm_core::imm::{mix_positions, Imm, ImmState};
use primm_core::mode::{Mode, ModeSet};
use primm_core::motion::constant_velocity::index as cv;
use primm_core::motion::{ModeModels, PredictContext};
use proptest::prelude::*;

/// Positive semi-definite up to rounding: a Cholesky factorisation exists after a shift of
/// 1e-9 times the largest entry.
fn is_positive_semi_definite<const N: usize>(m: &SMatrix<f64, N, N>) -> bool {
    let scale = m.abs().max().max(1e-12);
    nalgebra::Cholesky::new(m + SMatrix::<f64, N, N>::identity() * (scale * 1e-9)).is_some()
}

fn assert_psd<const N: usize>(m: &SMatrix<f64, N, N>, what: &str) {
    assert_eq!(*m, m.transpose(), "{what} is not symmetric");
    assert!(m.iter().all(|v| v.is_finite()), "{what} is not finite");
    assert!(is_positive_semi_definite(m), "{what} is not positive semi-definite: {m}");
}

fn spd<const N: usize>(entries: &[f64], diagonal: f64) -> SMatrix<f64, N, N> {
    let a = SMatrix::<f64, N, N>::from_iterator(entries.iter().copied().cycle().take(N * N));
    a * a.transpose() + SMatrix::<f64, N, N>::identity() * diagonal
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]

    #[test]
    fn covariances_stay_positive_semi_definite_and_probabilities_normalised_over_thousands_of_cycles(
        seed in 0u64..10_000,
        class in 0usize..2,
        missing_predictions in 0usize..4,
    ) {
        let config = Config::default();
        let class_config = if class == 0 { &config.classes.car } else { &config.classes.pedestrian };
        let models = ModeModels::from_config(class_config);
        let imm = Imm::new(&config.imm);
        let floor = config.imm.mode_probability_floor;
        let mut rng = common::rng(seed);
        let mut state = imm.initiate(&models, &common::measurement(25.0, -3.0, 4.0));
        let mut position = DVec2::new(25.0, -3.0);
        for step in 0..2500 {
            let dt = 0.005 + 0.2 * (common::standard_normal(&mut rng).abs().min(3.0) / 3.0);
            let velocity = DVec2::new(common::standard_normal(&mut rng) * 8.0, common::standard_normal(&mut rng) * 8.0);
            position += velocity * dt;
            let displacement = if step % 4 < missing_predictions { None } else {
                Some(velocity * dt + DVec2::new(common::standard_normal(&mut rng), common::standard_normal(&mut rng)) * 0.3)
            };
            let prior = imm.predict(&models, &state, &PredictContext { dt_s: dt, displacement_m: displacement, displacement_covariance_m2: None });
            // Occasionally coast, occasionally a wild outlier.
            state = if step % 17 == 0 {
                imm.coast(&prior)
            } else {
                let noise = if step % 29 == 0 { 40.0 } else { 0.4 };
                let z = position + DVec2::new(common::standard_normal(&mut rng), common::standard_normal(&mut rng)) * noise;
                imm.update(&models, &prior, z).expect("update succeeds")
            };
            assert_psd(&state.learned.covariance, "PR covariance");
            assert_psd(&state.constant_velocity.covariance, "CV covariance");
            assert_psd(&state.constant_acceleration.covariance, "CA covariance");
            assert_psd(&state.coordinated_turn.covariance, "CT covariance");
            let sum: f64 = state.probabilities.iter().sum();
            prop_assert!((sum - 1.0).abs() < 1e-12, "probabilities sum to {}", sum);
            for mode in Mode::ALL {
                prop_assert!(state.probabilities[mode.index()] >= floor * (1.0 - 1e-12), "{:?} below the floor", mode);
            }
            // Re-anchor the truth now and then so that the filter stays near it.
            if step % 200 == 0 { position = DVec2::new(state.constant_velocity.mean[cv::X], state.constant_velocity.mean[cv::Y]); }
        }
    }

    #[test]
    fn mixing_identical_mode_positions_leaves_the_position_unchanged(
        x in -100.0f64..100.0, y in -100.0f64..100.0,
        weights in proptest::array::uniform4(0.01f64..1.0),
        entries in proptest::collection::vec(-2.0f64..2.0, 36),
    ) {
        let config = Config::default();
        let models = ModeModels::from_config(&config.classes.car);
        let imm = Imm::new(&config.imm);
        let mut state: ImmState = imm.initiate(&models, &common::measurement(x, y, 1.0));
        state.constant_velocity.covariance = spd::<4>(&entries, 0.1);
        state.constant_acceleration.covariance = spd::<6>(&entries[3..], 0.2);
        state.coordinated_turn.covariance = spd::<5>(&entries[5..], 0.3);
        let sum: f64 = weights.iter().sum();
        let weights = weights.map(|w| w / sum);
        let mixed = mix_positions(&state, ModeSet::ALL, &weights);
        prop_assert!((mixed.mean - DVec2::new(x, y)).length() < 1e-12);
        // No spread term: the mixed covariance is the weighted mean of the covariances.
        let mut expected = DMat2::ZERO;
        for mode in Mode::ALL { expected += state.position(mode).covariance * weights[mode.index()]; }
        prop_assert!((mixed.covariance - expected).to_cols_array().iter().all(|v| v.abs() < 1e-12));
    }

    #[test]
    fn replacing_the_position_preserves_the_conditional_distribution_of_the_other_states(
        entries in proptest::collection::vec(-2.0f64..2.0, 36),
        mean in proptest::collection::vec(-10.0f64..10.0, 6),
        new_mean in proptest::array::uniform2(-10.0f64..10.0),
        new_entries in proptest::array::uniform4(-1.0f64..1.0),
    ) {
        let p = spd::<6>(&entries, 0.05);
        let mut g = Gaussian::new(SVector::<f64, 6>::from_column_slice(&mean), p);
        let before = g;
        let a = Matrix2::new(new_entries[0], new_entries[1], new_entries[2], new_entries[3]);
        let p_bar = a * a.transpose() + Matrix2::identity() * 0.01;
        let mixed = PositionEstimate { mean: DVec2::new(new_mean[0], new_mean[1]), covariance: primm_core::gaussian::to_glam(&p_bar) };
        replace_position(&mut g, &mixed);

        // B = P_hp P_pp⁻¹ and C = P_hh − B P_pp Bᵀ, before and after.
        let conditional = |p: &SMatrix<f64, 6, 6>| {
            let p_pp = p.fixed_view::<2, 2>(X, X).into_owned();
            let p_hp = p.fixed_view::<4, 2>(OTHERS, X).into_owned();
            let p_hh = p.fixed_view::<4, 4>(OTHERS, OTHERS).into_owned();
            let b = p_hp * p_pp.try_inverse().unwrap();
            (b, p_hh - b * p_pp * b.transpose())
        };
        let (b_before, c_before) = conditional(&before.covariance);
        let (b_after, c_after) = conditional(&g.covariance);
        let scale = before.covariance.abs().max();
        prop_assert!((b_before - b_after).abs().max() < 1e-7 * (1.0 + b_before.abs().max()));
        prop_assert!((c_before - c_after).abs().max() < 1e-7 * scale);
        // The position block is the mixed one; the non-position mean is the mode's own.
        prop_assert!((g.covariance.fixed_view::<2, 2>(X, X) - p_bar).abs().max() < 1e-12);
        prop_assert_eq!(g.mean[X], new_mean[0]);
        prop_assert_eq!(g.mean[Y], new_mean[1]);
        prop_assert_eq!(g.mean.fixed_rows::<4>(OTHERS).into_owned(), before.mean.fixed_rows::<4>(OTHERS).into_owned());
        // And the full covariance stays positive semi-definite.
        prop_assert!(nalgebra::Cholesky::new(g.covariance + SMatrix::<f64, 6, 6>::identity() * 1e-9 * scale).is_some());
    }

    #[test]
    fn the_floor_keeps_every_mode_alive_and_probabilities_normalised(
        prior in proptest::array::uniform4(0.0f64..1.0),
        log_likelihood in proptest::array::uniform4(-5000.0f64..10.0),
    ) {
        let config = Config::default();
        let imm = Imm::new(&config.imm);
        let sum: f64 = prior.iter().sum::<f64>().max(1e-9);
        let prior = prior.map(|p| p / sum);
        let mu = imm.updated_probabilities(&prior, ModeSet::ALL, &log_likelihood);
        prop_assert!((mu.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for p in mu { prop_assert!(p >= config.imm.mode_probability_floor * (1.0 - 1e-12)); }
    }
}

#[test]
fn tempered_mode_update_follows_the_formula_of_the_paper() {
    let mut config = Config::default();
    config.imm.mode_probability_floor = 0.0;
    let imm = Imm::new(&config.imm);
    let prior = [0.1, 0.2, 0.3, 0.4];
    let log_likelihood = [-1.0, -3.0, -0.5, -10.0];
    let mu = imm.updated_probabilities(&prior, ModeSet::ALL, &log_likelihood);
    let tau = config.imm.likelihood_temperature;
    let weights: Vec<f64> = (0..4).map(|i| log_likelihood[i].exp().powf(tau) * prior[i]).collect();
    let total: f64 = weights.iter().sum();
    for i in 0..4 {
        assert!((mu[i] - weights[i] / total).abs() < 1e-14);
    }
}

#[test]
fn a_mode_without_prediction_keeps_its_prior_probability() {
    let config = Config::default();
    let imm = Imm::new(&config.imm);
    let prior = [0.4, 0.2, 0.3, 0.1];
    let available = ModeSet::ALL.without(Mode::Learned);
    let mu = imm.updated_probabilities(&prior, available, &[0.0, -1.0, -2.0, -3.0]);
    assert_eq!(mu[Mode::Learned.index()], 0.4);
    assert!((mu.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn prior_and_mixing_probabilities_follow_the_transition_matrix() {
    let config = Config::default();
    let imm = Imm::new(&config.imm);
    let mu = [0.1, 0.5, 0.3, 0.1];
    let c = imm.prior_probabilities(&mu);
    let pi = config.imm.transition;
    for j in 0..4 {
        let expected: f64 = (0..4).map(|i| pi[i][j] * mu[i]).sum();
        assert!((c[j] - expected).abs() < 1e-15);
        let beta = imm.mixing_probabilities(&mu, &c, Mode::ALL[j]);
        assert!((beta.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for i in 0..4 {
            assert!((beta[i] - pi[i][j] * mu[i] / c[j]).abs() < 1e-15);
        }
    }
}
