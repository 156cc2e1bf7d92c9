//! The track file format written by `primm track` and `primm-subscriber --csv`.
//!
//! Header [`TRACK_CSV_HEADER`]
//! (`frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct,status,existence_probability,vx,vy,age_s,`
//! then the covariance columns); one row per track updated by a measurement in that frame:
//! `x`,`y` the fused posterior position (m), `prior_*` the fused one-step prior before the
//! update (m; empty for a track started in that frame), `gt_id` the ground-truth id of the
//! measurement (-1 when unknown), `mu_*` the posterior mode probabilities (0 for modes the method
//! does not use), `status` the track's lifecycle status after the frame (`tentative`,
//! `confirmed` or `coasting`), `existence_probability` the probability that its object exists
//! (dimensionless), `vx`,`vy` the fused velocity (m/s), `age_s` the time since the track's
//! first measurement (s), and `cov_xx,cov_xy,cov_xvx,cov_xvy,cov_yy,cov_yvx,cov_yvy,cov_vxvx,cov_vxvy,cov_vyvy`
//! the upper triangle of the covariance of `[x, y, vx, vy]` (m², m²/s, m²/s²).
//!
//! A file of frames tracked in the world frame (they carried an ego pose) adds the columns
//! [`WORLD_COLUMNS`]: the fused position (m), velocity over ground (m/s) and the upper triangle
//! of their covariance in the world frame, empty in a row of a frame tracked in the vehicle
//! frame. `x`, `y`, the velocity, the covariance and the prior stay in the vehicle frame of their
//! frame, so every scorer reads both kinds of file.
//!
//! A frame that arrived late (older than the newest tracked frame, which the tracker tracks in
//! its place before tracking the newer frames again) has the rows of the tracks as they were
//! right after it (`Tracker::late_frame_outputs`), with its own frame index and time, after the
//! rows of the newer frames that came before it. Rows already written for the newer frames stay
//! as they were written.

use super::recording::Sequence;
use primm_core::config::CoordinateFrame;
use primm_core::track::TrackOutput;
use std::io::Write;

/// The header line.
pub const TRACK_CSV_HEADER: &str = "frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct,status,existence_probability,vx,vy,age_s,cov_xx,cov_xy,cov_xvx,cov_xvy,cov_yy,cov_yvx,cov_yvy,cov_vxvx,cov_vxvy,cov_vyvy";

/// The columns a file with world-frame estimates adds to [`TRACK_CSV_HEADER`].
pub const WORLD_COLUMNS: &str = "world_x,world_y,world_vx,world_vy,world_cov_xx,world_cov_xy,world_cov_xvx,world_cov_xvy,world_cov_yy,world_cov_yvx,world_cov_yvy,world_cov_vxvx,world_cov_vxvy,world_cov_vyvy";

/// The upper triangle of a symmetric 4×4 covariance given row-major, in the order of the
/// `cov_*` columns.
pub fn upper_triangle(row_major: &[f64; 16]) -> [f64; 10] {
    let c = row_major;
    [c[0], c[1], c[2], c[3], c[5], c[6], c[7], c[10], c[11], c[15]]
}

/// One row of the track file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackRow<'a> {
    /// Frame index in its recording.
    pub frame: u64,
    /// Frame time, s.
    pub timestamp_s: f64,
    /// Track id.
    pub track_id: u64,
    /// Class name (`car`, `pedestrian`, ...).
    pub class: &'a str,
    /// Fused posterior position, m.
    pub position_m: [f64; 2],
    /// Fused prior position, m; `None` for a track started in this frame.
    pub prior_position_m: Option<[f64; 2]>,
    /// Ground-truth id of the measurement.
    pub ground_truth_id: Option<u64>,
    /// Mode probabilities, order PR, CV, CA, CT.
    pub mode_probabilities: [f64; 4],
    /// Lifecycle status after the frame (`tentative`, `confirmed`, `coasting`).
    pub status: &'a str,
    /// Probability that the track's object exists.
    pub existence_probability: f64,
    /// Fused velocity, m/s.
    pub velocity_mps: [f64; 2],
    /// Time since the track's first measurement, s.
    pub age_s: f64,
    /// Covariance of `[x, y, vx, vy]`, row-major.
    pub state_covariance: [f64; 16],
    /// World-frame position (m) and velocity (m/s), `[x, y, vx, vy]`, and their covariance
    /// (row-major), when the frame was tracked in the world frame.
    pub world: Option<([f64; 4], [f64; 16])>,
}

