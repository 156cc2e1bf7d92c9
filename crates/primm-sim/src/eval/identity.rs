//! Identity metrics: ID switches (IDSW) and IDF1 (`eq:idf1`), as defined in the paper's
//! Section IV-A "Evaluation Metrics".
//!
//! A ground-truth object frame is a (frame, ground-truth id) pair with at least one row; an
//! estimated object frame is a (frame, track) pair with at least one row whose measurement the
//! track consumed. A ground-truth object and a track are *matched* in a frame when a row of that
//! frame carries both ids. An object seen with several detections in one frame is one object
//! frame, and a track that took several detections of one frame is one estimated object frame;
//! with one measurement per object and frame and one per track and frame, object frames are rows.
//!
//! * **IDSW**: for every ground-truth id, frames are visited in order while remembering the
//!   track most recently matched to it. A frame whose matched tracks do not include the
//!   remembered one adds one switch, to the track that took most of the object's rows in that
//!   frame (the earliest row's on a tie). Frames without a match leave the memory unchanged, so
//!   a gap followed by the same track is no switch, and returning to an older track after a
//!   switch is another one.
//! * **IDF1**: per sequence, an overlap matrix counts the frames in which each (ground truth,
//!   track) pair is matched. A one-to-one assignment between ground-truth ids and track ids that
//!   maximises the total overlap gives IDTP; IDFP is the number of estimated object frames minus
//!   IDTP and IDFN the number of ground-truth object frames minus IDTP. Counts are summed over
//!   sequences ([`IdentityCounts::merge`]) before `IDF1 = 2 IDTP / (2 IDTP + IDFP + IDFN)`.

use std::collections::{BTreeMap, BTreeSet};

use pathfinding::kuhn_munkres::kuhn_munkres;
use pathfinding::matrix::Matrix;
use serde::{Deserialize, Serialize};

use super::record::{time_order, AssociationRecord};

/// Identity counts of one or more sequences; they add up over sequences.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct IdentityCounts {
    /// (Frame, ground-truth id) pairs with a row.
    pub gt_object_frames: u64,
    /// (Frame, track) pairs with a row the track consumed.
    pub estimated_object_frames: u64,
    /// Overlap of the optimal one-to-one ground truth/track assignment.
    pub idtp: u64,
    /// `estimated_object_frames - idtp`.
    pub idfp: u64,
    /// `gt_object_frames - idtp`.
    pub idfn: u64,
    /// ID switches.
    pub idsw: u64,
}

impl IdentityCounts {
    /// Adds the counts of another sequence (or subset).
    pub fn merge(&mut self, other: &IdentityCounts) {
        self.gt_object_frames += other.gt_object_frames;
        self.estimated_object_frames += other.estimated_object_frames;
        self.idtp += other.idtp;
        self.idfp += other.idfp;
        self.idfn += other.idfn;
        self.idsw += other.idsw;
    }

    /// `IDF1 = 2 IDTP / (2 IDTP + IDFP + IDFN)` (`eq:idf1`); `None` when there is neither a
    /// ground-truth nor an estimated object frame.
    pub fn idf1(&self) -> Option<f64> {
        let denominator = 2 * self.idtp + self.idfp + self.idfn;
        (denominator > 0).then(|| 2.0 * self.idtp as f64 / denominator as f64)
    }
}

/// Indices of the rows of one sequence at which an ID switch happens, in time order: per switch,
/// the first row (in input order) of the frame's new track among the object's rows.
pub fn id_switch_rows(records: &[AssociationRecord]) -> Vec<usize> {
    // Per ground-truth object and frame, the matched rows in input order.
    let mut matches: BTreeMap<u64, BTreeMap<u64, Vec<usize>>> = BTreeMap::new();
    for index in time_order(records) {
        let record = &records[index];
        if let (Some(gt), Some(_)) = (record.ground_truth_id, record.track_id) {
            matches.entry(gt).or_default().entry(record.frame).or_default().push(index);
        }
    }
    let mut switches = Vec::new();
    for frames in matches.values() {
        let mut last_track: Option<u64> = None;
        for rows in frames.values() {
            // The frame's tracks with their row count and first row, in order of first row
            // (the rows of a frame are in input order).
            let mut tracks: Vec<(u64, usize, usize)> = Vec::new();
            for &index in rows {
                let track = records[index].track_id.expect("a matched row has a track");
                match tracks.iter_mut().find(|(t, _, _)| *t == track) {
                    Some(entry) => entry.1 += 1,
                    None => tracks.push((track, 1, index)),
                }
            }
            if tracks.iter().any(|(track, _, _)| Some(*track) == last_track) {
                continue;
            }
            // The track with most rows; the earliest on a tie.
            let mut best = tracks[0];
            for &candidate in &tracks[1..] {
                if candidate.1 > best.1 {
                    best = candidate;
                }
            }
            if last_track.is_some() {
                switches.push(best.2);
            }
            last_track = Some(best.0);
        }
    }
    switches.sort_by_key(|&index| (records[index].frame, index));
    switches
}

