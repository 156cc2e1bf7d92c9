//! Per-class association of tracks to measurements (paper, Section III-E).
//!
//! For each class, every track is paired with the measurements of that class whose cost
//! `eq:association_cost` (computed from the fused prior) is within the class's gate; pairs
//! beyond the gate are forbidden, so that a far measurement starts a new track instead of being
//! forced onto an old one. Among the allowed pairs an optimal one-to-one assignment is found
//! ([`AssignmentSolver`]: as many pairs as possible, then the least total cost).
//!
//! # Keeping it sparse
//!
//! A dense `tracks × measurements` matrix would grow quadratically with the scene, while each
//! track can only reach the few measurements near it. So, per class:
//!
//! 1. **Gating by sorted x.** The measurements are sorted by x once per frame. The cost is at
//!    least the Euclidean distance, which is at least `|Δx|`, so a track's candidates lie in
//!    the x-window `prior.x ± gate`, found by binary search; only those costs are computed.
//!    The allowed pairs form a sparse bipartite graph.
//! 2. **Independent clusters.** Tracks and measurements linked by allowed pairs form connected
//!    clusters (union-find). No allowed pair joins two clusters, so both parts of the optimum
//!    (the number of pairs and the total cost) are sums over clusters and each cluster is solved
//!    on its own: a lone track-measurement pair directly, larger clusters by the optimal solver
//!    on their own small dense matrix.
//!
//! # Stages
//!
//! With `association.stages = "confirmed_first"` each class is associated in two stages, each
//! optimal within itself: the confirmed tracks first, over all of the class's measurements,
//! then the tentative tracks over the measurements the first stage left. A tentative track,
//! often born of a false detection, can then never take a measurement that a confirmed track
//! gates in and prefers. With `"joint"` all tracks of the class are one problem.
//!
//! # Costs
//!
//! `association.cost = "paper"` is `eq:association_cost` gated at `classes.<class>.paper_gate_m`;
//! `"likelihood"` is the negative log-likelihood of [`LikelihoodPrior`] gated by χ². Both
//! bound `|Δx|` per track, which is all the x-sorted gating needs.
//!
//! The result is the same optimum as one dense solve (a property test checks it against a dense
//! solve and against the `pathfinding` crate's Kuhn–Munkres), at a cost of
//! `O(T log M + pairs + Σ cluster³)` instead of `O(T·M + T²·M)`. All buffers are allocated once.

use super::assignment::{AssignmentError, AssignmentSolver};
use super::cost::{association_cost, LikelihoodPrior};
use super::reflection_memo::{ReflectionMemo, RowReflection, REFLECTION_MEMO_SENSORS};
use crate::config::{AssociationCost, AssociationStages, Config};
use crate::extent::{expected_reflection, ExpectedReflection, ExtentConfig, ObjectPrior};
use crate::imm::ImmPrior;
use crate::measurement::{FrameView, Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};
use crate::sensor_noise::MeasurementSensor;
use crate::track::Track;
use crate::track_table::MAX_TRACKS;
use alloc::boxed::Box;
use alloc::vec;
use arrayvec::ArrayVec;
use glam::DVec2;

/// Most allowed pairs of one class in one frame: every track with every measurement.
const MAX_PAIRS: usize = crate::limits::MAX_ASSOCIATION_PAIRS;

/// An allowed track-measurement pair of the current class: local row and column, cost.
#[derive(Debug, Clone, Copy, Default)]
struct Pair {
    row: u16,
    column: u16,
    cost: f64,
}

/// Statistics of the last [`Associator::associate`] call, for benchmarks and diagnostics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AssociationStats {
    /// Allowed (gated-in) track-measurement pairs, all classes.
    pub allowed_pairs: usize,
    /// Clusters with one track and one measurement, paired directly.
    pub single_pairs: usize,
    /// Clusters handed to the optimal solver.
    pub solved_clusters: usize,
    /// Rows × columns of the largest cluster handed to the solver.
    pub largest_cluster: (usize, usize),
    /// Rows × columns of the smallest cluster handed to the solver; `(0, 0)` when none was.
    pub smallest_solved_cluster: (usize, usize),
}

