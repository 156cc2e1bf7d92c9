//! Timing of the assignment solver on square problems of tracking-like and dense structure,
//! and of the tracker's whole association step (per-class gating, clusters, solves) against
//! one dense gated solve per class of the same frame.
//!
//! `cargo bench --bench assignment`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use primm_core::association::assignment::AssignmentSolver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SIZES: [usize; 5] = [8, 32, 64, 128, 256];

/// Gate radius in units of the mean spacing between objects: a row sees about three columns.
const GATE_RADIUS: f64 = 1.5;

/// Tracks spread along a line with unit mean spacing, measurements are noisy copies of them in
/// shuffled order, cost is the squared distance, and pairs beyond the gate radius are forbidden.
fn gated_problem(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let tracks: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..n as f64)).collect();
    let mut measurements: Vec<f64> = tracks.iter().map(|&x| x + rng.random_range(-0.5..0.5)).collect();
    for index in (1..n).rev() {
        measurements.swap(index, rng.random_range(0..=index));
    }
    let mut costs = Vec::with_capacity(n * n);
    for &track in &tracks {
        for &measurement in &measurements {
            let distance: f64 = track - measurement;
            costs.push(if distance.abs() <= GATE_RADIUS { distance * distance } else { f64::INFINITY });
        }
    }
    costs
}

/// Every pair allowed, costs uniform in [0, 100).
fn dense_problem(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n * n).map(|_| rng.random_range(0.0..100.0)).collect()
}

fn bench_assignment(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(2016);
    let mut group = c.benchmark_group("assignment");
    for n in SIZES {
        let mut solver = AssignmentSolver::with_capacity(n, n);
        let mut row_to_col = vec![None; n];
        for (kind, costs) in [("gated", gated_problem(&mut rng, n)), ("dense", dense_problem(&mut rng, n))] {
            group.bench_with_input(BenchmarkId::new(kind, n), &costs, |bencher, costs| {
                bencher.iter(|| {
                    solver
                        .solve(n, n, black_box(costs), &mut row_to_col)
                        .expect("benchmark problems are valid")
                });
            });
        }
    }
    group.finish();
}

/// Tracks on lanes 4 m apart (cars and pedestrians alternating), priors 0.3 m off their
/// measurements, in shuffled measurement order.
fn association_scene(
    n: usize,
) -> (Vec<primm_core::track::Track>, Vec<primm_core::imm::ImmPrior>, primm_core::measurement::Frame, Vec<bool>)
{
    use primm_core::measurement::{Frame, Measurement, ObjectClass};
    let config = primm_core::config::Config::default();
    let imm = primm_core::imm::Imm::new(&config.imm);
    let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
    let mut tracks = Vec::new();
    let mut priors = Vec::new();
    let mut frame = Frame::new(0.05);
    for i in 0..n {
        let (lane, block) = (i % 16, i / 16);
        let class = if lane % 2 == 0 { ObjectClass::Car } else { ObjectClass::Pedestrian };
        let measurement = Measurement {
            x_m: -150.0 + 40.0 * block as f64 + rng.random_range(-0.3..0.3),
            y_m: -32.0 + 4.0 * lane as f64 + rng.random_range(-0.3..0.3),
            radial_velocity_mps: 5.0,
            rcs_dbsm: 0.0,
            class,
            sensor_id: None,
            ground_truth_id: None,
        };
        let models = primm_core::motion::ModeModels::from_config(config.classes.get(class));
        let state = imm.initiate(&models, &measurement);
        let context = primm_core::motion::PredictContext {
            dt_s: 0.05,
            displacement_m: None,
            displacement_covariance_m2: None,
        };
        let mut prior = imm.predict(&models, &state, &context);
        prior.fused.mean = glam::DVec2::new(measurement.x_m + 0.3, measurement.y_m - 0.2);
        tracks.push(primm_core::track::Track::new(
            i as u64,
            &measurement,
            glam::DVec2::ZERO,
            0.0,
            state,
            0.5,
        ));
        priors.push(prior);
        frame.measurements.push(measurement);
    }
    for index in (1..n).rev() {
        frame.measurements.swap(index, rng.random_range(0..=index));
    }
    (tracks, priors, frame, vec![true; n])
}

fn bench_association(c: &mut Criterion) {
    use primm_core::association::associator::Associator;
    use primm_core::association::cost::association_cost;
    use primm_core::measurement::ObjectClass;
    let config = primm_core::config::Config::default();
    let mut group = c.benchmark_group("association");
    for n in SIZES {
        let (tracks, priors, frame, accepted) = association_scene(n);
        let mut associator = Associator::new();
        let sensors = vec![
            primm_core::sensor_noise::MeasurementSensor::unknown(glam::DVec2::ZERO, 0.5);
            accepted.len()
        ];
        let mut track_to_measurement = vec![None; n];
        group.bench_function(BenchmarkId::new("clustered", n), |bencher| {
            bencher.iter(|| {
                associator
                    .associate(
                        &tracks,
                        &priors,
                        &frame,
                        &accepted,
                        &sensors,
                        &config,
                        &mut track_to_measurement,
                    )
                    .expect("valid problem");
                black_box(track_to_measurement[0])
            });
        });
        // The same frame as one dense gated matrix per class (the cost matrix filled in full).
        let mut solver = AssignmentSolver::with_capacity(n, n);
        let mut costs = vec![0.0; n * n];
        let mut row_to_col = vec![None; n];
        group.bench_function(BenchmarkId::new("dense_per_class", n), |bencher| {
            bencher.iter(|| {
                for class in ObjectClass::ALL {
                    let rows: Vec<usize> = (0..n).filter(|&i| tracks[i].class == class).collect();
                    let columns: Vec<usize> =
                        (0..n).filter(|&j| frame.measurements[j].class == class).collect();
                    let gate = config.classes.get(class).paper_gate_m;
                    for (r, &i) in rows.iter().enumerate() {
                        for (k, &j) in columns.iter().enumerate() {
                            let cost = association_cost(
                                priors[i].fused.mean,
                                tracks[i].last_radial_velocity_mps,
                                &frame.measurements[j],
                                &config.association,
                            );
                            costs[r * columns.len() + k] = if cost <= gate { cost } else { f64::INFINITY };
                        }
                    }
                    let cells = rows.len() * columns.len();
                    solver
                        .solve(rows.len(), columns.len(), &costs[..cells], &mut row_to_col[..rows.len()])
                        .expect("valid problem");
                }
                black_box(row_to_col[0])
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bench_assignment, bench_association);
criterion_main!(benches);
