//! Track frames received from the service written in the track file format of
//! [`primm_sim::io::track_csv`].

use primm_core::measurement::ObjectClass;
use primm_sim::io::track_csv::{TrackCsvWriter as RowWriter, TrackRow};
use primm_wire::{FrameStatus, TrackFrame};
use std::io::Write;

/// Writes received track frames as track CSV rows.
#[derive(Debug)]
pub struct TrackCsvWriter<W: Write> {
    rows: RowWriter<W>,
}

impl<W: Write> TrackCsvWriter<W> {
    /// A writer that has written the header.
    pub fn new(output: W) -> std::io::Result<Self> {
        Ok(Self { rows: RowWriter::new(output)? })
    }

    /// Writes the rows of one frame (none for a rejected frame).
    pub fn write_frame(&mut self, frame: &TrackFrame) -> std::io::Result<()> {
        if frame.frame_status() != Some(FrameStatus::Tracked) {
            return Ok(());
        }
        for track in frame.valid_tracks().iter().filter(|track| track.measurement_index().is_some()) {
            let class_code = track.class_code.to_string();
            let class = match ObjectClass::from_code(track.class_code) {
                Some(class) => class.name(),
                None => class_code.as_str(),
            };
            self.rows.write(&TrackRow {
                frame: frame.source_frame,
                timestamp_s: frame.sensor_timestamp_s,
                track_id: track.id,
                class,
                position_m: [track.x_m, track.y_m],
                prior_position_m: track.prior_m(),
                ground_truth_id: u64::try_from(track.gt_id).ok(),
                mode_probabilities: track.mode_probabilities,
            })?;
        }
        Ok(())
    }

    /// Rows written.
    pub fn rows(&self) -> u64 {
        self.rows.rows()
    }

    /// Flushes the output.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.rows.flush()
    }
}
