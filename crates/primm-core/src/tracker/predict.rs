//! The predict stage: the learned predictor gets its batch, the physics modes and the
//! existence probabilities are predicted meanwhile, then the learned displacements are checked
//! and every track's prior is completed and fused (`eq:prior_fusion`).

use super::{step_imms, Tracker};
use crate::config::{LearnedProcessNoise, PredictorConfig};
use crate::displacement_check::{check_answer, DisplacementRejection};
use crate::existence;
use crate::mode::Mode;
use crate::predictor::{Displacement, DisplacementPredictor, PredictionRequest, RememberedDisplacement};
use crate::track::Track;
use crate::track_loops;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Hands the history (`eq:pr_input`) of every track of a class in `predictor.classes` to
    /// the learned predictor, less the requests that a batch computed ahead answers
    /// (`super::speculation`).
    pub(super) fn request_learned_predictions(&mut self, t: f64) {
        self.requests.clear();
        self.requested_rows.clear();
        let modes = self.config.imm.modes;
        if !modes.contains(Mode::Learned) {
            return;
        }
        let step_start = self.last_timestamp_s.unwrap_or(t);
        self.speculation.record_interval(t - step_start);
        for (row, track) in self.table.tracks().iter().enumerate() {
            if !self.config.predictor.predicts(track.class, modes) {
                continue;
            }
            self.requests.push(learned_request(track, t, step_start));
            // The table holds at most MAX_TRACKS (512) rows, so the row fits in u16.
            self.requested_rows.push(row as u16);
        }
        self.speculation.submit(&mut self.predictor, &self.requests);
    }

    /// Mixing and the CV, CA and CT predictions, while the predictor works.
    pub(super) fn predict_physics(&mut self, dt_s: f64) {
        self.dt_s = dt_s;
        track_loops::predict_physics(
            step_imms(self.step_pose.is_some(), &self.imms, &self.compensated_imms),
            &self.models,
            self.table.tracks(),
            dt_s,
            &mut self.priors[..],
        );
    }

    /// Every track's object may have ceased to exist since the last frame: `r⁻ = p_s · r`.
    pub(super) fn predict_existence(&mut self, dt_s: f64) {
        let survival = existence::survival_probability(dt_s, &self.config.tracker);
        for track in self.table.tracks_mut() {
            track.existence_probability *= survival;
        }
    }

    /// The learned displacements collected and checked, then every track's prior completed:
    /// the PR prior and the fused prior (`eq:prior_fusion`). A track without a request, or
    /// whose answer is missing or refused, gets no displacement and its PR mode sits out.
    pub(super) fn fuse_priors(&mut self) {
        let count = self.table.len();
        self.displacements[..count].fill(None);
        if !self.requests.is_empty() {
            self.collect_displacements();
        }
        track_loops::complete_priors(
            step_imms(self.step_pose.is_some(), &self.imms, &self.compensated_imms),
            &self.models,
            self.table.tracks(),
            self.dt_s,
            &self.displacements[..count],
            &mut self.priors[..],
        );
    }

    /// The predictor's answers, each checked (`crate::displacement_check`; a refused one is
    /// counted and dropped) and handed to its track's row.
    fn collect_displacements(&mut self) {
        let answers = &mut self.answers[..self.requests.len()];
        self.speculation.gather(&mut self.predictor, answers);
        for (answer, request) in answers.iter_mut().zip(self.requests.iter()) {
            let Some(displacement) = answer.as_mut() else { continue };
            if let Err(reason) = accept_displacement(request, displacement, &self.config.predictor) {
                self.last_step.count_displacement_rejection(reason);
                *answer = None;
            }
        }
        let missing = answers.iter().filter(|answer| answer.is_none()).count() as u64;
        self.last_step.counts.learned_predictions_missing = missing;
        self.last_step.counts.frames_with_learned_predictions_missing = u64::from(missing > 0);
        let tracks = self.table.tracks_mut();
        for ((answer, request), &row) in
            answers.iter().zip(self.requests.iter()).zip(self.requested_rows.iter())
        {
            let row = usize::from(row);
            self.displacements[row] = *answer;
            tracks[row].remembered_displacement =
                answer.as_ref().and_then(|answer| RememberedDisplacement::of(request, answer));
        }
    }
}

/// The learned-prediction request of `track` for `prediction_time_s`, its step starting at
/// `step_start_s` (the previous frame's time), with the displacement it remembers.
pub(super) fn learned_request(track: &Track, prediction_time_s: f64, step_start_s: f64) -> PredictionRequest {
    let (older, newer) = track.history.as_slices();
    let mut window = [Default::default(); crate::predictor::MAX_HISTORY];
    let len = older.len() + newer.len();
    window[..older.len()].copy_from_slice(older);
    window[older.len()..len].copy_from_slice(newer);
    PredictionRequest::from_history(&window[..len], prediction_time_s)
        .with_step_start(step_start_s)
        .with_remembered_step_start(track.remembered_displacement.as_ref())
}

/// Checks one learned displacement against its request and sets its process noise `Q_PR`
/// (`eq:pr_cov`) as `predictor.process_noise` says: the model's covariance, scaled, or none
/// (the class's constant then applies).
fn accept_displacement(
    request: &PredictionRequest,
    displacement: &mut Displacement,
    predictor: &PredictorConfig,
) -> Result<(), DisplacementRejection> {
    check_answer(request, displacement, predictor.max_displacement_speed_mps)?;
    displacement.covariance_m2 = match predictor.process_noise {
        LearnedProcessNoise::Learned => {
            displacement.covariance_m2.map(|q| q * predictor.learned_process_noise_scale)
        }
        LearnedProcessNoise::Constant => None,
    };
    Ok(())
}
