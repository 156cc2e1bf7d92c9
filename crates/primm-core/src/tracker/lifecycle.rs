//! Initiate, delete and merge: tracks start from unassigned measurements, end by the configured
//! lifecycle, and a track that shadows an older one of the same object is merged into it
//! (`crate::duplicates`).

use super::{confirms, retain_with_rows, MeasurementFate, RowRecord, Tracker};
use crate::duplicates::{self, DuplicateView};
use crate::existence::Lifecycle;
use crate::extent::ExpectedReflection;
use crate::measurement::FrameView;
use crate::measurement::Measurement;
use crate::predictor::DisplacementPredictor;
use crate::track::{Track, TrackStatus};

impl<P: DisplacementPredictor> Tracker<P> {
    /// Every accepted, unassigned measurement starts a tentative track, except one that a
    /// confirmed track of an extended class absorbs as a second detection of its object.
    pub(super) fn initiate(&mut self, t: f64) {
        let initial_existence = self.config.tracker.initial_existence_probability;
        let tracks_before = self.table.len();
        for index in 0..self.validated.len() {
            if self.fates[index] != MeasurementFate::Unassigned {
                continue;
            }
            let Some(measurement) = self.validated.accepted(index) else { continue };
            if self.absorbed_by_a_track(&measurement, tracks_before) {
                self.last_step.counts.detections_absorbed += 1;
                continue;
            }
            // Where the history's line of sight starts: the radial-velocity row's radar position.
            let sensor = self.measurement_sensors[index];
            if self.mirrors_a_track(&measurement, sensor.position_m, tracks_before) {
                self.last_step.counts.initiations_refused_as_ghost += 1;
                continue;
            }
            if !sensor.mounted && self.step_pose.is_some() {
                self.last_step.counts.initiations_from_unknown_sensor += 1;
            }
            let line_of_sight_origin = sensor.position_m;
            let models = &self.models[measurement.class.index()];
            // An extended object starts at the centre behind its reflection (no heading yet:
            // the disc model of `crate::extent`), its position spread by the reflection's.
            let (mut centre, mut reflection) = (measurement, ExpectedReflection::POINT);
            if models.extent.is_some() {
                let standing =
                    crate::extent::ObjectPrior { centre_m: measurement.position(), ..Default::default() };
                reflection =
                    models.expected_reflection(&standing, sensor.position_m, sensor.reflection_scale);
                (centre.x_m, centre.y_m) =
                    (measurement.x_m - reflection.offset_m.x, measurement.y_m - reflection.offset_m.y);
                if !sensor.mounted {
                    self.last_step.counts.updates_from_unknown_sensor += 1;
                }
            }
            let imms = super::step_imms(self.step_pose.is_some(), &self.imms, &self.compensated_imms);
            let mut estimate = imms[measurement.class.index()].initiate_seen_from(
                &self.models[measurement.class.index()],
                &centre,
                sensor.position_m,
            );
            // The radar's own noise spreads the start as it spreads every update.
            estimate.add_position_covariance(&crate::gaussian::to_nalgebra(
                &(reflection.covariance_m2 + sensor.noise_m2),
            ));
            let max_speed_mps = self.config.classes.get(measurement.class).max_speed_mps;
            if super::update::bound_speed(max_speed_mps, self.step_pose.is_some(), &mut estimate) {
                self.last_step.counts.speeds_bounded += 1;
            }
            let tracker = &self.config.tracker;
            match self.table.insert(|id| {
                Track::new(id, &measurement, line_of_sight_origin, t, estimate, initial_existence)
            }) {
                Ok(track) => {
                    track.birth_sensor_slot = sensor.slot;
                    self.last_step.counts.tracks_initiated += 1;
                    // A confirmation threshold of one hit (or an initial existence at the
                    // threshold) confirms at once.
                    if confirms(track, tracker) {
                        track.status = TrackStatus::Confirmed;
                        self.last_step.counts.tracks_confirmed += 1;
                    }
                    self.rows[self.table.len() - 1] = RowRecord {
                        prior_position_m: None,
                        available: self.config.imm.modes,
                        measurement_index: Some(index as u16),
                    };
                    self.fates[index] = MeasurementFate::Assigned;
                }
                Err(_) => self.last_step.counts.initiations_refused_table_full += 1,
            }
        }
    }

    /// Whether a confirmed track among the first `tracks` (those with a prior this frame) of the
    /// measurement's class, tracked as an extended object that absorbs extra detections, has
    /// `measurement` on its object ([`crate::extent::lies_on_object`], at the track's prior).
    pub(super) fn absorbed_by_a_track(&self, measurement: &Measurement, tracks: usize) -> bool {
        let extent = &self.config.classes.get(measurement.class).extent;
        if !(extent.enabled && extent.absorb_extra_detections) {
            return false;
        }
        self.table.tracks()[..tracks].iter().zip(&self.priors[..tracks]).any(|(track, prior)| {
            track.class == measurement.class
                && track.status.is_confirmed()
                && crate::extent::lies_on_object(
                    extent,
                    prior.fused.mean,
                    prior.fused_velocity_mps(),
                    measurement.position(),
                )
        })
    }

