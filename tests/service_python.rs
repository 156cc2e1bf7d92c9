//! The Python example `examples/python/subscriber.py` (iceoryx2 Python package + the ctypes
//! declarations) reads the live track stream and sees exactly what a Rust subscriber sees; the
//! frames it records (`--record`) read back through `examples/c/subscriber.c`, built against
//! `primm_wire.h` alone. Needs `pip install -r tools/requirements-test.txt`.

use crate::common;

use common::service::{spawn_serve, unique_prefix, ChildGuard, TestClient};
use primm_service::ServiceNames;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn the_python_subscriber_reads_the_tracks_the_tracker_publishes() {
    let check =
        Command::new("python3").args(["-c", "import iceoryx2, primm_wire"]).output().expect("python3 runs");
    assert!(
        check.status.success(),
        "the iceoryx2 or primm_wire Python package is missing: pip install -r tools/requirements-test.txt"
    );
    let prefix = unique_prefix("python");
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let _serve = spawn_serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));

    const FRAMES: usize = 40;
    let recording = std::env::temp_dir().join(format!("primm-python-{}.frames", std::process::id()));
    let _ = std::fs::remove_file(&recording);
    let mut python = ChildGuard(
        Command::new("python3")
            .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/python/subscriber.py"))
            .args([
                "--service-prefix",
                &prefix,
                "--frames",
                &FRAMES.to_string(),
                "--json",
                "--timeout-s",
                "30",
                "--record",
                recording.to_str().unwrap(),
            ])
            .stdout(Stdio::piped())
            .spawn()
            .expect("the Python subscriber starts"),
    );
    let deadline = Instant::now() + Duration::from_secs(30);
    while client.tracks.subscriber_count() < 2 {
        assert!(python.is_running(), "the Python subscriber exited early");
        assert!(Instant::now() < deadline, "the Python subscriber did not subscribe");
        std::thread::sleep(Duration::from_millis(20));
    }

    // Lines from the Python subscriber, read on a thread; one frame at a time so that the
    // Python side never falls behind by a full subscriber buffer.
    let line_rx = python.stdout_lines();

    let frames = common::scene_frames(&common::lanes(4), FRAMES, 0.05, 0.2, 3);
    let mut expected = Vec::new();
    let mut seen = Vec::new();
    let mut printed = Vec::new();
    for (k, frame) in frames.iter().enumerate() {
        client.send(frame, k as u64, 0);
        let answer = client
            .next_answer(Duration::from_secs(10), |answer| {
                let tracks: Vec<(u64, f64, f64, bool)> =
                    answer.valid_tracks().iter().map(|t| (t.id, t.x_m, t.y_m, t.status == 1)).collect();
                (answer.input_sequence, tracks)
            })
            .expect("the tracker answers");
        expected.push(answer);
        let line =
            line_rx.recv_timeout(Duration::from_secs(20)).expect("the Python subscriber prints the frame");
        let record: serde_json::Value = serde_json::from_str(&line).expect("one JSON object per line");
        let tracks: Vec<(u64, f64, f64, bool)> = record["tracks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| {
                (
                    t["id"].as_u64().unwrap(),
                    t["x_m"].as_f64().unwrap(),
                    t["y_m"].as_f64().unwrap(),
                    t["confirmed"].as_bool().unwrap(),
                )
            })
            .collect();
        assert_eq!(record["status"], "tracked");
        seen.push((record["input_sequence"].as_u64().unwrap(), tracks));
        printed.push(record);
    }
    let (status, _) = python.wait(Duration::from_secs(10));
    assert!(status.success());
    // JSON text round trip: equal to the last few bits.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(1.0);
    assert_eq!(seen.len(), expected.len());
    for ((seq_seen, seen_tracks), (seq_expected, expected_tracks)) in seen.iter().zip(&expected) {
        assert_eq!(seq_seen, seq_expected);
        assert_eq!(seen_tracks.len(), expected_tracks.len(), "frame {seq_seen}");
        for (s, e) in seen_tracks.iter().zip(expected_tracks) {
            assert!(
                s.0 == e.0 && s.3 == e.3 && close(s.1, e.1) && close(s.2, e.2),
                "frame {seq_seen}: {s:?} != {e:?}"
            );
        }
    }
    assert_eq!(seen.last().unwrap().1.iter().filter(|t| t.3).count(), 4, "four confirmed tracks at the end");

    // The recording, read by the C example with primm_wire.h alone, prints the same frames.
    let from_c = c_subscriber_json(&recording);
    assert_eq!(from_c.len(), printed.len());
    for (c, python) in from_c.iter().zip(&printed) {
        assert_same_json(c, python, "");
    }
    std::fs::remove_file(&recording).unwrap();
}

/// Builds `examples/c/subscriber.c` against `crates/primm-wire/include` only and returns what it
/// prints with `--json` for `recording`, one value per frame.
fn c_subscriber_json(recording: &std::path::Path) -> Vec<serde_json::Value> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let executable = std::env::temp_dir().join(format!("primm-c-subscriber-{}", std::process::id()));
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".to_owned());
    let build = Command::new(&compiler)
        .args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O2", "-I"])
        .arg(root.join("crates/primm-wire/include"))
        .arg(root.join("examples/c/subscriber.c"))
        .arg("-o")
        .arg(&executable)
        .output()
        .expect("the C compiler runs");
    assert!(build.status.success(), "examples/c/subscriber.c: {}", String::from_utf8_lossy(&build.stderr));
    let run = Command::new(&executable).arg("--json").arg(recording).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    std::fs::remove_file(&executable).unwrap();
    let text = String::from_utf8(run.stdout).unwrap();
    text.lines().map(|line| serde_json::from_str(line).expect("one JSON object per line")).collect()
}

/// Equal JSON values, numbers compared as f64 (C prints 0 where Python prints 0.0). Both print
/// doubles in a form that reads back exactly, but serde_json's default number parser is not
/// correctly rounded for 17 significant digits (C's `%.17g`): it may land one unit in the last
/// place off, so numbers may differ by two ulps.
fn assert_same_json(c: &serde_json::Value, python: &serde_json::Value, at: &str) {
    use serde_json::Value;
    match (c, python) {
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            assert!(a == b || (a - b).abs() <= 2.0 * f64::EPSILON * a.abs().max(b.abs()), "{at}: {a} vs {b}");
        }
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{at}");
            for (index, (a, b)) in a.iter().zip(b).enumerate() {
                assert_same_json(a, b, &format!("{at}[{index}]"));
            }
        }
        (Value::Object(a), Value::Object(b)) => {
            assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "{at}");
            for (key, value) in a {
                assert_same_json(value, &b[key], &format!("{at}.{key}"));
            }
        }
        _ => assert_eq!(c, python, "{at}"),
    }
}
