//! Multipath ghosts: a radar's echo that reached an object by way of a wall (a guard rail, a
//! building front along the road) appears at the object's mirror image behind the wall, moving
//! with the mirrored velocity. A tracker that starts a track on it follows a consistent object
//! that is not there.
//!
//! Walls run along the roads that objects drive and walk along, so the mirror line of a ghost
//! lies parallel to its object's heading, between the object and its image, with the radar on
//! the object's side. An unassigned measurement is taken for the ghost of a confirmed, moving
//! track when all of these hold:
//!
//! * it lies beside the track across the track's heading: its offset along the heading is at
//!   most half the track's extent plus [`GHOST_ALONG_SLOPE`] times its offset across;
//! * the radar lies on the track's side of the mirror line halfway between them, and the
//!   measurement is farther from the radar than the track;
//! * its radial velocity is that of the mirrored velocity seen from the radar, within three of
//!   the class's `likelihood_radial_velocity_std_mps`;
//! * the track moves at least twice its class's `extent.min_heading_speed_mps`, so that the
//!   velocity test says something (a standing object's image stands like any standing thing).
//!
//! The check runs on the frames of radars whose detections are grouped (`crate::grouping`):
//! on the generator's object-list presets with clutter it refused or ended more real objects'
//! tracks than ghosts (IMM IDF1 of confirmed tracks 0.950 → 0.932 on the `clutter` evaluation
//! split), so object radars are left to the existence model as before.
//!
//! Such a measurement starts no track (counted as `initiations_refused_as_ghost`), and a
//! tentative track that it updated ends (`tentative_tracks_ended_as_ghost`): a ghost and its
//! object often appear together, before the object's track is confirmed. A confirmed track is
//! never ended this way. A real object that happens to stand in the mirror
//! position of another (two vehicles side by side at one speed) is started a scan later, once
//! the two have moved apart, at the cost of a delay; a ghost stays in the mirror position and
//! never starts.

use super::Tracker;
use crate::measurement::Measurement;
use crate::predictor::DisplacementPredictor;
use glam::DVec2;

/// The slope of the mirror condition along the heading: the offset along the track's heading
/// may grow with the offset across it by this factor (tan 15°, for walls within 15° of the
/// heading).
pub const GHOST_ALONG_SLOPE: f64 = 0.267_949_192_431_122_7;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Whether the track in `row`, tentative, took a measurement in this step that mirrors a
    /// confirmed track ([`Self::mirrors_a_track`]).
    pub(super) fn follows_a_ghost(&self, row: usize) -> bool {
        let track = &self.table.tracks()[row];
        if track.status.is_confirmed() {
            return false;
        }
        let Some(measurement) = self.assigned_measurements[row] else { return false };
        self.mirrors_a_track(&measurement, self.assigned_sensors[row].position_m, self.table.len())
    }

    /// Whether `measurement`, seen by a radar at `sensor_m`, is the mirror image of one of the
    /// first `tracks` tracks (those with a prior this frame) in a wall along its heading.
    pub(super) fn mirrors_a_track(&self, measurement: &Measurement, sensor_m: DVec2, tracks: usize) -> bool {
        if self.step_pose.is_none() || !self.grouped_frame {
            // Radial velocities are over ground; vehicle-frame velocities are not. Only the
            // frames of point-cloud radars are checked: on object radars' frames the check
            // cost more real objects than it removed ghosts (docs/EVALUATION.md).
            return false;
        }
        let position_m = measurement.position();
        let line_of_sight = (position_m - sensor_m).normalize_or_zero();
        let range_m = position_m.distance(sensor_m);
        self.table.tracks()[..tracks].iter().zip(&self.priors[..tracks]).any(|(track, prior)| {
            if !track.status.is_confirmed() {
                return false;
            }
            let section = self.config.classes.get(track.class);
            let velocity_mps = prior.fused_velocity_mps();
            let speed_mps = velocity_mps.length();
            if !(speed_mps >= 2.0 * section.extent.min_heading_speed_mps) {
                return false;
            }
            let (heading, across) = (velocity_mps / speed_mps, (velocity_mps / speed_mps).perp());
            let centre_m = prior.fused.mean;
            let offset_m = position_m - centre_m;
            let (along_m, beside_m) = (offset_m.dot(heading), offset_m.dot(across));
            let sensor_beside_m = (sensor_m - centre_m).dot(across);
            let beside = along_m.abs() <= 0.5 * section.extent.length_m + GHOST_ALONG_SLOPE * beside_m.abs();
            let radar_on_track_side = beside_m.signum() * (0.5 * beside_m - sensor_beside_m) > 0.0;
            let farther = range_m > centre_m.distance(sensor_m);
            let mirrored_mps = heading * velocity_mps.dot(heading) - across * velocity_mps.dot(across);
            let tolerance_mps = 3.0 * section.likelihood_radial_velocity_std_mps;
            let moves_as_image =
                (mirrored_mps.dot(line_of_sight) - measurement.radial_velocity_mps).abs() <= tolerance_mps;
            beside && radar_on_track_side && farther && moves_as_image
        })
    }
}
