//! Learned predictions computed between frames, for the next frame's guessed time.
//!
//! Once a frame's update is done, a track's PR input (`eq:pr_input`) is fixed until the next
//! frame except for the prediction time: the history changes only in an update, the step
//! starts at the frame just tracked, and the remembered `f(t_{k−1})` is this frame's answer.
//! [`Tracker::speculate`] guesses the next frame's time from the recent frame intervals
//! ([`IntervalGuess`]) and hands the requests for that time to the predictor right away, so that
//! an inference thread works on them while the tracker is idle between frames.
//!
//! The next frame builds its requests as always and compares each with the one built ahead
//! for the same place in the batch. Where the predictor's [`AnswerDependence`] says the answer
//! would be the same ([`AnswerDependence::serves`]: the same model input bit for bit for the PR
//! model, whose input holds the time only as `f32` differences, so a guess a few `f64` bits
//! off still matches), the answer computed ahead is used; every other request (a wrong guess, a
//! change of tracking frame, a reset, a late frame's replay) is predicted in the frame as
//! without speculation. The results are therefore those of a tracker that never speculates, bit
//! for bit, with a deterministic predictor (`tests/speculation.rs`).
//!
//! With a [`ThreadedPredictor`](../../primm_predictor/threaded/index.html) the answers computed
//! ahead obey its deadline, measured from when they were handed over: a matched request whose
//! answer missed it goes without (as a late answer would), and only the requests not foreseen
//! are predicted in the frame, so a frame waits at most the rest of the speculative batch's
//! deadline and one deadline for the rest.
//!
//! Every buffer is allocated with the tracker; nothing is allocated per frame.

use super::predict::learned_request;
use super::Tracker;
use crate::limits::MAX_TRACKS;
use crate::mode::Mode;
use crate::predictor::{AnswerDependence, Displacement, DisplacementPredictor, PredictionRequest};
use alloc::boxed::Box;
use arrayvec::ArrayVec;

/// Frame intervals remembered for the guess.
const INTERVALS: usize = 8;

/// Longest repeating pattern of frame intervals the guess looks for (e.g. radars that scan in
/// turn at different offsets).
const MAX_PATTERN: usize = 4;

/// Two intervals closer than this fraction of the larger one count as the same.
const SAME_INTERVAL_FRACTION: f64 = 1e-6;

/// After this many frames in a row in which the batch computed ahead answered none of the
/// frame's requests (frame times that cannot be guessed, e.g. radars with scan jitter), the
/// tracker speculates only every [`PROBE_INTERVAL_FRAMES`] frames, so that the inference threads
/// do not compute answers that are thrown away.
const FRUITLESS_BEFORE_BACK_OFF: u32 = 3;

/// While backed off, one frame in this many still speculates, to notice when guessing works
/// again.
const PROBE_INTERVAL_FRAMES: u32 = 16;

/// Counters of the speculation, kept since the tracker was built.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SpeculationStats {
    /// Batches handed to the predictor ahead of their frame.
    pub batches: u64,
    /// Requests in those batches.
    pub requests_speculated: u64,
    /// Requests of a frame answered from the batch computed ahead.
    pub requests_served: u64,
    /// Requests of a frame with a batch computed ahead that had to be predicted in the frame
    /// (no request or a different one at their place in that batch).
    pub requests_recomputed: u64,
    /// Calls of [`Tracker::speculate`] that handed nothing over because the recent batches
    /// computed ahead answered nothing (see [`FRUITLESS_BEFORE_BACK_OFF`]).
    pub skipped_after_misses: u64,
}

/// The next frame interval, guessed from the recent ones: the interval that followed the
/// latest earlier occurrence of the newest one within [`MAX_PATTERN`] frames, so that a
/// constant rate and a repeating scan pattern both come out right; the newest interval
/// otherwise.
#[derive(Debug, Clone, Copy, Default)]
pub struct IntervalGuess {
    /// Recent intervals, oldest first (the first `count`).
    intervals: [f64; INTERVALS],
    count: usize,
}

impl IntervalGuess {
    /// Records the interval between two consecutive frames (ignored unless positive and
    /// finite).
    pub fn record(&mut self, interval_s: f64) {
        if !(interval_s.is_finite() && interval_s > 0.0) {
            return;
        }
        if self.count == INTERVALS {
            self.intervals.copy_within(1.., 0);
            self.count -= 1;
        }
        self.intervals[self.count] = interval_s;
        self.count += 1;
    }

