//! The check every learned displacement passes before the PR mode uses it.
//!
//! A [`DisplacementPredictor`](crate::predictor::DisplacementPredictor) is outside the
//! tracker's control: a model may answer NaN or infinity, or a displacement no road object could
//! make. Each answer is checked against its request:
//!
//! * a NaN or infinite component is [`DisplacementRejection::NonFinite`];
//! * a displacement longer than `max_displacement_speed_mps` (configuration key
//!   `predictor.max_displacement_speed_mps`) times the step's duration
//!   (`prediction_time_s − step_start_s`) is [`DisplacementRejection::Implausible`];
//! * a covariance that is not finite, symmetric and positive definite, or whose standard
//!   deviation exceeds that speed times the model's horizon (`prediction_time_s −
//!   anchor_time_s`, at least one second), is [`DisplacementRejection::InvalidCovariance`].
//!
//! A rejected displacement is treated like a missing one: the PR mode sits the frame out for
//! that track, the other modes carry on, and the tracker counts the rejection by reason
//! ([`TrackerStats`](crate::tracker::TrackerStats)).

use crate::predictor::{Displacement, PredictionRequest};
use glam::{DMat2, DVec2};

/// Why a learned displacement was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DisplacementRejection {
    /// A component is NaN or infinite.
    NonFinite,
    /// The displacement implies a speed above the configured bound over its step.
    Implausible,
    /// The covariance is not a finite, symmetric, positive-definite matrix of plausible size.
    InvalidCovariance,
}

/// Checks a predictor's answer, mean and covariance, against its request and the speed bound,
/// m/s.
pub fn check_answer(
    request: &PredictionRequest,
    answer: &Displacement,
    max_speed_mps: f64,
) -> Result<(), DisplacementRejection> {
    check_displacement(request, answer.mean_m, max_speed_mps)?;
    match answer.covariance_m2 {
        Some(covariance) => check_covariance(request, &covariance, max_speed_mps),
        None => Ok(()),
    }
}

/// Checks a displacement covariance: finite, symmetric to rounding, positive definite, and a
/// standard deviation along either axis of at most `max_speed_mps` times the model's horizon
/// (at least one second).
fn check_covariance(
    request: &PredictionRequest,
    covariance: &DMat2,
    max_speed_mps: f64,
) -> Result<(), DisplacementRejection> {
    let (a, b, c, d) = (covariance.x_axis.x, covariance.y_axis.x, covariance.x_axis.y, covariance.y_axis.y);
    let horizon_s = (request.prediction_time_s - request.anchor_time_s).max(1.0);
    let largest_m2 = crate::math::square(max_speed_mps * horizon_s);
    let scale = a.abs().max(d.abs());
    // Written so that NaN anywhere rejects.
    let valid = covariance.is_finite()
        && (b - c).abs() <= 1e-9 * scale
        && a > 0.0
        && d > 0.0
        && a * d - b * c > 0.0
        && a <= largest_m2
        && d <= largest_m2;
    if valid {
        Ok(())
    } else {
        Err(DisplacementRejection::InvalidCovariance)
    }
}

/// Checks `displacement_m` against its request and the speed bound, m/s.
pub fn check_displacement(
    request: &PredictionRequest,
    displacement_m: DVec2,
    max_speed_mps: f64,
) -> Result<DVec2, DisplacementRejection> {
    if !displacement_m.is_finite() {
        return Err(DisplacementRejection::NonFinite);
    }
    let step_s = (request.prediction_time_s - request.step_start_s).max(0.0);
    let longest_m = max_speed_mps * step_s;
    // Written so that a NaN bound rejects rather than accepts.
    if displacement_m.length() <= longest_m {
        Ok(displacement_m)
    } else {
        Err(DisplacementRejection::Implausible)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::predictor::HistoryEntry;

    /// A request for a step of `step_s` seconds.
    fn request(step_s: f64) -> PredictionRequest {
        let history = [HistoryEntry { x_m: 10.0, y_m: 2.0, timestamp_s: 1.0, ..Default::default() }];
        PredictionRequest::from_history(&history, 1.0 + step_s)
    }

    #[test]
    fn a_displacement_within_the_speed_bound_is_kept_unchanged() {
        let displacement = DVec2::new(3.0, -4.0);
        assert_eq!(check_displacement(&request(0.1), displacement, 60.0), Ok(displacement));
    }

    #[test]
    fn a_displacement_one_step_faster_than_the_bound_is_implausible() {
        // 5 m in 0.1 s is 50 m/s.
        let displacement = DVec2::new(3.0, -4.0);
        assert_eq!(
            check_displacement(&request(0.1), displacement, 49.0),
            Err(DisplacementRejection::Implausible)
        );
        for absurd in [1e6, 1e300, -1e300] {
            let result = check_displacement(&request(0.1), DVec2::new(absurd, 0.0), 100.0);
            assert_eq!(result, Err(DisplacementRejection::Implausible), "{absurd}");
        }
    }

    #[test]
    fn a_valid_covariance_passes_and_broken_ones_are_rejected() {
        let mean = DVec2::new(1.0, 0.5);
        let good = DMat2::from_cols(DVec2::new(0.04, 0.01), DVec2::new(0.01, 0.09));
        assert_eq!(check_answer(&request(0.1), &Displacement::with_covariance(mean, good), 100.0), Ok(()));
        assert_eq!(check_answer(&request(0.1), &Displacement::new(mean), 100.0), Ok(()));
        let broken = [
            DMat2::from_cols(DVec2::new(f64::NAN, 0.0), DVec2::new(0.0, 1.0)),
            DMat2::from_cols(DVec2::new(1.0, 0.0), DVec2::new(0.0, f64::INFINITY)),
            // Not symmetric.
            DMat2::from_cols(DVec2::new(1.0, 0.5), DVec2::new(0.0, 1.0)),
            // Negative variance, and indefinite.
            DMat2::from_cols(DVec2::new(-1.0, 0.0), DVec2::new(0.0, 1.0)),
            DMat2::from_cols(DVec2::new(1.0, 2.0), DVec2::new(2.0, 1.0)),
            // Zero: not positive definite.
            DMat2::ZERO,
            // A standard deviation of 1 km over a 1 s horizon under a 100 m/s bound.
            DMat2::from_cols(DVec2::new(1e6, 0.0), DVec2::new(0.0, 1.0)),
        ];
        for covariance in broken {
            assert_eq!(
                check_answer(&request(0.1), &Displacement::with_covariance(mean, covariance), 100.0),
                Err(DisplacementRejection::InvalidCovariance),
                "{covariance:?}"
            );
        }
        // The mean is checked first.
        let fast = Displacement::with_covariance(DVec2::new(1e3, 0.0), good);
        assert_eq!(check_answer(&request(0.1), &fast, 100.0), Err(DisplacementRejection::Implausible));
    }

    #[test]
    fn nan_and_infinite_components_are_non_finite() {
        for bad in
            [DVec2::new(f64::NAN, 0.0), DVec2::new(0.0, f64::INFINITY), DVec2::new(f64::NEG_INFINITY, 1.0)]
        {
            assert_eq!(check_displacement(&request(0.1), bad, 100.0), Err(DisplacementRejection::NonFinite));
        }
    }
}
