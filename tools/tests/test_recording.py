"""primm's recordings and live view read by Foxglove's own Python packages, not by primm code.

- A file recorded from ``primm demo --record`` is read with the ``mcap`` package: every topic is
  there, each topic holds as many messages as the demo's programs counted frames, log times never
  go back, and the scenes decode with the published ``foxglove-schemas-protobuf`` classes (and
  with the schema the file carries, to the same values).
- The file's measurement frames replayed into a fresh ``primm serve`` give the recorded track
  frames bit for bit (clocks aside).
- ``primm demo --foxglove`` serves the Foxglove WebSocket protocol (v1) on loopback: a
  ``websockets`` client with the subprotocol the Foxglove SDK's server speaks, ``foxglove.sdk.v1``,
  gets the channel advertisement, subscribes and receives scenes with tracks while the demo runs.

The tests run the ``primm`` binary that ``cargo test`` builds (``target/debug/primm``; another one
through ``PRIMM_BINARY``).
"""

from __future__ import annotations

import ctypes
import json
import os
import queue
import re
import socket
import struct
import subprocess
import threading
import time
from pathlib import Path

import primm_wire
import pytest
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from websockets.sync.client import connect

ROOT = Path(__file__).resolve().parents[2]

WIRE_TOPICS = {
    "/primm/measurements": "primm::MeasurementFrame",
    "/primm/tracks": "primm::TrackFrame",
    "/primm/latency": "primm::LatencyReport",
}
SCENE_TOPICS = ["/primm/scene/tracks", "/primm/scene/detections", "/primm/scene/ground_truth"]
JSON_TOPICS = ["/primm/latency/stages", "/primm/latency/frame"]
EVERY_TOPIC = [*WIRE_TOPICS, *SCENE_TOPICS, "/tf", *JSON_TOPICS]
# Bounded waits: a debug build on two shared cores, far above what a run takes.
RUN_TIMEOUT_S = 240
CONNECT_TIMEOUT_S = 60
# The Foxglove WebSocket protocol v1 under the name the Foxglove SDK's server accepts.
SUBPROTOCOL = "foxglove.sdk.v1"


def primm_binary() -> Path:
    binary = Path(os.environ.get("PRIMM_BINARY", ROOT / "target" / "debug" / "primm"))
    assert binary.is_file(), f"{binary} is missing: build primm first (cargo build, or ./test.sh)"
    return binary


def run_primm(*args: str, timeout: float = RUN_TIMEOUT_S) -> subprocess.CompletedProcess:
    result = subprocess.run(
        [str(primm_binary()), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "RUST_LOG": "warn"},
        check=False,
    )
    assert result.returncode == 0, f"primm {' '.join(args)}:\n{result.stdout}\n{result.stderr}"
    return result


