//! Route planning: the routes of cars junction by junction (lane changes, stop lines, turns)
//! and the walks of pedestrians leg by leg (waits, turn-arounds, crossings mid-block and on
//! crosswalks). The drivers' and walkers' constants are `car.driver` and `pedestrian.walker`.

use std::f64::consts::PI;

use glam::DVec2;
use rand::Rng;
use rand_chacha::ChaCha12Rng;

use super::super::config::{CarConfig, PedestrianConfig, ScenarioConfig};
use super::super::path::{Leg, Mark, MarkKind, Path};
use super::super::road::{right_of, Axis, JunctionId, RoadGrid};
use super::driver::{CarBrain, LaneCursor};
use super::pedestrian::PedBrain;
use super::{coin, uniform};

/// A car going straight on leaves the junction area this far beyond the crossing road's
/// edge, metres.
const STRAIGHT_EXIT_MARGIN_M: f64 = 1.0;
/// A pedestrian this close to a corner of the ring is at it, metres.
const AT_CORNER_M: f64 = 0.05;
/// A leg along a block ends at least this far before the corner; a longer one goes to the
/// corner, metres.
const MIN_LEG_BEFORE_CORNER_M: f64 = 1.0;
/// Distance behind a ring position at which the direction of the side before it is taken,
/// metres.
const TANGENT_PROBE_M: f64 = 0.5;
/// A sidewalk direction within 60° of the crossing direction continues it (cosine).
const ALONG_COS: f64 = 0.5;

/// Position on a block's sidewalk ring used for walk planning.
#[derive(Debug, Clone, Copy)]
pub(super) struct WalkCursor {
    /// The block whose ring is walked.
    pub block: (i64, i64),
    /// Ring coordinate, metres.
    pub p: f64,
    /// Walking direction along the ring: 1 or -1.
    pub dir: f64,
}

/// Appends the route up to and through the next junction: an optional lane change, the
/// approach with its stop line, and the manoeuvre (straight on, right or left turn); the ego
/// vehicle turns with its own probabilities where configured.
pub(super) fn plan_car(
    grid: &RoadGrid,
    cfg: &ScenarioConfig,
    rng: &mut ChaCha12Rng,
    brain: &mut CarBrain,
    path: &mut Path,
    is_ego: bool,
) {
    let cursor = brain.cursor;
    let d = cursor.dir;
    let junction = junction_ahead(grid, &cursor);
    let driver = &cfg.car.driver;
    let lane_change_m = (cfg.car.lane_change_duration_s
        * brain.desired_speed.max(driver.lane_change_min_speed_mps))
    .clamp(driver.min_lane_change_length_m, driver.max_lane_change_length_m);
    let mut turn = [cfg.car.turn_left_probability, cfg.car.turn_right_probability];
    if is_ego {
        turn = [
            cfg.ego.turn_left_probability.unwrap_or(turn[0]),
            cfg.ego.turn_right_probability.unwrap_or(turn[1]),
        ];
    }
    let (manoeuvre, target_lane) =
        choose_manoeuvre(grid, &cfg.car, turn, rng, &cursor, junction.distance_m, lane_change_m);
    let lane_change =
        LaneChange { target_lane, start_m: driver.lane_change_start_m, length_m: lane_change_m };
    let current = push_lane_change(grid, path, &cursor, lane_change);
    let stop_point = junction.centre - d * grid.stop_distance_m;
    let stop_ahead = (stop_point - cursor.pos).dot(d);
    let stop_s = path.end_s() + (stop_point - current).dot(d);
    brain.cursor = push_manoeuvre(grid, path, junction.centre, d, current, manoeuvre, target_lane);
    if stop_ahead > 0.0 {
        path.add_mark(Mark {
            s: stop_s,
            kind: MarkKind::StopLine { junction: junction.id, axis: Axis::of(d) },
        });
    }
}

/// The next junction on a car's road.
struct JunctionAhead {
    /// Distance from the cursor to the junction centre along the travel direction, m.
    distance_m: f64,
    /// The junction centre.
    centre: DVec2,
    id: JunctionId,
}

