//! The learned displacement predictor behind a small trait (paper, Section III-C).
//!
//! The tracker builds one [`PredictionRequest`] per live track and frame: the track's last
//! `L ≤ 5` associated measurements laid out as `eq:pr_input` (positions relative to the latest
//! measurement, radial velocity, RCS, time relative to the prediction time). A
//! [`DisplacementPredictor`] answers a whole batch at once; `None` for a request means "no
//! prediction this frame" and the PR mode sits the frame out for that track.
//!
//! # Which displacement
//!
//! `eq:pr_prior` adds the displacement to the PR estimate of the previous *frame*. A track is
//! not measured in every frame (the radars scan in turn, and an object is usually seen by only
//! some of them), so its latest measurement may be older than the previous frame. The
//! displacement a predictor returns is therefore the one over the tracker step
//! `[step_start_s, prediction_time_s]`. A model that predicts the displacement from the latest
//! measurement to a given time, `f(t)`, answers `f(t_k)` when the track was measured in the
//! previous frame and `f(t_k) − f(t_{k−1})` otherwise, so the PR prior stays
//! `z_latest + f(t_k)` however many frames the track coasts ([`PredictionRequest::at_time`]
//! builds the input for `f(t_{k−1})`).
//!
//! That second prediction is not new work: a track that was not measured in the previous frame
//! has the same history as then, and the previous frame asked for `f(t_{k−1})` already. A
//! predictor that returns `f(t_k)` with its answer ([`Displacement::from_latest_m`]) gets it back
//! the next frame as [`PredictionRequest::step_start_displacement_m`]: the tracker keeps it per
//! track ([`RememberedDisplacement`]) while the history stays the same, and the predictor needs
//! one model row for a coasting track instead of two.

use alloc::boxed::Box;
use alloc::string::String;
use glam::{DMat2, DVec2};

pub use crate::limits::MAX_HISTORY;
/// Features per history step: `[x − x_{k−1}, y − y_{k−1}, v_r, RCS, t − t_k]`.
pub const FEATURES: usize = 5;

/// One associated measurement in a track's history, absolute values.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HistoryEntry {
    /// x position, m.
    pub x_m: f64,
    /// y position, m.
    pub y_m: f64,
    /// Radial velocity, m/s.
    pub radial_velocity_mps: f64,
    /// Radar cross section, dBsm.
    pub rcs_dbsm: f64,
    /// Measurement time, s.
    pub timestamp_s: f64,
    /// x position of the radar that took the measurement, in the same frame as `x_m`, m: where
    /// its radial velocity's line of sight starts (the vehicle's reference point for a radar
    /// without a configured mount).
    pub sensor_x_m: f64,
    /// y position of that radar, m.
    pub sensor_y_m: f64,
}

/// A track's prediction input, laid out as `eq:pr_input`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PredictionRequest {
    /// Rows `0..len` hold the history oldest first; rows `len..` are zero padding.
    pub features: [[f32; FEATURES]; MAX_HISTORY],
    /// Number of valid rows (1..=5).
    pub len: usize,
    /// The latest measured position `z_{k−1}` in absolute coordinates, m (not a model input;
    /// lets an oracle or a diagnostic relate the request to the scene).
    pub anchor_m: DVec2,
    /// Time of the latest measurement, s (not a model input).
    pub anchor_time_s: f64,
    /// Where the radar that took the latest measurement was, in the frame of `anchor_m`, m (not
    /// a model input): the latest measurement's line of sight runs from here to `anchor_m`, and
    /// a predictor may take its input axes from it.
    pub sensor_m: DVec2,
    /// Prediction time `t_k`, s (not a model input).
    pub prediction_time_s: f64,
    /// Start of the tracker step, s: the time of the previous frame, where the PR estimate the
    /// displacement is added to lives (not a model input). Never earlier than the latest
    /// history measurement; equal to it when the track was measured in the previous frame.
    pub step_start_s: f64,
    /// The displacement from the latest measurement to `step_start_s`, `f(t_{k−1})`, as this
    /// predictor answered it for the same track and history in the previous frame; `None` when
    /// it is not known (not a model input). Set only when the step starts after the latest
    /// measurement. A predictor of `f(t)` may answer `f(t_k)` minus this instead of predicting
    /// `f(t_{k−1})` again; one that ignores it answers as without it.
    pub step_start_displacement_m: Option<DVec2>,
}

