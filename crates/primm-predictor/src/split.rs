//! A [`DisplacementPredictor`] that shares each frame's batch among several predictors, so
//! that the PR model runs on several inference threads at once.
//!
//! The PR model's cost grows with the batch (about 15 µs per model row through tract, plus
//! ~55 µs per run; `docs/BENCHMARKS.md`, section 1), and while it runs the tracking thread only
//! waits. With two cores, two [`ThreadedPredictor`]s that each take half of the batch finish
//! in about half the time. [`SplitPredictor`] does the sharing for any predictor type:
//!
//! * `submit` cuts the requests into contiguous parts, one per predictor, of nearly equal size
//!   (the first parts take one more when the batch does not divide evenly), and submits part
//!   `i` to predictor `i`; a batch smaller than [`min_requests_per_part`] times the number of
//!   predictors uses fewer of them, so a small frame does not pay several runs' overhead.
//!   Predictors without a part this frame get an empty submit.
//! * `collect` collects each predictor's part into its place in the displacements, in order.
//!   Each part keeps its own deadline (a [`ThreadedPredictor`]'s is measured from its own
//!   `submit`, microseconds apart), so the whole collect waits at most about one deadline.
//!
//! Nothing is allocated per frame: the parts are slices of the caller's buffers. A fault in
//! one predictor (a panic, a hang, a missed deadline) costs only its part: those tracks go
//! without a learned displacement, the others keep theirs.
//!
//! [`min_requests_per_part`]: SplitPredictor::min_requests_per_part

use crate::onnx::{ModelError, OnnxPredictor};
use crate::threaded::ThreadedPredictor;
use primm_core::predictor::{AnswerDependence, Displacement, DisplacementPredictor, PredictionRequest};
use std::ops::Range;
use std::time::Duration;

/// Fewest requests a part gets before the batch is split further. Below ~16 rows the fixed cost of
/// a tract run and of waking another thread outweighs what the split saves (`docs/BENCHMARKS.md`).
pub const DEFAULT_MIN_REQUESTS_PER_PART: usize = 16;

/// Why [`SplitPredictor::new`] refused its predictors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SplitError {
    /// No predictor was given.
    #[error("a split predictor needs at least one predictor")]
    NoPredictors,
}

/// Why [`on_inference_threads`] could not start the inference threads.
#[derive(Debug, thiserror::Error)]
pub enum InferenceThreadsError {
    /// The number of threads asked for was zero.
    #[error("at least one inference thread is needed")]
    NoThreads,
    /// A second instance of the model could not be prepared.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The operating system refused to start an inference thread.
    #[error("could not start an inference thread: {0}")]
    Spawn(#[source] std::io::Error),
}

/// Shares each frame's batch among several predictors (see the [module documentation](self)).
pub struct SplitPredictor<P> {
    parts: Vec<P>,
    min_requests_per_part: usize,
    /// Requests of the current frame's `submit`; `collect` splits the displacements alike.
    submitted: usize,
}

impl<P> std::fmt::Debug for SplitPredictor<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SplitPredictor")
            .field("parts", &self.parts.len())
            .field("min_requests_per_part", &self.min_requests_per_part)
            .finish_non_exhaustive()
    }
}

impl<P: DisplacementPredictor> SplitPredictor<P> {
    /// Shares batches among `parts`, splitting only batches of at least
    /// [`DEFAULT_MIN_REQUESTS_PER_PART`] requests per part.
    pub fn new(parts: Vec<P>) -> Result<Self, SplitError> {
        if parts.is_empty() {
            return Err(SplitError::NoPredictors);
        }
        Ok(SplitPredictor { parts, min_requests_per_part: DEFAULT_MIN_REQUESTS_PER_PART, submitted: 0 })
    }

    /// The same predictor, splitting batches of at least `min_requests_per_part` requests per
    /// part (at least 1): smaller parts suit inference threads that are already awake, or
    /// batches whose hand-off cost is not on the critical path.
    pub fn with_min_requests_per_part(mut self, min_requests_per_part: usize) -> Self {
        self.min_requests_per_part = min_requests_per_part.max(1);
        self
    }

