//! Timing of the assignment solver on square problems of tracking-like and dense structure.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use primm::association::assignment::AssignmentSolver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SIZES: [usize; 5] = [8, 32, 64, 128, 256];

/// Gate radius in units of the mean spacing between objects: a row sees about three columns.
const GATE_RADIUS: f64 = 1.5;

/// Tracks spread along a line with unit mean spacing, measurements are noisy copies of them in
/// shuffled order, cost is the squared distance, and pairs beyond the gate radius are forbidden.
fn gated_problem(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let tracks: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..n as f64)).collect();
    let mut measurements: Vec<f64> = tracks
        .iter()
        .map(|&x| x + rng.random_range(-0.5..0.5))
        .collect();
    for index in (1..n).rev() {
        measurements.swap(index, rng.random_range(0..=index));
    }
    let mut costs = Vec::with_capacity(n * n);
    for &track in &tracks {
        for &measurement in &measurements {
            let distance: f64 = track - measurement;
            costs.push(if distance.abs() <= GATE_RADIUS {
                distance * distance
            } else {
                f64::INFINITY
            });
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
        for (kind, costs) in [
            ("gated", gated_problem(&mut rng, n)),
            ("dense", dense_problem(&mut rng, n)),
        ] {
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

criterion_group!(benches, bench_assignment);
criterion_main!(benches);
