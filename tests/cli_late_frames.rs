//! `primm track` on a measurement file whose frames arrive out of order: a late frame writes
//! its own rows, so the track file holds the rows of in-order arrival.

use primm_sim::eval::identity::max_total_overlap;
use primm_sim::io::{read_sequence_file, write_sequence_file, Sequence};
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn primm(args: &[&str]) {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(output.status.success(), "primm {args:?} failed:\n{}", String::from_utf8_lossy(&output.stderr));
}

/// `primm track --method imm` of `input` into `output` (and the association file beside it).
fn track(input: &Path, output: &Path) {
    let associations = output.with_extension("associations.csv");
    primm(&[
        "track",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
        "--method",
        "imm",
        "--associations",
        associations.to_str().unwrap(),
    ]);
}

/// The data rows of a track file, each with its frame index.
fn rows(path: &Path) -> Vec<(u64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|line| (line.split(',').next().unwrap().parse().unwrap(), line.to_owned()))
        .collect()
}

/// IDF1 scored from a track file's rows (`track_id`, column 2; `gt_id`, column 8) against the
/// ground-truth object frames of the measurement file (`eq:idf1`).
fn idf1_of_track_file(sequence: &Sequence, rows: &[(u64, String)]) -> f64 {
    let truth_frames = sequence
        .frames
        .iter()
        .flat_map(|f| &f.measurements)
        .filter(|m| m.measurement.ground_truth_id.is_some());
    let truth_frames = truth_frames.count() as u64;
    let mut overlap = BTreeMap::new();
    for (_, row) in rows {
        let fields: Vec<&str> = row.split(',').collect();
        let track: u64 = fields[2].parse().unwrap();
        let truth: i64 = fields[8].parse().unwrap();
        if truth >= 0 {
            *overlap.entry((truth as u64, track)).or_insert(0u64) += 1;
        }
    }
    let true_positives = max_total_overlap(&overlap);
    2.0 * true_positives as f64 / (rows.len() as u64 + truth_frames) as f64
}

#[test]
fn a_shuffled_four_radar_sequence_gives_the_track_file_of_in_order_arrival_but_the_rows_written_early() {
    let dir = tempdir("late-frames");
    // Four radars scanning in turn every 15 ms, with ego poses.
    let generated = ScenarioGenerator::from_preset(Preset::Default).generate(Split::Evaluation, 0);
    let in_order_input = dir.join("in_order.csv");
    write_sequence_file(&in_order_input, &generated.sequence).unwrap();
    // Every fifth pair of neighbouring frames arrives swapped: the newer frame first.
    let mut shuffled = generated.sequence.clone();
    let mut written_early = BTreeSet::new();
    for first in (5..shuffled.frames.len() - 1).step_by(10) {
        shuffled.frames.swap(first, first + 1);
        written_early.insert(shuffled.frames[first].index);
    }
    let shuffled_input = dir.join("shuffled.csv");
    write_sequence_file(&shuffled_input, &shuffled).unwrap();
    let sequence = read_sequence_file(&in_order_input).unwrap();
    assert!(sequence.frames.len() > 400, "{}", sequence.frames.len());
    assert!(sequence.frames.iter().filter_map(|f| f.sensor_id).collect::<BTreeSet<_>>().len() == 4);

    let (in_order_tracks, shuffled_tracks) =
        (dir.join("in_order_tracks.csv"), dir.join("shuffled_tracks.csv"));
    track(&in_order_input, &in_order_tracks);
    track(&shuffled_input, &shuffled_tracks);
    let (in_order, shuffled) = (rows(&in_order_tracks), rows(&shuffled_tracks));

    // Every late frame wrote rows, after the newer frame that came before it.
    let order: Vec<u64> = shuffled.iter().map(|(frame, _)| *frame).collect();
    let stepped_back = order.windows(2).filter(|pair| pair[1] < pair[0]).count();
    // (A late frame when no track lives writes no rows, and one whose newer neighbour wrote none
    // does not step back: most, not all, show.)
    assert!(stepped_back * 4 > written_early.len() * 3, "{stepped_back} of {}", written_early.len());
    // The rows, as a set, are those of in-order arrival, but for the frames that came before a
    // late one (tracked without it).
    let kept = |rows: &[(u64, String)]| -> Vec<String> {
        let mut kept: Vec<String> = rows
            .iter()
            .filter(|(frame, _)| !written_early.contains(frame))
            .map(|(_, row)| row.clone())
            .collect();
        kept.sort();
        kept
    };
    assert_eq!(kept(&in_order), kept(&shuffled));
    // The measures: row count within 0.5 %, IDF1 scored from the file within 0.003.
    let ratio = shuffled.len() as f64 / in_order.len() as f64;
    assert!((ratio - 1.0).abs() <= 0.005, "{} rows against {}", shuffled.len(), in_order.len());
    let (idf1_in_order, idf1_shuffled) =
        (idf1_of_track_file(&sequence, &in_order), idf1_of_track_file(&sequence, &shuffled));
    assert!(idf1_in_order > 0.9, "{idf1_in_order}");
    assert!((idf1_shuffled - idf1_in_order).abs() <= 0.003, "IDF1 {idf1_shuffled} against {idf1_in_order}");
    println!(
        "{} frames, {} arrived early; rows {} (shuffled) against {} (in order), ratio {ratio:.4}; \
         IDF1 {idf1_shuffled:.4} against {idf1_in_order:.4}",
        sequence.frames.len(),
        written_early.len(),
        shuffled.len(),
        in_order.len()
    );

    // The association file has one row per measurement in both orders.
    for tracks in [&in_order_tracks, &shuffled_tracks] {
        let associations = std::fs::read_to_string(tracks.with_extension("associations.csv")).unwrap();
        assert_eq!(associations.lines().count() - 1, sequence.measurement_count());
    }
}

fn tempdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
