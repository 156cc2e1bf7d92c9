//! Metrics on confirmed tracks: the tracks a user of the published output sees.
//!
//! The paper's identity metrics ([`super::identity`]) count every row a track consumed,
//! tentative tracks included. The metrics here count only the rows of tracks that were confirmed
//! after that frame's update ([`AssociationRecord::track_confirmed`]), and treat measurements
//! without a ground-truth id (clutter) strictly:
//!
//! * a track whose first row (in time order, tentative or not) has no ground-truth id is *born of
//!   clutter*; every confirmed row of it is a false positive, even where it later takes
//!   measurements of a real object, so it never contributes to IDTP and never covers an object;
//! * identity counts use the confirmed rows of tracks not born of clutter as matches; the
//!   ground-truth object frames stay all rows with a ground-truth id, so an object that is only
//!   followed by a tentative track is missed (IDFN);
//! * a *false track* is a confirmed track born of clutter or whose confirmed frames are more than
//!   half on clutter alone (no row of the track in that frame has a ground-truth id); the rate
//!   divides their number by the sequences' time;
//! * a *fragmentation* is an interruption of an object's coverage by confirmed tracks (the MOT
//!   "Frag" count);
//! * *confirmed tracks per object frame*: the (frame, confirmed track) pairs with a row over the
//!   ground-truth object frames, 1 when every detected object is followed by one confirmed track
//!   and nothing else is; above 1 when objects are followed by several tracks or clutter by
//!   confirmed tracks;
//! * a track is *born of a ghost* when its first row is a multipath ghost (where the data say
//!   what produced each measurement, [`AssociationRecord::origin`]).
//!
//! Like the identity counts, everything is counted per object frame and track frame: an object
//! with several detections in one frame, or a track that took several, counts once.
//!
//! Counts of one sequence come from [`confirmed_track_counts`]; [`ConfirmedTrackCounts::merge`]
//! adds sequences. `docs/evaluation-metrics.md` defines every number exactly.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::identity::{identity_counts, IdentityCounts};
use super::record::{time_order, AssociationRecord};
use crate::io::MeasurementOrigin;

/// Counts on confirmed tracks of one or more sequences; they add up over sequences.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ConfirmedTrackCounts {
    /// Sequences counted.
    pub sequences: u64,
    /// Identity counts with the confirmed rows of tracks not born of clutter as matches:
    /// `gt_object_frames` are all rows with a ground-truth id, `estimated_object_frames` all rows
    /// of confirmed tracks (those born of clutter included, as false positives).
    pub identity: IdentityCounts,
    /// Tracks with at least one confirmed row.
    pub confirmed_tracks: u64,
    /// Confirmed tracks born of clutter or with more than half of their confirmed frames on
    /// clutter alone.
    pub false_tracks: u64,
    /// Confirmed tracks whose first row is a multipath ghost.
    #[serde(default)]
    pub ghost_born_tracks: u64,
    /// Rows whose origin (object, clutter, ghost) is known; without any, whether a track is born
    /// of a ghost is unknown.
    #[serde(default)]
    pub rows_with_origin: u64,
    /// Interruptions of the ground-truth objects' coverage by confirmed tracks.
    pub fragmentations: u64,
    /// Rows without a ground-truth id (clutter measurements).
    pub clutter_rows: u64,
    /// Rows without a ground-truth id that a confirmed track took.
    pub clutter_rows_in_confirmed_tracks: u64,
    /// Sum over sequences of the time from the first to the last row, s.
    pub duration_s: f64,
}

impl ConfirmedTrackCounts {
    /// Adds the counts of another sequence.
    pub fn merge(&mut self, other: &ConfirmedTrackCounts) {
        self.sequences += other.sequences;
        self.identity.merge(&other.identity);
        self.confirmed_tracks += other.confirmed_tracks;
        self.false_tracks += other.false_tracks;
        self.ghost_born_tracks += other.ghost_born_tracks;
        self.rows_with_origin += other.rows_with_origin;
        self.fragmentations += other.fragmentations;
        self.clutter_rows += other.clutter_rows;
        self.clutter_rows_in_confirmed_tracks += other.clutter_rows_in_confirmed_tracks;
        self.duration_s += other.duration_s;
    }