impl PredictionRequest {
    /// Builds the request from a history (oldest first, at least one entry, at most
    /// [`MAX_HISTORY`] used: the latest ones) and the prediction time.
    pub fn from_history(history: &[HistoryEntry], prediction_time_s: f64) -> Self {
        let start = history.len().saturating_sub(MAX_HISTORY);
        let history = &history[start..];
        let mut request = PredictionRequest { len: history.len(), prediction_time_s, ..Default::default() };
        if let Some(latest) = history.last() {
            request.anchor_m = DVec2::new(latest.x_m, latest.y_m);
            request.anchor_time_s = latest.timestamp_s;
            request.sensor_m = DVec2::new(latest.sensor_x_m, latest.sensor_y_m);
            request.step_start_s = latest.timestamp_s;
            for (row, entry) in request.features.iter_mut().zip(history) {
                *row = [
                    (entry.x_m - latest.x_m) as f32,
                    (entry.y_m - latest.y_m) as f32,
                    entry.radial_velocity_mps as f32,
                    entry.rcs_dbsm as f32,
                    (entry.timestamp_s - prediction_time_s) as f32,
                ];
            }
        }
        request
    }

    /// The same request with the step starting at `step_start_s` (the previous frame's time),
    /// kept between the latest measurement's time and the prediction time.
    pub fn with_step_start(mut self, step_start_s: f64) -> Self {
        self.step_start_s = step_start_s.max(self.anchor_time_s).min(self.prediction_time_s);
        self
    }

    /// The same request with `f(t_{k−1})` from `remembered`, if that is the previous frame's
    /// answer for this history and step start ([`RememberedDisplacement::serves`]).
    pub fn with_remembered_step_start(mut self, remembered: Option<&RememberedDisplacement>) -> Self {
        self.step_start_displacement_m = remembered.and_then(|remembered| remembered.serves(&self));
        self
    }

    /// Whether the step starts after the latest measurement, i.e. the track was not measured in
    /// the previous frame and the displacement is a difference of two predictions.
    pub fn step_starts_after_latest_measurement(&self) -> bool {
        self.len > 0 && self.step_start_s > self.anchor_time_s
    }

    /// Whether `self`, a request built ahead of its frame (speculatively, for a guessed
    /// prediction time), is `actual` for a predictor whose answer depends only on the model
    /// input ([`AnswerDependence::ModelInput`]): the same features bit for
    /// bit (the time feature `t_l − t_k` included, so a guessed time that differs in the last
    /// bits of an `f64` still matches when every `f32` feature is the same), the same history
    /// length, anchor, anchor time, sensor position, step start and remembered `f(t_{k−1})`,
    /// and the same `f32` step length `t_k − t_{k−1}` (the shift [`at_time`](Self::at_time)
    /// applies for the step start). Everything a predictor computes from such a request is
    /// then computed from the same numbers, so its answer is the same bit for bit.
    pub fn same_model_input(&self, actual: &PredictionRequest) -> bool {
        let step = |request: &PredictionRequest| {
            ((request.prediction_time_s - request.step_start_s) as f32).to_bits()
        };
        let same_features = self
            .features
            .iter()
            .flatten()
            .zip(actual.features.iter().flatten())
            .all(|(a, b)| a.to_bits() == b.to_bits());
        let same_remembered = match (self.step_start_displacement_m, actual.step_start_displacement_m) {
            (None, None) => true,
            (Some(a), Some(b)) => same_bits(a, b),
            _ => false,
        };
        same_features
            && same_remembered
            && self.len == actual.len
            && same_bits(self.anchor_m, actual.anchor_m)
            && self.anchor_time_s.to_bits() == actual.anchor_time_s.to_bits()
            && same_bits(self.sensor_m, actual.sensor_m)
            && self.step_start_s.to_bits() == actual.step_start_s.to_bits()
            && step(self) == step(actual)
    }

