//! Ground-truth object frames in which data association is ambiguous: the *Close Proximity* and
//! *Crossing Motion* rows of the scenario-wise tracking table (`tab:scenario_mot`).
//!
//! Both subsets depend on ground truth only, so they are identical for every method:
//!
//! * **Close proximity**: the nearest *other* ground-truth object in the same frame is at most
//!   [`InteractionRules::close_proximity_m`] (4 m) away.
//! * **Crossing motion**: some other ground-truth object in the same frame is at most
//!   [`InteractionRules::crossing_distance_m`] (8 m) away and the two headings differ by an angle
//!   within `[45°, 135°]` (both limits inclusive).
//!
//! Distances are between reference positions (true position when known, else the measurement).
//! The heading of a row is the direction from the previous row of the same object to this row;
//! it is undefined for an object's first row, after a time gap above
//! [`InteractionRules::max_heading_gap_s`], or when that step is slower than
//! [`InteractionRules::min_heading_speed_mps`]. A pair with an undefined heading is never
//! crossing. The heading difference is the smallest angle between the two directions, in
//! `[0°, 180°]`.
//!
//! How the identity metrics are restricted to a subset is described in
//! [`super::identity::identity_counts_subset`].

use std::collections::{BTreeMap, HashMap};

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::record::{time_order, AssociationRecord, EvalError};
use super::scenario::wrap_angle;

/// Thresholds of the interaction subsets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InteractionRules {
    /// Largest distance to the nearest other object for close proximity, metres.
    pub close_proximity_m: f64,
    /// Largest distance between two crossing objects, metres.
    pub crossing_distance_m: f64,
    /// Smallest heading difference of a crossing, degrees.
    pub crossing_min_heading_diff_deg: f64,
    /// Largest heading difference of a crossing, degrees.
    pub crossing_max_heading_diff_deg: f64,
    /// Largest time between the two positions that define a heading, seconds.
    pub max_heading_gap_s: f64,
    /// Smallest speed of the step that defines a heading, m/s.
    pub min_heading_speed_mps: f64,
}

impl Default for InteractionRules {
    fn default() -> Self {
        Self {
            close_proximity_m: 4.0,
            crossing_distance_m: 8.0,
            crossing_min_heading_diff_deg: 45.0,
            crossing_max_heading_diff_deg: 135.0,
            max_heading_gap_s: 1.0,
            min_heading_speed_mps: 0.5,
        }
    }
}

impl InteractionRules {
    /// Checks that the rules can be applied.
    pub fn validate(&self) -> Result<(), EvalError> {
        let values = [
            ("close_proximity_m", self.close_proximity_m),
            ("crossing_distance_m", self.crossing_distance_m),
            ("crossing_min_heading_diff_deg", self.crossing_min_heading_diff_deg),
            ("crossing_max_heading_diff_deg", self.crossing_max_heading_diff_deg),
            ("max_heading_gap_s", self.max_heading_gap_s),
            ("min_heading_speed_mps", self.min_heading_speed_mps),
        ];
        for (name, value) in values {
            if !value.is_finite() || value < 0.0 {
                return Err(EvalError::InvalidRules(format!(
                    "{name} must be finite and non-negative, got {value}"
                )));
            }
        }
        if self.crossing_min_heading_diff_deg > self.crossing_max_heading_diff_deg {
            return Err(EvalError::InvalidRules("crossing heading range is empty (min > max)".into()));
        }
        Ok(())
    }
}

/// Subset membership of one row.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct InteractionFlags {
    /// Row belongs to the close-proximity subset.
    pub close_proximity: bool,
    /// Row belongs to the crossing-motion subset.
    pub crossing: bool,
}

/// Subset flags of every row of one sequence (input order). Rows without a ground-truth id are
/// in neither subset.
pub fn interaction_flags(records: &[AssociationRecord], rules: &InteractionRules) -> Vec<InteractionFlags> {
    let headings = row_headings(records, rules);
    let mut by_frame: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    for (index, record) in records.iter().enumerate() {
        if record.ground_truth_id.is_some() {
            by_frame.entry(record.frame).or_default().push(index);
        }
    }
    let mut flags = vec![InteractionFlags::default(); records.len()];
    for rows in by_frame.values() {
        for &a in rows {
            let gt_a = records[a].ground_truth_id;
            let position_a = records[a].reference_position();
            let mut nearest = f64::INFINITY;
            let mut crossing = false;
            for &b in rows {
                if records[b].ground_truth_id == gt_a {
                    continue;
                }
                let distance = position_a.distance(records[b].reference_position());
                nearest = nearest.min(distance);
                if distance <= rules.crossing_distance_m {
                    if let (Some(ha), Some(hb)) = (headings[a], headings[b]) {
                        let difference = wrap_angle(ha - hb).abs().to_degrees();
                        crossing |= difference >= rules.crossing_min_heading_diff_deg
                            && difference <= rules.crossing_max_heading_diff_deg;
                    }
                }
            }
            flags[a] = InteractionFlags { close_proximity: nearest <= rules.close_proximity_m, crossing };
        }
    }
    flags
}

