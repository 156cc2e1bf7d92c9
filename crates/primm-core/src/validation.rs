//! Checks on every frame and measurement before anything touches a track.
//!
//! A frame-level fault rejects the whole frame: [`FrameError`]. A fault confined to one
//! measurement rejects only that measurement ([`MeasurementRejection`]) and the rest of the
//! frame is tracked; this is safe because a measurement never affects another one except
//! through association, which simply does not see the rejected one.

use crate::config::TrackerConfig;
use crate::measurement::{FrameView, Measurement, MAX_MEASUREMENTS_PER_FRAME};
use crate::readable_number::readable;

/// Largest accepted magnitude of a position, radial velocity or RCS value. Anything beyond is
/// not a radar measurement and would overflow squared distances.
pub const MAX_ABSOLUTE_VALUE: f64 = 1.0e6;

/// Why a whole frame was rejected. The tracker is left exactly as before the frame.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// The timestamp is NaN or infinite.
    #[error("frame timestamp {} is not finite", readable(.timestamp_s))]
    NonFiniteTimestamp {
        /// The timestamp, s.
        timestamp_s: f64,
    },
    /// The timestamp is not later than the previous accepted frame's.
    #[error(
        "frame timestamp {} s does not advance past the previous frame at {} s",
        readable(.timestamp_s),
        readable(.previous_s)
    )]
    TimestampNotIncreasing {
        /// The timestamp, s.
        timestamp_s: f64,
        /// The previous accepted frame's timestamp, s.
        previous_s: f64,
    },
    /// The time since the previous accepted frame exceeds `tracker.max_frame_interval_s`.
    /// Tracks cannot be bridged over such a gap; the caller may [`reset`](crate::tracker::Tracker::reset)
    /// the tracker and resubmit the frame.
    #[error("frame interval {} s exceeds the maximum of {} s", readable(.interval_s), readable(.max_s))]
    IntervalTooLong {
        /// The interval, s.
        interval_s: f64,
        /// The configured maximum, s.
        max_s: f64,
    },
    /// The frame's ego pose is not finite or lies beyond [`MAX_EGO_POSITION_M`] (checked only
    /// when tracking in the world frame).
    ///
    /// [`MAX_EGO_POSITION_M`]: crate::pose::MAX_EGO_POSITION_M
    #[error(
        "frame ego pose (x {} m, y {} m, yaw {} rad) is not finite or too far out",
        readable(.x_m),
        readable(.y_m),
        readable(.yaw_rad)
    )]
    InvalidEgoPose {
        /// x of the pose, m.
        x_m: f64,
        /// y of the pose, m.
        y_m: f64,
        /// Yaw of the pose, rad.
        yaw_rad: f64,
    },
    /// The frame is older than the newest tracked frame by more than the late-frame window
    /// reaches (`tracker.max_frame_delay_s`, or the `tracker.replay_frames` recorded frames).
    #[error(
        "frame timestamp {} s is older than the newest frame at {} s by more than the late-frame window (tracker.max_frame_delay_s, tracker.replay_frames) reaches",
        readable(.timestamp_s),
        readable(.newest_s)
    )]
    TooLate {
        /// The timestamp, s.
        timestamp_s: f64,
        /// The newest tracked frame's timestamp, s.
        newest_s: f64,
    },
    /// The frame claims more measurements than a frame may carry.
    #[error("frame carries {count} measurements, more than the maximum of {MAX_MEASUREMENTS_PER_FRAME}")]
    TooManyMeasurements {
        /// The claimed count.
        count: usize,
    },
}

/// Why one measurement was left out of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeasurementRejection {
    /// Its class code names no known class.
    UnknownClass,
    /// A value is NaN or infinite.
    NonFinite,
    /// A value's magnitude exceeds [`MAX_ABSOLUTE_VALUE`].
    OutOfRange,
}

/// Checks the frame-level fields; returns the interval since `previous_s` (0 for the first frame).
pub fn validate_frame<F: FrameView + ?Sized>(
    frame: &F,
    previous_s: Option<f64>,
    config: &TrackerConfig,
) -> Result<f64, FrameError> {
    let timestamp_s = frame.timestamp_s();
    if !timestamp_s.is_finite() {
        return Err(FrameError::NonFiniteTimestamp { timestamp_s });
    }
    if frame.len() > MAX_MEASUREMENTS_PER_FRAME {
        return Err(FrameError::TooManyMeasurements { count: frame.len() });
    }
    let Some(previous_s) = previous_s else { return Ok(0.0) };
    let interval_s = timestamp_s - previous_s;
    if interval_s <= 0.0 {
        return Err(FrameError::TimestampNotIncreasing { timestamp_s, previous_s });
    }
    if interval_s > config.max_frame_interval_s {
        return Err(FrameError::IntervalTooLong { interval_s, max_s: config.max_frame_interval_s });
    }
    Ok(interval_s)
}

/// Decodes and checks measurement `index` of `frame`.
pub fn validate_measurement<F: FrameView + ?Sized>(
    frame: &F,
    index: usize,
) -> Result<Measurement, MeasurementRejection> {
    let measurement = frame.measurement(index).map_err(|_| MeasurementRejection::UnknownClass)?;
    let values = [measurement.x_m, measurement.y_m, measurement.radial_velocity_mps, measurement.rcs_dbsm];
    if values.iter().any(|v| !v.is_finite()) {
        return Err(MeasurementRejection::NonFinite);
    }
    if values.iter().any(|v| v.abs() > MAX_ABSOLUTE_VALUE) {
        return Err(MeasurementRejection::OutOfRange);
    }
    Ok(measurement)
}
