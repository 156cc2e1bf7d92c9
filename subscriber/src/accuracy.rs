//! Tracking accuracy seen from a subscriber: pairs each track frame with the measurement frame
//! it answers (same sequence number) and scores what the tracker did with every measurement
//! against the ground truth the publisher sent along: prior RMSE (the paper's metric), posterior
//! RMSE, ID switches and IDF1 (`primm_sim::eval`).

use glam::DVec2;
use primm_core::measurement::ObjectClass;
use primm_sim::eval::{identity_counts, AssociationRecord, IdentityCounts, RmseAccumulator};
use primm_wire::{FrameStatus, MeasurementFrame, TrackFrame, TRACK_FLAG_TRACKER_RESET};
use std::collections::BTreeMap;

/// Measurement frames kept while waiting for their answers.
const MAX_PENDING_FRAMES: usize = 256;

/// One measurement as the subscriber needs it for scoring.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ScoredMeasurement {
    class: ObjectClass,
    measured: DVec2,
    ground_truth_id: Option<u64>,
    true_position: Option<DVec2>,
}

/// A measurement frame waiting for its track frame.
#[derive(Debug, Clone, PartialEq)]
struct PendingFrame {
    measurements: Vec<Option<ScoredMeasurement>>,
}

/// Accuracy figures.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct AccuracySummary {
    /// Track frames paired with their measurement frame.
    pub frames_scored: u64,
    /// Track frames whose measurement frame was not seen (subscribed late, or lost).
    pub frames_unpaired: u64,
    /// Measurements with a ground-truth id.
    pub ground_truth_measurements: u64,
    /// RMSE of the fused prior against the true position (measurement when no truth), m.
    pub prior_rmse_m: Option<f64>,
    /// Samples in the prior RMSE.
    pub prior_samples: u64,
    /// RMSE of the fused posterior of the updated track against the true position, m.
    pub posterior_rmse_m: Option<f64>,
    /// Samples in the posterior RMSE.
    pub posterior_samples: u64,
    /// Identity counts (IDSW, IDTP, ...), summed over streams.
    pub identity: IdentityCounts,
    /// IDF1.
    pub idf1: Option<f64>,
}

/// Scores track frames against the measurement frames they answer.
#[derive(Debug, Default)]
pub struct AccuracyMonitor {
    pending: BTreeMap<u64, PendingFrame>,
    stream_rows: Vec<AssociationRecord>,
    identity: IdentityCounts,
    prior: RmseAccumulator,
    posterior_sum_sq: f64,
    posterior_samples: u64,
    frames_scored: u64,
    frames_unpaired: u64,
    ground_truth_measurements: u64,
}

impl AccuracyMonitor {
    /// An empty monitor.
    pub fn new() -> Self {
        Self::default()
    }

    /// Remembers a measurement frame until its answer arrives. A frame whose count exceeds the
    /// capacity is remembered as empty (the tracker rejects it).
    pub fn add_measurements(&mut self, frame: &MeasurementFrame) {
        if self.pending.last_key_value().is_some_and(|(&last, _)| frame.sequence <= last) {
            // Sequence numbers went back: a new publisher. Older frames will not be answered.
            self.pending.clear();
        }
        let measurements = frame
            .valid_measurements()
            .unwrap_or(&[])
            .iter()
            .map(|wire| {
                wire.decode().ok().map(|m| ScoredMeasurement {
                    class: m.class,
                    measured: m.position(),
                    ground_truth_id: m.ground_truth_id,
                    true_position: wire.true_position_m().map(DVec2::from),
                })
            })
            .collect();
        self.pending.insert(frame.sequence, PendingFrame { measurements });
        while self.pending.len() > MAX_PENDING_FRAMES {
            self.pending.pop_first();
        }
    }

    /// Scores a track frame against its measurement frame.
    pub fn add_tracks(&mut self, frame: &TrackFrame) {
        if frame.flags & TRACK_FLAG_TRACKER_RESET != 0 {
            self.finish_stream();
        }
        let Some(pending) = self.pending.remove(&frame.input_sequence) else {
            self.frames_unpaired += 1;
            return;
        };
        // Frames before this one will not be answered any more.
        self.pending = self.pending.split_off(&frame.input_sequence);
        self.frames_scored += 1;
        let tracked = frame.frame_status() == Some(FrameStatus::Tracked);
        let mut track_of_measurement = vec![None; pending.measurements.len()];
        if tracked {
            for track in frame.valid_tracks() {
                if let Some(slot) =
                    track.measurement_index().and_then(|index| track_of_measurement.get_mut(index))
                {
                    *slot = Some(*track);
                }
            }
        }
        for (measurement, track) in pending.measurements.iter().zip(&track_of_measurement) {
            let Some(measurement) = measurement else { continue };
            self.ground_truth_measurements += u64::from(measurement.ground_truth_id.is_some());
            let record = AssociationRecord {
                frame: frame.source_frame,
                timestamp_s: frame.sensor_timestamp_s,
                ground_truth_id: measurement.ground_truth_id,
                class: measurement.class,
                measured: measurement.measured,
                true_position: measurement.true_position,
                true_velocity: None,
                origin: None,
                track_id: track.map(|t| t.id),
                prior: track.and_then(|t| t.prior_m()).map(DVec2::from),
                velocity: None,
                mode_probabilities: track.map(|t| t.mode_probabilities),
                // Wire status 0 is tentative; every other status counts as confirmed.
                track_confirmed: Some(track.is_some_and(|t| t.status != 0)),
            };
            self.prior.push_record(&record);
            if let (Some(track), Some(truth)) = (track, measurement.true_position) {
                self.posterior_sum_sq += (DVec2::new(track.x_m, track.y_m) - truth).length_squared();
                self.posterior_samples += 1;
            }
            self.stream_rows.push(record);
        }
    }

    /// Closes the current stream: identities are only comparable within one.
    fn finish_stream(&mut self) {
        if !self.stream_rows.is_empty() {
            self.identity.merge(&identity_counts(&self.stream_rows));
            self.stream_rows.clear();
        }
    }

    /// The figures so far (closes the current stream).
    pub fn summary(&mut self) -> AccuracySummary {
        self.finish_stream();
        AccuracySummary {
            frames_scored: self.frames_scored,
            frames_unpaired: self.frames_unpaired,
            ground_truth_measurements: self.ground_truth_measurements,
            prior_rmse_m: self.prior.rmse_xy(),
            prior_samples: self.prior.count(),
            posterior_rmse_m: (self.posterior_samples > 0)
                .then(|| (self.posterior_sum_sq / self.posterior_samples as f64).sqrt()),
            posterior_samples: self.posterior_samples,
            identity: self.identity,
            idf1: self.identity.idf1(),
        }
    }
}
