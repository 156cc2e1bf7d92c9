//! Mean posterior mode probabilities (`fig:mode_probability`).
//!
//! The mean is taken over every row that carries posterior mode probabilities, i.e. every track
//! update of an IMM method, pooled over all sequences.

use serde::{Deserialize, Serialize};

use super::record::AssociationRecord;

/// Mode names in the order of [`AssociationRecord::mode_probabilities`].
pub const MODE_NAMES: [&str; 4] = ["PR", "CV", "CA", "CT"];

/// Running sums of posterior mode probabilities.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ModeProbabilityAccumulator {
    sums: [f64; 4],
    count: u64,
}

impl ModeProbabilityAccumulator {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one probability vector (PR, CV, CA, CT).
    pub fn push(&mut self, probabilities: [f64; 4]) {
        for (sum, value) in self.sums.iter_mut().zip(probabilities) {
            *sum += value;
        }
        self.count += 1;
    }

    /// Adds the row's probabilities if it has any and a track took the measurement; returns
    /// whether it did.
    pub fn push_record(&mut self, record: &AssociationRecord) -> bool {
        match (record.track_id, record.mode_probabilities) {
            (Some(_), Some(probabilities)) => {
                self.push(probabilities);
                true
            }
            _ => false,
        }
    }

    /// Adds another accumulator.
    pub fn merge(&mut self, other: &ModeProbabilityAccumulator) {
        for (sum, value) in self.sums.iter_mut().zip(other.sums) {
            *sum += value;
        }
        self.count += other.count;
    }

    /// Number of probability vectors.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Mean probabilities (PR, CV, CA, CT); `None` without samples.
    pub fn mean(&self) -> Option<[f64; 4]> {
        (self.count > 0).then(|| self.sums.map(|sum| sum / self.count as f64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row;

    #[test]
    fn mean_over_updated_rows() {
        // Two updates: (0.4, 0.2, 0.3, 0.1) and (0.2, 0.2, 0.5, 0.1)
        // → mean (0.3, 0.2, 0.4, 0.1). A row without a track is ignored even if it has values.
        let mut first = identity_row(0, Some(1), Some(1));
        first.mode_probabilities = Some([0.4, 0.2, 0.3, 0.1]);
        let mut second = identity_row(1, Some(1), Some(1));
        second.mode_probabilities = Some([0.2, 0.2, 0.5, 0.1]);
        let mut dropped = identity_row(2, Some(1), None);
        dropped.mode_probabilities = Some([1.0, 0.0, 0.0, 0.0]);
        let single_model = identity_row(3, Some(1), Some(1));
        let mut acc = ModeProbabilityAccumulator::new();
        let added: Vec<bool> =
            [first, second, dropped, single_model].iter().map(|row| acc.push_record(row)).collect();
        assert_eq!(added, vec![true, true, false, false]);
        let mean = acc.mean().unwrap();
        for (got, want) in mean.iter().zip([0.3, 0.2, 0.4, 0.1]) {
            assert!((got - want).abs() < 1e-12);
        }
        assert!((mean.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn merge_pools_samples() {
        let mut a = ModeProbabilityAccumulator::new();
        a.push([1.0, 0.0, 0.0, 0.0]);
        let mut b = ModeProbabilityAccumulator::new();
        b.push([0.0, 1.0, 0.0, 0.0]);
        b.push([0.0, 1.0, 0.0, 0.0]);
        a.merge(&b);
        assert_eq!(a.count(), 3);
        let mean = a.mean().unwrap();
        assert!((mean[0] - 1.0 / 3.0).abs() < 1e-12 && (mean[1] - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(ModeProbabilityAccumulator::new().mean(), None);
    }
}
