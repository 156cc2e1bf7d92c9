//! Per-class association of tracks to measurements (paper, Section III-E).
//!
//! For each class, a cost matrix between that class's tracks and measurements is filled with
//! `eq:association_cost` from the fused priors; pairs whose cost exceeds the class's gate are
//! forbidden, so that a far measurement starts a new track instead of being forced onto an old
//! one. An optimal one-to-one assignment is then found ([`AssignmentSolver`]). Splitting by
//! class and gating keep the matrices small and sparse. All buffers are allocated once.

use super::assignment::{AssignmentError, AssignmentSolver};
use super::cost::association_cost;
use crate::config::Config;
use crate::imm::ImmPrior;
use crate::measurement::{FrameView, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::track::Track;
use crate::track_table::MAX_TRACKS;
use arrayvec::ArrayVec;

/// Reusable association workspace.
#[derive(Debug)]
pub struct Associator {
    solver: AssignmentSolver,
    costs: Box<[f64]>,
    rows: Box<ArrayVec<u16, MAX_TRACKS>>,
    columns: Box<ArrayVec<u16, MAX_MEASUREMENTS_PER_FRAME>>,
    row_to_column: Box<[Option<usize>]>,
}

impl Default for Associator {
    fn default() -> Self {
        Self::new()
    }
}

impl Associator {
    /// A workspace for up to [`MAX_TRACKS`] tracks and [`MAX_MEASUREMENTS_PER_FRAME`] measurements.
    pub fn new() -> Self {
        Self {
            solver: AssignmentSolver::with_capacity(MAX_TRACKS, MAX_MEASUREMENTS_PER_FRAME),
            costs: vec![0.0; MAX_TRACKS * MAX_MEASUREMENTS_PER_FRAME].into_boxed_slice(),
            rows: Box::new(ArrayVec::new()),
            columns: Box::new(ArrayVec::new()),
            row_to_column: vec![None; MAX_TRACKS].into_boxed_slice(),
        }
    }

    /// Assigns measurements to tracks of the same class.
    ///
    /// `accepted[j]` says whether measurement `j` passed validation; `priors[i]` is track `i`'s
    /// fused prior. On return `track_to_measurement[i]` holds the measurement assigned to track
    /// `i`, if any.
    pub fn associate<F: FrameView + ?Sized>(
        &mut self,
        tracks: &[Track],
        priors: &[ImmPrior],
        frame: &F,
        accepted: &[bool],
        config: &Config,
        track_to_measurement: &mut [Option<u16>],
    ) -> Result<(), AssignmentError> {
        track_to_measurement[..tracks.len()].fill(None);
        for class in ObjectClass::ALL {
            self.rows.clear();
            self.columns.clear();
            self.rows.extend((0..tracks.len()).filter(|&i| tracks[i].class == class).map(|i| i as u16));
            self.columns.extend((0..frame.len()).filter(|&j| accepted[j] && class_of(frame, j) == Some(class)).map(|j| j as u16));
            if self.rows.is_empty() || self.columns.is_empty() {
                continue;
            }
            let (rows, columns) = (self.rows.len(), self.columns.len());
            let gate = config.classes.get(class).gate_m;
            for (r, &track_index) in self.rows.iter().enumerate() {
                let track = &tracks[usize::from(track_index)];
                let prior = priors[usize::from(track_index)].fused.mean;
                for (c, &measurement_index) in self.columns.iter().enumerate() {
                    let cost = match frame.measurement(usize::from(measurement_index)) {
                        Ok(measurement) => association_cost(prior, track.last_radial_velocity_mps, &measurement, &config.association),
                        Err(_) => f64::INFINITY,
                    };
                    self.costs[r * columns + c] = if cost <= gate { cost } else { f64::INFINITY };
                }
            }
            self.solver.solve(rows, columns, &self.costs[..rows * columns], &mut self.row_to_column[..rows])?;
            for (r, &track_index) in self.rows.iter().enumerate() {
                track_to_measurement[usize::from(track_index)] = self.row_to_column[r].map(|c| self.columns[c]);
            }
        }
        Ok(())
    }
}

fn class_of<F: FrameView + ?Sized>(frame: &F, index: usize) -> Option<ObjectClass> {
    frame.measurement(index).ok().map(|m| m.class)
}
