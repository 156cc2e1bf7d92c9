//! Offline tracking of recorded sequences: the tracker run frame by frame over a
//! [`Sequence`], with every measurement's fate turned into evaluation rows.

use crate::eval::record::{counts_as_confirmed, AssociationRecord};
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

/// Tracks `sequence` from scratch with `tracker` (which is [`reset`](Tracker::reset) first, its
/// sensors' estimates back at their priors: [`Tracker::forget_sensors`]) and calls `on_frame`
/// with every recorded frame and the tracker's outputs for it. Frames come in the sequence's
/// order, which is arrival order: for a late frame, tracked in its place, the outputs are those
/// right after it ([`Tracker::late_frame_outputs`]), at its time and with measurement indices
/// into its own measurements.
pub fn track_sequence<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    sequence: &Sequence,
    mut on_frame: impl FnMut(&RecordedFrame, &[TrackOutput]),
) -> Result<(), OfflineError> {
    tracker.reset();
    tracker.forget_sensors();
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
        tracker.step(&frame).map_err(|source| OfflineError::Step {
            sequence: sequence.name.clone(),
            frame: recorded.index,
            source,
        })?;
        let outputs =
            if tracker.last_step().late() { tracker.late_frame_outputs() } else { tracker.last_outputs() };
        on_frame(recorded, outputs);
    }
    Ok(())
}

/// One evaluation row per measurement of `recorded`, from the tracker's outputs for that frame.
/// `method` decides whether mode probabilities are reported (IMM variants only). A row records
/// whether its track was confirmed after the frame's update ([`counts_as_confirmed`] of the
/// output's status).
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
            record.velocity = Some(output.velocity_mps);
            record.track_confirmed = Some(counts_as_confirmed(output.status));
            if with_modes && output.prior_position_m.is_some() {
                record.mode_probabilities = Some(output.mode_probabilities);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::RecordedMeasurement;
    use primm_core::config::Config;
    use primm_core::measurement::{Measurement, ObjectClass};

    #[test]
    fn rows_record_whether_their_track_was_confirmed_after_the_frame() {
        // One car driving away at 5 m/s, seen every 0.1 s; the default tracker confirms a track
        // with its third hit.
        let mut sequence = Sequence::new("one car");
        for index in 0..6u64 {
            let mut frame = RecordedFrame::new(index, index as f64 * 0.1);
            frame.measurements.push(RecordedMeasurement {
                measurement: Measurement {
                    x_m: 20.0 + 0.5 * index as f64,
                    y_m: 0.0,
                    radial_velocity_mps: 5.0,
                    rcs_dbsm: 10.0,
                    class: ObjectClass::Car,
                    sensor_id: None,
                    ground_truth_id: Some(1),
                },
                true_position: None,
                true_velocity: None,
                origin: None,
            });
            sequence.frames.push(frame);
        }
        let config = Config::default().with_modes(Method::Imm.modes());
        let hits = config.tracker.confirmation_hits as usize;
        assert_eq!(hits, 3);
        let mut tracker = Tracker::new(config).unwrap();
        let mut records = Vec::new();
        track_sequence(&mut tracker, &sequence, |recorded, outputs| {
            association_records(recorded, outputs, Method::Imm, &mut records)
        })
        .unwrap();
        let track = records[0].track_id;
        assert!(track.is_some() && records.iter().all(|r| r.track_id == track), "{records:?}");
        let confirmed: Vec<Option<bool>> = records.iter().map(|r| r.track_confirmed).collect();
        let expected: Vec<Option<bool>> = (0..6).map(|k| Some(k + 1 >= hits)).collect();
        assert_eq!(confirmed, expected);
    }
}
