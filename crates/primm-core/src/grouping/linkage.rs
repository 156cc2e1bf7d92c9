//! Single-linkage clustering of one frame's detections on fixed arrays: two detections belong
//! to one group when a chain of detections joins them in which each link is close in position
//! (a distance that grows with the range, as the radar's azimuth noise does), close in radial
//! velocity and from the same radar.
//!
//! A point may carry an owner (a confirmed track whose object holds it): the points of one
//! owner and radar are one group from the start, and two groups of different owners never
//! join, so a chain of points between two tracked objects stops at the first link that would
//! join them. The groups then depend on the order of the links, which is the sweep's, fixed by
//! the points' positions and indices.
//!
//! The pairs are found by a sweep over the detections sorted by x, so a frame of `n`
//! detections costs `O(n log n)` plus the pairs within one link distance along x; the groups
//! are the components of a union-find forest with path halving. Nothing allocates after
//! [`Linkage::new`].

use crate::limits::MAX_MEASUREMENTS_PER_FRAME;
use glam::DVec2;

/// One detection as the linkage sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkPoint {
    /// Position in the tracking frame, m.
    pub position_m: DVec2,
    /// Range from its radar, m.
    pub range_m: f64,
    /// Radial velocity, m/s.
    pub radial_velocity_mps: f64,
    /// The radar's slot in the sensor set: points of different radars never link.
    pub sensor_slot: u8,
    /// The owner (a track's table row), or [`NO_OWNER`].
    pub owner: u16,
}

/// The owner of a point that no track holds.
pub const NO_OWNER: u16 = u16::MAX;

/// When two detections link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkRule {
    /// Largest distance of a link at zero range, m.
    pub distance_m: f64,
    /// Growth of the link distance with the nearer point's range, m per m.
    pub distance_per_range: f64,
    /// Largest difference of radial velocity of a link, m/s.
    pub radial_velocity_gap_mps: f64,
}

impl LinkRule {
    /// Whether `a` and `b` link.
    pub fn links(&self, a: &LinkPoint, b: &LinkPoint) -> bool {
        let reach_m = self.reach_m(a.range_m.min(b.range_m));
        a.sensor_slot == b.sensor_slot
            && (a.radial_velocity_mps - b.radial_velocity_mps).abs() <= self.radial_velocity_gap_mps
            && a.position_m.distance_squared(b.position_m) <= reach_m * reach_m
    }

    /// The link distance at `range_m`, m.
    pub fn reach_m(&self, range_m: f64) -> f64 {
        self.distance_m + self.distance_per_range * range_m.max(0.0)
    }
}

/// The workspace of the clustering, sized once for a full frame.
#[derive(Debug, Clone)]
pub struct Linkage {
    parent: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// The owner of each root's group, [`NO_OWNER`] when none.
    owner: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// The first point of each owner (a track's table row) in the current frame.
    first_owned: [u16; crate::limits::MAX_TRACKS],
    /// Point indices sorted by x.
    order: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// The group of each point after [`Linkage::cluster`]: `0..groups`, numbered in the order
    /// of each group's first point.
    labels: [u16; MAX_MEASUREMENTS_PER_FRAME],
    groups: usize,
}

impl Default for Linkage {
    fn default() -> Self {
        Self::new()
    }
}

impl Linkage {
    /// An empty workspace.
    pub fn new() -> Self {
        Linkage {
            parent: [0; MAX_MEASUREMENTS_PER_FRAME],
            owner: [NO_OWNER; MAX_MEASUREMENTS_PER_FRAME],
            first_owned: [u16::MAX; crate::limits::MAX_TRACKS],
            order: [0; MAX_MEASUREMENTS_PER_FRAME],
            labels: [0; MAX_MEASUREMENTS_PER_FRAME],
            groups: 0,
        }
    }

