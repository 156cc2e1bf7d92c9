//! Learn the sensors: after the update, each sensor's running estimates take what this frame
//! said of them (`crate::sensor::estimates`): where its detections of confirmed tracks lay on
//! their objects, which confirmed tracks in its view it detected, how large a field it scanned;
//! the deletion of a tentative track adds its detections to its first sensor's clutter.

use super::Tracker;
use crate::measurement::{FrameView, Measurement, ObjectClass};
use crate::occlusion::ObjectBox;
use crate::predictor::DisplacementPredictor;
use crate::sensor::platform::{PlatformModel, PLATFORM_MIN_TRACK_AGE_S};
use crate::sensor::{ReflectionModel, UNMOUNTED};
use crate::sensor_noise::MeasurementSensor;
use crate::track::Track;
use glam::DVec2;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Takes the radial velocity of a confirmed track's update in a frame without an ego pose
    /// into the platform estimate (`crate::sensor::platform`), when `frame.platform = "auto"`:
    /// its innovation against the track's prior velocity, seen from `sensor`.
    pub(super) fn learn_platform(&mut self, i: usize, measurement: &Measurement, sensor: &MeasurementSensor) {
        if self.config.frame.platform != PlatformModel::Auto
            || self.validated.ego_pose().is_some()
            || !self.was_confirmed[i]
        {
            return;
        }
        // A young track's velocity still holds its first radial velocity (initiation), which
        // agrees with the radial velocities whether the sensors move or not.
        if self.validated.timestamp_s() - self.table.tracks()[i].started_s < PLATFORM_MIN_TRACK_AGE_S {
            return;
        }
        let line_of_sight = (measurement.position() - sensor.position_m).normalize_or_zero();
        if line_of_sight == DVec2::ZERO {
            return;
        }
        let object = self.priors[i].object_prior();
        let noise_std_mps =
            self.config.classes.get(self.table.tracks()[i].class).radial_velocity_update.std_mps;
        self.sensors.platform_mut().observe(
            measurement.radial_velocity_mps,
            line_of_sight,
            (object.velocity_mps, object.velocity_covariance_m2),
            noise_std_mps,
        );
    }

    /// Takes the update of track `i` with a measurement of `sensor` (its innovation
    /// `innovation_m` under the step's measurement model and the innovation's variance
    /// `variance_m2`) into the reflection estimate of a sensor whose model is `auto`, and
    /// remembers where the sensor was relative to the track for its next update. Only tracks of
    /// an extended class take part, and only confirmed ones are samples: a tentative track may
    /// follow clutter. Sensors of a fixed model estimate nothing (the filter does not follow
    /// the estimate there, so it would not converge) and cost nothing.
    pub(super) fn learn_reflection(
        &mut self,
        i: usize,
        sensor: &MeasurementSensor,
        innovation_m: DVec2,
        variance_m2: f64,
    ) {
        let class = self.table.tracks()[i].class;
        let Some(extent) = self.models[class.index()].extent else { return };
        if self.sensors.get(usize::from(sensor.slot)).reflection != ReflectionModel::Auto {
            return;
        }
        let object = self.priors[i].object_prior();
        let relative_m = sensor.position_m - object.centre_m;
        let track = &mut self.table.tracks_mut()[i];
        let previous = track.sensor_relative_m.replace(relative_m);
        let (Some(previous_relative_m), true) = (previous, self.was_confirmed[i]) else { return };
        let outline_m = if sensor.reflection_scale > 0.0 {
            // The step's reflection is the outline's, scaled.
            self.assigned_reflections[i].offset_m / sensor.reflection_scale
        } else {
            crate::extent::outline_reflection(&extent, &object, sensor.position_m).offset_m
        };
        // The offset the previous update's geometry gives with this prior's heading: the change
        // is the geometry's alone (the sensor moved or another sensor measured, the object
        // passed by), not the heading's, which the previous innovation moved.
        let before_m =
            crate::extent::outline_reflection(&extent, &object, object.centre_m + previous_relative_m)
                .offset_m;
        let config = self.config.frame.estimation;
        let estimate =
            &mut self.sensors.get_mut(usize::from(sensor.slot)).estimates[class.index()].reflection;
        estimate.observe(&config, innovation_m, outline_m - before_m, variance_m2);
    }

    /// The frame's scans (their fields of view's areas) and detection opportunities (each
    /// confirmed track in view of a scanning sensor: a detection if it detected the track, a
    /// miss unless another confirmed track hid the track from it) into the sensors' clutter
    /// and detection estimates.
    pub(super) fn learn_sensors(&mut self) {
        self.collect_occluders();
        let config = self.config.frame.estimation;
        let unknown_view = self.unknown_sensor_view;
        let scanned = self
            .scanning_sensors
            .iter()
            .map(|scanning| (scanning.slot, scanning.field_of_view))
            .chain(unknown_view.map(|view| (UNMOUNTED, view)));
        for (slot, view) in scanned.clone() {
            let sensor = self.sensors.get_mut(slot);
            for estimates in sensor.estimates.iter_mut() {
                estimates.clutter.observe_scan(&config, view.area_m2());
            }
        }
        for i in 0..self.table.len() {
            if !self.was_confirmed[i] {
                continue;
            }
            let class = self.table.tracks()[i].class;
            let prior_m = self.priors[i].fused.mean;
            let detected_by = self.track_to_measurement[i]
                .map(|index| usize::from(self.measurement_sensors[usize::from(index)].slot));
            for (slot, view) in scanned.clone().filter(|(_, view)| view.contains(prior_m)) {
                let detected = detected_by == Some(slot);
                // A miss of an object hidden behind another says nothing of how well the sensor
                // detects what it can see; a detection shows the object was seen.
                if !detected && self.occluders.hide(i as u16, view.origin_m(), prior_m) {
                    continue;
                }
                let estimate = &mut self.sensors.get_mut(slot).estimates[class.index()].detection;
                estimate.observe(&config, detected);
            }
        }
    }

    /// The nominal boxes ([`ObjectBox::nominal`], the class's extent) of the tracks confirmed
    /// before this frame's update, at their priors, into `occluders`.
    fn collect_occluders(&mut self) {
        self.occluders.clear();
        for (j, track) in self.table.tracks().iter().enumerate() {
            if !self.was_confirmed[j] {
                continue;
            }
            let extent = &self.config.classes.get(track.class).extent;
            let prior = &self.priors[j];
            let object = ObjectBox::nominal(extent, prior.fused.mean, prior.fused_velocity_mps());
            // The capacity is the table's: every track fits.
            let _ = self.occluders.push(j as u16, object);
        }
    }

    /// A tentative `track` that ends without confirmation: its detections were false, as far
    /// as the tracker can tell; they go to the clutter of the sensor that started it.
    pub(super) fn learn_false_track(&mut self, class: ObjectClass, birth_slot: u8, hits: u32) {
        let sensor = self.sensors.get_mut(usize::from(birth_slot));
        sensor.estimates[class.index()].clutter.observe_false(hits);
    }
}

/// Whether a deleted `track` counts as false: it never was confirmed.
pub(super) fn was_false(track: &Track) -> bool {
    track.status == crate::track::TrackStatus::Tentative
}
