//! The validate stage: frame checks, then per-measurement checks, every rejection counted
//! ([`TrackerStats`](super::TrackerStats) keeps one counter per reason).

use super::{MeasurementFate, StepError, Tracker};
use crate::coordinates::CoordinateFrame;
use crate::measurement::FrameView;
use crate::predictor::DisplacementPredictor;
use crate::validation::{validate_frame, validate_measurement, FrameError};

impl<P: DisplacementPredictor> Tracker<P> {
    /// Checks the recorded frame, then each of its measurements, into [`ValidatedFrame`]
    /// (every later stage reads that copy); returns the frame's interval, s.
    ///
    /// [`ValidatedFrame`]: crate::validated_frame::ValidatedFrame
    pub(super) fn validate(&mut self) -> Result<f64, StepError> {
        self.validated.read_header(&*self.recorded);
        let dt_s =
            self.check_frame().inspect_err(|error| self.last_step.counts.count_frame_rejection(error))?;
        for index in 0..self.validated.len() {
            let verdict = validate_measurement(&*self.recorded, index);
            self.validated.set(index, verdict.ok());
            self.accepted[index] = verdict.is_ok();
            match verdict {
                Ok(_) => {
                    self.fates[index] = MeasurementFate::Unassigned;
                    self.last_step.counts.measurements_accepted += 1;
                }
                Err(reason) => {
                    self.fates[index] = MeasurementFate::Rejected;
                    self.last_step.counts.count_measurement_rejection(reason);
                }
            }
        }
        Ok(dt_s)
    }

    /// The frame-level checks: a usable ego pose when tracking in the world frame, then the
    /// timestamp, interval and size (`crate::validation`); the interval, s.
    fn check_frame(&self) -> Result<f64, FrameError> {
        if self.config.frame.tracking_frame == CoordinateFrame::World {
            if let Some(pose) = self.validated.ego_pose().filter(|pose| !pose.is_valid()) {
                return Err(FrameError::InvalidEgoPose {
                    x_m: pose.x_m,
                    y_m: pose.y_m,
                    yaw_rad: pose.yaw_rad,
                });
            }
        }
        validate_frame(&*self.validated, self.last_timestamp_s, &self.config.tracker)
    }
}
