//! What the tracker hands out: the report of every live track after a step, and predictions
//! to a later time that change nothing.

use super::{RowRecord, Tracker};
use crate::coordinates::CoordinateFrame;
use crate::existence;
use crate::imm::ImmPrior;
use crate::pose::{EgoPose, RigidTransform};
use crate::prediction::PredictError;
use crate::predictor::DisplacementPredictor;
use crate::track::TrackOutput;
use crate::track_loops::ClassImms;
use crate::track_table::TrackTable;
use glam::DVec2;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Writes every live track's fused prediction to time `timestamp_s` into `out`, in table
    /// order, without changing any state (see [`crate::prediction`]); returns how many were
    /// written (the live tracks, at most `out.len()`). Positions and velocities are given in
    /// the vehicle frame of the newest frame's ego pose (world-frame tracking; the ego motion
    /// since is not known to the tracker) with the world-frame values beside; use
    /// [`predict_to_with_pose`](Self::predict_to_with_pose) with the ego pose at
    /// `timestamp_s` to have them in the vehicle frame of that time.
    pub fn predict_to(&self, timestamp_s: f64, out: &mut [TrackOutput]) -> Result<usize, PredictError> {
        self.predict_to_with_pose(timestamp_s, None, out)
    }

    /// [`predict_to`](Self::predict_to) with the ego pose at `timestamp_s`, if known: the
    /// vehicle-frame outputs of world-frame tracks are then in the vehicle frame of that pose.
    pub fn predict_to_with_pose(
        &self,
        timestamp_s: f64,
        ego_pose: Option<EgoPose>,
        out: &mut [TrackOutput],
    ) -> Result<usize, PredictError> {
        if !timestamp_s.is_finite() {
            return Err(PredictError::NonFiniteTime { timestamp_s });
        }
        let Some(newest_s) = self.last_timestamp_s else { return Ok(0) };
        let dt_s = timestamp_s - newest_s;
        if dt_s < 0.0 {
            return Err(PredictError::BeforeNewestFrame { timestamp_s, newest_s });
        }
        let max_s = self.config.tracker.max_frame_interval_s;
        if dt_s > max_s {
            return Err(PredictError::TooFarAhead { timestamp_s, ahead_s: dt_s, max_s });
        }
        let world = self.tracks_frame == CoordinateFrame::World;
        let to_vehicle = if world {
            ego_pose.filter(|pose| pose.is_valid()).or(self.last_pose).map(|pose| pose.world_to_vehicle())
        } else {
            None
        };
        let survival = existence::survival_probability(dt_s, &self.config.tracker);
        let mut written = 0;
        for (track, slot) in self.table.tracks().iter().zip(out.iter_mut()) {
            let class = track.class.index();
            let (imm, models) = (&self.imms[class], &self.models[class]);
            let mut prior = ImmPrior::default();
            imm.predict_physics_into(models, &track.estimate, dt_s, &mut prior);
            imm.complete_prior_in_place(models, &mut prior, dt_s, None);
            let estimate = imm.fuse_position_velocity(&prior.state, prior.available);
            let position = DVec2::new(estimate.mean.x, estimate.mean.y);
            let velocity = DVec2::new(estimate.mean.z, estimate.mean.w);
            let position_covariance = prior.fused.covariance;
            let (position_m, position_covariance_m2, velocity_mps, state_covariance) = match to_vehicle {
                Some(to_vehicle) => (
                    to_vehicle.apply_point(position),
                    to_vehicle.apply_covariance(position_covariance),
                    to_vehicle.apply_vector(velocity),
                    to_vehicle.apply_state_covariance(estimate.covariance),
                ),
                None => (position, position_covariance, velocity, estimate.covariance),
            };
            *slot = TrackOutput {
                id: track.id,
                class: track.class,
                status: track.status,
                position_m,
                position_covariance_m2,
                velocity_mps,
                state_covariance,
                prior_position_m: None,
                world_position_m: to_vehicle.map(|_| position),
                world_velocity_mps: to_vehicle.map(|_| velocity),
                world_state_covariance: to_vehicle.map(|_| estimate.covariance),
                mode_probabilities: prior.state.probabilities,
                age_frames: track.age_frames,
                age_s: timestamp_s - track.started_s,
                hits: track.hits,
                misses: track.misses,
                existence_probability: track.existence_probability * survival,
                ground_truth_id: None,
                measurement_index: None,
            };
            written += 1;
        }
        Ok(written)
    }
}

/// The output record of every live track, handed to `sink`. Tracks in the world frame are
/// reported in the vehicle frame of the current frame (`world_to_vehicle`) with their world
/// position and velocity beside.
pub(super) fn report(
    table: &TrackTable,
    rows: &[RowRecord],
    imms: &ClassImms,
    world_to_vehicle: Option<RigidTransform>,
    timestamp_s: f64,
    mut sink: impl FnMut(&TrackOutput),
) {
    for (track, row) in table.tracks().iter().zip(rows.iter()) {
        let imm = &imms[track.class.index()];
        let fused = imm.fuse_posterior(&track.estimate, row.available);
        let velocity = imm.fuse_velocity(&track.estimate, row.available);
        let state_covariance = imm.fuse_position_velocity(&track.estimate, row.available).covariance;
        let (position_m, position_covariance_m2, velocity_mps, prior_position_m, vehicle_state_covariance) =
            match world_to_vehicle {
                Some(to_vehicle) => (
                    to_vehicle.apply_point(fused.mean),
                    to_vehicle.apply_covariance(fused.covariance),
                    to_vehicle.apply_vector(velocity),
                    row.prior_position_m.map(|prior| to_vehicle.apply_point(prior)),
                    to_vehicle.apply_state_covariance(state_covariance),
                ),
                None => (fused.mean, fused.covariance, velocity, row.prior_position_m, state_covariance),
            };
        sink(&TrackOutput {
            id: track.id,
            class: track.class,
            status: track.status,
            position_m,
            position_covariance_m2,
            velocity_mps,
            prior_position_m,
            world_position_m: world_to_vehicle.map(|_| fused.mean),
            world_velocity_mps: world_to_vehicle.map(|_| velocity),
            state_covariance: vehicle_state_covariance,
            world_state_covariance: world_to_vehicle.map(|_| state_covariance),
            mode_probabilities: track.estimate.probabilities,
            age_frames: track.age_frames,
            age_s: timestamp_s - track.started_s,
            hits: track.hits,
            misses: track.misses,
            existence_probability: track.existence_probability,
            ground_truth_id: row.measurement_index.and(track.ground_truth_id),
            measurement_index: row.measurement_index,
        });
    }
}
