//! `primm soak` through the command line: a short soak of each method finds no violation and
//! prints its report; a configuration the tracker refuses fails the command.

use std::process::Command;

/// Runs `primm soak` with `args`; (success, stdout, stderr).
fn soak(args: &[&str]) -> (bool, String, String) {
    let output =
        Command::new(env!("CARGO_BIN_EXE_primm")).arg("soak").args(args).output().expect("primm runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The number after `label` on its report line.
fn figure(report: &str, label: &str) -> u64 {
    let line = report
        .lines()
        .find(|line| line.trim_start().starts_with(label))
        .unwrap_or_else(|| panic!("no '{label}' in\n{report}"));
    line.trim_start()[label.len()..]
        .trim_start()
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .and_then(|digits| digits.parse().ok())
        .unwrap_or_else(|| panic!("no number after '{label}' in '{line}'"))
}

fn a_short_soak_passes(method: &str, frames: u64, extra: &[&str]) {
    let frames_text = frames.to_string();
    let mut args =
        vec!["--method", method, "--frames", frames_text.as_str(), "--objects", "64", "--seed", "5"];
    args.extend_from_slice(extra);
    let (success, report, errors) = soak(&args);
    assert!(success, "{report}\n{errors}");
    assert_eq!(figure(&report, "invariant violations:"), 0, "{report}");
    assert_eq!(figure(&report, "frames:"), frames, "{report}");
    assert_eq!(figure(&report, "objects in view:"), 64, "{report}");
    assert!(figure(&report, "tracks:") >= 64, "every object gets a track: {report}");
    for label in ["resident set:", "step latency, first 10 %:", "step latency, last 10 %:"] {
        assert!(report.contains(label), "'{label}' missing from\n{report}");
    }
    assert!(report.contains("p50") && report.contains("p99") && report.contains("max"), "{report}");
}

#[test]
fn a_short_imm_soak_finds_no_violation_and_reports_memory_latency_and_tracks() {
    a_short_soak_passes("imm", 2000, &[]);
}

#[test]
fn a_short_pr_imm_soak_finds_no_violation_and_no_rejected_learned_displacement() {
    a_short_soak_passes("pr-imm", 300, &[]);
    let (_, report, _) = soak(&["--method", "pr-imm", "--frames", "300", "--objects", "64", "--seed", "5"]);
    assert_eq!(
        figure(&report, "learned predictions:"),
        0,
        "synchronous: every track gets its displacement\n{report}"
    );
    assert!(report.contains("0 rejected non-finite, 0 rejected implausible"), "{report}");
}

#[test]
fn a_configuration_the_tracker_refuses_fails_the_soak() {
    let path = std::env::temp_dir().join(format!("primm-soak-bad-{}.toml", std::process::id()));
    let text = primm_config::DEFAULT_CONFIG_TOML
        .replace("max_displacement_speed_mps = 100.0", "max_displacement_speed_mps = 0.0");
    std::fs::write(&path, text).unwrap();
    let (success, _, errors) = soak(&["--frames", "10", "--config", path.to_str().unwrap()]);
    std::fs::remove_file(&path).ok();
    assert!(!success);
    assert!(errors.contains("predictor.max_displacement_speed_mps"), "{errors}");
}
