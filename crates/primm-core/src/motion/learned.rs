//! The PR mode's filter (paper, Section III-C "PR Filter"), state `[x, y]`.
//!
//! The prior is the posterior plus the displacement predicted by the learned model
//! (`eq:pr_prior`); the covariance grows by `Q_PR` (`eq:pr_cov`): the constant of the
//! configuration, or the predictor's own covariance of this displacement when it gives one
//! ([`PredictContext::displacement_covariance_m2`]). The displacement itself comes
//! from a [`DisplacementPredictor`](crate::predictor::DisplacementPredictor) and reaches the
//! mode through [`PredictContext::displacement_m`]. Without a displacement the mean stays put and
//! the IMM leaves the mode out of that step's fusion.

use super::{MotionModel, PredictContext};
use crate::gaussian::Gaussian;
use crate::measurement::Measurement;
use glam::DVec2;
use nalgebra::{Matrix2, Vector2};

/// Named indices of the state `[x, y]`.
pub mod index {
    pub use crate::gaussian::index::{X, Y};
}

/// PR filter noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnedDisplacement {
    /// `Q_PR`, m².
    pub process_noise_m2: Matrix2<f64>,
    /// `R_PR`, m².
    pub measurement_noise_m2: Matrix2<f64>,
}

impl LearnedDisplacement {
    /// A PR filter with the given noise.
    pub fn new(process_noise_m2: Matrix2<f64>, measurement_noise_m2: Matrix2<f64>) -> Self {
        Self { process_noise_m2, measurement_noise_m2 }
    }
}

impl MotionModel<2> for LearnedDisplacement {
    fn initiate_seen_from(&self, measurement: &Measurement, _sensor_position_m: DVec2) -> Gaussian<2> {
        Gaussian::new(Vector2::new(measurement.x_m, measurement.y_m), self.measurement_noise_m2)
    }

    fn predict(&self, posterior: &Gaussian<2>, context: &PredictContext) -> Gaussian<2> {
        let displacement = context.displacement_m.map_or(Vector2::zeros(), |d| Vector2::new(d.x, d.y));
        let process_noise = context.displacement_covariance_m2.unwrap_or(self.process_noise_m2);
        Gaussian::new(posterior.mean + displacement, posterior.covariance + process_noise)
    }

    fn measurement_noise(&self) -> Matrix2<f64> {
        self.measurement_noise_m2
    }
}
