//! MCAP recordings and the live Foxglove view: `primm track --mcap` writes every topic once per
//! frame at the frame's sensor time, read back with the `mcap` crate; a drive recorded from the
//! service and replayed into a fresh tracker gives the recorded tracks bit for bit; the live
//! view streams the tracks to a WebSocket client on loopback and refuses an address in use.

use crate::common::service::{spawn_serve, unique_prefix, ChildGuard, TestClient};
use foxglove::schemas::SceneUpdate;
use primm_record::raw::{payload_bytes, WirePayload};
use primm_record::reading::read_frames;
use primm_record::Topic;
use primm_service::catalog;
use primm_service::ServiceNames;
use primm_wire::{MeasurementFrame, TrackFrame, FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn primm(args: &[&str]) -> std::process::Output {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(output.status.success(), "primm {args:?} failed:\n{}", String::from_utf8_lossy(&output.stderr));
    output
}

fn tempdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-recording-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Per topic: its messages' log times, and the channel's schema name, schema encoding and
/// message encoding.
type Topics = BTreeMap<String, (Vec<u64>, (String, String, String))>;

fn read_mcap(path: &Path) -> (Topics, mcap::Summary) {
    let bytes = std::fs::read(path).unwrap();
    let mut topics = Topics::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let channel = &message.channel;
        let schema = channel.schema.as_ref().expect("every channel has a schema");
        let entry = topics.entry(channel.topic.clone()).or_insert_with(|| {
            (Vec::new(), (schema.name.clone(), schema.encoding.clone(), channel.message_encoding.clone()))
        });
        entry.0.push(message.log_time);
        if channel.topic == Topic::TrackScene.name() {
            let scene: SceneUpdate = prost::Message::decode(&message.data[..]).expect("a SceneUpdate");
            assert!(scene.entities.iter().all(|entity| entity.id.starts_with("track/")));
        }
    }
    let summary = mcap::Summary::read(&bytes).unwrap().expect("the file has a summary");
    (topics, summary)
}

