//! What must hold of a tracker after every step, whatever it was fed: the checks that fuzzing,
//! the soak run and the fault tests apply after each frame, and that an integrator may run as
//! a health check.
//!
//! After any step, successful or rejected:
//! * the number of tracks is within [`MAX_TRACKS`];
//! * every active mode of every track has a finite mean and a finite, symmetric,
//!   positive-definite covariance (it has a Cholesky factor);
//! * every track's mode probabilities are finite, non-negative, zero on inactive modes and sum
//!   to 1 over the active modes.
//!
//! [`check_tracker`] returns the first violation it finds, with the track and mode it concerns.

use crate::imm::ImmState;
use crate::limits::MAX_TRACKS;
use crate::mode::{Mode, ModeSet, MODE_COUNT};
use crate::predictor::DisplacementPredictor;
use crate::readable_number::readable;
use crate::track::Track;
use crate::tracker::Tracker;
use nalgebra::SMatrix;

/// Largest relative asymmetry `|P_ij − P_ji| / max |P|` a covariance may have.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// Largest distance of the active modes' probability sum from 1.
pub const PROBABILITY_SUM_TOLERANCE: f64 = 1e-9;

/// A broken invariant of a tracker after a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InvariantViolation {
    /// More tracks than the table can hold.
    TooManyTracks {
        /// Number of tracks found.
        count: usize,
    },
    /// A mode's mean has a NaN or infinite element.
    NonFiniteMean {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
    },
    /// A mode's covariance has a NaN or infinite element.
    NonFiniteCovariance {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
    },
    /// A mode's covariance is not symmetric within [`SYMMETRY_TOLERANCE`].
    AsymmetricCovariance {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
        /// Largest relative asymmetry found.
        asymmetry: f64,
    },
    /// A mode's covariance has no Cholesky factor: it is not positive definite.
    CovarianceNotPositiveDefinite {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
    },
    /// A mode probability is NaN, infinite or negative, or an inactive mode's is not 0.
    InvalidProbability {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
        /// The probability found.
        probability: f64,
    },
    /// The active modes' probabilities do not sum to 1 within [`PROBABILITY_SUM_TOLERANCE`].
    ProbabilitiesDoNotSumToOne {
        /// The track.
        track_id: u64,
        /// The sum found.
        sum: f64,
    },
}