/// IDSW of one sequence.
pub fn id_switches(records: &[AssociationRecord]) -> u64 {
    id_switch_rows(records).len() as u64
}

/// All identity counts of one sequence.
pub fn identity_counts(records: &[AssociationRecord]) -> IdentityCounts {
    let everything = vec![true; records.len()];
    identity_counts_subset(records, &everything)
}

/// Identity counts of the rows of one sequence selected by `in_subset` (one flag per row).
///
/// * Switches are detected over the whole sequence, so the memory of the most recent track also
///   sees rows outside the subset; a switch counts when the row where it happens is selected.
/// * IDF1 counts use only the selected rows: the ground-truth and estimated object frames they
///   hold and an overlap matrix built from them.
///
/// # Panics
/// When `in_subset` does not have one flag per row.
pub fn identity_counts_subset(records: &[AssociationRecord], in_subset: &[bool]) -> IdentityCounts {
    assert_eq!(records.len(), in_subset.len(), "one subset flag per row is required");
    let mut counts = IdentityCounts::default();
    let mut object_frames: BTreeSet<(u64, u64)> = BTreeSet::new();
    let mut track_frames: BTreeSet<(u64, u64)> = BTreeSet::new();
    let mut matched_frames: BTreeSet<(u64, u64, u64)> = BTreeSet::new();
    for (record, _) in records.iter().zip(in_subset).filter(|(_, &selected)| selected) {
        if let Some(gt) = record.ground_truth_id {
            object_frames.insert((record.frame, gt));
        }
        if let Some(track) = record.track_id {
            track_frames.insert((record.frame, track));
        }
        if let (Some(gt), Some(track)) = (record.ground_truth_id, record.track_id) {
            matched_frames.insert((gt, track, record.frame));
        }
    }
    counts.gt_object_frames = object_frames.len() as u64;
    counts.estimated_object_frames = track_frames.len() as u64;
    let mut overlap: BTreeMap<(u64, u64), u64> = BTreeMap::new();
    for (gt, track, _) in matched_frames {
        *overlap.entry((gt, track)).or_insert(0) += 1;
    }
    counts.idtp = max_total_overlap(&overlap);
    counts.idfp = counts.estimated_object_frames - counts.idtp;
    counts.idfn = counts.gt_object_frames - counts.idtp;
    counts.idsw = id_switch_rows(records).into_iter().filter(|&index| in_subset[index]).count() as u64;
    counts
}

