//! The population around the ego vehicle: the ego vehicle itself, and cars and pedestrians
//! kept at their configured numbers, appearing unseen after the start and removed far away.

use glam::DVec2;
use rand::Rng;

use super::super::config::EgoPlacement;
use super::super::kinematics::{wrap_angle, Kinematics};
use super::super::path::{Leg, Path};
use super::super::road::{right_of, Axis};
use super::driver::{feasible_start_speed, CarBrain, LaneCursor};
use super::pedestrian::{Follow, PedBrain, FIRST_LEG_M};
use super::routes::{plan_car, plan_pedestrian, WalkCursor};
use super::{coin, uniform, Agent, Brain, World, CAR_PLAN_AHEAD_M, EGO_ID, PED_PLAN_AHEAD_M};
use primm_core::measurement::ObjectClass;

/// The ego vehicle starts at this fraction of its cruise speed (uniform), unless at
/// standstill.
const EGO_START_SPEED_FRACTION: [f64; 2] = [0.7, 1.0];
/// The ego vehicle starts at least this far from the junction areas at both ends of its
/// block, metres.
const EGO_START_CLEARANCE_M: f64 = 5.0;
/// The roadside ego platform stands this far beyond the outer edge of the sidewalk, metres.
const ROADSIDE_SETBACK_M: f64 = 1.0;
/// Largest number of spawn attempts per class and population check.
const SPAWN_TRIES: u32 = 60;
/// Cars never appear within this distance of a junction area, metres…
const CAR_SPAWN_JUNCTION_CLEARANCE_M: f64 = 3.0;
/// …nor closer than this to another vehicle, metres.
const CAR_SPAWN_SPACING_M: f64 = 12.0;
/// A new car starts at this fraction of its cruise speed (uniform).
const CAR_START_SPEED_FRACTION: [f64; 2] = [0.5, 1.0];
/// A new pedestrian appears within ± this fraction of the sidewalk's half width of its
/// centre line.
const PED_SPAWN_LATERAL_FRACTION: f64 = 0.6;
/// Probability that a new pedestrian (and its group) starts standing.
const PED_START_STANDING_PROBABILITY: f64 = 0.15;
/// A group member's place lies up to this far behind its leader, metres…
const GROUP_MAX_BEHIND_M: f64 = 0.6;
/// …or up to this far ahead of it, metres.
const GROUP_MAX_AHEAD_M: f64 = 0.3;