    /// The guess for the next interval, s; `None` before the first interval.
    pub fn next(&self) -> Option<f64> {
        let seen = &self.intervals[..self.count];
        let (&newest, _) = seen.split_last()?;
        let same = |a: f64, b: f64| (a - b).abs() <= SAME_INTERVAL_FRACTION * a.max(b);
        (1..=MAX_PATTERN.min(seen.len() - 1))
            .find(|&lag| same(newest, seen[seen.len() - 1 - lag]))
            .map(|lag| seen[seen.len() - lag])
            .or(Some(newest))
    }
}

/// The speculation's state and buffers (see the [module documentation](self)).
#[derive(Debug)]
pub(super) struct Speculation {
    guess: IntervalGuess,
    /// Whether the predictor holds a batch submitted ahead that no frame has collected yet.
    pending: bool,
    /// The requests of that batch and, once collected, their answers.
    requests: Box<ArrayVec<PredictionRequest, MAX_TRACKS>>,
    answers: Box<[Option<Displacement>; MAX_TRACKS]>,
    /// Per request of the current frame: whether the batch computed ahead answers it.
    served: Box<[bool; MAX_TRACKS]>,
    /// The current frame's requests that the batch computed ahead does not answer, and their
    /// places among the frame's requests.
    residual: Box<ArrayVec<PredictionRequest, MAX_TRACKS>>,
    residual_places: Box<ArrayVec<u16, MAX_TRACKS>>,
    residual_answers: Box<[Option<Displacement>; MAX_TRACKS]>,
    /// Whether the residual was submitted this frame (and is to be collected).
    residual_submitted: bool,
    /// Frames in a row whose batch computed ahead answered none of their requests.
    fruitless_in_a_row: u32,
    /// Calls of `speculate` skipped since the last probe while backed off.
    skipped: u32,
    stats: SpeculationStats,
}

impl Speculation {
    pub(super) fn new() -> Self {
        Speculation {
            guess: IntervalGuess::default(),
            pending: false,
            requests: Box::new(ArrayVec::new()),
            answers: Box::new([None; MAX_TRACKS]),
            served: Box::new([false; MAX_TRACKS]),
            residual: Box::new(ArrayVec::new()),
            residual_places: Box::new(ArrayVec::new()),
            residual_answers: Box::new([None; MAX_TRACKS]),
            residual_submitted: false,
            fruitless_in_a_row: 0,
            skipped: 0,
            stats: SpeculationStats::default(),
        }
    }

    /// Records a frame interval for the guess.
    pub(super) fn record_interval(&mut self, interval_s: f64) {
        self.guess.record(interval_s);
    }

    /// Whether this call of `speculate` is to be skipped because the recent batches computed
    /// ahead answered nothing (one in [`PROBE_INTERVAL_FRAMES`] still goes ahead).
    fn backs_off(&mut self) -> bool {
        if self.fruitless_in_a_row < FRUITLESS_BEFORE_BACK_OFF {
            return false;
        }
        self.skipped += 1;
        if self.skipped < PROBE_INTERVAL_FRAMES {
            self.stats.skipped_after_misses += 1;
            return true;
        }
        self.skipped = 0;
        false
    }

    /// Hands the frame's `requests` to `predictor`: the ones the batch computed ahead answers
    /// are marked served, the others submitted (after collecting the batch computed ahead, as
    /// the predictor holds one batch at a time; when every request is served, that collect
    /// waits until [`gather`](Self::gather), so the predictor may finish while the physics
    /// modes are predicted).
    pub(super) fn submit<P: DisplacementPredictor>(
        &mut self,
        predictor: &mut P,
        requests: &[PredictionRequest],
    ) {
        self.residual.clear();
        self.residual_places.clear();
        self.residual_submitted = false;
        let dependence = predictor.answer_dependence();
        let speculated = if self.pending { self.requests.len() } else { 0 };
        for (place, request) in requests.iter().enumerate() {
            let served = place < speculated && dependence.serves(&self.requests[place], request);
            self.served[place] = served;
            if !served {
                self.residual.push(*request);
                // At most MAX_TRACKS (512) requests, so the place fits in u16.
                self.residual_places.push(place as u16);
            }
        }
        if self.pending && !requests.is_empty() {
            let served = requests.len() - self.residual.len();
            self.stats.requests_served += served as u64;
            self.stats.requests_recomputed += self.residual.len() as u64;
            self.fruitless_in_a_row = if served == 0 { self.fruitless_in_a_row.saturating_add(1) } else { 0 };
        }
        if self.residual.is_empty() {
            return;
        }
        self.collect_pending(predictor);
        predictor.submit(&self.residual);
        self.residual_submitted = true;
    }

