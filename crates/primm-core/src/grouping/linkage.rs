//! Single-linkage clustering of one frame's detections on fixed arrays: two detections belong
//! to one group when a chain of detections joins them in which each link is close in position
//! (a distance that grows with the range, as the radar's azimuth noise does), close in radial
//! velocity and from the same radar.
//!
//! A point may carry an owner (a confirmed track whose object holds it): the points of one
//! owner and radar are one group from the start, and two groups of different owners never
//! join, so a chain of points between two tracked objects stops at the first link that would
//! join them. The groups then depend on the order of the links, which is fixed: the points
//! sorted by x (the indices `0..n` by an unstable sort on x, so points of equal x keep the
//! order that sort gives them, which depends on the frame alone), and each point's links to
//! the points after it in that order, taken in that order.
//!
//! A link's distance is at most the reach at the nearer point's range, so at most the reach at
//! either point's: each point's partners lie within its own reach along x and along y. Where
//! the points spread wider in x than in y, a sweep over the x order finds them (each point's
//! walk stops at its reach along x). Where they spread wider in y, as lanes side by side along
//! x do, seen from beside the road, most points within one reach along x lie on other lanes;
//! the partners are then found in a second list sorted by y, within the point's reach along y
//! and along x, and joined in the x order (a partner already in the point's group is skipped,
//! since its link would change nothing). Both walks take the same links in the same order, so
//! the groups do not depend on which one ran (tested). A frame of `n` detections costs two
//! sorts, `O(n log n)`, plus the pairs within one reach along the wider axis; the groups are
//! the components of a union-find forest with path halving. Nothing allocates after
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
    /// Whether it is labelled a pedestrian: two such points link within the rule's
    /// `pedestrian_distance_scale` of the link distance.
    pub pedestrian: bool,
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
    /// The share of the link distance within which two points both labelled pedestrian link,
    /// in (0, 1].
    pub pedestrian_distance_scale: f64,
}