    /// Removes tentative tracks after `tentative_max_coast_s` without update, confirmed ones
    /// after `max_coast_s`; and by the lifecycle: tracks whose existence probability fell below
    /// `deletion_existence_probability`, or (counting) tentative tracks after
    /// `tentative_max_misses` misses and confirmed ones after `confirmed_max_misses`.
    pub(super) fn delete(&mut self, t: f64) {
        let lifecycle = &self.config.tracker;
        let mut false_tracks =
            [(crate::measurement::ObjectClass::Car, 0u8, 0u32); crate::track_table::MAX_TRACKS];
        let mut false_count = 0;
        let ending = &self.ending;
        let deleted = retain_with_rows(&mut self.table, &mut self.rows[..], |index, track| {
            let (max_misses, max_coast_s) = if track.status.is_confirmed() {
                (lifecycle.confirmed_max_misses, lifecycle.max_coast_s)
            } else {
                (lifecycle.tentative_max_misses, lifecycle.tentative_max_coast_s)
            };
            let alive = match lifecycle.lifecycle {
                Lifecycle::Counts => track.misses <= max_misses,
                Lifecycle::Existence => {
                    track.existence_probability >= lifecycle.deletion_existence_probability
                }
            };
            let kept = alive && t - track.last_update_s <= max_coast_s && !ending[index];
            if !kept && super::sensors::was_false(track) {
                false_tracks[false_count] = (track.class, track.birth_sensor_slot, track.hits);
                false_count += 1;
            }
            kept
        });
        for &(class, slot, hits) in &false_tracks[..false_count] {
            self.learn_false_track(class, slot, hits);
        }
        self.last_step.counts.tracks_deleted = deleted as u64;
    }

    /// Merges each track that has shadowed an older track of its class for
    /// `tracker.duplicate_updates` exclusive updates into that track (`crate::duplicates`).
    pub(super) fn merge_duplicates(&mut self) {
        if !duplicates::enabled(&self.config) {
            return;
        }
        let count = self.table.len();
        for (i, track) in self.table.tracks().iter().enumerate() {
            let imm = &self.imms[track.class.index()];
            let available = self.rows[i].available;
            self.duplicate_views[i] = DuplicateView {
                position_m: imm.fuse_posterior(&track.estimate, available).mean,
                velocity_mps: imm.fuse_velocity(&track.estimate, available),
                updated: self.rows[i].measurement_index.is_some(),
            };
        }
        self.merged[..count].fill(false);
        let needed = self.config.tracker.duplicate_updates;
        for younger in 0..count {
            let partner = self.older_overlapping_track(younger);
            let views = &self.duplicate_views;
            let track = &mut self.table.tracks_mut()[younger];
            let Some(older) = partner else {
                track.duplicate_of = None;
                track.exclusive_updates = 0;
                continue;
            };
            let older_id = self.table.tracks()[older].id;
            let track = &mut self.table.tracks_mut()[younger];
            if track.duplicate_of != Some(older_id) {
                track.duplicate_of = Some(older_id);
                track.exclusive_updates = 0;
            }
            track.exclusive_updates = duplicates::next_exclusive_updates(
                track.exclusive_updates,
                views[younger].updated,
                views[older].updated,
            );
            if track.exclusive_updates >= needed && !self.merged[older] {
                self.merge_into(younger, older);
            }
        }
        let merged = &self.merged;
        let removed = retain_with_rows(&mut self.table, &mut self.rows[..], |index, _| !merged[index]);
        self.last_step.counts.duplicate_tracks_merged += removed as u64;
    }

    /// The nearest older track (more frames, or as many and a smaller id) of `index`'s class that
    /// overlaps it, not already merged away.
    pub(super) fn older_overlapping_track(&self, index: usize) -> Option<usize> {
        let tracks = self.table.tracks();
        let track = &tracks[index];
        let section = self.config.classes.get(track.class);
        let view = &self.duplicate_views[index];
        let older = |other: &crate::track::Track| {
            (other.age_frames, core::cmp::Reverse(other.id))
                > (track.age_frames, core::cmp::Reverse(track.id))
        };
        (0..tracks.len())
            .filter(|&j| j != index && !self.merged[j] && tracks[j].class == track.class && older(&tracks[j]))
            .filter(|&j| {
                duplicates::overlap(
                    view,
                    &self.duplicate_views[j],
                    section.duplicate_distance_m,
                    section.duplicate_speed_difference_mps,
                )
            })
            .min_by(|&a, &b| {
                let distance =
                    |j: usize| view.position_m.distance_squared(self.duplicate_views[j].position_m);
                distance(a).total_cmp(&distance(b))
            })
    }

    /// Merges track `younger` into `older`: the older keeps its id, age, hits and status (the
    /// better of the two), and takes the younger's state if that was updated more recently.
    pub(super) fn merge_into(&mut self, younger: usize, older: usize) {
        let source = self.table.tracks()[younger].clone();
        let target = &mut self.table.tracks_mut()[older];
        if source.last_update_s > target.last_update_s {
            target.estimate = source.estimate;
            target.history = source.history;
            target.last_radial_velocity_mps = source.last_radial_velocity_mps;
            target.last_update_s = source.last_update_s;
            target.misses = source.misses;
            target.ground_truth_id = source.ground_truth_id;
            if target.status == TrackStatus::Coasting {
                target.status = TrackStatus::Confirmed;
            }
            self.rows[older] = self.rows[younger];
        }
        target.existence_probability = target.existence_probability.max(source.existence_probability);
        if source.status.is_confirmed() && !target.status.is_confirmed() {
            target.status = source.status;
        }
        self.merged[younger] = true;
    }
}
