//! Per-measurement evaluation rows and the identifiers of the compared methods.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::io::MeasurementOrigin;
use primm_core::measurement::ObjectClass;
use primm_core::readable_number::readable;
use primm_core::track::TrackStatus;

pub use primm_core::mode::Method;

/// One evaluation row: a single measurement, which the paper counts as one ground-truth object
/// frame, together with what one method did with it.
///
/// Rows of one sequence are passed together as a slice; rows of different sequences must never be
/// mixed, because ground-truth and track identifiers are only unique within a sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AssociationRecord {
    /// Frame index within the sequence; defines the time order of rows.
    pub frame: u64,
    /// Frame time, seconds.
    pub timestamp_s: f64,
    /// Ground-truth object identity; `None` for a measurement without an annotated object, which
    /// is neither a ground-truth object frame nor part of any scenario subset.
    pub ground_truth_id: Option<u64>,
    /// Object class of the measurement.
    pub class: ObjectClass,
    /// Measured position (vehicle frame, metres).
    pub measured: DVec2,
    /// True object position when the data source knows it (simulation); otherwise the measurement
    /// is the reference position.
    pub true_position: Option<DVec2>,
    /// True velocity over ground of the object in the vehicle frame's axes when the data source
    /// knows it (simulation), m/s.
    #[serde(default)]
    pub true_velocity: Option<DVec2>,
    /// What produced the measurement (object, clutter or multipath ghost), where the data
    /// source knows it; `None` when unknown.
    #[serde(default)]
    pub origin: Option<MeasurementOrigin>,
    /// Track that this measurement updated or started; `None` when no track took it.
    pub track_id: Option<u64>,
    /// The track's fused one-step prior position before this update (`eq:prior_fusion` for the
    /// IMM variants); `None` when the measurement started a track or was not used.
    pub prior: Option<DVec2>,
    /// The track's fused velocity estimate after this update, in the vehicle frame's axes, m/s
    /// (`TrackOutput::velocity_mps`); `None` when no track took the measurement or the source
    /// does not give it.
    #[serde(default)]
    pub velocity: Option<DVec2>,
    /// Posterior mode probabilities after the update, in PR, CV, CA, CT order
    /// (`eq:mode_update`); `None` for single-model methods and rows without an update. A mode the
    /// method does not have carries probability 0.
    pub mode_probabilities: Option<[f64; 4]>,
    /// Whether the track that took this measurement was confirmed after this frame's update,
    /// i.e. whether a user of the published (confirmed) tracks saw this update. `Some(false)`
    /// when a tentative track or no track took it; `None` when the source does not say (an
    /// association file without the `confirmed` column). See [`counts_as_confirmed`].
    #[serde(default)]
    pub track_confirmed: Option<bool>,
}

/// Whether a track of this status is published as confirmed: every status except
/// [`TrackStatus::Tentative`] (a confirmed track stays confirmed while it coasts).
pub fn counts_as_confirmed(status: TrackStatus) -> bool {
    !matches!(status, TrackStatus::Tentative)
}

impl AssociationRecord {
    /// The position the prior is scored against and scenario rules are computed from: the true
    /// position when known, else the measurement.
    pub fn reference_position(&self) -> DVec2 {
        self.true_position.unwrap_or(self.measured)
    }

    /// Whether a confirmed track took this measurement: a track id and `track_confirmed ==
    /// Some(true)`.
    pub fn is_confirmed_track_frame(&self) -> bool {
        self.track_id.is_some() && self.track_confirmed == Some(true)
    }
}