    /// IDF1 of the confirmed rows; `None` without ground-truth and estimated object frames.
    pub fn idf1(&self) -> Option<f64> {
        self.identity.idf1()
    }

    /// Confirmed tracks per ground-truth object frame: estimated over ground-truth object frames
    /// of the confirmed rows; `None` without ground-truth object frames.
    pub fn tracks_per_object_frame(&self) -> Option<f64> {
        let objects = self.identity.gt_object_frames;
        (objects > 0).then(|| self.identity.estimated_object_frames as f64 / objects as f64)
    }

    /// Share of the confirmed tracks born of a ghost; `None` without confirmed tracks or when no
    /// row says what produced it.
    pub fn ghost_born_share(&self) -> Option<f64> {
        (self.confirmed_tracks > 0 && self.rows_with_origin > 0)
            .then(|| self.ghost_born_tracks as f64 / self.confirmed_tracks as f64)
    }

    /// False tracks per minute of sequence time; `None` when the sequences last no time.
    pub fn false_tracks_per_minute(&self) -> Option<f64> {
        (self.duration_s > 0.0).then(|| self.false_tracks as f64 / (self.duration_s / 60.0))
    }

    /// The counts as the JSON object `primm eval` and `primm score` write under
    /// `confirmed_tracks`.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(super::document::ConfirmedTracksDocument::from(self))
            .expect("the confirmed-track document serialises")
    }
}

/// A row was taken by a track, but whether that track was confirmed is not recorded (e.g. an
/// association file without the `confirmed` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("frame {frame}: track {track_id} took a measurement, but whether it was confirmed is not recorded")]
pub struct UnknownTrackStatus {
    /// Index of the row.
    pub row: usize,
    /// Its frame.
    pub frame: u64,
    /// The track.
    pub track_id: u64,
}

/// The tracks of one sequence whose first row (in time order, ties in input order) has no
/// ground-truth id.
pub fn tracks_born_of_clutter(records: &[AssociationRecord]) -> BTreeSet<u64> {
    tracks_born_of(records, |first| first.ground_truth_id.is_none())
}

/// The tracks of one sequence whose first row (in time order, ties in input order) is a
/// multipath ghost.
pub fn tracks_born_of_ghosts(records: &[AssociationRecord]) -> BTreeSet<u64> {
    tracks_born_of(records, |first| first.origin == Some(MeasurementOrigin::Ghost))
}

/// The tracks whose first row (in time order, ties in input order) passes `test`.
fn tracks_born_of(records: &[AssociationRecord], test: impl Fn(&AssociationRecord) -> bool) -> BTreeSet<u64> {
    let mut first_row: BTreeMap<u64, usize> = BTreeMap::new();
    for index in time_order(records) {
        if let Some(track) = records[index].track_id {
            first_row.entry(track).or_insert(index);
        }
    }
    first_row.into_iter().filter(|(_, index)| test(&records[*index])).map(|(track, _)| track).collect()
}

