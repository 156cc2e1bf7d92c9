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
//!   velocity test says something (a standing object's image stands like any standing thing);
//! * it is at least [`GHOST_RCS_LOSS_DB`] weaker than the track's remembered measurements on
//!   average. Without this a car in the next lane beyond a tracked one, moving alike, took the
//!   place and velocity of an image and never started: on a scene of 64 cars in parallel lanes
//!   4 m apart (`tools/point_cloud_lanes.py`) under the shipped configuration 27 of them
//!   stayed untracked.
//!
//! The check runs on the frames of radars whose detections are grouped (`crate::grouping`):
//! on the generator's object-list presets with clutter it refused or ended more real objects'
//! tracks than ghosts (IMM IDF1 of confirmed tracks 0.950 → 0.932 on the `clutter` evaluation
//! split), so object radars are left to the existence model as before.
//!
//! Such a measurement starts no track (counted as `initiations_refused_as_ghost`), and a
//! tentative track that it updated ends (`tentative_tracks_ended_as_ghost`): a ghost and its
//! object often appear together, before the object's track is confirmed. A confirmed track is
//! never ended this way. A real object as weak as an image that happens to stand in the mirror
//! position of another (a small car beside a lorry at one speed) does not start while it stays
//! there; a ghost stays in the mirror position and never starts.
//!
//! One measurement says little: a single radial velocity, a position that a wall at any angle
//! could explain. A ghost that slipped through (a pedestrian's, one in a wall across the
//! heading at a junction, one born before its object's track was confirmed) gathers more while
//! its track is tentative, so every track that was tentative when the step began and has a
//! prior is also held against each confirmed track started no later than it
//! ([`Tracker::images_a_track`]). That includes a track the step's own update has just
//! confirmed, as its first update confirms a pedestrian's image (a small spread makes a second
//! detection at the predicted place strong evidence), and a track started in the same frame as
//! the confirmed one: at first sight an object and its image appear together, and the image's
//! track may be the frame's first. The would-be wall is then the
//! line halfway between the two fused centres, at right angles to the line joining them, at
//! any orientation. The tentative track is the image, and ends (counted in
//! `tentative_tracks_ended_as_ghost` as well), when all of these hold:
//!
//! * the confirmed track moves at least its class's `extent.min_heading_speed_mps`, or it is
//!   of the tentative track's class (a standing object's image stands like any standing
//!   thing, so the velocity test says little there, and a parked car would otherwise end the
//!   tracks of pedestrians walking behind it);
//! * the two centres are farther apart than the confirmed track's class is wide (the object
//!   stands on the road side of the wall, so its image lies at least its own width away);
//! * every radar of the tentative track's remembered measurements stood on the confirmed
//!   track's side of the wall (a radar sees an image only through the wall, from the road
//!   side; it follows that the image is the farther of the two from each of them);
//! * its remembered measurements are on average at least [`GHOST_RCS_LOSS_DB`] weaker than the
//!   confirmed track's: the bounce off the wall and the longer path lose energy, whereas a
//!   real object beside another is as likely the stronger of the two as the weaker;
//! * its fused velocity is the confirmed track's mirrored in the wall, within a chi-square gate
//!   ([`GHOST_VELOCITY_GATE`]) of the two velocity covariances plus the class's
//!   `likelihood_radial_velocity_std_mps` in every direction.
//!
//! Tracks confirmed before the step are not checked: ending young ones too (up to 5 or 10
//! hits) lowered IDF1 of confirmed tracks on the point-cloud validation split, ending real
//! objects' tracks
//! (docs/EVALUATION.md, "Point clouds"). Without the RCS condition the check also ended real
//! objects' tentative tracks (pedestrians walking side by side, cars in adjacent lanes: one
//! for every nine of ghosts and clutter) and IDF1 with point-cloud radars did not rise; with a
//! mirror line along the heading only (as for single measurements) it caught too few ghosts.

use super::Tracker;
use crate::measurement::Measurement;
use crate::predictor::DisplacementPredictor;
use crate::track::Track;
use glam::{DMat2, DVec2};

/// The slope of the mirror condition along the heading: the offset along the track's heading
/// may grow with the offset across it by this factor (tan 15°, for walls within 15° of the
/// heading).
pub const GHOST_ALONG_SLOPE: f64 = 0.267_949_192_431_122_7;

/// How much weaker, dB, a tentative track's measurements must be on average than a confirmed
/// track's to be taken for its image: a wall's reflection loss and the longer path. Chosen on
/// the point-cloud validation splits between 3 and 8 dB: 6 dB while an `auto` radar's first
/// scans were tracked as objects (IDF1 of confirmed tracks flat from 5 to 7 dB), 5 dB since
/// they are grouped when they show point clouds (IDF1 level or higher on all four sets, and
/// ghost-born tracks 94 → 64; 4 dB lost IDF1; docs/EVALUATION.md, "Point clouds").
pub const GHOST_RCS_LOSS_DB: f64 = 5.0;

