//! The tracker's own copy of the frame it is stepping: the header and every measurement read
//! from the caller's frame exactly once, during validation.
//!
//! A frame read in place from shared memory can change while the tracker steps it (a hostile or
//! broken publisher may keep writing into a sample after sending it). Were the tracker to read
//! the frame again after validating it, a count raised past the capacity would index out of
//! bounds and a value turned into NaN would reach the filters. Every stage after validation
//! therefore reads this copy, whose contents were checked, and never the caller's frame.

use crate::measurement::{FrameView, Measurement, UnknownClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::pose::{EgoPose, RigidTransform};

/// A frame's header as read once, and its measurements as validated: `None` for a rejected one.
#[derive(Debug, Clone)]
pub(crate) struct ValidatedFrame {
    timestamp_s: f64,
    /// The count as the frame claimed it; at most [`MAX_MEASUREMENTS_PER_FRAME`] once the frame
    /// passed validation.
    count: usize,
    ego_pose: Option<EgoPose>,
    measurements: [Option<Measurement>; MAX_MEASUREMENTS_PER_FRAME],
}

impl ValidatedFrame {
    /// An empty copy.
    pub(crate) fn new() -> Self {
        Self { timestamp_s: 0.0, count: 0, ego_pose: None, measurements: [None; MAX_MEASUREMENTS_PER_FRAME] }
    }

    /// Reads `frame`'s header (time, claimed count and ego pose) once, forgetting the previous
    /// frame.
    pub(crate) fn read_header<F: FrameView + ?Sized>(&mut self, frame: &F) {
        self.timestamp_s = frame.timestamp_s();
        self.count = frame.len();
        self.ego_pose = frame.ego_pose();
    }

    /// Maps the accepted measurements' positions by `transform` (from the vehicle frame into
    /// the tracking frame); velocities along the line of sight and everything else stay.
    pub(crate) fn move_positions(&mut self, transform: &RigidTransform) {
        let count = self.count.min(MAX_MEASUREMENTS_PER_FRAME);
        for measurement in self.measurements[..count].iter_mut().flatten() {
            let position = transform.apply_point(measurement.position());
            measurement.x_m = position.x;
            measurement.y_m = position.y;
        }
    }

    /// Sets the number of measurements, after the grouping of a point cloud replaced them
    /// (`crate::grouping`; at most [`MAX_MEASUREMENTS_PER_FRAME`]).
    pub(crate) fn set_len(&mut self, count: usize) {
        self.count = count.min(MAX_MEASUREMENTS_PER_FRAME);
    }

    /// Records measurement `index` as validation left it: `None` when it was rejected.
    pub(crate) fn set(&mut self, index: usize, measurement: Option<Measurement>) {
        self.measurements[index] = measurement;
    }

    /// Measurement `index` if it was accepted.
    pub(crate) fn accepted(&self, index: usize) -> Option<Measurement> {
        self.measurements[index]
    }
}

impl FrameView for ValidatedFrame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }

    fn len(&self) -> usize {
        self.count
    }

    /// The accepted measurement `index`; a rejected one reads as an unknown class (the tracker
    /// never asks for one: its acceptance mask leaves them out).
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        self.measurements[index].ok_or(UnknownClass { code: u8::MAX })
    }

    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}
