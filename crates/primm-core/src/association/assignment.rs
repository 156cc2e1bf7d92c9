//! Optimal rectangular linear assignment with gating, on a fixed-capacity workspace.
//!
//! # Problem
//!
//! Given a `rows × cols` cost matrix in which some pairs are forbidden (cost `f64::INFINITY`,
//! typically because a measurement lies outside a track's gate), [`AssignmentSolver::solve`]
//! picks a set of (row, column) pairs such that every row and every column is used at most once,
//! only allowed pairs are used, and
//!
//! 1. the number of pairs is as large as possible, and
//! 2. among all pair sets of that size, the summed cost is as small as possible.
//!
//! Finite costs may have any sign.
//!
//! # Algorithm
//!
//! The core is the shortest augmenting path method of Jonker and Volgenant in the rectangular
//! form described by Crouse (2016, "On implementing 2D rectangular assignment algorithms"), the
//! same scheme used by SciPy's `linear_sum_assignment`. Rows are inserted one at a time; for each
//! new row a Dijkstra search over reduced costs `c(i, j) - u(i) - v(j)` finds the cheapest
//! alternating path to a free column, the dual potentials `u` and `v` are updated so that all
//! reduced costs stay non-negative and matched pairs keep a reduced cost of zero, and the matching
//! is flipped along the path. After the last row the matching is a minimum cost assignment of
//! every row of the (short side of the) matrix.
//!
//! Before that, the solver prepares a reduced problem in its own buffers:
//!
//! * **Pruning.** Rows and columns without a single allowed entry can never be paired, so they
//!   are dropped. With typical gating this removes most clutter measurements and lost tracks.
//! * **Orientation.** The core needs no more rows than columns. When more rows than columns
//!   survive pruning, the reduced matrix is written transposed; the caller's data is never
//!   copied into a new allocation or reordered.
//! * **Forbidden pairs.** The core works on finite numbers only, so every forbidden entry of the
//!   reduced matrix is replaced by a finite value `M` (below). Pairs that end up on an `M` entry
//!   are removed from the result.
//!
//! # Why the substitute value `M` is safe
//!
//! Let the reduced problem have `n` rows on its short side, and let `lo` and `hi` be the smallest
//! and largest allowed cost, `span = hi - lo` and `scale = span + max(|lo|, |hi|, 1)`. The solver
//! uses
//!
//! ```text
//! M = hi + (n + 1) · scale
//! ```
//!
//! The core returns a complete assignment of the `n` short-side lines. One that uses `f` forbidden
//! entries costs `A + f·M`, where `A` is a sum of `n - f` allowed costs. Take two complete
//! assignments `a` and `b` with `f < g` forbidden entries. Each allowed cost lies in `[lo, hi]`, so
//!
//! ```text
//! cost(b) - cost(a) ≥ (n - g)·lo + g·M - (n - f)·hi - f·M
//!                   = (g - f)·(M - hi) - (n - g)·span
//!                   ≥ (M - hi) - (n - 1)·span              (M - hi > 0, g - f ≥ 1, g ≥ 1)
//!                   = (n + 1)·scale - (n - 1)·span  ≥  2·scale      (span ≤ scale).
//! ```
//!
//! Hence an assignment with fewer forbidden entries is always strictly cheaper, by at least
//! `2·scale`, a margin no smaller than the magnitude of any allowed cost. Because every allowed
//! pair set of size `k` extends (with `n - k` forbidden entries; the long side has at least `n`
//! lines) to a complete assignment, the minimum of the substituted problem first minimises the
//! number of forbidden entries, i.e. maximises the number of allowed pairs, and then, since all
//! candidates pay the same `f·M`, minimises the summed allowed cost. Dropping the forbidden pairs
//! therefore yields exactly the requested optimum.
//!
//! The margin also covers floating-point rounding. The potentials and path lengths of the core are
//! sums of at most `2n` reduced costs along alternating paths, so every quantity it handles is
//! bounded by a small multiple of `n·(|M| + |lo|)`, and the rounding error accumulated over its `O(n)`
//! additions per entry is around `n²·|M|·2⁻⁵³ ≈ n³·scale·10⁻¹⁶`, far below `2·scale` for any
//! matrix size this solver is meant for. Inputs whose range is so wide that these bounds overflow
//! `f64` are rejected with [`AssignmentError::CostRangeTooLarge`] instead of being solved
//! inaccurately; this needs costs within a few orders of magnitude of `f64::MAX`.
//!
//! # Cost and memory
//!
//! With `n ≤ m` the sizes of the reduced problem, the core takes `O(n²·m)` time in the worst case
//! (each of the `n` insertions scans at most `n` rows of `m` entries); validation, pruning and the
//! copy add `O(rows·cols)`. Every buffer is sized once by [`AssignmentSolver::with_capacity`] and
//! reused, so [`AssignmentSolver::solve`] performs no heap allocation at all.

