//! One object measurement from a group of detections.
//!
//! * **Position:** the mean of the detections. The detections of a vehicle lie on the faces it
//!   turns to the radar, so their mean lies between its centre and its outline, where the
//!   sensor's reflection model (`crate::sensor`) expects a detection.
//! * **Radial velocity:** the median. Wheel returns carry the micro-Doppler of the rolling
//!   wheels, anywhere between no motion and twice the body's; the body's returns are the
//!   majority, and a median ignores the minority however far off it is, where a mean or a
//!   least-squares rigid-body fit would follow it. Across one object the lines of sight differ
//!   by less than its width over its range, so the body's returns agree to within the
//!   radar's noise and the median of theirs is the body's.
//! * **Class:** the majority of the detections' labels; a tie goes to the class of the
//!   strongest detection (largest radar cross section). The tracker gives a group that a
//!   confirmed track owns that track's class instead (`crate::tracker`'s grouping).
//! * **Radar cross section:** the sum of the detections' powers, in dBsm.
//! * **Ground truth** (carried for evaluation only): the majority id.

use crate::math;
use crate::measurement::{Measurement, ObjectClass};

/// Summarises the detections `members` (indices into `detections`; at least one) into one
/// measurement. `scratch` holds at least `members.len()` values.
pub fn summarise(detections: &[Measurement], members: &[u16], scratch: &mut [f64]) -> Measurement {
    let first = detections[members[0] as usize];
    if members.len() == 1 {
        return first;
    }
    let count = members.len() as f64;
    let (mut x_m, mut y_m, mut power) = (0.0, 0.0, 0.0);
    let mut votes = [0usize; ObjectClass::COUNT];
    let mut strongest = first;
    for (slot, &index) in members.iter().enumerate() {
        let detection = &detections[index as usize];
        x_m += detection.x_m;
        y_m += detection.y_m;
        power += math::exp(0.1 * core::f64::consts::LN_10 * detection.rcs_dbsm);
        votes[detection.class.index()] += 1;
        if detection.rcs_dbsm > strongest.rcs_dbsm {
            strongest = *detection;
        }
        scratch[slot] = detection.radial_velocity_mps;
    }
    let most = votes.iter().copied().max().unwrap_or(0);
    let class = if votes[strongest.class.index()] == most {
        strongest.class
    } else {
        ObjectClass::ALL.into_iter().find(|class| votes[class.index()] == most).unwrap_or(first.class)
    };
    Measurement {
        x_m: x_m / count,
        y_m: y_m / count,
        radial_velocity_mps: median(&mut scratch[..members.len()]),
        rcs_dbsm: 10.0 * math::ln(power) / core::f64::consts::LN_10,
        class,
        sensor_id: first.sensor_id,
        ground_truth_id: majority_id(detections, members),
    }
}

/// The median of `values` (reordered), the mean of the middle two for an even count.
fn median(values: &mut [f64]) -> f64 {
    values.sort_unstable_by(f64::total_cmp);
    let middle = values.len() / 2;
    if values.len() % 2 == 1 {
        values[middle]
    } else {
        0.5 * (values[middle - 1] + values[middle])
    }
}

/// The ground-truth id most members carry (the first member's on a tie), `None` when none do.
fn majority_id(detections: &[Measurement], members: &[u16]) -> Option<u64> {
    let mut best: Option<(u64, usize)> = None;
    for &index in members {
        let Some(id) = detections[index as usize].ground_truth_id else { continue };
        let count =
            members.iter().filter(|&&other| detections[other as usize].ground_truth_id == Some(id)).count();
        if best.is_none_or(|(_, best_count)| count > best_count) {
            best = Some((id, count));
        }
    }
    best.map(|(id, _)| id)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn detection(x_m: f64, radial_velocity_mps: f64, class: ObjectClass, id: u64) -> Measurement {
        Measurement {
            x_m,
            y_m: 2.0,
            radial_velocity_mps,
            rcs_dbsm: 0.0,
            class,
            sensor_id: Some(3),
            ground_truth_id: Some(id),
        }
    }

    #[test]
    fn a_group_reads_the_mean_position_and_the_median_radial_velocity_past_a_wheel_return() {
        let detections = [
            detection(10.0, 8.0, ObjectClass::Car, 1),
            detection(11.0, 8.2, ObjectClass::Car, 1),
            detection(12.0, 15.5, ObjectClass::Car, 1),
            detection(13.0, 7.9, ObjectClass::Car, 1),
            detection(14.0, 8.1, ObjectClass::Car, 1),
        ];
        let mut scratch = [0.0; 8];
        let group = summarise(&detections, &[0, 1, 2, 3, 4], &mut scratch);
        assert_eq!(group.x_m, 12.0);
        assert_eq!(group.radial_velocity_mps, 8.1);
        assert_eq!(group.sensor_id, Some(3));
        // Five detections of 0 dBsm: 10·log10(5).
        assert!((group.rcs_dbsm - 6.9897).abs() < 1e-3);
    }

    #[test]
    fn a_flipped_label_is_outvoted_and_a_tie_goes_to_the_strongest_detection() {
        let mut detections = [
            detection(10.0, 1.0, ObjectClass::Car, 1),
            detection(11.0, 1.0, ObjectClass::Pedestrian, 1),
            detection(12.0, 1.0, ObjectClass::Car, 2),
        ];
        let mut scratch = [0.0; 3];
        let group = summarise(&detections, &[0, 1, 2], &mut scratch);
        assert_eq!(group.class, ObjectClass::Car);
        assert_eq!(group.ground_truth_id, Some(1));
        detections[1].rcs_dbsm = 10.0;
        let tie = summarise(&detections, &[0, 1], &mut scratch);
        assert_eq!(tie.class, ObjectClass::Pedestrian);
    }

    #[test]
    fn a_group_of_one_is_its_detection_unchanged() {
        let detections = [detection(10.0, 1.0, ObjectClass::Pedestrian, 4)];
        assert_eq!(summarise(&detections, &[0], &mut [0.0; 1]), detections[0]);
    }
}