impl LinkRule {
    /// Whether `a` and `b` link.
    pub fn links(&self, a: &LinkPoint, b: &LinkPoint) -> bool {
        let mut reach_m = self.reach_m(a.range_m.min(b.range_m));
        if a.pedestrian && b.pedestrian {
            reach_m *= self.pedestrian_distance_scale;
        }
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
    /// Each point's position in `order`.
    rank_x: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// Point indices sorted by y, then their positions in `order`.
    by_y: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// The positions of the points in the order of `by_y`, m.
    by_y_m: [DVec2; MAX_MEASUREMENTS_PER_FRAME],
    /// Each point's position in `by_y`.
    at_y: [u16; MAX_MEASUREMENTS_PER_FRAME],
    /// The `order` positions of one point's partners later in `order`.
    later: [u16; MAX_MEASUREMENTS_PER_FRAME],
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
            rank_x: [0; MAX_MEASUREMENTS_PER_FRAME],
            by_y: [0; MAX_MEASUREMENTS_PER_FRAME],
            by_y_m: [DVec2::ZERO; MAX_MEASUREMENTS_PER_FRAME],
            at_y: [0; MAX_MEASUREMENTS_PER_FRAME],
            later: [0; MAX_MEASUREMENTS_PER_FRAME],
            labels: [0; MAX_MEASUREMENTS_PER_FRAME],
            groups: 0,
        }
    }

    /// Groups `points` by `rule`; returns the number of groups. Only the first
    /// [`MAX_MEASUREMENTS_PER_FRAME`] points are read. A point with a non-finite position or
    /// range links to nothing.
    pub fn cluster(&mut self, points: &[LinkPoint], rule: &LinkRule) -> usize {
        let n = points.len().min(MAX_MEASUREMENTS_PER_FRAME);
        let points = &points[..n];
        for index in 0..n {
            self.parent[index] = index as u16;
            self.owner[index] = points[index].owner;
            self.order[index] = index as u16;
        }
        self.join_owned(points);
        self.order[..n].sort_unstable_by(|&a, &b| {
            points[a as usize].position_m.x.total_cmp(&points[b as usize].position_m.x)
        });
        let span_m = points
            .iter()
            .filter(|point| linkable(point))
            .fold(None, |span: Option<(DVec2, DVec2)>, point| {
                let (low, high) = span.unwrap_or((point.position_m, point.position_m));
                Some((low.min(point.position_m), high.max(point.position_m)))
            })
            .map_or(DVec2::ZERO, |(low, high)| high - low);
        if span_m.y > span_m.x {
            self.link_through_y(points, rule);
        } else {
            self.link_along_x(points, rule);
        }
        self.label(n)
    }

    /// Takes the links in the sweep's order (see the module documentation) by walking the
    /// points sorted by x: each point's partners later in that order lie within its reach along
    /// x. The cheaper walk when the points spread wider in x than in y.
    fn link_along_x(&mut self, points: &[LinkPoint], rule: &LinkRule) {
        let order = &self.order[..points.len()];
        for (position, &a) in order.iter().enumerate() {
            let point_a = &points[a as usize];
            if !linkable(point_a) {
                continue;
            }
            // A link's distance is at most the reach at the nearer point's range, so at most
            // the reach at `a`'s.
            let reach_m = rule.reach_m(point_a.range_m);
            for &b in &order[position + 1..] {
                let point_b = &points[b as usize];
                if !(point_b.position_m.x - point_a.position_m.x <= reach_m) {
                    break;
                }
                if linkable(point_b) && rule.links(point_a, point_b) {
                    union(&mut self.parent, &mut self.owner, a, b);
                }
            }
        }
    }

    /// Takes the links in the same order as [`link_along_x`](Self::link_along_x), but finds
    /// each point's partners among the points sorted by y, within its reach along y (and along
    /// x), and joins them in the order of their x. The cheaper walk when the points spread wider
    /// in y (lanes side by side along x, seen from beside the road).
    fn link_through_y(&mut self, points: &[LinkPoint], rule: &LinkRule) {
        let n = points.len();
        let Linkage { parent, owner, order, rank_x, by_y, at_y, by_y_m, later, .. } = self;
        for (position, &point) in order[..n].iter().enumerate() {
            rank_x[point as usize] = position as u16;
        }
        by_y[..n].copy_from_slice(&order[..n]);
        by_y[..n].sort_unstable_by(|&a, &b| {
            points[a as usize].position_m.y.total_cmp(&points[b as usize].position_m.y)
        });
        // From here on `by_y` holds each point's position in `order`, and `by_y_m` its
        // position, so that the walk below reads them in sequence.
        for (position, slot) in by_y[..n].iter_mut().enumerate() {
            let point = *slot as usize;
            at_y[point] = position as u16;
            by_y_m[position] = points[point].position_m;
            *slot = rank_x[point];
        }
        for (position, &a) in order[..n].iter().enumerate() {
            let point_a = &points[a as usize];
            if !linkable(point_a) {
                continue;
            }
            let (reach_m, a_m) = (rule.reach_m(point_a.range_m), point_a.position_m);
            let centre = at_y[a as usize] as usize;
            // A partner already in `a`'s group needs no link: groups only ever merge.
            let root_a = find(parent, a);
            let mut count = 0;
            let mut consider = |k: usize| {
                let rank = by_y[k];
                if rank as usize > position && (by_y_m[k].x - a_m.x).abs() <= reach_m {
                    let b = order[rank as usize];
                    let point_b = &points[b as usize];
                    if find(parent, b) != root_a && linkable(point_b) && rule.links(point_a, point_b) {
                        later[count] = rank;
                        count += 1;
                    }
                }
            };
            for k in (0..centre).rev() {
                if !(a_m.y - by_y_m[k].y <= reach_m) {
                    break;
                }
                consider(k);
            }
            for k in centre + 1..n {
                if !(by_y_m[k].y - a_m.y <= reach_m) {
                    break;
                }
                consider(k);
            }
            later[..count].sort_unstable();
            for &rank in &later[..count] {
                union(parent, owner, a, order[rank as usize]);
            }
        }
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

/// Whether `point` can link at all: a finite position and range.
fn linkable(point: &LinkPoint) -> bool {
    point.position_m.is_finite() && point.range_m.is_finite()
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
        LinkRule {
            distance_m: 1.5,
            distance_per_range: 0.01,
            radial_velocity_gap_mps: 2.0,
            pedestrian_distance_scale: 0.5,
        }
    }

    fn point(x: f64, y: f64, radial_velocity_mps: f64, sensor_slot: u8) -> LinkPoint {
        let position_m = DVec2::new(x, y);
        LinkPoint {
            position_m,
            range_m: position_m.length(),
            radial_velocity_mps,
            sensor_slot,
            owner: NO_OWNER,
            pedestrian: false,
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

    /// The groups with owners by the rule the module documentation states, pair by pair: each
    /// owned point joined to the first earlier point of its owner and radar, then every pair
    /// in the order of the points sorted by x (the earlier point of the pair first, then the
    /// later), joined unless that would join two owners. Labels numbered like the linkage's.
    fn reference_labels_in_sweep_order(points: &[LinkPoint], rule: &LinkRule) -> Vec<usize> {
        let n = points.len();
        let mut parent: Vec<u16> = (0..n as u16).collect();
        let mut owner: Vec<u16> = points.iter().map(|point| point.owner).collect();
        for later in 0..n {
            let first = (0..later).find(|&earlier| {
                points[later].owner != NO_OWNER
                    && points[earlier].owner == points[later].owner
                    && points[earlier].sensor_slot == points[later].sensor_slot
            });
            if let Some(first) = first {
                union(&mut parent, &mut owner, first as u16, later as u16);
            }
        }
        let mut order: Vec<u16> = (0..n as u16).collect();
        order.sort_unstable_by(|&a, &b| {
            points[a as usize].position_m.x.total_cmp(&points[b as usize].position_m.x)
        });
        for (position, &a) in order.iter().enumerate() {
            for &b in &order[position + 1..] {
                let (point_a, point_b) = (&points[a as usize], &points[b as usize]);
                if linkable(point_a) && linkable(point_b) && rule.links(point_a, point_b) {
                    union(&mut parent, &mut owner, a, b);
                }
            }
        }
        let mut first_of_root = Vec::new();
        (0..n)
            .map(|index| {
                let root = find(&mut parent, index as u16);
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

    /// Points on `lanes` lanes 4 m apart in y (so the frame spreads wider in y than in x), each
    /// within 2.5 m of its lane's line and 20 m of x = 0: cars side by side, seen from beside
    /// the road.
    fn lanes_stacked_in_y(raw: &[(usize, f64, f64, f64, u8, u16)], lanes: usize) -> Vec<LinkPoint> {
        raw.iter()
            .map(|&(lane, x, dy, v, s, owner)| {
                let y = -2.0 * lanes as f64 + 4.0 * (lane % lanes) as f64 + dy;
                LinkPoint {
                    owner: if owner < 6 { owner } else { NO_OWNER },
                    // Every third point a pedestrian: their links reach half as far.
                    pedestrian: owner % 3 == 0,
                    ..point(x, y, v, s)
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
    fn two_people_walking_a_metre_apart_stay_two_groups_where_a_cars_points_a_metre_apart_link() {
        let pedestrian = |x: f64| LinkPoint { pedestrian: true, ..point(x, 10.0, 1.0, 0) };
        // The link distance at 10 m is 1.6 m; between pedestrians' detections, 0.8 m.
        let people = [pedestrian(0.0), pedestrian(0.3), pedestrian(1.2), pedestrian(1.4)];
        let mut linkage = Box::new(Linkage::new());
        assert_eq!(linkage.cluster(&people, &rule()), 2);
        assert_eq!([0, 1, 2, 3].map(|index| linkage.label_of(index)), [0, 0, 1, 1]);
        let car = [point(0.0, 10.0, 1.0, 0), point(0.3, 10.0, 1.0, 0), point(1.2, 10.0, 1.0, 0)];
        assert_eq!(linkage.cluster(&car, &rule()), 1);
        // A car's point labelled pedestrian by mistake still links to the car's at full reach.
        let mislabelled = [point(0.0, 10.0, 1.0, 0), pedestrian(1.2)];
        assert_eq!(linkage.cluster(&mislabelled, &rule()), 1);
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

        #[test]
        fn on_lanes_stacked_in_y_the_groups_are_the_connected_components_of_every_linking_pair(
            raw in proptest::collection::vec(
                (0usize..40, -20.0f64..20.0, -2.5f64..2.5, -3.0f64..3.0, 0u8..2, 0u16..1), 0..300),
        ) {
            let points: Vec<LinkPoint> = lanes_stacked_in_y(&raw, 40)
                .into_iter()
                .map(|point| LinkPoint { owner: NO_OWNER, ..point })
                .collect();
            let mut linkage = Box::new(Linkage::new());
            let groups = linkage.cluster(&points, &rule());
            let expected = reference_labels(&points, &rule());
            let labels: Vec<usize> = (0..points.len()).map(|i| linkage.label_of(i)).collect();
            prop_assert_eq!(&labels, &expected);
            prop_assert_eq!(groups, expected.iter().map(|&l| l + 1).max().unwrap_or(0));
        }

        #[test]
        fn with_owners_the_groups_follow_the_links_in_the_order_of_x_wherever_the_points_spread(
            raw in proptest::collection::vec(
                (0usize..40, -20.0f64..20.0, -2.5f64..2.5, -3.0f64..3.0, 0u8..2, 0u16..12), 0..300),
            lanes in 1usize..40,
        ) {
            // One lane spreads the points wider in x, forty wider in y.
            let points = lanes_stacked_in_y(&raw, lanes);
            let mut linkage = Box::new(Linkage::new());
            let groups = linkage.cluster(&points, &rule());
            let expected = reference_labels_in_sweep_order(&points, &rule());
            let labels: Vec<usize> = (0..points.len()).map(|i| linkage.label_of(i)).collect();
            prop_assert_eq!(&labels, &expected);
            prop_assert_eq!(groups, expected.iter().map(|&l| l + 1).max().unwrap_or(0));
        }
    }
}
