//! The urban road grid: roads, lanes, junctions with signals, and sidewalk rings.
//!
//! Roads run along world `y = j·B` ("X roads", travel along x) and `x = i·B` ("Y roads", travel
//! along y) for every integer `i`, `j`, with `B` the block length. Junction `(i, j)` is centred at
//! `(i·B, j·B)`. Traffic keeps right; lane 0 is the lane next to the centre line. Each block is
//! enclosed by a rectangular sidewalk ring at a fixed distance from the road centre lines.

use glam::DVec2;

use super::config::ScenarioConfig;

/// Direction of travel of a road.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Axis {
    /// Travel along the world x axis.
    X,
    /// Travel along the world y axis.
    Y,
}

impl Axis {
    /// The axis a unit direction vector (axis-aligned) travels along.
    pub(crate) fn of(direction: DVec2) -> Axis {
        if direction.x.abs() >= direction.y.abs() {
            Axis::X
        } else {
            Axis::Y
        }
    }
}

/// Integer index of a junction.
pub(crate) type JunctionId = (i64, i64);

/// Right-hand normal of a travel direction.
pub(crate) fn right_of(direction: DVec2) -> DVec2 {
    DVec2::new(direction.y, -direction.x)
}

/// Road geometry and signal timing derived from the configuration.
#[derive(Debug, Clone)]
pub(crate) struct RoadGrid {
    pub block_m: f64,
    pub lane_width_m: f64,
    pub lanes: u32,
    /// Width of the carriageway of one direction, metres.
    pub half_road_m: f64,
    /// Distance from a road centre line to the sidewalk centre line, metres.
    pub sidewalk_m: f64,
    /// Half width of the walkable sidewalk band, metres.
    pub sidewalk_half_width_m: f64,
    /// Distance from the junction centre to the stop line, metres.
    pub stop_distance_m: f64,
    pub right_turn_radius_m: f64,
    pub left_turn_radius_m: f64,
    green_s: f64,
    clearance_s: f64,
    signalised_fraction: f64,
    signal_seed: u64,
}

