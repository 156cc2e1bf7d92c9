//! Constant-acceleration model (`eq:ca_F`), state `[x, y, vx, vy, ax, ay]`.

use super::{initiate_position_velocity, InitialVelocity, MotionModel, PredictContext};
use crate::gaussian::Gaussian;
use crate::measurement::Measurement;
use glam::DVec2;
use nalgebra::{Matrix2, Matrix6};

/// Named indices of the state `[x, y, vx, vy, ax, ay]`.
pub mod index {
    pub use crate::motion::index::{VX, VY, X, Y};
    /// x acceleration, m/s².
    pub const AX: usize = 4;
    /// y acceleration, m/s².
    pub const AY: usize = 5;
}

/// Constant acceleration with continuous white-noise jerk (Wiener-process acceleration).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantAcceleration {
    /// Jerk power spectral density, m²/s⁵.
    pub jerk_psd_m2_per_s5: f64,
    /// Standard deviation of the initial acceleration, m/s².
    pub initial_acceleration_std_mps2: f64,
    /// Measurement noise covariance, m².
    pub measurement_noise_m2: Matrix2<f64>,
    /// Velocity initiation.
    pub initial_velocity: InitialVelocity,
}

const AXES: [[usize; 3]; 2] = [[index::X, index::VX, index::AX], [index::Y, index::VY, index::AY]];

impl ConstantAcceleration {
    /// A model with the given noise.
    pub fn new(
        jerk_psd_m2_per_s5: f64,
        initial_acceleration_std_mps2: f64,
        measurement_noise_m2: Matrix2<f64>,
        initial_velocity: InitialVelocity,
    ) -> Self {
        Self { jerk_psd_m2_per_s5, initial_acceleration_std_mps2, measurement_noise_m2, initial_velocity }
    }

    /// The transition matrix `F(Δt)` of `eq:ca_F` in position-first order.
    pub fn transition(dt: f64) -> Matrix6<f64> {
        let mut f = Matrix6::identity();
        for [p, v, a] in AXES {
            f[(p, v)] = dt;
            f[(p, a)] = 0.5 * dt * dt;
            f[(v, a)] = dt;
        }
        f
    }

    /// The process noise `Q(Δt)`.
    pub fn process_noise(&self, dt: f64) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        self.add_process_noise(&mut m, dt);
        m
    }

    /// `covariance += Q(Δt)`, touching only `Q`'s eighteen non-zero entries.
    #[inline]
    pub fn add_process_noise(&self, covariance: &mut Matrix6<f64>, dt: f64) {
        let q = self.jerk_psd_m2_per_s5;
        let (dt2, dt3) = (dt * dt, dt * dt * dt);
        let block = [
            [dt3 * dt2 / 20.0, dt2 * dt2 / 8.0, dt3 / 6.0],
            [dt2 * dt2 / 8.0, dt3 / 3.0, dt2 / 2.0],
            [dt3 / 6.0, dt2 / 2.0, dt],
        ];
        for axis in AXES {
            for (r, &row) in axis.iter().enumerate() {
                for (c, &col) in axis.iter().enumerate() {
                    covariance[(row, col)] += q * block[r][c];
                }
            }
        }
    }
}

impl MotionModel<6> for ConstantAcceleration {
    fn initiate_seen_from(&self, measurement: &Measurement, sensor_position_m: DVec2) -> Gaussian<6> {
        let mut gaussian = initiate_position_velocity(
            measurement,
            sensor_position_m,
            &self.measurement_noise_m2,
            &self.initial_velocity,
        );
        let acceleration_variance = crate::math::square(self.initial_acceleration_std_mps2);
        gaussian.covariance[(index::AX, index::AX)] = acceleration_variance;
        gaussian.covariance[(index::AY, index::AY)] = acceleration_variance;
        gaussian
    }

    fn predict(&self, posterior: &Gaussian<6>, context: &PredictContext) -> Gaussian<6> {
        let mut prior = *posterior;
        self.predict_in_place(&mut prior, context);
        prior
    }

    #[inline(always)]
    fn predict_in_place(&self, estimate: &mut Gaussian<6>, context: &PredictContext) {
        let dt = context.dt_s;
        let half_dt2 = 0.5 * dt * dt;
        // F = transition(dt), applied through its six off-diagonal terms.
        let [[x, vx, ax], [y, vy, ay]] = AXES;
        let terms =
            [(x, vx, dt), (x, ax, half_dt2), (vx, ax, dt), (y, vy, dt), (y, ay, half_dt2), (vy, ay, dt)];
        super::propagate_linear_in_place(estimate, &terms);
        self.add_process_noise(&mut estimate.covariance, dt);
        crate::gaussian::symmetrize(&mut estimate.covariance);
    }

    fn measurement_noise(&self) -> Matrix2<f64> {
        self.measurement_noise_m2
    }
}
