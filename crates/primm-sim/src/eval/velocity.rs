//! Velocity errors of the tracks: the fused velocity of the track that took a measurement,
//! after that update, against the true velocity of the measured object.
//!
//! Two accumulators, both additive over sequences like [`super::rmse::RmseAccumulator`]:
//!
//! * [`VelocityRmseAccumulator`]: the RMSE of the velocity vector, over the same rows as the
//!   prior RMSE of Table II (a track that existed before the update took a measurement of a
//!   ground-truth object), wherever the row carries both velocities;
//! * [`SpeedHeadingAccumulator`]: speed and heading errors over the rows of confirmed tracks
//!   (what a user of the published tracks plans with). The heading error is wrapped to
//!   [−π, π] and left out where the true speed is below [`HEADING_MIN_TRUE_SPEED_MPS`], where
//!   the heading of the motion is not defined.
//!
//! The definitions are in `docs/evaluation-metrics.md` ("Velocity errors").

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::record::AssociationRecord;

/// Rows whose true speed is below this have no heading error, m/s.
pub const HEADING_MIN_TRUE_SPEED_MPS: f64 = 0.5;

/// Sums of squared velocity errors along x and y plus the number of samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct VelocityRmseAccumulator {
    sum_sq_x: f64,
    sum_sq_y: f64,
    count: u64,
}

impl VelocityRmseAccumulator {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample: a true velocity and an estimate, m/s.
    pub fn push(&mut self, truth: DVec2, estimate: DVec2) {
        let error = estimate - truth;
        self.sum_sq_x += error.x * error.x;
        self.sum_sq_y += error.y * error.y;
        self.count += 1;
    }

    /// Adds the row's velocity error when the row is scored: it has a ground-truth id, a prior
    /// (the track existed before this update, as for the prior RMSE), an estimated and a true
    /// velocity. Returns whether a sample was added.
    pub fn push_record(&mut self, record: &AssociationRecord) -> bool {
        if record.ground_truth_id.is_none() || record.prior.is_none() {
            return false;
        }
        match (record.true_velocity, record.velocity) {
            (Some(truth), Some(estimate)) => {
                self.push(truth, estimate);
                true
            }
            _ => false,
        }
    }

    /// Adds the samples of another accumulator.
    pub fn merge(&mut self, other: &VelocityRmseAccumulator) {
        self.sum_sq_x += other.sum_sq_x;
        self.sum_sq_y += other.sum_sq_y;
        self.count += other.count;
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// RMSE of the velocity's x component, m/s; `None` without samples.
    pub fn rmse_x_mps(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_x)
    }

    /// RMSE of the velocity's y component, m/s; `None` without samples.
    pub fn rmse_y_mps(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_y)
    }

    /// RMSE of the velocity vector, `sqrt(Σ |v̂ − v|² / N)`, m/s; `None` without samples.
    pub fn rmse_mps(&self) -> Option<f64> {
        self.mean_of(self.sum_sq_x + self.sum_sq_y)
    }

    fn mean_of(&self, sum: f64) -> Option<f64> {
        (self.count > 0).then(|| (sum / self.count as f64).sqrt())
    }
}

/// Speed and heading errors: sums, sums of squares and counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SpeedHeadingAccumulator {
    speed_sum: f64,
    speed_sum_sq: f64,
    speed_count: u64,
    heading_sum_abs: f64,
    heading_sum_sq: f64,
    heading_count: u64,
}

impl SpeedHeadingAccumulator {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample: a true velocity and an estimate, m/s. The speed error `|v̂| − |v|` is
    /// always added; the heading error `wrap(atan2(v̂) − atan2(v))` only when `|v|` is at least
    /// [`HEADING_MIN_TRUE_SPEED_MPS`].
    pub fn push(&mut self, truth: DVec2, estimate: DVec2) {
        let speed_error = estimate.length() - truth.length();
        self.speed_sum += speed_error;
        self.speed_sum_sq += speed_error * speed_error;
        self.speed_count += 1;
        if truth.length() >= HEADING_MIN_TRUE_SPEED_MPS {
            let error = heading_error_rad(truth, estimate);
            self.heading_sum_abs += error.abs();
            self.heading_sum_sq += error * error;
            self.heading_count += 1;
        }
    }