/// Reusable association workspace.
#[derive(Debug)]
pub struct Associator {
    solver: AssignmentSolver,
    /// Dense cost matrix of one cluster.
    costs: Box<[f64]>,
    /// Track-table index of each local row (tracks of the current class).
    rows: Box<ArrayVec<u16, MAX_TRACKS>>,
    /// Frame index of each local column (accepted measurements of the current class).
    columns: Box<ArrayVec<u16, MAX_MEASUREMENTS_PER_FRAME>>,
    /// (x, local column) of the current class's measurements, sorted by x.
    sorted_x: Box<ArrayVec<(f64, u16), MAX_MEASUREMENTS_PER_FRAME>>,
    /// Allowed pairs, grouped by row in row order.
    pairs: Box<[Pair]>,
    /// `pairs[row_start[r]..row_start[r + 1]]` are row `r`'s pairs.
    row_start: Box<[u32]>,
    /// Union-find parents over rows `0..R` and columns `R..R + C`.
    parent: Box<[u16]>,
    /// Rows and columns of each cluster, grouped by cluster root (counting sort).
    members: Box<[u16]>,
    member_start: Box<[u32]>,
    /// Position of a column inside its cluster's dense matrix.
    local_column: Box<[u16]>,
    row_to_column: Box<[Option<usize>]>,
    /// Whether each measurement of the frame was assigned in an earlier stage.
    taken: Box<[bool; MAX_MEASUREMENTS_PER_FRAME]>,
    /// The expected reflections of each local row's track, per sensor position, of the
    /// current stage (extended classes only).
    row_reflections: Box<[ReflectionMemo<RowReflection, REFLECTION_MEMO_SENSORS>]>,
    /// Per track of the table: the expected reflection of its assigned measurement's sensor,
    /// where gating computed it.
    assigned_reflections: Box<[Option<ExpectedReflection>]>,
    /// The largest x variance of the current stage's measurements from their radars' own noise,
    /// m² (widens the likelihood gate's x-window).
    largest_sensor_noise_xx_m2: f64,
    stats: AssociationStats,
}

/// Which tracks of a class one stage associates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Every track.
    All,
    /// Confirmed tracks (coasting ones included).
    Confirmed,
    /// Tentative tracks.
    Tentative,
}

impl Stage {
    fn admits(self, track: &Track) -> bool {
        match self {
            Stage::All => true,
            Stage::Confirmed => track.status.is_confirmed(),
            Stage::Tentative => !track.status.is_confirmed(),
        }
    }
}

impl Default for Associator {
    fn default() -> Self {
        Self::new()
    }
}

impl Associator {
    /// A workspace for up to [`MAX_TRACKS`] tracks and [`MAX_MEASUREMENTS_PER_FRAME`] measurements.
    pub fn new() -> Self {
        const NODES: usize = MAX_TRACKS + MAX_MEASUREMENTS_PER_FRAME;
        Self {
            solver: AssignmentSolver::with_capacity(MAX_TRACKS, MAX_MEASUREMENTS_PER_FRAME),
            costs: vec![0.0; MAX_PAIRS].into_boxed_slice(),
            rows: Box::new(ArrayVec::new()),
            columns: Box::new(ArrayVec::new()),
            sorted_x: Box::new(ArrayVec::new()),
            pairs: vec![Pair::default(); MAX_PAIRS].into_boxed_slice(),
            row_start: vec![0; MAX_TRACKS + 1].into_boxed_slice(),
            parent: vec![0; NODES].into_boxed_slice(),
            members: vec![0; NODES].into_boxed_slice(),
            member_start: vec![0; NODES + 1].into_boxed_slice(),
            local_column: vec![0; MAX_MEASUREMENTS_PER_FRAME].into_boxed_slice(),
            row_to_column: vec![None; MAX_TRACKS].into_boxed_slice(),
            taken: Box::new([false; MAX_MEASUREMENTS_PER_FRAME]),
            row_reflections: vec![ReflectionMemo::new(); MAX_TRACKS].into_boxed_slice(),
            assigned_reflections: vec![None; MAX_TRACKS].into_boxed_slice(),
            largest_sensor_noise_xx_m2: 0.0,
            stats: AssociationStats::default(),
        }
    }

