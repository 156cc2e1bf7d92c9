//! Coordinated-turn model (`eq:ct_x` … `eq:ct_vy`), state `[x, y, vx, vy, ω]`, propagated as an
//! extended Kalman filter with the analytic Jacobian.
//!
//! With `φ = ωΔt` the transition is written through two smooth functions,
//! `s(φ) = sin φ / φ` and `g(φ) = (1 − cos φ) / φ`:
//! `x⁺ = x + Δt (s vx − g vy)`, `y⁺ = y + Δt (g vx + s vy)`, `vx⁺ = cos φ vx − sin φ vy`,
//! `vy⁺ = sin φ vx + cos φ vy`, `ω⁺ = ω`. This is exactly the paper's form for `ω ≠ 0`
//! (`sin φ / ω = Δt s(φ)`), and for `|φ| <` [`TAYLOR_THRESHOLD`] `s`, `g` and their derivatives
//! come from Taylor series whose truncation error (`< φ⁶/5040`) is far below double precision,
//! so the switch has no visible discontinuity and nothing divides by a vanishing `ω`.

use super::{
    add_white_acceleration, initiate_position_velocity, InitialVelocity, MotionModel, PredictContext,
};
use crate::gaussian::Gaussian;
use crate::measurement::Measurement;
use glam::DVec2;
use nalgebra::{Matrix2, SMatrix, SVector};

/// 5×5 matrix.
pub type Matrix5 = SMatrix<f64, 5, 5>;
/// 5-vector.
pub type Vector5 = SVector<f64, 5>;

/// Named indices of the state `[x, y, vx, vy, ω]`.
pub mod index {
    pub use crate::motion::index::{VX, VY, X, Y};
    /// Turn rate, rad/s (positive counter-clockwise).
    pub const OMEGA: usize = 4;
}

/// Below this `|ωΔt|` (rad) the Taylor series replace the closed forms.
pub const TAYLOR_THRESHOLD: f64 = 1e-3;

/// Coordinated turn with white-noise acceleration and a random-walk turn rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoordinatedTurn {
    /// Acceleration power spectral density, m²/s³.
    pub acceleration_psd_m2_per_s3: f64,
    /// Turn-rate power spectral density, rad²/s³.
    pub turn_rate_psd_rad2_per_s3: f64,
    /// Standard deviation of the initial turn rate, rad/s.
    pub initial_turn_rate_std_radps: f64,
    /// Measurement noise covariance, m².
    pub measurement_noise_m2: Matrix2<f64>,
    /// Velocity initiation.
    pub initial_velocity: InitialVelocity,
    /// Largest turn rate predicted with, rad/s (see [`predict_in_place`](MotionModel::predict_in_place)).
    pub max_turn_rate_radps: f64,
}

/// `s(φ) = sin φ/φ`, `g(φ) = (1 − cos φ)/φ` and their derivatives `s'`, `g'` as Taylor series
/// around `φ = 0` (exact to `O(φ⁶)`), used below [`TAYLOR_THRESHOLD`].
#[inline]
pub fn turn_functions_series(phi: f64) -> (f64, f64, f64, f64) {
    let p2 = phi * phi;
    let s = 1.0 - p2 / 6.0 + p2 * p2 / 120.0;
    let g = phi * (0.5 - p2 / 24.0 + p2 * p2 / 720.0);
    let ds = phi * (-1.0 / 3.0 + p2 / 30.0);
    let dg = 0.5 - p2 / 8.0 + p2 * p2 / 144.0;
    (s, g, ds, dg)
}

/// The same four functions in closed form, used above [`TAYLOR_THRESHOLD`]; undefined at `φ = 0`.
pub fn turn_functions_closed_form(phi: f64) -> (f64, f64, f64, f64) {
    let (sin, cos) = crate::math::sin_cos(phi);
    closed_form_from(phi, sin, cos)
}

/// The closed forms from `sin φ` and `cos φ` already at hand.
#[inline]
fn closed_form_from(phi: f64, sin: f64, cos: f64) -> (f64, f64, f64, f64) {
    let s = sin / phi;
    let g = (1.0 - cos) / phi;
    let ds = (phi * cos - sin) / (phi * phi);
    let dg = (phi * sin - (1.0 - cos)) / (phi * phi);
    (s, g, ds, dg)
}