use crate::readable_number::readable;
use alloc::vec;
use alloc::vec::Vec;
use thiserror::Error;

/// Marker for a line that is not matched yet.
const UNASSIGNED: usize = usize::MAX;

/// Safety factor between the coarse bound on the core's intermediate values and `f64::MAX`.
const OVERFLOW_HEADROOM: f64 = 8.0;

/// Outcome of one [`AssignmentSolver::solve`] call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AssignmentSummary {
    /// Number of (row, column) pairs in the assignment.
    pub pairs: usize,
    /// Sum of the costs of those pairs; `0.0` when nothing is assigned.
    pub total_cost: f64,
}

/// Reasons why [`AssignmentSolver::solve`] refuses a problem.
///
/// The output slice is left untouched whenever an error is returned.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum AssignmentError {
    /// The problem has more rows or columns than the solver was built for.
    #[error("a {rows}x{cols} problem exceeds the solver capacity of {max_rows}x{max_cols}")]
    CapacityExceeded {
        /// Rows requested.
        rows: usize,
        /// Columns requested.
        cols: usize,
        /// Largest row count the solver accepts.
        max_rows: usize,
        /// Largest column count the solver accepts.
        max_cols: usize,
    },
    /// The cost slice does not hold exactly `rows * cols` entries.
    #[error("cost slice has {actual} entries but a {rows}x{cols} problem needs {expected}")]
    CostLengthMismatch {
        /// Rows requested.
        rows: usize,
        /// Columns requested.
        cols: usize,
        /// Required length, `rows * cols`.
        expected: usize,
        /// Length of the slice that was passed.
        actual: usize,
    },
    /// The output slice has fewer entries than the problem has rows.
    #[error("output slice has {actual} entries but the problem has {rows} rows")]
    OutputTooShort {
        /// Rows requested.
        rows: usize,
        /// Length of the output slice that was passed.
        actual: usize,
    },
    /// A cost is NaN.
    #[error("cost at row {row}, column {col} is NaN")]
    NanCost {
        /// Row of the offending entry.
        row: usize,
        /// Column of the offending entry.
        col: usize,
    },
    /// A cost is negative infinity, which would make the optimum unbounded.
    #[error("cost at row {row}, column {col} is negative infinity")]
    NegativeInfiniteCost {
        /// Row of the offending entry.
        row: usize,
        /// Column of the offending entry.
        col: usize,
    },
    /// The allowed costs span a range so wide that solving could overflow `f64`.
    #[error(
        "allowed costs range from {} to {}, too wide to solve without overflow",
        readable(.lowest),
        readable(.highest)
    )]
    CostRangeTooLarge {
        /// Smallest allowed cost.
        lowest: f64,
        /// Largest allowed cost.
        highest: f64,
    },
}

