//! The detections of a `MeasurementFrame` as a Foxglove `SceneUpdate`, and the ground truth that
//! a frame may carry.
//!
//! Each detection is a sphere in the vehicle frame, coloured by class. Where the tracker's
//! answer to the frame says which detection each track took, a detection taken by a track is a
//! larger, solid sphere and one taken by none a smaller, faint one. Where the frame carries ground
//! truth (some detection has a ground-truth id), a detection without one is clutter (a false
//! detection or a multipath ghost) and is drawn as a cube instead.

use crate::scene::{class_look, delete_all, pose, timestamp, with_alpha, VEHICLE_FRAME};
use foxglove::schemas::{
    Color, CubePrimitive, KeyValuePair, SceneEntity, SceneUpdate, SpherePrimitive, Vector3,
};
use primm_wire::{MeasurementFrame, TrackFrame, TRACK_FLAG_LATE_FRAME, TRACK_FLAG_PREDICTED};

/// Diameter of a detection taken by a track, m.
const TAKEN_SIZE_M: f64 = 0.7;
/// Diameter of a detection no track took (or when unknown), m.
const FREE_SIZE_M: f64 = 0.4;
/// Diameter of a ground-truth marker, m.
const TRUTH_SIZE_M: f64 = 0.3;

/// Which detections of a frame its tracks took: `None` when the answer does not say (a late
/// frame, whose indices refer to another frame, or predicted tracks).
pub fn taken_detections(measurements: &MeasurementFrame, tracks: &TrackFrame) -> Option<Vec<bool>> {
    if tracks.flags & (TRACK_FLAG_LATE_FRAME | TRACK_FLAG_PREDICTED) != 0
        || tracks.input_sequence != measurements.sequence
    {
        return None;
    }
    let mut taken = vec![false; measurements.valid_measurements().map_or(0, <[_]>::len)];
    for index in tracks.valid_tracks().iter().filter_map(|track| track.measurement_index()) {
        if let Some(slot) = taken.get_mut(index) {
            *slot = true;
        }
    }
    Some(taken)
}

/// Whether the frame carries ground truth: some detection has a ground-truth id.
pub fn carries_truth(frame: &MeasurementFrame) -> bool {
    frame.valid_measurements().is_some_and(|measurements| measurements.iter().any(|m| m.gt_id >= 0))
}

/// The scene of `frame`'s detections at `log_time_ns`; `taken` from [`taken_detections`].
pub fn detection_scene(frame: &MeasurementFrame, taken: Option<&[bool]>, log_time_ns: u64) -> SceneUpdate {
    let measurements = frame.valid_measurements().unwrap_or(&[]);
    let truth = carries_truth(frame);
    let mut entity = SceneEntity {
        timestamp: Some(timestamp(log_time_ns)),
        frame_id: VEHICLE_FRAME.to_owned(),
        id: "detections".to_owned(),
        metadata: vec![
            KeyValuePair { key: "sequence".to_owned(), value: frame.sequence.to_string() },
            KeyValuePair { key: "detections".to_owned(), value: measurements.len().to_string() },
        ],
        ..Default::default()
    };
    for (index, measurement) in measurements.iter().enumerate() {
        let (_, color, _) = class_look(measurement.class_code);
        let was_taken = taken.and_then(|taken| taken.get(index).copied());
        let (size, alpha) = match was_taken {
            Some(true) => (TAKEN_SIZE_M, 1.0),
            Some(false) => (FREE_SIZE_M, 0.45),
            None => (FREE_SIZE_M, 0.9),
        };
        let at = Some(pose(measurement.x_m, measurement.y_m, 0.5 * size, 0.0));
        let dimensions = Some(Vector3 { x: size, y: size, z: size });
        let color = Some(with_alpha(color, alpha));
        if truth && measurement.gt_id < 0 {
            entity.cubes.push(CubePrimitive { pose: at, size: dimensions, color });
        } else {
            entity.spheres.push(SpherePrimitive { pose: at, size: dimensions, color });
        }
    }
    SceneUpdate { deletions: vec![delete_all(log_time_ns)], entities: vec![entity] }
}

/// The true object positions of `frame` (one marker per ground-truth id), or `None` when the
/// frame carries no true position.
pub fn ground_truth_scene(frame: &MeasurementFrame, log_time_ns: u64) -> Option<SceneUpdate> {
    let measurements = frame.valid_measurements()?;
    let mut seen: Vec<i64> = Vec::new();
    let mut entity = SceneEntity {
        timestamp: Some(timestamp(log_time_ns)),
        frame_id: VEHICLE_FRAME.to_owned(),
        id: "ground_truth".to_owned(),
        ..Default::default()
    };
    for measurement in measurements {
        let Some([x, y]) = measurement.true_position_m() else { continue };
        if measurement.gt_id >= 0 && seen.contains(&measurement.gt_id) {
            continue;
        }
        seen.push(measurement.gt_id);
        entity.spheres.push(SpherePrimitive {
            pose: Some(pose(x, y, 0.5 * TRUTH_SIZE_M, 0.0)),
            size: Some(Vector3 { x: TRUTH_SIZE_M, y: TRUTH_SIZE_M, z: TRUTH_SIZE_M }),
            color: Some(Color { r: 1.0, g: 1.0, b: 1.0, a: 0.9 }),
        });
    }
    if entity.spheres.is_empty() {
        return None;
    }
    Some(SceneUpdate { deletions: vec![delete_all(log_time_ns)], entities: vec![entity] })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raw::zeroed_box;

    fn frame_with(gt_ids: &[i64]) -> Box<MeasurementFrame> {
        let mut frame = MeasurementFrame::boxed_zeroed();
        frame.sequence = 3;
        frame.count = gt_ids.len() as u32;
        for (slot, &gt_id) in frame.measurements.iter_mut().zip(gt_ids) {
            slot.gt_id = gt_id;
            slot.x_m = 10.0;
        }
        frame
    }

    #[test]
    fn taken_detections_are_solid_free_ones_faint_and_clutter_is_a_cube() {
        let measurements = frame_with(&[4, -1, 5]);
        let mut tracks = zeroed_box::<TrackFrame>();
        tracks.input_sequence = 3;
        tracks.count = 1;
        tracks.tracks[0].measurement_index = 2;
        let taken = taken_detections(&measurements, &tracks).unwrap();
        assert_eq!(taken, [false, false, true]);
        let scene = detection_scene(&measurements, Some(&taken), 0);
        let entity = &scene.entities[0];
        assert_eq!((entity.spheres.len(), entity.cubes.len()), (2, 1));
        assert_eq!(entity.spheres[1].size.unwrap().x, TAKEN_SIZE_M);
        assert!(entity.spheres[0].color.unwrap().a < 1.0);
        tracks.flags = TRACK_FLAG_LATE_FRAME;
        assert_eq!(taken_detections(&measurements, &tracks), None);
    }

    #[test]
    fn without_ground_truth_no_detection_is_called_clutter() {
        let measurements = frame_with(&[-1, -1]);
        let scene = detection_scene(&measurements, None, 0);
        assert_eq!((scene.entities[0].spheres.len(), scene.entities[0].cubes.len()), (2, 0));
        assert!(ground_truth_scene(&measurements, 0).is_none());
    }
}