/// The trigonometric terms of one step, `φ = ωΔt`: `sin φ`, `cos φ`, `s(φ)`, `g(φ)` and
/// their derivatives, computed once per prediction.
#[derive(Debug, Clone, Copy)]
struct TurnTerms {
    sin: f64,
    cos: f64,
    s: f64,
    g: f64,
    ds: f64,
    dg: f64,
}

impl TurnTerms {
    #[inline]
    fn new(state: &Vector5, dt: f64) -> Self {
        let phi = state[index::OMEGA] * dt;
        let (sin, cos) = crate::math::sin_cos(phi);
        let (s, g, ds, dg) = if phi.abs() < TAYLOR_THRESHOLD {
            turn_functions_series(phi)
        } else {
            closed_form_from(phi, sin, cos)
        };
        Self { sin, cos, s, g, ds, dg }
    }

    #[inline]
    fn transition(&self, state: &Vector5, dt: f64) -> Vector5 {
        let (vx, vy) = (state[index::VX], state[index::VY]);
        let Self { sin, cos, s, g, .. } = *self;
        Vector5::new(
            state[index::X] + dt * (s * vx - g * vy),
            state[index::Y] + dt * (g * vx + s * vy),
            cos * vx - sin * vy,
            sin * vx + cos * vy,
            state[index::OMEGA],
        )
    }

    /// The Jacobian's rows x, y, vx and vy over the columns vx, vy and ω (its other entries
    /// are those of the identity).
    #[inline]
    fn jacobian_rows(&self, state: &Vector5, dt: f64) -> JacobianRows {
        let (vx, vy) = (state[index::VX], state[index::VY]);
        let Self { sin, cos, s, g, ds, dg } = *self;
        JacobianRows([
            [dt * s, -dt * g, dt * dt * (ds * vx - dg * vy)],
            [dt * g, dt * s, dt * dt * (dg * vx + ds * vy)],
            [cos, -sin, dt * (-sin * vx - cos * vy)],
            [sin, cos, dt * (cos * vx - sin * vy)],
        ])
    }

    fn jacobian(&self, state: &Vector5, dt: f64) -> Matrix5 {
        let mut j = Matrix5::identity();
        let rows = self.jacobian_rows(state, dt);
        for (row, values) in rows.0.iter().enumerate() {
            for (column, &value) in [index::VX, index::VY, index::OMEGA].iter().zip(values) {
                j[(row, *column)] = value;
            }
        }
        j
    }
}

/// Rows x, y, vx, vy of the CT Jacobian over the columns vx, vy, ω: `J = [[I₂, A], [0, B]]`
/// with `A` the first two rows here and `B` (rows vx, vy, ω) the rotation, its ω column and
/// `[0 0 1]`.
struct JacobianRows([[f64; 3]; 4]);

impl JacobianRows {
    /// `P ← J P Jᵀ` in place: rows first (`J P`), then columns (`(J P) Jᵀ`). Each pass reads a
    /// row's (column's) vx, vy and ω entries before writing any of them, and x, y, vx, vy are
    /// the only ones written; 2 × 5 × 12 multiply-adds.
    #[inline(always)]
    fn propagate_covariance(&self, p: &mut Matrix5) {
        let j = &self.0;
        let (vx, vy, w) = (index::VX, index::VY, index::OMEGA);
        for column in 0..5 {
            let (a, b, c) = (p[(vx, column)], p[(vy, column)], p[(w, column)]);
            p[(index::X, column)] += j[0][0] * a + j[0][1] * b + j[0][2] * c;
            p[(index::Y, column)] += j[1][0] * a + j[1][1] * b + j[1][2] * c;
            p[(vx, column)] = j[2][0] * a + j[2][1] * b + j[2][2] * c;
            p[(vy, column)] = j[3][0] * a + j[3][1] * b + j[3][2] * c;
        }
        for row in 0..5 {
            let (a, b, c) = (p[(row, vx)], p[(row, vy)], p[(row, w)]);
            p[(row, index::X)] += j[0][0] * a + j[0][1] * b + j[0][2] * c;
            p[(row, index::Y)] += j[1][0] * a + j[1][1] * b + j[1][2] * c;
            p[(row, vx)] = j[2][0] * a + j[2][1] * b + j[2][2] * c;
            p[(row, vy)] = j[3][0] * a + j[3][1] * b + j[3][2] * c;
        }
    }
}

