//! The walker model of pedestrians: steering and speed control along the planned path or
//! beside a group's leader, stopping at wait points and crosswalks, the heading wander, the
//! marks of the path (new pace, waits, signalised crossings) and replanning. Its constants are
//! `pedestrian.walker`.

use rand_distr::{Distribution, Normal};

use super::super::config::{PedestrianConfig, WalkerConfig};
use super::super::kinematics::wrap_angle;
use super::super::path::{Leg, MarkKind, Path};
use super::routes::{plan_pedestrian, WalkCursor};
use super::{Agent, Brain, Env, World, PED_PLAN_AHEAD_M};
use glam::DVec2;

/// A pedestrian keeps its heading when the point it aims at is closer than this, metres.
const MIN_AIM_DISTANCE_M: f64 = 0.05;
/// A new pace applies once its mark is within this distance, metres.
const SET_SPEED_REACH_M: f64 = 0.05;
/// Path legs are kept this long behind the pedestrian, metres.
const PATH_KEEP_M: f64 = 5.0;
/// A pedestrian that starts walking on its own first walks this far along the sidewalk,
/// metres.
pub(super) const FIRST_LEG_M: f64 = 0.5;

/// A group member's place: the leader and the offset from it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Follow {
    pub leader: u64,
    /// Offset in the leader's frame (x forward, y left), metres.
    pub offset: DVec2,
}

/// The planning and walking state of a pedestrian.
#[derive(Debug, Clone)]
pub(super) struct PedBrain {
    /// Where the planned path ends.
    pub cursor: WalkCursor,
    /// Walking speed, m/s.
    pub speed: f64,
    /// Current heading wander, radians.
    pub wander: f64,
    /// End of the current wait, seconds.
    pub wait_until: f64,
    /// The place in a group, for a member walking beside its leader.
    pub follow: Option<Follow>,
}

/// The speed at which a walker planning to stop `distance` metres ahead (less `stop_short_m`)
/// still stops in time.
fn stopping_speed(w: &WalkerConfig, distance: f64) -> f64 {
    (2.0 * w.stop_deceleration_mps2 * (distance - w.stop_short_m).max(0.0)).sqrt()
}

/// Target speed and heading of a group member beside `leader` at `offset`.
fn follow_target(p: &PedestrianConfig, me: &Agent, leader: &Agent, offset: DVec2) -> (f64, f64) {
    let w = &p.walker;
    let position = me.kin.position;
    let slot = leader.kin.position + leader.kin.direction().rotate(offset);
    let error = slot - position;
    let along = error.dot(leader.kin.direction());
    let speed = (leader.kin.speed + w.group_position_gain_per_s * along)
        .clamp(0.0, w.group_max_speed_fraction * p.limits.max_speed_mps);
    let aim = slot + leader.kin.direction() * w.group_aim_ahead_m;
    let heading =
        if leader.kin.speed < w.group_standing_speed_mps && error.length() < w.group_slot_tolerance_m {
            me.kin.heading
        } else {
            (aim - position).to_angle()
        };
    (speed, heading)
}

/// Target speed and heading of a pedestrian walking its own path at simulation time `t`:
/// towards the path a little ahead, slowing down to stop at the next wait point or crosswalk
/// and at the end of the path.
fn path_target(w: &WalkerConfig, me: &Agent, brain: &PedBrain, t: f64) -> (f64, f64) {
    let position = me.kin.position;
    let waiting = t < brain.wait_until;
    let heading = match me.path.lookahead(me.s, w.path_lookahead_m, w.max_lookahead_turn_rad) {
        Some(point) if point.distance(position) > MIN_AIM_DISTANCE_M => {
            (point - position).to_angle() + brain.wander
        }
        _ => me.kin.heading,
    };
    let mut speed = if waiting { 0.0 } else { brain.speed };
    for mark in &me.path.marks {
        let stop_here = matches!(mark.kind, MarkKind::Wait { .. } | MarkKind::Crosswalk { .. });
        if stop_here {
            let d = mark.s - me.s;
            speed = speed.min(stopping_speed(w, d));
            break;
        }
    }
    let remaining = me.path.end_s() - me.s;
    speed = speed.min((2.0 * w.stop_deceleration_mps2 * remaining.max(0.0)).sqrt());
    (speed, heading)
}