/// Reusable solver for gated rectangular assignment problems up to a fixed size.
///
/// See the [module documentation](self) for the algorithm and its guarantees.
///
/// ```
/// use primm_core::association::assignment::AssignmentSolver;
///
/// let mut solver = AssignmentSolver::with_capacity(4, 4);
/// let inf = f64::INFINITY;
/// // Two tracks, three measurements; track 1 may only take measurement 0.
/// let costs = [
///     1.0, 2.0, 9.0, //
///     0.5, inf, inf,
/// ];
/// let mut row_to_col = [None; 2];
/// let summary = solver.solve(2, 3, &costs, &mut row_to_col).unwrap();
/// assert_eq!(row_to_col, [Some(1), Some(0)]);
/// assert_eq!(summary.pairs, 2);
/// assert_eq!(summary.total_cost, 2.5);
/// ```
#[derive(Debug, Clone)]
pub struct AssignmentSolver {
    max_rows: usize,
    max_cols: usize,
    /// Original indices of the rows that have an allowed entry (first `live_row_count` used).
    live_rows: Vec<usize>,
    /// Original indices of the columns that have an allowed entry.
    live_cols: Vec<usize>,
    /// Per original column: has an allowed entry.
    col_is_live: Vec<bool>,
    /// Reduced, finite, short-side-major cost matrix.
    reduced: Vec<f64>,
    /// Buffers of the shortest augmenting path core.
    core: AugmentingPathWorkspace,
}

impl AssignmentSolver {
    /// Preallocates every buffer for problems up to `max_rows × max_cols`.
    ///
    /// # Panics
    ///
    /// Panics if `max_rows * max_cols` overflows `usize` or the buffers cannot be allocated.
    pub fn with_capacity(max_rows: usize, max_cols: usize) -> Self {
        let cells = max_rows.checked_mul(max_cols).expect("assignment solver capacity overflows usize");
        let short = max_rows.min(max_cols);
        let long = max_rows.max(max_cols);
        Self {
            max_rows,
            max_cols,
            live_rows: vec![0; max_rows],
            live_cols: vec![0; max_cols],
            col_is_live: vec![false; max_cols],
            reduced: vec![0.0; cells],
            core: AugmentingPathWorkspace::new(short, long),
        }
    }

    /// Largest number of rows [`solve`](Self::solve) accepts.
    pub fn max_rows(&self) -> usize {
        self.max_rows
    }

    /// Largest number of columns [`solve`](Self::solve) accepts.
    pub fn max_cols(&self) -> usize {
        self.max_cols
    }

    /// Solves one assignment problem.
    ///
    /// `costs` is row-major and `rows * cols` long; `f64::INFINITY` marks a forbidden (gated)
    /// pair, any other finite value is the cost of pairing that row with that column. Among all
    /// one-to-one assignments that use only allowed pairs, the solver finds one with the largest
    /// number of pairs and, among those, the smallest total cost. On success `row_to_col[r]` is
    /// `Some(c)` when row `r` is paired with column `c` and `None` when it stays unassigned, for
    /// every `r < rows`; entries beyond `rows` are not touched. When several assignments are
    /// optimal, which one is returned is unspecified.
    ///
    /// No heap memory is allocated.
    ///
    /// # Errors
    ///
    /// Returns an [`AssignmentError`] and leaves `row_to_col` untouched when the problem exceeds
    /// the capacity, the slice lengths do not match, a cost is NaN or negative infinity, or the
    /// allowed costs span a range too wide for `f64` arithmetic.
    pub fn solve(
        &mut self,
        rows: usize,
        cols: usize,
        costs: &[f64],
        row_to_col: &mut [Option<usize>],
    ) -> Result<AssignmentSummary, AssignmentError> {
        self.check_dimensions(rows, cols, costs, row_to_col)?;
        let live = self.find_live_lines(cols, costs)?;
        let shape = ReducedShape::new(&live)?;

        // All checks passed: from here on the call succeeds.
        let row_to_col = &mut row_to_col[..rows];
        row_to_col.fill(None);
        if shape.short == 0 {
            return Ok(AssignmentSummary { pairs: 0, total_cost: 0.0 });
        }
        self.write_reduced(cols, costs, &live, &shape);
        self.core.solve(shape.short, shape.long, &self.reduced[..shape.short * shape.long]);
        Ok(self.read_pairs(cols, costs, &live, &shape, row_to_col))
    }

