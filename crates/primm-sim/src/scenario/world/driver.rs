//! The driver model of cars and the ego vehicle: pure-pursuit steering along the planned
//! route, the intelligent driver model for the speed (cruise speed, curves, the object ahead,
//! red signals, giving way at junctions without signals) and the behaviour updates (new
//! cruise speeds, passed stop lines, replanning). Its constants are `car.driver`.

use glam::DVec2;

use super::super::config::{CarConfig, DriverConfig, ScenarioConfig};
use super::super::kinematics::wrap_angle;
use super::super::path::{MarkKind, Path};
use super::super::road::{Axis, JunctionId};
use super::routes::plan_car;
use super::{uniform, Agent, Env, World, CAR_PLAN_AHEAD_M};
use primm_core::measurement::ObjectClass;

/// Floor of the distance to the pure-pursuit target, metres (keeps the steering law finite).
const MIN_PURSUIT_DISTANCE_M: f64 = 0.1;
/// Floor of the cruise speed in the free-road term, m/s (keeps it finite at standstill).
const MIN_DESIRED_SPEED_MPS: f64 = 0.1;
/// Floor of the gap to the object ahead in the interaction term, metres.
const MIN_GAP_M: f64 = 0.2;
/// Floor of the distance to a stop line in the needed-deceleration estimate, metres.
const MIN_STOP_DISTANCE_M: f64 = 0.1;
/// Exponent of the free-road term of the intelligent driver model.
const ACCELERATION_EXPONENT: i32 = 4;
/// Marks are dropped once the vehicle's front is this far past them, metres.
const PASSED_MARK_M: f64 = 1.0;
/// Path legs are kept this long behind the vehicle, metres.
const PATH_KEEP_M: f64 = 20.0;

/// Position on a lane used for route planning.
#[derive(Debug, Clone, Copy)]
pub(super) struct LaneCursor {
    /// Point on the lane centre.
    pub pos: DVec2,
    /// Axis-aligned travel direction.
    pub dir: DVec2,
    pub lane: u32,
}

/// The planning state of a car.
#[derive(Debug, Clone)]
pub(super) struct CarBrain {
    /// Where the planned route ends.
    pub cursor: LaneCursor,
    /// Current cruise speed, m/s.
    pub desired_speed: f64,
    /// When the cruise speed is drawn anew, seconds.
    pub next_speed_change: f64,
}

/// Where a car is on its path.
#[derive(Debug, Clone, Copy)]
pub(super) struct Progress {
    /// Path coordinate of the centre, metres.
    pub s: f64,
    /// Length of the vehicle, metres.
    pub length: f64,
    pub is_ego: bool,
}

/// Caps an initial speed so that the curves of `path` within `car.driver.start_curve_preview_m`
/// can be taken with comfortable braking.
pub(super) fn feasible_start_speed(cfg: &ScenarioConfig, path: &Path, speed: f64) -> f64 {
    let c = &cfg.car;
    path.arcs_ahead(0.0, c.driver.start_curve_preview_m)
        .map(|(d, radius)| {
            let vc2 = c.curve_lateral_acceleration_mps2 * radius;
            (vc2 + 2.0 * c.comfortable_deceleration_mps2 * d).sqrt()
        })
        .fold(speed, f64::min)
}

/// Pure-pursuit yaw rate towards the point of the path one look-ahead distance ahead.
fn pursuit_yaw_rate(d: &DriverConfig, me: &Agent) -> f64 {
    let v = me.kin.speed;
    let position = me.kin.position;
    let heading = me.kin.direction();
    let look = (d.lookahead_per_speed_s * v + d.lookahead_base_m).clamp(d.min_lookahead_m, d.max_lookahead_m);
    let target = me.path.point_at(me.s + look).unwrap_or(position + heading * look);
    let to = target - position;
    let distance = to.length().max(MIN_PURSUIT_DISTANCE_M);
    let alpha = wrap_angle(to.to_angle() - me.kin.heading);
    v * 2.0 * alpha.sin() / distance
}