/// The largest total overlap of a one-to-one assignment between ground-truth ids and track ids.
///
/// `overlap` maps `(ground_truth_id, track_id)` to the number of rows in which the pair is
/// matched; missing pairs have overlap 0. The bipartite graph of non-zero entries is split into
/// connected components, which can be assigned independently, and each component is solved with
/// the Hungarian (Kuhn–Munkres) algorithm. Orienting each matrix so that it has no more rows than
/// columns is equivalent to padding the smaller side with zero-overlap dummies.
pub fn max_total_overlap(overlap: &BTreeMap<(u64, u64), u64>) -> u64 {
    let mut gt_index: BTreeMap<u64, usize> = BTreeMap::new();
    let mut track_index: BTreeMap<u64, usize> = BTreeMap::new();
    for &(gt, track) in overlap.keys() {
        let next = gt_index.len();
        gt_index.entry(gt).or_insert(next);
        let next = track_index.len();
        track_index.entry(track).or_insert(next);
    }
    // Union-find over ground-truth nodes [0, n_gt) and track nodes [n_gt, n_gt + n_track).
    let n_gt = gt_index.len();
    let mut parent: Vec<usize> = (0..n_gt + track_index.len()).collect();
    fn find(parent: &mut [usize], mut node: usize) -> usize {
        while parent[node] != node {
            parent[node] = parent[parent[node]];
            node = parent[node];
        }
        node
    }
    for (&(gt, track), &count) in overlap {
        if count == 0 {
            continue;
        }
        let a = find(&mut parent, gt_index[&gt]);
        let b = find(&mut parent, n_gt + track_index[&track]);
        parent[a] = b;
    }
    // Group the non-zero entries by component.
    let mut components: BTreeMap<usize, Vec<(u64, u64, u64)>> = BTreeMap::new();
    for (&(gt, track), &count) in overlap {
        if count > 0 {
            let root = find(&mut parent, gt_index[&gt]);
            components.entry(root).or_default().push((gt, track, count));
        }
    }
    components.values().map(|entries| component_optimum(entries)).sum()
}

