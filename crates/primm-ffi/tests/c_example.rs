//! The C and C++ examples, built as a user would build them, write the same track CSV file as
//! `primm track --method imm`, byte for byte:
//!
//! * `examples/c/track_csv.c` and `examples/cpp/track_csv.cpp`, compiled with the system
//!   compilers against `include/` and linked with `libprimm_ffi.a` by the plain link line,
//!   link without a warning and with a non-executable stack (`readelf -lW`);
//! * the C++ wrapper's own checks (`tests/cpp/wrapper.cpp`) pass;
//! * `tools/install_c_api.sh` installs a package that CMake (`find_package(primm)`, static and
//!   shared) and pkg-config (`primm-static`, `primm`) build the examples against.
//!
//! The static library is the one cargo built for this test run: cargo builds every crate type of
//! primm-ffi's library (`staticlib`, `cdylib`, `rlib`) before it links this test against it,
//! into the directory of this test's executable. A nested `cargo build -p primm-ffi` would
//! resolve features for primm-ffi alone, and since these library files carry no hash in their
//! names, it would overwrite them and rebuild the dependency graph on every run.
//!
//! CMake and pkg-config come from the test virtual environment (`tools/requirements-test.txt`,
//! which `./test.sh` installs and puts first in `PATH`). Where they are missing the CMake test
//! says so and passes, except under `CI` (set by CI services), where it fails.

use primm_core::config::Config;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use primm_predictor::predictor_for;
use primm_sim::io::track_csv::{TrackCsvWriter, WORLD_COLUMNS};
use primm_sim::io::{read_sequence_file, write_sequence_file};
use primm_sim::scenario::{Preset, ScenarioGenerator, Split};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// The path of `libprimm_ffi.a` that cargo built with this test's executable.
fn static_library() -> PathBuf {
    let executable = std::env::current_exe().expect("the test knows its executable");
    let library = executable.with_file_name("libprimm_ffi.a");
    assert!(library.is_file(), "cargo built no {} beside the test", library.display());
    library
}

