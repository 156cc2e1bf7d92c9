//! Proves that solving assignment problems does not touch the heap.
//!
//! The test binary's counting global allocator counts the allocations made by the current
//! thread, so that other test threads cannot interfere.

use crate::common::counting_allocator::count_allocations;
use primm_core::association::assignment::{AssignmentError, AssignmentSolver};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Number of heap allocations the current thread makes while running `work`.
fn allocations_during(work: impl FnOnce()) -> u64 {
    count_allocations(work)
}

#[test]
fn allocation_counter_sees_heap_allocations() {
    let count = allocations_during(|| {
        let buffer: Vec<u64> = Vec::with_capacity(16);
        std::hint::black_box(&buffer);
    });
    assert_eq!(count, 1);
}

#[test]
fn solving_performs_no_heap_allocation() {
    const MAX: usize = 64;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    // Problems of many shapes: dense, gated, wide, tall, all-forbidden and empty.
    let mut problems: Vec<(usize, usize, Vec<f64>)> = Vec::new();
    for _ in 0..40 {
        let rows = rng.random_range(0..=MAX);
        let cols = rng.random_range(0..=MAX);
        let gate_probability = [0.0, 0.5, 0.9, 1.0][rng.random_range(0..4)];
        let costs = (0..rows * cols)
            .map(|_| {
                if rng.random_bool(gate_probability) {
                    f64::INFINITY
                } else {
                    rng.random_range(-50.0..50.0)
                }
            })
            .collect();
        problems.push((rows, cols, costs));
    }
    problems.push((MAX, MAX, vec![1.0; MAX * MAX]));
    let nan_problem = [0.0, f64::NAN];

    let mut solver = AssignmentSolver::with_capacity(MAX, MAX);
    let mut row_to_col = vec![None; MAX];
    let mut pairs = 0;
    let count = allocations_during(|| {
        for (rows, cols, costs) in &problems {
            pairs += solver.solve(*rows, *cols, costs, &mut row_to_col).unwrap().pairs;
        }
        let error = solver.solve(1, 2, &nan_problem, &mut row_to_col);
        assert!(matches!(error, Err(AssignmentError::NanCost { row: 0, col: 1 })));
        let error = solver.solve(MAX + 1, 1, &[], &mut row_to_col);
        assert!(matches!(error, Err(AssignmentError::CapacityExceeded { .. })));
    });
    assert_eq!(count, 0, "solve allocated {count} times");
    // The full-size dense problem alone yields MAX pairs, so real work was done.
    assert!(pairs >= MAX);
}