    /// Assigns measurements to tracks of the same class, in the stages of
    /// `association.stages`.
    ///
    /// `accepted[j]` says whether measurement `j` passed validation; `priors[i]` is track `i`'s
    /// fused prior. On return `track_to_measurement[i]` holds the measurement assigned to track
    /// `i`, if any.
    pub fn associate<F: FrameView + ?Sized>(
        &mut self,
        tracks: &[Track],
        priors: &[ImmPrior],
        frame: &F,
        accepted: &[bool],
        sensors: &[MeasurementSensor],
        config: &Config,
        track_to_measurement: &mut [Option<u16>],
    ) -> Result<(), AssignmentError> {
        track_to_measurement[..tracks.len()].fill(None);
        self.assigned_reflections[..tracks.len()].fill(None);
        self.stats = AssociationStats::default();
        self.taken[..frame.len()].fill(false);
        let stages: &[Stage] = match config.association.stages {
            AssociationStages::Joint => &[Stage::All],
            AssociationStages::ConfirmedFirst => &[Stage::Confirmed, Stage::Tentative],
        };
        for class in ObjectClass::ALL {
            for &stage in stages {
                self.associate_stage(
                    tracks,
                    priors,
                    frame,
                    accepted,
                    sensors,
                    config,
                    class,
                    stage,
                    track_to_measurement,
                )?;
            }
        }
        Ok(())
    }

    /// One optimal assignment: the tracks of `class` that `stage` admits, the accepted
    /// measurements of `class` that no earlier stage took.
    fn associate_stage<F: FrameView + ?Sized>(
        &mut self,
        tracks: &[Track],
        priors: &[ImmPrior],
        frame: &F,
        accepted: &[bool],
        sensors: &[MeasurementSensor],
        config: &Config,
        class: ObjectClass,
        stage: Stage,
        track_to_measurement: &mut [Option<u16>],
    ) -> Result<(), AssignmentError> {
        self.rows.clear();
        self.rows.extend(
            (0..tracks.len())
                .filter(|&i| tracks[i].class == class && stage.admits(&tracks[i]))
                .map(|i| i as u16),
        );
        self.columns.clear();
        self.sorted_x.clear();
        self.largest_sensor_noise_xx_m2 = 0.0;
        for j in 0..frame.len() {
            if !accepted[j] || self.taken[j] {
                continue;
            }
            if let Ok(measurement) = frame.measurement(j) {
                if measurement.class == class {
                    self.sorted_x.push((measurement.x_m, self.columns.len() as u16));
                    self.columns.push(j as u16);
                    self.largest_sensor_noise_xx_m2 =
                        self.largest_sensor_noise_xx_m2.max(sensors[j].noise_m2.x_axis.x);
                }
            }
        }
        if self.rows.is_empty() || self.columns.is_empty() {
            return Ok(());
        }
        self.sorted_x.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        match config.association.cost {
            AssociationCost::Paper => self.gate_paper(tracks, priors, frame, sensors, config, class),
            AssociationCost::Likelihood => {
                self.gate_likelihood(tracks, priors, frame, sensors, config, class)
            }
        }
        self.cluster();
        self.solve_clusters(track_to_measurement)?;
        let extended = extent_of(config, class).is_some();
        for (r, &track_index) in self.rows.iter().enumerate() {
            if let Some(index) = track_to_measurement[usize::from(track_index)] {
                self.taken[usize::from(index)] = true;
                if extended {
                    let sensor = &sensors[usize::from(index)];
                    self.assigned_reflections[usize::from(track_index)] = self.row_reflections[r]
                        .find(sensor.position_m, sensor.reflection_scale)
                        .map(|entry| entry.reflection);
                }
            }
        }
        Ok(())
    }

