//! Stepping a tracker through the C API allocates nothing: not for good frames, not for
//! rejected ones, not when copying tracks and counters out, not when dense crossing clusters
//! send every frame through the optimal assignment solver. A global allocator counts the
//! allocations of the calling thread.

use primm_ffi::*;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::ptr::{null, null_mut};

// The workspace's one counting allocator, shared with the integration tests.
#[path = "../../../tests/common/counting_allocator.rs"]
#[allow(dead_code)] // `allocations` is not used here
mod counting_allocator;
use counting_allocator::{count_allocations, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// The frames of a generated 5 s scenario as C measurement arrays, with their timestamps.
fn scenario_frames() -> Vec<(f64, Vec<PrimmMeasurement>)> {
    let mut config = Preset::Default.config();
    config.sequence.duration_s = 5.0;
    let generated = ScenarioGenerator::new(config).unwrap().generate(Split::Evaluation, 1);
    generated
        .sequence
        .frames
        .iter()
        .map(|frame| {
            let measurements = frame
                .measurements
                .iter()
                .map(|recorded| {
                    let m = recorded.measurement;
                    PrimmMeasurement {
                        x_m: m.x_m,
                        y_m: m.y_m,
                        radial_velocity_mps: m.radial_velocity_mps,
                        rcs_dbsm: m.rcs_dbsm,
                        ground_truth_id: m.ground_truth_id.map_or(PRIMM_NO_GROUND_TRUTH_ID, |id| id as i64),
                        sensor_id: m.sensor_id.map_or(PRIMM_NO_SENSOR_ID, i32::from),
                        class_code: m.class.code(),
                    }
                })
                .collect();
            (frame.timestamp_s, measurements)
        })
        .collect()
}

/// Steps every frame (each good frame followed by a rejected repeat of it) and copies tracks and
/// counters out after each; returns the allocations and the track rows updated.
fn run_counted(options: &PrimmTrackerOptions) -> (u64, usize) {
    let frames = scenario_frames();
    assert!(frames.len() > 300, "{} frames", frames.len());
    let mut tracker = null_mut();
    // SAFETY: valid options and out-pointer.
    assert_eq!(unsafe { primm_tracker_create(options, &mut tracker) }, PrimmStatus::Ok);
    let mut tracks = vec![
        // SAFETY: `PrimmTrack` is plain data (integers, doubles, a bool); all zeroes is valid.
        unsafe { std::mem::zeroed::<PrimmTrack>() };
        PRIMM_MAX_TRACKS
    ];
    let mut message = [0 as std::ffi::c_char; 256];
    let mut updated = 0;
    let allocations = count_allocations(|| {
        for (timestamp_s, measurements) in &frames {
            let mut summary = PrimmStepSummary::default();
            let mut stats = PrimmStats::default();
            let mut count = 0;
            // SAFETY: a live tracker, valid buffers of the lengths given.
            unsafe {
                let status = primm_tracker_step(
                    tracker,
                    *timestamp_s,
                    measurements.as_ptr(),
                    measurements.len(),
                    &mut summary,
                );
                assert_eq!(status, PrimmStatus::Ok);
                updated += summary.updated_track_count;
                let status = primm_tracker_step(
                    tracker,
                    *timestamp_s,
                    measurements.as_ptr(),
                    measurements.len(),
                    null_mut(),
                );
                assert_eq!(status, PrimmStatus::InvalidFrame);
                primm_tracker_last_error(tracker, message.as_mut_ptr(), message.len());
                let status = primm_tracker_tracks(tracker, tracks.as_mut_ptr(), tracks.len(), &mut count);
                assert_eq!(status, PrimmStatus::Ok);
                assert_eq!(count, summary.track_count);
                assert_eq!(primm_tracker_stats(tracker, &mut stats), PrimmStatus::Ok);
            }
        }
    });
    // SAFETY: a live tracker, not used afterwards.
    unsafe { primm_tracker_destroy(tracker) };
    (allocations, updated)
}

#[test]
fn stepping_with_imm_allocates_nothing() {
    let options = PrimmTrackerOptions { method: PRIMM_METHOD_IMM, ..primm_tracker_options_default() };
    let (allocations, updated) = run_counted(&options);
    assert_eq!(allocations, 0);
    assert!(updated > 300, "{updated} track updates");
}

#[test]
fn stepping_with_pr_imm_on_the_inference_thread_allocates_nothing_on_the_calling_thread() {
    let options = PrimmTrackerOptions {
        method: PRIMM_METHOD_PR_IMM,
        use_builtin_model: true,
        inference_thread: true,
        ..primm_tracker_options_default()
    };
    let (allocations, updated) = run_counted(&options);
    assert_eq!(allocations, 0);
    assert!(updated > 300, "{updated} track updates");
}

#[test]
fn failed_calls_without_a_tracker_allocate_nothing() {
    let mut count = 0;
    let allocations = count_allocations(|| {
        // SAFETY: NULL trackers are refused; other pointers are valid.
        unsafe {
            assert_eq!(primm_tracker_step(null_mut(), 0.0, null(), 0, null_mut()), PrimmStatus::NullArgument);
            assert_eq!(
                primm_tracker_tracks(null_mut(), null_mut(), 0, &mut count),
                PrimmStatus::NullArgument
            );
        }
    });
    assert_eq!(allocations, 0);
}

/// Clusters and cars per cluster of the crossing scene: 72 cars in groups of 8.
const CLUSTERS: usize = 9;
const CARS_PER_CLUSTER: usize = 8;

/// One 4 s crossing of `CLUSTERS` groups of `CARS_PER_CLUSTER` cars, 100 frames 40 ms apart:
/// in each group, 30 m from the next, car `i` drives from angle `2πi/n` on a circle of radius
/// 2 m along a chord to the angle `0.8π` further on, so every car of a group stays within 4 m
/// of the others (inside the 6 m car gate) and crosses their paths. A small deterministic
/// jitter plays the measurement noise.
fn crossing_frames() -> Vec<Vec<PrimmMeasurement>> {
    const FRAMES: usize = 100;
    const CROSSING_S: f64 = 4.0;
    const RADIUS_M: f64 = 2.0;
    (0..FRAMES)
        .map(|k| {
            let t = k as f64 * CROSSING_S / FRAMES as f64;
            let mut measurements = Vec::new();
            for cluster in 0..CLUSTERS {
                let centre = [40.0, -120.0 + 30.0 * cluster as f64];
                for i in 0..CARS_PER_CLUSTER {
                    let from = std::f64::consts::TAU * i as f64 / CARS_PER_CLUSTER as f64;
                    let to = from + 0.8 * std::f64::consts::PI;
                    let start = [centre[0] + RADIUS_M * from.cos(), centre[1] + RADIUS_M * from.sin()];
                    let end = [centre[0] + RADIUS_M * to.cos(), centre[1] + RADIUS_M * to.sin()];
                    let velocity = [(end[0] - start[0]) / CROSSING_S, (end[1] - start[1]) / CROSSING_S];
                    let jitter = 0.05 * ((k * 7 + i * 13 + cluster * 29) as f64).sin();
                    let x = start[0] + velocity[0] * t + jitter;
                    let y = start[1] + velocity[1] * t - jitter;
                    let range = (x * x + y * y).sqrt();
                    measurements.push(PrimmMeasurement {
                        x_m: x,
                        y_m: y,
                        radial_velocity_mps: (x * velocity[0] + y * velocity[1]) / range,
                        rcs_dbsm: 10.0,
                        ground_truth_id: (cluster * CARS_PER_CLUSTER + i) as i64,
                        sensor_id: PRIMM_NO_SENSOR_ID,
                        class_code: PRIMM_OBJECT_CLASS_CAR,
                    });
                }
            }
            measurements
        })
        .collect()
}

#[test]
fn stepping_dense_crossing_clusters_through_the_solver_allocates_nothing() {
    let frames = crossing_frames();
    // The scene packs eight cars closer than their own size, so confirmed tracks hold several
    // detections each, as under a point cloud, and `detections = "auto"` would group them; the
    // radar is declared an object radar, as the scene is here to load the assignment solver.
    let config = c"[frame]\nunmounted_detections = \"objects\"\n";
    let options = PrimmTrackerOptions {
        method: PRIMM_METHOD_IMM,
        config_toml: config.as_ptr(),
        ..primm_tracker_options_default()
    };
    let mut tracker = null_mut();
    // SAFETY: valid options and out-pointer.
    assert_eq!(unsafe { primm_tracker_create(&options, &mut tracker) }, PrimmStatus::Ok);
    const STEPS: usize = 2_000;
    let mut summaries = vec![PrimmStepSummary::default(); STEPS];
    let allocations = count_allocations(|| {
        for (k, summary) in summaries.iter_mut().enumerate() {
            let measurements = &frames[k % frames.len()];
            // SAFETY: a live tracker, a valid buffer of the length given.
            let status = unsafe {
                primm_tracker_step(
                    tracker,
                    k as f64 * 0.04,
                    measurements.as_ptr(),
                    measurements.len(),
                    summary,
                )
            };
            assert_eq!(status, PrimmStatus::Ok);
        }
    });
    // SAFETY: a live tracker, not used afterwards.
    unsafe { primm_tracker_destroy(tracker) };
    assert_eq!(allocations, 0);
    // After the first frame, which only starts tracks, every frame hands every group to the
    // solver as one cluster of at least 5 tracks × 5 measurements.
    let solved = &summaries[1..];
    let smallest = solved
        .iter()
        .map(|s| (s.smallest_solved_cluster_tracks, s.smallest_solved_cluster_measurements))
        .min_by_key(|(tracks, measurements)| tracks * measurements)
        .unwrap();
    let largest = solved
        .iter()
        .map(|s| (s.largest_solved_cluster_tracks, s.largest_solved_cluster_measurements))
        .max_by_key(|(tracks, measurements)| tracks * measurements)
        .unwrap();
    let clusters: usize = solved.iter().map(|s| s.solved_clusters).sum();
    println!(
        "{} frames: {clusters} clusters solved, smallest {smallest:?}, largest {largest:?}",
        solved.len()
    );
    assert!(solved.iter().all(|s| s.solved_clusters >= CLUSTERS), "a frame solved fewer clusters");
    assert!(smallest.0 >= 5 && smallest.1 >= 5, "smallest cluster solved {smallest:?}");
    let updated: usize = solved.iter().map(|s| s.updated_track_count).sum();
    assert!(updated > solved.len() * CLUSTERS * CARS_PER_CLUSTER * 9 / 10, "{updated} track updates");
}