impl World<'_> {
    /// Places the ego vehicle: on a random lane of the road grid with its route planned, or,
    /// with `ego.placement = "roadside"`, beside a junction ([`World::spawn_roadside_ego`]).
    pub(super) fn spawn_ego(&mut self) {
        if self.cfg.ego.placement == EgoPlacement::Roadside {
            self.spawn_roadside_ego();
            return;
        }
        let cfg = self.cfg;
        let b = self.grid.block_m;
        let dir = [DVec2::X, DVec2::Y, DVec2::NEG_X, DVec2::NEG_Y][self.rng.random_range(0..4)];
        let lane = self.rng.random_range(0..self.grid.lanes);
        let desired = uniform(&mut self.rng, cfg.ego.desired_speed_mps);
        let speed = if self.rng.random_bool(cfg.ego.initial_standstill_probability) {
            0.0
        } else {
            desired * self.rng.random_range(EGO_START_SPEED_FRACTION[0]..=EGO_START_SPEED_FRACTION[1])
        };
        // Place the ego so that, when recording starts after the warm-up, it is typically
        // approaching the junction at the end of its block, clear of the junction areas.
        let clear = self.grid.stop_distance_m + EGO_START_CLEARANCE_M;
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

    /// The roadside ego platform: at rest for good, `ROADSIDE_SETBACK_M` beyond the outer edge
    /// of the sidewalk at a random corner of junction (0, 0), facing the junction centre, so
    /// that its reference point (the rear axle) lies on that corner's diagonal.
    fn spawn_roadside_ego(&mut self) {
        let cfg = self.cfg;
        let corner =
            [DVec2::new(1.0, 1.0), DVec2::new(-1.0, 1.0), DVec2::new(-1.0, -1.0), DVec2::new(1.0, -1.0)]
                [self.rng.random_range(0..4)];
        let reference =
            corner * (self.grid.sidewalk_m + self.grid.sidewalk_half_width_m + ROADSIDE_SETBACK_M);
        let heading = -corner.normalize();
        let pos = reference + heading * cfg.ego.rear_axle_to_centre_m;
        self.agents.push(Agent {
            id: EGO_ID,
            class: ObjectClass::Car,
            is_ego: true,
            length: cfg.ego.length_m,
            width: cfg.ego.width_m,
            kin: Kinematics::new(pos, heading.to_angle(), 0.0),
            path: Path::default(),
            s: 0.0,
            brain: Brain::Stationary,
        });
    }

    /// Whether any sensor could see `point` (fields of view widened by the spawn margins).
    fn in_sensor_coverage(&self, point: DVec2) -> bool {
        let pose = self.ego_pose();
        let margin_deg = self.cfg.traffic.spawn_fov_margin_deg;
        self.cfg.radar.sensors.iter().any(|sensor| {
            let s = &sensor.layout;
            let origin = pose.point_to_world(s.position());
            let rel = point - origin;
            if rel.length() > s.max_range_m + self.cfg.traffic.spawn_range_margin_m {
                return false;
            }
            let boresight = pose.yaw_rad + s.yaw_rad;
            let az = wrap_angle(rel.to_angle() - boresight);
            // The margin is given in degrees: the field of view is widened in degrees.
            az.abs() <= (s.half_fov_rad.to_degrees() + margin_deg).to_radians()
        })
    }

    /// Whether an object may appear at `point`: within the population radius, not too close
    /// to the ego vehicle and, after the start, unseen.
    fn spawn_point_ok(&self, point: DVec2, initial: bool) -> bool {
        let t = &self.cfg.traffic;
        let d = point.distance(self.ego().kin.position);
        if d < t.min_spawn_distance_m || d > t.population_radius_m {
            return false;
        }
        initial || !self.in_sensor_coverage(point)
    }

    /// Removes the objects beyond `traffic.despawn_radius_m`, lets orphaned group members walk
    /// on their own, and spawns cars and pedestrians up to their counts (at the start
    /// anywhere, later only where no sensor sees them appear).
    pub(super) fn maintain_population(&mut self, initial: bool) {
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
        while cars < traffic.car_count as usize && tries < SPAWN_TRIES {
            tries += 1;
            if self.try_spawn_car(initial) {
                cars += 1;
            }
        }
        let mut peds = self.agents.iter().filter(|a| a.class == ObjectClass::Pedestrian).count();
        let mut tries = 0;
        while peds < traffic.pedestrian_count as usize && tries < SPAWN_TRIES {
            tries += 1;
            peds += self.try_spawn_pedestrians(initial, traffic.pedestrian_count as usize - peds);
        }
    }

    /// Tries to spawn one car on a random lane near the ego vehicle; whether it did.
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
        if self.grid.near_junction(pos, CAR_SPAWN_JUNCTION_CLEARANCE_M) || !self.spawn_point_ok(pos, initial)
        {
            return false;
        }
        if self
            .agents
            .iter()
            .any(|a| a.class != ObjectClass::Pedestrian && a.kin.position.distance(pos) < CAR_SPAWN_SPACING_M)
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
        let speed =
            desired * self.rng.random_range(CAR_START_SPEED_FRACTION[0]..=CAR_START_SPEED_FRACTION[1]);
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
        let dir = if coin(&mut self.rng) { 1.0 } else { -1.0 };
        let lateral = self.rng.random_range(-PED_SPAWN_LATERAL_FRACTION..=PED_SPAWN_LATERAL_FRACTION)
            * self.grid.sidewalk_half_width_m;
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
        path.push(Leg::Line { a: pos, b: pos + self.grid.ring_tangent(p) * dir * FIRST_LEG_M });
        brain.cursor.p = (p + dir * FIRST_LEG_M).rem_euclid(self.grid.ring_length_m());
        while path.end_s() < PED_PLAN_AHEAD_M {
            plan_pedestrian(&self.grid, cfg, &mut self.rng, &mut brain, &mut path);
        }
        let speed = if self.rng.random_bool(PED_START_STANDING_PROBABILITY) { 0.0 } else { brain.speed };
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
            let along = self.rng.random_range(-GROUP_MAX_BEHIND_M..=GROUP_MAX_AHEAD_M);
            let offset = DVec2::new(along, side * spacing * (k.div_ceil(2)) as f64);
            let member_pos = pos + DVec2::from_angle(heading).rotate(offset);
            let member_brain =
                PedBrain { follow: Some(Follow { leader: leader_id, offset }), ..brain.clone() };
            let member = self.new_pedestrian(member_pos, heading, speed, Path::default(), member_brain);
            self.agents.push(member);
        }
        group_size
    }

    /// A new pedestrian with a random body size and the next id.
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

    /// A walking speed: hurried with `pedestrian.hurry_probability`.
    fn walking_speed(&mut self) -> f64 {
        let p = &self.cfg.pedestrian;
        if self.rng.random_bool(p.hurry_probability) {
            uniform(&mut self.rng, p.hurry_speed_mps)
        } else {
            uniform(&mut self.rng, p.desired_speed_mps)
        }
    }
}