    /// Adds the row when it is scored: a confirmed track took a measurement of a ground-truth
    /// object ([`AssociationRecord::is_confirmed_track_frame`]) and the row carries an
    /// estimated and a true velocity. Returns whether a sample was added.
    pub fn push_record(&mut self, record: &AssociationRecord) -> bool {
        if record.ground_truth_id.is_none() || !record.is_confirmed_track_frame() {
            return false;
        }
        match (record.true_velocity, record.velocity) {
            (Some(truth), Some(estimate)) => {
                self.push(truth, estimate);
                true
            }
            _ => false,
        }
    }

    /// Adds the samples of another accumulator.
    pub fn merge(&mut self, other: &SpeedHeadingAccumulator) {
        self.speed_sum += other.speed_sum;
        self.speed_sum_sq += other.speed_sum_sq;
        self.speed_count += other.speed_count;
        self.heading_sum_abs += other.heading_sum_abs;
        self.heading_sum_sq += other.heading_sum_sq;
        self.heading_count += other.heading_count;
    }

    /// Number of speed samples.
    pub fn speed_count(&self) -> u64 {
        self.speed_count
    }

    /// Number of heading samples (rows with a true speed of at least
    /// [`HEADING_MIN_TRUE_SPEED_MPS`]).
    pub fn heading_count(&self) -> u64 {
        self.heading_count
    }

    /// RMSE of the speed, m/s; `None` without samples.
    pub fn speed_rmse_mps(&self) -> Option<f64> {
        (self.speed_count > 0).then(|| (self.speed_sum_sq / self.speed_count as f64).sqrt())
    }

    /// Mean speed error `|v̂| − |v|` (positive: too fast), m/s; `None` without samples.
    pub fn speed_mean_error_mps(&self) -> Option<f64> {
        (self.speed_count > 0).then(|| self.speed_sum / self.speed_count as f64)
    }

    /// RMSE of the heading, degrees; `None` without samples.
    pub fn heading_rmse_deg(&self) -> Option<f64> {
        (self.heading_count > 0)
            .then(|| (self.heading_sum_sq / self.heading_count as f64).sqrt().to_degrees())
    }

    /// Mean absolute heading error, degrees; `None` without samples.
    pub fn heading_mean_abs_deg(&self) -> Option<f64> {
        (self.heading_count > 0).then(|| (self.heading_sum_abs / self.heading_count as f64).to_degrees())
    }
}

