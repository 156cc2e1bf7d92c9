//! The traffic simulation: the ego vehicle, cars and pedestrians moving on the road grid.
//!
//! Cars follow lanes with a pure-pursuit steering law and an intelligent-driver-model speed law
//! (free-road acceleration towards a cruise speed, braking for the object ahead, for red signals
//! and for curves). Their routes are planned junction by junction: straight on, right or left
//! turn (with the lane change a turn needs), and random lane changes mid-block. Pedestrians walk
//! the sidewalk rings around blocks with random leg lengths, stop, turn around, cross on
//! signalised crosswalks or mid-block, and may walk in groups. All motion goes through
//! [`Kinematics::step`], which enforces the hard limits of the configuration.

use std::f64::consts::PI;

use glam::DVec2;
use rand::Rng;
use rand_chacha::ChaCha12Rng;
use rand_distr::{Distribution, Normal};

use super::config::{CarConfig, Interval, PedestrianConfig, ScenarioConfig};
use super::kinematics::{wrap_angle, Kinematics, Limits};
use super::path::{Leg, Mark, MarkKind, Path};
use super::road::{right_of, Axis, JunctionId, RoadGrid};
use crate::io::EgoPose;
use primm_core::measurement::ObjectClass;

/// Identity used for the ego vehicle, which is never reported as an object.
pub(crate) const EGO_ID: u64 = u64::MAX;

/// Planning horizon of car routes, metres.
const CAR_PLAN_AHEAD_M: f64 = 130.0;
/// Planning horizon of pedestrian paths, metres.
const PED_PLAN_AHEAD_M: f64 = 25.0;
/// Interval between population checks, seconds.
const POPULATION_INTERVAL_S: f64 = 0.25;

fn uniform(rng: &mut ChaCha12Rng, interval: Interval) -> f64 {
    if interval[1] > interval[0] {
        rng.random_range(interval[0]..=interval[1])
    } else {
        interval[0]
    }
}

/// Caps an initial speed so that the first curve of `path` can be taken with comfortable
/// braking.
fn feasible_start_speed(cfg: &ScenarioConfig, path: &Path, speed: f64) -> f64 {
    let c = &cfg.car;
    path.arcs_ahead(0.0, 250.0)
        .map(|(d, radius)| {
            let vc2 = c.curve_lateral_acceleration_mps2 * radius;
            (vc2 + 2.0 * c.comfortable_deceleration_mps2 * d).sqrt()
        })
        .fold(speed, f64::min)
}

/// Position on a lane used for route planning.
#[derive(Debug, Clone, Copy)]
struct LaneCursor {
    /// Point on the lane centre.
    pos: DVec2,
    /// Axis-aligned travel direction.
    dir: DVec2,
    lane: u32,
}

#[derive(Debug, Clone)]
struct CarBrain {
    cursor: LaneCursor,
    desired_speed: f64,
    next_speed_change: f64,
}

/// Position on a block's sidewalk ring used for walk planning.
#[derive(Debug, Clone, Copy)]
struct WalkCursor {
    block: (i64, i64),
    p: f64,
    dir: f64,
}

#[derive(Debug, Clone, Copy)]
struct Follow {
    leader: u64,
    /// Offset in the leader's frame (x forward, y left), metres.
    offset: DVec2,
}

#[derive(Debug, Clone)]
struct PedBrain {
    cursor: WalkCursor,
    speed: f64,
    wander: f64,
    wait_until: f64,
    follow: Option<Follow>,
}

#[derive(Debug, Clone)]
enum Brain {
    Car(CarBrain),
    Pedestrian(PedBrain),
}

/// One simulated road user.
#[derive(Debug, Clone)]
pub(crate) struct Agent {
    pub id: u64,
    pub class: ObjectClass,
    pub is_ego: bool,
    pub length: f64,
    pub width: f64,
    pub kin: Kinematics,
    path: Path,
    s: f64,
    brain: Brain,
}

impl Agent {
    /// Corners of the object's box, counter-clockwise from rear right.
    pub(crate) fn corners(&self) -> [DVec2; 4] {
        let f = self.kin.direction() * (self.length / 2.0);
        let l = self.kin.direction().perp() * (self.width / 2.0);
        let c = self.kin.position;
        [c - f - l, c + f - l, c + f + l, c - f + l]
    }
}

