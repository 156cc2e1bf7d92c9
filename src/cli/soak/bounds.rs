//! The state bounds `primm soak` checks after every frame, beyond
//! `primm_core::invariants::check_tracker`.
//!
//! The scene stays within 250 m of the radar and objects move at most 25 m/s, and a track
//! coasts at most `tracker.max_coast_s` (1 s by default), so these bounds are generous by orders
//! of magnitude: crossing one means the state ran away, not that tracking was poor.

use primm_core::mode::{Mode, ModeSet};
use primm_core::track::Track;

/// Largest |x| or |y| of any active mode's mean, m.
pub const MAX_POSITION_M: f64 = 10_000.0;
/// Largest |vx| or |vy| of any active mode's mean (CV, CA, CT) and of the PR velocity, m/s.
pub const MAX_VELOCITY_MPS: f64 = 500.0;
/// Largest trace of any active mode's covariance (mixed units: m², m²/s², m²/s⁴, rad²/s²).
pub const MAX_COVARIANCE_TRACE: f64 = 1.0e6;

/// A bound a track crossed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoundViolation {
    /// A mode's position is beyond [`MAX_POSITION_M`].
    Position {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
    },
    /// A mode's velocity is beyond [`MAX_VELOCITY_MPS`].
    Velocity {
        /// The track.
        track_id: u64,
        /// The mode (the PR mode's velocity is the one implied by its last displacement).
        mode: Mode,
        /// The mode's velocity, m/s.
        velocity_mps: [f64; 2],
        /// The CT mode's turn rate, rad/s (`None` for the other modes).
        turn_rate_radps: Option<f64>,
        /// The mode's probability.
        probability: f64,
    },
    /// A mode's covariance trace is beyond [`MAX_COVARIANCE_TRACE`].
    CovarianceTrace {
        /// The track.
        track_id: u64,
        /// The mode.
        mode: Mode,
        /// The trace found.
        trace: f64,
    },
    /// More live tracks than the scene can explain.
    TrackCount {
        /// Live tracks.
        count: usize,
        /// The bound.
        bound: usize,
    },
}

impl std::fmt::Display for BoundViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            BoundViolation::Position { track_id, mode } => {
                write!(f, "track {track_id}: the {} position is beyond {MAX_POSITION_M} m", mode.id())
            }
            BoundViolation::Velocity { track_id, mode, velocity_mps, turn_rate_radps, probability } => {
                write!(
                    f,
                    "track {track_id}: the {} velocity ({:.4e}, {:.4e}) m/s is beyond {MAX_VELOCITY_MPS} m/s \
                     (mode probability {probability:.3e}",
                    mode.id(),
                    velocity_mps[0],
                    velocity_mps[1],
                )?;
                if let Some(omega) = turn_rate_radps {
                    write!(f, ", turn rate {omega:.4e} rad/s")?;
                }
                write!(f, ")")
            }
            BoundViolation::CovarianceTrace { track_id, mode, trace } => {
                write!(f, "track {track_id}: the {} covariance trace is {trace:.3e}", mode.id())
            }
            BoundViolation::TrackCount { count, bound } => {
                write!(f, "{count} live tracks, more than {bound}")
            }
        }
    }
}

