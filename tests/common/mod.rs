//! Helpers shared by the integration tests: seeded sampling and simple true-motion simulators.
#![allow(dead_code)]

use nalgebra::{SMatrix, SVector};
use primm::config::Config;
use primm::measurement::{Measurement, ObjectClass};
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
pub fn straight_turn_straight(dt: &[f64], speed: f64, turn_start_s: f64, turn_end_s: f64, turn_rate: f64) -> Vec<(f64, [f64; 2], [f64; 2], f64)> {
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