    /// Checks the problem against the capacity and the slices against the problem.
    fn check_dimensions(
        &self,
        rows: usize,
        cols: usize,
        costs: &[f64],
        row_to_col: &[Option<usize>],
    ) -> Result<(), AssignmentError> {
        if rows > self.max_rows || cols > self.max_cols {
            return Err(AssignmentError::CapacityExceeded {
                rows,
                cols,
                max_rows: self.max_rows,
                max_cols: self.max_cols,
            });
        }
        // Cannot overflow: bounded by the capacity product checked in `with_capacity`.
        let expected = rows * cols;
        if costs.len() != expected {
            return Err(AssignmentError::CostLengthMismatch { rows, cols, expected, actual: costs.len() });
        }
        if row_to_col.len() < rows {
            return Err(AssignmentError::OutputTooShort { rows, actual: row_to_col.len() });
        }
        Ok(())
    }

    /// Validates every entry of the row-major `costs` (`cols` columns), records the live rows
    /// and columns (those with an allowed entry) in `live_rows` and `live_cols`, and finds the
    /// range of the allowed costs.
    fn find_live_lines(&mut self, cols: usize, costs: &[f64]) -> Result<LiveLines, AssignmentError> {
        let col_is_live = &mut self.col_is_live[..cols];
        col_is_live.fill(false);
        let mut live = LiveLines { rows: 0, cols: 0, lowest: f64::INFINITY, highest: f64::NEG_INFINITY };
        if cols > 0 {
            for (row, row_costs) in costs.chunks_exact(cols).enumerate() {
                let mut row_is_live = false;
                for (col, &cost) in row_costs.iter().enumerate() {
                    if cost.is_finite() {
                        row_is_live = true;
                        col_is_live[col] = true;
                        live.lowest = live.lowest.min(cost);
                        live.highest = live.highest.max(cost);
                    } else if cost.is_nan() {
                        return Err(AssignmentError::NanCost { row, col });
                    } else if cost == f64::NEG_INFINITY {
                        return Err(AssignmentError::NegativeInfiniteCost { row, col });
                    }
                }
                if row_is_live {
                    self.live_rows[live.rows] = row;
                    live.rows += 1;
                }
            }
        }
        for (col, &is_live) in col_is_live.iter().enumerate() {
            if is_live {
                self.live_cols[live.cols] = col;
                live.cols += 1;
            }
        }
        Ok(live)
    }

    /// Writes the reduced, finite, short-side-major matrix of the live lines into `reduced`,
    /// forbidden entries replaced by the substitute value.
    fn write_reduced(&mut self, cols: usize, costs: &[f64], live: &LiveLines, shape: &ReducedShape) {
        let live_rows = &self.live_rows[..live.rows];
        let live_cols = &self.live_cols[..live.cols];
        let reduced = &mut self.reduced[..shape.short * shape.long];
        let finite_or_forbidden = |cost: f64| {
            if cost.is_finite() {
                cost
            } else {
                shape.forbidden_cost
            }
        };
        if shape.transposed {
            for (line, &col) in reduced.chunks_exact_mut(shape.long).zip(live_cols) {
                for (slot, &row) in line.iter_mut().zip(live_rows) {
                    *slot = finite_or_forbidden(costs[row * cols + col]);
                }
            }
        } else {
            for (line, &row) in reduced.chunks_exact_mut(shape.long).zip(live_rows) {
                let row_costs = &costs[row * cols..(row + 1) * cols];
                for (slot, &col) in line.iter_mut().zip(live_cols) {
                    *slot = finite_or_forbidden(row_costs[col]);
                }
            }
        }
    }

