//! Tracker step time versus the number of objects, and one IMM cycle of a single track.
//!
//! `cargo bench --bench tracker`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec2;
use primm_core::config::Config;
use primm_core::imm::Imm;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::motion::{ModeModels, PredictContext};
use primm_core::tracker::Tracker;
use std::hint::black_box;

/// `count` objects on parallel lanes 4 m apart (half cars, half pedestrians), `frames` frames
/// 40 ms apart, with a deterministic ±0.2 m jitter.
fn lane_frames(count: usize, frames: usize) -> Vec<Frame> {
    (0..frames)
        .map(|k| {
            let t = k as f64 * 0.04;
            let mut frame = Frame::new(t);
            for i in 0..count {
                let class = if i % 2 == 0 { ObjectClass::Car } else { ObjectClass::Pedestrian };
                let speed = if class == ObjectClass::Car { 8.0 + (i % 5) as f64 } else { 1.3 };
                let jitter = 0.2 * (((k * 31 + i * 17) % 13) as f64 / 6.0 - 1.0);
                let (x, y) = (5.0 + speed * t + jitter, -2.0 * count as f64 + 4.0 * i as f64 - jitter);
                frame.measurements.push(Measurement {
                    x_m: x,
                    y_m: y,
                    radial_velocity_mps: speed * x / (x * x + y * y).sqrt(),
                    rcs_dbsm: 5.0,
                    class,
                    sensor_id: Some(0),
                    ground_truth_id: Some(i as u64),
                });
            }
            frame
        })
        .collect()
}

fn tracker_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("tracker_step");
    for method in [Method::Imm, Method::ConstantVelocity] {
        for count in [8usize, 32, 64, 128, 256] {
            let frames = lane_frames(count, 400);
            group.throughput(Throughput::Elements(count as u64));
            group.bench_with_input(BenchmarkId::new(method.id(), count), &frames, |b, frames| {
                let mut tracker = Tracker::new(Config::default().with_modes(method.modes())).unwrap();
                // Warm up into a steady state of confirmed tracks.
                for frame in &frames[..50] {
                    tracker.step(frame).unwrap();
                }
                let mut k = 50;
                let mut frame = frames[k].clone();
                b.iter(|| {
                    frame.timestamp_s += 0.04;
                    frame.measurements.clone_from(&frames[50 + k % 350].measurements);
                    k += 1;
                    black_box(tracker.step(&frame).unwrap().len())
                });
            });
        }
    }
    group.finish();
}

fn imm_cycle(c: &mut Criterion) {
    let config = Config::default();
    let models = ModeModels::from_config(&config.classes.car);
    let mut group = c.benchmark_group("imm_cycle");
    for method in [Method::PrImm, Method::Imm, Method::ConstantVelocity] {
        let imm = Imm::new(&config.clone().with_modes(method.modes()).imm);
        let first = Measurement {
            x_m: 20.0,
            y_m: 1.0,
            radial_velocity_mps: 5.0,
            rcs_dbsm: 5.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: None,
        };
        let mut state = imm.initiate(&models, &first);
        let mut t = 0.0;
        group.bench_function(method.id(), |b| {
            b.iter(|| {
                t += 0.04;
                let context = PredictContext {
                    dt_s: 0.04,
                    displacement_m: Some(DVec2::new(0.2, 0.0)),
                    displacement_covariance_m2: None,
                };
                let prior = imm.predict(&models, &state, &context);
                state = imm.update(&models, &prior, DVec2::new(20.0 + 5.0 * t, 1.0)).unwrap();
                black_box(imm.fuse_posterior(&state, prior.available))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, tracker_step, imm_cycle);
criterion_main!(benches);