/// Heading (radians) of every row from the previous row of the same object, if defined.
fn row_headings(records: &[AssociationRecord], rules: &InteractionRules) -> Vec<Option<f64>> {
    let mut headings = vec![None; records.len()];
    let mut previous: HashMap<u64, (f64, DVec2)> = HashMap::new();
    for index in time_order(records) {
        let record = &records[index];
        let Some(gt) = record.ground_truth_id else {
            continue;
        };
        let position = record.reference_position();
        if let Some((time, last)) = previous.insert(gt, (record.timestamp_s, position)) {
            let dt = record.timestamp_s - time;
            let step = position - last;
            if dt > 0.0
                && dt <= rules.max_heading_gap_s
                && step.length() / dt >= rules.min_heading_speed_mps
                && step.length() > 0.0
            {
                headings[index] = Some(step.y.atan2(step.x));
            }
        }
    }
    headings
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::position_row;

    /// Two frames (0 and 1, 0.1 s apart) of two objects; object 1 moves along +x at 10 m/s from
    /// the origin, object 2 moves with heading `heading_deg` at 10 m/s and ends frame 1 at
    /// `offset` from object 1's frame-1 position. Returns the flags of the frame-1 rows
    /// (object 1, object 2).
    fn pair(heading_deg: f64, offset: DVec2) -> (InteractionFlags, InteractionFlags) {
        let p1_end = DVec2::new(1.0, 0.0);
        let direction = DVec2::new(heading_deg.to_radians().cos(), heading_deg.to_radians().sin());
        let p2_end = p1_end + offset;
        let records = vec![
            position_row(0, 0.0, 1, DVec2::ZERO),
            position_row(0, 0.0, 2, p2_end - direction),
            position_row(1, 0.1, 1, p1_end),
            position_row(1, 0.1, 2, p2_end),
        ];
        let flags = interaction_flags(&records, &InteractionRules::default());
        (flags[2], flags[3])
    }

    #[test]
    fn close_proximity_threshold() {
        // Parallel objects 3 m apart: close, not crossing (heading difference 0°).
        let (a, b) = pair(0.0, DVec2::new(0.0, 3.0));
        assert!(a.close_proximity && b.close_proximity);
        assert!(!a.crossing && !b.crossing);
        // 4 m exactly is still "within 4 m"; 4.5 m is not.
        assert!(pair(0.0, DVec2::new(0.0, 4.0)).0.close_proximity);
        assert!(!pair(0.0, DVec2::new(0.0, 4.5)).0.close_proximity);
    }

    #[test]
    fn crossing_needs_distance_and_heading_range() {
        // Perpendicular at 6 m: crossing, not close.
        let (a, b) = pair(90.0, DVec2::new(0.0, 6.0));
        assert!(a.crossing && b.crossing);
        assert!(!a.close_proximity);
        // Perpendicular at 9 m: too far.
        assert!(!pair(90.0, DVec2::new(0.0, 9.0)).0.crossing);
        // Head-on (180°) and parallel (0°) at 6 m: outside [45°, 135°].
        assert!(!pair(180.0, DVec2::new(0.0, 6.0)).0.crossing);
        assert!(!pair(0.0, DVec2::new(0.0, 6.0)).0.crossing);
        // Limits: 135° is inside, 150° and 30° are not; −60° (clockwise) is a 60° difference.
        assert!(pair(135.0, DVec2::new(0.0, 6.0)).0.crossing);
        assert!(!pair(150.0, DVec2::new(0.0, 6.0)).0.crossing);
        assert!(!pair(30.0, DVec2::new(0.0, 6.0)).0.crossing);
        assert!(pair(-60.0, DVec2::new(0.0, 6.0)).0.crossing);
    }

    #[test]
    fn first_rows_have_no_heading_and_own_rows_do_not_count() {
        // Frame 0 rows have no heading yet, so they cannot be crossing even though the objects
        // are perpendicular and close.
        let records = vec![
            position_row(0, 0.0, 1, DVec2::ZERO),
            position_row(0, 0.0, 2, DVec2::new(0.0, 2.0)),
            // A second measurement of object 1 in the same frame is not "another object".
            position_row(0, 0.0, 1, DVec2::new(0.5, 0.0)),
            position_row(0, 0.0, 3, DVec2::new(50.0, 0.0)),
        ];
        let flags = interaction_flags(&records, &InteractionRules::default());
        assert!(flags.iter().all(|flag| !flag.crossing));
        assert!(flags[0].close_proximity && flags[1].close_proximity && flags[2].close_proximity);
        assert!(!flags[3].close_proximity);
    }

    #[test]
    fn unlabelled_rows_are_ignored() {
        let mut unlabelled = position_row(0, 0.0, 9, DVec2::new(1.0, 0.0));
        unlabelled.ground_truth_id = None;
        let records = vec![position_row(0, 0.0, 1, DVec2::ZERO), unlabelled];
        let flags = interaction_flags(&records, &InteractionRules::default());
        assert_eq!(flags, vec![InteractionFlags::default(); 2]);
    }

    #[test]
    fn rules_validation() {
        assert!(InteractionRules::default().validate().is_ok());
        let empty = InteractionRules {
            crossing_min_heading_diff_deg: 100.0,
            crossing_max_heading_diff_deg: 50.0,
            ..InteractionRules::default()
        };
        assert!(empty.validate().is_err());
    }
}
