//! The check every learned displacement passes before the PR mode uses it.
//!
//! A [`DisplacementPredictor`](crate::predictor::DisplacementPredictor) is outside the
//! tracker's control: a model may answer NaN or infinity, or a displacement no road object could
//! make. Each answer is checked against its request:
//!
//! * a NaN or infinite component is [`DisplacementRejection::NonFinite`];
//! * a displacement longer than `max_displacement_speed_mps` (configuration key
//!   `predictor.max_displacement_speed_mps`) times the step's duration
//!   (`prediction_time_s − step_start_s`) is [`DisplacementRejection::Implausible`].
//!
//! A rejected displacement is treated like a missing one: the PR mode sits the frame out for
//! that track, the other modes carry on, and the tracker counts the rejection by reason
//! ([`TrackerStats`](crate::tracker::TrackerStats)).

use crate::predictor::PredictionRequest;
use glam::DVec2;

/// Why a learned displacement was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DisplacementRejection {
    /// A component is NaN or infinite.
    NonFinite,
    /// The displacement implies a speed above the configured bound over its step.
    Implausible,
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
    fn nan_and_infinite_components_are_non_finite() {
        for bad in
            [DVec2::new(f64::NAN, 0.0), DVec2::new(0.0, f64::INFINITY), DVec2::new(f64::NEG_INFINITY, 1.0)]
        {
            assert_eq!(check_displacement(&request(0.1), bad, 100.0), Err(DisplacementRejection::NonFinite));
        }
    }
}