/// Errors of the evaluation library.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// A drop fraction outside `[0, 1]` (or not finite).
    #[error("drop fraction {} is not within [0, 1]", readable(.0))]
    InvalidDropFraction(f64),
    /// Scenario or interaction rules that cannot be applied.
    #[error("invalid rule parameters: {0}")]
    InvalidRules(String),
    /// A list whose length does not match the one a mask or flag set was built for.
    #[error("expected {expected} items, got {actual}")]
    LengthMismatch {
        /// Length the mask was built for.
        expected: usize,
        /// Length of the list it was applied to.
        actual: usize,
    },
    /// Drawing a figure failed.
    #[error("plot failed: {0}")]
    Plot(String),
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Encoding JSON failed.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// For each row of one sequence, whether it stands for its object frame in the metrics that are
/// computed row by row (prior RMSE, velocity errors, mode probabilities): the first row, in
/// input order, of its frame with its ground-truth id and track. With several detections of one
/// object in one frame taken by one track, the track's prior, velocity and mode probabilities
/// are those of one update, counted once. A row with neither a ground-truth id nor a track stands
/// for itself.
pub fn object_frame_rows(records: &[AssociationRecord]) -> Vec<bool> {
    first_rows(records, |r| {
        (r.ground_truth_id.is_some() || r.track_id.is_some()).then_some((
            r.frame,
            r.ground_truth_id,
            r.track_id,
        ))
    })
}

/// For each row of one sequence, whether it is the first row, in input order, of its frame with
/// its ground-truth id (`false` for rows without one): one per ground-truth object frame.
pub fn ground_truth_frame_rows(records: &[AssociationRecord]) -> Vec<bool> {
    let first = first_rows(records, |r| r.ground_truth_id.map(|gt| (r.frame, Some(gt), None)));
    first.into_iter().zip(records).map(|(first, r)| first && r.ground_truth_id.is_some()).collect()
}

/// The class each row of one sequence is scored under in the per-class metrics: for a row of a
/// ground-truth object the class most of that object's rows carry (on a tie the class of its
/// first row in input order), since a detection-level radar labels single detections wrongly now
/// and then; for a row without one its own class. With one label per object, every row keeps its
/// own.
pub fn object_classes(records: &[AssociationRecord]) -> Vec<ObjectClass> {
    // Per object: its classes with their row counts, in order of first appearance.
    let mut votes: std::collections::HashMap<u64, Vec<(ObjectClass, usize)>> =
        std::collections::HashMap::new();
    for record in records {
        if let Some(gt) = record.ground_truth_id {
            let classes = votes.entry(gt).or_default();
            match classes.iter_mut().find(|(class, _)| *class == record.class) {
                Some(entry) => entry.1 += 1,
                None => classes.push((record.class, 1)),
            }
        }
    }
    let majority: std::collections::HashMap<u64, ObjectClass> = votes
        .into_iter()
        .map(|(gt, classes)| {
            let mut best = classes[0];
            for &candidate in &classes[1..] {
                if candidate.1 > best.1 {
                    best = candidate;
                }
            }
            (gt, best.0)
        })
        .collect();
    records.iter().map(|r| r.ground_truth_id.map_or(r.class, |gt| majority[&gt])).collect()
}

/// Whether each row is the first with its key; rows without a key are always first.
fn first_rows(
    records: &[AssociationRecord],
    key: impl Fn(&AssociationRecord) -> Option<(u64, Option<u64>, Option<u64>)>,
) -> Vec<bool> {
    let mut seen = std::collections::HashSet::new();
    records.iter().map(|record| key(record).is_none_or(|key| seen.insert(key))).collect()
}