/// A fresh scratch directory for one test.
fn scratch_directory(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-ffi-{name}-{}", std::process::id()));
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `command`, panics with its output when it fails, and returns the output.
fn run_checked(command: &mut Command, what: &str) -> Output {
    let output = command.output().unwrap_or_else(|error| panic!("cannot run {what} ({command:?}): {error}"));
    assert!(
        output.status.success(),
        "{what} failed ({command:?}):\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// Compiles and links with the compiler of `compiler_variable` (`CC`, `CXX`; `default` when
/// unset) and `arguments`; the compiler and linker must print nothing (no warning).
fn compile(compiler_variable: &str, default: &str, arguments: &[OsString], what: &str) {
    let compiler = std::env::var_os(compiler_variable).unwrap_or_else(|| default.into());
    let output = run_checked(Command::new(&compiler).args(arguments), what);
    let printed =
        String::from_utf8_lossy(&output.stderr).into_owned() + &String::from_utf8_lossy(&output.stdout);
    assert!(printed.trim().is_empty(), "{what}: the compiler or linker printed:\n{printed}");
}

/// Compiles the C example into `dir`, linked with `libprimm_ffi.a` by the plain link line.
fn compile_c_example(dir: &Path, library: &Path) -> PathBuf {
    let workspace = Path::new(WORKSPACE);
    let executable = dir.join("track_csv");
    let mut arguments: Vec<OsString> =
        ["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-I"].map(OsString::from).to_vec();
    arguments.push(workspace.join("include").into());
    arguments.push(workspace.join("examples/c/track_csv.c").into());
    arguments.push(library.into());
    arguments.extend(["-lpthread", "-ldl", "-lm", "-o"].map(OsString::from));
    arguments.push(executable.clone().into());
    compile("CC", "cc", &arguments, "compiling and linking examples/c/track_csv.c");
    executable
}

/// Compiles the C++ example into `dir`, linked with `libprimm_ffi.a` by the plain link line.
fn compile_cpp_source(source: &Path, executable: &Path, library: &Path) {
    let workspace = Path::new(WORKSPACE);
    let mut arguments: Vec<OsString> =
        ["-std=c++17", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-I"].map(OsString::from).to_vec();
    arguments.push(workspace.join("include").into());
    arguments.push(source.into());
    arguments.push(library.into());
    arguments.extend(["-lpthread", "-ldl", "-lm", "-o"].map(OsString::from));
    arguments.push(executable.into());
    compile("CXX", "c++", &arguments, &format!("compiling and linking {}", source.display()));
}

/// The `GNU_STACK` segment's flags of an ELF executable (`readelf -lW`), e.g. `RW` or `RWE`.
fn stack_flags(executable: &Path) -> String {
    let output = run_checked(Command::new("readelf").arg("-lW").arg(executable), "readelf -lW");
    let text = String::from_utf8_lossy(&output.stdout);
    let segment = text
        .lines()
        .find(|line| line.trim_start().starts_with("GNU_STACK"))
        .unwrap_or_else(|| panic!("{} has no GNU_STACK segment:\n{text}", executable.display()));
    // Type, offset, virtual and physical address, file and memory size, flags, alignment.
    let fields: Vec<&str> = segment.split_whitespace().collect();
    assert!(fields.len() >= 8, "unexpected readelf line: {segment}");
    fields[6..fields.len() - 1].concat()
}

/// Fails when `executable`'s stack is executable.
fn assert_non_executable_stack(executable: &Path) {
    let flags = stack_flags(executable);
    assert!(!flags.contains('E'), "{}: GNU_STACK is {flags}, an executable stack", executable.display());
    assert_eq!(flags, "RW", "{}: GNU_STACK flags", executable.display());
}

/// Writes a generated 3 s scene with ego poses to `dir/measurements.csv`, its classes under the
/// names other data sets give them (`Truck`, `bus`, `person`, `Bicycle`, ...), which `primm
/// track` and the C API read as the same classes.
fn write_scene(dir: &Path) -> PathBuf {
    let mut config = Preset::Default.config();
    config.sequence.duration_s = 3.0;
    let generated = ScenarioGenerator::new(config).unwrap().generate(Split::Evaluation, 0);
    let input = dir.join("measurements.csv");
    write_sequence_file(&input, &generated.sequence).unwrap();
    let text = std::fs::read_to_string(&input).unwrap();
    let mut relabelled = 0;
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(number, line)| {
            let mut fields: Vec<&str> = line.split(',').collect();
            let names: &[&str] = match fields[3] {
                "car" => &["Truck", "car", " bus ", "Passenger-Car"],
                "pedestrian" => &["person", "Pedestrian"],
                "two_wheeler" => &["Bicycle", "motorcycle", "Two Wheeler"],
                _ => return line.to_owned(),
            };
            fields[3] = names[number % names.len()];
            relabelled += 1;
            fields.join(",")
        })
        .collect();
    assert!(relabelled > 100, "{relabelled} measurements");
    std::fs::write(&input, lines.join("\n") + "\n").unwrap();
    input
}

/// What `primm track --method imm --input INPUT` writes (the logic of `src/cli/track.rs`).
fn primm_track_imm(input: &Path) -> String {
    let method = Method::Imm;
    let config = Config::default().with_modes(method.modes());
    let mut tracker = Tracker::with_predictor(
        config,
        predictor_for(method, None, primm_config::InferenceEngine::default()).unwrap(),
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

/// Runs an example `executable` on `input` and asserts that its track file equals `expected`
/// byte for byte.
fn assert_same_track_file(executable: &Path, input: &Path, expected: &str, what: &str) {
    let output = input.with_file_name(format!(
        "tracks-{}.csv",
        executable.file_name().unwrap().to_string_lossy().replace('/', "_")
    ));
    let run = Command::new(executable).arg(input).arg(&output).output().unwrap();
    assert!(run.status.success(), "{what} failed:\n{}", String::from_utf8_lossy(&run.stderr));
    let written = std::fs::read_to_string(&output).unwrap();
    for (number, (got, want)) in written.lines().zip(expected.lines()).enumerate() {
        assert_eq!(got, want, "{what}: line {} differs (left: the example, right: primm track)", number + 1);
    }
    assert_eq!(written.lines().count(), expected.lines().count(), "{what}: row counts differ");
    assert_eq!(written, expected, "{what}");
}

/// Sanity of the reference output: world-frame columns, enough rows, priors present.
fn check_reference(from_rust: &str) {
    // The generated scene carries ego poses: both track in the world frame.
    assert!(from_rust.lines().next().unwrap().ends_with(WORLD_COLUMNS), "no world-frame columns");
    let rows = from_rust.lines().count() - 1;
    assert!(rows > 100, "a 3 s scenario gives more than 100 track rows, got {rows}");
    assert!(from_rust.lines().skip(1).any(|line| !line.split(',').nth(6).unwrap().is_empty()));
}

#[test]
fn the_c_example_writes_the_same_track_file_as_primm_track_with_imm() {
    let dir = scratch_directory("c-example");
    let started = Instant::now();
    let library = static_library();
    let built = started.elapsed();
    let executable = compile_c_example(&dir, &library);
    eprintln!(
        "static library {} ready in {:.1} s, example compiled and linked in {:.1} s",
        library.display(),
        built.as_secs_f64(),
        (started.elapsed() - built).as_secs_f64()
    );
    assert_non_executable_stack(&executable);

    let input = write_scene(&dir);
    let from_rust = primm_track_imm(&input);
    check_reference(&from_rust);
    assert_same_track_file(&executable, &input, &from_rust, "examples/c/track_csv.c");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_cpp_example_writes_the_same_track_file_as_primm_track_with_imm() {
    let dir = scratch_directory("cpp-example");
    let executable = dir.join("track_csv_cpp");
    compile_cpp_source(
        &Path::new(WORKSPACE).join("examples/cpp/track_csv.cpp"),
        &executable,
        &static_library(),
    );
    assert_non_executable_stack(&executable);

    let input = write_scene(&dir);
    let from_rust = primm_track_imm(&input);
    check_reference(&from_rust);
    assert_same_track_file(&executable, &input, &from_rust, "examples/cpp/track_csv.cpp");

    // Faults come out as the wrapper's exceptions, printed with the library's message.
    std::fs::write(
        dir.join("bad.csv"),
        "frame,t,gt_id,class,x,y,vr,rcs\n0,0.1,,car,1,2,3,4\n1,0.1,,car,1,2,3,4\n",
    )
    .unwrap();
    let run =
        Command::new(&executable).arg(dir.join("bad.csv")).arg(dir.join("bad-tracks.csv")).output().unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.starts_with("track_csv: frame 1: "), "{stderr}");
    assert!(stderr.contains("frame timestamp 0.1 s does not advance"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_cpp_wrapper_owns_its_tracker_and_reports_errors_as_exceptions() {
    let dir = scratch_directory("cpp-wrapper");
    let executable = dir.join("wrapper");
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cpp/wrapper.cpp");
    compile_cpp_source(&source, &executable, &static_library());
    let output = run_checked(&mut Command::new(&executable), "tests/cpp/wrapper.cpp");
    let printed = String::from_utf8_lossy(&output.stdout);
    assert!(printed.contains("all wrapper checks passed"), "{printed}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Whether this run is under a CI service (which sets `CI`), where a missing tool is a failure.
fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|value| !value.is_empty() && value != "false" && value != "0")
}

/// The first of `names` that runs with `--version`, or `None`.
fn find_tool(names: &[&str]) -> Option<String> {
    names
        .iter()
        .find(|name| Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success()))
        .map(|name| name.to_string())
}

/// The `NEEDED` entries of an ELF file (`readelf -dW`).
fn needed_libraries(executable: &Path) -> Vec<String> {
    let output = run_checked(Command::new("readelf").arg("-dW").arg(executable), "readelf -dW");
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter(|line| line.contains("(NEEDED)"))
        .filter_map(|line| line.split('[').nth(1).and_then(|rest| rest.split(']').next()).map(str::to_string))
        .collect()
}

#[test]
fn the_installed_package_builds_the_examples_with_cmake_and_pkg_config() {
    let Some(cmake) = find_tool(&["cmake"]) else {
        assert!(
            !under_ci(),
            "cmake is not in PATH: pip install -r tools/requirements-test.txt (./test.sh does)"
        );
        eprintln!("skipped: cmake is not in PATH (pip install -r tools/requirements-test.txt)");
        return;
    };
    let Some(pkg_config) = find_tool(&["pkg-config", "pkgconf"]) else {
        assert!(
            !under_ci(),
            "pkg-config is not in PATH: pip install -r tools/requirements-test.txt (./test.sh does)"
        );
        eprintln!("skipped: pkg-config is not in PATH (pip install -r tools/requirements-test.txt)");
        return;
    };
    // Ninja from the test environment where it is there (a C toolchain need not bring make).
    let generator = find_tool(&["ninja"]).map(|_| "-GNinja".to_string());
    let workspace = Path::new(WORKSPACE);
    let dir = scratch_directory("install");
    let prefix = dir.join("prefix");
    let library_dir = static_library().parent().unwrap().to_path_buf();
    run_checked(
        Command::new(workspace.join("tools/install_c_api.sh"))
            .arg("--library-dir")
            .arg(&library_dir)
            .arg(&prefix),
        "tools/install_c_api.sh",
    );
    // The wire header beside the C API's, as it is in the tree.
    assert_eq!(
        std::fs::read(prefix.join("include/primm_wire.h")).unwrap(),
        std::fs::read(workspace.join("crates/primm-wire/include/primm_wire.h")).unwrap()
    );
    // The C subscriber builds against the installed headers alone, without a warning.
    let mut arguments: Vec<OsString> =
        ["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-I"].map(OsString::from).to_vec();
    arguments.push(prefix.join("include").into());
    arguments.push(workspace.join("examples/c/subscriber.c").into());
    arguments.push("-o".into());
    arguments.push(dir.join("subscriber").into());
    compile("CC", "cc", &arguments, "building examples/c/subscriber.c against the installed primm_wire.h");
    let abi_version = primm_ffi::PRIMM_ABI_VERSION;
    let soname = format!("libprimm_ffi.so.{abi_version}");
    assert_eq!(std::fs::read_link(prefix.join("lib/libprimm_ffi.so")).unwrap(), Path::new(&soname));
    let dynamic =
        run_checked(Command::new("readelf").arg("-dW").arg(prefix.join("lib").join(&soname)), "readelf -dW");
    assert!(
        String::from_utf8_lossy(&dynamic.stdout).contains(&format!("Library soname: [{soname}]")),
        "the shared library's soname is {soname}"
    );

    let input = write_scene(&dir);
    let from_rust = primm_track_imm(&input);
    check_reference(&from_rust);

    // CMake: primm::primm, static (the default) and shared.
    for (linkage, shared) in [("static", "OFF"), ("shared", "ON")] {
        let build = dir.join(format!("cmake-{linkage}"));
        run_checked(
            Command::new(&cmake)
                .arg("-S")
                .arg(workspace.join("examples/cpp"))
                .arg("-B")
                .arg(&build)
                .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()))
                .arg(format!("-DPRIMM_USE_SHARED={shared}"))
                .arg("-DCMAKE_BUILD_TYPE=Release")
                .args(&generator),
            &format!("cmake configure ({linkage})"),
        );
        let output = run_checked(
            Command::new(&cmake).arg("--build").arg(&build),
            &format!("cmake --build ({linkage})"),
        );
        let printed = String::from_utf8_lossy(&output.stdout);
        assert!(
            !printed.to_lowercase().contains("warning"),
            "cmake --build ({linkage}) printed a warning:\n{printed}"
        );
        let executable = build.join("track_csv");
        assert_non_executable_stack(&executable);
        let needed = needed_libraries(&executable);
        assert_eq!(needed.contains(&soname), shared == "ON", "{linkage}: NEEDED {needed:?}");
        let executable_copy = dir.join(format!("track_csv_cmake_{linkage}"));
        std::fs::copy(&executable, &executable_copy).unwrap();
        assert_same_track_file(&executable_copy, &input, &from_rust, &format!("CMake build ({linkage})"));
    }

    // pkg-config: primm-static and primm, with the C example.
    for package in ["primm-static", "primm"] {
        let flags = run_checked(
            Command::new(&pkg_config)
                .args(["--cflags", "--libs", package])
                .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig")),
            &format!("pkg-config {package}"),
        );
        let flags = String::from_utf8(flags.stdout).unwrap();
        let executable = dir.join(format!("track_csv_pkg_config_{package}"));
        let mut arguments: Vec<OsString> =
            ["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2"].map(OsString::from).to_vec();
        arguments.push(workspace.join("examples/c/track_csv.c").into());
        arguments.extend(flags.split_whitespace().map(OsString::from));
        if package == "primm" {
            arguments.push(format!("-Wl,-rpath,{}", prefix.join("lib").display()).into());
        }
        arguments.push("-o".into());
        arguments.push(executable.clone().into());
        compile("CC", "cc", &arguments, &format!("building the C example with pkg-config {package}"));
        assert_non_executable_stack(&executable);
        assert_eq!(needed_libraries(&executable).contains(&soname), package == "primm", "{package}");
        assert_same_track_file(&executable, &input, &from_rust, &format!("pkg-config {package}"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
