//! primm's streams across two "hosts" on one machine: two iceoryx2 domains that share no shared
//! memory, each with a `primm tunnel`, joined over zenoh on 127.0.0.1 with multicast scouting
//! off (the `tunnel` feature; `./test.sh` builds it).
//!
//! What is sent on one host must arrive on the other intact and in order; whatever does not
//! is counted, and the tunnels' own counters say where it was lost.

use crate::common;

use common::service::{write_frame, ChildGuard, TestClient};
use common::tunnel::{counts, TwoHosts, HANG_GUARD};
use primm_service::catalog;
use primm_wire::{MeasurementFrame, WireMeasurement};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What the far side must see of a sent frame.
#[derive(Debug, Clone, PartialEq)]
struct Sent {
    sequence: u64,
    sensor_timestamp_s: f64,
    publish_time_ns: u64,
    measurements: Vec<WireMeasurement>,
}

impl Sent {
    fn of(frame: &MeasurementFrame) -> Self {
        Self {
            sequence: frame.sequence,
            sensor_timestamp_s: frame.sensor_timestamp_s,
            publish_time_ns: frame.publish_time_ns,
            measurements: frame.valid_measurements().expect("a valid count").to_vec(),
        }
    }
}

#[test]
fn every_frame_sent_on_one_host_arrives_intact_and_in_order_on_the_other() {
    every_frame_crosses(TwoHosts::start("tunnel_frames"), 400);
}

#[test]
fn frames_cross_between_a_tunnel_in_router_mode_and_one_in_client_mode() {
    every_frame_crosses(TwoHosts::start_in_modes("tunnel_router", "router", "client"), 100);
}

/// Sends `count` measurement frames on host A, paced by what host B has received, and checks
/// that host B receives each of them intact and in order, and that the tunnels' counters agree.
fn every_frame_crosses(hosts: TwoHosts, count: usize) {
    let names = hosts.names();
    let (node_a, node_b) = (hosts.node_a("sender"), hosts.node_b("receiver"));
    let stream_a = catalog::measurements(&node_a, &names).unwrap();
    let (publisher, notifier) = (stream_a.publisher().unwrap(), stream_a.notifier().unwrap());
    let stream_b = catalog::measurements(&node_b, &names).unwrap();
    let (subscriber, listener) = (stream_b.subscriber().unwrap(), stream_b.listener().unwrap());

    let frames = common::scene_frames(&common::lanes(12), count + 1, 0.05, 0.2, 11);
    let send = |sequence: usize| -> Sent {
        let mut loan = publisher.loan_uninit().unwrap();
        write_frame(loan.payload_mut(), &frames[sequence], sequence as u64, 0);
        // SAFETY: write_frame wrote the header and the measurements; the rest is plain data.
        let sample = unsafe { loan.assume_init() };
        let sent = Sent::of(&sample);
        sample.send().unwrap();
        notifier.notify().unwrap();
        sent
    };
    let mut received: Vec<Sent> = Vec::new();
    let receive = |received: &mut Vec<Sent>| {
        while let Some(sample) = subscriber.receive().unwrap() {
            received.push(Sent::of(&sample));
        }
    };

    // Frame 0 until one copy arrives: zenoh has then matched the two sides' channels.
    let deadline = Instant::now() + HANG_GUARD;
    let mut probes_sent = 0;
    while received.is_empty() {
        assert!(Instant::now() < deadline, "no frame crossed the tunnel within {HANG_GUARD:?}");
        send(0);
        probes_sent += 1;
        let _ = listener.timed_wait(|_| {}, Duration::from_millis(50));
        receive(&mut received);
    }
    std::thread::sleep(Duration::from_millis(200));
    receive(&mut received);
    let probes = received.len();
    received.clear();

    // Then frames 1..=count as fast as the far side takes them, with at most IN_FLIGHT frames
    // sent and not yet received (a quarter of the subscriber's buffer of 64): the pace follows
    // the tunnels' progress, so a loaded machine slows the test down instead of overflowing a
    // buffer.
    const IN_FLIGHT: usize = 16;
    let mut sent = Vec::new();
    let received_frames = |received: &Vec<Sent>| received.iter().filter(|frame| frame.sequence > 0).count();
    let deadline = Instant::now() + HANG_GUARD;
    while received.last().map(|frame| frame.sequence) != Some(count as u64) && Instant::now() < deadline {
        if sent.len() < count && sent.len() - received_frames(&received) < IN_FLIGHT {
            sent.push(send(sent.len() + 1));
        } else {
            let _ = listener.timed_wait(|_| {}, Duration::from_millis(50));
        }
        receive(&mut received);
    }
    drop((publisher, notifier, subscriber, listener, stream_a, stream_b, node_a, node_b));
    let (report_a, report_b) = hosts.stop();

    // Where frames were lost, if any: host A's tunnel saw them (sent), host B's tunnel
    // published them (arrived), this test's subscriber on host B took them.
    let [sent_by_a, ..] = counts(&report_a, "primm/measurements");
    let [_, arrived_at_b, gaps_at_b, _] = counts(&report_b, "primm/measurements");
    let lost = count - received.iter().filter(|frame| frame.sequence > 0).count();
    let where_lost = format!(
        "{lost} of {count} frames lost: tunnel A picked up {sent_by_a} ({probes} probe frames arrived before), \
         ({probes_sent} probes, {count} frames sent), tunnel B published {arrived_at_b} with {gaps_at_b} sequence gaps\nhost A:\n{report_a}host B:\n{report_b}"
    );
    assert_eq!(sent_by_a as usize, probes_sent + count, "tunnel A missed local frames\n{where_lost}");
    assert_eq!(arrived_at_b as usize, probes + count, "{where_lost}");
    let received: Vec<Sent> = received.into_iter().filter(|frame| frame.sequence > 0).collect();
    assert_eq!(received.len(), count, "{where_lost}");
    for (got, expected) in received.iter().zip(&sent) {
        assert_eq!(
            got, expected,
            "frame {} arrived changed or out of order\n{where_lost}",
            expected.sequence
        );
    }
    assert_eq!(gaps_at_b, 0, "{where_lost}");
}