impl core::fmt::Display for InvariantViolation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            InvariantViolation::TooManyTracks { count } => {
                write!(f, "{count} tracks, more than the capacity of {MAX_TRACKS}")
            }
            InvariantViolation::NonFiniteMean { track_id, mode } => {
                write!(f, "track {track_id}: the {} mean is not finite", mode.id())
            }
            InvariantViolation::NonFiniteCovariance { track_id, mode } => {
                write!(f, "track {track_id}: the {} covariance is not finite", mode.id())
            }
            InvariantViolation::AsymmetricCovariance { track_id, mode, asymmetry } => write!(
                f,
                "track {track_id}: the {} covariance is asymmetric (relative {asymmetry:.1e})",
                mode.id()
            ),
            InvariantViolation::CovarianceNotPositiveDefinite { track_id, mode } => {
                write!(f, "track {track_id}: the {} covariance is not positive definite", mode.id())
            }
            InvariantViolation::InvalidProbability { track_id, mode, probability } => {
                write!(f, "track {track_id}: the {} probability is {}", mode.id(), readable(probability))
            }
            InvariantViolation::ProbabilitiesDoNotSumToOne { track_id, sum } => {
                write!(f, "track {track_id}: the mode probabilities sum to {}", readable(sum))
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for InvariantViolation {}

/// Checks every invariant of `tracker` (see the module documentation).
pub fn check_tracker<P: DisplacementPredictor>(tracker: &Tracker<P>) -> Result<(), InvariantViolation> {
    check_tracks(tracker.tracks(), tracker.config().imm.modes)
}

/// Checks the invariants of `tracks`, a tracker's tracks whose active modes are `modes`.
pub fn check_tracks(tracks: &[Track], modes: ModeSet) -> Result<(), InvariantViolation> {
    if tracks.len() > MAX_TRACKS {
        return Err(InvariantViolation::TooManyTracks { count: tracks.len() });
    }
    tracks.iter().try_for_each(|track| check_estimate(track.id, &track.estimate, modes))
}

/// Checks one track's IMM state over the active `modes`.
pub fn check_estimate(track_id: u64, state: &ImmState, modes: ModeSet) -> Result<(), InvariantViolation> {
    for mode in modes.iter() {
        match mode {
            Mode::Learned => check_gaussian(track_id, mode, &state.learned.mean, &state.learned.covariance)?,
            Mode::ConstantVelocity => check_gaussian(
                track_id,
                mode,
                &state.constant_velocity.mean,
                &state.constant_velocity.covariance,
            )?,
            Mode::ConstantAcceleration => check_gaussian(
                track_id,
                mode,
                &state.constant_acceleration.mean,
                &state.constant_acceleration.covariance,
            )?,
            Mode::CoordinatedTurn => check_gaussian(
                track_id,
                mode,
                &state.coordinated_turn.mean,
                &state.coordinated_turn.covariance,
            )?,
        }
    }
    check_probabilities(track_id, &state.probabilities, modes)
}

fn check_gaussian<const N: usize>(
    track_id: u64,
    mode: Mode,
    mean: &SMatrix<f64, N, 1>,
    covariance: &SMatrix<f64, N, N>,
) -> Result<(), InvariantViolation> {
    if !mean.iter().all(|v| v.is_finite()) {
        return Err(InvariantViolation::NonFiniteMean { track_id, mode });
    }
    if !covariance.iter().all(|v| v.is_finite()) {
        return Err(InvariantViolation::NonFiniteCovariance { track_id, mode });
    }
    let scale = covariance.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut asymmetry = 0.0f64;
    for i in 0..N {
        for j in (i + 1)..N {
            asymmetry = asymmetry.max((covariance[(i, j)] - covariance[(j, i)]).abs());
        }
    }
    let asymmetry = if scale > 0.0 { asymmetry / scale } else { asymmetry };
    if asymmetry > SYMMETRY_TOLERANCE {
        return Err(InvariantViolation::AsymmetricCovariance { track_id, mode, asymmetry });
    }
    if covariance.cholesky().is_none() {
        return Err(InvariantViolation::CovarianceNotPositiveDefinite { track_id, mode });
    }
    Ok(())
}

fn check_probabilities(
    track_id: u64,
    probabilities: &[f64; MODE_COUNT],
    modes: ModeSet,
) -> Result<(), InvariantViolation> {
    let mut sum = 0.0;
    for mode in Mode::ALL {
        let probability = probabilities[mode.index()];
        let valid = if modes.contains(mode) {
            probability.is_finite() && probability >= 0.0
        } else {
            probability == 0.0
        };
        if !valid {
            return Err(InvariantViolation::InvalidProbability { track_id, mode, probability });
        }
        sum += probability;
    }
    if (sum - 1.0).abs() > PROBABILITY_SUM_TOLERANCE {
        return Err(InvariantViolation::ProbabilitiesDoNotSumToOne { track_id, sum });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::measurement::{Frame, Measurement, ObjectClass};
    use crate::mode::Method;

    fn tracker_with_one_track() -> Tracker {
        let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
        let mut frame = Frame::new(0.0);
        frame.measurements.push(Measurement {
            x_m: 20.0,
            y_m: 1.5,
            radial_velocity_mps: 4.0,
            rcs_dbsm: 8.0,
            class: ObjectClass::Car,
            sensor_id: Some(0),
            ground_truth_id: None,
        });
        tracker.step(&frame).unwrap();
        tracker
    }

    #[test]
    fn a_tracker_after_a_normal_step_holds_every_invariant() {
        let tracker = tracker_with_one_track();
        assert_eq!(tracker.tracks().len(), 1);
        assert_eq!(check_tracker(&tracker), Ok(()));
    }

    #[test]
    fn each_broken_invariant_is_named() {
        let tracker = tracker_with_one_track();
        let modes = tracker.config().imm.modes;
        let good = tracker.tracks()[0].clone();
        let check = |edit: &dyn Fn(&mut Track)| {
            let mut track = good.clone();
            edit(&mut track);
            check_tracks(core::slice::from_ref(&track), modes)
        };
        let id = good.id;
        assert_eq!(
            check(&|t| t.estimate.constant_velocity.mean[2] = f64::NAN),
            Err(InvariantViolation::NonFiniteMean { track_id: id, mode: Mode::ConstantVelocity })
        );
        assert_eq!(
            check(&|t| t.estimate.coordinated_turn.covariance[(4, 4)] = f64::INFINITY),
            Err(InvariantViolation::NonFiniteCovariance { track_id: id, mode: Mode::CoordinatedTurn })
        );
        assert!(matches!(
            check(&|t| t.estimate.constant_acceleration.covariance[(0, 1)] += 1.0),
            Err(InvariantViolation::AsymmetricCovariance { mode: Mode::ConstantAcceleration, .. })
        ));
        assert_eq!(
            check(&|t| t.estimate.constant_velocity.covariance[(1, 1)] = -1.0),
            Err(InvariantViolation::CovarianceNotPositiveDefinite {
                track_id: id,
                mode: Mode::ConstantVelocity
            })
        );
        assert!(matches!(
            check(&|t| t.estimate.probabilities[Mode::ConstantVelocity.index()] = -0.1),
            Err(InvariantViolation::InvalidProbability { mode: Mode::ConstantVelocity, .. })
        ));
        assert!(matches!(
            check(&|t| t.estimate.probabilities[Mode::Learned.index()] = 0.5),
            Err(InvariantViolation::InvalidProbability { mode: Mode::Learned, .. })
        ));
        assert!(matches!(
            check(&|t| t.estimate.probabilities[Mode::ConstantVelocity.index()] += 0.01),
            Err(InvariantViolation::ProbabilitiesDoNotSumToOne { .. })
        ));
        let many = alloc::vec![good.clone(); MAX_TRACKS + 1];
        assert_eq!(
            check_tracks(&many, modes),
            Err(InvariantViolation::TooManyTracks { count: MAX_TRACKS + 1 })
        );
    }
}