/// The simulated world.
#[derive(Debug)]
pub(crate) struct World<'c> {
    cfg: &'c ScenarioConfig,
    pub grid: RoadGrid,
    pub t: f64,
    /// All agents; index 0 is the ego vehicle.
    pub agents: Vec<Agent>,
    next_id: u64,
    rng: ChaCha12Rng,
    car_limits: Limits,
    ped_limits: Limits,
    next_population_check: f64,
}

impl<'c> World<'c> {
    /// A new world with the ego vehicle and an initial population.
    pub(crate) fn new(cfg: &'c ScenarioConfig, mut rng: ChaCha12Rng) -> Self {
        let grid = RoadGrid::new(cfg, rng.random());
        let c = &cfg.car;
        let p = &cfg.pedestrian;
        let car_limits = Limits {
            max_speed: c.max_speed_mps,
            max_accel: c.max_acceleration_mps2,
            max_decel: c.max_deceleration_mps2,
            max_jerk: c.max_jerk_mps3,
            max_yaw_rate: c.max_yaw_rate_radps,
            max_yaw_accel: c.max_yaw_acceleration_radps2,
            max_lateral_accel: c.max_lateral_acceleration_mps2,
            stop_taper: c.stop_taper_s,
        };
        let ped_limits = Limits {
            max_speed: p.max_speed_mps,
            max_accel: p.max_acceleration_mps2,
            max_decel: p.max_deceleration_mps2,
            max_jerk: p.max_jerk_mps3,
            max_yaw_rate: p.max_yaw_rate_radps,
            max_yaw_accel: p.max_yaw_acceleration_radps2,
            max_lateral_accel: f64::INFINITY,
            stop_taper: 0.3,
        };
        let mut world = Self {
            cfg,
            grid,
            t: 0.0,
            agents: Vec::new(),
            next_id: 0,
            rng,
            car_limits,
            ped_limits,
            next_population_check: 0.0,
        };
        world.spawn_ego();
        world.maintain_population(true);
        world
    }

    /// The ego vehicle.
    pub(crate) fn ego(&self) -> &Agent {
        &self.agents[0]
    }

    /// Pose of the ego vehicle's reference point (rear axle centre).
    pub(crate) fn ego_pose(&self) -> EgoPose {
        let ego = self.ego();
        let rear = ego.kin.position - ego.kin.direction() * self.cfg.ego.rear_axle_to_centre_m;
        EgoPose { x_m: rear.x, y_m: rear.y, yaw_rad: ego.kin.heading }
    }

    /// Runs the simulation up to time `t_end`.
    pub(crate) fn advance_to(&mut self, t_end: f64) {
        while t_end - self.t > 1e-9 {
            let dt = (t_end - self.t).min(self.cfg.sequence.max_step_s);
            self.step(dt);
        }
    }

    fn step(&mut self, dt: f64) {
        let controls: Vec<(f64, f64)> = (0..self.agents.len()).map(|i| self.control(i)).collect();
        for (agent, (accel, yaw_rate)) in self.agents.iter_mut().zip(controls) {
            let limits = match agent.class {
                ObjectClass::Pedestrian => &self.ped_limits,
                _ => &self.car_limits,
            };
            agent.kin.step(accel, yaw_rate, dt, limits);
            let reach = if agent.class == ObjectClass::Pedestrian { 0.35 } else { 0.0 };
            agent.s = agent.path.advance(agent.s, agent.kin.position, reach);
        }
        self.t += dt;
        for i in 0..self.agents.len() {
            self.update_behaviour(i, dt);
        }
        if self.t >= self.next_population_check {
            self.maintain_population(false);
            self.next_population_check = self.t + POPULATION_INTERVAL_S;
        }
    }

    // --------------------------------------------------------------------------------------------
    // Control laws

    fn control(&self, i: usize) -> (f64, f64) {
        match &self.agents[i].brain {
            Brain::Car(brain) => self.car_control(i, brain),
            Brain::Pedestrian(brain) => self.ped_control(i, brain),
        }
    }