impl World<'_> {
    /// The commanded acceleration and yaw rate of pedestrian `i`.
    pub(super) fn ped_control(&self, i: usize, brain: &PedBrain) -> (f64, f64) {
        let me = &self.agents[i];
        let p = &self.cfg.pedestrian;
        let w = &p.walker;
        let leader =
            brain.follow.and_then(|f| self.agents.iter().find(|a| a.id == f.leader).map(|a| (a, f.offset)));
        let (mut target_speed, desired_heading) = match leader {
            Some((leader, offset)) => follow_target(p, me, leader, offset),
            None => path_target(w, me, brain, self.t),
        };
        let error = wrap_angle(desired_heading - me.kin.heading);
        target_speed *= error.cos().max(0.0).powi(2);
        let yaw_rate = w.heading_gain_per_s * error;
        let accel = (target_speed - me.kin.speed) / w.speed_time_constant_s;
        (accel, yaw_rate)
    }

    /// Makes group member `i` walk on its own: back onto the sidewalk ring, in the direction it
    /// faces, at least at the slowest walking speed.
    pub(super) fn make_independent(&mut self, i: usize) {
        let pos = self.agents[i].kin.position;
        let block = self.grid.block_of(pos);
        let p = self.grid.ring_project(block, pos);
        let along = self.agents[i].kin.direction().dot(self.grid.ring_tangent(p));
        let dir = if along >= 0.0 { 1.0 } else { -1.0 };
        let start = self.grid.ring_point(block, p);
        let cfg = self.cfg;
        let grid = self.grid.clone();
        let agent = &mut self.agents[i];
        if let Brain::Pedestrian(brain) = &mut agent.brain {
            brain.follow = None;
            brain.cursor = WalkCursor { block, p, dir };
            brain.speed = brain.speed.max(cfg.pedestrian.desired_speed_mps[0]);
            let mut path = Path::default();
            path.push(Leg::Line { a: pos, b: start });
            if path.is_empty() {
                path.push(Leg::Line { a: pos, b: pos + grid.ring_tangent(p) * dir * FIRST_LEG_M });
                brain.cursor.p = (p + dir * FIRST_LEG_M).rem_euclid(grid.ring_length_m());
            }
            while path.end_s() < PED_PLAN_AHEAD_M {
                plan_pedestrian(&grid, cfg, &mut self.rng, brain, &mut path);
            }
            agent.path = path;
            agent.s = 0.0;
        }
    }
}

/// The behaviour update of a pedestrian at path coordinate `s` walking at `speed` (m/s): the
/// heading wander, the marks reached, the path planned on to the planning horizon, walked legs
/// pruned. Group members only follow their leader.
pub(super) fn update_pedestrian(
    env: &mut Env<'_>,
    dt: f64,
    brain: &mut PedBrain,
    path: &mut Path,
    s: f64,
    speed: f64,
) {
    if brain.follow.is_some() {
        return;
    }
    let cfg = env.cfg;
    let p = &cfg.pedestrian;
    let w = &p.walker;
    // Heading wander: Ornstein-Uhlenbeck process.
    let tau = p.heading_wander_time_s;
    let noise = Normal::new(0.0, 1.0).expect("unit normal");
    brain.wander += -brain.wander / tau * dt
        + p.heading_wander_rad * (2.0 * dt / tau).sqrt() * noise.sample(&mut *env.rng);
    brain.wander = brain
        .wander
        .clamp(-w.max_wander_sigmas * p.heading_wander_rad, w.max_wander_sigmas * p.heading_wander_rad);
    while let Some(mark) = path.marks.front().copied() {
        if !mark_done(env, brain, mark.kind, mark.s - s, speed) {
            break;
        }
        path.marks.pop_front();
    }
    while path.end_s() - s < PED_PLAN_AHEAD_M {
        plan_pedestrian(env.grid, cfg, env.rng, brain, path);
    }
    path.prune(s, PATH_KEEP_M);
}

/// Whether a pedestrian walking at `speed` (m/s) is done with the mark `d` metres ahead: a new
/// pace once reached, a wait once stopped at it (the wait then starts), a crosswalk once
/// passed or, near it, once the green time left suffices to cross.
fn mark_done(env: &Env<'_>, brain: &mut PedBrain, kind: MarkKind, d: f64, speed: f64) -> bool {
    let w = &env.cfg.pedestrian.walker;
    match kind {
        MarkKind::SetSpeed { speed_mps } => {
            if d <= SET_SPEED_REACH_M {
                brain.speed = speed_mps;
                true
            } else {
                false
            }
        }
        MarkKind::Wait { duration_s } => {
            if (d < w.wait_reach_m && speed < w.wait_speed_mps) || d < -w.passed_mark_m {
                brain.wait_until = env.t + duration_s;
                true
            } else {
                false
            }
        }
        MarkKind::Crosswalk { junction, axis, length_m } => {
            let needed = w.crosswalk_green_fraction * length_m / brain.speed.max(w.crosswalk_min_speed_mps);
            d < -w.passed_mark_m
                || (d < w.crosswalk_decision_m && env.grid.green_remaining(junction, axis, env.t) >= needed)
        }
        MarkKind::StopLine { .. } => true,
    }
}