    /// Whether `self` and `actual` are the same request bit for bit, the prediction time
    /// included: the rule for a predictor that may read any field.
    pub fn same_bits(&self, actual: &PredictionRequest) -> bool {
        self.same_model_input(actual)
            && self.prediction_time_s.to_bits() == actual.prediction_time_s.to_bits()
    }

    /// The model input for predicting at `time_s` instead of the prediction time: the time
    /// feature `t_l − t` of every valid row shifted; everything else unchanged.
    pub fn at_time(&self, time_s: f64) -> Self {
        let mut request = *self;
        let shift = (self.prediction_time_s - time_s) as f32;
        for row in &mut request.features[..self.len] {
            row[4] += shift;
        }
        request.prediction_time_s = time_s;
        request
    }
}

/// Whether two vectors are the same bit for bit.
fn same_bits(a: DVec2, b: DVec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// A predictor's answer for one track and step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Displacement {
    /// The displacement over the tracker step (see the module documentation), m.
    pub mean_m: DVec2,
    /// The covariance of the displacement's error as the model estimates it, m² (symmetric,
    /// positive definite), or `None` from a model without an uncertainty output. With one, and
    /// `predictor.process_noise = "learned"`, it is the PR mode's `Q_PR` of this track and step
    /// (`eq:pr_cov`); otherwise the configured constant `Q_PR` is used.
    pub covariance_m2: Option<DMat2>,
    /// The displacement from the request's latest measurement to its prediction time, `f(t_k)`,
    /// m, from a predictor that computes it (`None` otherwise): the tracker remembers it for the
    /// next frame ([`RememberedDisplacement`]). Equal to `mean_m` when the step starts at the
    /// latest measurement.
    pub from_latest_m: Option<DVec2>,
}

impl Displacement {
    /// A displacement without an uncertainty.
    pub fn new(mean_m: DVec2) -> Self {
        Self { mean_m, covariance_m2: None, from_latest_m: None }
    }

    /// A displacement with the model's covariance of its error.
    pub fn with_covariance(mean_m: DVec2, covariance_m2: DMat2) -> Self {
        Self { mean_m, covariance_m2: Some(covariance_m2), from_latest_m: None }
    }

    /// The same displacement, telling `f(t_k)` (see [`from_latest_m`](Self::from_latest_m)).
    pub fn with_from_latest(mut self, from_latest_m: DVec2) -> Self {
        self.from_latest_m = Some(from_latest_m);
        self
    }
}

/// A predictor's `f(t)` for one track, kept by the tracker for the next frame: the displacement
/// from the latest measurement of a history to a prediction time, with what identifies that
/// history. A small `Copy` value in each track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RememberedDisplacement {
    /// Time of the history's latest measurement, s.
    pub anchor_time_s: f64,
    /// Position of that measurement, m (in the tracking frame: a change of frame moves it, and
    /// the remembered answer no longer serves).
    pub anchor_m: DVec2,
    /// Number of measurements in the history.
    pub len: usize,
    /// The time the displacement reaches, s.
    pub prediction_time_s: f64,
    /// The displacement from the latest measurement to `prediction_time_s`, m.
    pub from_latest_m: DVec2,
}

impl RememberedDisplacement {
    /// What `answer` tells about `request`'s history, if it tells `f(t_k)`.
    pub fn of(request: &PredictionRequest, answer: &Displacement) -> Option<Self> {
        let from_latest_m = answer.from_latest_m.filter(|d| d.is_finite())?;
        Some(Self {
            anchor_time_s: request.anchor_time_s,
            anchor_m: request.anchor_m,
            len: request.len,
            prediction_time_s: request.prediction_time_s,
            from_latest_m,
        })
    }