    fn car_control(&self, i: usize, brain: &CarBrain) -> (f64, f64) {
        let me = &self.agents[i];
        let c = &self.cfg.car;
        let v = me.kin.speed;
        let position = me.kin.position;
        let heading = me.kin.direction();

        // Pure pursuit on the planned path.
        let look = (0.7 * v + 2.5).clamp(3.5, 18.0);
        let target = me.path.point_at(me.s + look).unwrap_or(position + heading * look);
        let to = target - position;
        let distance = to.length().max(0.1);
        let alpha = wrap_angle(to.to_angle() - me.kin.heading);
        let yaw_rate = v * 2.0 * alpha.sin() / distance;

        // Intelligent driver model.
        let mut v0 = brain.desired_speed;
        let mut curve_accel = f64::INFINITY;
        for (d, radius) in me.path.arcs_ahead(me.s, 60.0) {
            let vc = (c.curve_lateral_acceleration_mps2 * radius).sqrt();
            if d <= 0.0 {
                v0 = v0.min(vc);
            } else if v > vc {
                curve_accel = curve_accel.min((vc * vc - v * v) / (2.0 * d));
            }
        }
        let a = c.comfortable_acceleration_mps2;
        let b = c.comfortable_deceleration_mps2;
        let free = a * (1.0 - (v / v0.max(0.1)).powi(4));
        let mut interaction: f64 = 0.0;
        let mut consider = |gap: f64, v_lead: f64| {
            let dynamic = v * c.time_headway_s + v * (v - v_lead) / (2.0 * (a * b).sqrt());
            let s_star = c.standstill_gap_m + dynamic.max(0.0);
            interaction = interaction.max((s_star / gap.max(0.2)).powi(2));
        };
        for (j, other) in self.agents.iter().enumerate() {
            if j == i {
                continue;
            }
            let rel = other.kin.position - position;
            if rel.length_squared() > 55.0 * 55.0 {
                continue;
            }
            let lon = rel.dot(heading);
            if lon <= 0.0 {
                continue;
            }
            let on_path = me.path.point_at(me.s + lon).unwrap_or(position + heading * lon);
            let lateral = other.kin.position.distance(on_path);
            let margin = if other.class == ObjectClass::Pedestrian { 0.9 } else { 0.3 };
            if lateral > me.width / 2.0 + other.width / 2.0 + margin {
                continue;
            }
            let dh = other.kin.heading - me.kin.heading;
            let extent = other.length / 2.0 * dh.cos().abs() + other.width / 2.0 * dh.sin().abs();
            let gap = lon - me.length / 2.0 - extent;
            let v_lead = other.kin.velocity().dot(heading).max(0.0);
            consider(gap, v_lead);
        }
        // Junctions: stop at the next stop line for a red signal, or, where there is no
        // signal, for crossing traffic that gets there first; unless too close to stop
        // comfortably.
        if let Some((junction, axis, d)) = self.next_stop_line(me) {
            let must_stop = if self.grid.is_signalised(junction) {
                !self.grid.is_green(junction, axis, self.t)
            } else {
                self.must_give_way(i, junction, axis, d)
            };
            if d > 0.0 && must_stop {
                let needed = v * v / (2.0 * d.max(0.1));
                if needed <= 1.6 * b || v < 0.5 {
                    consider(d, 0.0);
                }
            }
        }
        let accel = (free - a * interaction).min(curve_accel);
        (accel, yaw_rate)
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
        let centre = self.grid.junction_centre(junction);
        let box_half = self.grid.half_road_m + 1.0;
        let my_eta = (distance.max(0.0) + self.grid.stop_distance_m) / me.kin.speed.max(1.0);
        self.agents.iter().enumerate().any(|(j, other)| {
            if j == i || other.class == ObjectClass::Pedestrian {
                return false;
            }
            let rel = (other.kin.position - centre).abs();
            if rel.x < box_half && rel.y < box_half {
                // Inside the junction: wait unless it drives along with us.
                return Axis::of(other.kin.direction()) != axis || other.kin.speed < 0.5;
            }
            match self.next_stop_line(other) {
                Some((their_junction, their_axis, their_distance))
                    if their_junction == junction
                        && their_axis != axis
                        && their_distance > -1.0
                        && their_distance < 30.0 =>
                {
                    let eta =
                        (their_distance.max(0.0) + self.grid.stop_distance_m) / other.kin.speed.max(1.0);
                    eta < my_eta || (eta == my_eta && other.id < me.id)
                }
                _ => false,
            }
        })
    }

