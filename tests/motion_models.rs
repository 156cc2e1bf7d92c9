//! The motion models' mathematics: CT's small-turn limit and Jacobian, CV convergence, and the
//! Kalman update against the textbook closed form.

use crate::common;

use glam::DVec2;
use nalgebra::{Matrix2, Matrix4, SMatrix, Vector4};
use primm_core::gaussian::{kalman_update, Gaussian};
use primm_core::motion::constant_velocity::index as cv;
use primm_core::motion::coordinated_turn::{
    index as ct, turn_functions_closed_form, turn_functions_series, Vector5, TAYLOR_THRESHOLD,
};
use primm_core::motion::{ConstantVelocity, CoordinatedTurn, ModeModels, MotionModel, PredictContext};

fn cv_prediction(state: &Vector5, dt: f64) -> Vector4<f64> {
    ConstantVelocity::transition(dt) * Vector4::new(state[ct::X], state[ct::Y], state[ct::VX], state[ct::VY])
}

#[test]
fn coordinated_turn_without_turning_is_constant_velocity() {
    for omega in [0.0, 1e-12, -1e-12, 1e-11] {
        for dt in [0.01, 0.06, 0.5] {
            let state = Vector5::new(3.0, -4.0, 12.0, -7.0, omega);
            let ct = CoordinatedTurn::transition(&state, dt);
            let cv = cv_prediction(&state, dt);
            for i in 0..4 {
                assert!(
                    (ct[i] - cv[i]).abs() < 1e-9,
                    "omega {omega} dt {dt} index {i}: {} vs {}",
                    ct[i],
                    cv[i]
                );
            }
            let jacobian = CoordinatedTurn::jacobian(&state, dt);
            let f = ConstantVelocity::transition(dt);
            for r in 0..4 {
                for c in 0..4 {
                    assert!((jacobian[(r, c)] - f[(r, c)]).abs() < 1e-9);
                }
            }
        }
    }
}

#[test]
fn series_and_closed_forms_agree_on_both_sides_of_the_taylor_switch() {
    let mut phi = TAYLOR_THRESHOLD / 4.0;
    while phi < TAYLOR_THRESHOLD * 4.0 {
        for sign in [1.0, -1.0] {
            let series = turn_functions_series(sign * phi);
            let closed = turn_functions_closed_form(sign * phi);
            assert!((series.0 - closed.0).abs() < 1e-9, "s at {phi}");
            assert!((series.1 - closed.1).abs() < 1e-9, "g at {phi}");
            assert!((series.2 - closed.2).abs() < 1e-9, "s' at {phi}");
            assert!((series.3 - closed.3).abs() < 1e-9, "g' at {phi}");
        }
        phi *= 1.01;
    }
}

#[test]
fn coordinated_turn_is_continuous_across_the_taylor_switch() {
    let dt = 0.1;
    let below = TAYLOR_THRESHOLD * (1.0 - 1e-9) / dt;
    let above = TAYLOR_THRESHOLD * (1.0 + 1e-9) / dt;
    let a = Vector5::new(1.0, 2.0, 15.0, -3.0, below);
    let b = Vector5::new(1.0, 2.0, 15.0, -3.0, above);
    let difference = CoordinatedTurn::transition(&a, dt) - CoordinatedTurn::transition(&b, dt);
    assert!(difference.abs().max() < 1e-9, "{difference}");
    let difference = CoordinatedTurn::jacobian(&a, dt) - CoordinatedTurn::jacobian(&b, dt);
    assert!(difference.abs().max() < 1e-9, "{difference}");
}

#[test]
fn coordinated_turn_matches_the_closed_form_turn_of_the_paper() {
    // eq:ct_x .. eq:ct_vy written with ω directly, away from the switch.
    let (x, y, vx, vy, omega, dt) = (5.0, 1.0, 8.0, 3.0, 0.4, 0.2);
    let phi: f64 = omega * dt;
    let expected = [
        x + phi.sin() / omega * vx - (1.0 - phi.cos()) / omega * vy,
        y + (1.0 - phi.cos()) / omega * vx + phi.sin() / omega * vy,
        phi.cos() * vx - phi.sin() * vy,
        phi.sin() * vx + phi.cos() * vy,
        omega,
    ];
    let got = CoordinatedTurn::transition(&Vector5::new(x, y, vx, vy, omega), dt);
    for i in 0..5 {
        assert!((got[i] - expected[i]).abs() < 1e-12);
    }
}