/// The gate on the squared Mahalanobis distance between a tentative track's fused velocity and
/// a confirmed track's mirrored one: the chi-square quantile of two degrees of freedom at
/// 10⁻⁴. A young track's velocity covariance understates its error: on the point-cloud
/// validation split the 1 % quantile (9.21) ended fewer ghosts and scored lower IDF1; 12 to 30
/// scored within 0.005 of each other.
pub const GHOST_VELOCITY_GATE: f64 = 18.42;

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
            // Weaker, as an image is (a wall's loss, a longer path); a second car beside the
            // first, moving alike in the next lane, is as strong.
            let weaker = measurement.rcs_dbsm <= mean_rcs_dbsm(track) - GHOST_RCS_LOSS_DB;
            beside && radar_on_track_side && farther && moves_as_image && weaker
        })
    }

    /// Whether the track in `row`, tentative when the step began (confirmed by this step's
    /// update or not) and with a prior this step, is the mirror image of a confirmed track started
    /// no later than it in a wall halfway between them (module docs).
    pub(super) fn images_a_track(&self, row: usize) -> bool {
        let tracks = self.table.tracks();
        let image = &tracks[row];
        if self.step_pose.is_none()
            || !self.grouped_frame
            || self.was_confirmed[row]
            || self.rows[row].prior_position_m.is_none()
        {
            return false;
        }
        let image_prior = self.priors[row].object_prior();
        let image_rcs_dbsm = mean_rcs_dbsm(image);
        tracks.iter().zip(self.rows.iter()).enumerate().any(|(other, (track, record))| {
            let not_younger = track.started_s <= image.started_s;
            if other == row
                || !not_younger
                || !track.status.is_confirmed()
                || record.prior_position_m.is_none()
            {
                return false;
            }
            let section = self.config.classes.get(track.class);
            let object = self.priors[other].object_prior();
            let offset_m = image_prior.centre_m - object.centre_m;
            let apart_m = offset_m.length();
            // A standing object's image stands like any standing thing, so only one of its own
            // class is held against it: a parked car would otherwise end the tracks of
            // pedestrians walking behind it.
            let moving = object.velocity_mps.length() >= section.extent.min_heading_speed_mps;
            if !((moving || track.class == image.class)
                && apart_m > section.extent.width_m
                && image_rcs_dbsm + GHOST_RCS_LOSS_DB <= mean_rcs_dbsm(track))
            {
                return false;
            }
            let normal = offset_m / apart_m;
            let wall_m = object.centre_m + 0.5 * offset_m;
            let seen_through_the_wall = image
                .history
                .oldest_ordered()
                .all(|entry| (DVec2::new(entry.sensor_x_m, entry.sensor_y_m) - wall_m).dot(normal) < 0.0);
            seen_through_the_wall
                && moves_as_mirrored(
                    &image_prior,
                    &object,
                    normal,
                    section.likelihood_radial_velocity_std_mps,
                )
        })
    }
}

/// Whether `image`'s velocity is `object`'s mirrored in a wall of unit normal `normal`: the
/// squared Mahalanobis distance of the difference, under both velocity covariances (the
/// object's mirrored) plus `floor_mps`² in every direction, within [`GHOST_VELOCITY_GATE`].
fn moves_as_mirrored(
    image: &crate::extent::ObjectPrior,
    object: &crate::extent::ObjectPrior,
    normal: DVec2,
    floor_mps: f64,
) -> bool {
    let reflection = DMat2::IDENTITY - 2.0 * DMat2::from_cols(normal * normal.x, normal * normal.y);
    let spread = image.velocity_covariance_m2
        + reflection * object.velocity_covariance_m2 * reflection
        + DMat2::from_diagonal(DVec2::splat(floor_mps * floor_mps));
    let difference = image.velocity_mps - reflection * object.velocity_mps;
    let determinant = spread.determinant();
    determinant > 0.0 && difference.dot(spread.inverse() * difference) <= GHOST_VELOCITY_GATE
}

/// The mean RCS of a track's remembered measurements, dBsm (0 with none).
fn mean_rcs_dbsm(track: &Track) -> f64 {
    let (sum, count) = track
        .history
        .oldest_ordered()
        .fold((0.0, 0.0), |(sum, count), entry| (sum + entry.rcs_dbsm, count + 1.0));
    if count > 0.0 {
        sum / count
    } else {
        0.0
    }
}