impl CoordinatedTurn {
    /// A model with the given noise.
    pub fn new(
        acceleration_psd_m2_per_s3: f64,
        turn_rate_psd_rad2_per_s3: f64,
        initial_turn_rate_std_radps: f64,
        measurement_noise_m2: Matrix2<f64>,
        initial_velocity: InitialVelocity,
    ) -> Self {
        Self {
            acceleration_psd_m2_per_s3,
            turn_rate_psd_rad2_per_s3,
            initial_turn_rate_std_radps,
            measurement_noise_m2,
            initial_velocity,
            max_turn_rate_radps: f64::INFINITY,
        }
    }

    /// The model with its turn rate limited to `max_turn_rate_radps` (rad/s).
    pub fn with_max_turn_rate(mut self, max_turn_rate_radps: f64) -> Self {
        self.max_turn_rate_radps = max_turn_rate_radps;
        self
    }

    /// The transition `f(x, Δt)`.
    pub fn transition(state: &Vector5, dt: f64) -> Vector5 {
        TurnTerms::new(state, dt).transition(state, dt)
    }

    /// The Jacobian `∂f/∂x` at `state`.
    pub fn jacobian(state: &Vector5, dt: f64) -> Matrix5 {
        TurnTerms::new(state, dt).jacobian(state, dt)
    }

    /// The process noise `Q(Δt)`.
    pub fn process_noise(&self, dt: f64) -> Matrix5 {
        let mut m = Matrix5::zeros();
        self.add_process_noise(&mut m, dt);
        m
    }

    /// `covariance += Q(Δt)`, touching only `Q`'s nine non-zero entries.
    #[inline]
    pub fn add_process_noise(&self, covariance: &mut Matrix5, dt: f64) {
        add_white_acceleration(covariance, self.acceleration_psd_m2_per_s3, dt);
        covariance[(index::OMEGA, index::OMEGA)] += self.turn_rate_psd_rad2_per_s3 * dt;
    }
}

impl MotionModel<5> for CoordinatedTurn {
    fn initiate_seen_from(&self, measurement: &Measurement, sensor_position_m: DVec2) -> Gaussian<5> {
        let mut gaussian = initiate_position_velocity(
            measurement,
            sensor_position_m,
            &self.measurement_noise_m2,
            &self.initial_velocity,
        );
        gaussian.covariance[(index::OMEGA, index::OMEGA)] =
            crate::math::square(self.initial_turn_rate_std_radps);
        gaussian
    }

    fn predict(&self, posterior: &Gaussian<5>, context: &PredictContext) -> Gaussian<5> {
        let mut prior = *posterior;
        self.predict_in_place(&mut prior, context);
        prior
    }

    /// The EKF prediction. The turn rate is first clamped to `±max_turn_rate_radps`
    /// (projection of the mean onto the plausible set; the covariance stays): an estimate far
    /// beyond any real turn, left over from a manoeuvre or a bad association while the mode had
    /// little weight, makes `x⁺` nearly independent of the velocity (`sin φ / φ → 0`), so that
    /// position measurements no longer correct the velocity and it can drift without bound.
    #[inline(always)]
    fn predict_in_place(&self, estimate: &mut Gaussian<5>, context: &PredictContext) {
        let dt = context.dt_s;
        let omega = &mut estimate.mean[index::OMEGA];
        *omega = omega.clamp(-self.max_turn_rate_radps, self.max_turn_rate_radps);
        // One evaluation of sin/cos serves both the mean and the Jacobian.
        let terms = TurnTerms::new(&estimate.mean, dt);
        let jacobian = terms.jacobian_rows(&estimate.mean, dt);
        jacobian.propagate_covariance(&mut estimate.covariance);
        estimate.mean = terms.transition(&estimate.mean, dt);
        self.add_process_noise(&mut estimate.covariance, dt);
        crate::gaussian::symmetrize(&mut estimate.covariance);
    }

    fn measurement_noise(&self) -> Matrix2<f64> {
        self.measurement_noise_m2
    }
}
