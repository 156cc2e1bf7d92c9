//! The tracker's private copy of a caller's frame, read exactly once.
//!
//! Every frame handed to the tracker is first copied here: the header and each measurement as
//! the caller's [`FrameView`] decodes it (an undecodable one is kept as its error, so that
//! validation counts it the same way every time). The tracker then works only on this copy:
//! a frame read in place from shared memory may change while it is being tracked, and a late
//! frame must be tracked again, identically, when an older frame arrives after it
//! ([`crate::replay`]). The copy is what the replay ring keeps.

use crate::measurement::{FrameView, Measurement, UnknownClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::pose::EgoPose;

/// A frame as read once from the caller: header and decoded measurements.
#[derive(Debug, Clone)]
pub(crate) struct RecordedFrame {
    timestamp_s: f64,
    /// The count as the frame claimed it (validation rejects one above the capacity; only the
    /// first [`MAX_MEASUREMENTS_PER_FRAME`] are read).
    count: usize,
    ego_pose: Option<EgoPose>,
    measurements: [Result<Measurement, UnknownClass>; MAX_MEASUREMENTS_PER_FRAME],
}

impl RecordedFrame {
    /// An empty frame.
    pub(crate) fn new() -> Self {
        Self {
            timestamp_s: 0.0,
            count: 0,
            ego_pose: None,
            measurements: [Err(UnknownClass { code: u8::MAX }); MAX_MEASUREMENTS_PER_FRAME],
        }
    }

    /// Reads `frame` once: header, then every measurement. A frame claiming more than
    /// [`MAX_MEASUREMENTS_PER_FRAME`] is not read further: validation rejects it by its count.
    pub(crate) fn read_from<F: FrameView + ?Sized>(&mut self, frame: &F) {
        self.timestamp_s = frame.timestamp_s();
        self.count = frame.len();
        self.ego_pose = frame.ego_pose();
        if self.count > MAX_MEASUREMENTS_PER_FRAME {
            return;
        }
        for (index, slot) in self.measurements[..self.count].iter_mut().enumerate() {
            *slot = frame.measurement(index);
        }
    }
}

impl FrameView for RecordedFrame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }

    fn len(&self) -> usize {
        self.count
    }

    /// Measurement `index` as it was read; an index past the capacity reads as an unknown
    /// class (validation rejects a frame claiming more before any measurement is asked for).
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        self.measurements.get(index).copied().unwrap_or(Err(UnknownClass { code: u8::MAX }))
    }

    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}
