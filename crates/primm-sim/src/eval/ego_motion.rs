//! What the ego vehicle was doing when a measurement was taken: driving straight or turning.
//!
//! A frame's ego yaw rate is the change of the recorded ego heading over a window of
//! ±[`YAW_RATE_HALF_WINDOW_S`] around it (the frames nearest to its ends, within the
//! sequence), divided by the time between them. A frame turns when the magnitude exceeds
//! [`TURNING_YAW_RATE_RADPS`]. Frames without an ego pose (or with no other posed frame in
//! reach) have no label, and neither do the measurements taken in them.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::record::AssociationRecord;
use crate::io::Sequence;

/// Smallest ego yaw rate magnitude of a turning frame, rad/s.
pub const TURNING_YAW_RATE_RADPS: f64 = 0.1;

/// Half the time window over which the ego yaw rate is measured, s.
pub const YAW_RATE_HALF_WINDOW_S: f64 = 0.05;

/// The ego vehicle's motion in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EgoMotion {
    /// |yaw rate| at most [`TURNING_YAW_RATE_RADPS`].
    Straight,
    /// |yaw rate| above [`TURNING_YAW_RATE_RADPS`].
    Turning,
}

impl EgoMotion {
    /// Both states, in table order.
    pub const ALL: [EgoMotion; 2] = [EgoMotion::Straight, EgoMotion::Turning];

    /// The label in tables.
    pub fn label(self) -> &'static str {
        match self {
            EgoMotion::Straight => "Ego straight",
            EgoMotion::Turning => "Ego turning",
        }
    }
}

/// The ego yaw rate of every frame of `sequence` that has one (see the module documentation),
/// by frame index, rad/s.
pub fn ego_yaw_rates(sequence: &Sequence) -> BTreeMap<u64, f64> {
    let posed: Vec<(u64, f64, f64)> = sequence
        .frames
        .iter()
        .filter_map(|frame| frame.ego_pose.map(|pose| (frame.index, frame.timestamp_s, pose.yaw_rad)))
        .collect();
    let mut rates = BTreeMap::new();
    for (i, &(index, t, _)) in posed.iter().enumerate() {
        // The posed frames nearest to t − window and t + window, clamped to the sequence.
        let before = posed[..=i].iter().rev().find(|(_, other, _)| *other <= t - YAW_RATE_HALF_WINDOW_S);
        let after = posed[i..].iter().find(|(_, other, _)| *other >= t + YAW_RATE_HALF_WINDOW_S);
        let (first, last) = (before.unwrap_or(&posed[0]), after.unwrap_or(&posed[posed.len() - 1]));
        let dt = last.1 - first.1;
        if dt > 0.0 {
            rates.insert(index, wrap_angle(last.2 - first.2) / dt);
        }
    }
    rates
}

/// The ego motion of each record's frame, aligned with `records` (`None`: unknown).
pub fn ego_motion_labels(sequence: &Sequence, records: &[AssociationRecord]) -> Vec<Option<EgoMotion>> {
    let rates = ego_yaw_rates(sequence);
    records
        .iter()
        .map(|record| {
            rates.get(&record.frame).map(|rate| {
                if rate.abs() > TURNING_YAW_RATE_RADPS {
                    EgoMotion::Turning
                } else {
                    EgoMotion::Straight
                }
            })
        })
        .collect()
}

/// `angle` wrapped into (−π, π], rad.
fn wrap_angle(angle: f64) -> f64 {
    let wrapped = angle.rem_euclid(std::f64::consts::TAU);
    if wrapped > std::f64::consts::PI {
        wrapped - std::f64::consts::TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{EgoPose, RecordedFrame};

    fn sequence(yaw_rate_radps: impl Fn(f64) -> f64) -> Sequence {
        let mut sequence = Sequence::default();
        let mut yaw = 3.0; // near π, so that the heading wraps
        for index in 0..200u64 {
            let t = index as f64 * 0.015;
            let mut frame = RecordedFrame::new(index, t);
            frame.ego_pose = Some(EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: wrap_angle(yaw) });
            yaw += yaw_rate_radps(t) * 0.015;
            sequence.frames.push(frame);
        }
        sequence
    }

    #[test]
    fn the_yaw_rate_is_measured_across_the_heading_wrap() {
        let rates = ego_yaw_rates(&sequence(|_| 0.4));
        assert_eq!(rates.len(), 200);
        assert!(rates.values().all(|rate| (rate - 0.4).abs() < 1e-9), "{rates:?}");
    }

    #[test]
    fn frames_are_labelled_straight_or_turning_by_their_yaw_rate() {
        let sequence = sequence(|t| if t < 1.5 { 0.0 } else { -0.3 });
        let records: Vec<AssociationRecord> = [10u64, 190]
            .iter()
            .map(|&frame| AssociationRecord {
                frame,
                timestamp_s: 0.0,
                ground_truth_id: Some(1),
                class: primm_core::measurement::ObjectClass::Car,
                measured: glam::DVec2::ZERO,
                true_position: None,
                true_velocity: None,
                origin: None,
                track_id: None,
                prior: None,
                velocity: None,
                mode_probabilities: None,
                track_confirmed: Some(false),
            })
            .collect();
        assert_eq!(
            ego_motion_labels(&sequence, &records),
            [Some(EgoMotion::Straight), Some(EgoMotion::Turning)]
        );
        assert_eq!(ego_motion_labels(&Sequence::default(), &records), [None, None]);
    }
}
