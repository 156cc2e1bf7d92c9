//! [`OnnxPredictor`]: the PR model as a synchronous [`DisplacementPredictor`]. `submit` runs
//! the batch at once, `collect` hands the results out. It is deterministic (no clock, no
//! thread), which is what offline tracking and evaluation want;
//! [`ThreadedPredictor`](crate::threaded::ThreadedPredictor) moves it onto an inference thread
//! for real-time use.
//!
//! # From model output to the tracker's displacement
//!
//! The model answers `f(t)`: the displacement from a track's latest measurement to time `t`. The
//! tracker needs the displacement over its step `[step_start_s, prediction_time_s]` (see the
//! [`primm_core::predictor`] documentation): `f(t_k)` when the track was measured in the previous frame,
//! `f(t_k) − f(t_{k−1})` otherwise. Where the request brings `f(t_{k−1})` from the previous
//! frame ([`PredictionRequest::step_start_displacement_m`]), [`OnnxPredictor`] subtracts that;
//! otherwise it evaluates both rows in the same batch, so a frame in which `n` of `N` tracks
//! coasted without it runs a batch of `N + n` rows. Every answer tells its `f(t_k)`
//! ([`Displacement::from_latest_m`]), which the tracker hands back the next frame. Each request's
//! positions go in rotated into the input axes its model names ([`InputRotation`]: along the
//! latest measurement's line of sight for the shipped model), and its displacement comes out
//! rotated back.

use super::contract::{covariance_from_cholesky, InferenceError, InputRotation, ModelError, CHOLESKY_VALUES};
use super::model::PrModel;
use glam::DVec2;
use primm_config::InferenceEngine;
use primm_core::limits::MAX_TRACKS;
use primm_core::predictor::{
    AnswerDependence, Displacement, DisplacementPredictor, PredictionRequest, FEATURES, MAX_HISTORY,
};
use std::path::Path;

/// Where a request's step starts, for turning `f(t_k)` into the step's displacement.
#[derive(Debug, Clone, Copy)]
enum StepStart {
    /// At the latest measurement: the displacement is `f(t_k)`.
    Latest,
    /// Later, with `f(t_{k−1})` in this model row of the batch.
    Row(usize),
    /// Later, with `f(t_{k−1})` known from the previous frame (request frame), m.
    Known(DVec2),
}

/// Counters of an [`OnnxPredictor`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct OnnxPredictorStats {
    /// Batches run (non-empty ones).
    pub batches: u64,
    /// Model rows run (requests plus the extra rows for tracks that coasted).
    pub rows: u64,
    /// Requests answered with a displacement.
    pub predictions: u64,
    /// Requests refused before inference (history length outside `1..=5`, non-finite values).
    pub invalid_requests: u64,
    /// Requests whose model output was not finite.
    pub non_finite_outputs: u64,
    /// Batches whose inference failed (every request of the batch went without).
    pub failed_batches: u64,
}

/// The PR model as a synchronous [`DisplacementPredictor`].
#[derive(Debug)]
pub struct OnnxPredictor {
    model: PrModel,
    features: Vec<f32>,
    valid: Vec<f32>,
    output: Vec<f32>,
    /// The covariance output of the last batch (empty for a model without one).
    cholesky: Vec<f32>,
    /// Model row of each request (`None`: refused), where its step starts, and the request's
    /// input rotation.
    rows: Vec<(Option<usize>, StepStart, InputRotation)>,
    results: Vec<Option<Displacement>>,
    stats: OnnxPredictorStats,
    last_error: Option<InferenceError>,
}