    /// Translates the core's assignment back to original rows and columns in `row_to_col`,
    /// dropping pairs on forbidden entries, and sums the costs of the pairs kept.
    fn read_pairs(
        &self,
        cols: usize,
        costs: &[f64],
        live: &LiveLines,
        shape: &ReducedShape,
        row_to_col: &mut [Option<usize>],
    ) -> AssignmentSummary {
        let live_rows = &self.live_rows[..live.rows];
        let live_cols = &self.live_cols[..live.cols];
        let mut pairs = 0;
        let mut total_cost = 0.0;
        for (short_index, &long_index) in self.core.col_for_row[..shape.short].iter().enumerate() {
            let (row, col) = if shape.transposed {
                (live_rows[long_index], live_cols[short_index])
            } else {
                (live_rows[short_index], live_cols[long_index])
            };
            let cost = costs[row * cols + col];
            if cost.is_finite() {
                row_to_col[row] = Some(col);
                pairs += 1;
                total_cost += cost;
            }
        }
        AssignmentSummary { pairs, total_cost }
    }
}

/// What pruning found: how many rows and columns are live (their original indices lead
/// [`AssignmentSolver`]'s `live_rows` and `live_cols`) and the range of the allowed costs
/// (`lowest > highest` when there is none).
#[derive(Debug, Clone, Copy)]
struct LiveLines {
    rows: usize,
    cols: usize,
    lowest: f64,
    highest: f64,
}

/// The reduced problem: its orientation, its sizes and the substitute `M` for forbidden
/// entries (see the module documentation).
#[derive(Debug, Clone, Copy)]
struct ReducedShape {
    /// The live columns are the short side (more live rows than columns survive pruning).
    transposed: bool,
    /// Lines on the short side, `n`.
    short: usize,
    /// Lines on the long side.
    long: usize,
    /// `M`; zero when `short` is zero.
    forbidden_cost: f64,
}

impl ReducedShape {
    /// Orientation and `M` for the live lines; refuses allowed costs whose range would let the
    /// core's intermediate values overflow `f64`.
    fn new(live: &LiveLines) -> Result<Self, AssignmentError> {
        let transposed = live.rows > live.cols;
        let (short, long) = if transposed { (live.cols, live.rows) } else { (live.rows, live.cols) };
        let (lowest, highest) = (live.lowest, live.highest);
        let mut forbidden_cost = 0.0;
        if short > 0 {
            let span = highest - lowest;
            let scale = span + lowest.abs().max(highest.abs()).max(1.0);
            let lines = short as f64 + 1.0;
            forbidden_cost = highest + lines * scale;
            let bound = OVERFLOW_HEADROOM * lines * (forbidden_cost.abs() + lowest.abs());
            if !bound.is_finite() {
                return Err(AssignmentError::CostRangeTooLarge { lowest, highest });
            }
        }
        Ok(Self { transposed, short, long, forbidden_cost })
    }
}

/// Buffers of the shortest augmenting path core, for up to `short × long` finite problems.
#[derive(Debug, Clone)]
struct AugmentingPathWorkspace {
    /// Dual potential of each row.
    row_potential: Vec<f64>,
    /// Dual potential of each column.
    col_potential: Vec<f64>,
    /// Column matched to each row, or [`UNASSIGNED`].
    col_for_row: Vec<usize>,
    /// Row matched to each column, or [`UNASSIGNED`].
    row_for_col: Vec<usize>,
    /// Row preceding each column on the current shortest path tree.
    predecessor: Vec<usize>,
    /// Tentative shortest path length to each column.
    distance: Vec<f64>,
    /// Columns not yet settled by the current search (first `count` entries).
    unsettled: Vec<usize>,
    /// Rows visited by the current search, in visiting order.
    visited_rows: Vec<usize>,
    /// Columns settled by the current search.
    settled_cols: Vec<usize>,
}

