//! Associate, update and coast: per-class optimal assignment, the Kalman and mode-probability
//! update of every assigned track with its existence, and the tracks without a measurement.

use super::{confirms, covariance, MeasurementFate, RowRecord, StepError, Tracker};
use crate::existence::{self, Evidence};
use crate::extent::ExpectedReflection;
use crate::gaussian::RadialVelocityOutcome;
use crate::imm::ImmState;
use crate::measurement::FrameView;
use crate::measurement::ObjectClass;
use crate::predictor::DisplacementPredictor;
use crate::sensor::UNMOUNTED;
use crate::sensor_noise::MeasurementSensor;
use crate::track::TrackStatus;
use crate::track_loops;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Per-class gated optimal assignment (`eq:association_cost`).
    pub(super) fn associate(&mut self) -> Result<(), StepError> {
        self.locate_measurement_sensors();
        self.associator.associate(
            self.table.tracks(),
            &self.priors[..self.table.len()],
            &*self.validated,
            &self.accepted[..self.validated.len()],
            &self.measurement_sensors[..self.validated.len()],
            &self.config,
            &mut self.track_to_measurement[..],
        )?;
        Ok(())
    }

    /// The expected reflection of track `i`'s object for a measurement of `sensor` (a point
    /// class: none).
    pub(super) fn expected_reflection(&self, i: usize, sensor: &MeasurementSensor) -> ExpectedReflection {
        let class = self.table.tracks()[i].class;
        let models = &self.models[class.index()];
        match models.extent {
            Some(_) => {
                let prior = &self.priors[i];
                models.expected_reflection(&prior.object_prior(), sensor.position_m, sensor.reflection_scale)
            }
            None => ExpectedReflection::POINT,
        }
    }

    /// Each assigned track's measurement, its radar's position and the expected reflection
    /// there; a track whose measurement does not read back is left unassigned.
    fn read_assignment(&mut self) {
        for i in 0..self.table.len() {
            // An accepted measurement always reads back; if one did not, the track coasts rather
            // than keep a stale state.
            self.assigned_measurements[i] =
                self.track_to_measurement[i].and_then(|index| self.validated.accepted(usize::from(index)));
            let (Some(index), Some(measurement)) =
                (self.track_to_measurement[i], self.assigned_measurements[i])
            else {
                self.track_to_measurement[i] = None;
                continue;
            };
            let sensor = self.measurement_sensors[usize::from(index)];
            self.assigned_sensors[i] = sensor;
            // Gating computed it already, for the same prior and sensor.
            let reflection = self
                .associator
                .assigned_reflection(i)
                .unwrap_or_else(|| self.expected_reflection(i, &sensor));
            self.assigned_reflections[i] = reflection;
            let models = &self.models[measurement.class.index()];
            if !sensor.mounted && (models.radial_velocity_update.enabled || models.extent.is_some()) {
                self.last_step.counts.updates_from_unknown_sensor += 1;
            }
        }
    }

    /// Scales track `i`'s velocities back onto its class's highest speed over ground, in a step
    /// with an ego pose (without one, the velocities are relative to an ego whose motion is
    /// unknown, and any speed is possible).
    fn bound_speed(&mut self, i: usize, class: ObjectClass) {
        let max_speed_mps = self.config.classes.get(class).max_speed_mps;
        if bound_speed(max_speed_mps, self.step_pose.is_some(), &mut self.table.tracks_mut()[i].estimate) {
            self.last_step.counts.speeds_bounded += 1;
        }
    }

    /// Kalman and mode-probability update of every assigned track.
    pub(super) fn update(&mut self, t: f64) {
        let count = self.table.len();
        for (was_confirmed, track) in self.was_confirmed.iter_mut().zip(self.table.tracks()) {
            *was_confirmed = track.status.is_confirmed();
        }
        self.read_assignment();
        track_loops::update(
            super::step_imms(self.step_pose.is_some(), &self.imms, &self.compensated_imms),
            &self.models,
            self.table.tracks_mut(),
            &self.priors[..count],
            &self.assigned_measurements[..count],
            &self.assigned_sensors[..count],
            &self.assigned_reflections[..count],
            // Radial velocities are over ground: they measure the velocity of world-frame
            // tracks, not of vehicle-frame tracks of an ego whose motion is unknown.
            self.step_pose.is_some(),
            &mut self.update_outcomes[..count],
        );
        for i in 0..count {
            let (Some(index), Some(measurement)) =
                (self.track_to_measurement[i], self.assigned_measurements[i])
            else {
                continue;
            };
            if let Ok(radial_velocity) = self.update_outcomes[i] {
                match radial_velocity {
                    Some(RadialVelocityOutcome::Applied) => {
                        self.last_step.counts.radial_velocity_updates += 1
                    }
                    Some(RadialVelocityOutcome::Gated) => {
                        self.last_step.counts.radial_velocity_updates_gated += 1
                    }
                    Some(RadialVelocityOutcome::NoLineOfSight) | None => {}
                }
                let class = self.table.tracks()[i].class;
                self.bound_speed(i, class);
                let sensor = self.assigned_sensors[i];
                let (detection, clutter) = self.detection_and_clutter(class, usize::from(sensor.slot));
                let reflection = self.assigned_reflections[i];
                let prior = &self.priors[i].fused;
                let innovation_m = measurement.position() - reflection.offset_m - prior.mean;
                let innovation_covariance_m2 = prior.covariance
                    + covariance(&self.config.classes.get(class).measurement_noise_covariance_m2)
                    + reflection.covariance_m2
                    + sensor.noise_m2;
                let likelihood = existence::gaussian_density_per_m2(innovation_m, innovation_covariance_m2);
                self.learn_reflection(
                    i,
                    &sensor,
                    innovation_m,
                    0.5 * (innovation_covariance_m2.x_axis.x + innovation_covariance_m2.y_axis.y),
                );
                self.learn_platform(i, &measurement, &sensor);
                let tracker = &self.config.tracker;
                let track = &mut self.table.tracks_mut()[i];
                track.existence_probability = existence::updated_existence(
                    track.existence_probability,
                    Evidence::Detected { likelihood_per_m2: likelihood },
                    detection,
                    clutter,
                );
                track.record_hit(&measurement, self.assigned_sensors[i].position_m, t);
                if track.status == TrackStatus::Tentative && confirms(track, tracker) {
                    track.status = TrackStatus::Confirmed;
                    self.last_step.counts.tracks_confirmed += 1;
                }
                self.last_step.counts.tracks_updated += 1;
                self.fates[usize::from(index)] = MeasurementFate::Assigned;
            } else {
                // Numerically unusable: the track coasts and the measurement is free to start a
                // track of its own.
                self.last_step.counts.update_failures += 1;
                self.track_to_measurement[i] = None;
            }
        }
    }

    /// Tracks without a measurement keep their priors, and lose existence if a sensor of the
    /// frame had them in view (a confirmed one then coasts); every existing track's frame
    /// record.
    pub(super) fn coast(&mut self) {
        for i in 0..self.table.len() {
            let measurement_index = self.track_to_measurement[i];
            if measurement_index.is_none() {
                let track = &self.table.tracks()[i];
                let mut existence_probability = track.existence_probability;
                let mut missed = false;
                let prior_m = self.priors[i].fused.mean;
                for sensor in self.scanning_sensors.iter().filter(|s| s.field_of_view.contains(prior_m)) {
                    let (detection, clutter) = self.missed_detection_and_clutter(track.class, sensor.slot);
                    existence_probability = existence::updated_existence(
                        existence_probability,
                        Evidence::MissedInView,
                        detection,
                        clutter,
                    );
                    missed = true;
                }
                if self.unknown_sensor_view.is_some_and(|view| view.contains(prior_m)) {
                    let (detection, clutter) = self.missed_detection_and_clutter(track.class, UNMOUNTED);
                    existence_probability = existence::updated_existence(
                        existence_probability,
                        Evidence::MissedInView,
                        detection,
                        clutter,
                    );
                    missed = true;
                }
                self.last_step.counts.tracks_missed_in_view += u64::from(missed);
                let track = &mut self.table.tracks_mut()[i];
                track.estimate = self.imms[track.class.index()].coast(&self.priors[i]);
                track.record_miss();
                track.existence_probability = existence_probability;
                if missed && track.status == TrackStatus::Confirmed {
                    track.status = TrackStatus::Coasting;
                }
            }
            let track = &mut self.table.tracks_mut()[i];
            track.age_frames = track.age_frames.saturating_add(1);
            self.rows[i] = RowRecord {
                prior_position_m: Some(self.priors[i].fused.mean),
                available: self.priors[i].available,
                measurement_index,
            };
        }
    }
}

/// Scales `estimate`'s velocities back onto `max_speed_mps` (the class's
/// `classes.<class>.max_speed_mps`) in a step with an ego pose (`posed`); whether any was.
pub(super) fn bound_speed(max_speed_mps: Option<f64>, posed: bool, estimate: &mut ImmState) -> bool {
    match max_speed_mps {
        Some(max_speed_mps) if posed => estimate.bound_speed(max_speed_mps),
        _ => false,
    }
}