/// The junction ahead of `cursor` on its road.
fn junction_ahead(grid: &RoadGrid, cursor: &LaneCursor) -> JunctionAhead {
    let d = cursor.dir;
    let r = right_of(d);
    let b = grid.block_m;
    let coord = cursor.pos.dot(d.abs());
    let sign = d.x + d.y;
    let next = if sign > 0.0 { (coord / b).floor() + 1.0 } else { (coord / b).ceil() - 1.0 } * b;
    let distance_m = (next - coord) * sign;
    let centre_line = cursor.pos - r * grid.lane_offset(cursor.lane);
    let centre = centre_line + d * distance_m;
    JunctionAhead { distance_m, centre, id: grid.nearest_junction(centre) }
}

/// What a car does at the next junction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Manoeuvre {
    Straight,
    Right,
    Left,
}

/// Draws the manoeuvre at the junction `dist_j` metres ahead (straight on when the turn lane
/// cannot be reached in time) and the lane to take: the outer lane for a right turn, the inner
/// one for a left turn, and sometimes another lane when going straight on.
fn choose_manoeuvre(
    grid: &RoadGrid,
    c: &CarConfig,
    [turn_left_probability, turn_right_probability]: [f64; 2],
    rng: &mut ChaCha12Rng,
    cursor: &LaneCursor,
    dist_j: f64,
    lane_change_m: f64,
) -> (Manoeuvre, u32) {
    let outer = grid.lanes - 1;
    let d = &c.driver;
    let lane_change_room = d.lane_change_start_m + lane_change_m + d.lane_change_clearance_m;
    let right_entry = dist_j - (grid.lane_offset(outer) + grid.right_turn_radius_m);
    let left_entry = dist_j + grid.lane_offset(0) - grid.left_turn_radius_m;
    let feasible = |entry: f64, lane: u32| {
        entry >= if lane == cursor.lane { d.min_turn_entry_m } else { lane_change_room }
    };

    let u: f64 = rng.random();
    let mut manoeuvre = if u < turn_left_probability {
        Manoeuvre::Left
    } else if u < turn_left_probability + turn_right_probability {
        Manoeuvre::Right
    } else {
        Manoeuvre::Straight
    };
    if (manoeuvre == Manoeuvre::Right && !feasible(right_entry, outer))
        || (manoeuvre == Manoeuvre::Left && !feasible(left_entry, 0))
    {
        manoeuvre = Manoeuvre::Straight;
    }
    let target_lane = match manoeuvre {
        Manoeuvre::Right => outer,
        Manoeuvre::Left => 0,
        Manoeuvre::Straight => {
            let room = dist_j - grid.stop_distance_m;
            if grid.lanes > 1 && room >= lane_change_room && rng.random_bool(c.lane_change_probability) {
                let other = rng.random_range(0..grid.lanes - 1);
                if other >= cursor.lane {
                    other + 1
                } else {
                    other
                }
            } else {
                cursor.lane
            }
        }
    };
    (manoeuvre, target_lane)
}

/// A planned lane change.
#[derive(Debug, Clone, Copy)]
struct LaneChange {
    /// The lane to change to.
    target_lane: u32,
    /// Distance from the cursor to the start of the change, metres.
    start_m: f64,
    /// Length of the change, metres.
    length_m: f64,
}

/// Appends the change from the cursor's lane to the lane change's target lane, if they
/// differ. Returns where the route continues.
fn push_lane_change(grid: &RoadGrid, path: &mut Path, cursor: &LaneCursor, change: LaneChange) -> DVec2 {
    let current = cursor.pos;
    if change.target_lane == cursor.lane {
        return current;
    }
    let d = cursor.dir;
    let start = current + d * change.start_m;
    let shift = grid.lane_offset(change.target_lane) - grid.lane_offset(cursor.lane);
    let end = current + d * (change.start_m + change.length_m) + right_of(d) * shift;
    path.push(Leg::Line { a: current, b: start });
    path.push(Leg::Line { a: start, b: end });
    end
}

