//! Where the tracks and the sensors are: the tracking frame of each step (world or vehicle,
//! `crate::tracking_frame`), odometry resets, and the sensors' positions and fields of view in
//! the tracking frame.

use super::{ScanningSensor, Tracker};
use crate::coordinates::CoordinateFrame;
use crate::existence::FieldOfView;
use crate::measurement::FrameView;
use crate::measurement::ObjectClass;
use crate::pose::{EgoPose, RigidVelocity};
use crate::predictor::DisplacementPredictor;
use crate::sensor::UNMOUNTED;
use crate::sensor_noise::MeasurementSensor;
use glam::DVec2;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Decides the frame of this step from the frame's ego pose and the configuration, and
    /// moves the live tracks into it if they are in the other one: into the world frame with
    /// this frame's pose (the tracks' vehicle frame is taken as this frame's, which is off by
    /// the ego motion since the last frame), back into the vehicle frame of the last pose.
    /// Velocities change reference with the frame: a vehicle-frame track without poses has
    /// learned its object's velocity relative to the moving, turning ego, so entering the world
    /// frame adds the ego's motion over the gap (its mean velocity and yaw rate from the pose
    /// before the gap and this one, `v + ω × (p − p_ego)`), and leaving it subtracts the ego's
    /// latest motion (from its two latest poses).
    pub(super) fn enter_tracking_frame(&mut self, pose: Option<EgoPose>, dt_s: f64, t: f64) {
        let world = self.config.frame.tracking_frame == CoordinateFrame::World;
        self.step_pose = pose.filter(|_| world);
        self.follow_odometry_reset(dt_s);
        let step_frame =
            if self.step_pose.is_some() { CoordinateFrame::World } else { CoordinateFrame::Vehicle };
        self.last_step.tracking_frame = step_frame;
        if world && pose.is_none() {
            self.last_step.counts.frames_without_ego_pose += 1;
        }
        if step_frame == CoordinateFrame::World {
            self.last_step.counts.frames_in_world_frame += 1;
        }
        let motion_since_last = self.ego_motion_since_last_pose(t);
        if step_frame != self.tracks_frame && !self.table.is_empty() {
            // The ego's motion in world coordinates, added to the tracks where they are in the
            // world frame: after the move in, before the move out.
            let change = match (step_frame, self.step_pose, self.last_pose) {
                (CoordinateFrame::World, Some(pose), _) => {
                    Some((pose.vehicle_to_world(), motion_since_last, 1.0))
                }
                (CoordinateFrame::Vehicle, _, Some(last)) => {
                    Some((last.world_to_vehicle(), self.ego_motion.latest, -1.0))
                }
                _ => None,
            };
            if let Some((transform, ego, sign)) = change {
                let max_speed_mps = self.config.predictor.max_displacement_speed_mps;
                let entering = sign > 0.0;
                let add_ego = |track: &mut crate::track::Track| {
                    if let Some(ego) = &ego {
                        track.add_velocity_field(ego, sign, max_speed_mps);
                    }
                };
                for track in self.table.tracks_mut() {
                    if !entering {
                        add_ego(track);
                    }
                    track.transform(&transform);
                    if entering {
                        add_ego(track);
                    }
                }
                self.last_step.counts.tracking_frame_changes = 1;
            }
        }
        self.tracks_frame = step_frame;
        if self.step_pose.is_some() {
            self.last_pose = self.step_pose;
            self.ego_motion.pose_time_s = Some(t);
            if motion_since_last.is_some() {
                self.ego_motion.latest = motion_since_last;
            }
        }
    }

    /// The ego's motion from the last pose to this step's (over a gap: its mean), about this
    /// step's position; `None` without both poses, after an odometry reset, or where the poses
    /// imply a motion beyond the ego's limits (`tracker.max_ego_speed_mps`,
    /// `max_ego_yaw_rate_radps`).
    fn ego_motion_since_last_pose(&self, t: f64) -> Option<RigidVelocity> {
        let (Some(pose), Some(last), Some(last_s)) =
            (self.step_pose, self.last_pose, self.ego_motion.pose_time_s)
        else {
            return None;
        };
        if !(t > last_s) || self.last_step.odometry_reset() {
            return None;
        }
        let velocity_mps = (pose.position() - last.position()) / (t - last_s);
        let yaw_rate_radps = crate::math::wrap_angle(pose.yaw_rad - last.yaw_rad) / (t - last_s);
        let limits = &self.config.tracker;
        (velocity_mps.length() <= limits.max_ego_speed_mps
            && yaw_rate_radps.abs() <= limits.max_ego_yaw_rate_radps)
            .then_some(RigidVelocity { velocity_mps, yaw_rate_radps, centre_m: pose.position() })
    }

    /// Moves the live world-frame tracks across an odometry reset: when this frame's pose is
    /// further from the last one, or turned further, than `tracker.max_ego_speed_mps` and
    /// `tracker.max_ego_yaw_rate_radps` allow over `dt_s` (plus 1 m and 0.1 rad), the vehicle
    /// cannot have moved so; the world frame did. The tracks keep their place around the
    /// vehicle: into its frame with the last pose, back out with this one.
    pub(super) fn follow_odometry_reset(&mut self, dt_s: f64) {
        let (Some(pose), Some(last)) = (self.step_pose, self.last_pose) else { return };
        if self.tracks_frame != CoordinateFrame::World {
            return;
        }
        let tracker = &self.config.tracker;
        let moved_m = pose.position().distance(last.position());
        let turned_rad = crate::math::wrap_angle(pose.yaw_rad - last.yaw_rad).abs();
        let jumped = moved_m > tracker.max_ego_speed_mps * dt_s + 1.0
            || turned_rad > tracker.max_ego_yaw_rate_radps * dt_s + 0.1;
        if !jumped {
            return;
        }
        self.last_step.counts.odometry_resets = 1;
        let (to_vehicle, to_world) = (last.world_to_vehicle(), pose.vehicle_to_world());
        for track in self.table.tracks_mut() {
            track.transform(&to_vehicle);
            track.transform(&to_world);
        }
    }

    /// The sensors that scanned in this frame, as its measurements name them, with their fields
    /// of view in the tracking frame. A measurement without a sensor id or of a sensor without a
    /// configured mount marks the frame; such radars are taken to look where their detections lie
    /// (`unknown_sensor_view`).
    pub(super) fn find_scanning_sensors(&mut self) {
        self.scanning_sensors.clear();
        self.unknown_sensor_view = None;
        for index in 0..self.validated.len() {
            let Some(measurement) = self.validated.accepted(index) else { continue };
            let slot = self.sensors.slot(measurement.sensor_id);
            let Some(field_of_view) = self.sensors.get(slot).field_of_view(self.step_pose) else {
                self.last_step.counts.frames_with_unknown_sensor = 1;
                continue;
            };
            if self.scanning_sensors.iter().any(|sensor| sensor.slot == slot) {
                continue;
            }
            // There are at most MAX_SENSORS configured mounts, so this never overflows.
            let _ = self.scanning_sensors.try_push(ScanningSensor { slot, field_of_view });
        }
        if self.last_step.unknown_sensor() {
            self.unknown_sensor_view = self.unknown_sensor_view();
        }
    }

    /// Where the frame's radars without a configured mount looked: the sector their detections
    /// span, seen from the vehicle's reference point ([`FieldOfView::spanning`]).
    fn unknown_sensor_view(&self) -> Option<FieldOfView> {
        let frame = &self.config.frame;
        let unknown = (0..self.validated.len()).filter_map(|index| {
            let measurement = self.validated.accepted(index)?;
            (self.sensors.slot(measurement.sensor_id) == UNMOUNTED).then(|| measurement.position())
        });
        let origin_m = self.step_pose.map_or(DVec2::ZERO, |pose| pose.position());
        FieldOfView::spanning(
            origin_m,
            unknown,
            frame.unknown_sensor_margin_rad,
            frame.unknown_sensor_margin_m,
        )
    }

    /// Where the radar of every accepted measurement is, in the tracking frame, as its
    /// [`Sensor`](crate::sensor::Sensor) says: its mount (the vehicle's reference point without
    /// one), the detection's covariance from the radar's own noise, and the scale of its
    /// measurement model for the measurement's class.
    pub(super) fn locate_measurement_sensors(&mut self) {
        for index in 0..self.validated.len() {
            let Some(measurement) = self.validated.accepted(index) else { continue };
            let slot = self.sensors.slot(measurement.sensor_id);
            let sensor = self.sensors.get(slot);
            let position_m = sensor.position_m(self.step_pose);
            let mut noise_m2 =
                sensor.noise(self.step_pose).covariance_m2(measurement.position() - position_m);
            let extent = &self.config.classes.get(measurement.class).extent;
            // A group moved to its object's centre is a measurement of the centre: the mean of
            // its detections, each with the radar's noise and scattered over the contour.
            let centre_spread_m2 = if self.grouped_frame { self.group_centre_spread[index] } else { None };
            if let Some(spread_m2) = centre_spread_m2 {
                let count = self.frame_groups.members(index).len();
                let scale = self.config.frame.grouping.group_noise_scale;
                noise_m2 = crate::grouping::contour::group_noise_m2(noise_m2, spread_m2, count, scale);
            }
            self.measurement_sensors[index] = MeasurementSensor {
                position_m,
                mounted: sensor.mount.is_some(),
                noise_m2,
                slot: slot as u8,
                reflection_scale: if centre_spread_m2.is_some() {
                    0.0
                } else {
                    sensor.reflection_scale(measurement.class, extent)
                },
            };
        }
    }

    /// The detection probability and clutter density of `class` for the sensor in `slot`.
    pub(super) fn detection_and_clutter(&self, class: ObjectClass, slot: usize) -> (f64, f64) {
        self.sensors.get(slot).detection_and_clutter(class)
    }

    /// The same for a scan in which the sensor missed a track: while the radar groups its
    /// detections, the detection probability is scaled by the grouping's
    /// `detection_probability_factor` (a group misses its object only when every one of its
    /// detections does, so a scan without it says more of the object's absence). A detection
    /// keeps the configured probability, so that an echo seen scan after scan (a multipath
    /// ghost) is confirmed no faster than on an object radar.
    pub(super) fn missed_detection_and_clutter(&self, class: ObjectClass, slot: usize) -> (f64, f64) {
        let sensor = self.sensors.get(slot);
        let (detection, clutter) = sensor.detection_and_clutter(class);
        if sensor.groups_detections() {
            let factor = self.config.frame.grouping.detection_probability_factor;
            ((detection * factor).min(crate::sensor::MAX_DETECTION_PROBABILITY), clutter)
        } else {
            (detection, clutter)
        }
    }
}
