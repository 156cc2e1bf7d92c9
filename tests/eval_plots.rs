//! Renders the evaluation figures for a synthetic two-object scene and checks their content.
//! The SVGs are left in Cargo's per-target temporary directory for viewing.

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::DVec2;
use primm_core::measurement::ObjectClass;
use primm_sim::eval::plots::{
    ground_truth_points, majority_ground_truth, mode_probability_svg, trajectory_svg,
    write_mode_probability_svg, write_trajectory_svg, TrajectoryPanel, TrajectoryPlotOptions,
    TrajectoryPoint,
};
use primm_sim::eval::{AssociationRecord, Method};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("eval-plots");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Two cars over 60 frames (0.1 s): object 1 drives along +x at 10 m/s, object 2 crosses it
/// heading +y at 6 m/s, then both keep going. Returns the evaluation rows of a tracker whose
/// posterior positions scatter with `noise_m` and which swaps object 2 to a new track at frame
/// `switch_frame` (if any), plus that tracker's posterior trajectory points.
fn scene(
    noise_m: f64,
    switch_frame: Option<u64>,
    seed: u64,
) -> (Vec<AssociationRecord>, Vec<TrajectoryPoint>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut records = Vec::new();
    let mut posterior = Vec::new();
    for k in 0..60u64 {
        let t = k as f64 * 0.1;
        let objects = [
            (1u64, DVec2::new(10.0 * t, 0.0), 1u64),
            (
                2u64,
                DVec2::new(30.0, -18.0 + 6.0 * t),
                match switch_frame {
                    Some(frame) if k >= frame => 3,
                    _ => 2,
                },
            ),
        ];
        for (gt, truth, track) in objects {
            let jitter = DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let estimate = truth + noise_m * jitter;
            records.push(AssociationRecord {
                frame: k,
                timestamp_s: t,
                ground_truth_id: Some(gt),
                class: ObjectClass::Car,
                measured: truth,
                true_position: Some(truth),
                true_velocity: None,
                origin: None,
                track_id: Some(track),
                prior: (k > 0).then_some(estimate),
                velocity: None,
                mode_probabilities: Some([0.35, 0.2, 0.3, 0.15]),
                track_confirmed: Some(true),
            });
            posterior.push(TrajectoryPoint { id: track, frame: k, position: estimate });
        }
    }
    (records, posterior)
}

fn count(haystack: &str, needle: &str) -> usize {
    haystack.matches(needle).count()
}

#[test]
fn trajectory_figure_has_one_panel_per_method_with_all_trajectories() {
    let methods = [(Method::Imm, 1.2, Some(35)), (Method::Learned, 0.6, None), (Method::PrImm, 0.3, None)];
    let mut ground_truth = Vec::new();
    let mut panels = Vec::new();
    for (index, (method, noise, switch)) in methods.into_iter().enumerate() {
        let (records, posterior) = scene(noise, switch, index as u64);
        ground_truth = ground_truth_points(&records);
        panels.push(TrajectoryPanel {
            title: method.label().to_string(),
            tracks: posterior,
            track_to_ground_truth: majority_ground_truth(&records),
        });
    }
    assert_eq!(panels[0].track_to_ground_truth, BTreeMap::from([(1, 1), (2, 2), (3, 2)]));
    let options = TrajectoryPlotOptions {
        title: Some("Synthetic crossing scene".into()),
        ..TrajectoryPlotOptions::default()
    };
    let svg = trajectory_svg(&ground_truth, &panels, &options).unwrap();
    assert!(svg.starts_with("<svg"));
    for text in
        ["IMM", "PR-IMM", "Synthetic crossing scene", "ground truth", "estimated track", "track start"]
    {
        assert!(svg.contains(text), "missing text {text}");
    }
    assert_eq!(count(&svg, "x, longitudinal [m]"), 3);
    assert_eq!(count(&svg, "y, lateral [m]"), 3);
    // Per panel: 2 ground-truth lines and one line plus one start marker per track (3, 2, 2
    // tracks); the legend adds one sample of each line style and one marker.
    let ground_truth_lines = count(&svg, "<polyline fill=\"none\" opacity=\"1\" stroke=\"#");
    let thick = count(&svg, "stroke-width=\"7\"");
    let thin = count(&svg, "stroke-width=\"2\"");
    assert_eq!(thick, 3 * 2 + 1);
    assert_eq!(thin, 2 * (3 + 2 + 2) + 2);
    assert_eq!(count(&svg, "<circle"), 3 + 2 + 2 + 1);
    assert!(ground_truth_lines >= 3 * 2 + 3 + 2 + 2);
    write_trajectory_svg(output_dir().join("trajectories.svg"), &ground_truth, &panels, &options).unwrap();
}

#[test]
fn single_point_tracks_are_drawn_as_dots() {
    let ground_truth = vec![
        TrajectoryPoint { id: 1, frame: 0, position: DVec2::new(0.0, 0.0) },
        TrajectoryPoint { id: 1, frame: 1, position: DVec2::new(1.0, 0.0) },
    ];
    let panel = TrajectoryPanel {
        title: "CV".into(),
        tracks: vec![TrajectoryPoint { id: 5, frame: 0, position: DVec2::new(0.5, 0.2) }],
        track_to_ground_truth: BTreeMap::new(),
    };
    let svg = trajectory_svg(&ground_truth, &[panel], &TrajectoryPlotOptions::default()).unwrap();
    // One filled dot for the track; the legend's start marker is the only hollow circle.
    let circles: Vec<&str> = svg.split("<circle").skip(1).filter_map(|rest| rest.split('>').next()).collect();
    assert_eq!(circles.len(), 2);
    assert_eq!(circles.iter().filter(|c| c.contains("fill=\"none\"")).count(), 1);
}

#[test]
fn mode_probability_bars_show_values_and_labels() {
    let means = [0.348, 0.185, 0.304, 0.163];
    let svg = mode_probability_svg(means, 17_866).unwrap();
    for text in ["PR", "CV", "CA", "CT", "0.348", "0.185", "0.304", "0.163", "17,866 updates"] {
        assert!(svg.contains(text), "missing text {text}");
    }
    assert!(svg.contains("mean posterior probability"));
    write_mode_probability_svg(output_dir().join("mode_probabilities.svg"), means, 17_866).unwrap();
}