impl OnnxPredictor {
    /// Loads the model (see [`PrModel::load`]); the working buffers are sized for
    /// [`MAX_TRACKS`] requests with a step-start row each.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, ModelError> {
        Ok(Self::from_model(PrModel::load(path)?))
    }

    /// The default model built into the binary (see [`PrModel::embedded`]).
    pub fn embedded() -> Result<Self, ModelError> {
        Ok(Self::from_model(PrModel::embedded()?))
    }

    /// Wraps an already loaded model.
    pub fn from_model(model: PrModel) -> Self {
        let rows = 2 * MAX_TRACKS;
        OnnxPredictor {
            model,
            features: Vec::with_capacity(rows * MAX_HISTORY * FEATURES),
            valid: Vec::with_capacity(rows * MAX_HISTORY),
            output: Vec::with_capacity(rows * 2),
            cholesky: Vec::with_capacity(rows * CHOLESKY_VALUES),
            rows: Vec::with_capacity(MAX_TRACKS),
            results: Vec::with_capacity(MAX_TRACKS),
            stats: OnnxPredictorStats::default(),
            last_error: None,
        }
    }

    /// A second predictor on the same model (see [`PrModel::fork`]), with its own buffers and
    /// zeroed counters.
    pub fn fork(&self) -> Result<Self, ModelError> {
        Ok(Self::from_model(self.model.fork()?))
    }

    /// Chooses the model's engine ([`PrModel::set_engine`]); returns the one in use.
    pub fn set_engine(&mut self, engine: InferenceEngine) -> InferenceEngine {
        self.model.set_engine(engine)
    }

    /// The model.
    pub fn model(&self) -> &PrModel {
        &self.model
    }

    /// The counters.
    pub fn stats(&self) -> &OnnxPredictorStats {
        &self.stats
    }

    /// The error of the last failed batch, if any batch failed.
    pub fn last_error(&self) -> Option<&InferenceError> {
        self.last_error.as_ref()
    }

    /// Lays out the model rows of `requests` (see [`predict_batch`](Self::predict_batch)) in the
    /// input buffers and `rows`; returns how many there are.
    fn lay_out_rows(&mut self, requests: &[PredictionRequest]) -> usize {
        self.features.clear();
        self.valid.clear();
        self.rows.clear();
        let mut row_count = 0;
        for request in requests {
            let rotation = InputRotation::of(request, self.model.input_frame());
            let row = push_row(request, &rotation, &mut self.features, &mut self.valid).then(|| {
                row_count += 1;
                row_count - 1
            });
            self.stats.invalid_requests += u64::from(row.is_none());
            self.rows.push((row, StepStart::Latest, rotation));
        }
        for (request, rows) in requests.iter().zip(self.rows.iter_mut()) {
            if rows.0.is_none() || !request.step_starts_after_latest_measurement() {
                continue;
            }
            if let Some(known) = request.step_start_displacement_m.filter(|known| known.is_finite()) {
                rows.1 = StepStart::Known(known);
                continue;
            }
            let shifted = request.at_time(request.step_start_s);
            if push_row(&shifted, &rows.2, &mut self.features, &mut self.valid) {
                rows.1 = StepStart::Row(row_count);
                row_count += 1;
            } else {
                rows.0 = None;
                self.stats.invalid_requests += 1;
            }
        }
        row_count
    }

    /// Runs the model on `requests` and writes each request's step displacement (see the
    /// [module documentation](self)) to `displacements` (same length): `None` for a refused
    /// request or a non-finite output. On an inference failure every entry is `None` and the
    /// error is returned.
    ///
    /// With a model that estimates its uncertainty, each displacement carries the covariance
    /// of the model's answer at the prediction time, rotated back like the displacement. For
    /// a track that coasted (the displacement is the difference of two answers) that is the
    /// covariance of the displacement from the latest measurement, which bounds the one of the
    /// step from above: the two answers' errors are strongly correlated and no model output
    /// describes their difference.
    pub fn predict_batch(
        &mut self,
        requests: &[PredictionRequest],
        displacements: &mut [Option<Displacement>],
    ) -> Result<(), InferenceError> {
        displacements.fill(None);
        let row_count = self.lay_out_rows(requests);
        if row_count == 0 {
            return Ok(());
        }
        self.output.clear();
        self.output.resize(row_count * 2, 0.0);
        self.cholesky.clear();
        self.stats.batches += 1;
        self.stats.rows += row_count as u64;
        let run = if self.model.has_uncertainty() {
            self.cholesky.resize(row_count * CHOLESKY_VALUES, 0.0);
            self.model.run_with_uncertainty(&self.features, &self.valid, &mut self.output, &mut self.cholesky)
        } else {
            self.model.run(&self.features, &self.valid, &mut self.output)
        };
        if let Err(error) = run {
            self.stats.failed_batches += 1;
            self.last_error = Some(error.clone());
            return Err(error);
        }
        let at =
            |row: usize| DVec2::new(f64::from(self.output[2 * row]), f64::from(self.output[2 * row + 1]));
        let covariance_at = |row: usize| {
            let values = self.cholesky.get(CHOLESKY_VALUES * row..CHOLESKY_VALUES * (row + 1))?;
            Some(covariance_from_cholesky([values[0], values[1], values[2]]))
        };
        for (out, &(row, start_row, rotation)) in displacements.iter_mut().zip(&self.rows) {
            let Some(row) = row else { continue };
            let from_latest = rotation.from_model(at(row));
            let displacement = match start_row {
                StepStart::Latest => from_latest,
                StepStart::Row(start_row) => rotation.from_model(at(row) - at(start_row)),
                StepStart::Known(known) => from_latest - known,
            };
            if displacement.is_finite() && from_latest.is_finite() {
                *out = Some(Displacement {
                    mean_m: displacement,
                    covariance_m2: covariance_at(row)
                        .map(|covariance| rotation.covariance_from_model(covariance)),
                    from_latest_m: Some(from_latest),
                });
                self.stats.predictions += 1;
            } else {
                self.stats.non_finite_outputs += 1;
            }
        }
        Ok(())
    }
}