/// Appends the approach from `current` (travelling along `d` in `target_lane`) and the
/// manoeuvre through the junction centred at `junction`. Returns the cursor after it.
fn push_manoeuvre(
    grid: &RoadGrid,
    path: &mut Path,
    junction: DVec2,
    d: DVec2,
    current: DVec2,
    manoeuvre: Manoeuvre,
    target_lane: u32,
) -> LaneCursor {
    let r = right_of(d);
    let outer = grid.lanes - 1;
    let o_in = grid.lane_offset(target_lane);
    match manoeuvre {
        Manoeuvre::Straight => {
            let exit = junction + d * (grid.half_road_m + STRAIGHT_EXIT_MARGIN_M) + r * o_in;
            path.push(Leg::Line { a: current, b: exit });
            LaneCursor { pos: exit, dir: d, lane: target_lane }
        }
        Manoeuvre::Right => {
            let r_right = grid.right_turn_radius_m;
            let o_out = grid.lane_offset(outer);
            let corner = junction - d * o_out + r * o_in;
            let entry = corner - d * r_right;
            let exit = corner + r * r_right;
            let centre = corner - d * r_right + r * r_right;
            path.push(Leg::Line { a: current, b: entry });
            path.push(Leg::Arc {
                centre,
                radius: r_right,
                start: (entry - centre).to_angle(),
                sweep: -PI / 2.0,
            });
            LaneCursor { pos: exit, dir: r, lane: outer }
        }
        Manoeuvre::Left => {
            let r_left = grid.left_turn_radius_m;
            let o_out = grid.lane_offset(0);
            let corner = junction + d * o_out + r * o_in;
            let entry = corner - d * r_left;
            let exit = corner - r * r_left;
            let centre = corner - d * r_left - r * r_left;
            path.push(Leg::Line { a: current, b: entry });
            path.push(Leg::Arc {
                centre,
                radius: r_left,
                start: (entry - centre).to_angle(),
                sweep: PI / 2.0,
            });
            LaneCursor { pos: exit, dir: -r, lane: 0 }
        }
    }
}

/// Appends one walking leg and the decision at its end.
pub(super) fn plan_pedestrian(
    grid: &RoadGrid,
    cfg: &ScenarioConfig,
    rng: &mut ChaCha12Rng,
    brain: &mut PedBrain,
    path: &mut Path,
) {
    let p_cfg = &cfg.pedestrian;
    let side = grid.ring_side_m();
    let start = path.end_point().unwrap_or_else(|| grid.ring_point(brain.cursor.block, brain.cursor.p));
    let cursor = &mut brain.cursor;
    let p = cursor.p;
    let k = (p / side).floor();
    let mut to_corner = if cursor.dir > 0.0 { (k + 1.0) * side - p } else { p - k * side };
    if to_corner < AT_CORNER_M {
        to_corner += side;
    }

    // Occasionally change pace for the coming leg.
    if rng.random_bool(p_cfg.walker.pace_change_probability) {
        let speed = if rng.random_bool(p_cfg.hurry_probability) {
            uniform(rng, p_cfg.hurry_speed_mps)
        } else {
            uniform(rng, p_cfg.desired_speed_mps)
        };
        path.add_mark(Mark { s: path.end_s(), kind: MarkKind::SetSpeed { speed_mps: speed } });
    }

    let leg = uniform(rng, p_cfg.leg_length_m);
    if leg < to_corner - MIN_LEG_BEFORE_CORNER_M {
        walk_along_block(grid, p_cfg, rng, cursor, path, start, leg);
    } else {
        walk_to_corner(grid, p_cfg, rng, cursor, path, start, to_corner);
    }
}

