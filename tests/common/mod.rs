//! Helpers shared by the integration tests: seeded sampling and simple true-motion simulators.
#![allow(dead_code)]

use nalgebra::{SMatrix, SVector};
use primm_core::config::Config;
use primm_core::measurement::{Measurement, ObjectClass};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A sample of N(0, covariance) (covariance positive semi-definite).
pub fn sample<const N: usize>(rng: &mut ChaCha8Rng, covariance: &SMatrix<f64, N, N>) -> SVector<f64, N> {
    let scale = covariance.abs().max().max(1e-300);
    let jittered = covariance + SMatrix::<f64, N, N>::identity() * (scale * 1e-14);
    let l = nalgebra::Cholesky::new(jittered).expect("covariance is positive semi-definite").l();
    let mut z = SVector::<f64, N>::zeros();
    for i in 0..N {
        z[i] = StandardNormal.sample(rng);
    }
    l * z
}

pub fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

pub fn measurement(x: f64, y: f64, radial_velocity: f64) -> Measurement {
    Measurement {
        x_m: x,
        y_m: y,
        radial_velocity_mps: radial_velocity,
        rcs_dbsm: 10.0,
        class: ObjectClass::Car,
        sensor_id: None,
        ground_truth_id: None,
    }
}

pub fn config() -> Config {
    Config::default()
}

/// Radial velocity of an object at `position` moving with `velocity`, seen from the origin.
pub fn radial_velocity(position: [f64; 2], velocity: [f64; 2]) -> f64 {
    let range = (position[0].powi(2) + position[1].powi(2)).sqrt();
    (position[0] * velocity[0] + position[1] * velocity[1]) / range
}

/// True planar motion sampled at irregular times: straight, then a constant-rate turn, then
/// straight again. Returns (t, position, velocity, turn rate) per step.
pub fn straight_turn_straight(
    dt: &[f64],
    speed: f64,
    turn_start_s: f64,
    turn_end_s: f64,
    turn_rate: f64,
) -> Vec<(f64, [f64; 2], [f64; 2], f64)> {
    let mut t = 0.0;
    let (mut x, mut y, mut heading) = (10.0, -20.0, 0.3_f64);
    let mut out = Vec::with_capacity(dt.len() + 1);
    out.push((t, [x, y], [speed * heading.cos(), speed * heading.sin()], 0.0));
    for &step in dt {
        // integrate finely so the truth is exact enough
        let substeps = 20;
        let h = step / substeps as f64;
        for _ in 0..substeps {
            let omega = if t >= turn_start_s && t < turn_end_s { turn_rate } else { 0.0 };
            heading += omega * h * 0.5;
            x += speed * heading.cos() * h;
            y += speed * heading.sin() * h;
            heading += omega * h * 0.5;
            t += h;
        }
        let omega = if t >= turn_start_s && t < turn_end_s { turn_rate } else { 0.0 };
        out.push((t, [x, y], [speed * heading.cos(), speed * heading.sin()], omega));
    }
    out
}

use primm_core::measurement::Frame;

/// A moving object of a hand-built scene: constant velocity from `start`.
#[derive(Debug, Clone, Copy)]
pub struct SceneObject {
    pub id: u64,
    pub class: ObjectClass,
    pub start: [f64; 2],
    pub velocity: [f64; 2],
    /// Visible during [from, to) seconds.
    pub visible: (f64, f64),
}

impl SceneObject {
    pub fn position(&self, t: f64) -> [f64; 2] {
        [self.start[0] + self.velocity[0] * t, self.start[1] + self.velocity[1] * t]
    }
}

/// Frames of a scene at a fixed interval, with Gaussian position noise of `noise_std` m.
pub fn scene_frames(
    objects: &[SceneObject],
    frames: usize,
    dt: f64,
    noise_std: f64,
    seed: u64,
) -> Vec<Frame> {
    let mut rng = rng(seed);
    (0..frames)
        .map(|k| {
            let t = k as f64 * dt;
            let mut frame = Frame::new(t);
            for object in objects.iter().filter(|o| t >= o.visible.0 && t < o.visible.1) {
                let p = object.position(t);
                frame.measurements.push(Measurement {
                    x_m: p[0] + standard_normal(&mut rng) * noise_std,
                    y_m: p[1] + standard_normal(&mut rng) * noise_std,
                    radial_velocity_mps: radial_velocity(p, object.velocity)
                        + standard_normal(&mut rng) * 0.1,
                    rcs_dbsm: 10.0,
                    class: object.class,
                    sensor_id: Some(0),
                    ground_truth_id: Some(object.id),
                });
            }
            frame
        })
        .collect()
}

