//! The confirmed tracks of one step, indexed for the grouping's look-ups (`grouping.rs`): which
//! tracks lie near a detection, and which of those hold it, in one fixed order.
//!
//! The tracks are sorted by the x of their priors (ties by table row), and the holders of a
//! detection are always visited in that order, because the choice among several holders
//! depends on it. The tracks near a detection are found along the axis on which the priors
//! spread wider: along x by a window of that order, along y by a second list sorted by y. Lanes
//! side by side along x (a road seen from beside it) put many tracks within one window along x
//! but few along y. Holders are marked in a bit set over the positions in the x order, so they
//! come out in that order whichever axis found them. Nothing allocates after
//! [`ConfirmedIndex::new`].

use crate::limits::MAX_TRACKS;
use arrayvec::ArrayVec;
use glam::DVec2;

const WORDS: usize = MAX_TRACKS.div_ceil(64);

/// The confirmed tracks of one step, sorted for the look-ups near a position.
#[derive(Debug, Clone)]
pub(super) struct ConfirmedIndex {
    /// (x of the prior, table row), sorted by x then row.
    by_x: ArrayVec<(f64, u16), MAX_TRACKS>,
    /// (y of the prior, position in `by_x`), sorted by y then position; filled only when the
    /// priors spread wider in y than in x.
    by_y: ArrayVec<(f64, u16), MAX_TRACKS>,
    /// Whether the look-ups go along y.
    along_y: bool,
    /// How far from its centre any indexed track can hold a detection, m.
    reach_m: f64,
    /// Each indexed track's fused velocity at its prior, by table row, m/s.
    velocity_mps: [DVec2; MAX_TRACKS],
    /// Each indexed track's y at its prior, by table row, m.
    y_m: [f64; MAX_TRACKS],
}

/// The holders of one detection: a bit per position in the x order.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Holders([u64; WORDS]);

impl ConfirmedIndex {
    /// An empty index.
    pub(super) fn new() -> Self {
        ConfirmedIndex {
            by_x: ArrayVec::new(),
            by_y: ArrayVec::new(),
            along_y: false,
            reach_m: 0.0,
            velocity_mps: [DVec2::ZERO; MAX_TRACKS],
            y_m: [0.0; MAX_TRACKS],
        }
    }

    /// Indexes `tracks` (table row, prior position, fused velocity; at most [`MAX_TRACKS`],
    /// more are ignored), any of which holds detections at most `reach_m` from its position.
    pub(super) fn rebuild(&mut self, tracks: impl Iterator<Item = (u16, DVec2, DVec2)>, reach_m: f64) {
        self.by_x.clear();
        self.by_y.clear();
        self.reach_m = reach_m;
        let (mut low, mut high) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for (row, position_m, velocity_mps) in tracks {
            if self.by_x.try_push((position_m.x, row)).is_err() {
                break;
            }
            self.velocity_mps[usize::from(row)] = velocity_mps;
            self.y_m[usize::from(row)] = position_m.y;
            if position_m.is_finite() {
                (low, high) = (low.min(position_m), high.max(position_m));
            }
        }
        self.by_x.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let span_m = high - low;
        self.along_y = span_m.y > span_m.x;
        if self.along_y {
            for (position, &(_, row)) in self.by_x.iter().enumerate() {
                // As many entries as `by_x`, so this never overflows.
                let _ = self.by_y.try_push((self.y_m[usize::from(row)], position as u16));
            }
            self.by_y.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        }
    }

    /// The fused velocity at its prior of the indexed track in table row `row`, m/s.
    pub(super) fn velocity_mps(&self, row: usize) -> DVec2 {
        self.velocity_mps[row]
    }

