//! The track CSV format written by the subscriber: one row per track that a measurement
//! updated or started in a frame.
//!
//! ```text
//! frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct
//! ```
//!
//! `frame` is the frame's index in its recording, `t` its sensor time (s), `x,y` the fused
//! posterior and `prior_x,prior_y` the fused prior (m; empty for a track started in the frame),
//! `gt_id` the ground-truth id of the measurement (empty when unknown), `mu_*` the mode
//! probabilities. Floats are written in the shortest form that reads back exactly.

use crate::measurement::ObjectClass;
use crate::wire::{FrameStatus, TrackFrame};
use std::io::Write;

/// The header row.
pub const TRACK_CSV_HEADER: [&str; 13] =
    ["frame", "t", "track_id", "class", "x", "y", "prior_x", "prior_y", "gt_id", "mu_pr", "mu_cv", "mu_ca", "mu_ct"];

/// Writes track frames as CSV rows.
#[derive(Debug)]
pub struct TrackCsvWriter<W: Write> {
    writer: csv::Writer<W>,
    rows: u64,
}

impl<W: Write> TrackCsvWriter<W> {
    /// A writer that has written the header.
    pub fn new(output: W) -> Result<Self, csv::Error> {
        let mut writer = csv::Writer::from_writer(output);
        writer.write_record(TRACK_CSV_HEADER)?;
        Ok(Self { writer, rows: 0 })
    }

    /// Writes the rows of one frame (none for a rejected frame).
    pub fn write_frame(&mut self, frame: &TrackFrame) -> Result<(), csv::Error> {
        if frame.frame_status() != Some(FrameStatus::Tracked) {
            return Ok(());
        }
        let float = |value: f64| value.to_string();
        for track in frame.valid_tracks().iter().filter(|track| track.measurement_index().is_some()) {
            let class = ObjectClass::from_code(track.class_code).map_or_else(|| track.class_code.to_string(), |c| c.name().to_owned());
            let (prior_x, prior_y) = track.prior_m().map_or((String::new(), String::new()), |[x, y]| (float(x), float(y)));
            let gt_id = if track.gt_id >= 0 { track.gt_id.to_string() } else { String::new() };
            let [mu_pr, mu_cv, mu_ca, mu_ct] = track.mode_probabilities;
            self.writer.write_record([
                frame.source_frame.to_string(),
                float(frame.sensor_timestamp_s),
                track.id.to_string(),
                class,
                float(track.x_m),
                float(track.y_m),
                prior_x,
                prior_y,
                gt_id,
                float(mu_pr),
                float(mu_cv),
                float(mu_ca),
                float(mu_ct),
            ])?;
            self.rows += 1;
        }
        Ok(())
    }

    /// Rows written.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes the output.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}