    fn ped_control(&self, i: usize, brain: &PedBrain) -> (f64, f64) {
        let me = &self.agents[i];
        let p = &self.cfg.pedestrian;
        let position = me.kin.position;
        let leader =
            brain.follow.and_then(|f| self.agents.iter().find(|a| a.id == f.leader).map(|a| (a, f.offset)));
        let (mut target_speed, desired_heading) = if let Some((leader, offset)) = leader {
            let slot = leader.kin.position + leader.kin.direction().rotate(offset);
            let error = slot - position;
            let along = error.dot(leader.kin.direction());
            let speed = (leader.kin.speed + 0.8 * along).clamp(0.0, 0.95 * p.max_speed_mps);
            let aim = slot + leader.kin.direction() * 1.0;
            let heading = if leader.kin.speed < 0.2 && error.length() < 0.5 {
                me.kin.heading
            } else {
                (aim - position).to_angle()
            };
            (speed, heading)
        } else {
            let waiting = self.t < brain.wait_until;
            let heading = match me.path.lookahead(me.s, 1.2, 1.7) {
                Some(point) if point.distance(position) > 0.05 => {
                    (point - position).to_angle() + brain.wander
                }
                _ => me.kin.heading,
            };
            let mut speed = if waiting { 0.0 } else { brain.speed };
            for mark in &me.path.marks {
                let stop_here = matches!(mark.kind, MarkKind::Wait { .. } | MarkKind::Crosswalk { .. });
                if stop_here {
                    let d = mark.s - me.s;
                    speed = speed.min((2.0 * 0.8 * (d - 0.1).max(0.0)).sqrt());
                    break;
                }
            }
            let remaining = me.path.end_s() - me.s;
            speed = speed.min((2.0 * 0.8 * remaining.max(0.0)).sqrt());
            (speed, heading)
        };
        let error = wrap_angle(desired_heading - me.kin.heading);
        target_speed *= error.cos().max(0.0).powi(2);
        let yaw_rate = 3.0 * error;
        let accel = (target_speed - me.kin.speed) / 0.4;
        (accel, yaw_rate)
    }

    // --------------------------------------------------------------------------------------------
    // Behaviour updates (random decisions, marks, replanning)

    fn update_behaviour(&mut self, i: usize, dt: f64) {
        let t = self.t;
        let cfg = self.cfg;
        let agent = &mut self.agents[i];
        match &mut agent.brain {
            Brain::Car(brain) => {
                if t >= brain.next_speed_change {
                    let range =
                        if agent.is_ego { cfg.ego.desired_speed_mps } else { cfg.car.desired_speed_mps };
                    brain.desired_speed = uniform(&mut self.rng, range);
                    brain.next_speed_change = t + uniform(&mut self.rng, cfg.car.speed_change_interval_s);
                }
                let front = agent.s + agent.length / 2.0;
                while agent.path.marks.front().is_some_and(|m| m.s < front - 1.0) {
                    agent.path.marks.pop_front();
                }
                while agent.path.end_s() - agent.s < CAR_PLAN_AHEAD_M {
                    plan_car(&self.grid, cfg, &mut self.rng, brain, &mut agent.path, agent.is_ego);
                }
                agent.path.prune(agent.s, 20.0);
            }
            Brain::Pedestrian(brain) => {
                if brain.follow.is_some() {
                    return;
                }
                let p = &cfg.pedestrian;
                // Heading wander: Ornstein-Uhlenbeck process.
                let tau = p.heading_wander_time_s;
                let noise = Normal::new(0.0, 1.0).expect("unit normal");
                brain.wander += -brain.wander / tau * dt
                    + p.heading_wander_rad * (2.0 * dt / tau).sqrt() * noise.sample(&mut self.rng);
                brain.wander = brain.wander.clamp(-3.0 * p.heading_wander_rad, 3.0 * p.heading_wander_rad);
                while let Some(mark) = agent.path.marks.front().copied() {
                    let d = mark.s - agent.s;
                    let done = match mark.kind {
                        MarkKind::SetSpeed { speed_mps } => {
                            if d <= 0.05 {
                                brain.speed = speed_mps;
                                true
                            } else {
                                false
                            }
                        }
                        MarkKind::Wait { duration_s } => {
                            if (d < 0.35 && agent.kin.speed < 0.15) || d < -0.5 {
                                brain.wait_until = t + duration_s;
                                true
                            } else {
                                false
                            }
                        }
                        MarkKind::Crosswalk { junction, axis, length_m } => {
                            let needed = 0.6 * length_m / brain.speed.max(0.5);
                            d < -0.5 || (d < 3.0 && self.grid.green_remaining(junction, axis, t) >= needed)
                        }
                        MarkKind::StopLine { .. } => true,
                    };
                    if done {
                        agent.path.marks.pop_front();
                    } else {
                        break;
                    }
                }
                while agent.path.end_s() - agent.s < PED_PLAN_AHEAD_M {
                    plan_pedestrian(&self.grid, cfg, &mut self.rng, brain, &mut agent.path);
                }
                agent.path.prune(agent.s, 5.0);
            }
        }
    }

    // --------------------------------------------------------------------------------------------
    // Population