/// The cruise speed capped by the curve the vehicle is in (m/s), and the deceleration needed
/// for the curves ahead (m/s²; infinite when none needs braking).
fn curve_limits(c: &CarConfig, me: &Agent, desired_speed: f64) -> (f64, f64) {
    let v = me.kin.speed;
    let mut v0 = desired_speed;
    let mut curve_accel = f64::INFINITY;
    for (d, radius) in me.path.arcs_ahead(me.s, c.driver.curve_preview_m) {
        let vc = (c.curve_lateral_acceleration_mps2 * radius).sqrt();
        if d <= 0.0 {
            v0 = v0.min(vc);
        } else if v > vc {
            curve_accel = curve_accel.min((vc * vc - v * v) / (2.0 * d));
        }
    }
    (v0, curve_accel)
}

/// The interaction term of the intelligent driver model for an obstacle `gap` metres ahead
/// moving at `v_lead` m/s, for a vehicle at speed `v`.
fn interaction_term(c: &CarConfig, v: f64, gap: f64, v_lead: f64) -> f64 {
    let (a, b) = (c.comfortable_acceleration_mps2, c.comfortable_deceleration_mps2);
    let dynamic = v * c.time_headway_s + v * (v - v_lead) / (2.0 * (a * b).sqrt());
    let s_star = c.standstill_gap_m + dynamic.max(0.0);
    (s_star / gap.max(MIN_GAP_M)).powi(2)
}