    /// The expected reflection of track `track`'s object for the sensor of the measurement
    /// the last [`associate`](Self::associate) assigned to it, as gating computed it (exactly
    /// [`expected_reflection`] of its prior); `None` for a point class, an unassigned track, or
    /// a reflection the memo did not hold.
    pub fn assigned_reflection(&self, track: usize) -> Option<ExpectedReflection> {
        self.assigned_reflections.get(track).copied().flatten()
    }

    /// Statistics of the last call to [`associate`](Self::associate).
    pub fn stats(&self) -> &AssociationStats {
        &self.stats
    }

    /// Fills `pairs` with every pair of the current class that `eq:association_cost` gates in,
    /// row by row.
    fn gate_paper<F: FrameView + ?Sized>(
        &mut self,
        tracks: &[Track],
        priors: &[ImmPrior],
        frame: &F,
        sensors: &[MeasurementSensor],
        config: &Config,
        class: ObjectClass,
    ) {
        let gate = config.classes.get(class).paper_gate_m;
        let extent = extent_of(config, class);
        // An expected reflection moves the compared point by at most the extent's half diagonal.
        let window = gate + extent.map_or(0.0, |extent| extent.max_offset_m());
        let mut count = 0usize;
        for (r, &track_index) in self.rows.iter().enumerate() {
            self.row_start[r] = count as u32;
            let track = &tracks[usize::from(track_index)];
            let prior = &priors[usize::from(track_index)];
            let centre = prior.fused.mean;
            let object = extent.map(|_| prior.object_prior());
            self.row_reflections[r] = ReflectionMemo::new();
            let first = self.sorted_x.partition_point(|&(x, _)| x < centre.x - window);
            for &(x, column) in &self.sorted_x[first..] {
                if x > centre.x + window {
                    break;
                }
                let index = usize::from(self.columns[usize::from(column)]);
                let Ok(measurement) = frame.measurement(index) else {
                    continue;
                };
                let expected = match (extent, &object) {
                    (Some(extent), Some(object)) => {
                        let (sensor, scale) = (sensors[index].position_m, sensors[index].reflection_scale);
                        let entry = self.row_reflections[r].get(sensor, scale, || RowReflection {
                            reflection: expected_reflection(extent, object, sensor, scale),
                            prepared: None,
                        });
                        centre + entry.reflection.offset_m
                    }
                    _ => centre,
                };
                let cost = association_cost(
                    expected,
                    track.last_radial_velocity_mps,
                    &measurement,
                    &config.association,
                );
                if cost <= gate {
                    self.pairs[count] = Pair { row: r as u16, column, cost };
                    count += 1;
                }
            }
        }
        self.row_start[self.rows.len()] = count as u32;
        self.stats.allowed_pairs += count;
    }