#[test]
fn coordinated_turn_jacobian_matches_central_finite_differences() {
    let mut rng = common::rng(7);
    for case in 0..300 {
        let omega = match case % 4 {
            0 => 0.0,
            1 => common::standard_normal(&mut rng) * 1e-4,
            2 => common::standard_normal(&mut rng) * 0.5,
            _ => common::standard_normal(&mut rng) * 3.0,
        };
        let state = Vector5::new(
            common::standard_normal(&mut rng) * 30.0,
            common::standard_normal(&mut rng) * 30.0,
            common::standard_normal(&mut rng) * 10.0,
            common::standard_normal(&mut rng) * 10.0,
            omega,
        );
        let dt = 0.01 + 0.3 * (case as f64 / 300.0);
        let analytic = CoordinatedTurn::jacobian(&state, dt);
        for c in 0..5 {
            let h = 1e-6 * state[c].abs().max(1e-2);
            let mut plus = state;
            let mut minus = state;
            plus[c] += h;
            minus[c] -= h;
            let numeric = (CoordinatedTurn::transition(&plus, dt) - CoordinatedTurn::transition(&minus, dt))
                / (2.0 * h);
            for r in 0..5 {
                let tolerance = 1e-6 * (1.0 + analytic[(r, c)].abs());
                assert!(
                    (numeric[r] - analytic[(r, c)]).abs() < tolerance,
                    "case {case} d f{r}/d x{c}: numeric {} analytic {}",
                    numeric[r],
                    analytic[(r, c)]
                );
            }
        }
    }
}

#[test]
fn constant_velocity_converges_to_the_true_state_on_noise_free_straight_motion() {
    let models = ModeModels::from_config(&common::config().classes.car);
    let model = &models.constant_velocity;
    let (velocity_x, velocity_y) = (11.0, -2.5);
    let start = [20.0, 5.0];
    let mut t = 0.0;
    let first =
        common::measurement(start[0], start[1], common::radial_velocity(start, [velocity_x, velocity_y]));
    let mut estimate = model.initiate(&first);
    for k in 0..400 {
        let dt = 0.03 + 0.04 * ((k * 7) % 5) as f64 / 4.0;
        t += dt;
        let truth = DVec2::new(start[0] + velocity_x * t, start[1] + velocity_y * t);
        let prior = model.predict(
            &estimate,
            &PredictContext { dt_s: dt, displacement_m: None, displacement_covariance_m2: None },
        );
        estimate = kalman_update(&prior, truth, &model.measurement_noise()).unwrap().posterior;
    }
    let truth = Vector4::new(start[0] + velocity_x * t, start[1] + velocity_y * t, velocity_x, velocity_y);
    let error = estimate.mean - truth;
    assert!(error.fixed_rows::<2>(cv::X).norm() < 1e-3, "position error {error}");
    assert!(error.fixed_rows::<2>(cv::VX).norm() < 1e-3, "velocity error {error}");
}

#[test]
fn kalman_update_matches_the_textbook_closed_form() {
    // The textbook form with an explicit H, S, K and the simple covariance (I − KH)P, which
    // equals the Joseph form for the optimal gain.
    let a = Matrix4::new(1.0, 0.3, 0.0, 0.2, 0.1, 2.0, 0.4, 0.0, 0.0, 0.2, 1.5, 0.1, 0.3, 0.0, 0.2, 0.9);
    let p = a * a.transpose() + Matrix4::identity() * 0.2;
    let prior = Gaussian::new(Vector4::new(1.0, -2.0, 3.0, 0.5), p);
    let r = Matrix2::new(0.4, 0.05, 0.05, 0.3);
    let z = DVec2::new(1.8, -2.6);

    let mut h = SMatrix::<f64, 2, 4>::zeros();
    h[(0, 0)] = 1.0;
    h[(1, 1)] = 1.0;
    let s = h * p * h.transpose() + r;
    let k = p * h.transpose() * s.try_inverse().unwrap();
    let nu = nalgebra::Vector2::new(z.x, z.y) - h * prior.mean;
    let expected_mean = prior.mean + k * nu;
    let expected_covariance = (Matrix4::identity() - k * h) * p;

    let update = kalman_update(&prior, z, &r).unwrap();
    assert!((update.posterior.mean - expected_mean).abs().max() < 1e-12);
    assert!((update.posterior.covariance - expected_covariance).abs().max() < 1e-12);
    assert!((update.innovation_covariance - s).abs().max() < 1e-12);
}

#[test]
fn kalman_update_refuses_an_indefinite_innovation_covariance() {
    let prior = Gaussian::new(Vector4::zeros(), Matrix4::zeros());
    let r = Matrix2::new(-1.0, 0.0, 0.0, 1.0);
    assert!(kalman_update(&prior, DVec2::ZERO, &r).is_err());
}

#[test]
fn initial_velocity_lies_along_the_line_of_sight_with_the_measured_radial_speed() {
    let models = ModeModels::from_config(&common::config().classes.car);
    let m = common::measurement(30.0, 40.0, -5.0);
    let g = models.constant_velocity.initiate(&m);
    assert!((g.mean[cv::VX] - (-3.0)).abs() < 1e-12 && (g.mean[cv::VY] - (-4.0)).abs() < 1e-12);
    // Variance along the line of sight is the radial-velocity variance, across it the wide one.
    let along = nalgebra::Vector2::new(0.6, 0.8);
    let across = nalgebra::Vector2::new(-0.8, 0.6);
    let velocity_covariance = g.covariance.fixed_view::<2, 2>(cv::VX, cv::VX).into_owned();
    let config = common::config();
    assert!(
        ((along.transpose() * velocity_covariance * along)[(0, 0)]
            - config.classes.car.initial_radial_speed_std_mps.powi(2))
        .abs()
            < 1e-12
    );
    assert!(
        ((across.transpose() * velocity_covariance * across)[(0, 0)]
            - config.classes.car.initial_tangential_speed_std_mps.powi(2))
        .abs()
            < 1e-9
    );
}

