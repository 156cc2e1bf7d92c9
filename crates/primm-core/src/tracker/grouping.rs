//! Group the detections of point-cloud radars into object measurements (`crate::grouping`),
//! after the prediction and before the association: the validated frame then holds one
//! measurement per group, and the outputs name each group by its representative detection's
//! index (the one nearest to the group's mean).

use super::{MeasurementFate, Tracker};
use crate::grouping::frame_groups::Detection;
use crate::grouping::DetectionModel;
use crate::measurement::{FrameView, Measurement};
use crate::predictor::DisplacementPredictor;
use glam::DMat2;

/// The most vehicle detections of one radar's scan that [`Tracker::scan_clusters`] links (the
/// first in frame order): a point cloud's vehicles show within far fewer.
const SCAN_EVIDENCE_DETECTIONS: usize = 128;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Hands the frame's accepted detections of radars that deliver points (or may: `auto`)
    /// to the grouping with the confirmed track whose object holds each, counts what the
    /// `auto` radars' data say, and, when a radar of the frame delivers points, replaces the
    /// validated frame's measurements by the groups'. A frame of object radars only is left as
    /// it is.
    pub(super) fn group_detections(&mut self) {
        self.frame_groups.clear();
        self.grouped_frame = false;
        self.shadowed.fill(false);
        let mut any_points = false;
        let mut any_candidates = false;
        if self.sensors.iter().any(|sensor| sensor.detections != DetectionModel::Objects) {
            self.index_confirmed_tracks();
        }
        for index in 0..self.validated.len() {
            let Some(measurement) = self.validated.accepted(index) else { continue };
            let slot = self.sensors.slot(measurement.sensor_id);
            let sensor = self.sensors.get(slot);
            let candidate = sensor.detections != DetectionModel::Objects;
            let grouped = sensor.groups_detections();
            // Only grouped detections need their owner; an `auto` radar's count looks itself.
            let sensor_position_m = sensor.position_m(self.step_pose);
            let (owner, shadowed) =
                if grouped { self.owner_of(&measurement, sensor_position_m) } else { (None, None) };
            if let Some(row) = shadowed.filter(|_| grouped) {
                self.shadowed[usize::from(row)] = true;
            }
            let detection = Detection {
                measurement,
                frame_index: index as u16,
                sensor_slot: slot as u8,
                sensor_position_m,
                grouped,
                owner,
            };
            // The workspace holds a full frame, so this never refuses.
            let _ = self.frame_groups.push(detection);
            any_points |= grouped;
            any_candidates |= candidate;
        }
        if any_candidates {
            self.learn_points();
        }
        if any_points {
            self.replace_by_groups();
        }
    }

    /// The table row of the confirmed track (of any class: labels flip) whose object at its
    /// prior holds `measurement` (its class's box grown by [`Self::owner_margin_m`]) and which
    /// it moves with ([`Self::moves_with`]; `sensor_position_m` is its radar's). When
    /// several do, the nearest one's; but of two tracks that are likely one object followed
    /// twice ([`Self::duplicates`]), the older one's. The younger one is returned second: it is
    /// *shadowed*, and ends with the step when it took no measurement
    /// ([`Self::end_shadowed_tracks`]).
    fn owner_of(
        &self,
        measurement: &Measurement,
        sensor_position_m: glam::DVec2,
    ) -> (Option<u16>, Option<u16>) {
        let position_m = measurement.position();
        let tracks = self.table.tracks();
        let holds = |row: usize| {
            let distance_m2 = self.holds(row, position_m, self.owner_margin_m(row))?;
            self.moves_with(row, measurement, sensor_position_m).then_some(distance_m2)
        };
        let holders = self.confirmed.holders(position_m, |row| holds(row).is_some());
        let mut best: Option<(usize, f64)> = None;
        let mut shadowed = None;
        // The holders in the order of their priors' x: the choice below depends on it.
        for row in self.confirmed.rows(&holders) {
            let Some(distance_m2) = holds(row) else { continue };
            let better = match best {
                None => true,
                Some((best_row, best_m2)) => {
                    let (older, younger) =
                        if tracks[row].id < tracks[best_row].id { (row, best_row) } else { (best_row, row) };
                    if self.duplicates(older, younger) {
                        shadowed = Some(younger as u16);
                        older == row
                    } else {
                        distance_m2 < best_m2
                    }
                }
            };
            if better {
                best = Some((row, distance_m2));
            }
        }
        (best.map(|(row, _)| row as u16), shadowed)
    }

    /// Whether `measurement` moves as a return of the confirmed track in `row` can: its radial
    /// velocity within `link_radial_velocity_gap_mps` of the span a rigid body's returns cover
    /// along the line of sight from the radar, from the body's own radial speed `v_r` less
    /// `|v_r|` to it plus `|v_r|` (a wheel's contact point stands still, its top moves at twice
    /// the body's speed). A multipath image of the object moves with the mirrored velocity and
    /// clutter as it will; both fall outside once the object moves faster than the gap.
    fn moves_with(&self, row: usize, measurement: &Measurement, sensor_position_m: glam::DVec2) -> bool {
        let line_of_sight = (measurement.position() - sensor_position_m).normalize_or_zero();
        let expected_mps = self.radial_velocity_mps(row, line_of_sight);
        (measurement.radial_velocity_mps - expected_mps).abs()
            <= self.config.frame.grouping.link_radial_velocity_gap_mps + expected_mps.abs()
    }

    /// The velocity of the confirmed track in `row` at its prior (as the step's index holds
    /// it) along the unit `line_of_sight`, m/s.
    fn radial_velocity_mps(&self, row: usize, line_of_sight: glam::DVec2) -> f64 {
        self.confirmed.velocity_mps(row).dot(line_of_sight)
    }

    /// How far beyond its box a detection still joins the group of the track in `row`: the
    /// grouping's `owner_margin_m` for an extended class, whose point cloud spreads over its
    /// faces, the class's `extent.absorb_margin_m` for a point-like one (pedestrians walking
    /// side by side stay apart).
    fn owner_margin_m(&self, row: usize) -> f64 {
        let extent = &self.config.classes.get(self.table.tracks()[row].class).extent;
        if extent.enabled {
            self.config.frame.grouping.owner_margin_m
        } else {
            extent.absorb_margin_m
        }
    }

    /// Whether the confirmed tracks in rows `older` and `younger` follow one object: of one
    /// class with centres within its `duplicate_distance_m`, or with overlapping boxes
    /// ([`Self::boxes_overlap`]), or the younger one's centre on the older one's object (its
    /// class's box grown by `extent.absorb_margin_m`; a pedestrian track started on a car by a
    /// wrong label).
    fn duplicates(&self, older: usize, younger: usize) -> bool {
        let tracks = self.table.tracks();
        let younger_m = self.priors[younger].fused.mean;
        let apart_m = self.priors[older].fused.mean.distance(younger_m);
        let section = self.config.classes.get(tracks[older].class);
        (tracks[older].class == tracks[younger].class && apart_m <= section.duplicate_distance_m)
            || self.boxes_overlap(older, younger)
            || self.holds(older, younger_m, section.extent.absorb_margin_m).is_some()
    }

    /// Whether the confirmed tracks in rows `older` and `younger`, of one class with an extent,
    /// move as one (fused velocities within the class's `duplicate_speed_difference_mps`, at
    /// least its `extent.min_heading_speed_mps`) with boxes that overlap at their priors (the
    /// younger one's centre within the older one's box doubled along its heading). Two vehicles
    /// cannot stand in each other's box; a vehicle longer than the class's box, whose front
    /// and rear were tracked apart while its radar still delivered objects, does.
    fn boxes_overlap(&self, older: usize, younger: usize) -> bool {
        let tracks = self.table.tracks();
        let section = self.config.classes.get(tracks[older].class);
        let extent = &section.extent;
        let velocity_mps = self.confirmed.velocity_mps(older);
        let moving_as_one = velocity_mps.distance(self.confirmed.velocity_mps(younger))
            <= section.duplicate_speed_difference_mps;
        if tracks[older].class != tracks[younger].class
            || !extent.enabled
            || !(velocity_mps.length() >= extent.min_heading_speed_mps)
            || !moving_as_one
        {
            return false;
        }
        let doubled = crate::extent::ExtentConfig {
            length_m: 2.0 * extent.length_m,
            width_m: 2.0 * extent.width_m,
            absorb_margin_m: 0.0,
            ..*extent
        };
        crate::extent::lies_on_object(
            &doubled,
            self.priors[older].fused.mean,
            velocity_mps,
            self.priors[younger].fused.mean,
        )
    }

    /// Before the deletion: marks for ending (counted as deleted) every shadowed track that took
    /// no measurement in this step, a duplicate of the older track that took its object's
    /// detections, and every tentative track whose measurement of this step was a ghost of a
    /// confirmed track (`ghosts`); returns how many.
    pub(super) fn end_shadowed_and_ghost_tracks(&mut self) -> usize {
        let tracks = self.table.len();
        let mut ended = 0;
        for row in 0..tracks {
            self.ending[row] = self.shadowed[row] && self.rows[row].measurement_index.is_none();
            if !self.ending[row] && (self.follows_a_ghost(row) || self.images_a_track(row)) {
                self.ending[row] = true;
                self.last_step.counts.tentative_tracks_ended_as_ghost += 1;
            }
            ended += usize::from(self.ending[row]);
        }
        self.ending[tracks..].fill(false);
        ended
    }

    /// Indexes the confirmed tracks for the look-ups near a detection (`confirmed_index.rs`),
    /// with how far from its centre any of them can hold a detection: the circle through the
    /// corners of the largest class box grown by the largest margin.
    fn index_confirmed_tracks(&mut self) {
        let margin_m = self.config.frame.grouping.owner_margin_m;
        let reach_m = crate::measurement::ObjectClass::ALL
            .iter()
            .map(|&class| {
                let extent = &self.config.classes.get(class).extent;
                let grown = margin_m.max(extent.absorb_margin_m);
                crate::math::sqrt(
                    crate::math::square(0.5 * extent.length_m + grown)
                        + crate::math::square(0.5 * extent.width_m + grown),
                )
            })
            .fold(0.0, f64::max);
        let confirmed = self
            .table
            .tracks()
            .iter()
            .zip(self.priors.iter())
            .enumerate()
            .filter(|(_, (track, _))| track.status.is_confirmed())
            .map(|(row, (_, prior))| (row as u16, prior.fused.mean, prior.fused_velocity_mps()));
        self.confirmed.rebuild(confirmed, reach_m);
    }

    /// When the confirmed track in `row` holds `position_m` on its object at its prior (its
    /// class's box grown by `margin_m`): the squared distance from its centre, m². Only for the
    /// tracks of the current step's [`index_confirmed_tracks`](Self::index_confirmed_tracks).
    fn holds(&self, row: usize, position_m: glam::DVec2, margin_m: f64) -> Option<f64> {
        let track = &self.table.tracks()[row];
        let prior = &self.priors[row];
        let section = &self.config.classes.get(track.class).extent;
        // Beyond the circle through the grown box's corners (the disc lies within it too).
        let reach_m2 = crate::math::square(0.5 * section.length_m + margin_m)
            + crate::math::square(0.5 * section.width_m + margin_m);
        if prior.fused.mean.distance_squared(position_m) > reach_m2 {
            return None;
        }
        let extent = crate::extent::ExtentConfig { absorb_margin_m: margin_m, ..*section };
        let centre_m = prior.fused.mean;
        crate::extent::lies_on_object(&extent, centre_m, self.confirmed.velocity_mps(row), position_m)
            .then(|| centre_m.distance_squared(position_m))
    }

    /// Each confirmed track's count of the frame's detections of an `auto` radar on its object
    /// and moving as it (every detection inside its box grown by `points_evidence_margin_m` and
    /// inside no other object's box, whose radial velocity is the track's along the detection's
    /// line of sight within `link_radial_velocity_gap_mps`, so that clutter and crossing objects
    /// in the box do not count; whichever track owns it: a radar's point cloud tracked one
    /// detection at a time gives an object several tracks, each holding the object's detections)
    /// into that radar's
    /// [`PointsEstimate`](crate::sensor::points::PointsEstimate), one radar at a time; counted
    /// up to two, as the estimate asks only for one or several. A radar without a track scan
    /// yet also counts its scan's clusters ([`Self::scan_clusters`]).
    fn learn_points(&mut self) {
        let config = self.config.frame.grouping;
        let mut slots = arrayvec::ArrayVec::<u8, { crate::limits::MAX_SENSORS + 1 }>::new();
        for detection in self.frame_groups.detections() {
            let auto =
                self.sensors.get(usize::from(detection.sensor_slot)).detections == DetectionModel::Auto;
            if auto && !slots.contains(&detection.sensor_slot) {
                // There are at most MAX_SENSORS + 1 slots, so this never overflows.
                let _ = slots.try_push(detection.sensor_slot);
            }
        }
        let tracks = self.table.len();
        for slot in slots {
            if self.sensors.get(usize::from(slot)).points.samples == 0 {
                let (detections, clustered) = self.scan_clusters(slot);
                self.sensors.get_mut(usize::from(slot)).points.observe_scan(detections, clustered);
            }
            self.owned_counts[..tracks].fill(0);
            for detection in self.frame_groups.detections() {
                // A vehicle's points, by their labels (a tenth may be wrong): a pedestrian
                // passing a slow car stands in its box moving much as the car does.
                if detection.sensor_slot != slot
                    || !self.config.classes.get(detection.measurement.class).extent.enabled
                {
                    continue;
                }
                let position_m = detection.measurement.position();
                let line_of_sight = (position_m - detection.sensor_position_m).normalize_or_zero();
                for row in self.confirmed.near(position_m) {
                    // The estimate asks only whether a track scan holds one detection or
                    // several, so a track that has two already needs no more.
                    if self.owned_counts[row] >= 2 {
                        continue;
                    }
                    // On the box grown by the evidence margin (a point cloud lies on its object),
                    // moving as the object (clutter and crossing objects in the box do not), and
                    // not on another object's box (a neighbour's detection lies on the
                    // neighbour); the costliest test last.
                    let expected_mps = self.radial_velocity_mps(row, line_of_sight);
                    if self.holds(row, position_m, config.points_evidence_margin_m).is_some()
                        && (detection.measurement.radial_velocity_mps - expected_mps).abs()
                            <= config.link_radial_velocity_gap_mps
                        && !self.held_by_another_object(row, position_m)
                    {
                        self.owned_counts[row] += 1;
                    }
                }
            }
            let estimate = &mut self.sensors.get_mut(usize::from(slot)).points;
            let table = self.table.tracks();
            for (row, &count) in
                self.owned_counts[..tracks].iter().enumerate().filter(|(_, &count)| count > 0)
            {
                if self.config.classes.get(table[row].class).extent.enabled {
                    estimate.observe(&config, usize::from(count));
                }
            }
        }
        self.sensors.decide_points(&config);
    }

    /// The frame's vehicle-labelled detections of the radar in `slot` (the first
    /// [`SCAN_EVIDENCE_DETECTIONS`] of them in frame order) and how many of those lie in a
    /// cluster of at least [`SCAN_CLUSTER_DETECTIONS`](crate::sensor::points::SCAN_CLUSTER_DETECTIONS)
    /// linked by the grouping's link rule: the scan's own evidence of a point cloud before the
    /// radar's first track scan.
    fn scan_clusters(&mut self, slot: u8) -> (usize, usize) {
        let rule = self.config.frame.grouping.link_rule();
        let classes = &self.config.classes;
        self.frame_groups.clustered(
            &rule,
            |detection| {
                detection.sensor_slot == slot && classes.get(detection.measurement.class).extent.enabled
            },
            SCAN_EVIDENCE_DETECTIONS,
            crate::sensor::points::SCAN_CLUSTER_DETECTIONS,
        )
    }

    /// Whether a confirmed track other than the one in `row`, and not following its object
    /// (neither is the other's duplicate), holds `position_m` inside its box (not grown): the
    /// detection is then a neighbour's, a car queued behind or parked beside, and says nothing of
    /// how many detections the radar gives one object.
    fn held_by_another_object(&self, row: usize, position_m: glam::DVec2) -> bool {
        self.confirmed.near(position_m).any(|other| {
            other != row
                && self.holds(other, position_m, 0.0).is_some()
                && !(self.duplicates(row, other) || self.duplicates(other, row))
        })
    }

    /// Forms the groups and makes them the validated frame's measurements.
    fn replace_by_groups(&mut self) {
        let rule = self.config.frame.grouping.link_rule();
        let groups = self.frame_groups.form(&rule);
        let detections = self.frame_groups.detections().count();
        self.validated.set_len(groups);
        for group in 0..groups {
            let mut measurement = self.frame_groups.measurement(group);
            // A confirmed track's class is many scans' evidence; one scan's labels, a tenth of
            // them wrong, do not overrule it for the detections on its object.
            if let Some(row) = self.frame_groups.owner(group) {
                measurement.class = self.table.tracks()[usize::from(row)].class;
            }
            self.group_centre_spread[group] = self.move_to_centre(group, &mut measurement);
            self.validated.set(group, Some(measurement));
            self.accepted[group] = true;
            self.fates[group] = MeasurementFate::Unassigned;
            self.group_first_index[group] = self.frame_groups.representative_frame_index(group);
        }
        self.last_step.counts.detections_grouped += (detections - groups) as u64;
        self.grouped_frame = true;
    }

    /// Moves the measurement of `group`, when it holds several detections of an extended class,
    /// from the mean of its detections to the centre of its object by the offset of the
    /// visible contour's centroid (`crate::grouping::contour`): of the owning confirmed track's
    /// box at its prior, or, for a group no track owns (a new object, no heading yet), of the
    /// disc about the group's mean. Returns, when it did, the contour's covariance of one point
    /// about its centroid; such a measurement is then a measurement of the centre (reflection
    /// scale 0) whose noise is that covariance and the radar's, over the count
    /// (`crate::grouping::contour::group_noise_m2`). A single detection keeps the
    /// radar's reflection model: moved to the contour's centroid, it lost accuracy on the
    /// `extended` validation split, whose radars briefly took points.
    fn move_to_centre(&self, group: usize, measurement: &mut Measurement) -> Option<DMat2> {
        let count = self.frame_groups.members(group).len();
        if count < 2 {
            return None;
        }
        let owner = self.frame_groups.owner(group).map(usize::from);
        let class = owner.map_or(measurement.class, |row| self.table.tracks()[row].class);
        let extent = &self.config.classes.get(class).extent;
        if !extent.enabled {
            return None;
        }
        let sensor_m = self.sensors.of(measurement.sensor_id).position_m(self.step_pose);
        // A tracked object's box at its prior; a new object's disc about the group's mean.
        let (centre_m, velocity_mps) = match owner {
            Some(row) => (self.priors[row].fused.mean, self.priors[row].fused_velocity_mps()),
            None => (measurement.position(), glam::DVec2::ZERO),
        };
        let contour = crate::grouping::contour::visible_contour(extent, centre_m, velocity_mps, sensor_m);
        measurement.x_m -= contour.offset_m.x;
        measurement.y_m -= contour.offset_m.y;
        Some(contour.covariance_m2)
    }

    /// After a grouped frame: the measurement index of every row names its group's
    /// representative detection in the frame, as the outputs report it.
    pub(super) fn name_groups_by_representative(&mut self) {
        if !self.grouped_frame {
            return;
        }
        for row in self.rows[..self.table.len()].iter_mut() {
            if let Some(group) = row.measurement_index {
                row.measurement_index = Some(self.group_first_index[usize::from(group)]);
            }
        }
    }
}
