//! The C header `include/primm_wire.h` and the Python module `python/primm_wire.py`
//! describe exactly the bytes of the Rust wire types: same size, alignment and offset of every
//! field. The Rust field lists are checked for completeness by exhaustive destructuring, and
//! every field is checked to start exactly where the one before it ends, so that no type has
//! padding the compiler inserted (every gap is a named `_pad` field instead).

use primm_wire::{
    LatencyReport, MeasurementFrame, StageLatency, TrackFrame, WireMeasurement, WireTrack, WIRE_VERSION,
};
use std::collections::BTreeSet;
use std::mem::{align_of, offset_of, size_of};
use std::path::Path;
use std::process::Command;

struct TypeLayout {
    name: &'static str,
    c_name: &'static str,
    size: usize,
    align: usize,
    /// Name, offset and size of every field, in declaration order (which `repr(C)` keeps).
    fields: Vec<(&'static str, usize, usize)>,
}

/// The size of the field that `project` reads, from its type alone.
fn field_size<T, F>(_project: fn(&T) -> &F) -> usize {
    size_of::<F>()
}

macro_rules! layout {
    ($ty:ident, $c_name:literal, [$($field:ident),* $(,)?]) => {{
        // Compiles only if the list names every field.
        #[allow(dead_code, unused_variables)]
        fn exhaustive(value: &$ty) {
            let $ty { $($field: _),* } = value;
        }
        TypeLayout {
            name: stringify!($ty),
            c_name: $c_name,
            size: size_of::<$ty>(),
            align: align_of::<$ty>(),
            fields: vec![$((
                stringify!($field),
                offset_of!($ty, $field),
                field_size(|value: &$ty| &value.$field),
            )),*],
        }
    }};
}

fn rust_layouts() -> Vec<TypeLayout> {
    vec![
        layout!(
            WireMeasurement,
            "primm_wire_measurement",
            [
                x_m,
                y_m,
                vr_mps,
                rcs_dbsm,
                true_x_m,
                true_y_m,
                gt_id,
                sensor_id,
                class_code,
                truth_valid,
                _pad0
            ]
        ),
        layout!(
            MeasurementFrame,
            "primm_measurement_frame",
            [
                sequence,
                source_frame,
                sensor_timestamp_s,
                publish_time_ns,
                scheduled_time_ns,
                ego_x_m,
                ego_y_m,
                ego_yaw_rad,
                count,
                flags,
                measurements
            ]
        ),
        layout!(
            WireTrack,
            "primm_wire_track",
            [
                id,
                x_m,
                y_m,
                vx_mps,
                vy_mps,
                state_covariance,
                prior_x_m,
                prior_y_m,
                mode_probabilities,
                world_x_m,
                world_y_m,
                world_vx_mps,
                world_vy_mps,
                world_state_covariance,
                existence_probability,
                age_s,
                gt_id,
                age_frames,
                hits,
                misses,
                measurement_index,
                class_code,
                status,
                prior_valid,
                world_valid,
                _pad0
            ]
        ),
        layout!(
            TrackFrame,
            "primm_track_frame",
            [
                input_sequence,
                source_frame,
                sensor_timestamp_s,
                tracks_timestamp_s,
                input_publish_time_ns,
                input_scheduled_time_ns,
                receive_time_ns,
                publish_time_ns,
                count,
                status,
                flags,
                measurements_accepted,
                measurements_rejected,
                wire_version,
                _pad0,
                tracks
            ]
        ),
        layout!(
            StageLatency,
            "primm_stage_latency",
            [name, count, p50_ns, p90_ns, p99_ns, p999_ns, max_ns, mean_ns]
        ),
        layout!(
            LatencyReport,
            "primm_latency_report",
            [
                sequence,
                publish_time_ns,
                frames_received,
                frames_tracked,
                frames_rejected,
                frames_lost,
                measurements_rejected,
                resets,
                stage_count,
                _pad0,
                stages
            ]
        ),
    ]
}

/// `Type size N align A` and `Type.field offset` lines, sorted.
fn rust_lines() -> BTreeSet<String> {
    let mut lines = BTreeSet::new();
    lines.insert(format!("version {WIRE_VERSION}"));
    for layout in rust_layouts() {
        lines.insert(format!("{} size {} align {}", layout.name, layout.size, layout.align));
        for (field, offset, _) in &layout.fields {
            lines.insert(format!("{}.{} {}", layout.name, field, offset));
        }
    }
    lines
}

fn lines_of(output: &[u8]) -> BTreeSet<String> {
    String::from_utf8_lossy(output).lines().map(str::to_owned).collect()
}

/// Every gap in `layout`: bytes between the end of a field and the start of the next, or
/// between the last field and the end of the type.
fn gaps(layout: &TypeLayout) -> Vec<String> {
    let mut gaps = Vec::new();
    let mut end = 0;
    let mut previous = "the start";
    for &(field, offset, size) in &layout.fields {
        if offset != end {
            gaps.push(format!(
                "{}: {} bytes between {previous} and {field}",
                layout.name,
                offset as isize - end as isize
            ));
        }
        end = offset + size;
        previous = field;
    }
    if end != layout.size {
        gaps.push(format!("{}: {} bytes after {previous}", layout.name, layout.size as isize - end as isize));
    }
    gaps
}

#[test]
fn the_rust_types_have_no_implicit_padding() {
    // The payloads and every type nested in them (`WireMeasurement` in `MeasurementFrame`,
    // `WireTrack` in `TrackFrame`, `StageLatency` in `LatencyReport`); the other fields are
    // integers, floats and arrays of them, and an array has no padding between its elements
    // (an element's size is a multiple of its alignment).
    let layouts = rust_layouts();
    assert_eq!(layouts.len(), 6);
    for layout in &layouts {
        assert_eq!(gaps(layout), Vec::<String>::new());
        assert_eq!(layout.size % 8, 0, "{}", layout.name);
        println!("{}: {} fields, {} bytes, no gaps", layout.name, layout.fields.len(), layout.size);
    }
    assert_eq!(size_of::<WireMeasurement>(), 64);
    assert_eq!(size_of::<MeasurementFrame>(), 65_608);
    assert_eq!(size_of::<WireTrack>(), 424);
    assert_eq!(size_of::<TrackFrame>(), 217_168);
    assert_eq!(size_of::<LatencyReport>(), 1032);
}

#[test]
fn the_padding_check_finds_gaps_between_fields_and_at_the_end() {
    #[allow(dead_code)]
    #[repr(C)]
    struct GapInside {
        flag: u8,
        value: u32,
    }
    #[allow(dead_code)]
    #[repr(C)]
    struct GapAtTheEnd {
        value: u64,
        flag: u8,
    }
    #[allow(dead_code)]
    #[repr(C)]
    struct Padded {
        flag: u8,
        _pad0: [u8; 3],
        value: u32,
    }
    let inside = layout!(GapInside, "gap_inside", [flag, value]);
    assert_eq!(gaps(&inside), vec!["GapInside: 3 bytes between flag and value".to_owned()]);
    let at_the_end = layout!(GapAtTheEnd, "gap_at_the_end", [value, flag]);
    assert_eq!(gaps(&at_the_end), vec!["GapAtTheEnd: 7 bytes after flag".to_owned()]);
    let padded = layout!(Padded, "padded", [flag, _pad0, value]);
    assert_eq!(gaps(&padded), Vec::<String>::new());
}

#[test]
fn the_c_header_matches_the_rust_layout() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("primm-wire-layout-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut source = String::from(
        "#include <stdio.h>\n#include <stddef.h>\n#include \"primm_wire.h\"\nint main(void) {\n    printf(\"version %d\\n\", PRIMM_WIRE_VERSION);\n",
    );
    for layout in rust_layouts() {
        source += &format!(
            "    printf(\"{} size %zu align %zu\\n\", sizeof({c}), _Alignof({c}));\n",
            layout.name,
            c = layout.c_name
        );
        for (field, _, _) in &layout.fields {
            source += &format!(
                "    printf(\"{}.{} %zu\\n\", offsetof({}, {}));\n",
                layout.name, field, layout.c_name, field
            );
        }
    }
    source += "    return 0;\n}\n";
    let c_file = dir.join("layout.c");
    let binary = dir.join("layout");
    std::fs::write(&c_file, source).unwrap();
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".to_owned());
    let status = Command::new(&compiler)
        .args(["-std=c11", "-Wall", "-Werror", "-I"])
        .arg(root.join("include"))
        .arg(&c_file)
        .arg("-o")
        .arg(&binary)
        .status()
        .unwrap_or_else(|error| panic!("cannot run the C compiler '{compiler}': {error}"));
    assert!(status.success(), "the layout program does not compile against primm_wire.h");
    let output = Command::new(&binary).output().unwrap();
    assert!(output.status.success());
    assert_eq!(lines_of(&output.stdout), rust_lines());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_python_ctypes_module_matches_the_rust_layout() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let output =
        Command::new("python3").arg(root.join("python/primm_wire.py")).output().expect("python3 runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert_eq!(lines_of(&output.stdout), rust_lines());
}
