//! The traffic simulation: the ego vehicle, cars and pedestrians moving on the road grid.
//!
//! Cars follow lanes with a pure-pursuit steering law and an intelligent-driver-model speed law
//! (free-road acceleration towards a cruise speed, braking for the object ahead, for red signals
//! and for curves). Their routes are planned junction by junction: straight on, right or left
//! turn (with the lane change a turn needs), and random lane changes mid-block. Pedestrians walk
//! the sidewalk rings around blocks with random leg lengths, stop, turn around, cross on
//! signalised crosswalks or mid-block, and may walk in groups. All motion goes through
//! [`Kinematics::step`], which enforces the hard limits of the configuration.
//!
//! This module holds the world and its time step; `driver` the control law and behaviour of
//! cars, `pedestrian` those of pedestrians, `spawn` the population around the ego vehicle and
//! `routes` the route planning of both. The constants of the driver and walker models are part
//! of the configuration (`car.driver`, `pedestrian.walker`).

mod driver;
mod pedestrian;
mod routes;
mod spawn;

use glam::DVec2;
use rand::Rng;
use rand_chacha::ChaCha12Rng;

use super::config::{Interval, ScenarioConfig};
use super::kinematics::Kinematics;
use super::path::Path;
use super::road::RoadGrid;
use crate::io::EgoPose;
use driver::CarBrain;
use pedestrian::PedBrain;
use primm_core::measurement::ObjectClass;

/// Identity used for the ego vehicle, which is never reported as an object.
pub(crate) const EGO_ID: u64 = u64::MAX;

/// Planning horizon of car routes, metres.
const CAR_PLAN_AHEAD_M: f64 = 130.0;
/// Planning horizon of pedestrian paths, metres.
const PED_PLAN_AHEAD_M: f64 = 25.0;
/// Interval between population checks, seconds.
const POPULATION_INTERVAL_S: f64 = 0.25;
/// Cars follow their path by projection alone: a leg is done when the car has passed its end.
const CAR_WAYPOINT_REACH_M: f64 = 0.0;

/// A draw uniform in `interval` (its lower end, without a draw, when it is a single value).
fn uniform(rng: &mut ChaCha12Rng, interval: Interval) -> f64 {
    if interval[1] > interval[0] {
        rng.random_range(interval[0]..=interval[1])
    } else {
        interval[0]
    }
}

/// A fair coin.
fn coin(rng: &mut ChaCha12Rng) -> bool {
    rng.random_bool(0.5)
}

#[derive(Debug, Clone)]
enum Brain {
    Car(CarBrain),
    Pedestrian(PedBrain),
    /// Never moves: the roadside ego platform (`ego.placement = "roadside"`).
    Stationary,
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

/// What the behaviour update of one agent reads and draws from besides the agent itself.
struct Env<'a> {
    cfg: &'a ScenarioConfig,
    grid: &'a RoadGrid,
    rng: &'a mut ChaCha12Rng,
    /// Simulation time, seconds.
    t: f64,
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
    next_population_check: f64,
}

impl<'c> World<'c> {
    /// A new world with the ego vehicle and an initial population.
    pub(crate) fn new(cfg: &'c ScenarioConfig, mut rng: ChaCha12Rng) -> Self {
        let grid = RoadGrid::new(cfg, rng.random());
        let mut world =
            Self { cfg, grid, t: 0.0, agents: Vec::new(), next_id: 0, rng, next_population_check: 0.0 };
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

    /// One step: every agent's control from the same state, the motion under its class's
    /// limits, then the behaviour updates and, now and then, the population check.
    fn step(&mut self, dt: f64) {
        let controls: Vec<(f64, f64)> = (0..self.agents.len()).map(|i| self.control(i)).collect();
        let cfg = self.cfg;
        for (agent, (accel, yaw_rate)) in self.agents.iter_mut().zip(controls) {
            let (limits, reach) = match agent.class {
                ObjectClass::Pedestrian => (&cfg.pedestrian.limits, cfg.pedestrian.walker.waypoint_reach_m),
                _ => (&cfg.car.limits, CAR_WAYPOINT_REACH_M),
            };
            agent.kin.step(accel, yaw_rate, dt, limits);
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

    /// The commanded acceleration (m/s²) and yaw rate (rad/s) of agent `i`.
    fn control(&self, i: usize) -> (f64, f64) {
        match &self.agents[i].brain {
            Brain::Car(brain) => self.car_control(i, brain),
            Brain::Pedestrian(brain) => self.ped_control(i, brain),
            Brain::Stationary => (0.0, 0.0),
        }
    }

    /// Random decisions, passed marks and replanning of agent `i`.
    fn update_behaviour(&mut self, i: usize, dt: f64) {
        let mut env = Env { cfg: self.cfg, grid: &self.grid, rng: &mut self.rng, t: self.t };
        let agent = &mut self.agents[i];
        match &mut agent.brain {
            Brain::Car(brain) => {
                let progress = driver::Progress { s: agent.s, length: agent.length, is_ego: agent.is_ego };
                driver::update_car(&mut env, brain, &mut agent.path, progress);
            }
            Brain::Pedestrian(brain) => {
                pedestrian::update_pedestrian(&mut env, dt, brain, &mut agent.path, agent.s, agent.kin.speed);
            }
            Brain::Stationary => {}
        }
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