impl AugmentingPathWorkspace {
    fn new(short: usize, long: usize) -> Self {
        Self {
            row_potential: vec![0.0; short],
            col_potential: vec![0.0; long],
            col_for_row: vec![UNASSIGNED; short],
            row_for_col: vec![UNASSIGNED; long],
            predecessor: vec![UNASSIGNED; long],
            distance: vec![0.0; long],
            unsettled: vec![0; long],
            visited_rows: vec![0; short],
            settled_cols: vec![0; long],
        }
    }

    /// Computes a minimum cost assignment of all `n` rows of the finite row-major `n × m`
    /// matrix `cost` (`n ≤ m`), leaving it in `col_for_row[..n]`.
    fn solve(&mut self, n: usize, m: usize, cost: &[f64]) {
        debug_assert!(n <= m && cost.len() == n * m);
        let u = &mut self.row_potential[..n];
        let v = &mut self.col_potential[..m];
        let col_for_row = &mut self.col_for_row[..n];
        let row_for_col = &mut self.row_for_col[..m];
        let predecessor = &mut self.predecessor[..m];
        let distance = &mut self.distance[..m];
        let unsettled = &mut self.unsettled[..m];
        let visited_rows = &mut self.visited_rows[..n];
        let settled_cols = &mut self.settled_cols[..m];
        u.fill(0.0);
        v.fill(0.0);
        col_for_row.fill(UNASSIGNED);
        row_for_col.fill(UNASSIGNED);

        for start in 0..n {
            // Dijkstra over reduced costs from the free row `start` to the nearest free column.
            for (slot, col) in unsettled.iter_mut().zip(0..) {
                *slot = col;
            }
            let mut unsettled_count = m;
            distance.fill(f64::INFINITY);
            let mut visited_count = 0;
            let mut settled_count = 0;
            let mut row = start;
            let mut path_length = 0.0;
            let sink = loop {
                visited_rows[visited_count] = row;
                visited_count += 1;
                let offset = path_length - u[row];
                let row_costs = &cost[row * m..(row + 1) * m];
                let mut lowest = f64::INFINITY;
                let mut best = 0;
                for (position, &col) in unsettled[..unsettled_count].iter().enumerate() {
                    let reduced = offset + row_costs[col] - v[col];
                    if reduced < distance[col] {
                        predecessor[col] = row;
                        distance[col] = reduced;
                    }
                    let candidate = distance[col];
                    // Prefer free columns on ties: the search can stop there at once.
                    if candidate < lowest || (candidate == lowest && row_for_col[col] == UNASSIGNED) {
                        lowest = candidate;
                        best = position;
                    }
                }
                path_length = lowest;
                let col = unsettled[best];
                unsettled_count -= 1;
                unsettled[best] = unsettled[unsettled_count];
                settled_cols[settled_count] = col;
                settled_count += 1;
                if row_for_col[col] == UNASSIGNED {
                    break col;
                }
                row = row_for_col[col];
            };

            // Update the potentials so that reduced costs stay non-negative and the pairs along
            // the new path become tight.
            u[start] += path_length;
            for &row in &visited_rows[1..visited_count] {
                u[row] += path_length - distance[col_for_row[row]];
            }
            for &col in &settled_cols[..settled_count] {
                v[col] -= path_length - distance[col];
            }

            augment(start, sink, predecessor, col_for_row, row_for_col);
        }
    }
}

/// Flips the matching along the shortest path found from the free row `start` back from its
/// free column `sink`: every column on it takes its predecessor row.
#[inline]
fn augment(
    start: usize,
    sink: usize,
    predecessor: &[usize],
    col_for_row: &mut [usize],
    row_for_col: &mut [usize],
) {
    let mut col = sink;
    loop {
        let row = predecessor[col];
        row_for_col[col] = row;
        let previous = col_for_row[row];
        col_for_row[row] = col;
        if row == start {
            break;
        }
        col = previous;
    }
}