/// A random symmetric positive definite matrix.
fn spd<const N: usize>(rng: &mut rand_chacha::ChaCha8Rng) -> SMatrix<f64, N, N> {
    use rand::Rng;
    let a = SMatrix::<f64, N, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
    a * a.transpose() + SMatrix::<f64, N, N>::identity() * 0.1
}

#[test]
fn linear_predictions_equal_the_dense_textbook_products() {
    use primm_core::motion::ConstantAcceleration;
    let mut rng = common::rng(77);
    let config = common::config();
    let models = ModeModels::from_config(&config.classes.car);
    for dt in [0.0, 0.015, 0.07, 0.4] {
        let context = PredictContext { dt_s: dt, displacement_m: None, displacement_covariance_m2: None };
        let cv = Gaussian::new(Vector4::new(1.0, -2.0, 3.0, 0.5), spd::<4>(&mut rng));
        let f = ConstantVelocity::transition(dt);
        let expected = f * cv.covariance * f.transpose() + models.constant_velocity.process_noise(dt);
        let predicted = models.constant_velocity.predict(&cv, &context);
        assert!((predicted.covariance - expected).abs().max() < 1e-12, "CV dt {dt}");
        assert!((predicted.mean - f * cv.mean).abs().max() < 1e-12, "CV dt {dt}");

        let ca = Gaussian::new(SMatrix::<f64, 6, 1>::new(1.0, -2.0, 3.0, 0.5, -0.2, 0.1), spd::<6>(&mut rng));
        let f = ConstantAcceleration::transition(dt);
        let expected = f * ca.covariance * f.transpose() + models.constant_acceleration.process_noise(dt);
        let predicted = models.constant_acceleration.predict(&ca, &context);
        assert!((predicted.covariance - expected).abs().max() < 1e-12, "CA dt {dt}");
        assert!((predicted.mean - f * ca.mean).abs().max() < 1e-12, "CA dt {dt}");
    }
}

#[test]
fn coordinated_turn_prediction_equals_the_dense_jacobian_product() {
    let mut rng = common::rng(78);
    let config = common::config();
    let models = ModeModels::from_config(&config.classes.car);
    for (omega, dt) in [(0.0, 0.05), (1e-5, 0.05), (0.4, 0.015), (-1.2, 0.3)] {
        let posterior = Gaussian::new(Vector5::new(1.0, -2.0, 8.0, 1.5, omega), spd::<5>(&mut rng));
        let context = PredictContext { dt_s: dt, displacement_m: None, displacement_covariance_m2: None };
        let j = CoordinatedTurn::jacobian(&posterior.mean, dt);
        let expected = j * posterior.covariance * j.transpose() + models.coordinated_turn.process_noise(dt);
        let predicted = models.coordinated_turn.predict(&posterior, &context);
        assert!((predicted.covariance - expected).abs().max() < 1e-12, "omega {omega} dt {dt}");
        assert_eq!(predicted.mean, CoordinatedTurn::transition(&posterior.mean, dt));
    }
}

#[test]
fn coordinated_turn_predicts_an_absurd_turn_rate_at_its_configured_bound() {
    let config = common::config();
    let models = ModeModels::from_config(&config.classes.car);
    let bound = config.classes.car.coordinated_turn.max_turn_rate_radps;
    assert!(bound.is_finite() && bound > 0.0);
    let mut rng = common::rng(79);
    let context = PredictContext { dt_s: 0.05, displacement_m: None, displacement_covariance_m2: None };
    for (omega, expected_omega) in [(50.0, bound), (-1e6, -bound), (0.5 * bound, 0.5 * bound)] {
        let posterior = Gaussian::new(Vector5::new(1.0, -2.0, 8.0, 1.5, omega), spd::<5>(&mut rng));
        let predicted = models.coordinated_turn.predict(&posterior, &context);
        let mut clamped = posterior.mean;
        clamped[ct::OMEGA] = expected_omega;
        // The mean moves as from the clamped turn rate, and the turn rate stays at the bound.
        assert_eq!(predicted.mean, CoordinatedTurn::transition(&clamped, 0.05), "omega {omega}");
        assert_eq!(predicted.mean[ct::OMEGA], expected_omega);
    }
    // Without a bound (the model built by hand) the turn rate is used as it is.
    let unbounded = CoordinatedTurn { max_turn_rate_radps: f64::INFINITY, ..models.coordinated_turn };
    let posterior = Gaussian::new(Vector5::new(1.0, -2.0, 8.0, 1.5, 50.0), spd::<5>(&mut rng));
    assert_eq!(unbounded.predict(&posterior, &context).mean[ct::OMEGA], 50.0);
}