impl World<'_> {
    /// The commanded acceleration and yaw rate of car `i`.
    pub(super) fn car_control(&self, i: usize, brain: &CarBrain) -> (f64, f64) {
        let me = &self.agents[i];
        let c = &self.cfg.car;
        let v = me.kin.speed;
        let yaw_rate = pursuit_yaw_rate(&c.driver, me);

        // Intelligent driver model.
        let (v0, curve_accel) = curve_limits(c, me, brain.desired_speed);
        let a = c.comfortable_acceleration_mps2;
        let free = a * (1.0 - (v / v0.max(MIN_DESIRED_SPEED_MPS)).powi(ACCELERATION_EXPONENT));
        let mut interaction: f64 = 0.0;
        for (gap, v_lead) in self.obstacles_ahead(i) {
            interaction = interaction.max(interaction_term(c, v, gap, v_lead));
        }
        if let Some(d) = self.stop_line_to_stop_at(i) {
            interaction = interaction.max(interaction_term(c, v, d, 0.0));
        }
        let accel = (free - a * interaction).min(curve_accel);
        (accel, yaw_rate)
    }

    /// The objects in the path of car `i` within `car.driver.interaction_range_m`, in agent
    /// order: the gap to each (metres) and its speed along the car's heading (m/s).
    fn obstacles_ahead(&self, i: usize) -> impl Iterator<Item = (f64, f64)> + '_ {
        let me = &self.agents[i];
        let d = &self.cfg.car.driver;
        let position = me.kin.position;
        let heading = me.kin.direction();
        self.agents.iter().enumerate().filter_map(move |(j, other)| {
            if j == i {
                return None;
            }
            let rel = other.kin.position - position;
            if rel.length_squared() > d.interaction_range_m * d.interaction_range_m {
                return None;
            }
            let lon = rel.dot(heading);
            if lon <= 0.0 {
                return None;
            }
            let on_path = me.path.point_at(me.s + lon).unwrap_or(position + heading * lon);
            let lateral = other.kin.position.distance(on_path);
            let margin = if other.class == ObjectClass::Pedestrian {
                d.pedestrian_lateral_margin_m
            } else {
                d.vehicle_lateral_margin_m
            };
            if lateral > me.width / 2.0 + other.width / 2.0 + margin {
                return None;
            }
            let dh = other.kin.heading - me.kin.heading;
            let extent = other.length / 2.0 * dh.cos().abs() + other.width / 2.0 * dh.sin().abs();
            let gap = lon - me.length / 2.0 - extent;
            let v_lead = other.kin.velocity().dot(heading).max(0.0);
            Some((gap, v_lead))
        })
    }

    /// Junctions: the distance to the next stop line (metres) when car `i` stops there, for a
    /// red signal or, where there is no signal, for crossing traffic that gets there first;
    /// unless it is too close to stop comfortably.
    fn stop_line_to_stop_at(&self, i: usize) -> Option<f64> {
        let me = &self.agents[i];
        let c = &self.cfg.car;
        let v = me.kin.speed;
        let (junction, axis, d) = self.next_stop_line(me)?;
        let must_stop = if self.grid.is_signalised(junction) {
            !self.grid.is_green(junction, axis, self.t)
        } else {
            self.must_give_way(i, junction, axis, d)
        };
        if d > 0.0 && must_stop {
            let needed = v * v / (2.0 * d.max(MIN_STOP_DISTANCE_M));
            let b = c.comfortable_deceleration_mps2;
            if needed <= c.driver.max_stop_deceleration_factor * b || v < c.driver.always_stop_below_speed_mps
            {
                return Some(d);
            }
        }
        None
    }

    /// The next stop line on the path of a vehicle: junction, travel axis, and the distance
    /// from the vehicle's front to the line (metres).
    fn next_stop_line(&self, agent: &Agent) -> Option<(JunctionId, Axis, f64)> {
        agent.path.marks.iter().find_map(|m| match m.kind {
            MarkKind::StopLine { junction, axis } => {
                Some((junction, axis, m.s - (agent.s + agent.length / 2.0)))
            }
            _ => None,
        })
    }

    /// First come, first served at a junction without signals: vehicle `i`, `distance` before
    /// its stop line on `axis`, gives way to vehicles inside the junction area that travel
    /// along the other axis, and to crossing vehicles that will reach the junction sooner
    /// (ties go to the lower id).
    fn must_give_way(&self, i: usize, junction: JunctionId, axis: Axis, distance: f64) -> bool {
        let me = &self.agents[i];
        let d = &self.cfg.car.driver;
        let centre = self.grid.junction_centre(junction);
        let box_half = self.grid.half_road_m + d.give_way_box_margin_m;
        let my_eta =
            (distance.max(0.0) + self.grid.stop_distance_m) / me.kin.speed.max(d.min_arrival_speed_mps);
        self.agents.iter().enumerate().any(|(j, other)| {
            if j == i || other.class == ObjectClass::Pedestrian {
                return false;
            }
            let rel = (other.kin.position - centre).abs();
            if rel.x < box_half && rel.y < box_half {
                // Inside the junction: wait unless it drives along with us.
                return Axis::of(other.kin.direction()) != axis
                    || other.kin.speed < d.give_way_stopped_speed_mps;
            }
            match self.next_stop_line(other) {
                Some((their_junction, their_axis, their_distance))
                    if their_junction == junction
                        && their_axis != axis
                        && their_distance > -d.give_way_overshoot_m
                        && their_distance < d.give_way_horizon_m =>
                {
                    let eta = (their_distance.max(0.0) + self.grid.stop_distance_m)
                        / other.kin.speed.max(d.min_arrival_speed_mps);
                    eta < my_eta || (eta == my_eta && other.id < me.id)
                }
                _ => false,
            }
        })
    }
}

/// The behaviour update of a car at `progress` on `path`: a new cruise speed when due, passed
/// marks dropped, the route planned on to the planning horizon, walked legs pruned.
pub(super) fn update_car(env: &mut Env<'_>, brain: &mut CarBrain, path: &mut Path, progress: Progress) {
    let cfg = env.cfg;
    let t = env.t;
    if t >= brain.next_speed_change {
        let range = if progress.is_ego { cfg.ego.desired_speed_mps } else { cfg.car.desired_speed_mps };
        brain.desired_speed = uniform(env.rng, range);
        brain.next_speed_change = t + uniform(env.rng, cfg.car.speed_change_interval_s);
    }
    let front = progress.s + progress.length / 2.0;
    while path.marks.front().is_some_and(|m| m.s < front - PASSED_MARK_M) {
        path.marks.pop_front();
    }
    while path.end_s() - progress.s < CAR_PLAN_AHEAD_M {
        plan_car(env.grid, cfg, env.rng, brain, path, progress.is_ego);
    }
    path.prune(progress.s, PATH_KEEP_M);
}