/// The counts on confirmed tracks of one sequence.
///
/// Fails when a row with a track does not say whether that track was confirmed; a row without a
/// track is never a confirmed-track row, whatever its `track_confirmed`.
pub fn confirmed_track_counts(
    records: &[AssociationRecord],
) -> Result<ConfirmedTrackCounts, UnknownTrackStatus> {
    if let Some((row, record)) =
        records.iter().enumerate().find(|(_, r)| r.track_id.is_some() && r.track_confirmed.is_none())
    {
        return Err(UnknownTrackStatus { row, frame: record.frame, track_id: record.track_id.unwrap_or(0) });
    }
    let born_of_clutter = tracks_born_of_clutter(records);
    let from_clutter =
        |record: &AssociationRecord| record.track_id.is_some_and(|t| born_of_clutter.contains(&t));

    // Rows as the user sees them: the track is kept only where it counts as a match.
    let matched: Vec<AssociationRecord> = records
        .iter()
        .map(|record| {
            let mut row = *record;
            if !record.is_confirmed_track_frame() || from_clutter(record) {
                row.track_id = None;
            }
            row
        })
        .collect();
    let mut identity = identity_counts(&matched);
    let clutter_born_frames: BTreeSet<(u64, u64)> = records
        .iter()
        .filter(|r| r.is_confirmed_track_frame() && from_clutter(r))
        .filter_map(|r| r.track_id.map(|track| (r.frame, track)))
        .collect();
    identity.estimated_object_frames += clutter_born_frames.len() as u64;
    identity.idfp += clutter_born_frames.len() as u64;

    // Per confirmed track and frame: whether any of its rows there has a ground-truth id.
    let mut confirmed_frames: BTreeMap<(u64, u64), bool> = BTreeMap::new();
    for record in records.iter().filter(|r| r.is_confirmed_track_frame()) {
        if let Some(track) = record.track_id {
            *confirmed_frames.entry((track, record.frame)).or_default() |= record.ground_truth_id.is_some();
        }
    }
    // Per confirmed track: its confirmed frames and how many of them are on clutter alone.
    let mut confirmed_tracks: BTreeMap<u64, (u64, u64)> = BTreeMap::new();
    for ((track, _), real) in confirmed_frames {
        let entry = confirmed_tracks.entry(track).or_default();
        entry.0 += 1;
        entry.1 += u64::from(!real);
    }
    let false_tracks = confirmed_tracks
        .iter()
        .filter(|(track, (frames, clutter))| born_of_clutter.contains(track) || 2 * clutter > *frames)
        .count() as u64;
    let born_of_ghosts = tracks_born_of_ghosts(records);
    let ghost_born_tracks =
        confirmed_tracks.keys().filter(|track| born_of_ghosts.contains(track)).count() as u64;

    let clutter_rows = records.iter().filter(|r| r.ground_truth_id.is_none()).count() as u64;
    let clutter_rows_in_confirmed_tracks =
        records.iter().filter(|r| r.ground_truth_id.is_none() && r.is_confirmed_track_frame()).count() as u64;

    Ok(ConfirmedTrackCounts {
        sequences: 1,
        identity,
        confirmed_tracks: confirmed_tracks.len() as u64,
        false_tracks,
        ghost_born_tracks,
        rows_with_origin: records.iter().filter(|r| r.origin.is_some()).count() as u64,
        fragmentations: fragmentations(&matched),
        clutter_rows,
        clutter_rows_in_confirmed_tracks,
        duration_s: duration_s(records),
    })
}

/// Fragmentations of one sequence whose rows keep a track only where it covers its object.
///
/// Per ground-truth object and frame the object is *covered* when any of its rows in that frame
/// has a track. Over the object's frames in increasing order, each covered frame that follows
/// one or more uncovered frames, which in turn follow an earlier covered frame, is one
/// fragmentation. Frames without a row of the object do not count as uncovered.
fn fragmentations(matched: &[AssociationRecord]) -> u64 {
    let mut coverage: BTreeMap<u64, BTreeMap<u64, bool>> = BTreeMap::new();
    for record in matched {
        if let Some(gt) = record.ground_truth_id {
            *coverage.entry(gt).or_default().entry(record.frame).or_default() |= record.track_id.is_some();
        }
    }
    let mut count = 0;
    for frames in coverage.values() {
        let (mut covered_before, mut in_gap) = (false, false);
        for &covered in frames.values() {
            if covered {
                count += u64::from(covered_before && in_gap);
                covered_before = true;
                in_gap = false;
            } else if covered_before {
                in_gap = true;
            }
        }
    }
    count
}