    fn spawn_ego(&mut self) {
        let cfg = self.cfg;
        let b = self.grid.block_m;
        let dir = [DVec2::X, DVec2::Y, DVec2::NEG_X, DVec2::NEG_Y][self.rng.random_range(0..4)];
        let lane = self.rng.random_range(0..self.grid.lanes);
        let desired = uniform(&mut self.rng, cfg.ego.desired_speed_mps);
        let speed = if self.rng.random_bool(cfg.ego.initial_standstill_probability) {
            0.0
        } else {
            desired * self.rng.random_range(0.7..=1.0)
        };
        // Place the ego so that, when recording starts after the warm-up, it is typically
        // approaching the junction at the end of its block, clear of the junction areas.
        let clear = self.grid.stop_distance_m + 5.0;
        let ahead =
            uniform(&mut self.rng, cfg.ego.start_distance_to_junction_m) + speed * cfg.sequence.warmup_s;
        let along_dir = (b - ahead).clamp(clear, b - clear);
        let along = if dir.x + dir.y > 0.0 { along_dir } else { b - along_dir };
        let axis_point =
            if Axis::of(dir) == Axis::X { DVec2::new(along, 0.0) } else { DVec2::new(0.0, along) };
        let pos = axis_point + right_of(dir) * self.grid.lane_offset(lane);
        let brain = CarBrain {
            cursor: LaneCursor { pos, dir, lane },
            desired_speed: desired,
            next_speed_change: uniform(&mut self.rng, cfg.car.speed_change_interval_s),
        };
        let mut agent = Agent {
            id: EGO_ID,
            class: ObjectClass::Car,
            is_ego: true,
            length: cfg.ego.length_m,
            width: cfg.ego.width_m,
            kin: Kinematics::new(pos, dir.to_angle(), speed),
            path: Path::default(),
            s: 0.0,
            brain: Brain::Car(brain),
        };
        if let Brain::Car(brain) = &mut agent.brain {
            while agent.path.end_s() < CAR_PLAN_AHEAD_M {
                plan_car(&self.grid, cfg, &mut self.rng, brain, &mut agent.path, true);
            }
        }
        agent.kin.speed = feasible_start_speed(cfg, &agent.path, agent.kin.speed);
        self.agents.push(agent);
    }

    /// Whether any sensor could see `point` (fields of view widened by the spawn margins).
    fn in_sensor_coverage(&self, point: DVec2) -> bool {
        let pose = self.ego_pose();
        let margin_deg = self.cfg.traffic.spawn_fov_margin_deg;
        self.cfg.radar.sensors.iter().any(|s| {
            let origin = pose.car_to_world(DVec2::new(s.x_m, s.y_m));
            let rel = point - origin;
            if rel.length() > s.max_range_m + self.cfg.traffic.spawn_range_margin_m {
                return false;
            }
            let boresight = pose.yaw_rad + s.yaw_deg.to_radians();
            let az = wrap_angle(rel.to_angle() - boresight);
            az.abs() <= (s.half_fov_deg + margin_deg).to_radians()
        })
    }

    fn spawn_point_ok(&self, point: DVec2, initial: bool) -> bool {
        let t = &self.cfg.traffic;
        let d = point.distance(self.ego().kin.position);
        if d < t.min_spawn_distance_m || d > t.population_radius_m {
            return false;
        }
        initial || !self.in_sensor_coverage(point)
    }

    fn maintain_population(&mut self, initial: bool) {
        let ego_pos = self.ego().kin.position;
        let despawn = self.cfg.traffic.despawn_radius_m;
        self.agents.retain(|a| a.is_ego || a.kin.position.distance(ego_pos) <= despawn);

        // Group members whose leader left walk on their own.
        let ids: Vec<u64> = self.agents.iter().map(|a| a.id).collect();
        for i in 0..self.agents.len() {
            let orphan = matches!(&self.agents[i].brain, Brain::Pedestrian(PedBrain { follow: Some(f), .. }) if !ids.contains(&f.leader));
            if orphan {
                self.make_independent(i);
            }
        }

        let traffic = &self.cfg.traffic;
        let mut cars = self.agents.iter().filter(|a| !a.is_ego && a.class == ObjectClass::Car).count();
        let mut tries = 0;
        while cars < traffic.car_count as usize && tries < 60 {
            tries += 1;
            if self.try_spawn_car(initial) {
                cars += 1;
            }
        }
        let mut peds = self.agents.iter().filter(|a| a.class == ObjectClass::Pedestrian).count();
        let mut tries = 0;
        while peds < traffic.pedestrian_count as usize && tries < 60 {
            tries += 1;
            peds += self.try_spawn_pedestrians(initial, traffic.pedestrian_count as usize - peds);
        }
    }