    /// The fewest requests a part gets before a batch is split further.
    pub fn min_requests_per_part(&self) -> usize {
        self.min_requests_per_part
    }

    /// The predictors, in the order of the parts they take.
    pub fn parts(&self) -> &[P] {
        &self.parts
    }

    /// The predictors, to change their settings.
    pub fn parts_mut(&mut self) -> &mut [P] {
        &mut self.parts
    }

    /// How many predictors a batch of `requests` requests is shared among.
    pub fn parts_used(&self, requests: usize) -> usize {
        (requests / self.min_requests_per_part).clamp(1, self.parts.len())
    }
}

/// The requests of part `index` of a batch of `requests` shared among `used` parts.
fn part_range(requests: usize, used: usize, index: usize) -> Range<usize> {
    let (base, extra) = (requests / used, requests % used);
    let start = index * base + index.min(extra);
    start..start + base + usize::from(index < extra)
}

impl<P: DisplacementPredictor> DisplacementPredictor for SplitPredictor<P> {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.submitted = requests.len();
        let used = self.parts_used(requests.len());
        for (index, part) in self.parts.iter_mut().enumerate() {
            if index < used {
                part.submit(&requests[part_range(requests.len(), used, index)]);
            } else {
                part.submit(&[]);
            }
        }
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
        let used = self.parts_used(self.submitted);
        let available = displacements.len();
        for (index, part) in self.parts.iter_mut().enumerate() {
            if index < used {
                let range = part_range(self.submitted, used, index);
                // A caller that collects fewer displacements than it submitted gets the ones
                // that fit; every part is still collected, so none keeps a stale batch.
                let (start, end) = (range.start.min(available), range.end.min(available));
                part.collect(&mut displacements[start..end]);
            } else {
                part.collect(&mut []);
            }
        }
    }

    /// The least of the parts' (each answer comes from one part, whichever way a batch is cut).
    fn answer_dependence(&self) -> AnswerDependence {
        self.parts.iter().map(DisplacementPredictor::answer_dependence).min().unwrap_or_default()
    }

    fn report(&self) -> Option<String> {
        let lines: Vec<String> = self
            .parts
            .iter()
            .enumerate()
            .filter_map(|(index, part)| part.report().map(|line| format!("  part {}: {line}", index + 1)))
            .collect();
        Some(format!(
            "learned predictor split over {} parts (batches of at least {} requests per part are split):\n{}",
            self.parts.len(),
            self.min_requests_per_part,
            lines.join("\n")
        ))
    }
}

/// The PR model on `threads` inference threads with a per-frame `deadline`: `model` and
/// `threads − 1` forks of it (sharing its optimised plans, [`OnnxPredictor::fork`]), each on its
/// own [`ThreadedPredictor`], sharing every batch. Build it on the tracking thread (see
/// [`ThreadedPredictor::new`]).
pub fn on_inference_threads(
    model: OnnxPredictor,
    threads: usize,
    deadline: Duration,
) -> Result<SplitPredictor<ThreadedPredictor>, InferenceThreadsError> {
    if threads == 0 {
        return Err(InferenceThreadsError::NoThreads);
    }
    let forks = (1..threads).map(|_| model.fork()).collect::<Result<Vec<_>, _>>()?;
    let mut parts = Vec::with_capacity(threads);
    for model in std::iter::once(model).chain(forks) {
        parts.push(ThreadedPredictor::new(model, deadline).map_err(InferenceThreadsError::Spawn)?);
    }
    SplitPredictor::new(parts).map_err(|_| InferenceThreadsError::NoThreads)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_the_batch_in_order_with_sizes_differing_by_at_most_one() {
        for requests in 0..200 {
            for used in 1..6 {
                let ranges: Vec<_> = (0..used).map(|i| part_range(requests, used, i)).collect();
                assert_eq!(ranges[0].start, 0);
                assert_eq!(ranges[used - 1].end, requests);
                for pair in ranges.windows(2) {
                    assert_eq!(pair[0].end, pair[1].start);
                    assert!(pair[0].len() >= pair[1].len() && pair[0].len() - pair[1].len() <= 1);
                }
            }
        }
    }
}
