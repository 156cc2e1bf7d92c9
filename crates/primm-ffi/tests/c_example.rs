//! `examples/c/track_csv.c`, compiled with the system C compiler against `include/primm.h` and
//! `libprimm_ffi.a`, writes the same track CSV file as `primm track --method imm`, byte for
//! byte.
//!
//! The static library is the one cargo built for this test run: cargo builds every crate type of
//! primm-ffi's library (`staticlib`, `cdylib`, `rlib`) before it links this test against it,
//! into the directory of this test's executable. A nested `cargo build -p primm-ffi` would
//! resolve features for primm-ffi alone, and since these library files carry no hash in their
//! names, it would overwrite them and rebuild the dependency graph on every run.

use primm_core::config::Config;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use primm_predictor::predictor_for;
use primm_sim::io::track_csv::{TrackCsvWriter, WORLD_COLUMNS};
use primm_sim::io::{read_sequence_file, write_sequence_file};
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// The path of `libprimm_ffi.a` that cargo built with this test's executable.
fn static_library() -> PathBuf {
    let executable = std::env::current_exe().expect("the test knows its executable");
    let library = executable.with_file_name("libprimm_ffi.a");
    assert!(library.is_file(), "cargo built no {} beside the test", library.display());
    library
}

/// Compiles the example into `dir` and returns the executable.
fn compile_example(dir: &Path, library: &Path) -> PathBuf {
    let workspace = Path::new(WORKSPACE);
    let executable = dir.join("track_csv");
    let cc = std::env::var_os("CC").unwrap_or_else(|| "cc".into());
    let output = Command::new(&cc)
        .args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-I"])
        .arg(workspace.join("include"))
        .arg(workspace.join("examples/c/track_csv.c"))
        .arg(library)
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&executable)
        .output()
        .unwrap_or_else(|error| panic!("cannot run the C compiler {cc:?}: {error}"));
    assert!(
        output.status.success(),
        "compiling track_csv.c failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    executable
}

/// What `primm track --method imm --input INPUT` writes (the logic of `src/cli/track.rs`).
fn primm_track_imm(input: &Path) -> String {
    let method = Method::Imm;
    let config = Config::default().with_modes(method.modes());
    let mut tracker = Tracker::with_predictor(
        config,
        predictor_for(method, None, Config::default().predictor.engine).unwrap(),
    )
    .unwrap();
    let sequence = read_sequence_file(input).unwrap();
    let frames = sequence.to_frames().unwrap();
    let mut writer =
        TrackCsvWriter::for_sequence(Vec::new(), &sequence, tracker.config().frame.tracking_frame).unwrap();
    tracker.reset();
    for (recorded, frame) in sequence.frames.iter().zip(&frames) {
        let outputs = tracker.step(frame).unwrap();
        writer.write_frame(recorded.index, recorded.timestamp_s, outputs).unwrap();
    }
    String::from_utf8(writer.finish().unwrap()).unwrap()
}

#[test]
fn the_c_example_writes_the_same_track_file_as_primm_track_with_imm() {
    let dir = std::env::temp_dir().join(format!("primm-ffi-c-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    let started = Instant::now();
    let library = static_library();
    let built = started.elapsed();
    let executable = compile_example(&dir, &library);
    eprintln!(
        "static library {} ready in {:.1} s, example compiled and linked in {:.1} s",
        library.display(),
        built.as_secs_f64(),
        (started.elapsed() - built).as_secs_f64()
    );

    let mut config = Preset::Default.config();
    config.sequence.duration_s = 3.0;
    let generated = ScenarioGenerator::new(config).unwrap().generate(Split::Evaluation, 0);
    let input = dir.join("measurements.csv");
    write_sequence_file(&input, &generated.sequence).unwrap();
    let output = dir.join("tracks.csv");

    let run = Command::new(&executable).arg(&input).arg(&output).output().unwrap();
    assert!(run.status.success(), "track_csv failed:\n{}", String::from_utf8_lossy(&run.stderr));
    let from_c = std::fs::read_to_string(&output).unwrap();
    let from_rust = primm_track_imm(&input);

    // The generated scene carries ego poses: both track in the world frame.
    assert!(from_rust.lines().next().unwrap().ends_with(WORLD_COLUMNS), "no world-frame columns");
    let rows = from_rust.lines().count() - 1;
    assert!(rows > 100, "a 3 s scenario gives more than 100 track rows, got {rows}");
    assert!(from_rust.lines().skip(1).any(|line| !line.split(',').nth(6).unwrap().is_empty()));
    for (number, (c, rust)) in from_c.lines().zip(from_rust.lines()).enumerate() {
        assert_eq!(c, rust, "line {} differs (left: C example, right: primm track)", number + 1);
    }
    assert_eq!(from_c.lines().count(), from_rust.lines().count(), "row counts differ");
    assert_eq!(from_c, from_rust);
    std::fs::remove_dir_all(&dir).unwrap();
}