    /// The positions in the x order of the indexed tracks whose prior lies within the reach of
    /// `position_m` along the look-up axis: every track that can hold a detection there, and
    /// maybe others, in no particular order.
    fn near_positions(&self, position_m: DVec2) -> impl Iterator<Item = usize> + '_ {
        let (along_x, along_y) = if self.along_y {
            (0..0, window(&self.by_y, position_m.y, self.reach_m))
        } else {
            (window(&self.by_x, position_m.x, self.reach_m), 0..0)
        };
        along_x.chain(self.by_y[along_y].iter().map(|&(_, position)| usize::from(position)))
    }

    /// The table rows of the indexed tracks that can hold a detection at `position_m` (and
    /// maybe others), in no particular order.
    pub(super) fn near(&self, position_m: DVec2) -> impl Iterator<Item = usize> + '_ {
        self.near_positions(position_m).map(|position| usize::from(self.by_x[position].1))
    }

    /// The indexed tracks near `position_m` for which `holds` (given a table row) is true.
    pub(super) fn holders(&self, position_m: DVec2, mut holds: impl FnMut(usize) -> bool) -> Holders {
        let mut holders = Holders::default();
        for position in self.near_positions(position_m) {
            if holds(usize::from(self.by_x[position].1)) {
                holders.0[position / 64] |= 1 << (position % 64);
            }
        }
        holders
    }

    /// The table rows of `holders`, in the order of their priors' x (ties by row).
    pub(super) fn rows<'a>(&'a self, holders: &'a Holders) -> impl Iterator<Item = usize> + 'a {
        holders.0.iter().enumerate().flat_map(move |(word_index, &word)| {
            let mut bits = word;
            core::iter::from_fn(move || {
                if bits == 0 {
                    return None;
                }
                let position = word_index * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                Some(usize::from(self.by_x[position].1))
            })
        })
    }
}

/// The range of `sorted` (sorted by its first field) whose first field lies within `reach_m` of
/// `centre`.
fn window(sorted: &[(f64, u16)], centre: f64, reach_m: f64) -> core::ops::Range<usize> {
    let start = sorted.partition_point(|&(key, _)| key < centre - reach_m);
    let end = sorted.partition_point(|&(key, _)| key <= centre + reach_m);
    start..end.max(start)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::boxed::Box;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// Tracks on `lanes` lanes 4 m apart in y, each within 30 m of x = 0 (one lane spreads them
    /// wider in x, many wider in y), some of them on one spot.
    fn tracks(raw: &[(usize, f64, f64)], lanes: usize) -> Vec<(u16, DVec2, DVec2)> {
        raw.iter()
            .enumerate()
            .map(|(row, &(lane, x, dy))| {
                let x = if row % 7 == 3 { 0.0 } else { x };
                (row as u16, DVec2::new(x, 4.0 * (lane % lanes) as f64 + dy), DVec2::new(row as f64, 0.0))
            })
            .collect()
    }

    proptest! {
        #[test]
        fn the_holders_are_every_track_that_holds_the_position_in_the_order_of_x_then_row(
            raw in proptest::collection::vec((0usize..40, -30.0f64..30.0, -1.0f64..1.0), 0..200),
            lanes in 1usize..40,
            probe in (-32.0f64..32.0, -2.0f64..162.0),
            hold_m in 0.0f64..6.0,
        ) {
            let tracks = tracks(&raw, lanes);
            let mut index = Box::new(ConfirmedIndex::new());
            index.rebuild(tracks.iter().copied(), 6.0);
            let probe_m = DVec2::new(probe.0, probe.1);
            let holds = |row: usize| tracks[row].1.distance(probe_m) <= hold_m;
            let holders = index.holders(probe_m, holds);
            let found: Vec<usize> = index.rows(&holders).collect();
            let mut expected: Vec<usize> = (0..tracks.len()).filter(|&row| holds(row)).collect();
            expected.sort_by(|&a, &b| tracks[a].1.x.total_cmp(&tracks[b].1.x).then(a.cmp(&b)));
            prop_assert_eq!(found, expected.clone());
            let mut near: Vec<usize> = index.near(probe_m).collect();
            prop_assert!(expected.iter().all(|row| near.contains(row)));
            near.sort_unstable();
            near.dedup();
            prop_assert_eq!(near.len(), index.near(probe_m).count());
            prop_assert!(tracks.iter().all(|&(row, _, velocity)| index.velocity_mps(usize::from(row)) == velocity));
        }
    }
}
