//! Offline tracking of recorded sequences: the tracker run frame by frame over a
//! [`Sequence`], with every measurement's fate turned into evaluation rows.

use crate::eval::record::AssociationRecord;
use crate::io::{RecordedFrame, Sequence, TooManyMeasurements};
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::predictor::DisplacementPredictor;
use primm_core::track::TrackOutput;
use primm_core::tracker::{StepError, Tracker};

/// Why an offline run stopped.
#[derive(Debug, thiserror::Error)]
pub enum OfflineError {
    /// A recorded frame has more measurements than a frame may carry.
    #[error("sequence {sequence}: {source}")]
    TooManyMeasurements {
        /// Sequence name.
        sequence: String,
        /// The offending frame.
        source: TooManyMeasurements,
    },
    /// The tracker rejected a frame.
    #[error("sequence {sequence}, frame {frame}: {source}")]
    Step {
        /// Sequence name.
        sequence: String,
        /// Frame index.
        frame: u64,
        /// The tracker's error.
        source: StepError,
    },
}

/// Tracks `sequence` from scratch with `tracker` (which is [`reset`](Tracker::reset) first) and
/// calls `on_frame` with every recorded frame and the tracker's outputs for it.
pub fn track_sequence<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    sequence: &Sequence,
    mut on_frame: impl FnMut(&RecordedFrame, &[TrackOutput]),
) -> Result<(), OfflineError> {
    tracker.reset();
    let mut frame = Frame::default();
    for recorded in &sequence.frames {
        frame.timestamp_s = recorded.timestamp_s;
        frame.ego_pose = recorded.ego_pose;
        frame.measurements.clear();
        if recorded.measurements.len() > frame.measurements.capacity() {
            return Err(OfflineError::TooManyMeasurements {
                sequence: sequence.name.clone(),
                source: TooManyMeasurements { frame: recorded.index, count: recorded.measurements.len() },
            });
        }
        frame.measurements.extend(recorded.measurements.iter().map(|m| m.measurement));
        let outputs = tracker.step(&frame).map_err(|source| OfflineError::Step {
            sequence: sequence.name.clone(),
            frame: recorded.index,
            source,
        })?;
        on_frame(recorded, outputs);
    }
    Ok(())
}

/// One evaluation row per measurement of `recorded`, from the tracker's outputs for that frame.
/// `method` decides whether mode probabilities are reported (IMM variants only).
pub fn association_records(
    recorded: &RecordedFrame,
    outputs: &[TrackOutput],
    method: Method,
    records: &mut Vec<AssociationRecord>,
) {
    let start = records.len();
    records.extend(recorded.measurements.iter().map(|m| recorded.unassigned_record(m)));
    let with_modes = method.modes().len() > 1;
    for output in outputs {
        let Some(index) = output.measurement_index else { continue };
        if let Some(record) = records.get_mut(start + usize::from(index)) {
            record.track_id = Some(output.id);
            record.prior = output.prior_position_m;
            if with_modes && output.prior_position_m.is_some() {
                record.mode_probabilities = Some(output.mode_probabilities);
            }
        }
    }
}

/// Tracks `sequence` and returns its evaluation rows.
pub fn evaluate_sequence<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    sequence: &Sequence,
    method: Method,
) -> Result<Vec<AssociationRecord>, OfflineError> {
    let mut records = Vec::with_capacity(sequence.measurement_count());
    track_sequence(tracker, sequence, |recorded, outputs| {
        association_records(recorded, outputs, method, &mut records)
    })?;
    Ok(records)
}