/// Time from the earliest to the latest row, s (0 without rows or without finite times).
fn duration_s(records: &[AssociationRecord]) -> f64 {
    let times = records.iter().map(|r| r.timestamp_s).filter(|t| t.is_finite());
    let (first, last) =
        times.fold((f64::INFINITY, f64::NEG_INFINITY), |(first, last), t| (first.min(t), last.max(t)));
    if last > first {
        last - first
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row;
    use serde_json::json;

    /// A row of object `gt` (or clutter) taken by `track` (or no track), confirmed or not.
    fn row(frame: u64, gt: Option<u64>, track: Option<u64>, confirmed: bool) -> AssociationRecord {
        let mut row = identity_row(frame, gt, track);
        row.track_confirmed = Some(confirmed && track.is_some());
        row
    }

    #[test]
    fn a_track_confirmed_after_its_third_row_contributes_only_the_later_rows() {
        // Object 1 in frames 0..=5, all taken by track 7, confirmed from its third row on.
        let records: Vec<_> = (0..6).map(|frame| row(frame, Some(1), Some(7), frame >= 2)).collect();
        let counts = confirmed_track_counts(&records).unwrap();
        // GT frames stay all six rows; the two tentative rows are missed.
        assert_eq!(counts.identity.gt_object_frames, 6);
        assert_eq!(counts.identity.estimated_object_frames, 4);
        assert_eq!((counts.identity.idtp, counts.identity.idfp, counts.identity.idfn), (4, 0, 2));
        assert!((counts.idf1().unwrap() - 0.8).abs() < 1e-12);
        assert_eq!(counts.confirmed_tracks, 1);
        assert_eq!(counts.false_tracks, 0);
        // Uncovered at the start is no interruption.
        assert_eq!(counts.fragmentations, 0);
        // The paper's counts of the same rows take the tentative rows as well.
        assert_eq!(identity_counts(&records).idtp, 6);
    }

    #[test]
    fn a_clutter_born_track_is_a_false_positive_in_every_row_even_on_a_real_object() {
        // Track 9 starts on clutter in frame 0 (tentative), is confirmed in frame 1 on clutter,
        // then takes object 1's measurements in frames 2..=4. Track 5 follows object 2 throughout.
        let mut records = vec![
            row(0, None, Some(9), false),
            row(1, None, Some(9), true),
            row(2, Some(1), Some(9), true),
            row(3, Some(1), Some(9), true),
            row(4, Some(1), Some(9), true),
        ];
        records.extend((0..5).map(|frame| row(frame, Some(2), Some(5), true)));
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!(tracks_born_of_clutter(&records), BTreeSet::from([9]));
        // Estimated: 4 confirmed rows of track 9 + 5 of track 5. Only track 5's rows match.
        assert_eq!(counts.identity.estimated_object_frames, 9);
        assert_eq!(counts.identity.gt_object_frames, 8);
        assert_eq!((counts.identity.idtp, counts.identity.idfp, counts.identity.idfn), (5, 4, 3));
        // Track 9 is a false track although most of its confirmed rows are real.
        assert_eq!((counts.confirmed_tracks, counts.false_tracks), (2, 1));
        assert_eq!((counts.clutter_rows, counts.clutter_rows_in_confirmed_tracks), (2, 1));
        // Object 1 is never covered: no fragmentation, no switch.
        assert_eq!((counts.fragmentations, counts.identity.idsw), (0, 0));
        // The paper's counts would credit track 9 with object 1's three rows.
        assert_eq!(identity_counts(&records).idtp, 8);
    }

    #[test]
    fn a_gap_then_re_cover_counts_one_fragmentation() {
        // Object 1: covered, uncovered twice, covered again (same track) → one fragmentation.
        let covered = [true, true, false, false, true, true];
        let records: Vec<_> = covered
            .iter()
            .enumerate()
            .map(|(frame, &covered)| row(frame as u64, Some(1), covered.then_some(3), true))
            .collect();
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!(counts.fragmentations, 1);
        assert_eq!(counts.identity.idsw, 0);
    }

    #[test]
    fn only_interruptions_between_covered_frames_are_fragmentations() {
        // Object 1: uncovered, covered, uncovered, covered by another track, uncovered at the
        // end → one fragmentation (and one switch). A tentative track does not cover.
        // Object 2: covered by track 20, then by track 21 without a gap → no fragmentation.
        let records = vec![
            row(0, Some(1), None, false),
            row(1, Some(1), Some(10), true),
            row(2, Some(1), Some(12), false),
            row(3, Some(1), Some(11), true),
            row(4, Some(1), None, false),
            row(0, Some(2), Some(20), true),
            row(1, Some(2), Some(21), true),
        ];
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!(counts.fragmentations, 1);
        assert_eq!(counts.identity.idsw, 2);
    }

    #[test]
    fn a_frame_counts_as_covered_when_any_row_of_the_object_in_it_is_covered() {
        // Two measurements of object 1 in frame 1, one taken by the confirmed track: no gap.
        let records = vec![
            row(0, Some(1), Some(4), true),
            row(1, Some(1), None, false),
            row(1, Some(1), Some(4), true),
            row(2, Some(1), Some(4), true),
        ];
        assert_eq!(confirmed_track_counts(&records).unwrap().fragmentations, 0);
    }

    #[test]
    fn a_tentative_track_between_two_confirmed_ones_is_no_switch_but_the_second_confirmed_one_is() {
        // Object 1: confirmed track 1, then tentative track 2 twice, then track 2 confirmed.
        let records = vec![
            row(0, Some(1), Some(1), true),
            row(1, Some(1), Some(2), false),
            row(2, Some(1), Some(2), false),
            row(3, Some(1), Some(2), true),
        ];
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!(counts.identity.idsw, 1);
        assert_eq!(counts.fragmentations, 1);
        assert_eq!(identity_counts(&records).idsw, 1);
    }

    #[test]
    fn a_track_with_more_than_half_of_its_confirmed_rows_on_clutter_is_a_false_track() {
        // Track 1 starts on object 1 and then takes clutter: confirmed rows 1 real, 2 clutter.
        // Track 2 starts on object 2: confirmed rows 2 real, 2 clutter (exactly half): not false.
        let records = vec![
            row(0, Some(1), Some(1), true),
            row(1, None, Some(1), true),
            row(2, None, Some(1), true),
            row(0, Some(2), Some(2), true),
            row(1, Some(2), Some(2), true),
            row(2, None, Some(2), true),
            row(3, None, Some(2), true),
        ];
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!((counts.confirmed_tracks, counts.false_tracks), (2, 1));
        assert_eq!((counts.clutter_rows, counts.clutter_rows_in_confirmed_tracks), (4, 4));
        assert_eq!(counts.identity.idfp, 4);
    }

    #[test]
    fn a_clutter_born_track_that_is_never_confirmed_is_not_a_false_track() {
        let records =
            vec![row(0, None, Some(1), false), row(1, None, Some(1), false), row(1, None, None, false)];
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!((counts.confirmed_tracks, counts.false_tracks), (0, 0));
        assert_eq!((counts.clutter_rows, counts.clutter_rows_in_confirmed_tracks), (3, 0));
        assert_eq!(counts.identity.estimated_object_frames, 0);
        assert_eq!(counts.idf1(), None);
    }

    #[test]
    fn the_false_track_rate_divides_by_the_summed_sequence_time() {
        // Sequence A: one clutter-born confirmed track, rows from 0.0 s to 1.5 s (frames 0..=15).
        let a: Vec<_> = (0..16).map(|frame| row(frame, None, Some(1), frame > 0)).collect();
        // Sequence B: one real track over 0.0..=4.5 s.
        let b: Vec<_> = (0..46).map(|frame| row(frame, Some(1), Some(1), true)).collect();
        let mut total = confirmed_track_counts(&a).unwrap();
        total.merge(&confirmed_track_counts(&b).unwrap());
        assert_eq!(total.sequences, 2);
        assert!((total.duration_s - 6.0).abs() < 1e-9, "{}", total.duration_s);
        assert_eq!(total.false_tracks, 1);
        assert!((total.false_tracks_per_minute().unwrap() - 10.0).abs() < 1e-9);
        assert_eq!(ConfirmedTrackCounts::default().false_tracks_per_minute(), None);
        let json = total.to_json();
        assert_eq!(json["false_tracks"], json!(1));
        assert_eq!(json["tracks"], json!(2));
        assert!((json["false_tracks_per_minute"].as_f64().unwrap() - 10.0).abs() < 1e-9);
    }

    #[test]
    fn a_row_with_a_track_of_unknown_status_is_refused_and_one_without_a_track_is_not() {
        let mut records = vec![row(0, Some(1), None, false), row(1, Some(1), Some(2), true)];
        records[0].track_confirmed = None;
        assert!(confirmed_track_counts(&records).is_ok());
        records[1].track_confirmed = None;
        let error = confirmed_track_counts(&records).unwrap_err();
        assert_eq!(error, UnknownTrackStatus { row: 1, frame: 1, track_id: 2 });
        assert!(error.to_string().contains("not recorded"), "{error}");
    }

    #[test]
    fn several_detections_per_object_and_track_count_once_per_frame() {
        // Object 1 gives three detections per frame in frames 0..=3, all taken by track 1 once
        // it is confirmed (frame 1 on); a second confirmed track, 2, takes one of them in frames
        // 2 and 3 (a duplicate). A clutter detection in frame 3 is taken by track 1 too.
        let mut records = Vec::new();
        for frame in 0..4 {
            records.extend((0..3).map(|_| row(frame, Some(1), Some(1), frame >= 1)));
        }
        records.push(row(2, Some(1), Some(2), true));
        records.push(row(3, Some(1), Some(2), true));
        records.push(row(3, None, Some(1), true));
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!(counts.identity.gt_object_frames, 4);
        // Track 1 in frames 1..=3, track 2 in frames 2 and 3.
        assert_eq!(counts.identity.estimated_object_frames, 5);
        assert_eq!((counts.identity.idtp, counts.identity.idfp, counts.identity.idfn), (3, 2, 1));
        assert_eq!(counts.identity.idsw, 0, "track 1 still follows the object beside track 2");
        assert!((counts.tracks_per_object_frame().unwrap() - 1.25).abs() < 1e-12);
        assert_eq!((counts.confirmed_tracks, counts.false_tracks), (2, 0));
        assert_eq!((counts.clutter_rows, counts.clutter_rows_in_confirmed_tracks), (1, 1));
    }

    #[test]
    fn a_track_whose_first_row_is_a_ghost_is_born_of_a_ghost() {
        // Track 3 starts on a ghost and is confirmed; track 4 starts on clutter (not a ghost);
        // track 5 starts on object 1 and later takes a ghost; track 6 starts on a ghost but is
        // never confirmed.
        let ghost = |frame, track, confirmed| {
            let mut r = row(frame, None, Some(track), confirmed);
            r.origin = Some(MeasurementOrigin::Ghost);
            r
        };
        let mut clutter = row(0, None, Some(4), false);
        clutter.origin = Some(MeasurementOrigin::Clutter);
        let mut object = row(0, Some(1), Some(5), false);
        object.origin = Some(MeasurementOrigin::Object);
        let records = vec![
            ghost(0, 3, false),
            ghost(1, 3, true),
            clutter,
            row(1, None, Some(4), true),
            object,
            ghost(1, 5, true),
            ghost(0, 6, false),
        ];
        assert_eq!(tracks_born_of_ghosts(&records), BTreeSet::from([3, 6]));
        let counts = confirmed_track_counts(&records).unwrap();
        assert_eq!((counts.confirmed_tracks, counts.ghost_born_tracks), (3, 1));
        assert!((counts.ghost_born_share().unwrap() - 1.0 / 3.0).abs() < 1e-12);
        // Without any origin in the rows the share is unknown, not zero.
        let unknown: Vec<AssociationRecord> =
            records.iter().map(|r| AssociationRecord { origin: None, ..*r }).collect();
        assert_eq!(confirmed_track_counts(&unknown).unwrap().ghost_born_share(), None);
        let json = counts.to_json();
        assert_eq!(json["ghost_born_tracks"], json!(1));
        assert!((json["ghost_born_share"].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn an_empty_sequence_counts_one_sequence_of_no_time() {
        let counts = confirmed_track_counts(&[]).unwrap();
        assert_eq!(counts, ConfirmedTrackCounts { sequences: 1, ..ConfirmedTrackCounts::default() });
    }
}