    /// Fills `pairs` with every pair of the current class that the likelihood cost's χ² gate
    /// lets through, row by row.
    fn gate_likelihood<F: FrameView + ?Sized>(
        &mut self,
        tracks: &[Track],
        priors: &[ImmPrior],
        frame: &F,
        sensors: &[MeasurementSensor],
        config: &Config,
        class: ObjectClass,
    ) {
        let section = config.classes.get(class);
        let extent = extent_of(config, class);
        let [[xx, xy], [yx, yy]] = section.measurement_noise_covariance_m2;
        let noise = glam::DMat2::from_cols(glam::DVec2::new(xx, yx), glam::DVec2::new(xy, yy));
        let mut count = 0usize;
        for (r, &track_index) in self.rows.iter().enumerate() {
            self.row_start[r] = count as u32;
            let track = &tracks[usize::from(track_index)];
            let prepared = LikelihoodPrior::new(
                &priors[usize::from(track_index)].fused,
                noise,
                track.last_radial_velocity_mps,
                section.likelihood_radial_velocity_std_mps,
                config.association.likelihood_gate_chi2,
            );
            let Some(prepared) = prepared else { continue };
            let object = extent.map(|_| priors[usize::from(track_index)].object_prior());
            self.row_reflections[r] = ReflectionMemo::new();
            let sensor_spread_m2 = self.largest_sensor_noise_xx_m2;
            let (x, half) = (
                prepared.mean_m().x,
                match extent {
                    Some(extent) => {
                        prepared.x_half_window_with_spread_m(extent.max_spread_m2() + sensor_spread_m2)
                            + extent.max_offset_m()
                    }
                    None => prepared.x_half_window_with_spread_m(sensor_spread_m2),
                },
            );
            let reach_m =
                config.association.likelihood_gate_distance_m + extent.map_or(0.0, |e| e.max_offset_m());
            let half = half.min(reach_m);
            let first = self.sorted_x.partition_point(|&(mx, _)| mx < x - half);
            for &(mx, column) in &self.sorted_x[first..] {
                if mx > x + half {
                    break;
                }
                let index = usize::from(self.columns[usize::from(column)]);
                let Ok(measurement) = frame.measurement(index) else {
                    continue;
                };
                if measurement.position().distance_squared(prepared.mean_m()) > reach_m * reach_m {
                    continue;
                }
                let extended = extent.zip(object.as_ref());
                let cost = likelihood_pair_cost(
                    &prepared,
                    &mut self.row_reflections[r],
                    extended,
                    &measurement,
                    &sensors[index],
                );
                if let Some(cost) = cost {
                    self.pairs[count] = Pair { row: r as u16, column, cost };
                    count += 1;
                }
            }
        }
        self.row_start[self.rows.len()] = count as u32;
        self.stats.allowed_pairs += count;
    }

    /// Groups rows and columns into clusters linked by allowed pairs.
    fn cluster(&mut self) {
        let (rows, columns) = (self.rows.len(), self.columns.len());
        let nodes = rows + columns;
        for (i, parent) in self.parent[..nodes].iter_mut().enumerate() {
            *parent = i as u16;
        }
        let pair_count = self.row_start[rows] as usize;
        for pair in &self.pairs[..pair_count] {
            union(&mut self.parent, usize::from(pair.row), rows + usize::from(pair.column));
        }
        // Counting sort of the nodes by cluster root; afterwards `parent[node]` is its root.
        self.member_start[..=nodes].fill(0);
        for node in 0..nodes {
            let root = find(&mut self.parent, node);
            self.parent[node] = root as u16;
            self.member_start[root + 1] += 1;
        }
        for i in 0..nodes {
            self.member_start[i + 1] += self.member_start[i];
        }
        for node in 0..nodes {
            let root = usize::from(self.parent[node]);
            self.members[self.member_start[root] as usize] = node as u16;
            self.member_start[root] += 1;
        }
        // Every start was advanced by its cluster's size: shift them back.
        for i in (1..=nodes).rev() {
            self.member_start[i] = self.member_start[i - 1];
        }
        self.member_start[0] = 0;
    }

