//! The crate layout holds: `primm-core` stays free of I/O, runtime and CLI crates and builds
//! as a real `no_std` library, and every dependency between primm's crates points the way
//! `ARCHITECTURE.md` draws it (core ← config ← predictor, core ← wire ← ipc ← service,
//! core ← sim), with
//! the fuzz targets' crate on top of them and nothing depending on it; the publisher, the
//! subscriber, the tunnel and the recorder use the shared-memory plumbing (`primm-ipc`), not the
//! tracking service, and the Foxglove SDK and MCAP crates stay in the recorder.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The packages in `cargo tree -p PACKAGE` (normal dependencies, build-dependencies included),
/// with `extra` arguments.
fn dependency_names(package: &str, extra: &[&str]) -> BTreeSet<String> {
    let output = Command::new(env!("CARGO"))
        .current_dir(ROOT)
        .args(["tree", "--offline", "--locked", "-p", package, "--edges", "normal,build", "--prefix", "none"])
        .args(["--format", "{p}"])
        .args(extra)
        .output()
        .expect("cargo runs");
    assert!(output.status.success(), "cargo tree -p {package}: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

#[test]
fn primm_core_names_no_runtime_io_or_command_line_crate() {
    const FORBIDDEN: [&str; 14] = [
        "foxglove",
        "mcap",
        "tokio",
        "tract-onnx",
        "tract-core",
        "iceoryx2",
        "clap",
        "plotters",
        "csv",
        "rand",
        "tracing-subscriber",
        "signal-hook",
        "toml",
        "serde_json",
    ];
    for features in [&[][..], &["--no-default-features"][..], &["--all-features"][..]] {
        let names = dependency_names("primm-core", features);
        assert!(names.contains("primm-core") && names.contains("nalgebra"), "{names:?}");
        for forbidden in FORBIDDEN {
            assert!(!names.contains(forbidden), "primm-core {features:?} depends on {forbidden}: {names:?}");
        }
    }
    let names = dependency_names("primm-core", &["--no-default-features"]);
    assert!(!names.contains("serde") && !names.contains("multiversion"), "{names:?}");
}

#[test]
fn dependencies_between_primm_crates_point_one_way() {
    let primm = |package: &str| -> BTreeSet<String> {
        dependency_names(package, &[]).into_iter().filter(|name| name.starts_with("primm")).collect()
    };
    let set = |names: &[&str]| -> BTreeSet<String> { names.iter().map(|n| n.to_string()).collect() };
    assert_eq!(primm("primm-core"), set(&["primm-core"]));
    assert_eq!(primm("primm-config"), set(&["primm-config", "primm-core"]));
    assert_eq!(primm("primm-predictor"), set(&["primm-predictor", "primm-config", "primm-core"]));
    assert_eq!(primm("primm-wire"), set(&["primm-wire", "primm-core"]));
    assert_eq!(primm("primm-ipc"), set(&["primm-ipc", "primm-wire", "primm-core"]));
    assert_eq!(primm("primm-service"), set(&["primm-service", "primm-ipc", "primm-wire", "primm-core"]));
    assert_eq!(primm("primm-sim"), set(&["primm-sim", "primm-core"]));
    assert_eq!(primm("primm-ffi"), set(&["primm-ffi", "primm-config", "primm-predictor", "primm-core"]));
    assert_eq!(primm("primm-tunnel"), set(&["primm-tunnel", "primm-ipc", "primm-wire", "primm-core"]));
    assert_eq!(primm("primm-record"), set(&["primm-record", "primm-ipc", "primm-wire", "primm-core"]));
    assert_eq!(
        primm("primm-publisher"),
        set(&["primm-publisher", "primm-ipc", "primm-sim", "primm-wire", "primm-core"])
    );
    assert_eq!(
        primm("primm-subscriber"),
        set(&["primm-subscriber", "primm-record", "primm-ipc", "primm-sim", "primm-wire", "primm-core"])
    );
    assert_eq!(
        primm("primm-fuzz-targets"),
        set(&[
            "primm-fuzz-targets",
            "primm-config",
            "primm-predictor",
            "primm-ffi",
            "primm-wire",
            "primm-service",
            "primm-ipc",
            "primm-sim",
            "primm-core"
        ])
    );
}

#[test]
fn the_publisher_subscriber_tunnel_and_recorder_do_not_build_the_tracking_service() {
    for package in ["primm-publisher", "primm-subscriber", "primm-tunnel", "primm-record"] {
        let names = dependency_names(package, &[]);
        assert!(names.contains("primm-ipc"), "{package}: {names:?}");
        assert!(!names.contains("primm-service"), "{package} depends on primm-service");
    }
}

#[test]
fn no_library_crate_depends_on_the_fuzz_targets_or_a_fuzzing_crate() {
    let packages = [
        "primm-core",
        "primm-config",
        "primm-predictor",
        "primm-wire",
        "primm-ipc",
        "primm-service",
        "primm-sim",
        "primm-ffi",
        "primm-tunnel",
        "primm-record",
    ];
    for package in packages {
        let names = dependency_names(package, &[]);
        for forbidden in ["primm-fuzz-targets", "arbitrary", "libfuzzer-sys"] {
            assert!(!names.contains(forbidden), "{package} depends on {forbidden}");
        }
    }
}

#[test]
fn zenoh_is_built_into_primm_only_with_the_tunnel_feature() {
    for package in [
        "primm-core",
        "primm-ipc",
        "primm-service",
        "primm-wire",
        "primm-ffi",
        "primm-publisher",
        "primm-subscriber",
        "primm-record",
    ] {
        assert!(!dependency_names(package, &[]).contains("zenoh"), "{package} depends on zenoh");
    }
    assert!(!dependency_names("primm", &[]).contains("zenoh"), "a plain `primm` build includes zenoh");
    let with_tunnel = dependency_names("primm", &["--features", "tunnel"]);
    assert!(with_tunnel.contains("zenoh") && with_tunnel.contains("primm-tunnel"), "{with_tunnel:?}");
}

#[test]
fn primm_core_without_default_features_links_no_standard_library() {
    // The probe is `#![no_std]` and defines its own panic handler: if anything in primm-core's
    // graph linked std, the compiler would refuse a second `panic_impl`.
    let probe = Path::new(ROOT).join("tests/no_std_probe");
    let output = Command::new(env!("CARGO"))
        .current_dir(&probe)
        .args(["check", "--offline", "--quiet"])
        .env("CARGO_TARGET_DIR", Path::new(ROOT).join("target/no-std-probe"))
        .output()
        .expect("cargo runs");
    assert!(output.status.success(), "no_std probe: {}", String::from_utf8_lossy(&output.stderr));
}
