//! The tracker allocates nothing per frame: on lanes, where each gate holds one pair, and in
//! dense crossing clusters, where every frame hands clusters of at least 5 tracks × 5
//! measurements to the optimal assignment solver.

use crate::common;
use crate::common::counting_allocator;

use counting_allocator::count_allocations;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;

/// 10 000 frames of 64 objects, built before counting; frames cycle through 500 recorded ones
/// with timestamps shifted so that time keeps advancing.
fn run_counted<P: primm_core::predictor::DisplacementPredictor>(mut tracker: Tracker<P>) -> (u64, u64) {
    let base = common::scene_frames(&common::lanes(64), 500, 0.04, 0.2, 21);
    let mut frame: Frame = base[0].clone();
    let mut updates = 0u64;
    let allocations = count_allocations(|| {
        for k in 0..10_000usize {
            let source = &base[k % base.len()];
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&source.measurements);
            // Restart the scene every 500 frames; the old tracks are deleted after coasting.
            let outputs = tracker.step(&frame).expect("valid frame");
            updates += outputs.iter().filter(|o| o.measurement_index.is_some()).count() as u64;
        }
    });
    (allocations, updates)
}

#[test]
fn ten_thousand_frames_of_sixty_four_objects_allocate_nothing_without_the_learned_mode() {
    let tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    let (allocations, updates) = run_counted(tracker);
    assert_eq!(allocations, 0);
    assert_eq!(updates, 640_000);
}

#[test]
fn ten_thousand_frames_of_sixty_four_objects_allocate_nothing_with_an_oracle_predictor() {
    let oracle = common::LaneOracle { objects: common::lanes(64) };
    let tracker = Tracker::with_predictor(Config::default(), oracle).unwrap();
    let (allocations, updates) = run_counted(tracker);
    assert_eq!(allocations, 0);
    assert_eq!(updates, 640_000);
}

/// `config` with every radar delivering objects. The crossing scene packs eight cars closer than
/// their own size, so confirmed tracks hold several detections each, as under a point cloud,
/// and `detections = "auto"` would group them; the scene is here to load the assignment solver.
fn object_radars(mut config: Config) -> Config {
    use primm_core::grouping::DetectionModel;
    config.frame.unmounted_detections = DetectionModel::Objects;
    config.frame.sensors.iter_mut().for_each(|sensor| sensor.detections = DetectionModel::Objects);
    config
}

/// Clusters and cars per cluster of the crossing scene: 72 cars in groups of 8.
const CLUSTERS: usize = 9;
const CARS_PER_CLUSTER: usize = 8;

/// What the associator did over a counted run of the crossing scene.
#[derive(Debug, Default)]
struct SolverWork {
    /// Frames stepped.
    frames: u64,
    /// Frames in which every group went to the solver as a cluster of at least 5 × 5.
    frames_with_every_cluster_solved_at_5x5: u64,
    /// Frames in which every track was inside the gate of every measurement of its group.
    frames_with_every_pair_of_a_group_gated_in: u64,
    /// Clusters solved, all frames.
    clusters_solved: u64,
    /// Smallest and largest cluster solved in any frame (rows × columns).
    smallest: Option<(usize, usize)>,
    largest: (usize, usize),
    /// Track updates.
    updates: u64,
}

