//! The process noise `Q(Δt)` of the CV, CA and CT models against closed forms written out here
//! element by element, independently of the helpers that build `Q` in `primm_core::motion`.
//!
//! Which discretisation: every model integrates continuous-time white noise over the frame
//! interval (Bar-Shalom, Li and Kirubarajan, 2001, §6.2), not the "discrete white noise" form
//! that assumes one constant random input per interval. The paper leaves `Q_i` open: it adds a
//! predefined process-noise covariance in `eq:kf_cov_pred` (Section III-B) without giving its
//! form, for CT as for CV and CA; the CT transition it does define (`eq:ct_x` … `eq:ct_vy`) keeps
//! the turn rate constant between frames. The continuous form is what scales correctly with the
//! irregular intervals of interleaved radar scans, so it is the one primm implements and the
//! one tested here; a test below shows that the comparison tells the two forms apart.
//!
//! State orders (position first, as in `primm_core::motion`):
//! CV `[x, y, vx, vy]`, CA `[x, y, vx, vy, ax, ay]`, CT `[x, y, vx, vy, ω]`.

use nalgebra::{Matrix2, SMatrix, SVector};
use primm_core::gaussian::Gaussian;
use primm_core::motion::{
    ConstantAcceleration, ConstantVelocity, CoordinatedTurn, InitialVelocity, MotionModel, PredictContext,
};

/// Frame intervals, s: radar-like ones, a long gap and an exactly representable one.
const INTERVALS_S: [f64; 5] = [0.015, 0.05, 0.1, 0.5, 2.0];
/// Power spectral densities (units per model).
const DENSITIES: [f64; 4] = [0.01, 0.5, 3.0, 40.0];

fn measurement_noise() -> Matrix2<f64> {
    Matrix2::new(0.3, 0.05, 0.05, 0.2)
}

fn initial_velocity() -> InitialVelocity {
    InitialVelocity { radial_std_mps: 0.3, tangential_std_mps: 4.0 }
}

/// Fails unless `actual` equals `expected` entry by entry: zeros exactly, every other entry to
/// a relative 1e-12.
fn assert_matches<const N: usize>(actual: &SMatrix<f64, N, N>, expected: &[[f64; N]; N], what: &str) {
    if let Some(difference) = first_difference(actual, expected) {
        panic!("{what}: {difference}\nactual {actual}\nexpected {expected:?}");
    }
}

/// The first entry where `actual` and `expected` disagree, described; `None` if they agree.
fn first_difference<const N: usize>(actual: &SMatrix<f64, N, N>, expected: &[[f64; N]; N]) -> Option<String> {
    for (row, expected_row) in expected.iter().enumerate() {
        for (column, &wanted) in expected_row.iter().enumerate() {
            let got = actual[(row, column)];
            let agrees =
                if wanted == 0.0 { got == 0.0 } else { (got - wanted).abs() <= 1e-12 * wanted.abs() };
            if !agrees {
                return Some(format!("entry ({row}, {column}) is {got}, the closed form gives {wanted}"));
            }
        }
    }
    None
}

/// The constant-velocity closed form: per axis `q·[[Δt³/3, Δt²/2], [Δt²/2, Δt]]`, axes
/// uncorrelated.
fn constant_velocity_closed_form(q: f64, dt: f64) -> [[f64; 4]; 4] {
    let (p, c, v) = (q * dt.powi(3) / 3.0, q * dt.powi(2) / 2.0, q * dt);
    [
        // Columns x, y, vx, vy.
        [p, 0.0, c, 0.0], // x
        [0.0, p, 0.0, c], // y
        [c, 0.0, v, 0.0], // vx
        [0.0, c, 0.0, v], // vy
    ]
}