/// Appends a leg of `leg` metres along the block's sidewalk from `start` (ending off the centre
/// of the sidewalk) and what the pedestrian does at its end: wait, turn around, cross the road
/// mid-block, or walk on.
fn walk_along_block(
    grid: &RoadGrid,
    p_cfg: &PedestrianConfig,
    rng: &mut ChaCha12Rng,
    cursor: &mut WalkCursor,
    path: &mut Path,
    start: DVec2,
    leg: f64,
) {
    let w = &p_cfg.walker;
    let jitter_width = w.waypoint_jitter_fraction * grid.sidewalk_half_width_m;
    let p = cursor.p;
    cursor.p = (p + cursor.dir * leg).rem_euclid(grid.ring_length_m());
    let waypoint = grid.ring_point(cursor.block, cursor.p)
        + grid.ring_outward(cursor.p) * rng.random_range(-jitter_width..=jitter_width);
    path.push(Leg::Line { a: start, b: waypoint });
    let u: f64 = rng.random();
    let stop = p_cfg.stop_probability;
    let turn = stop + p_cfg.turn_around_probability;
    let cross = turn + p_cfg.mid_block_crossing_probability;
    if u < stop {
        let duration_s = uniform(rng, p_cfg.stop_duration_s);
        path.add_mark(Mark { s: path.end_s(), kind: MarkKind::Wait { duration_s } });
    } else if u < turn {
        cursor.dir = -cursor.dir;
    } else if u < cross {
        // Cross the adjacent road straight over to the facing block.
        let out = grid.ring_outward(cursor.p);
        let here = grid.ring_point(cursor.block, cursor.p);
        let spread = w.crossing_spread_m;
        let across = here + out * (2.0 * grid.sidewalk_m) + out.perp() * rng.random_range(-spread..=spread);
        if rng.random_bool(w.kerb_wait_probability) {
            let duration_s = uniform(rng, w.kerb_wait_s);
            path.add_mark(Mark { s: path.end_s(), kind: MarkKind::Wait { duration_s } });
        }
        path.push(Leg::Line { a: waypoint, b: across });
        cursor.block = grid.block_of(across);
        cursor.p = grid.ring_project(cursor.block, across);
        cursor.dir = if coin(rng) { 1.0 } else { -1.0 };
    }
}

/// Appends the walk from `start` to the corner `to_corner` metres ahead and what the pedestrian
/// does there: cross on the crosswalk of one of the two roads, turn around, or walk on round the
/// corner.
fn walk_to_corner(
    grid: &RoadGrid,
    p_cfg: &PedestrianConfig,
    rng: &mut ChaCha12Rng,
    cursor: &mut WalkCursor,
    path: &mut Path,
    start: DVec2,
    to_corner: f64,
) {
    let side = grid.ring_side_m();
    let ring = grid.ring_length_m();
    let p = cursor.p;
    cursor.p = (((p + cursor.dir * to_corner) / side).round() * side).rem_euclid(ring);
    let corner = grid.ring_point(cursor.block, cursor.p);
    let jitter = p_cfg.walker.corner_jitter_m;
    let waypoint =
        corner + DVec2::new(rng.random_range(-jitter..=jitter), rng.random_range(-jitter..=jitter));
    path.push(Leg::Line { a: start, b: waypoint });
    let u: f64 = rng.random();
    if u < p_cfg.crosswalk_probability {
        // The two roads meeting at this corner lie along the outward normals of the two sides.
        let before = grid.ring_outward((cursor.p - 0.5 * side).rem_euclid(ring));
        let after = grid.ring_outward((cursor.p + 0.5 * side).rem_euclid(ring));
        let v = if coin(rng) { before } else { after };
        let crossing_m = 2.0 * grid.sidewalk_m;
        let target = corner + v * crossing_m;
        let junction = grid.nearest_junction(corner + v * grid.sidewalk_m);
        path.add_mark(Mark {
            s: path.end_s(),
            kind: MarkKind::Crosswalk { junction, axis: Axis::of(v), length_m: crossing_m },
        });
        path.push(Leg::Line { a: waypoint, b: target });
        cursor.block = grid.block_of(target);
        cursor.p = (grid.ring_project(cursor.block, target) / side).round() * side % ring;
        let forward = grid.ring_tangent(cursor.p);
        let backward = -grid.ring_tangent((cursor.p - TANGENT_PROBE_M).rem_euclid(ring));
        cursor.dir = if forward.dot(v) > ALONG_COS {
            1.0
        } else if backward.dot(v) > ALONG_COS {
            -1.0
        } else if coin(rng) {
            1.0
        } else {
            -1.0
        };
    } else if u < p_cfg.crosswalk_probability
        + (1.0 - p_cfg.crosswalk_probability) * p_cfg.walker.corner_turn_around_fraction
    {
        cursor.dir = -cursor.dir;
    }
}