    /// Groups `points` by `rule`; returns the number of groups. Only the first
    /// [`MAX_MEASUREMENTS_PER_FRAME`] points are read. A point with a non-finite position or
    /// range links to nothing.
    pub fn cluster(&mut self, points: &[LinkPoint], rule: &LinkRule) -> usize {
        let n = points.len().min(MAX_MEASUREMENTS_PER_FRAME);
        for index in 0..n {
            self.parent[index] = index as u16;
            self.owner[index] = points[index].owner;
            self.order[index] = index as u16;
        }
        self.join_owned(&points[..n]);
        let order = &mut self.order[..n];
        order.sort_unstable_by(|&a, &b| {
            points[a as usize].position_m.x.total_cmp(&points[b as usize].position_m.x)
        });
        let largest_range_m = points[..n]
            .iter()
            .map(|point| point.range_m)
            .filter(|range| range.is_finite())
            .fold(0.0, f64::max);
        let window_m = rule.reach_m(largest_range_m);
        for (position, &a) in order.iter().enumerate() {
            let point_a = &points[a as usize];
            if !(point_a.position_m.is_finite() && point_a.range_m.is_finite()) {
                continue;
            }
            for &b in &order[position + 1..] {
                let point_b = &points[b as usize];
                if !(point_b.position_m.x - point_a.position_m.x <= window_m) {
                    break;
                }
                if rule.links(point_a, point_b) {
                    union(&mut self.parent, &mut self.owner, a, b);
                }
            }
        }
        self.label(n)
    }

    /// Joins the points of each owner and radar: each to the owner's first point (of its radar;
    /// a second radar's points of one owner in one frame, which is rare, are found by a scan
    /// back over the points).
    fn join_owned(&mut self, points: &[LinkPoint]) {
        self.first_owned.fill(u16::MAX);
        for (index, point) in points.iter().enumerate() {
            let Some(first) = self.first_owned.get_mut(usize::from(point.owner)) else { continue };
            if *first == u16::MAX {
                *first = index as u16;
                continue;
            }
            let same_radar = points[usize::from(*first)].sensor_slot == point.sensor_slot;
            let partner = if same_radar {
                Some(usize::from(*first))
            } else {
                points[..index]
                    .iter()
                    .position(|other| other.owner == point.owner && other.sensor_slot == point.sensor_slot)
            };
            if let Some(partner) = partner {
                union(&mut self.parent, &mut self.owner, partner as u16, index as u16);
            }
        }
    }

    /// Numbers the components `0..` in the order of their first point.
    fn label(&mut self, n: usize) -> usize {
        const UNSET: u16 = u16::MAX;
        // The label of each root, kept at the root's own index until every point is read.
        let mut groups = 0usize;
        for index in 0..n {
            self.labels[index] = UNSET;
        }
        for index in 0..n {
            let root = find(&mut self.parent, index as u16) as usize;
            if self.labels[root] == UNSET {
                self.labels[root] = groups as u16;
                groups += 1;
            }
            if root != index {
                self.labels[index] = self.labels[root];
            }
        }
        self.groups = groups;
        groups
    }

    /// The group of point `index` after the latest [`cluster`](Self::cluster).
    pub fn label_of(&self, index: usize) -> usize {
        self.labels[index] as usize
    }

    /// The number of groups of the latest [`cluster`](Self::cluster).
    pub fn groups(&self) -> usize {
        self.groups
    }
}

fn find(parent: &mut [u16], mut node: u16) -> u16 {
    while parent[node as usize] != node {
        let grandparent = parent[parent[node as usize] as usize];
        parent[node as usize] = grandparent;
        node = grandparent;
    }
    node
}