/// The constant-acceleration closed form (continuous white jerk): per axis
/// `q·[[Δt⁵/20, Δt⁴/8, Δt³/6], [Δt⁴/8, Δt³/3, Δt²/2], [Δt³/6, Δt²/2, Δt]]`.
fn constant_acceleration_closed_form(q: f64, dt: f64) -> [[f64; 6]; 6] {
    let pp = q * dt.powi(5) / 20.0;
    let pv = q * dt.powi(4) / 8.0;
    let pa = q * dt.powi(3) / 6.0;
    let vv = q * dt.powi(3) / 3.0;
    let va = q * dt.powi(2) / 2.0;
    let aa = q * dt;
    [
        // Columns x, y, vx, vy, ax, ay.
        [pp, 0.0, pv, 0.0, pa, 0.0], // x
        [0.0, pp, 0.0, pv, 0.0, pa], // y
        [pv, 0.0, vv, 0.0, va, 0.0], // vx
        [0.0, pv, 0.0, vv, 0.0, va], // vy
        [pa, 0.0, va, 0.0, aa, 0.0], // ax
        [0.0, pa, 0.0, va, 0.0, aa], // ay
    ]
}

/// The coordinated-turn closed form: continuous white acceleration of PSD `q` on each axis'
/// position and velocity (as CV), and a random-walk turn rate of PSD `q_omega`, `q_ω·Δt`,
/// uncorrelated with the rest.
fn coordinated_turn_closed_form(q: f64, q_omega: f64, dt: f64) -> [[f64; 5]; 5] {
    let (p, c, v) = (q * dt.powi(3) / 3.0, q * dt.powi(2) / 2.0, q * dt);
    [
        // Columns x, y, vx, vy, ω.
        [p, 0.0, c, 0.0, 0.0],              // x
        [0.0, p, 0.0, c, 0.0],              // y
        [c, 0.0, v, 0.0, 0.0],              // vx
        [0.0, c, 0.0, v, 0.0],              // vy
        [0.0, 0.0, 0.0, 0.0, q_omega * dt], // ω
    ]
}

/// The prior of a model's prediction from a state known exactly (zero covariance): `F·0·Fᵀ + Q`
/// is `Q` itself, so this reads the `Q` the prediction really adds.
fn noise_added_by_prediction<const N: usize>(
    model: &impl MotionModel<N>,
    mean: SVector<f64, N>,
    dt: f64,
) -> SMatrix<f64, N, N> {
    let certain = Gaussian::new(mean, SMatrix::zeros());
    model
        .predict(
            &certain,
            &PredictContext { dt_s: dt, displacement_m: None, displacement_covariance_m2: None },
        )
        .covariance
}

#[test]
fn constant_velocity_noise_is_integrated_white_acceleration() {
    for q in DENSITIES {
        for dt in INTERVALS_S {
            let model = ConstantVelocity::new(q, measurement_noise(), initial_velocity());
            let expected = constant_velocity_closed_form(q, dt);
            assert_matches(&model.process_noise(dt), &expected, &format!("CV Q, q {q} dt {dt}"));
            let mean = SVector::<f64, 4>::new(3.0, -1.0, 7.0, 0.5);
            let added = noise_added_by_prediction(&model, mean, dt);
            assert_matches(&added, &expected, &format!("CV prediction, q {q} dt {dt}"));
        }
    }
}

#[test]
fn constant_acceleration_noise_is_integrated_white_jerk() {
    for q in DENSITIES {
        for dt in INTERVALS_S {
            let model = ConstantAcceleration::new(q, 2.0, measurement_noise(), initial_velocity());
            let expected = constant_acceleration_closed_form(q, dt);
            assert_matches(&model.process_noise(dt), &expected, &format!("CA Q, q {q} dt {dt}"));
            let mean = SVector::<f64, 6>::new(3.0, -1.0, 7.0, 0.5, -0.4, 0.2);
            let added = noise_added_by_prediction(&model, mean, dt);
            assert_matches(&added, &expected, &format!("CA prediction, q {q} dt {dt}"));
        }
    }
}