/// Heading of `estimate` minus heading of `truth`, wrapped to [−π, π], radians. An estimate of
/// zero length has heading 0.
pub fn heading_error_rad(truth: DVec2, estimate: DVec2) -> f64 {
    let difference = estimate.y.atan2(estimate.x) - truth.y.atan2(truth.x);
    let wrapped =
        (difference + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    // rem_euclid maps +π to −π; keep the sign of the difference there.
    if wrapped == -std::f64::consts::PI && difference > 0.0 {
        std::f64::consts::PI
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row;
    use std::f64::consts::PI;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    /// A row of object 1 taken by track 1 with a prior, both velocities and a confirmation.
    fn row(truth: DVec2, estimate: DVec2, confirmed: bool) -> AssociationRecord {
        let mut row = identity_row(0, Some(1), Some(1));
        row.prior = Some(DVec2::ZERO);
        row.true_velocity = Some(truth);
        row.velocity = Some(estimate);
        row.track_confirmed = Some(confirmed);
        row
    }

    #[test]
    fn velocity_rmse_of_a_hand_made_case() {
        // Errors (v̂ − v): (3, 4), (0, 0), (−1, 2), (0, −2).
        // Σ ex² = 10, Σ ey² = 24, N = 4 → RMSE_x = sqrt(2.5), RMSE_y = sqrt(6), RMSE = sqrt(8.5).
        let mut acc = VelocityRmseAccumulator::new();
        acc.push(DVec2::ZERO, DVec2::new(3.0, 4.0));
        acc.push(DVec2::new(1.0, 1.0), DVec2::new(1.0, 1.0));
        acc.push(DVec2::new(1.0, 3.0), DVec2::new(0.0, 5.0));
        acc.push(DVec2::new(2.0, 1.0), DVec2::new(2.0, -1.0));
        assert_eq!(acc.count(), 4);
        assert!(close(acc.rmse_x_mps().unwrap(), 2.5f64.sqrt()));
        assert!(close(acc.rmse_y_mps().unwrap(), 6f64.sqrt()));
        assert!(close(acc.rmse_mps().unwrap(), 8.5f64.sqrt()));
        assert_eq!(VelocityRmseAccumulator::new().rmse_mps(), None);
    }

    #[test]
    fn velocity_rmse_scores_only_rows_of_existing_tracks_with_both_velocities() {
        let scored = row(DVec2::new(10.0, 0.0), DVec2::new(7.0, 4.0), false); // error 5
        let mut started = row(DVec2::new(10.0, 0.0), DVec2::new(0.0, 0.0), true);
        started.prior = None; // the measurement started the track
        let mut no_truth = row(DVec2::ZERO, DVec2::new(50.0, 0.0), true);
        no_truth.true_velocity = None;
        let mut clutter = row(DVec2::ZERO, DVec2::new(50.0, 0.0), true);
        clutter.ground_truth_id = None;
        let mut untracked = row(DVec2::ZERO, DVec2::new(50.0, 0.0), false);
        untracked.velocity = None;
        untracked.track_id = None;
        let mut acc = VelocityRmseAccumulator::new();
        let added: Vec<bool> =
            [scored, started, no_truth, clutter, untracked].iter().map(|r| acc.push_record(r)).collect();
        assert_eq!(added, vec![true, false, false, false, false]);
        assert!(close(acc.rmse_mps().unwrap(), 5.0));
        let mut other = VelocityRmseAccumulator::new();
        other.push(DVec2::ZERO, DVec2::new(0.0, 1.0));
        acc.merge(&other);
        // Pooled: (25 + 1) / 2.
        assert!(close(acc.rmse_mps().unwrap(), 13f64.sqrt()));
    }

    #[test]
    fn speed_and_heading_errors_of_confirmed_rows() {
        let mut acc = SpeedHeadingAccumulator::new();
        // True 10 m/s east; estimate 8 m/s north-east-ish: speed error −2, heading +45°.
        let estimate = DVec2::from_angle(PI / 4.0) * 8.0;
        assert!(acc.push_record(&row(DVec2::new(10.0, 0.0), estimate, true)));
        // A tentative track's row is not scored.
        assert!(!acc.push_record(&row(DVec2::new(10.0, 0.0), DVec2::ZERO, false)));
        // Across ±π: true heading 170°, estimate −170°: the error is +20°, not −340°.
        let truth = DVec2::from_angle(170f64.to_radians()) * 4.0;
        let estimate = DVec2::from_angle(-170f64.to_radians()) * 5.0;
        assert!(acc.push_record(&row(truth, estimate, true)));
        // A standing object: speed error 0.3 counted, heading skipped.
        assert!(acc.push_record(&row(DVec2::new(0.1, 0.0), DVec2::new(0.0, -0.4), true)));
        assert_eq!((acc.speed_count(), acc.heading_count()), (3, 2));
        // Speed errors −2, +1, +0.3: mean −0.7/3, RMSE sqrt((4 + 1 + 0.09) / 3).
        assert!(close(acc.speed_mean_error_mps().unwrap(), -0.7 / 3.0));
        assert!(close(acc.speed_rmse_mps().unwrap(), (5.09f64 / 3.0).sqrt()));
        // Heading errors 45° and 20°.
        assert!(
            (acc.heading_rmse_deg().unwrap() - ((45f64.powi(2) + 20f64.powi(2)) / 2.0).sqrt()).abs() < 1e-9
        );
        assert!((acc.heading_mean_abs_deg().unwrap() - 32.5).abs() < 1e-9);
        assert_eq!(SpeedHeadingAccumulator::new().heading_rmse_deg(), None);
    }

    #[test]
    fn heading_error_is_wrapped_to_plus_minus_pi() {
        let east = DVec2::new(1.0, 0.0);
        assert!(close(heading_error_rad(east, DVec2::new(0.0, 1.0)), PI / 2.0));
        assert!(close(heading_error_rad(east, DVec2::new(0.0, -1.0)), -PI / 2.0));
        assert!(close(heading_error_rad(east, DVec2::new(-1.0, 0.0)).abs(), PI));
        let a = DVec2::from_angle(-3.0);
        let b = DVec2::from_angle(3.0);
        assert!(close(heading_error_rad(a, b), 6.0 - 2.0 * PI));
        assert!(close(heading_error_rad(b, a), 2.0 * PI - 6.0));
        for k in -50..50 {
            let error =
                heading_error_rad(DVec2::from_angle(0.37 * k as f64), DVec2::from_angle(-1.1 * k as f64));
            assert!((-PI..=PI).contains(&error), "{error}");
        }
    }
}
