//! A deterministic stand-in for the learned predictor whose answers follow the input frames.

use glam::{DMat2, DVec2};
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};

/// Predicts the displacement a track made between its last two measurements (taken from the
/// request's relative-position features), so that a hostile frame controls the predictor's
/// answers as well as the measurements; `None` for a track with one measurement. Its covariance
/// is made of that row's radial velocity, RCS and time (`[[v_r, t], [t, RCS]]`), so the frame
/// controls it too, valid or not.
#[derive(Debug, Clone, Default)]
pub struct ExtrapolatingPredictor {
    answers: Vec<Option<Displacement>>,
}

impl DisplacementPredictor for ExtrapolatingPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.answers.clear();
        self.answers.extend(requests.iter().map(|request| {
            let previous = request.len.checked_sub(2).map(|row| request.features[row])?;
            // Features hold x − x_latest: the last step moved by minus the previous row's value.
            let mean_m = DVec2::new(-f64::from(previous[0]), -f64::from(previous[1]));
            let [_, _, radial_velocity, rcs, time] = previous.map(f64::from);
            Some(Displacement::with_covariance(
                mean_m,
                DMat2::from_cols(DVec2::new(radial_velocity, time), DVec2::new(time, rcs)),
            ))
        }));
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        for (displacement, answer) in
            displacements.iter_mut().zip(self.answers.iter().chain(std::iter::repeat(&None)))
        {
            *displacement = *answer;
        }
    }
}
