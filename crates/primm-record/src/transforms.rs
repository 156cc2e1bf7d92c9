//! `FrameTransforms` of a measurement frame: world → vehicle from the frame's ego pose (when it
//! carries one) and vehicle → `radar_<id>` for every configured sensor mount.

use crate::scene::{timestamp, yaw_quaternion, VEHICLE_FRAME, WORLD_FRAME};
use foxglove::schemas::{FrameTransform, FrameTransforms, Vector3};
use primm_core::pose::SensorMount;
use primm_wire::MeasurementFrame;

/// Where a radar sits on the vehicle (the part of a configured `SensorMount` drawn here).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadarPose {
    /// The sensor id.
    pub id: u16,
    /// Longitudinal position, m.
    pub x_m: f64,
    /// Lateral position (left positive), m.
    pub y_m: f64,
    /// Boresight heading, rad, counter-clockwise from the vehicle's x axis.
    pub yaw_rad: f64,
}

impl From<&SensorMount> for RadarPose {
    fn from(mount: &SensorMount) -> Self {
        Self { id: mount.id, x_m: mount.x_m, y_m: mount.y_m, yaw_rad: mount.yaw_rad }
    }
}

/// The frame name of sensor `id`.
pub fn sensor_frame(id: u16) -> String {
    format!("radar_{id}")
}

/// The transforms at `log_time_ns`; `None` when there is none (no ego pose, no mount).
pub fn frame_transforms(
    frame: &MeasurementFrame,
    sensors: &[RadarPose],
    log_time_ns: u64,
) -> Option<FrameTransforms> {
    let time = Some(timestamp(log_time_ns));
    let mut transforms = Vec::with_capacity(1 + sensors.len());
    if let Some((x, y, yaw)) = frame.ego_pose() {
        if [x, y, yaw].iter().all(|v| v.is_finite()) {
            transforms.push(FrameTransform {
                timestamp: time,
                parent_frame_id: WORLD_FRAME.to_owned(),
                child_frame_id: VEHICLE_FRAME.to_owned(),
                translation: Some(Vector3 { x, y, z: 0.0 }),
                rotation: Some(yaw_quaternion(yaw)),
            });
        }
    }
    transforms.extend(sensors.iter().map(|mount| FrameTransform {
        timestamp: time,
        parent_frame_id: VEHICLE_FRAME.to_owned(),
        child_frame_id: sensor_frame(mount.id),
        translation: Some(Vector3 { x: mount.x_m, y: mount.y_m, z: 0.0 }),
        rotation: Some(yaw_quaternion(mount.yaw_rad)),
    }));
    (!transforms.is_empty()).then_some(FrameTransforms { transforms })
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_wire::FRAME_FLAG_EGO_VALID;

    #[test]
    fn the_ego_pose_places_the_vehicle_and_each_mount_a_radar() {
        let mut frame = MeasurementFrame::boxed_zeroed();
        assert!(frame_transforms(&frame, &[], 0).is_none());
        (frame.ego_x_m, frame.ego_y_m, frame.ego_yaw_rad, frame.flags) =
            (3.0, 4.0, 0.5, FRAME_FLAG_EGO_VALID);
        let mount = RadarPose { id: 2, x_m: 3.6, y_m: 0.0, yaw_rad: 0.0 };
        let transforms = frame_transforms(&frame, &[mount], 0).unwrap().transforms;
        assert_eq!(transforms.len(), 2);
        assert_eq!(
            (transforms[0].parent_frame_id.as_str(), transforms[0].child_frame_id.as_str()),
            ("world", "vehicle")
        );
        assert_eq!(transforms[1].child_frame_id, "radar_2");
        assert_eq!(transforms[0].translation.unwrap().x, 3.0);
    }
}
