//! Replays every file of every committed fuzz corpus (`fuzz/corpus/TARGET/`) through its
//! target, on stable and without libFuzzer, so that every input that ever crashed primm, and
//! every seed, keeps passing. A target panics on a defect; the test then fails naming the file.

use primm_fuzz_targets::{Target, TARGETS};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn corpus_directory(target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus").join(target)
}

fn target_named(name: &str) -> Target {
    TARGETS.iter().find(|(target, _)| *target == name).map(|(_, run)| *run).expect("a known target")
}

/// Runs every corpus file of `name`; fails listing each file whose replay panicked.
fn replay_corpus(name: &str) {
    let directory = corpus_directory(name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&directory)
        .unwrap_or_else(|error| panic!("corpus {}: {error}", directory.display()))
        .map(|entry| entry.expect("a readable directory entry").path())
        .filter(|path| path.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "corpus {} holds no file", directory.display());
    let run = target_named(name);
    let failures: Vec<String> = files
        .iter()
        .filter_map(|path| {
            let data = std::fs::read(path).expect("a readable corpus file");
            catch_unwind(AssertUnwindSafe(|| run(&data))).err().map(|_| path.display().to_string())
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{name}: {} of {} corpus files panic: {failures:#?}",
        failures.len(),
        files.len()
    );
}

#[test]
fn every_target_has_a_corpus_directory() {
    for (name, _) in TARGETS {
        assert!(corpus_directory(name).is_dir(), "no corpus for {name}");
    }
}

#[test]
fn every_measurement_csv_corpus_file_replays_without_a_panic() {
    replay_corpus("measurement_csv");
}

#[test]
fn every_tracker_steps_corpus_file_replays_without_a_panic() {
    replay_corpus("tracker_steps");
}

#[test]
fn every_measurement_frame_bytes_corpus_file_replays_without_a_panic() {
    replay_corpus("measurement_frame_bytes");
}

#[test]
fn every_config_toml_corpus_file_replays_without_a_panic() {
    replay_corpus("config_toml");
}

#[test]
fn every_onnx_model_bytes_corpus_file_replays_without_a_panic() {
    replay_corpus("onnx_model_bytes");
}

#[test]
fn every_ego_pose_frames_corpus_file_replays_without_a_panic() {
    replay_corpus("ego_pose_frames");
}

#[test]
fn every_c_api_calls_corpus_file_replays_without_a_panic() {
    replay_corpus("c_api_calls");
}