    fn try_spawn_car(&mut self, initial: bool) -> bool {
        let cfg = self.cfg;
        let radius = cfg.traffic.population_radius_m;
        let ego = self.ego().kin.position;
        let b = self.grid.block_m;
        let dir = [DVec2::X, DVec2::Y, DVec2::NEG_X, DVec2::NEG_Y][self.rng.random_range(0..4)];
        let lane = self.rng.random_range(0..self.grid.lanes);
        let centre = if Axis::of(dir) == Axis::X {
            let road = ((ego.y + self.rng.random_range(-radius..radius)) / b).round() * b;
            DVec2::new(ego.x + self.rng.random_range(-radius..radius), road)
        } else {
            let road = ((ego.x + self.rng.random_range(-radius..radius)) / b).round() * b;
            DVec2::new(road, ego.y + self.rng.random_range(-radius..radius))
        };
        let pos = centre + right_of(dir) * self.grid.lane_offset(lane);
        if self.grid.near_junction(pos, 3.0) || !self.spawn_point_ok(pos, initial) {
            return false;
        }
        if self
            .agents
            .iter()
            .any(|a| a.class != ObjectClass::Pedestrian && a.kin.position.distance(pos) < 12.0)
        {
            return false;
        }
        let c = &cfg.car;
        let (length, width) = if self.rng.random_bool(c.large_vehicle_probability) {
            (uniform(&mut self.rng, c.large_length_m), uniform(&mut self.rng, c.large_width_m))
        } else {
            (uniform(&mut self.rng, c.length_m), uniform(&mut self.rng, c.width_m))
        };
        let desired = uniform(&mut self.rng, c.desired_speed_mps);
        let speed = desired * self.rng.random_range(0.5..=1.0);
        let mut brain = CarBrain {
            cursor: LaneCursor { pos, dir, lane },
            desired_speed: desired,
            next_speed_change: self.t + uniform(&mut self.rng, c.speed_change_interval_s),
        };
        let mut path = Path::default();
        while path.end_s() < CAR_PLAN_AHEAD_M {
            plan_car(&self.grid, cfg, &mut self.rng, &mut brain, &mut path, false);
        }
        let speed = feasible_start_speed(cfg, &path, speed);
        let id = self.next_id;
        self.next_id += 1;
        self.agents.push(Agent {
            id,
            class: ObjectClass::Car,
            is_ego: false,
            length,
            width,
            kin: Kinematics::new(pos, dir.to_angle(), speed),
            path,
            s: 0.0,
            brain: Brain::Car(brain),
        });
        true
    }

    /// Spawns a pedestrian, possibly with companions (at most `budget` persons); returns how
    /// many were added.
    fn try_spawn_pedestrians(&mut self, initial: bool, budget: usize) -> usize {
        let cfg = self.cfg;
        let radius = cfg.traffic.population_radius_m;
        let ego = self.ego().kin.position;
        let point =
            ego + DVec2::new(self.rng.random_range(-radius..radius), self.rng.random_range(-radius..radius));
        let block = self.grid.block_of(point);
        let mut p = self.grid.ring_project(block, point);
        if self.rng.random_bool(cfg.traffic.pedestrian_corner_spawn_probability) {
            // Street corners are where pedestrians gather and cross.
            let side = self.grid.ring_side_m();
            let corner = (p / side).round() * side;
            let reach = cfg.traffic.corner_spawn_distance_m.min(side / 2.0);
            p = (corner + self.rng.random_range(-reach..=reach)).rem_euclid(self.grid.ring_length_m());
        }
        let dir = if self.rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let lateral = self.rng.random_range(-0.6..=0.6) * self.grid.sidewalk_half_width_m;
        let pos = self.grid.ring_point(block, p) + self.grid.ring_outward(p) * lateral;
        if !self.spawn_point_ok(pos, initial) {
            return 0;
        }
        let heading = (self.grid.ring_tangent(p) * dir).to_angle();
        let mut brain = PedBrain {
            cursor: WalkCursor { block, p, dir },
            speed: self.walking_speed(),
            wander: 0.0,
            wait_until: 0.0,
            follow: None,
        };
        let mut path = Path::default();
        path.push(Leg::Line { a: pos, b: pos + self.grid.ring_tangent(p) * dir * 0.5 });
        brain.cursor.p = (p + dir * 0.5).rem_euclid(self.grid.ring_length_m());
        while path.end_s() < PED_PLAN_AHEAD_M {
            plan_pedestrian(&self.grid, cfg, &mut self.rng, &mut brain, &mut path);
        }
        let speed = if self.rng.random_bool(0.15) { 0.0 } else { brain.speed };
        let group_size = if budget >= 2 && self.rng.random_bool(cfg.traffic.pedestrian_group_probability) {
            self.rng.random_range(2..=cfg.traffic.max_group_size as usize).min(budget)
        } else {
            1
        };
        let leader_id = self.next_id;
        let leader = self.new_pedestrian(pos, heading, speed, path, brain.clone());
        self.agents.push(leader);
        for k in 1..group_size {
            let spacing = uniform(&mut self.rng, cfg.traffic.group_spacing_m);
            let side = if k % 2 == 1 { 1.0 } else { -1.0 };
            let offset =
                DVec2::new(self.rng.random_range(-0.6..=0.3), side * spacing * (k.div_ceil(2)) as f64);
            let member_pos = pos + DVec2::from_angle(heading).rotate(offset);
            let member_brain =
                PedBrain { follow: Some(Follow { leader: leader_id, offset }), ..brain.clone() };
            let member = self.new_pedestrian(member_pos, heading, speed, Path::default(), member_brain);
            self.agents.push(member);
        }
        group_size
    }

