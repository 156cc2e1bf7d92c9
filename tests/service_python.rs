//! The Python example `examples/python/subscriber.py` (iceoryx2 Python package + the ctypes
//! declarations) reads the live track stream and sees exactly what a Rust subscriber sees.
//! Needs `pip install -r tools/requirements-test.txt`.

use crate::common;

use common::service::{spawn_serve, unique_prefix, ChildGuard, TestClient};
use primm_service::ServiceNames;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn the_python_subscriber_reads_the_tracks_the_tracker_publishes() {
    let check = Command::new("python3").args(["-c", "import iceoryx2"]).output().expect("python3 runs");
    assert!(
        check.status.success(),
        "the iceoryx2 Python package is missing: pip install -r tools/requirements-test.txt"
    );
    let prefix = unique_prefix("python");
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let _serve = spawn_serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));

    const FRAMES: usize = 40;
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
}