/// Optimal assignment within one connected component of `(gt, track, overlap)` entries.
fn component_optimum(entries: &[(u64, u64, u64)]) -> u64 {
    if let [(_, _, count)] = entries {
        return *count;
    }
    let mut gts: BTreeMap<u64, usize> = BTreeMap::new();
    let mut tracks: BTreeMap<u64, usize> = BTreeMap::new();
    for &(gt, track, _) in entries {
        let next = gts.len();
        gts.entry(gt).or_insert(next);
        let next = tracks.len();
        tracks.entry(track).or_insert(next);
    }
    let transpose = gts.len() > tracks.len();
    let (rows, columns) = if transpose { (tracks.len(), gts.len()) } else { (gts.len(), tracks.len()) };
    let mut weights = Matrix::new(rows, columns, 0i64);
    for &(gt, track, count) in entries {
        let weight = i64::try_from(count).expect("overlap count fits in i64");
        let (row, column) = if transpose { (tracks[&track], gts[&gt]) } else { (gts[&gt], tracks[&track]) };
        weights[(row, column)] = weight;
    }
    let (total, _) = kuhn_munkres(&weights);
    u64::try_from(total).expect("sum of non-negative overlaps is non-negative")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::identity_row as row;

    #[test]
    fn idsw_with_gap_return_and_transfer() {
        // Object 1 over frames 0..=7 with tracks: 10, 10, –, 10, 11, –, 10, 10
        //   f3: gap then same track 10            → no switch
        //   f4: 10 → 11                           → switch #1
        //   f6: gap, then back to 10 (≠ last 11)  → switch #2
        //   f7: 10 again                          → no switch
        // Object 2 over frames 0..=2 with tracks 20, –, 11 → switch #3 at f2.
        // Unlabelled row with track 10 at frame 8 → ignored.
        let records = vec![
            row(0, Some(1), Some(10)),
            row(0, Some(2), Some(20)),
            row(1, Some(1), Some(10)),
            row(1, Some(2), None),
            row(2, Some(1), None),
            row(2, Some(2), Some(11)),
            row(3, Some(1), Some(10)),
            row(4, Some(1), Some(11)),
            row(5, Some(1), None),
            row(6, Some(1), Some(10)),
            row(7, Some(1), Some(10)),
            row(8, None, Some(10)),
        ];
        assert_eq!(id_switch_rows(&records), vec![5, 7, 9]);
        assert_eq!(id_switches(&records), 3);
    }

    #[test]
    fn idsw_follows_frames_not_input_order() {
        // Same object, frames given out of order: f0→7, f1→8, f2→7. Two switches.
        let records = vec![row(2, Some(1), Some(7)), row(0, Some(1), Some(7)), row(1, Some(1), Some(8))];
        assert_eq!(id_switches(&records), 2);
        // Index 2 (frame 1) and index 0 (frame 2), in time order.
        assert_eq!(id_switch_rows(&records), vec![2, 0]);
    }

    #[test]
    fn idf1_with_fragmented_track() {
        // Object 1 present in frames 0..=9 (10 GT frames):
        //   tracks 100 for f0..=5 (6 frames), none at f6, track 101 for f7..=9 (3 frames).
        // Object 2 present in frames 0..=3 (4 GT frames), all matched to track 200.
        // Track 101 also consumes an unlabelled measurement at frame 10 (estimated frame, no GT).
        // Overlap: (1,100)=6, (1,101)=3, (2,200)=4. Optimal one-to-one: (1,100)+(2,200) = 10.
        // GT frames = 14, estimated frames = 6 + 3 + 4 + 1 = 14.
        // IDTP = 10, IDFP = 14 - 10 = 4, IDFN = 14 - 10 = 4, IDF1 = 20 / (20 + 8) = 5/7.
        // IDSW: object 1 goes 100 → 101 once.
        let mut records = Vec::new();
        for frame in 0..10 {
            let track = match frame {
                0..=5 => Some(100),
                6 => None,
                _ => Some(101),
            };
            records.push(row(frame, Some(1), track));
        }
        for frame in 0..4 {
            records.push(row(frame, Some(2), Some(200)));
        }
        records.push(row(10, None, Some(101)));
        let counts = identity_counts(&records);
        assert_eq!(
            counts,
            IdentityCounts {
                gt_object_frames: 14,
                estimated_object_frames: 14,
                idtp: 10,
                idfp: 4,
                idfn: 4,
                idsw: 1,
            }
        );
        assert!((counts.idf1().unwrap() - 5.0 / 7.0).abs() < 1e-12);
    }

    #[test]
    fn assignment_is_one_to_one_not_greedy() {
        // Overlaps: (1,a)=5, (1,b)=4, (2,a)=4, (2,b)=0.
        // Greedy on the largest entry picks (1,a)=5 then nothing for 2 → 5.
        // Optimal: (1,b)+(2,a) = 8.
        let overlap = BTreeMap::from([((1, 10), 5), ((1, 11), 4), ((2, 10), 4)]);
        assert_eq!(max_total_overlap(&overlap), 8);
    }

    #[test]
    fn more_ground_truth_than_tracks_is_handled() {
        // Three objects compete for one track: best single overlap wins.
        let overlap = BTreeMap::from([((1, 10), 2), ((2, 10), 7), ((3, 10), 3)]);
        assert_eq!(max_total_overlap(&overlap), 7);
        assert_eq!(max_total_overlap(&BTreeMap::new()), 0);
    }

    #[test]
    fn merged_sequences_sum_counts_before_idf1() {
        // Sequence A: 2 GT frames, both matched to one track → IDTP 2, IDFP 0, IDFN 0.
        // Sequence B: 2 GT frames, none tracked              → IDTP 0, IDFP 0, IDFN 2.
        // Summed: IDF1 = 4 / (4 + 0 + 2) = 2/3 (mean of per-sequence IDF1 would be 0.5).
        let a = identity_counts(&[row(0, Some(1), Some(1)), row(1, Some(1), Some(1))]);
        let b = identity_counts(&[row(0, Some(1), None), row(1, Some(1), None)]);
        let mut total = a;
        total.merge(&b);
        assert_eq!(total.idtp, 2);
        assert_eq!(total.idfn, 2);
        assert!((total.idf1().unwrap() - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(IdentityCounts::default().idf1(), None);
    }

    #[test]
    fn subset_counts_events_and_overlap_inside_subset_only() {
        // Object 1: f0 track 5, f1 track 5, f2 track 6 (switch at row 2), f3 track 6.
        // Subset = rows 2 and 3. The switch row is selected → IDSW 1, although the earlier
        // track 5 lies outside the subset. Overlap inside the subset: (1,6)=2 → IDTP 2.
        let records = vec![
            row(0, Some(1), Some(5)),
            row(1, Some(1), Some(5)),
            row(2, Some(1), Some(6)),
            row(3, Some(1), Some(6)),
        ];
        let counts = identity_counts_subset(&records, &[false, false, true, true]);
        assert_eq!(counts.idsw, 1);
        assert_eq!(counts.gt_object_frames, 2);
        assert_eq!(counts.idtp, 2);
        assert_eq!(counts.idfn, 0);
        // Subset = rows 0 and 3: no switch row selected; the two rows use different tracks,
        // one-to-one assignment keeps one of them → IDTP 1, IDFP 1, IDFN 1.
        let counts = identity_counts_subset(&records, &[true, false, false, true]);
        assert_eq!((counts.idsw, counts.idtp, counts.idfp, counts.idfn), (0, 1, 1, 1));
    }

    #[test]
    fn several_detections_of_one_object_in_one_frame_are_one_object_frame() {
        // Object 1 in frames 0..=2 with three detections each, all taken by track 7; object 2
        // once in frame 1 with two detections, neither taken; a clutter detection in frame 2
        // taken by track 7 too.
        let mut records = Vec::new();
        for frame in 0..3 {
            records.extend((0..3).map(|_| row(frame, Some(1), Some(7))));
        }
        records.extend([row(1, Some(2), None), row(1, Some(2), None), row(2, None, Some(7))]);
        let counts = identity_counts(&records);
        assert_eq!(counts.gt_object_frames, 4, "three frames of object 1, one of object 2");
        assert_eq!(counts.estimated_object_frames, 3, "track 7 in three frames");
        assert_eq!((counts.idtp, counts.idfp, counts.idfn, counts.idsw), (3, 0, 1, 0));
        assert!((counts.idf1().unwrap() - 6.0 / 7.0).abs() < 1e-12);
    }

    #[test]
    fn a_frame_that_still_holds_the_remembered_track_is_no_switch() {
        // Object 1: frame 0 track 5; frame 1 tracks 6, 6 and 5 (5 still follows it); frame 2
        // tracks 6 and 6: a switch to 6 there; frame 3 tracks 8, 9, 9: a switch to 9, the
        // track with most of its rows, at its first row.
        let records = vec![
            row(0, Some(1), Some(5)),
            row(1, Some(1), Some(6)),
            row(1, Some(1), Some(6)),
            row(1, Some(1), Some(5)),
            row(2, Some(1), Some(6)),
            row(2, Some(1), Some(6)),
            row(3, Some(1), Some(8)),
            row(3, Some(1), Some(9)),
            row(3, Some(1), Some(9)),
        ];
        assert_eq!(id_switch_rows(&records), vec![4, 7]);
        // Tracks 5 and 6 both match object 1 in frame 1: the duplicate is an identity false
        // positive, the object frame one true positive.
        let counts = identity_counts(&records);
        assert_eq!((counts.gt_object_frames, counts.estimated_object_frames), (4, 6));
        assert_eq!((counts.idtp, counts.idfp, counts.idfn), (2, 4, 2));
        // On a tie the earliest row's track wins.
        let tie = vec![row(0, Some(1), Some(5)), row(1, Some(1), Some(4)), row(1, Some(1), Some(3))];
        assert_eq!(id_switch_rows(&tie), vec![1]);
    }

    /// Exhaustive optimum over all injective maps from ground-truth rows to track columns.
    fn brute_force(matrix: &[Vec<u64>], columns: usize) -> u64 {
        fn go(matrix: &[Vec<u64>], row: usize, used: &mut Vec<bool>) -> u64 {
            if row == matrix.len() {
                return 0;
            }
            // Leaving a row unassigned is allowed (rows may outnumber columns).
            let mut best = go(matrix, row + 1, used);
            for column in 0..used.len() {
                if !used[column] {
                    used[column] = true;
                    best = best.max(matrix[row][column] + go(matrix, row + 1, used));
                    used[column] = false;
                }
            }
            best
        }
        go(matrix, 0, &mut vec![false; columns])
    }

    proptest::proptest! {
        #[test]
        fn hungarian_matches_brute_force(
            rows in 1usize..5,
            columns in 1usize..5,
            cells in proptest::collection::vec(0u64..6, 25),
        ) {
            let matrix: Vec<Vec<u64>> =
                (0..rows).map(|r| (0..columns).map(|c| cells[r * 5 + c]).collect()).collect();
            let mut overlap = BTreeMap::new();
            for (r, line) in matrix.iter().enumerate() {
                for (c, &value) in line.iter().enumerate() {
                    if value > 0 {
                        overlap.insert((r as u64, 100 + c as u64), value);
                    }
                }
            }
            proptest::prop_assert_eq!(max_total_overlap(&overlap), brute_force(&matrix, columns));
        }
    }
}
