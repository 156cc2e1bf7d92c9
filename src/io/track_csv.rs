//! The track file format written by `primm track` and `primm-subscriber --csv`.
//!
//! Header `frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct`; one row
//! per track updated by a measurement in that frame: `x`,`y` the fused posterior position (m),
//! `prior_*` the fused one-step prior before the update (m; empty for a track started in that
//! frame), `gt_id` the ground-truth id of the measurement (-1 when unknown), `mu_*` the posterior
//! mode probabilities (0 for modes the method does not use).

use crate::track::TrackOutput;
use std::io::Write;

/// The header line.
pub const TRACK_CSV_HEADER: &str = "frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct";

/// Writes track rows.
#[derive(Debug)]
pub struct TrackCsvWriter<W: Write> {
    out: W,
}

impl<W: Write> TrackCsvWriter<W> {
    /// A writer that starts with the header.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{TRACK_CSV_HEADER}")?;
        Ok(Self { out })
    }

    /// Writes the rows of one frame (tracks updated by a measurement only).
    pub fn write_frame(&mut self, frame: u64, timestamp_s: f64, outputs: &[TrackOutput]) -> std::io::Result<()> {
        for output in outputs.iter().filter(|o| o.measurement_index.is_some()) {
            self.write_row(frame, timestamp_s, output)?;
        }
        Ok(())
    }

    /// Writes one row.
    pub fn write_row(&mut self, frame: u64, timestamp_s: f64, output: &TrackOutput) -> std::io::Result<()> {
        let (prior_x, prior_y) = match output.prior_position_m {
            Some(p) => (p.x.to_string(), p.y.to_string()),
            None => (String::new(), String::new()),
        };
        let gt = output.ground_truth_id.map_or(-1, |id| id as i64);
        let mu = output.mode_probabilities;
        writeln!(
            self.out,
            "{frame},{timestamp_s},{},{},{},{},{prior_x},{prior_y},{gt},{},{},{},{}",
            output.id, output.class, output.position_m.x, output.position_m.y, mu[0], mu[1], mu[2], mu[3]
        )
    }

    /// Flushes and returns the inner writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}