    /// Collects the batch computed ahead, if one is pending.
    fn collect_pending<P: DisplacementPredictor>(&mut self, predictor: &mut P) {
        if self.pending {
            self.pending = false;
            let count = self.requests.len();
            predictor.collect(&mut self.answers[..count]);
        }
    }

    /// The frame's answers, aligned with the requests given to [`submit`](Self::submit): from
    /// the batch computed ahead where it serves, from the predictor otherwise.
    pub(super) fn gather<P: DisplacementPredictor>(
        &mut self,
        predictor: &mut P,
        answers: &mut [Option<Displacement>],
    ) {
        self.collect_pending(predictor);
        for (place, answer) in answers.iter_mut().enumerate() {
            *answer = if self.served[place] { self.answers[place] } else { None };
        }
        if self.residual_submitted {
            self.residual_submitted = false;
            let count = self.residual.len();
            predictor.collect(&mut self.residual_answers[..count]);
            for (&place, answer) in self.residual_places.iter().zip(self.residual_answers.iter()) {
                if let Some(slot) = answers.get_mut(usize::from(place)) {
                    *slot = *answer;
                }
            }
        }
    }
}

impl<P: DisplacementPredictor> Tracker<P> {
    /// Hands the predictor the learned-prediction requests of the next frame, for its time as
    /// guessed from the recent frame intervals, so that they are computed before it arrives (see
    /// the [module documentation](self)). Call it after a step, once its output is on its way:
    /// the next step uses the answers where its requests turn out the same and predicts the
    /// others itself, so the results do not change. Does nothing without the learned mode,
    /// before two frames have been tracked, when no track is predicted, or when the predictor's
    /// answers may depend on more than the request ([`AnswerDependence::Batch`]). After
    /// several frames whose batch computed ahead answered nothing (frame times that cannot be
    /// guessed), it hands a batch over only every few calls
    /// ([`SpeculationStats::skipped_after_misses`]).
    pub fn speculate(&mut self) {
        if !self.config.imm.modes.contains(Mode::Learned)
            || self.predictor.answer_dependence() == AnswerDependence::Batch
            || self.speculation.backs_off()
        {
            return;
        }
        let (Some(t), Some(interval_s)) = (self.last_timestamp_s, self.speculation.guess.next()) else {
            return;
        };
        let next_s = t + interval_s;
        let speculation = &mut self.speculation;
        speculation.requests.clear();
        for track in self.table.tracks() {
            if self.config.predictor.predicts(track.class, self.config.imm.modes) {
                speculation.requests.push(learned_request(track, next_s, t));
            }
        }
        if speculation.requests.is_empty() {
            return;
        }
        self.predictor.submit(&speculation.requests);
        speculation.pending = true;
        speculation.stats.batches += 1;
        speculation.stats.requests_speculated += speculation.requests.len() as u64;
    }

    /// The speculation's counters ([`speculate`](Self::speculate)).
    pub fn speculation_stats(&self) -> &SpeculationStats {
        &self.speculation.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_interval_is_guessed_as_the_next_one() {
        let mut guess = IntervalGuess::default();
        assert_eq!(guess.next(), None);
        for _ in 0..3 {
            guess.record(0.05);
        }
        assert_eq!(guess.next(), Some(0.05));
    }

    #[test]
    fn a_repeating_pattern_of_intervals_is_continued() {
        let mut guess = IntervalGuess::default();
        for interval in [0.01, 0.04, 0.01, 0.04, 0.01, 0.04] {
            guess.record(interval);
        }
        assert_eq!(guess.next(), Some(0.01));
        guess.record(0.01);
        assert_eq!(guess.next(), Some(0.04));
    }

    #[test]
    fn without_a_pattern_the_newest_interval_is_guessed_and_bad_intervals_are_ignored() {
        let mut guess = IntervalGuess::default();
        for interval in [0.01, 0.02, 0.03, f64::NAN, -1.0, 0.0] {
            guess.record(interval);
        }
        assert_eq!(guess.next(), Some(0.03));
        for interval in 1..=20 {
            guess.record(f64::from(interval));
        }
        assert_eq!(guess.next(), Some(20.0));
    }
}
