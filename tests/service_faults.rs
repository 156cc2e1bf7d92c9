//! The served tracker under faults: malformed frames, dead subscribers, a publisher killed and
//! restarted, the tracker itself killed with SIGKILL and restarted.
//!
//! No outcome depends on the machine's speed: the test either sends a frame and waits for its
//! answer, or lets a publisher with flow control (`--max-in-flight 1`: a frame goes out only
//! once the tracker answered the one before) pace itself against the tracker. The timeouts are
//! there only to fail instead of hanging when the tracker is gone. Each test runs in an
//! iceoryx2 domain of its own ([`PrivateService`]): what a killed process leaves behind stays
//! there.

use crate::common;

use common::service::{unique_prefix, ChildGuard, PrivateService, TestClient};
use primm_core::measurement::Frame;
use primm_service::ServiceNames;
use primm_wire::{FrameStatus, TRACK_FLAG_LATE_FRAME, TRACK_FLAG_PREDICTED, TRACK_FLAG_TRACKER_RESET};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn lane_frames(count: usize) -> Vec<Frame> {
    common::scene_frames(&common::lanes(6), count, 0.05, 0.2, 9)
}

/// (sequence, status, confirmed ids, measurements rejected, flags) of the next answer.
fn answer(client: &TestClient) -> (u64, Option<FrameStatus>, Vec<u64>, u16, u8) {
    client
        .next_answer(Duration::from_secs(10), |a| {
            let confirmed =
                a.valid_tracks().iter().filter(|t| matches!(t.status, 1 | 2)).map(|t| t.id).collect();
            (a.input_sequence, a.frame_status(), confirmed, a.measurements_rejected, a.flags)
        })
        .expect("the tracker answers")
}

#[test]
fn malformed_frames_are_rejected_and_counted_and_the_next_good_frame_is_tracked() {
    let prefix = unique_prefix("malformed");
    let service = PrivateService::new("faults_malformed", &ServiceNames::new(&prefix));
    let client = service.client();
    let serve = service.serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));
    let frames = lane_frames(40);
    let mut confirmed_before = Vec::new();
    for (k, frame) in frames.iter().take(20).enumerate() {
        client.send(frame, k as u64, 0);
        let (sequence, status, confirmed, _, _) = answer(client);
        assert_eq!((sequence, status), (k as u64, Some(FrameStatus::Tracked)));
        confirmed_before = confirmed;
    }
    assert_eq!(confirmed_before.len(), 6);

    // A NaN position: that measurement is left out, the frame is tracked.
    let mut with_nan = frames[20].clone();
    with_nan.measurements[0].x_m = f64::NAN;
    client.send(&with_nan, 20, 0);
    let (_, status, _, rejected, _) = answer(client);
    assert_eq!((status, rejected), (Some(FrameStatus::Tracked), 1));

    // More measurements claimed than a frame holds.
    client.send_raw(|frame| {
        frame.sequence = 21;
        frame.sensor_timestamp_s = frames[21].timestamp_s;
        frame.count = 100_000;
    });
    assert_eq!(answer(client).1, Some(FrameStatus::RejectedTooManyMeasurements));
    // Time going backwards beyond the late-frame window.
    client.send(&frames[5], 22, 0);
    assert_eq!(answer(client).1, Some(FrameStatus::RejectedTooLate));
    // A NaN timestamp.
    client.send_raw(|frame| {
        frame.sequence = 23;
        frame.sensor_timestamp_s = f64::NAN;
    });
    assert_eq!(answer(client).1, Some(FrameStatus::RejectedNonFiniteTimestamp));

    // The next good frame continues the same tracks.
    client.send(&frames[24], 24, 0);
    let (sequence, status, confirmed, rejected, flags) = answer(client);
    assert_eq!((sequence, status, rejected), (24, Some(FrameStatus::Tracked), 0));
    assert_eq!(confirmed, confirmed_before, "the rejected frames did not disturb the tracks");
    assert_eq!(flags & TRACK_FLAG_TRACKER_RESET, 0);

    serve.signal(libc::SIGTERM);
    let (status, stdout) = serve.wait(Duration::from_secs(10));
    assert!(status.success());
    assert!(stdout.contains("frames: 25 received, 22 tracked, 3 rejected, 0 lost"), "{stdout}");
    assert!(stdout.contains("measurements_rejected_non_finite 1,"), "{stdout}");
}

