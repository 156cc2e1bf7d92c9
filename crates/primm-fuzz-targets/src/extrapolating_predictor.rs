//! A deterministic stand-in for the learned predictor whose answers follow the input frames.

use glam::DVec2;
use primm_core::predictor::{DisplacementPredictor, PredictionRequest};

/// Predicts the displacement a track made between its last two measurements (taken from the
/// request's relative-position features), so that a hostile frame controls the predictor's
/// answers as well as the measurements; `None` for a track with one measurement.
#[derive(Debug, Clone, Default)]
pub struct ExtrapolatingPredictor {
    answers: Vec<Option<DVec2>>,
}

impl DisplacementPredictor for ExtrapolatingPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.answers.clear();
        self.answers.extend(requests.iter().map(|request| {
            let previous = request.len.checked_sub(2).map(|row| request.features[row])?;
            // Features hold x − x_latest: the last step moved by minus the previous row's value.
            Some(DVec2::new(-f64::from(previous[0]), -f64::from(previous[1])))
        }));
    }

    fn collect(&mut self, displacements: &mut [Option<DVec2>]) {
        for (displacement, answer) in
            displacements.iter_mut().zip(self.answers.iter().chain(std::iter::repeat(&None)))
        {
            *displacement = *answer;
        }
    }
}