/// Appends the model rows of one request, its positions rotated by `rotation`; `false` (nothing
/// appended) if the request is unusable.
fn push_row(
    request: &PredictionRequest,
    rotation: &InputRotation,
    features: &mut Vec<f32>,
    valid: &mut Vec<f32>,
) -> bool {
    let len = request.len;
    if !(1..=MAX_HISTORY).contains(&len) || !request.features[..len].iter().flatten().all(|v| v.is_finite()) {
        return false;
    }
    for (index, row) in request.features.iter().enumerate() {
        if index < len {
            let position = rotation.to_model(DVec2::new(f64::from(row[0]), f64::from(row[1])));
            features.extend_from_slice(&[position.x as f32, position.y as f32, row[2], row[3], row[4]]);
            valid.push(1.0);
        } else {
            features.extend_from_slice(&[0.0; FEATURES]);
            valid.push(0.0);
        }
    }
    true
}

impl DisplacementPredictor for OnnxPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        let mut results = std::mem::take(&mut self.results);
        results.clear();
        results.resize(requests.len(), None);
        // A failed batch leaves every entry `None`; the error is counted and kept.
        let _ = self.predict_batch(requests, &mut results);
        self.results = results;
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
        for (out, result) in displacements.iter_mut().zip(&self.results) {
            *out = *result;
        }
    }

    /// On the native engine, the model input alone: it computes one sample at a time, reading
    /// the request only through its features (rotated by the anchor and sensor positions), its
    /// step start and remembered `f(t_{k−1})`, and the `f32` step length. On tract, whose plans
    /// for different batch sizes may round differently, anything in the batch.
    fn answer_dependence(&self) -> AnswerDependence {
        match self.model.engine() {
            InferenceEngine::Native => AnswerDependence::ModelInput,
            InferenceEngine::Tract => AnswerDependence::Batch,
        }
    }

    fn report(&self) -> Option<String> {
        let s = &self.stats;
        Some(format!(
            "learned predictor ({}): {} batches, {} rows, {} predictions, {} invalid requests, {} non-finite outputs, {} failed batches",
            self.model.source(),
            s.batches,
            s.rows,
            s.predictions,
            s.invalid_requests,
            s.non_finite_outputs,
            s.failed_batches
        ))
    }
}