#[test]
fn a_subscriber_that_dies_or_stops_reading_never_blocks_the_tracker() {
    let prefix = unique_prefix("slow-subscriber");
    let service = PrivateService::new("faults_subscriber", &ServiceNames::new(&prefix));
    let client = service.client();
    let _serve = service.serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));
    let spawn_subscriber = || {
        ChildGuard(
            Command::new(env!("CARGO_BIN_EXE_primm"))
                .args(["subscribe", "--quiet", "--service-prefix", &prefix])
                .env("PRIMM_ICEORYX2_DOMAIN", service.domain.name())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap(),
        )
    };
    let stopped = spawn_subscriber();
    let killed = spawn_subscriber();
    let deadline = Instant::now() + Duration::from_secs(20);
    while client.tracks.subscriber_count() < 3 {
        assert!(Instant::now() < deadline, "subscribers did not come up");
        std::thread::sleep(Duration::from_millis(10));
    }
    stopped.signal(libc::SIGSTOP);
    killed.signal(libc::SIGKILL);

    // Far more frames than any subscriber buffer holds; every answer must still come promptly.
    let frames = lane_frames(300);
    for (k, frame) in frames.iter().enumerate() {
        client.send(frame, k as u64, 0);
        let (sequence, status, _, _, _) = answer(client);
        assert_eq!((sequence, status), (k as u64, Some(FrameStatus::Tracked)));
    }
    stopped.signal(libc::SIGCONT);
}

/// The counters of `primm serve`'s final summary line `frames: R received, T tracked, J rejected,
/// L lost; resets: …, new publisher N, …`: (R, T, J, L, N).
fn summary_counts(stdout: &str) -> (u64, u64, u64, u64, u64) {
    let number_before = |text: &str, label: &str| -> u64 {
        let end = text.find(label).unwrap_or_else(|| panic!("no '{label}' in {stdout}"));
        let digits: String = text[..end].trim_end().chars().rev().take_while(char::is_ascii_digit).collect();
        digits
            .chars()
            .rev()
            .collect::<String>()
            .parse()
            .unwrap_or_else(|_| panic!("no count before '{label}'"))
    };
    let line = stdout.lines().find(|line| line.starts_with("frames: ")).unwrap_or_else(|| panic!("{stdout}"));
    let new_publisher = line.find("new publisher ").map(|at| &line[at + "new publisher ".len()..]).unwrap();
    let new_publisher: String = new_publisher.chars().take_while(char::is_ascii_digit).collect();
    (
        number_before(line, " received"),
        number_before(line, " tracked"),
        number_before(line, " rejected,"),
        number_before(line, " lost"),
        new_publisher.parse().unwrap(),
    )
}

#[test]
fn a_publisher_killed_mid_stream_and_restarted_resumes_tracking() {
    let prefix = unique_prefix("publisher-restart");
    let service = PrivateService::new("faults_publisher", &ServiceNames::new(&prefix));
    let client = service.client();
    let serve = service.serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));
    // With flow control the tracker's input can never overflow, whatever the load. The test's
    // own answer buffer (16 frames) may drop answers when the test falls behind, so nothing
    // below needs every answer: only their order, and the newest ones.
    let spawn_publisher = |extra: &[&str]| {
        ChildGuard(
            Command::new(env!("CARGO_BIN_EXE_primm"))
                .args(["publish", "--scenario", "--duration-s", "30", "--speed", "2", "--max-in-flight", "1"])
                .args(["--service-prefix", &prefix])
                .args(extra)
                .env("RUST_LOG", "warn")
                .env("PRIMM_ICEORYX2_DOMAIN", service.domain.name())
                .stdout(Stdio::null())
                .spawn()
                .unwrap(),
        )
    };

    let first = spawn_publisher(&[]);
    let mut previous = None;
    loop {
        let (sequence, status, ..) = answer(client);
        assert_eq!(status, Some(FrameStatus::Tracked), "frame {sequence}");
        assert!(previous.is_none_or(|previous| sequence > previous), "{sequence} after {previous:?}");
        previous = Some(sequence);
        if sequence >= 59 {
            break;
        }
    }
    first.signal(libc::SIGKILL);
    drop(first);

    // The second publisher sends 60 frames and exits successfully only once the tracker has
    // answered every one of them (each frame waits for the answer to the one before, the last
    // for its own).
    let second = spawn_publisher(&["--frames", "60"]);
    let (status, _) = second.wait(Duration::from_secs(120));
    assert!(status.success(), "the second publisher: {status}");
    // The test's buffer now holds the newest answers, all of the second stream: consecutive,
    // tracked, ending with its last frame, with tracks confirmed again.
    let mut newest = Vec::new();
    while let Some(answer) = client.next_answer(Duration::ZERO, |a| {
        let confirmed = a.valid_tracks().iter().filter(|t| t.status == 1).count();
        (a.input_sequence, a.frame_status(), confirmed)
    }) {
        newest.push(answer);
    }
    let last = *newest.last().expect("answers to the second stream");
    assert_eq!(last.0, 59, "{newest:?}");
    assert!(newest.windows(2).all(|w| w[1].0 == w[0].0 + 1), "{newest:?}");
    assert!(newest.iter().all(|a| a.1 == Some(FrameStatus::Tracked)), "{newest:?}");
    assert!(last.2 > 0, "tracks are confirmed again after the restart");

    serve.signal(libc::SIGTERM);
    let (status, stdout) = serve.wait(Duration::from_secs(20));
    assert!(status.success(), "{stdout}");
    let (received, tracked, rejected, lost, new_publisher) = summary_counts(&stdout);
    assert_eq!((tracked, rejected, lost), (received, 0, 0), "{stdout}");
    assert!(received >= 60 + 60, "{stdout}");
    // The tracker started afresh for the new publisher's stream.
    assert!(new_publisher >= 1, "{stdout}");
}