/// Row indices of one sequence in time order: sorted by frame, ties kept in input order.
pub(crate) fn time_order(records: &[AssociationRecord]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..records.len()).collect();
    order.sort_by_key(|&index| records[index].frame);
    order
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;

    /// A row with a ground-truth id, an optional track and nothing else of interest.
    pub fn identity_row(frame: u64, gt: Option<u64>, track: Option<u64>) -> AssociationRecord {
        AssociationRecord {
            frame,
            timestamp_s: frame as f64 * 0.1,
            ground_truth_id: gt,
            class: ObjectClass::Car,
            measured: DVec2::ZERO,
            true_position: None,
            true_velocity: None,
            origin: None,
            track_id: track,
            prior: None,
            velocity: None,
            mode_probabilities: None,
            track_confirmed: Some(track.is_some()),
        }
    }

    /// A row of ground-truth object `gt` at a given time and reference position.
    pub fn position_row(frame: u64, time_s: f64, gt: u64, position: DVec2) -> AssociationRecord {
        AssociationRecord {
            frame,
            timestamp_s: time_s,
            ground_truth_id: Some(gt),
            class: ObjectClass::Car,
            measured: position,
            true_position: Some(position),
            true_velocity: None,
            origin: None,
            track_id: Some(gt),
            prior: None,
            velocity: None,
            mode_probabilities: None,
            track_confirmed: Some(true),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_keys_and_labels_round_trip() {
        for method in Method::ALL {
            assert_eq!(Method::parse(method.key()), Some(method));
            assert_eq!(Method::parse(method.label()), Some(method));
            let json = serde_json::to_string(&method).unwrap();
            assert_eq!(json, format!("\"{}\"", method.id()));
        }
        assert_eq!(Method::parse("pr-imm"), Some(Method::PrImm));
        assert_eq!(Method::parse("kalman"), None);
    }

    #[test]
    fn every_status_but_tentative_counts_as_confirmed() {
        assert!(!counts_as_confirmed(TrackStatus::Tentative));
        assert!(counts_as_confirmed(TrackStatus::Confirmed));
    }

    #[test]
    fn a_row_is_a_confirmed_track_frame_only_with_a_track_known_to_be_confirmed() {
        let mut row = test_support::identity_row(0, Some(1), Some(1));
        assert!(row.is_confirmed_track_frame());
        row.track_confirmed = None;
        assert!(!row.is_confirmed_track_frame());
        row.track_confirmed = Some(true);
        row.track_id = None;
        assert!(!row.is_confirmed_track_frame());
    }

    #[test]
    fn reference_position_prefers_truth() {
        let mut row = test_support::identity_row(0, Some(1), Some(1));
        row.measured = DVec2::new(1.0, 2.0);
        assert_eq!(row.reference_position(), DVec2::new(1.0, 2.0));
        row.true_position = Some(DVec2::new(3.0, 4.0));
        assert_eq!(row.reference_position(), DVec2::new(3.0, 4.0));
    }

    #[test]
    fn one_row_stands_for_each_object_frame_and_track() {
        let rows = [
            test_support::identity_row(0, Some(1), Some(7)),
            test_support::identity_row(0, Some(1), Some(7)),
            test_support::identity_row(0, Some(1), Some(8)),
            test_support::identity_row(0, Some(1), None),
            test_support::identity_row(1, Some(1), Some(7)),
            test_support::identity_row(1, None, Some(7)),
            test_support::identity_row(1, None, Some(7)),
            test_support::identity_row(1, None, None),
            test_support::identity_row(1, None, None),
        ];
        assert_eq!(object_frame_rows(&rows), [true, false, true, true, true, true, false, true, true]);
        assert_eq!(
            ground_truth_frame_rows(&rows),
            [true, false, false, false, true, false, false, false, false]
        );
    }

    #[test]
    fn a_row_is_scored_under_its_objects_majority_class() {
        let labelled =
            |gt: Option<u64>, class| AssociationRecord { class, ..test_support::identity_row(0, gt, None) };
        let (car, pedestrian) = (ObjectClass::Car, ObjectClass::Pedestrian);
        let rows = [
            labelled(Some(1), car),
            labelled(Some(1), pedestrian),
            labelled(Some(1), car),
            labelled(Some(2), pedestrian),
            labelled(Some(2), car),
            labelled(None, pedestrian),
        ];
        // Object 1: two car labels against one; object 2: a tie, its first row's class; the
        // row without an object keeps its own label.
        assert_eq!(object_classes(&rows), [car, car, car, pedestrian, pedestrian, pedestrian]);
    }

    #[test]
    fn time_order_is_stable_by_frame() {
        let rows = [
            test_support::identity_row(3, Some(1), None),
            test_support::identity_row(1, Some(2), None),
            test_support::identity_row(3, Some(3), None),
            test_support::identity_row(0, Some(4), None),
        ];
        assert_eq!(time_order(&rows), vec![3, 1, 0, 2]);
    }
}