/// SplitMix64 finaliser: a fixed, well-mixing hash of a 64-bit value.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl RoadGrid {
    pub(crate) fn new(config: &ScenarioConfig, signal_seed: u64) -> Self {
        let road = &config.road;
        let half_road_m = config.half_road_width_m();
        Self {
            block_m: road.block_length_m,
            lane_width_m: road.lane_width_m,
            lanes: road.lanes_per_direction,
            half_road_m,
            sidewalk_m: half_road_m + road.sidewalk_offset_m,
            sidewalk_half_width_m: road.sidewalk_width_m / 2.0,
            stop_distance_m: half_road_m + road.stop_line_offset_m,
            right_turn_radius_m: road.right_turn_radius_m,
            left_turn_radius_m: road.left_turn_radius_m,
            green_s: road.signal_green_s,
            clearance_s: road.signal_clearance_s,
            signalised_fraction: road.signalised_junction_fraction,
            signal_seed,
        }
    }

    /// Lateral offset of lane `lane` from the centre line (to the right of travel), metres.
    pub(crate) fn lane_offset(&self, lane: u32) -> f64 {
        (f64::from(lane) + 0.5) * self.lane_width_m
    }

    /// Centre of junction `id`.
    pub(crate) fn junction_centre(&self, id: JunctionId) -> DVec2 {
        DVec2::new(id.0 as f64 * self.block_m, id.1 as f64 * self.block_m)
    }

    /// The junction nearest to `point`.
    pub(crate) fn nearest_junction(&self, point: DVec2) -> JunctionId {
        ((point.x / self.block_m).round() as i64, (point.y / self.block_m).round() as i64)
    }

    /// Length of one signal cycle, seconds.
    fn cycle_s(&self) -> f64 {
        2.0 * (self.green_s + self.clearance_s)
    }

    /// Two independent uniform numbers in [0, 1) fixed per junction.
    fn junction_draws(&self, id: JunctionId) -> (f64, f64) {
        let h = mix64(self.signal_seed ^ mix64(id.0 as u64 ^ mix64(id.1 as u64 ^ 0x6a09_e667)));
        let g = mix64(h);
        let unit = |v: u64| (v >> 11) as f64 / (1u64 << 53) as f64;
        (unit(h), unit(g))
    }

    /// Whether junction `id` has traffic signals.
    pub(crate) fn is_signalised(&self, id: JunctionId) -> bool {
        self.junction_draws(id).1 < self.signalised_fraction
    }

    /// Time into the cycle of junction `id` at time `t`.
    fn cycle_time(&self, id: JunctionId, t: f64) -> f64 {
        let offset = self.junction_draws(id).0 * self.cycle_s();
        (t + offset).rem_euclid(self.cycle_s())
    }

    /// Remaining green time for traffic along `axis` at junction `id`, seconds; 0 when the
    /// signal shows red (or all-red clearance) for that axis; infinite at junctions without
    /// signals.
    pub(crate) fn green_remaining(&self, id: JunctionId, axis: Axis, t: f64) -> f64 {
        if !self.is_signalised(id) {
            return f64::INFINITY;
        }
        let c = self.cycle_time(id, t);
        let start = match axis {
            Axis::X => 0.0,
            Axis::Y => self.green_s + self.clearance_s,
        };
        if c >= start && c < start + self.green_s {
            start + self.green_s - c
        } else {
            0.0
        }
    }

    /// Whether traffic along `axis` has green at junction `id` at time `t`.
    pub(crate) fn is_green(&self, id: JunctionId, axis: Axis, t: f64) -> bool {
        self.green_remaining(id, axis, t) > 0.0
    }

    /// Whether `point` lies in a junction area or its approach up to the stop lines.
    pub(crate) fn near_junction(&self, point: DVec2, margin_m: f64) -> bool {
        let c = self.junction_centre(self.nearest_junction(point));
        let d = (point - c).abs();
        d.x.min(d.y) < self.half_road_m + 1.0 && d.x.max(d.y) < self.stop_distance_m + margin_m
    }

    // --------------------------------------------------------------------------------------------
    // Sidewalk rings

    /// Length of one side of a block's sidewalk ring, metres.
    pub(crate) fn ring_side_m(&self) -> f64 {
        self.block_m - 2.0 * self.sidewalk_m
    }

    /// Corners of the sidewalk ring of block `(i, j)` (the block between roads `i`, `i + 1`
    /// and `j`, `j + 1`), counter-clockwise from the south-west corner.
    pub(crate) fn ring_corners(&self, block: (i64, i64)) -> [DVec2; 4] {
        let x0 = block.0 as f64 * self.block_m + self.sidewalk_m;
        let y0 = block.1 as f64 * self.block_m + self.sidewalk_m;
        let x1 = (block.0 + 1) as f64 * self.block_m - self.sidewalk_m;
        let y1 = (block.1 + 1) as f64 * self.block_m - self.sidewalk_m;
        [DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(x1, y1), DVec2::new(x0, y1)]
    }

    /// Perimeter of a ring, metres.
    pub(crate) fn ring_length_m(&self) -> f64 {
        4.0 * self.ring_side_m()
    }

    /// Point at ring coordinate `p` (metres counter-clockwise from the south-west corner).
    pub(crate) fn ring_point(&self, block: (i64, i64), p: f64) -> DVec2 {
        let side = self.ring_side_m();
        let p = p.rem_euclid(self.ring_length_m());
        let k = ((p / side).floor() as usize).min(3);
        let corners = self.ring_corners(block);
        let a = corners[k];
        let b = corners[(k + 1) % 4];
        a + (b - a) * ((p - k as f64 * side) / side)
    }

    /// Walking direction along the ring at coordinate `p` when `p` increases.
    pub(crate) fn ring_tangent(&self, p: f64) -> DVec2 {
        let side = self.ring_side_m();
        let k = ((p.rem_euclid(self.ring_length_m()) / side).floor() as usize).min(3);
        [DVec2::X, DVec2::Y, DVec2::NEG_X, DVec2::NEG_Y][k]
    }

    /// Outward normal (towards the adjacent road) of the ring side containing `p`.
    pub(crate) fn ring_outward(&self, p: f64) -> DVec2 {
        -self.ring_tangent(p).perp()
    }

    /// Ring coordinate of the ring point closest to `point`.
    pub(crate) fn ring_project(&self, block: (i64, i64), point: DVec2) -> f64 {
        let side = self.ring_side_m();
        let corners = self.ring_corners(block);
        let mut best = (f64::INFINITY, 0.0);
        for k in 0..4 {
            let a = corners[k];
            let b = corners[(k + 1) % 4];
            let u = ((point - a).dot(b - a) / side.powi(2)).clamp(0.0, 1.0);
            let d = (a + (b - a) * u).distance_squared(point);
            if d < best.0 {
                best = (d, k as f64 * side + u * side);
            }
        }
        best.1.rem_euclid(self.ring_length_m())
    }

    /// The block whose ring is nearest to `point`.
    pub(crate) fn block_of(&self, point: DVec2) -> (i64, i64) {
        ((point.x / self.block_m).floor() as i64, (point.y / self.block_m).floor() as i64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> RoadGrid {
        RoadGrid::new(&ScenarioConfig::default(), 7)
    }

    #[test]
    fn ring_coordinates_round_trip() {
        let g = grid();
        let block = (2, -3);
        for step in 0..40 {
            let p = step as f64 * g.ring_length_m() / 40.0 + 0.37;
            let point = g.ring_point(block, p);
            let back = g.ring_project(block, point);
            assert!((back - p).abs() < 1e-9, "p {p} came back as {back}");
            assert_eq!(g.block_of(point), block);
        }
    }

    #[test]
    fn signals_alternate_and_never_both_green() {
        let g = grid();
        let id = (-50..50).map(|i| (i, 4)).find(|&id| g.is_signalised(id)).expect("a signalised junction");
        let mut x_green = 0;
        let mut y_green = 0;
        for k in 0..4000 {
            let t = k as f64 * 0.01;
            let x = g.is_green(id, Axis::X, t);
            let y = g.is_green(id, Axis::Y, t);
            assert!(!(x && y), "both axes green at {t}");
            x_green += usize::from(x);
            y_green += usize::from(y);
        }
        // Each axis is green for green / cycle of the time.
        let share = 15.0 / 38.0;
        for count in [x_green, y_green] {
            let observed = count as f64 / 4000.0;
            assert!((observed - share).abs() < 0.03, "green share {observed}");
        }
    }

    #[test]
    fn signalised_fraction_is_respected() {
        let g = grid();
        let signalised =
            (0..40).flat_map(|i| (0..40).map(move |j| (i, j))).filter(|&id| g.is_signalised(id)).count();
        let share = signalised as f64 / 1600.0;
        assert!((share - 0.5).abs() < 0.05, "signalised share {share}");
        let unsignalised = (0..40).map(|i| (i, 0)).find(|&id| !g.is_signalised(id)).unwrap();
        assert!(g.is_green(unsignalised, Axis::X, 3.0) && g.is_green(unsignalised, Axis::Y, 3.0));
    }
}