/// Tracks as the Python example prints them: id, x, y, confirmed.
type PrintedTracks = Vec<(u64, f64, f64, bool)>;

fn printed_tracks(record: &serde_json::Value) -> PrintedTracks {
    record["tracks"]
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
        .collect()
}

#[test]
fn the_python_subscriber_on_the_far_host_reads_the_tracks_of_a_tracker_on_the_near_one() {
    const FRAMES: usize = 30;
    let check = Command::new("python3").args(["-c", "import iceoryx2"]).output().expect("python3 runs");
    assert!(
        check.status.success(),
        "the iceoryx2 Python package is missing: pip install -r tools/requirements-test.txt"
    );
    let hosts = TwoHosts::start("tunnel_python");
    let names = hosts.names();
    let client = TestClient::in_domain(&names, hosts.host_a.name());
    let tracker = ChildGuard(
        hosts
            .host_a
            .primm("warn")
            .args(["serve", "--service-prefix", &hosts.prefix, "--latency-every", "20"])
            .stdout(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    client.wait_for_tracker(HANG_GUARD);
    // A Rust subscriber on host B tells when the tracks' channel has crossed.
    let node_b = hosts.node_b("probe");
    let tracks_b = catalog::tracks(&node_b, &names).unwrap();
    let probe = tracks_b.subscriber().unwrap();
    let mut python = ChildGuard(
        Command::new("python3")
            .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/python/subscriber.py"))
            .args(["--service-prefix", &hosts.prefix, "--json", "--timeout-s", "30"])
            .env("PRIMM_ICEORYX2_DOMAIN", hosts.host_b.name())
            .stdout(Stdio::piped())
            .spawn()
            .expect("the Python subscriber starts"),
    );
    let deadline = Instant::now() + HANG_GUARD;
    while tracks_b.subscriber_count() < 4 {
        // The tunnel's link and its counter, the probe, and the Python subscriber.
        assert!(python.is_running(), "the Python subscriber exited early");
        assert!(Instant::now() < deadline, "the Python subscriber did not subscribe on host B");
        std::thread::sleep(Duration::from_millis(20));
    }
    let line_rx = python.stdout_lines();

    let frames = common::scene_frames(&common::lanes(4), FRAMES + 1, 0.05, 0.2, 3);
    // Frame 0, as a stream start, until its answer reaches host B.
    let deadline = Instant::now() + HANG_GUARD;
    loop {
        assert!(Instant::now() < deadline, "no track frame crossed the tunnel within {HANG_GUARD:?}");
        client.send(&frames[0], 0, primm_wire::FRAME_FLAG_STREAM_START);
        client.next_answer(Duration::from_secs(10), |_| ()).expect("the tracker answers");
        std::thread::sleep(Duration::from_millis(50));
        if probe.receive().unwrap().is_some() {
            break;
        }
    }
    // Frames 1..=FRAMES one at a time, each once the Python subscriber has printed the one
    // before, so that its buffer of 16 track frames never overflows (that would be the
    // subscriber's loss, not the tunnel's).
    let mut expected = Vec::new();
    let mut seen = Vec::new();
    for (k, frame) in frames.iter().enumerate().skip(1) {
        client.send(frame, k as u64, 0);
        let answer = client
            .next_answer(Duration::from_secs(10), |answer| {
                let tracks: PrintedTracks = answer
                    .valid_tracks()
                    .iter()
                    .map(|t| (t.id, t.x_m, t.y_m, matches!(t.status, 1 | 2)))
                    .collect();
                (answer.input_sequence, tracks)
            })
            .expect("the tracker answers");
        expected.push(answer);
        loop {
            let line = line_rx.recv_timeout(Duration::from_secs(20)).unwrap_or_else(|_| {
                panic!("the Python subscriber on host B printed {} of {FRAMES} frames", seen.len())
            });
            let record: serde_json::Value = serde_json::from_str(&line).expect("one JSON object per line");
            let sequence = record["input_sequence"].as_u64().unwrap();
            if sequence > 0 {
                seen.push((sequence, printed_tracks(&record)));
                break;
            }
        }
    }
    drop(python);
    drop(tracker);
    drop((probe, tracks_b, node_b, client));
    let _ = hosts.stop();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(1.0);
    for ((seq_seen, seen_tracks), (seq_expected, expected_tracks)) in seen.iter().zip(&expected) {
        assert_eq!(seq_seen, seq_expected, "frames arrived out of order or with gaps");
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

#[test]
fn the_demo_on_two_hosts_tracks_on_one_and_answers_on_the_other_through_the_tunnel() {
    let domain = common::service::Iceoryx2Domain::new("demo_hosts");
    let demo = ChildGuard(
        domain
            .primm("warn")
            .args(["demo", "--hosts", "2", "--duration-s", "4", "--speed", "2"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let (status, output) = demo.wait(Duration::from_secs(180));
    assert!(status.success(), "{status}\n{output}");
    for expected in [
        "== subscriber on host B (primm-subscriber) ==",
        "prior RMSE",
        "== tunnel of host A (primm tunnel) ==",
        "tunnel hop (tracker publishes on host A -> subscriber receives on host B",
        "demo finished: every frame tracked on host A and answered on host B through the tunnel",
    ] {
        assert!(output.contains(expected), "'{expected}' missing from:\n{output}");
    }
    // Every frame's answer reached host B: no gap in the input sequence numbers.
    assert!(output.contains("input sequence gaps 0,"), "{output}");
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "the demo left {leftovers:?}");
    assert_eq!(domain.processes(), 0, "the demo left processes running");
}