/// Joins the groups of `a` and `b` unless they have different owners.
fn union(parent: &mut [u16], owner: &mut [u16], a: u16, b: u16) {
    let (root_a, root_b) = (find(parent, a), find(parent, b));
    let (owner_a, owner_b) = (owner[root_a as usize], owner[root_b as usize]);
    if root_a == root_b || (owner_a != NO_OWNER && owner_b != NO_OWNER && owner_a != owner_b) {
        return;
    }
    // The smaller index becomes the root, so the labels do not depend on the sweep.
    let (low, high) = if root_a < root_b { (root_a, root_b) } else { (root_b, root_a) };
    parent[high as usize] = low;
    owner[low as usize] = if owner_a != NO_OWNER { owner_a } else { owner_b };
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::boxed::Box;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    fn rule() -> LinkRule {
        LinkRule { distance_m: 1.5, distance_per_range: 0.01, radial_velocity_gap_mps: 2.0 }
    }

    fn point(x: f64, y: f64, radial_velocity_mps: f64, sensor_slot: u8) -> LinkPoint {
        let position_m = DVec2::new(x, y);
        LinkPoint {
            position_m,
            range_m: position_m.length(),
            radial_velocity_mps,
            sensor_slot,
            owner: NO_OWNER,
        }
    }

    /// The components by petgraph's union-find over every linking pair, as a label per point
    /// numbered like the linkage's.
    fn reference_labels(points: &[LinkPoint], rule: &LinkRule) -> Vec<usize> {
        let mut forest = petgraph::unionfind::UnionFind::<usize>::new(points.len());
        for a in 0..points.len() {
            for b in a + 1..points.len() {
                if rule.links(&points[a], &points[b]) {
                    forest.union(a, b);
                }
            }
        }
        let mut first_of_root = Vec::new();
        (0..points.len())
            .map(|index| {
                let root = forest.find(index);
                match first_of_root.iter().position(|&known| known == root) {
                    Some(label) => label,
                    None => {
                        first_of_root.push(root);
                        first_of_root.len() - 1
                    }
                }
            })
            .collect()
    }

    #[test]
    fn a_chain_of_close_detections_is_one_group_and_a_far_one_its_own() {
        let points = [
            point(10.0, 0.0, 5.0, 0),
            point(11.2, 0.0, 5.5, 0),
            point(12.4, 0.0, 5.0, 0),
            point(20.0, 0.0, 5.0, 0),
        ];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&points, &rule()), 2);
        assert_eq!([0, 1, 2, 3].map(|index| linkage.label_of(index)), [0, 0, 0, 1]);
    }

    #[test]
    fn detections_of_other_radars_or_other_speeds_never_link() {
        let points = [point(10.0, 0.0, 5.0, 0), point(10.5, 0.0, 5.0, 1), point(10.2, 0.0, 9.0, 0)];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&points, &rule()), 3);
    }

    #[test]
    fn the_link_distance_grows_with_range() {
        // 1.9 m apart: too far at 10 m (1.6 m), close enough at 80 m (2.3 m).
        let near = [point(0.0, 10.0, 0.0, 0), point(1.9, 10.0, 0.0, 0)];
        let far = [point(0.0, 80.0, 0.0, 0), point(1.9, 80.0, 0.0, 0)];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&near, &rule()), 2);
        assert_eq!(linkage.cluster(&far, &rule()), 1);
    }

    #[test]
    fn a_point_without_a_finite_position_is_a_group_of_its_own() {
        let points = [point(10.0, 0.0, 0.0, 0), point(f64::NAN, 0.0, 0.0, 0), point(10.5, 0.0, 0.0, 0)];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&points, &rule()), 2);
        assert_ne!(linkage.label_of(1), linkage.label_of(0));
    }

    #[test]
    fn points_of_one_owner_are_one_group_and_two_owners_never_join_through_a_chain() {
        let owned = |x: f64, owner: u16| LinkPoint { owner, ..point(x, 0.0, 0.0, 0) };
        // Owner 1 at 10 and 16 m (not linked by distance), a free point at 11.5, owner 2 at 13.
        let points = [owned(10.0, 1), point(11.5, 0.0, 0.0, 0), owned(13.0, 2), owned(16.0, 1)];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&points, &rule()), 2);
        assert_eq!([0, 1, 2, 3].map(|index| linkage.label_of(index)), [0, 0, 1, 0]);
    }

    proptest! {
        #[test]
        fn the_groups_are_the_connected_components_of_every_linking_pair(
            raw in proptest::collection::vec(
                (-30.0f64..30.0, -30.0f64..30.0, -3.0f64..3.0, 0u8..2), 0..120),
        ) {
            let points: Vec<LinkPoint> =
                raw.iter().map(|&(x, y, v, s)| point(x, y, v, s)).collect();
            let mut linkage = Box::new(Linkage::new());
            let groups = linkage.cluster(&points, &rule());
            let expected = reference_labels(&points, &rule());
            let labels: Vec<usize> = (0..points.len()).map(|i| linkage.label_of(i)).collect();
            prop_assert_eq!(&labels, &expected);
            prop_assert_eq!(groups, expected.iter().map(|&l| l + 1).max().unwrap_or(0));
        }
    }
}