/// `count` objects on parallel lanes 4 m apart, alternating cars and pedestrians.
pub fn lanes(count: usize) -> Vec<SceneObject> {
    (0..count)
        .map(|i| {
            let class = if i % 2 == 0 { ObjectClass::Car } else { ObjectClass::Pedestrian };
            let speed =
                if class == ObjectClass::Car { 8.0 + (i % 5) as f64 } else { 1.2 + 0.1 * (i % 4) as f64 };
            SceneObject {
                id: i as u64 + 1,
                class,
                start: [5.0 + (i % 3) as f64 * 10.0, -128.0 + 4.0 * i as f64],
                velocity: [speed, 0.0],
                visible: (0.0, f64::INFINITY),
            }
        })
        .collect()
}

/// `clusters` groups of `per_cluster` cars, 30 m apart, in which every car crosses the others:
/// car `i` of a group starts on a circle of radius 2 m at angle `2πi/n` and drives along a
/// chord to the angle `0.8π` further on, which it reaches after `crossing_s` seconds. Every car
/// of a group stays within 4 m of every other, well inside the car gate, so that each group
/// is one association cluster of `per_cluster` tracks and measurements. Played for
/// `crossing_s` and then started again, the cars jump back by at most 4 m: the groups stay
/// clusters for as long as the scene runs.
pub fn crossing_clusters(clusters: usize, per_cluster: usize, crossing_s: f64) -> Vec<SceneObject> {
    const RADIUS_M: f64 = 2.0;
    let mut objects = Vec::new();
    for cluster in 0..clusters {
        let centre = [40.0, -120.0 + 30.0 * cluster as f64];
        for i in 0..per_cluster {
            let from = std::f64::consts::TAU * i as f64 / per_cluster as f64;
            let to = from + 0.8 * std::f64::consts::PI;
            let start = [centre[0] + RADIUS_M * from.cos(), centre[1] + RADIUS_M * from.sin()];
            let end = [centre[0] + RADIUS_M * to.cos(), centre[1] + RADIUS_M * to.sin()];
            objects.push(SceneObject {
                id: objects.len() as u64 + 1,
                class: ObjectClass::Car,
                start,
                velocity: [(end[0] - start[0]) / crossing_s, (end[1] - start[1]) / crossing_s],
                visible: (0.0, f64::INFINITY),
            });
        }
    }
    objects
}

/// A predictor that knows the lane scene: it finds the object nearest to the request's anchor
/// and returns its exact displacement over the step. Allocates nothing.
pub struct LaneOracle {
    pub objects: Vec<SceneObject>,
}

impl primm_core::predictor::DisplacementPredictor for LaneOracle {
    fn submit(&mut self, _requests: &[primm_core::predictor::PredictionRequest]) {}
    fn collect(&mut self, _displacements: &mut [Option<primm_core::predictor::Displacement>]) {}
    fn predict(
        &mut self,
        requests: &[primm_core::predictor::PredictionRequest],
        displacements: &mut [Option<primm_core::predictor::Displacement>],
    ) {
        for (request, out) in requests.iter().zip(displacements.iter_mut()) {
            let step = -f64::from(request.features[request.len - 1][4]);
            let t = request.prediction_time_s - step;
            let nearest = self.objects.iter().min_by(|a, b| {
                let da = (glam::DVec2::from(a.position(t)) - request.anchor_m).length();
                let db = (glam::DVec2::from(b.position(t)) - request.anchor_m).length();
                da.total_cmp(&db)
            });
            *out = nearest.map(|o| (glam::DVec2::from(o.velocity) * step).into());
        }
    }
}
/// One request per track of `frame`, each a single measurement at `x = 100·frame + i`, so that
/// [`echoed_anchor`] names the request an answer belongs to (for predictors that answer with the
/// anchor scaled by 1/1000).
pub fn anchored_requests(frame: usize, count: usize) -> Vec<primm_core::predictor::PredictionRequest> {
    (0..count)
        .map(|i| {
            let entry = primm_core::predictor::HistoryEntry {
                x_m: (frame * 100 + i) as f64,
                y_m: 1.0,
                radial_velocity_mps: 0.0,
                rcs_dbsm: 0.0,
                timestamp_s: frame as f64 * 0.02,
                ..Default::default()
            };
            primm_core::predictor::PredictionRequest::from_history(&[entry], frame as f64 * 0.02 + 0.02)
        })
        .collect()
}

/// The anchor of request `i` of [`anchored_requests`]`(frame, _)`, scaled by 1/1000.
pub fn echoed_anchor(frame: usize, i: usize) -> Option<primm_core::predictor::Displacement> {
    Some((glam::DVec2::new((frame * 100 + i) as f64, 1.0) / 1000.0).into())
}

pub mod counting_allocator;
pub mod service;
#[cfg(feature = "tunnel")]
pub mod tunnel;

/// The key a configuration error names, for a result that must be `ConfigError::Invalid`.
pub fn invalid_key(result: Result<impl std::fmt::Debug, primm_core::config::ConfigError>) -> String {
    match result {
        Err(primm_core::config::ConfigError::Invalid { key, .. }) => key,
        other => panic!("expected an invalid key, got {other:?}"),
    }
}