#[test]
fn the_tracker_restarts_after_sigkill() {
    let prefix = unique_prefix("tracker-restart");
    let service = PrivateService::new("faults_tracker", &ServiceNames::new(&prefix));
    let client = service.client();
    let frames = lane_frames(40);
    let first = service.serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));
    for (k, frame) in frames.iter().take(10).enumerate() {
        client.send(frame, k as u64, 0);
        assert_eq!(answer(client).0, k as u64);
    }
    first.signal(libc::SIGKILL);
    drop(first);

    let second = service.serve(&prefix, &[]);
    // The dead tracker's publisher may still be listed until the new node cleans it up.
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        client.send(&frames[10], 10, 0);
        if let Some(sequence) = client.next_answer(Duration::from_millis(200), |a| a.input_sequence) {
            assert_eq!(sequence, 10);
            break;
        }
        assert!(Instant::now() < deadline, "the restarted tracker does not answer");
    }
    // A probe sent again while an answer was on its way is answered again (as a repeat of
    // frame 10, rejected for its timestamp): skip such answers, whatever their number.
    for (k, frame) in frames.iter().enumerate().skip(11) {
        client.send(frame, k as u64, 0);
        let (sequence, status, _, _, _) = loop {
            let answer = answer(client);
            if answer.0 != 10 {
                break answer;
            }
        };
        assert_eq!((sequence, status), (k as u64, Some(FrameStatus::Tracked)));
    }
    second.signal(libc::SIGINT);
    assert!(second.wait(Duration::from_secs(10)).0.success());
}

#[test]
fn a_late_frame_within_the_window_is_tracked_in_its_place_and_flagged() {
    let prefix = unique_prefix("late");
    let service = PrivateService::new("faults_late", &ServiceNames::new(&prefix));
    let client = service.client();
    let _serve = service.serve(&prefix, &[]);
    client.wait_for_tracker(Duration::from_secs(20));
    let frames = lane_frames(12);
    // Frame 9 arrives after frame 10 (50 ms late, inside the 150 ms window).
    let order = [0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 9, 11];
    let mut late_answer = None;
    for (sequence, &index) in order.iter().enumerate() {
        client.send(&frames[index], sequence as u64, 0);
        let got = client
            .next_answer(Duration::from_secs(10), |a| {
                (a.frame_status(), a.flags, a.sensor_timestamp_s, a.tracks_timestamp_s, a.count)
            })
            .expect("the tracker answers");
        assert_eq!(got.0, Some(FrameStatus::Tracked), "frame {index}");
        if index == 9 {
            late_answer = Some(got);
        } else {
            assert_eq!(got.1 & TRACK_FLAG_LATE_FRAME, 0);
            assert_eq!(got.3, frames[index].timestamp_s);
        }
    }
    let (_, flags, sensor_s, tracks_s, count) = late_answer.unwrap();
    assert_ne!(flags & TRACK_FLAG_LATE_FRAME, 0);
    assert_eq!(sensor_s, frames[9].timestamp_s);
    assert_eq!(tracks_s, frames[10].timestamp_s, "the tracks are those at the newest frame");
    assert!(count >= 6, "{count} tracks");
}

#[test]
fn with_publish_time_now_the_tracks_are_predicted_to_the_publish_time() {
    let prefix = unique_prefix("publish_now");
    let service = PrivateService::new("faults_publish_now", &ServiceNames::new(&prefix));
    let client = service.client();
    let _serve = service.serve(&prefix, &["--publish-time", "now"]);
    client.wait_for_tracker(Duration::from_secs(20));
    let frames = lane_frames(15);
    for (sequence, frame) in frames.iter().enumerate() {
        client.send(frame, sequence as u64, 0);
        let (status, flags, sensor_s, tracks_s, indexed) = client
            .next_answer(Duration::from_secs(10), |a| {
                let indexed = a.valid_tracks().iter().filter(|t| t.measurement_index().is_some()).count();
                (a.frame_status(), a.flags, a.sensor_timestamp_s, a.tracks_timestamp_s, indexed)
            })
            .expect("the tracker answers");
        assert_eq!(status, Some(FrameStatus::Tracked));
        assert_ne!(flags & TRACK_FLAG_PREDICTED, 0);
        assert!(tracks_s >= sensor_s && tracks_s <= sensor_s + 1.0, "{sensor_s} -> {tracks_s}");
        assert_eq!(indexed, 0, "predicted tracks carry no measurement");
    }
}
