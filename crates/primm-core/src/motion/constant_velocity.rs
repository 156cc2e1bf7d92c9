//! Constant-velocity model (`eq:cv_F`), state `[x, y, vx, vy]`.

use super::{initiate_position_velocity, InitialVelocity, MotionModel, PredictContext};
use crate::gaussian::Gaussian;
use crate::measurement::Measurement;
use glam::DVec2;
use nalgebra::{Matrix2, Matrix4};

/// Named indices of the state `[x, y, vx, vy]`.
pub mod index {
    pub use crate::motion::index::{VX, VY, X, Y};
}

/// Constant velocity with continuous white-noise acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantVelocity {
    /// Acceleration power spectral density, m²/s³.
    pub acceleration_psd_m2_per_s3: f64,
    /// Measurement noise covariance, m².
    pub measurement_noise_m2: Matrix2<f64>,
    /// Velocity initiation.
    pub initial_velocity: InitialVelocity,
}

impl ConstantVelocity {
    /// A model with the given noise.
    pub fn new(
        acceleration_psd_m2_per_s3: f64,
        measurement_noise_m2: Matrix2<f64>,
        initial_velocity: InitialVelocity,
    ) -> Self {
        Self { acceleration_psd_m2_per_s3, measurement_noise_m2, initial_velocity }
    }

    /// The transition matrix `F(Δt)` of `eq:cv_F` in position-first order.
    pub fn transition(dt: f64) -> Matrix4<f64> {
        let mut f = Matrix4::identity();
        f[(index::X, index::VX)] = dt;
        f[(index::Y, index::VY)] = dt;
        f
    }

    /// The process noise `Q(Δt)`.
    pub fn process_noise(&self, dt: f64) -> Matrix4<f64> {
        let mut m = Matrix4::zeros();
        self.add_process_noise(&mut m, dt);
        m
    }

    /// `covariance += Q(Δt)`, touching only `Q`'s eight non-zero entries.
    #[inline]
    pub fn add_process_noise(&self, covariance: &mut Matrix4<f64>, dt: f64) {
        super::add_white_acceleration(covariance, self.acceleration_psd_m2_per_s3, dt);
    }
}

impl MotionModel<4> for ConstantVelocity {
    fn initiate_seen_from(&self, measurement: &Measurement, sensor_position_m: DVec2) -> Gaussian<4> {
        initiate_position_velocity(
            measurement,
            sensor_position_m,
            &self.measurement_noise_m2,
            &self.initial_velocity,
        )
    }

    fn predict(&self, posterior: &Gaussian<4>, context: &PredictContext) -> Gaussian<4> {
        let mut prior = *posterior;
        self.predict_in_place(&mut prior, context);
        prior
    }

    #[inline(always)]
    fn predict_in_place(&self, estimate: &mut Gaussian<4>, context: &PredictContext) {
        let dt = context.dt_s;
        // F = transition(dt), applied through its two off-diagonal terms.
        super::propagate_linear_in_place(estimate, &[(index::X, index::VX, dt), (index::Y, index::VY, dt)]);
        self.add_process_noise(&mut estimate.covariance, dt);
        crate::gaussian::symmetrize(&mut estimate.covariance);
    }

    fn measurement_noise(&self) -> Matrix2<f64> {
        self.measurement_noise_m2
    }
}
