//! A configuration file laid over the shipped defaults: a file of one key tracks exactly like
//! the shipped file with that key changed, and `primm config show` prints what is in effect.

use primm_config::DEFAULT_CONFIG_TOML;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::process::Command;

/// A generated four-radar sequence (one radar per frame, with ego poses).
fn four_radar_frames() -> Vec<Frame> {
    let generated = ScenarioGenerator::from_preset(Preset::Default).generate(Split::Validation, 0);
    let frames: Vec<Frame> =
        generated.sequence.frames.iter().map(|frame| frame.to_frame().unwrap()).collect();
    let sensors: std::collections::BTreeSet<u16> =
        frames.iter().flat_map(|frame| frame.measurements.iter().filter_map(|m| m.sensor_id)).collect();
    assert_eq!(sensors.len(), 4, "four radars: {sensors:?}");
    frames
}

/// Every output of every frame, with each number's bits (`{:?}` of an `f64` is exact).
fn track(config: Config, frames: &[Frame]) -> Vec<String> {
    let mut tracker = Tracker::new(config.with_modes(Method::Imm.modes())).unwrap();
    frames.iter().map(|frame| format!("{:?}", tracker.step(frame).unwrap())).collect()
}

#[test]
fn a_file_of_one_key_tracks_a_four_radar_sequence_bit_for_bit_like_the_shipped_file_with_that_key_changed() {
    let frames = four_radar_frames();
    let shipped = track(Config::default(), &frames);
    for (one_key, shipped_line, changed_line) in [
        (
            "[tracker]\nexistence_persistence_time_s = 5.0\n",
            "existence_persistence_time_s = 40.0",
            "existence_persistence_time_s = 5.0",
        ),
        (
            "[classes.car]\nmeasurement_noise_covariance_m2 = [[0.3, 0.0], [0.0, 0.3]]\n",
            "measurement_noise_covariance_m2 = [[0.36, 0.0], [0.0, 0.36]]",
            "measurement_noise_covariance_m2 = [[0.3, 0.0], [0.0, 0.3]]",
        ),
    ] {
        assert_eq!(DEFAULT_CONFIG_TOML.matches(shipped_line).count(), 1, "{shipped_line}");
        let whole_file = DEFAULT_CONFIG_TOML.replace(shipped_line, changed_line);
        let from_one_key = primm_config::from_toml_str(one_key).unwrap();
        let from_whole_file = primm_config::from_toml_str(&whole_file).unwrap();
        assert_eq!(from_one_key, from_whole_file, "{one_key}");
        let tracks = track(from_one_key, &frames);
        assert_eq!(tracks, track(from_whole_file, &frames), "{one_key}");
        assert_ne!(tracks, shipped, "the key changes the tracks: {one_key}");
    }
}

fn primm(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(output.status.success(), "primm {args:?} failed:\n{}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8(output.stdout).unwrap()
}

fn temporary_file(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-layered-config-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn config_show_diff_prints_nothing_for_the_shipped_file_and_the_changed_key_for_a_one_key_file() {
    let shipped = concat!(env!("CARGO_MANIFEST_DIR"), "/config/primm.toml");
    assert_eq!(primm(&["config", "show", "--config", shipped, "--diff"]), "");
    assert_eq!(primm(&["config", "show", "--diff"]), "");
    let one_key = temporary_file("one_key.toml", "[tracker]\n# two seconds\nmax_coast_s = 2.0\n");
    let difference = primm(&["config", "show", "--config", one_key.to_str().unwrap(), "--diff"]);
    assert_eq!(difference.trim(), "[tracker]\nmax_coast_s = 2.0");
    // The whole configuration in effect reads back to itself.
    let shown = primm(&["config", "show", "--config", one_key.to_str().unwrap()]);
    let mut expected = Config::default();
    expected.tracker.max_coast_s = 2.0;
    assert_eq!(primm_config::from_toml_str(&shown).unwrap(), expected);
}

#[test]
fn config_show_refuses_an_unknown_key_with_its_line() {
    let path = temporary_file("unknown.toml", "[tracker]\nmax_coast_s = 2.0\nmax_coast_seconds = 2.0\n");
    let output = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["config", "show", "--config", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("max_coast_seconds") && stderr.contains("line 3"), "{stderr}");
}

#[test]
fn config_parameters_prints_the_committed_parameters_page() {
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/parameters.md")).unwrap();
    assert_eq!(primm(&["config", "parameters"]), committed);
}
