//! Correctness tests for the gated rectangular assignment solver.

use pathfinding::kuhn_munkres::kuhn_munkres;
use pathfinding::matrix::Matrix;
use primm_core::association::assignment::{AssignmentError, AssignmentSolver, AssignmentSummary};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const INF: f64 = f64::INFINITY;

/// Best (largest cardinality, then smallest cost) found by enumerating every partial injection
/// from rows to columns that uses only finite entries.
fn exhaustive_optimum(rows: usize, cols: usize, costs: &[f64]) -> (usize, f64) {
    fn visit(
        row: usize,
        rows: usize,
        cols: usize,
        costs: &[f64],
        used: &mut [bool],
        pairs: usize,
        total: f64,
        best: &mut (usize, f64),
    ) {
        if row == rows {
            if pairs > best.0 || (pairs == best.0 && total < best.1) {
                *best = (pairs, total);
            }
            return;
        }
        // Leave this row unassigned.
        visit(row + 1, rows, cols, costs, used, pairs, total, best);
        for col in 0..cols {
            let cost = costs[row * cols + col];
            if !used[col] && cost.is_finite() {
                used[col] = true;
                visit(row + 1, rows, cols, costs, used, pairs + 1, total + cost, best);
                used[col] = false;
            }
        }
    }
    let mut best = (0, 0.0);
    let mut used = vec![false; cols];
    visit(0, rows, cols, costs, &mut used, 0, 0.0, &mut best);
    best
}

/// Checks that `row_to_col` is one-to-one, uses only allowed pairs, and agrees with `summary`.
fn assert_valid_assignment(
    rows: usize,
    cols: usize,
    costs: &[f64],
    row_to_col: &[Option<usize>],
    summary: AssignmentSummary,
) {
    let mut used = vec![false; cols];
    let mut pairs = 0;
    let mut total = 0.0;
    for (row, assigned) in row_to_col[..rows].iter().enumerate() {
        if let Some(col) = *assigned {
            assert!(col < cols, "row {row} assigned to out-of-range column {col}");
            assert!(!used[col], "column {col} assigned twice");
            used[col] = true;
            let cost = costs[row * cols + col];
            assert!(cost.is_finite(), "row {row} assigned to forbidden column {col}");
            pairs += 1;
            total += cost;
        }
    }
    assert_eq!(summary.pairs, pairs, "summary pair count disagrees with the assignment");
    assert!(
        (summary.total_cost - total).abs() <= 1e-9 * (1.0 + total.abs()),
        "summary cost {} disagrees with the assignment cost {total}",
        summary.total_cost
    );
}

/// A random gated matrix: about 30 % forbidden entries, sometimes whole forbidden rows or
/// columns, and costs that are either small integers (many ties) or reals of either sign.
fn random_gated_matrix(rng: &mut ChaCha8Rng, rows: usize, cols: usize) -> Vec<f64> {
    let integer_costs = rng.random_bool(0.5);
    let magnitude = if rng.random_bool(0.2) { 1e6 } else { 10.0 };
    let mut costs: Vec<f64> = (0..rows * cols)
        .map(|_| {
            if rng.random_bool(0.3) {
                INF
            } else if integer_costs {
                f64::from(rng.random_range(-3_i32..=3))
            } else {
                rng.random_range(-magnitude..magnitude)
            }
        })
        .collect();
    if rng.random_bool(0.2) {
        let row = rng.random_range(0..rows);
        costs[row * cols..(row + 1) * cols].fill(INF);
    }
    if rng.random_bool(0.2) {
        let col = rng.random_range(0..cols);
        for row in 0..rows {
            costs[row * cols + col] = INF;
        }
    }
    costs
}