/// Writes track rows. Floats are written in the shortest form that reads back exactly.
#[derive(Debug)]
pub struct TrackCsvWriter<W: Write> {
    out: W,
    rows: u64,
    world_columns: bool,
}

impl<W: Write> TrackCsvWriter<W> {
    /// A writer that starts with the header.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{TRACK_CSV_HEADER}")?;
        Ok(Self { out, rows: 0, world_columns: false })
    }

    /// The writer for a file tracked with `tracking_frame` from `sequence`: with the world-frame
    /// columns when the tracker keeps world-frame tracks and the sequence carries ego poses.
    pub fn for_sequence(
        out: W,
        sequence: &Sequence,
        tracking_frame: CoordinateFrame,
    ) -> std::io::Result<Self> {
        if tracking_frame == CoordinateFrame::World && sequence.has_ego_pose() {
            Self::with_world_columns(out)
        } else {
            Self::new(out)
        }
    }

    /// A writer whose header and rows have the world-frame columns [`WORLD_COLUMNS`].
    pub fn with_world_columns(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{TRACK_CSV_HEADER},{WORLD_COLUMNS}")?;
        Ok(Self { out, rows: 0, world_columns: true })
    }

    /// Writes the rows of one frame (tracks updated by a measurement only).
    pub fn write_frame(
        &mut self,
        frame: u64,
        timestamp_s: f64,
        outputs: &[TrackOutput],
    ) -> std::io::Result<()> {
        for output in outputs.iter().filter(|o| o.measurement_index.is_some()) {
            self.write_row(frame, timestamp_s, output)?;
        }
        Ok(())
    }

    /// Writes one row from a tracker output.
    pub fn write_row(&mut self, frame: u64, timestamp_s: f64, output: &TrackOutput) -> std::io::Result<()> {
        self.write(&TrackRow {
            frame,
            timestamp_s,
            track_id: output.id,
            class: output.class.name(),
            position_m: [output.position_m.x, output.position_m.y],
            prior_position_m: output.prior_position_m.map(|p| [p.x, p.y]),
            ground_truth_id: output.ground_truth_id,
            mode_probabilities: output.mode_probabilities,
            status: output.status.name(),
            existence_probability: output.existence_probability,
            velocity_mps: [output.velocity_mps.x, output.velocity_mps.y],
            age_s: output.age_s,
            state_covariance: output.state_covariance.transpose().to_cols_array(),
            world: match (output.world_position_m, output.world_velocity_mps, output.world_state_covariance) {
                (Some(position), Some(velocity), Some(covariance)) => Some((
                    [position.x, position.y, velocity.x, velocity.y],
                    covariance.transpose().to_cols_array(),
                )),
                _ => None,
            },
        })
    }

    /// Writes one row.
    pub fn write(&mut self, row: &TrackRow<'_>) -> std::io::Result<()> {
        let (prior_x, prior_y) = match row.prior_position_m {
            Some([x, y]) => (x.to_string(), y.to_string()),
            None => (String::new(), String::new()),
        };
        let gt = row.ground_truth_id.map_or(-1, |id| id as i64);
        let [mu_pr, mu_cv, mu_ca, mu_ct] = row.mode_probabilities;
        let [x, y] = row.position_m;
        let [vx, vy] = row.velocity_mps;
        write!(
            self.out,
            "{},{},{},{},{x},{y},{prior_x},{prior_y},{gt},{mu_pr},{mu_cv},{mu_ca},{mu_ct},{},{},{vx},{vy},{}",
            row.frame,
            row.timestamp_s,
            row.track_id,
            row.class,
            row.status,
            row.existence_probability,
            row.age_s
        )?;
        for value in upper_triangle(&row.state_covariance) {
            write!(self.out, ",{value}")?;
        }
        match (self.world_columns, row.world) {
            (false, _) => {}
            (true, Some(([x, y, vx, vy], covariance))) => {
                write!(self.out, ",{x},{y},{vx},{vy}")?;
                for value in upper_triangle(&covariance) {
                    write!(self.out, ",{value}")?;
                }
            }
            (true, None) => write!(self.out, "{}", ",".repeat(14))?,
        }
        writeln!(self.out)?;
        self.rows += 1;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes the output.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }

    /// Flushes and returns the inner writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}