/// Checks every track's active modes against the bounds and the track count against
/// `max_tracks`.
pub fn check_bounds(tracks: &[Track], modes: ModeSet, max_tracks: usize) -> Result<(), BoundViolation> {
    if tracks.len() > max_tracks {
        return Err(BoundViolation::TrackCount { count: tracks.len(), bound: max_tracks });
    }
    for track in tracks {
        let state = &track.estimate;
        let track_id = track.id;
        for mode in modes.iter() {
            let (position, velocity, trace) = match mode {
                Mode::Learned => (
                    [state.learned.mean[0], state.learned.mean[1]],
                    [state.learned_velocity_mps.x, state.learned_velocity_mps.y],
                    state.learned.covariance.trace(),
                ),
                Mode::ConstantVelocity => {
                    let m = &state.constant_velocity.mean;
                    ([m[0], m[1]], [m[2], m[3]], state.constant_velocity.covariance.trace())
                }
                Mode::ConstantAcceleration => {
                    let m = &state.constant_acceleration.mean;
                    ([m[0], m[1]], [m[2], m[3]], state.constant_acceleration.covariance.trace())
                }
                Mode::CoordinatedTurn => {
                    let m = &state.coordinated_turn.mean;
                    ([m[0], m[1]], [m[2], m[3]], state.coordinated_turn.covariance.trace())
                }
            };
            if position.iter().any(|v| !within(*v, MAX_POSITION_M)) {
                return Err(BoundViolation::Position { track_id, mode });
            }
            if velocity.iter().any(|v| !within(*v, MAX_VELOCITY_MPS)) {
                let turn_rate_radps = (mode == Mode::CoordinatedTurn).then(|| state.coordinated_turn.mean[4]);
                let probability = state.probabilities[mode.index()];
                return Err(BoundViolation::Velocity {
                    track_id,
                    mode,
                    velocity_mps: velocity,
                    turn_rate_radps,
                    probability,
                });
            }
            if !within(trace, MAX_COVARIANCE_TRACE) {
                return Err(BoundViolation::CovarianceTrace { track_id, mode, trace });
            }
        }
    }
    Ok(())
}

/// Whether `value` is a number of magnitude at most `bound` (NaN is not).
fn within(value: f64, bound: f64) -> bool {
    value.abs() <= bound
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_core::imm::ImmState;
    use primm_core::measurement::{Measurement, ObjectClass};
    use primm_core::mode::Method;

    /// A car track at (20 m, 1 m) moving 10 m/s in every mode, unit covariances.
    fn track() -> Track {
        let measurement = Measurement {
            x_m: 20.0,
            y_m: 1.0,
            radial_velocity_mps: 3.0,
            rcs_dbsm: 5.0,
            class: ObjectClass::Car,
            sensor_id: Some(0),
            ground_truth_id: None,
        };
        let mut state = ImmState::default();
        state.constant_velocity.mean[0] = 20.0;
        state.constant_velocity.mean[2] = 10.0;
        for i in 0..4 {
            state.constant_velocity.covariance[(i, i)] = 1.0;
        }
        Track::new(1, &measurement, glam::DVec2::ZERO, 0.0, state, 0.5)
    }

    fn modes() -> ModeSet {
        Method::ConstantVelocity.modes()
    }

    #[test]
    fn a_sane_track_is_within_bounds() {
        assert_eq!(check_bounds(&[track()], modes(), 1), Ok(()));
    }

    #[test]
    fn a_runaway_position_velocity_or_covariance_is_named() {
        let mut far = track();
        far.estimate.constant_velocity.mean[1] = 2.0 * MAX_POSITION_M;
        assert!(matches!(
            check_bounds(&[far], modes(), 1),
            Err(BoundViolation::Position { track_id: 1, .. })
        ));
        let mut fast = track();
        fast.estimate.constant_velocity.mean[3] = f64::NAN;
        assert!(matches!(
            check_bounds(&[fast], modes(), 1),
            Err(BoundViolation::Velocity { track_id: 1, .. })
        ));
        let mut uncertain = track();
        uncertain.estimate.constant_velocity.covariance[(2, 2)] = 2.0 * MAX_COVARIANCE_TRACE;
        assert!(matches!(
            check_bounds(&[uncertain], modes(), 1),
            Err(BoundViolation::CovarianceTrace { track_id: 1, .. })
        ));
    }

    #[test]
    fn more_tracks_than_the_bound_is_a_violation() {
        let tracks = [track(), track()];
        assert_eq!(check_bounds(&tracks, modes(), 1), Err(BoundViolation::TrackCount { count: 2, bound: 1 }));
    }
}