/// 5 000 frames of the crossing scene, built before counting: 100 recorded frames of one
/// 4 s crossing, played again and again with timestamps that keep advancing.
fn run_crossing_counted<P: primm_core::predictor::DisplacementPredictor>(
    mut tracker: Tracker<P>,
) -> (u64, SolverWork) {
    let objects = common::crossing_clusters(CLUSTERS, CARS_PER_CLUSTER, 4.0);
    let base = common::scene_frames(&objects, 100, 0.04, 0.1, 31);
    let mut frame: Frame = base[0].clone();
    let mut work = SolverWork::default();
    let allocations = count_allocations(|| {
        for k in 0..5_000usize {
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&base[k % base.len()].measurements);
            let outputs = tracker.step(&frame).expect("valid frame");
            work.updates += outputs.iter().filter(|o| o.measurement_index.is_some()).count() as u64;
            if k == 0 {
                // The first frame only starts tracks: nothing to associate.
                continue;
            }
            let stats = *tracker.association_stats();
            work.frames += 1;
            work.clusters_solved += stats.solved_clusters as u64;
            if stats.allowed_pairs == CLUSTERS * CARS_PER_CLUSTER * CARS_PER_CLUSTER {
                work.frames_with_every_pair_of_a_group_gated_in += 1;
            }
            let (rows, columns) = stats.smallest_solved_cluster;
            if stats.solved_clusters >= CLUSTERS && rows >= 5 && columns >= 5 {
                work.frames_with_every_cluster_solved_at_5x5 += 1;
            }
            if work.smallest.is_none_or(|(r, c)| rows * columns < r * c) {
                work.smallest = Some(stats.smallest_solved_cluster);
            }
            if stats.largest_cluster.0 * stats.largest_cluster.1 > work.largest.0 * work.largest.1 {
                work.largest = stats.largest_cluster;
            }
        }
    });
    (allocations, work)
}

fn assert_the_solver_ran_on_every_cluster(work: &SolverWork) {
    println!("crossing clusters: {work:?}");
    assert_eq!(work.frames, 4_999);
    assert_eq!(work.frames_with_every_cluster_solved_at_5x5, work.frames, "{work:?}");
    assert!(work.smallest.is_some_and(|(rows, columns)| rows >= 5 && columns >= 5), "{work:?}");
    assert!(work.clusters_solved >= work.frames * CLUSTERS as u64, "{work:?}");
    // The groups are dense, not chains: in most frames each of the 8 tracks of a group may take
    // any of its 8 measurements.
    assert!(work.frames_with_every_pair_of_a_group_gated_in > work.frames / 2, "{work:?}");
    // Most cars are updated in most frames: the solver's assignments were used.
    assert!(work.updates > 4_999 * (CLUSTERS * CARS_PER_CLUSTER) as u64 * 9 / 10, "{work:?}");
}

#[test]
fn dense_crossing_clusters_reach_the_assignment_solver_and_allocate_nothing_without_the_learned_mode() {
    let tracker = Tracker::new(object_radars(Config::default().with_modes(Method::Imm.modes()))).unwrap();
    let (allocations, work) = run_crossing_counted(tracker);
    assert_eq!(allocations, 0);
    assert_the_solver_ran_on_every_cluster(&work);
}

#[test]
fn dense_crossing_clusters_reach_the_assignment_solver_and_allocate_nothing_with_an_oracle_predictor() {
    let oracle = common::LaneOracle { objects: common::crossing_clusters(CLUSTERS, CARS_PER_CLUSTER, 4.0) };
    let tracker = Tracker::with_predictor(object_radars(Config::default()), oracle).unwrap();
    let (allocations, work) = run_crossing_counted(tracker);
    assert_eq!(allocations, 0);
    assert_the_solver_ran_on_every_cluster(&work);
}

#[test]
fn late_frames_tracked_in_their_place_allocate_nothing() {
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    let frames = common::scene_frames(&common::lanes(64), 600, 0.04, 0.2, 23);
    // Every third frame arrives two frames late: it is tracked in its place and the two newer
    // frames are tracked again.
    let mut order = Vec::with_capacity(frames.len());
    for block in frames.chunks(3) {
        order.extend(block.iter().skip(1));
        order.push(&block[0]);
    }
    let mut late = 0u64;
    let allocations = count_allocations(|| {
        for frame in &order {
            tracker.step(*frame).expect("within the late-frame window");
            late += u64::from(tracker.last_step().late());
        }
    });
    assert_eq!(allocations, 0);
    assert_eq!(late, 200);
    assert_eq!(tracker.stats().frames_replayed, 400);
}