#[test]
fn solver_matches_exhaustive_search_on_every_small_gated_matrix() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_a551);
    let mut solver = AssignmentSolver::with_capacity(7, 7);
    let mut row_to_col = [None; 7];
    let mut checked = 0;
    for rows in 1..=7 {
        for cols in 1..=7 {
            for _ in 0..60 {
                let costs = random_gated_matrix(&mut rng, rows, cols);
                let summary = solver.solve(rows, cols, &costs, &mut row_to_col).unwrap();
                assert_valid_assignment(rows, cols, &costs, &row_to_col, summary);
                let (best_pairs, best_cost) = exhaustive_optimum(rows, cols, &costs);
                assert_eq!(
                    summary.pairs, best_pairs,
                    "{rows}x{cols} cardinality is not maximal for {costs:?}"
                );
                assert!(
                    (summary.total_cost - best_cost).abs() <= 1e-9 * (1.0 + best_cost.abs()),
                    "{rows}x{cols} cost {} is not the optimum {best_cost} for {costs:?}",
                    summary.total_cost
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 49 * 60);
}

/// Integer-valued random matrix and the optimum `kuhn_munkres` finds for it.
fn compare_with_kuhn_munkres(rng: &mut ChaCha8Rng, rows: usize, cols: usize) {
    let values: Vec<i64> = (0..rows * cols).map(|_| rng.random_range(0..1000)).collect();
    let costs: Vec<f64> = values.iter().map(|&value| value as f64).collect();

    // `kuhn_munkres` maximises and needs rows <= columns.
    let negated = if rows <= cols {
        Matrix::from_vec(rows, cols, values.iter().map(|&value| -value).collect()).unwrap()
    } else {
        Matrix::from_fn(cols, rows, |(col, row)| -values[row * cols + col])
    };
    let (negated_optimum, _) = kuhn_munkres(&negated);
    let optimum = -negated_optimum;

    let mut solver = AssignmentSolver::with_capacity(rows, cols);
    let mut row_to_col = vec![None; rows];
    let summary = solver.solve(rows, cols, &costs, &mut row_to_col).unwrap();
    assert_valid_assignment(rows, cols, &costs, &row_to_col, summary);
    assert_eq!(summary.pairs, rows.min(cols));
    assert_eq!(summary.total_cost, optimum as f64, "{rows}x{cols} differs from kuhn_munkres");
}

#[test]
fn solver_agrees_with_kuhn_munkres_on_large_square_matrices() {
    let mut rng = ChaCha8Rng::seed_from_u64(100);
    for _ in 0..5 {
        compare_with_kuhn_munkres(&mut rng, 100, 100);
    }
}

#[test]
fn solver_agrees_with_kuhn_munkres_on_wide_and_tall_matrices() {
    let mut rng = ChaCha8Rng::seed_from_u64(60);
    for _ in 0..3 {
        compare_with_kuhn_munkres(&mut rng, 60, 100);
        compare_with_kuhn_munkres(&mut rng, 100, 60);
    }
}

#[test]
fn empty_problems_assign_nothing() {
    let mut solver = AssignmentSolver::with_capacity(4, 4);
    let mut row_to_col = [Some(9); 4];

    let summary = solver.solve(0, 0, &[], &mut []).unwrap();
    assert_eq!(summary, AssignmentSummary { pairs: 0, total_cost: 0.0 });

    let summary = solver.solve(0, 3, &[], &mut []).unwrap();
    assert_eq!(summary.pairs, 0);

    let summary = solver.solve(3, 0, &[], &mut row_to_col).unwrap();
    assert_eq!(summary.pairs, 0);
    assert_eq!(row_to_col, [None, None, None, Some(9)]);
}

#[test]
fn fully_forbidden_matrix_assigns_nothing() {
    let mut solver = AssignmentSolver::with_capacity(3, 4);
    let mut row_to_col = [Some(0); 3];
    let summary = solver.solve(3, 4, &[INF; 12], &mut row_to_col).unwrap();
    assert_eq!(summary, AssignmentSummary { pairs: 0, total_cost: 0.0 });
    assert_eq!(row_to_col, [None; 3]);
}

#[test]
fn single_row_takes_its_cheapest_allowed_column() {
    let mut solver = AssignmentSolver::with_capacity(1, 5);
    let mut row_to_col = [None];
    let costs = [4.0, INF, -2.5, 7.0, INF];
    let summary = solver.solve(1, 5, &costs, &mut row_to_col).unwrap();
    assert_eq!(row_to_col, [Some(2)]);
    assert_eq!(summary, AssignmentSummary { pairs: 1, total_cost: -2.5 });
}

#[test]
fn single_column_goes_to_the_cheapest_allowed_row() {
    let mut solver = AssignmentSolver::with_capacity(4, 1);
    let mut row_to_col = [None; 4];
    let costs = [3.0, INF, 1.0, 2.0];
    let summary = solver.solve(4, 1, &costs, &mut row_to_col).unwrap();
    assert_eq!(row_to_col, [None, None, Some(0), None]);
    assert_eq!(summary, AssignmentSummary { pairs: 1, total_cost: 1.0 });
}

#[test]
fn an_extra_pair_outweighs_any_cost_saving() {
    let mut solver = AssignmentSolver::with_capacity(2, 2);
    let mut row_to_col = [None; 2];
    // Pairing row 0 with column 0 alone would cost 0, but only the expensive pairing
    // lets both rows be assigned.
    let costs = [0.0, 1e12, -1e3, INF];
    let summary = solver.solve(2, 2, &costs, &mut row_to_col).unwrap();
    assert_eq!(row_to_col, [Some(1), Some(0)]);
    assert_eq!(summary, AssignmentSummary { pairs: 2, total_cost: 1e12 - 1e3 });
}

#[test]
fn tall_gated_matrix_is_solved_like_its_transpose() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut solver = AssignmentSolver::with_capacity(9, 9);
    let mut row_to_col = [None; 9];
    let mut col_to_row = [None; 9];
    for _ in 0..200 {
        let (rows, cols) = (rng.random_range(1..=9), rng.random_range(1..=9));
        let costs = random_gated_matrix(&mut rng, rows, cols);
        let transposed: Vec<f64> =
            (0..cols * rows).map(|index| costs[(index % rows) * cols + index / rows]).collect();
        let direct = solver.solve(rows, cols, &costs, &mut row_to_col).unwrap();
        let flipped = solver.solve(cols, rows, &transposed, &mut col_to_row).unwrap();
        assert_valid_assignment(cols, rows, &transposed, &col_to_row, flipped);
        assert_eq!(direct.pairs, flipped.pairs);
        assert!((direct.total_cost - flipped.total_cost).abs() <= 1e-9 * (1.0 + direct.total_cost.abs()));
    }
}

#[test]
fn problem_larger_than_capacity_is_rejected() {
    let mut solver = AssignmentSolver::with_capacity(3, 5);
    assert_eq!((solver.max_rows(), solver.max_cols()), (3, 5));
    let mut row_to_col = [None; 4];
    let error = solver.solve(4, 2, &[0.0; 8], &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::CapacityExceeded { rows: 4, cols: 2, max_rows: 3, max_cols: 5 });
    let error = solver.solve(2, 6, &[0.0; 12], &mut row_to_col).unwrap_err();
    assert!(matches!(error, AssignmentError::CapacityExceeded { rows: 2, cols: 6, .. }));
    assert!(error.to_string().contains("2x6"));
}

#[test]
fn cost_slice_of_the_wrong_length_is_rejected() {
    let mut solver = AssignmentSolver::with_capacity(3, 3);
    let mut row_to_col = [None; 3];
    let error = solver.solve(2, 3, &[0.0; 5], &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::CostLengthMismatch { rows: 2, cols: 3, expected: 6, actual: 5 });
}

#[test]
fn output_slice_shorter_than_the_rows_is_rejected() {
    let mut solver = AssignmentSolver::with_capacity(3, 3);
    let mut row_to_col = [None; 2];
    let error = solver.solve(3, 1, &[0.0; 3], &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::OutputTooShort { rows: 3, actual: 2 });
}

#[test]
fn nan_cost_is_rejected_with_its_position_and_output_is_untouched() {
    let mut solver = AssignmentSolver::with_capacity(3, 3);
    let mut row_to_col = [Some(7); 3];
    let costs = [1.0, 2.0, 3.0, 4.0, INF, f64::NAN];
    let error = solver.solve(2, 3, &costs, &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::NanCost { row: 1, col: 2 });
    assert_eq!(row_to_col, [Some(7); 3]);
}

#[test]
fn negative_infinite_cost_is_rejected_with_its_position() {
    let mut solver = AssignmentSolver::with_capacity(3, 3);
    let mut row_to_col = [None; 3];
    let costs = [1.0, f64::NEG_INFINITY, 3.0, 4.0];
    let error = solver.solve(2, 2, &costs, &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::NegativeInfiniteCost { row: 0, col: 1 });
}

#[test]
fn cost_range_too_wide_for_f64_is_rejected() {
    let mut solver = AssignmentSolver::with_capacity(2, 2);
    let mut row_to_col = [None; 2];
    let costs = [-1e307, 1e307, 0.0, INF];
    let error = solver.solve(2, 2, &costs, &mut row_to_col).unwrap_err();
    assert_eq!(error, AssignmentError::CostRangeTooLarge { lowest: -1e307, highest: 1e307 });
}

#[test]
fn one_solver_reused_across_shapes_matches_fresh_solvers() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut reused = AssignmentSolver::with_capacity(12, 12);
    for _ in 0..300 {
        let (rows, cols) = (rng.random_range(0..=12), rng.random_range(0..=12));
        let costs =
            if rows == 0 || cols == 0 { Vec::new() } else { random_gated_matrix(&mut rng, rows, cols) };
        let mut reused_out = vec![Some(99); rows];
        let mut fresh_out = vec![Some(99); rows];
        let reused_summary = reused.solve(rows, cols, &costs, &mut reused_out).unwrap();
        let fresh_summary =
            AssignmentSolver::with_capacity(rows, cols).solve(rows, cols, &costs, &mut fresh_out).unwrap();
        assert_eq!(reused_out, fresh_out, "{rows}x{cols} differs: {costs:?}");
        assert_eq!(reused_summary, fresh_summary);
    }
}
