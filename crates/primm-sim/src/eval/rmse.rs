//! One-step prior RMSE (`eq:rmse_x`, `eq:rmse_y`, `eq:rmse_xy`) as a streaming accumulator.
//!
//! The accumulator keeps the sums of squared errors and the sample count, so results of
//! sequences, classes or scenario subsets merge exactly by addition; the square root is taken
//! only when a value is read.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::record::AssociationRecord;

/// Sums of squared prior errors along x and y plus the number of samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RmseAccumulator {
    sum_sq_x: f64,
    sum_sq_y: f64,
    count: u64,
}

impl RmseAccumulator {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample: the error between a reference position and an estimate.
    pub fn push(&mut self, reference: DVec2, estimate: DVec2) {
        let error = reference - estimate;
        self.sum_sq_x += error.x * error.x;
        self.sum_sq_y += error.y * error.y;
        self.count += 1;
    }

    /// Adds the row's prior error against its reference position (true position when known,
    /// else the measurement). Rows without a prior, and rows of no ground-truth object (false
    /// detections: there is no object whose motion the prior predicted), are skipped; returns
    /// whether a sample was added.
    pub fn push_record(&mut self, record: &AssociationRecord) -> bool {
        match record.prior.filter(|_| record.ground_truth_id.is_some()) {
            Some(prior) => {
                self.push(record.reference_position(), prior);
                true
            }
            None => false,
        }
    }

    /// Adds every row of `records` that has a prior.
    pub fn extend_records<'a>(&mut self, records: impl IntoIterator<Item = &'a AssociationRecord>) {
        for record in records {
            self.push_record(record);
        }
    }

    /// Adds the samples of another accumulator.
    pub fn merge(&mut self, other: &RmseAccumulator) {
        self.sum_sq_x += other.sum_sq_x;
        self.sum_sq_y += other.sum_sq_y;
        self.count += other.count;
    }

    /// Number of samples (N in `eq:rmse_x`).
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Longitudinal RMSE in metres; `None` without samples.
    pub fn rmse_x(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_x)
    }

    /// Lateral RMSE in metres; `None` without samples.
    pub fn rmse_y(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_y)
    }

    /// Planar RMSE in metres; `None` without samples. Note that
    /// `rmse_xy² = rmse_x² + rmse_y²`.
    pub fn rmse_xy(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_x + self.sum_sq_y)
    }

    fn mean_of(&self, sum: f64) -> Option<f64> {
        (self.count > 0).then(|| (sum / self.count as f64).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn known_errors() {
        // Errors (dx, dy): (3, 4), (0, 0), (-1, 2), (0, -2).
        // sum dx² = 9 + 0 + 1 + 0 = 10 → RMSE_x = sqrt(10/4) = sqrt(2.5)
        // sum dy² = 16 + 0 + 4 + 4 = 24 → RMSE_y = sqrt(24/4) = sqrt(6)
        // RMSE_xy = sqrt(34/4) = sqrt(8.5)
        let mut acc = RmseAccumulator::new();
        acc.push(DVec2::new(3.0, 4.0), DVec2::ZERO);
        acc.push(DVec2::new(1.0, 1.0), DVec2::new(1.0, 1.0));
        acc.push(DVec2::new(0.0, 5.0), DVec2::new(1.0, 3.0));
        acc.push(DVec2::new(2.0, -1.0), DVec2::new(2.0, 1.0));
        assert_eq!(acc.count(), 4);
        assert!(close(acc.rmse_x().unwrap(), 2.5f64.sqrt()));
        assert!(close(acc.rmse_y().unwrap(), 6f64.sqrt()));
        assert!(close(acc.rmse_xy().unwrap(), 8.5f64.sqrt()));
    }

    #[test]
    fn empty_has_no_value() {
        let acc = RmseAccumulator::new();
        assert_eq!(acc.rmse_x(), None);
        assert_eq!(acc.rmse_xy(), None);
    }

    #[test]
    fn merge_equals_pooled_samples() {
        // Sequence A: one error (2, 0); sequence B: three errors (0, 1).
        // Pooled: sum dx² = 4, sum dy² = 3, N = 4 → RMSE_xy = sqrt(7/4).
        // (Averaging per-sequence RMSE_xy values, 2 and 1, would give 1.5 instead.)
        let mut a = RmseAccumulator::new();
        a.push(DVec2::new(2.0, 0.0), DVec2::ZERO);
        let mut b = RmseAccumulator::new();
        for _ in 0..3 {
            b.push(DVec2::new(0.0, 1.0), DVec2::ZERO);
        }
        a.merge(&b);
        assert_eq!(a.count(), 4);
        assert!(close(a.rmse_xy().unwrap(), (7.0f64 / 4.0).sqrt()));
    }

    #[test]
    fn records_use_truth_then_measurement_and_skip_rows_without_prior_or_object() {
        let mut with_truth = identity_row(0, Some(1), Some(1));
        with_truth.measured = DVec2::new(10.0, 0.0);
        with_truth.true_position = Some(DVec2::new(1.0, 0.0));
        with_truth.prior = Some(DVec2::new(0.0, 0.0)); // error 1 against truth, not 10
        let mut measured_only = identity_row(1, Some(1), Some(1));
        measured_only.measured = DVec2::new(0.0, 3.0);
        measured_only.prior = Some(DVec2::ZERO); // error 3 in y
        let started = identity_row(2, Some(2), Some(2)); // no prior: new track
        let mut clutter = identity_row(3, None, Some(1)); // a false detection a track took
        clutter.prior = Some(DVec2::new(50.0, 50.0));
        let mut acc = RmseAccumulator::new();
        acc.extend_records(&[with_truth, measured_only, started, clutter]);
        assert_eq!(acc.count(), 2);
        assert!(close(acc.rmse_x().unwrap(), (1.0f64 / 2.0).sqrt()));
        assert!(close(acc.rmse_y().unwrap(), (9.0f64 / 2.0).sqrt()));
    }
}