    fn new_pedestrian(&mut self, pos: DVec2, heading: f64, speed: f64, path: Path, brain: PedBrain) -> Agent {
        let p = &self.cfg.pedestrian;
        let id = self.next_id;
        self.next_id += 1;
        Agent {
            id,
            class: ObjectClass::Pedestrian,
            is_ego: false,
            length: uniform(&mut self.rng, p.length_m),
            width: uniform(&mut self.rng, p.width_m),
            kin: Kinematics::new(pos, heading, speed),
            path,
            s: 0.0,
            brain: Brain::Pedestrian(brain),
        }
    }

    fn walking_speed(&mut self) -> f64 {
        let p = &self.cfg.pedestrian;
        if self.rng.random_bool(p.hurry_probability) {
            uniform(&mut self.rng, p.hurry_speed_mps)
        } else {
            uniform(&mut self.rng, p.desired_speed_mps)
        }
    }

    fn make_independent(&mut self, i: usize) {
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
                path.push(Leg::Line { a: pos, b: pos + grid.ring_tangent(p) * dir * 0.5 });
                brain.cursor.p = (p + dir * 0.5).rem_euclid(grid.ring_length_m());
            }
            while path.end_s() < PED_PLAN_AHEAD_M {
                plan_pedestrian(&grid, cfg, &mut self.rng, brain, &mut path);
            }
            agent.path = path;
            agent.s = 0.0;
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Route planning

/// Appends the route up to and through the next junction: an optional lane change, the
/// approach with its stop line, and the manoeuvre (straight on, right or left turn); the ego
/// vehicle turns with its own probabilities where configured.
fn plan_car(
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
    let lane_change_m = (cfg.car.lane_change_duration_s * brain.desired_speed.max(5.0)).clamp(15.0, 60.0);
    let mut turn = [cfg.car.turn_left_probability, cfg.car.turn_right_probability];
    if is_ego {
        turn = [
            cfg.ego.turn_left_probability.unwrap_or(turn[0]),
            cfg.ego.turn_right_probability.unwrap_or(turn[1]),
        ];
    }
    let (manoeuvre, target_lane) =
        choose_manoeuvre(grid, &cfg.car, turn, rng, &cursor, junction.distance_m, lane_change_m);
    let current = push_lane_change(grid, path, &cursor, target_lane, lane_change_m);
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
    let lane_change_room = 8.0 + lane_change_m + 5.0;
    let right_entry = dist_j - (grid.lane_offset(outer) + grid.right_turn_radius_m);
    let left_entry = dist_j + grid.lane_offset(0) - grid.left_turn_radius_m;
    let feasible = |entry: f64, lane: u32| entry >= if lane == cursor.lane { 1.0 } else { lane_change_room };

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

/// Appends the change from the cursor's lane to `target_lane` (8 m ahead, over
/// `lane_change_m`), if they differ. Returns where the route continues.
fn push_lane_change(
    grid: &RoadGrid,
    path: &mut Path,
    cursor: &LaneCursor,
    target_lane: u32,
    lane_change_m: f64,
) -> DVec2 {
    let current = cursor.pos;
    if target_lane == cursor.lane {
        return current;
    }
    let d = cursor.dir;
    let start = current + d * 8.0;
    let shift = grid.lane_offset(target_lane) - grid.lane_offset(cursor.lane);
    let end = current + d * (8.0 + lane_change_m) + right_of(d) * shift;
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
            let exit = junction + d * (grid.half_road_m + 1.0) + r * o_in;
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
fn plan_pedestrian(
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
    if to_corner < 0.05 {
        to_corner += side;
    }

    // Occasionally change pace for the coming leg.
    if rng.random_bool(0.3) {
        let speed = if rng.random_bool(p_cfg.hurry_probability) {
            uniform(rng, p_cfg.hurry_speed_mps)
        } else {
            uniform(rng, p_cfg.desired_speed_mps)
        };
        path.add_mark(Mark { s: path.end_s(), kind: MarkKind::SetSpeed { speed_mps: speed } });
    }

    let leg = uniform(rng, p_cfg.leg_length_m);
    if leg < to_corner - 1.0 {
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
    let jitter_width = 0.7 * grid.sidewalk_half_width_m;
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
        let across = here + out * (2.0 * grid.sidewalk_m) + out.perp() * rng.random_range(-1.0..=1.0);
        if rng.random_bool(0.5) {
            let duration_s = rng.random_range(0.5..=2.0);
            path.add_mark(Mark { s: path.end_s(), kind: MarkKind::Wait { duration_s } });
        }
        path.push(Leg::Line { a: waypoint, b: across });
        cursor.block = grid.block_of(across);
        cursor.p = grid.ring_project(cursor.block, across);
        cursor.dir = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
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
    let waypoint = corner + DVec2::new(rng.random_range(-0.3..=0.3), rng.random_range(-0.3..=0.3));
    path.push(Leg::Line { a: start, b: waypoint });
    let u: f64 = rng.random();
    if u < p_cfg.crosswalk_probability {
        // The two roads meeting at this corner lie along the outward normals of the two sides.
        let before = grid.ring_outward((cursor.p - 0.5 * side).rem_euclid(ring));
        let after = grid.ring_outward((cursor.p + 0.5 * side).rem_euclid(ring));
        let v = if rng.random_bool(0.5) { before } else { after };
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
        let backward = -grid.ring_tangent((cursor.p - 0.5).rem_euclid(ring));
        cursor.dir = if forward.dot(v) > 0.5 {
            1.0
        } else if backward.dot(v) > 0.5 {
            -1.0
        } else if rng.random_bool(0.5) {
            1.0
        } else {
            -1.0
        };
    } else if u < p_cfg.crosswalk_probability + (1.0 - p_cfg.crosswalk_probability) * 0.25 {
        cursor.dir = -cursor.dir;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn agents_stay_on_their_infrastructure() {
        for seed in 0..6 {
            check_infrastructure(&ScenarioConfig::default(), 100 + seed);
            check_infrastructure(&ScenarioConfig::robustness(), 200 + seed);
        }
    }

    fn check_infrastructure(cfg: &ScenarioConfig, seed: u64) {
        let mut world = World::new(cfg, ChaCha12Rng::seed_from_u64(seed));
        let grid = world.grid.clone();
        for _ in 0..1500 {
            let t = world.t + 0.02;
            world.advance_to(t);
            for agent in &world.agents {
                let pos = agent.kin.position;
                let b = grid.block_m;
                // Distance to the nearest road centre line along each axis.
                let dx = (pos.x - (pos.x / b).round() * b).abs();
                let dy = (pos.y - (pos.y / b).round() * b).abs();
                let nearest = dx.min(dy);
                // Junction corners have rounded curbs (radius 6 m): turning vehicles may use
                // the area between the rounded curb and the straight road edges.
                let curb_radius = 6.0;
                let c = grid.half_road_m + curb_radius;
                let in_corner = dx < c && dy < c && (c - dx).hypot(c - dy) >= curb_radius - 1.0;
                match agent.class {
                    ObjectClass::Car => assert!(
                        nearest <= grid.half_road_m + 1.0 || in_corner,
                        "seed {seed}: car {} off the road at {pos:?} (t = {}): {:?} {:?}",
                        agent.id,
                        world.t,
                        agent.kin,
                        agent.brain
                    ),
                    _ => {
                        // Pedestrians are on a sidewalk or crossing a road.
                        assert!(
                            nearest <= grid.sidewalk_m + grid.sidewalk_half_width_m + 1.5,
                            "pedestrian {} off the sidewalk at {pos:?}",
                            agent.id
                        );
                    }
                }
            }
        }
    }
}