#[test]
fn coordinated_turn_noise_is_white_acceleration_plus_a_turn_rate_random_walk() {
    for (q, q_omega) in DENSITIES.iter().zip(DENSITIES.iter().rev()) {
        let (q, q_omega) = (*q, *q_omega / 100.0);
        for dt in INTERVALS_S {
            let model = CoordinatedTurn::new(q, q_omega, 0.1, measurement_noise(), initial_velocity());
            let expected = coordinated_turn_closed_form(q, q_omega, dt);
            assert_matches(
                &model.process_noise(dt),
                &expected,
                &format!("CT Q, q {q} q_ω {q_omega} dt {dt}"),
            );
            // Straight and turning: the Jacobian of a certain state maps zero covariance to zero
            // whatever the turn rate, so the prediction adds exactly Q.
            for omega in [0.0, 0.35] {
                let mean = SVector::<f64, 5>::new(3.0, -1.0, 7.0, 0.5, omega);
                let added = noise_added_by_prediction(&model, mean, dt);
                assert_matches(&added, &expected, &format!("CT prediction, ω {omega} q {q} dt {dt}"));
            }
        }
    }
}

#[test]
fn the_closed_form_comparison_rejects_the_discrete_white_noise_form() {
    // The discrete white-noise acceleration model (one constant acceleration per interval):
    // per axis q·[[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]]. A CV model built on it must fail the check.
    let (q, dt): (f64, f64) = (0.5, 0.1);
    let (p, c, v) = (q * dt.powi(4) / 4.0, q * dt.powi(3) / 2.0, q * dt.powi(2));
    let rows = [[p, 0.0, c, 0.0], [0.0, p, 0.0, c], [c, 0.0, v, 0.0], [0.0, c, 0.0, v]];
    let discrete = SMatrix::<f64, 4, 4>::from_fn(|row, column| rows[row][column]);
    assert!(first_difference(&discrete, &constant_velocity_closed_form(q, dt)).is_some());
    // So is a correct Q that leaks one cross-axis correlation.
    let model = ConstantVelocity::new(q, measurement_noise(), initial_velocity());
    let mut leaky = model.process_noise(dt);
    leaky[(0, 3)] = 1e-9;
    assert!(first_difference(&leaky, &constant_velocity_closed_form(q, dt)).is_some());
}

#[test]
fn noise_grows_with_the_interval_as_the_closed_forms_say() {
    // Doubling Δt multiplies the position variance by 8 (CV, CT) or 32 (CA) and the highest
    // derivative's variance by 2: a check of the powers of Δt through the models alone.
    let constant_velocity = ConstantVelocity::new(1.0, measurement_noise(), initial_velocity());
    let constant_acceleration = ConstantAcceleration::new(1.0, 2.0, measurement_noise(), initial_velocity());
    let coordinated_turn = CoordinatedTurn::new(1.0, 0.01, 0.1, measurement_noise(), initial_velocity());
    let ratio = |long: f64, short: f64| long / short;
    let (short, long) = (0.04, 0.08);
    let (a, b) = (constant_velocity.process_noise(long), constant_velocity.process_noise(short));
    assert!((ratio(a[(0, 0)], b[(0, 0)]) - 8.0).abs() < 1e-12);
    assert!((ratio(a[(2, 2)], b[(2, 2)]) - 2.0).abs() < 1e-12);
    let (a, b) = (constant_acceleration.process_noise(long), constant_acceleration.process_noise(short));
    assert!((ratio(a[(0, 0)], b[(0, 0)]) - 32.0).abs() < 1e-12);
    assert!((ratio(a[(4, 4)], b[(4, 4)]) - 2.0).abs() < 1e-12);
    let (a, b) = (coordinated_turn.process_noise(long), coordinated_turn.process_noise(short));
    assert!((ratio(a[(1, 1)], b[(1, 1)]) - 8.0).abs() < 1e-12);
    assert!((ratio(a[(4, 4)], b[(4, 4)]) - 2.0).abs() < 1e-12);
}
