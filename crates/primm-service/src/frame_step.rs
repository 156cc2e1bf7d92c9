//! One received measurement frame through the tracker, exactly as the tracking loop does it,
//! without the shared-memory ports around it: step the tracker on the frame in place, writing
//! its tracks into the answer; after a gap longer than `tracker.max_frame_interval_s`, reset the
//! tracker and step again on the same frame.
//!
//! [`TrackingService`](crate::TrackingService) calls [`step_received_frame`] for every sample
//! it receives. The raw-frame fuzz target calls the same function on frames made of arbitrary
//! bytes, which is what makes it evidence about the service and not about a copy of its code.

use primm_core::predictor::DisplacementPredictor;
use primm_core::stage_timing::StageObserver;
use primm_core::tracker::{StepError, StepSummary, Tracker};
use primm_core::validation::FrameError;
use primm_wire::{MeasurementFrame, TrackFrameWriter, FRAME_FLAG_STREAM_START};

/// What tracking one received frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct SteppedFrame {
    /// The step's summary, or why the frame was rejected.
    pub result: Result<StepSummary, StepError>,
    /// Whether the frame came after too long a gap, so that the tracker was reset and the frame
    /// tracked again from scratch.
    pub reset_for_interval: bool,
}

/// Whether `frame` asks the tracker to forget its tracks before tracking it
/// ([`FRAME_FLAG_STREAM_START`]).
pub fn starts_stream(frame: &MeasurementFrame) -> bool {
    frame.flags & FRAME_FLAG_STREAM_START != 0
}

/// Steps `tracker` on `frame` (read in place; every field untrusted), timing the stages with
/// `observer` and writing the tracks with `writer` when there is one. A frame after too long a
/// gap is tracked again after a reset, which [`SteppedFrame::reset_for_interval`] records.
pub fn step_received_frame<P: DisplacementPredictor, O: StageObserver>(
    tracker: &mut Tracker<P>,
    frame: &MeasurementFrame,
    observer: &mut O,
    writer: &mut Option<TrackFrameWriter<'_>>,
) -> SteppedFrame {
    let mut result = step_once(tracker, frame, observer, writer);
    let mut reset_for_interval = false;
    if let Err(StepError::InvalidFrame(FrameError::IntervalTooLong { .. })) = result {
        // Tracks cannot be bridged over the gap: start afresh with this frame.
        tracker.reset();
        reset_for_interval = true;
        if let Some(writer) = writer.as_mut() {
            writer.clear();
        }
        result = step_once(tracker, frame, observer, writer);
    }
    SteppedFrame { result, reset_for_interval }
}

fn step_once<P: DisplacementPredictor, O: StageObserver>(
    tracker: &mut Tracker<P>,
    frame: &MeasurementFrame,
    observer: &mut O,
    writer: &mut Option<TrackFrameWriter<'_>>,
) -> Result<StepSummary, StepError> {
    tracker.step_observed(frame, observer, |output| {
        if let Some(writer) = writer.as_mut() {
            writer.push(output);
        }
    })
}