    /// `f(t_{k−1})` for `request`: the remembered displacement, if `request` starts its step
    /// after its latest measurement, at the time this one reaches, from the same history.
    pub fn serves(&self, request: &PredictionRequest) -> Option<DVec2> {
        let same = request.step_starts_after_latest_measurement()
            && self.prediction_time_s == request.step_start_s
            && self.anchor_time_s == request.anchor_time_s
            && self.anchor_m == request.anchor_m
            && self.len == request.len;
        same.then_some(self.from_latest_m)
    }
}

impl From<DVec2> for Displacement {
    fn from(mean_m: DVec2) -> Self {
        Self::new(mean_m)
    }
}

/// What a predictor's answer to one request depends on (see
/// [`DisplacementPredictor::answer_dependence`]); ordered from the most to the least.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum AnswerDependence {
    /// Possibly on the other requests of its batch, on earlier batches or on anything else: an
    /// answer computed ahead of its frame is never reused (none is computed).
    #[default]
    Batch,
    /// On the request alone, any of its fields: an answer computed ahead is reused when the
    /// frame's request is the same bit for bit ([`PredictionRequest::same_bits`]).
    Request,
    /// On the model input alone ([`PredictionRequest::same_model_input`]): an answer computed
    /// ahead for a guessed prediction time is reused when the model input is the same.
    ModelInput,
}

impl AnswerDependence {
    /// Whether an answer computed for `speculated` serves `actual` under this dependence.
    pub fn serves(self, speculated: &PredictionRequest, actual: &PredictionRequest) -> bool {
        match self {
            AnswerDependence::Batch => false,
            AnswerDependence::Request => speculated.same_bits(actual),
            AnswerDependence::ModelInput => speculated.same_model_input(actual),
        }
    }
}

/// Predicts the displacement of many tracks over one tracker step (see the module
/// documentation), in two steps so that an implementation may run the batch elsewhere (another
/// thread) while the tracker predicts its physics modes.
pub trait DisplacementPredictor {
    /// Starts predicting one batch. May return before the work is done.
    fn submit(&mut self, requests: &[PredictionRequest]);
    /// Delivers the batch submitted last: fills `displacements[i]` for the `i`-th request
    /// (`displacements.len()` equals the batch size); `None` where no prediction is available,
    /// e.g. after a missed deadline.
    fn collect(&mut self, displacements: &mut [Option<Displacement>]);
    /// [`submit`](Self::submit) then [`collect`](Self::collect).
    fn predict(&mut self, requests: &[PredictionRequest], displacements: &mut [Option<Displacement>]) {
        self.submit(requests);
        self.collect(displacements);
    }
    /// What this predictor's answer to one request depends on, which says when the tracker
    /// may reuse an answer computed ahead of its frame for a guessed prediction time
    /// ([`Tracker::speculate`](crate::tracker::Tracker::speculate)). The default,
    /// [`AnswerDependence::Batch`], never lets it.
    fn answer_dependence(&self) -> AnswerDependence {
        AnswerDependence::Batch
    }
    /// A one-line summary of the predictor's own counters (batches, deadline misses, errors),
    /// for a service's shutdown report; `None` when it keeps none.
    fn report(&self) -> Option<String> {
        None
    }
}

/// A predictor that never predicts: the PR mode sits out every frame.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoPredictor;

impl DisplacementPredictor for NoPredictor {
    fn submit(&mut self, _requests: &[PredictionRequest]) {}
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
    }
}

impl<P: DisplacementPredictor + ?Sized> DisplacementPredictor for Box<P> {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        (**self).submit(requests)
    }
    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        (**self).collect(displacements)
    }
    fn answer_dependence(&self) -> AnswerDependence {
        (**self).answer_dependence()
    }
    fn report(&self) -> Option<String> {
        (**self).report()
    }
}