def read_topics(path: Path) -> dict[str, list]:
    """Every message of the file by topic, in file order: (schema, channel, message)."""
    topics: dict[str, list] = {}
    with path.open("rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            topics.setdefault(channel.topic, []).append((schema, channel, message))
    return topics


def wire_frame(kind, data: bytes):
    """A wire frame of type `kind` from a recorded payload (its header and valid entries)."""
    frame = kind()
    assert len(data) <= ctypes.sizeof(frame)
    ctypes.memmove(ctypes.addressof(frame), data, len(data))
    return frame


def count_after(label: str, text: str) -> int:
    match = re.search(rf"{label}:? (\d+)", text)
    assert match, f"no '{label}' in:\n{text}"
    return int(match.group(1))


@pytest.fixture(scope="module")
def demo_recording(tmp_path_factory) -> tuple[Path, str]:
    path = tmp_path_factory.mktemp("recording") / "demo.mcap"
    result = run_primm("demo", "--duration-s", "8", "--record", str(path))
    return path, result.stdout


def test_every_topic_of_a_demo_recording_is_there_once_per_frame(demo_recording):
    path, output = demo_recording
    topics = read_topics(path)
    assert sorted(topics) == sorted(EVERY_TOPIC)
    # The subscriber of the demo counts the track frames it received, the tracker the frames it
    # took: the recorder, a third subscriber, wrote one message of each per frame.
    subscriber = output.split("== subscriber", 1)[1].split("== tracker", 1)[0]
    track_frames = count_after("track frames", subscriber)
    assert track_frames > 50
    assert len(topics["/primm/tracks"]) == track_frames
    assert len(topics["/primm/measurements"]) == track_frames
    for topic in ["/primm/scene/tracks", "/primm/scene/detections", "/primm/latency/frame", "/tf"]:
        assert len(topics[topic]) == track_frames, topic
    # The ground truth: one scene per measurement frame that carries a true position.
    with_truth = 0
    for _, _, message in topics["/primm/measurements"]:
        frame = wire_frame(primm_wire.MeasurementFrame, message.data)
        with_truth += any(frame.measurements[k].truth_valid for k in range(frame.count))
    assert 0 < with_truth < track_frames
    assert len(topics["/primm/scene/ground_truth"]) == with_truth
    assert len(topics["/primm/latency/stages"]) == len(topics["/primm/latency"]) >= 1


def test_log_times_never_go_back_and_are_the_frames_sensor_times(demo_recording):
    path, _ = demo_recording
    topics = read_topics(path)
    for topic, messages in topics.items():
        times = [message.log_time for _, _, message in messages]
        assert all(a <= b for a, b in zip(times, times[1:])), topic
    # The measurement frames' own sensor times, read with the Python wire types.
    for _, channel, message in topics["/primm/measurements"]:
        frame = wire_frame(primm_wire.MeasurementFrame, message.data)
        assert message.log_time == round(frame.sensor_timestamp_s * 1e9)
        assert message.publish_time == frame.publish_time_ns


def test_wire_channels_name_their_type_and_the_wire_version(demo_recording):
    path, _ = demo_recording
    for topic, (schema, channel, message) in ((t, m[0]) for t, m in read_topics(path).items()):
        if topic in WIRE_TOPICS:
            assert schema.name == WIRE_TOPICS[topic]
            assert channel.message_encoding == "primm-wire"
            assert int(channel.metadata["wire_version"]) == primm_wire.WIRE_VERSION
    tracks = read_topics(path)["/primm/tracks"]
    header = ctypes.sizeof(primm_wire.TrackFrame) - primm_wire.TRACK_CAPACITY * ctypes.sizeof(primm_wire.WireTrack)
    for _, _, message in tracks:
        frame = wire_frame(primm_wire.TrackFrame, message.data)
        assert len(message.data) == header + frame.count * ctypes.sizeof(primm_wire.WireTrack)


def test_scenes_decode_with_foxglove_published_schemas(demo_recording):
    path, _ = demo_recording
    topics = read_topics(path)
    decoder_factory = DecoderFactory()
    largest = 0
    for topic in SCENE_TOPICS:
        for schema, _, message in topics[topic]:
            assert (schema.name, schema.encoding) == ("foxglove.SceneUpdate", "protobuf")
            published = SceneUpdate()
            published.ParseFromString(message.data)
            # The descriptor the file carries decodes the same message to the same values.
            from_file = decoder_factory.decoder_for("protobuf", schema)(message.data)
            assert MessageToDict(from_file) == MessageToDict(published)
            if topic == "/primm/scene/tracks":
                assert all(entity.id.startswith("track/") for entity in published.entities)
                largest = max(largest, len(published.entities))
                assert all(len(entity.cubes) == 1 and entity.texts for entity in published.entities)
    assert largest >= 3, "no scene with the scenario's tracks"
    for schema, _, message in topics["/tf"]:
        transforms = FrameTransforms()
        transforms.ParseFromString(message.data)
        assert transforms.transforms
    for topic in JSON_TOPICS:
        for schema, _, message in topics[topic]:
            assert schema.encoding == "jsonschema"
            json.loads(message.data)


def test_the_file_has_its_summary_and_compressed_chunks(demo_recording):
    path, _ = demo_recording
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    total = sum(len(messages) for messages in read_topics(path).values())
    assert summary.statistics.message_count == total
    assert summary.chunk_indexes and all(index.compression == "zstd" for index in summary.chunk_indexes)


def without_clocks(data: bytes) -> bytes:
    frame = wire_frame(primm_wire.TrackFrame, data)
    for clock in ("input_publish_time_ns", "input_scheduled_time_ns", "receive_time_ns", "publish_time_ns"):
        setattr(frame, clock, 0)
    return bytes(memoryview(frame).cast("B")[: len(data)])


def test_the_demo_replayed_into_a_fresh_tracker_gives_its_tracks_bit_for_bit(demo_recording, tmp_path):
    path, _ = demo_recording
    prefix = f"primm-pytest-replay-{os.getpid()}"
    again = tmp_path / "again.mcap"
    binary = str(primm_binary())
    environment = {**os.environ, "RUST_LOG": "warn"}
    common = ["--service-prefix", prefix]
    serve = subprocess.Popen([binary, "serve", *common, "--method", "imm"], env=environment,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    recorder = subprocess.Popen([binary, "record", *common, "--until-end", "--output", str(again)],
                                env=environment, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # The recorder says where it records once it has subscribed; `primm replay` waits for the
        # tracker itself. At twice the recorded pace, as a debug build's recorder keeps up.
        first_line = queue.Queue()
        threading.Thread(target=lambda: first_line.put(recorder.stderr.readline()), daemon=True).start()
        assert "recording" in first_line.get(timeout=CONNECT_TIMEOUT_S)
        replay = run_primm("replay", str(path), *common, "--rate", "2")
        assert "(0 dropped" in replay.stdout, replay.stdout
        recorder_out, recorder_err = recorder.communicate(timeout=RUN_TIMEOUT_S)
        assert recorder.returncode == 0, recorder_out + recorder_err
        assert recorder_out.count("(0 missed)") == 2, recorder_out
    finally:
        for process in (recorder, serve):
            if process.poll() is None:
                process.send_signal(2)
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
    recorded = [m.data for _, _, m in read_topics(path)["/primm/tracks"]]
    replayed = [m.data for _, _, m in read_topics(again)["/primm/tracks"]]
    assert len(recorded) == len(replayed) > 50
    for index, (a, b) in enumerate(zip(recorded, replayed)):
        assert without_clocks(a) == without_clocks(b), f"track frame {index} differs"


def free_loopback_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def receive_scenes_with_tracks(port: int) -> tuple[list[dict], int]:
    """Connects (retrying until the server is up), subscribes to the track scene and returns
    the advertised channels and the most entities one received scene had."""
    deadline = time.monotonic() + CONNECT_TIMEOUT_S
    while True:
        try:
            socket_ = connect(f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL], open_timeout=5,
                              max_size=None)
            break
        except OSError:
            assert time.monotonic() < deadline, "the live view did not come up"
            time.sleep(0.1)
    with socket_:
        assert socket_.subprotocol == SUBPROTOCOL
        channels: list[dict] = []
        while len(channels) < len(EVERY_TOPIC):
            message = json.loads(socket_.recv(timeout=10))
            if message["op"] == "advertise":
                channels.extend(message["channels"])
        scene = next(channel for channel in channels if channel["topic"] == "/primm/scene/tracks")
        assert (scene["encoding"], scene["schemaName"]) == ("protobuf", "foxglove.SceneUpdate")
        socket_.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": scene["id"]}]}))
        largest = 0
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        while largest < 3 and time.monotonic() < deadline:
            message = socket_.recv(timeout=10)
            if isinstance(message, str):
                continue
            opcode, subscription, _log_time = struct.unpack_from("<BIQ", message)
            assert (opcode, subscription) == (1, 7)
            update = SceneUpdate()
            update.ParseFromString(message[13:])
            largest = max(largest, len(update.entities))
        return channels, largest


def test_a_websocket_client_gets_the_track_scenes_of_a_running_demo():
    for _attempt in range(3):
        port = free_loopback_port()
        demo = subprocess.Popen(
            [str(primm_binary()), "demo", "--duration-s", "30", "--speed", "1", "--foxglove", f"127.0.0.1:{port}"],
            env={**os.environ, "RUST_LOG": "warn"},
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            channels, largest = receive_scenes_with_tracks(port)
        except AssertionError:
            if demo.poll() is not None and "in use" in (demo.stdout.read() + demo.stderr.read()):
                continue  # another program took the port in between: choose again
            raise
        finally:
            if demo.poll() is None:
                demo.send_signal(2)
                try:
                    demo.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    demo.kill()
                    demo.wait()
        assert sorted(channel["topic"] for channel in channels) == sorted(EVERY_TOPIC)
        assert largest >= 3
        return
    pytest.fail("no free loopback port stayed free")


def test_the_layout_names_topics_and_fields_a_recording_has(demo_recording):
    path, _ = demo_recording
    layout = json.loads((ROOT / "tools" / "foxglove" / "primm.json").read_text())
    panels = layout["configById"]
    assert set(panels) == {"3D!primm", "Plot!latency", "RawMessages!latency"}
    assert set(panels["3D!primm"]["topics"]) <= set(EVERY_TOPIC)
    assert panels["RawMessages!latency"]["topicPath"] in EVERY_TOPIC
    topics = read_topics(path)
    last = {topic: json.loads(messages[-1][2].data) for topic, messages in topics.items() if topic in JSON_TOPICS}
    for plotted in panels["Plot!latency"]["paths"]:
        topic, _, fields = plotted["value"].partition(".")
        value = last[topic]
        for field in fields.split("."):
            value = value[field]
        assert isinstance(value, (int, float)), plotted["value"]