#[test]
fn track_mcap_writes_every_topic_once_per_frame_at_the_sensor_time() {
    let dir = tempdir("offline");
    let dir_text = dir.to_str().unwrap();
    primm(&[
        "generate",
        "--output",
        dir_text,
        "--split",
        "evaluation",
        "--sequences",
        "1",
        "--duration-s",
        "3",
    ]);
    primm(&[
        "generate",
        "--output",
        dir_text,
        "--split",
        "evaluation",
        "--sequences",
        "1",
        "--duration-s",
        "3",
        "--preset",
        "clutter",
    ]);
    let input = dir.join("evaluation/evaluation_0000.csv");
    let recording = dir.join("run.mcap");
    primm(&[
        "track",
        "--input",
        input.to_str().unwrap(),
        "--output",
        dir.join("tracks.csv").to_str().unwrap(),
        "--method",
        "imm",
        "--mcap",
        recording.to_str().unwrap(),
    ]);
    let sequence = primm_sim::io::read_sequence_file(&input).unwrap();
    let frames = sequence.frames.len();
    let sensor_times: Vec<u64> =
        sequence.frames.iter().map(|frame| (frame.timestamp_s * 1e9).round() as u64).collect();

    let (topics, summary) = read_mcap(&recording);
    let frames_with_truth = sequence
        .frames
        .iter()
        .filter(|frame| frame.measurements.iter().any(|m| m.true_position.is_some()))
        .count();
    assert!(frames_with_truth > 0 && frames_with_truth < frames);
    assert_eq!(topics[Topic::GroundTruthScene.name()].0.len(), frames_with_truth);
    for topic in [
        Topic::Measurements,
        Topic::Tracks,
        Topic::TrackScene,
        Topic::DetectionScene,
        Topic::Transforms,
        Topic::FrameLatency,
    ] {
        let (times, _) =
            topics.get(topic.name()).unwrap_or_else(|| panic!("{} missing: {topics:?}", topic.name()));
        assert_eq!(times.len(), frames, "{}", topic.name());
        assert!(times.windows(2).all(|pair| pair[0] <= pair[1]), "{} log times go back", topic.name());
    }
    assert_eq!(topics[Topic::Measurements.name()].0, sensor_times);
    assert_eq!(topics[Topic::Tracks.name()].0, sensor_times);
    let schema = |topic: Topic| topics[topic.name()].1.clone();
    assert_eq!(
        schema(Topic::TrackScene),
        ("foxglove.SceneUpdate".into(), "protobuf".into(), "protobuf".into())
    );
    assert_eq!(
        schema(Topic::Transforms),
        ("foxglove.FrameTransforms".into(), "protobuf".into(), "protobuf".into())
    );
    assert_eq!(schema(Topic::Tracks), ("primm::TrackFrame".into(), "primm-wire".into(), "primm-wire".into()));
    assert_eq!(schema(Topic::FrameLatency).1, "jsonschema");

    let statistics = summary.stats.expect("statistics");
    assert_eq!(statistics.message_count, topics.values().map(|(times, _)| times.len() as u64).sum::<u64>());
    assert!(!summary.chunk_indexes.is_empty());
    assert!(summary.chunk_indexes.iter().all(|chunk| chunk.compression == "zstd"));
    let wire_channel = summary.channels.values().find(|c| c.topic == Topic::Tracks.name()).unwrap();
    assert_eq!(wire_channel.metadata["wire_version"], primm_wire::WIRE_VERSION.to_string());

    // The recorded track frames are the tracker's: the first and last frames' flags, and as
    // many confirmed tracks in the last frame as the track CSV has rows of confirmed tracks.
    let tracks = read_frames::<TrackFrame>(&recording, Topic::Tracks).unwrap();
    let measurements = read_frames::<MeasurementFrame>(&recording, Topic::Measurements).unwrap();
    assert_eq!(measurements[0].flags & FRAME_FLAG_STREAM_START, FRAME_FLAG_STREAM_START);
    assert_eq!(measurements[frames - 1].flags & FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_END);
    assert!(tracks.iter().any(|frame| frame.valid_tracks().iter().any(|track| track.status == 1)));
    for (frame, recorded) in measurements.iter().zip(&sequence.frames) {
        assert_eq!(frame.count as usize, recorded.measurements.len());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Waits until `count` subscribers read the track stream of `names`.
fn wait_for_subscribers(names: &ServiceNames, count: usize) {
    let node = catalog::create_node("primm-recording-test").unwrap();
    let tracks = catalog::tracks(&node, names).unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    while tracks.subscriber_count() < count || tracks.publisher_count() == 0 {
        assert!(Instant::now() < deadline, "the tracker and the recorder did not come up");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs a tracker and a recorder under a fresh prefix, feeds them with `feed`, and returns once
/// the recorder has written the end of the stream into `output`.
fn record_a_run(output: &Path, feed: impl FnOnce(&str)) {
    let prefix = unique_prefix("record");
    let names = ServiceNames::new(&prefix);
    let serve = spawn_serve(&prefix, &["--method", "imm"]);
    let recorder = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["record", "--service-prefix", &prefix, "--until-end", "--output"])
        .arg(output)
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let recorder = ChildGuard(recorder);
    wait_for_subscribers(&names, 1);
    feed(&prefix);
    let (status, stdout) = recorder.wait(Duration::from_secs(60));
    assert!(status.success(), "{status}: {stdout}");
    assert_eq!(stdout.matches("(0 missed)").count(), 2, "the recorder missed frames: {stdout}");
    assert!(!stdout.contains(" 0 track frames"), "{stdout}");
    serve.signal(libc::SIGINT);
    let (status, output) = serve.wait(Duration::from_secs(10));
    assert!(status.success(), "primm serve: {status}\n{output}");
}

/// The bytes of a frame without its clocks (which differ from run to run).
fn without_clocks(frame: &TrackFrame) -> Vec<u8> {
    let mut copy = primm_record::raw::zeroed_box::<TrackFrame>();
    primm_record::raw::read_payload(payload_bytes(frame), &mut *copy).unwrap();
    (copy.input_publish_time_ns, copy.input_scheduled_time_ns, copy.receive_time_ns, copy.publish_time_ns) =
        (0, 0, 0, 0);
    payload_bytes(&*copy).to_vec()
}

#[test]
fn a_replayed_recording_gives_the_recorded_tracks_bit_for_bit() {
    let dir = tempdir("replay");
    let first = dir.join("drive.mcap");
    record_a_run(&first, |prefix| {
        primm(&["publish", "--service-prefix", prefix, "--scenario", "--duration-s", "6", "--speed", "2"]);
    });
    let again = dir.join("again.mcap");
    record_a_run(&again, |prefix| {
        let output = primm(&["replay", first.to_str().unwrap(), "--service-prefix", prefix, "--rate", "2"]);
        assert!(String::from_utf8_lossy(&output.stdout).contains("0 dropped"));
    });
    let recorded = read_frames::<TrackFrame>(&first, Topic::Tracks).unwrap();
    let replayed = read_frames::<TrackFrame>(&again, Topic::Tracks).unwrap();
    assert!(recorded.len() > 50, "{} track frames", recorded.len());
    assert_eq!(recorded.len(), replayed.len());
    assert!(recorded.iter().any(|frame| frame.count > 0));
    for (index, (a, b)) in recorded.iter().zip(&replayed).enumerate() {
        assert!(without_clocks(a) == without_clocks(b), "track frame {index} differs");
    }
    let sent = read_frames::<MeasurementFrame>(&first, Topic::Measurements).unwrap();
    let resent = read_frames::<MeasurementFrame>(&again, Topic::Measurements).unwrap();
    assert_eq!(sent.len(), resent.len());
    let measurements =
        |frame: &MeasurementFrame| payload_bytes(frame)[MeasurementFrame::HEADER_BYTES..].to_vec();
    assert!(sent.iter().zip(&resent).all(|(a, b)| measurements(a) == measurements(b)));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn replay_names_the_file_and_what_is_wrong_with_it() {
    let dir = tempdir("bad-replay");
    let foreign = dir.join("foreign.mcap");
    std::fs::write(&foreign, b"frame,t,x\n0,0,1\n").unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["replay", foreign.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("foreign.mcap") && stderr.contains("not an MCAP file"),
        "{stderr}"
    );

    let input = dir.join("frames.csv");
    let mut rows = String::from("frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y\n");
    for k in 0..40 {
        rows.push_str(&format!(
            "{k},{},1,car,{},1,0,5,{},1\n",
            0.1 * k as f64,
            10.0 + 0.5 * k as f64,
            10.0 + 0.5 * k as f64
        ));
    }
    std::fs::write(&input, rows).unwrap();
    let whole = dir.join("whole.mcap");
    primm(&[
        "track",
        "--input",
        input.to_str().unwrap(),
        "--output",
        dir.join("t.csv").to_str().unwrap(),
        "--method",
        "cv",
        "--mcap",
        whole.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&whole).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let output =
        Command::new(env!("CARGO_BIN_EXE_primm")).args(["replay", cut.to_str().unwrap()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("cut.mcap") && stderr.contains("truncated"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The address `primm serve --foxglove` says it serves on.
fn served_address(lines: &std::sync::mpsc::Receiver<String>) -> std::net::SocketAddr {
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        if let Ok(line) = lines.recv_timeout(Duration::from_millis(200)) {
            if let Some(address) = line.strip_prefix("Foxglove live view on ws://") {
                return address.trim().parse().unwrap();
            }
        }
    }
    panic!("primm serve did not say where its live view listens");
}

#[test]
fn the_live_view_streams_the_tracks_to_a_client_on_loopback() {
    let prefix = unique_prefix("foxglove");
    let names = ServiceNames::new(&prefix);
    let client = TestClient::new(&names);
    let mut serve = spawn_serve(&prefix, &["--method", "imm", "--foxglove", "127.0.0.1:0"]);
    // Kept until serve exits: its stdout stays read (a closed pipe would fail its last prints).
    let lines = serve.stdout_lines();
    let address = served_address(&lines);
    assert!(address.ip().is_loopback());
    client.wait_for_tracker(Duration::from_secs(20));
    let mut viewer = primm_record::client::LiveClient::connect(address, Duration::from_secs(5)).unwrap();
    assert_eq!(viewer.subscribe_all(Topic::COUNT, Duration::from_secs(10)).unwrap(), Topic::COUNT);
    let scene_channel = viewer.channels().iter().find(|c| c.topic == Topic::TrackScene.name()).unwrap();
    assert_eq!(
        (scene_channel.encoding.as_str(), scene_channel.schema_name.as_str()),
        ("protobuf", "foxglove.SceneUpdate")
    );
    // Subscriptions take effect asynchronously: keep sending until scenes with tracks come.
    let frames = crate::common::scene_frames(&crate::common::lanes(4), 400, 0.05, 0.2, 3);
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut largest_scene = 0;
    let mut next = 0;
    for (k, frame) in frames.iter().enumerate() {
        next = k + 1;
        client.send(frame, k as u64, 0);
        let _ = client.next_answer(Duration::from_secs(5), |_| ());
        while let Some(message) = viewer.next_message().unwrap() {
            if message.topic == Topic::TrackScene.name() {
                let scene: SceneUpdate = prost::Message::decode(&message.data[..]).unwrap();
                largest_scene = largest_scene.max(scene.entities.len());
                assert!(
                    message.log_time_ns <= (frame_time(k) * 1e9).round() as u64,
                    "a scene from the future"
                );
            }
        }
        if largest_scene == 4 || Instant::now() > deadline {
            break;
        }
    }
    assert_eq!(largest_scene, 4, "the client saw no scene of the four tracks");
    // A viewer that vanishes (its connection dropped unread, no closing handshake) changes
    // nothing for the tracker: it answers every further frame.
    drop(viewer);
    for (k, frame) in frames.iter().enumerate().skip(next).take(40) {
        client.send(frame, k as u64, 0);
        let answered = client.next_answer(Duration::from_secs(5), |answer| answer.input_sequence);
        assert_eq!(answered, Some(k as u64), "frame {k} after the viewer left");
    }
    serve.signal(libc::SIGINT);
    let (status, _) = serve.wait(Duration::from_secs(10));
    let output: Vec<String> = lines.try_iter().collect();
    assert!(status.success(), "primm serve: {status}\n{}", output.join("\n"));
}

/// The sensor time of frame `k` of `common::scene_frames(.., 0.05, ..)`.
fn frame_time(k: usize) -> f64 {
    k as f64 * 0.05
}

#[test]
fn an_address_in_use_stops_serve_with_the_address_named() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let address = taken.local_addr().unwrap().to_string();
    let output = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["serve", "--service-prefix", &unique_prefix("foxglove-taken"), "--foxglove", &address])
        .env("RUST_LOG", "error")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && stderr.contains(&address), "{stderr}");
}

/// Largest file `primm record` may write in the test below, bytes: one or two compressed chunks
/// (about 400 kB each for the built-in scenario).
const FILE_SIZE_LIMIT: u64 = 768 * 1024;

#[test]
fn a_recording_that_runs_out_of_room_stops_with_a_message_and_stays_readable() {
    let dir = tempdir("full");
    let output = dir.join("full.mcap");
    let log = dir.join("recorder.log");
    let prefix = unique_prefix("record-full");
    let names = ServiceNames::new(&prefix);
    let serve = spawn_serve(&prefix, &["--method", "imm"]);
    let mut command = Command::new(env!("CARGO_BIN_EXE_primm"));
    command
        .args(["record", "--service-prefix", &prefix, "--until-end", "--output"])
        .arg(&output)
        .env("RUST_LOG", "warn")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap());
    // The file may not grow past the limit: a write past it fails (EFBIG) as one on a full disk
    // fails (ENOSPC), and SIGXFSZ, ignored here, stays ignored across exec.
    unsafe {
        use std::os::unix::process::CommandExt;
        command.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: FILE_SIZE_LIMIT, rlim_max: FILE_SIZE_LIMIT };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            Ok(())
        });
    }
    let recorder = ChildGuard(command.spawn().unwrap());
    wait_for_subscribers(&names, 1);
    // The tracker answers every frame although the recorder stops on the way.
    primm(&[
        "publish",
        "--service-prefix",
        &prefix,
        "--scenario",
        "--duration-s",
        "40",
        "--as-fast-as-possible",
        "--max-in-flight",
        "8",
    ]);
    let (status, _) = recorder.wait(Duration::from_secs(60));
    let message = std::fs::read_to_string(&log).unwrap();
    assert!(!status.success(), "the recorder went on past the limit: {message}");
    assert!(
        message.contains("full.mcap")
            && message.contains("cannot write")
            && message.contains("File too large")
            && message.contains("mcap recover"),
        "{message}"
    );
    let bytes = std::fs::read(&output).unwrap();
    assert!(bytes.len() as u64 <= FILE_SIZE_LIMIT);
    let readable = mcap::MessageStream::new(&bytes).unwrap().take_while(Result::is_ok).count();
    assert!(readable > 100, "{readable} messages readable");
    serve.signal(libc::SIGINT);
    let (status, output) = serve.wait(Duration::from_secs(10));
    assert!(status.success(), "primm serve: {status}\n{output}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_recording_stopped_by_its_duration_or_by_ctrl_c_is_a_finished_file() {
    let dir = tempdir("stop");
    let timed = dir.join("timed.mcap");
    let prefix = unique_prefix("record-stop");
    let started = Instant::now();
    primm(&["record", "--service-prefix", &prefix, "--duration-s", "1", "--output", timed.to_str().unwrap()]);
    assert!(started.elapsed() >= Duration::from_secs(1));
    let interrupted = dir.join("interrupted.mcap");
    let mut recorder = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["record", "--service-prefix", &prefix, "--output"])
        .arg(&interrupted)
        .env("RUST_LOG", "warn")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // It says where it records once it has subscribed (and its signal handlers are in place).
    // (Kept open until it exits, so that nothing it prints meets a closed pipe.)
    let mut stderr = std::io::BufReader::new(recorder.stderr.take().unwrap());
    let mut first_line = String::new();
    std::io::BufRead::read_line(&mut stderr, &mut first_line).unwrap();
    assert!(first_line.starts_with("recording"), "{first_line}");
    let recorder = ChildGuard(recorder);
    recorder.signal(libc::SIGINT);
    let (status, stdout) = recorder.wait(Duration::from_secs(10));
    assert!(status.success() && stdout.contains("0 track frames"), "{status}: {stdout}");
    drop(stderr);
    for path in [&timed, &interrupted] {
        let bytes = std::fs::read(path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
        assert_eq!(summary.stats.expect("statistics").message_count, 0);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