    /// Solves every cluster that has both a track and a measurement.
    fn solve_clusters(&mut self, track_to_measurement: &mut [Option<u16>]) -> Result<(), AssignmentError> {
        let (rows, columns) = (self.rows.len(), self.columns.len());
        let nodes = rows + columns;
        for root in 0..nodes {
            let members =
                &self.members[self.member_start[root] as usize..self.member_start[root + 1] as usize];
            // Rows come first in each cluster because nodes were placed in index order.
            let row_count = members.partition_point(|&node| usize::from(node) < rows);
            let (cluster_rows, cluster_columns) = members.split_at(row_count);
            if cluster_rows.is_empty() || cluster_columns.is_empty() {
                continue;
            }
            if cluster_rows.len() == 1 && cluster_columns.len() == 1 {
                // Linked, so the one pair is allowed.
                let r = usize::from(cluster_rows[0]);
                let column = usize::from(cluster_columns[0]) - rows;
                track_to_measurement[usize::from(self.rows[r])] = Some(self.columns[column]);
                self.stats.single_pairs += 1;
                continue;
            }
            let width = cluster_columns.len();
            let height = cluster_rows.len();
            for (local, &node) in cluster_columns.iter().enumerate() {
                self.local_column[usize::from(node) - rows] = local as u16;
            }
            let costs = &mut self.costs[..height * width];
            costs.fill(f64::INFINITY);
            for (local_row, &r) in cluster_rows.iter().enumerate() {
                let r = usize::from(r);
                for pair in &self.pairs[self.row_start[r] as usize..self.row_start[r + 1] as usize] {
                    costs[local_row * width + usize::from(self.local_column[usize::from(pair.column)])] =
                        pair.cost;
                }
            }
            self.solver.solve(height, width, costs, &mut self.row_to_column[..height])?;
            self.stats.solved_clusters += 1;
            let largest = &mut self.stats.largest_cluster;
            if height * width > largest.0 * largest.1 {
                *largest = (height, width);
            }
            let smallest = &mut self.stats.smallest_solved_cluster;
            if self.stats.solved_clusters == 1 || height * width < smallest.0 * smallest.1 {
                *smallest = (height, width);
            }
            for (local_row, &r) in cluster_rows.iter().enumerate() {
                if let Some(local) = self.row_to_column[local_row] {
                    let column = usize::from(cluster_columns[local]) - rows;
                    track_to_measurement[usize::from(self.rows[usize::from(r)])] = Some(self.columns[column]);
                }
            }
        }
        Ok(())
    }
}

/// Union-find root with path halving.
fn find(parent: &mut [u16], mut node: usize) -> usize {
    while usize::from(parent[node]) != node {
        let grandparent = parent[usize::from(parent[node])];
        parent[node] = grandparent;
        node = usize::from(grandparent);
    }
    node
}

fn union(parent: &mut [u16], a: usize, b: usize) {
    let (root_a, root_b) = (find(parent, a), find(parent, b));
    if root_a != root_b {
        // The smaller index becomes the root, keeping roots stable and the result deterministic.
        let (low, high) = (root_a.min(root_b), root_a.max(root_b));
        parent[high] = low as u16;
    }
}

/// The likelihood cost of one pair. For an extended class the track's expected reflection for
/// the measurement's radar comes from (or goes into) its `memo`; with the radar's own noise,
/// which differs between measurements, `S` is formed for this pair.
fn likelihood_pair_cost(
    prepared: &LikelihoodPrior,
    memo: &mut ReflectionMemo<RowReflection, REFLECTION_MEMO_SENSORS>,
    extended: Option<(&ExtentConfig, &ObjectPrior)>,
    measurement: &Measurement,
    sensor: &MeasurementSensor,
) -> Option<f64> {
    let own_noise = sensor.noise_m2 != glam::DMat2::ZERO;
    match extended {
        Some((extent, object)) => {
            let entry = memo.get(sensor.position_m, sensor.reflection_scale, || {
                let reflection =
                    expected_reflection(extent, object, sensor.position_m, sensor.reflection_scale);
                RowReflection { reflection, prepared: prepared.prepare_reflection(&reflection) }
            });
            if own_noise {
                let spread = ExpectedReflection {
                    covariance_m2: entry.reflection.covariance_m2 + sensor.noise_m2,
                    ..entry.reflection
                };
                prepared.cost_of_reflection(measurement, &spread)
            } else {
                entry
                    .prepared
                    .and_then(|reflection| prepared.cost_of_prepared_reflection(measurement, &reflection))
            }
        }
        None if own_noise => prepared.cost_of_reflection(
            measurement,
            &ExpectedReflection { offset_m: DVec2::ZERO, covariance_m2: sensor.noise_m2 },
        ),
        None => prepared.cost(measurement),
    }
}

/// The extent of `class` when it is tracked as an extended object.
fn extent_of(config: &Config, class: ObjectClass) -> Option<&ExtentConfig> {
    let extent = &config.classes.get(class).extent;
    extent.enabled.then_some(extent)
}
