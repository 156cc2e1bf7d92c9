"""Tests of the RadarScenes converter on a tiny data set written in RadarScenes' schema."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import radarscenes_to_csv as conv  # noqa: E402

RADAR_DTYPE = np.dtype([
    ("timestamp", "<i8"), ("sensor_id", "u1"), ("range_sc", "<f4"), ("azimuth_sc", "<f4"),
    ("rcs", "<f4"), ("vr", "<f4"), ("vr_compensated", "<f4"), ("x_cc", "<f4"), ("y_cc", "<f4"),
    ("x_seq", "<f4"), ("y_seq", "<f4"), ("uuid", "S36"), ("track_id", "S36"), ("label_id", "u1"),
])
ODOMETRY_DTYPE = np.dtype([
    ("timestamp", "<i8"), ("x_seq", "<f4"), ("y_seq", "<f4"), ("yaw_seq", "<f4"),
    ("vx", "<f4"), ("yaw_rate", "<f4"),
])

T0 = 156_862_647_501  # microseconds, like RadarScenes timestamps


def detection(ts, sensor, x, y, vr, rcs, track, label, n):
    return (ts, sensor, np.hypot(x, y), np.arctan2(y, x), rcs, vr + 1.0, vr, x, y, x + 100, y + 200,
            f"uuid-{n}".encode(), track.encode(), label)


def write_sequence(root: Path, number: int, scans) -> Path:
    """scans: list of (timestamp_us, sensor_id, [detection tuples])."""
    seq = root / "data" / f"sequence_{number}"
    seq.mkdir(parents=True)
    radar_rows = []
    scenes = {}
    odometry = []
    for k, (ts, sensor, dets) in enumerate(scans):
        start = len(radar_rows)
        radar_rows.extend(dets)
        odometry.append((ts - 100, 10.0 * k, -2.0 * k, 0.25 * k, 5.0, 0.1))
        scenes[str(ts)] = {
            "sensor_id": sensor,
            "odometry_timestamp": ts - 100,
            "odometry_index": k,
            "image_name": f"{ts}.jpg",
            "radar_indices": [start, len(radar_rows)],
            "prev_timestamp": None,
            "next_timestamp": None,
            "prev_timestamp_same_sensor": None,
            "next_timestamp_same_sensor": None,
        }
    with h5py.File(seq / "radar_data.h5", "w") as h5:
        h5.create_dataset("radar_data", data=np.array(radar_rows, dtype=RADAR_DTYPE))
        h5.create_dataset("odometry", data=np.array(odometry, dtype=ODOMETRY_DTYPE))
    timestamps = [s[0] for s in scans]
    # Written out of order on purpose: the converter must sort scenes by time.
    shuffled = dict(reversed(list(scenes.items())))
    with open(seq / "scenes.json", "w", encoding="utf-8") as handle:
        json.dump({"sequence_name": f"sequence_{number}", "category": "train",
                   "first_timestamp": min(timestamps), "last_timestamp": max(timestamps),
                   "scenes": shuffled}, handle)
    return seq


@pytest.fixture()
def dataset(tmp_path: Path) -> Path:
    root = tmp_path / "RadarScenes"
    scans = [
        (T0, 1, [
            detection(T0, 1, 10.0, 2.0, -3.0, 5.0, "car-a", 0, 0),
            detection(T0, 1, 12.0, 4.0, -1.0, 9.0, "car-a", 0, 1),
            detection(T0, 1, 5.0, -1.0, 0.5, -8.0, "ped-b", 7, 2),
            detection(T0, 1, 30.0, 5.0, 0.0, 3.0, "", 11, 3),  # static, no track
            detection(T0, 1, 8.0, 8.0, 2.0, 0.0, "bike-c", 5, 4),  # bicycle: dropped
        ]),
        (T0 + 15_000, 2, [
            detection(T0 + 15_000, 2, 20.0, -6.0, 4.0, 10.0, "van-d", 1, 5),  # large vehicle
            detection(T0 + 15_000, 2, 6.0, 1.0, 1.0, -6.0, "group-e", 8, 6),  # pedestrian group
            detection(T0 + 15_000, 2, 6.5, 1.5, 1.5, -4.0, "group-e", 8, 7),
        ]),
        (T0 + 31_000, 3, [
            detection(T0 + 31_000, 3, 40.0, 0.0, 0.0, 1.0, "", 11, 8),
        ]),
        (T0 + 44_000, 4, [
            detection(T0 + 44_000, 4, 11.0, 3.0, -2.0, 7.0, "car-a", 0, 9),
            detection(T0 + 44_000, 4, 3.0, 3.0, 0.0, 0.0, "truck-f", 2, 10),  # truck: dropped
        ]),
    ]
    write_sequence(root, 42, scans)  # validation
    write_sequence(root, 1, scans[:2])  # evaluation
    write_sequence(root, 7, scans[1:3])  # train
    return root


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def test_averaging_class_mapping_drops_and_empty_scans(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    written = conv.convert(dataset, out)
    assert sorted(p.relative_to(out).as_posix() for p in written) == [
        "evaluation/sequence_1.csv", "train/sequence_7.csv", "validation/sequence_42.csv",
    ]
    with open(out / "validation" / "sequence_42.csv", encoding="utf-8") as handle:
        assert handle.readline().strip() == ",".join(conv.HEADER)
    rows = read_csv(out / "validation" / "sequence_42.csv")
    # Scan 0: car-a (2 points) and ped-b; static and bicycle dropped.
    frame0 = [r for r in rows if r["frame"] == "0"]
    assert len(frame0) == 2
    car = next(r for r in frame0 if r["class"] == "car")
    assert float(car["x"]) == pytest.approx(11.0)
    assert float(car["y"]) == pytest.approx(3.0)
    assert float(car["vr"]) == pytest.approx(-2.0)
    assert float(car["rcs"]) == pytest.approx(7.0)
    assert car["true_x"] == "" and car["true_y"] == ""
    assert car["t"] == "0.0" and car["sensor_id"] == "1"
    ped = next(r for r in frame0 if r["class"] == "pedestrian")
    assert float(ped["x"]) == pytest.approx(5.0)
    # Scan 1: large vehicle -> car, pedestrian group -> pedestrian (averaged).
    frame1 = {r["class"]: r for r in rows if r["frame"] == "1"}
    assert set(frame1) == {"car", "pedestrian"}
    assert float(frame1["pedestrian"]["x"]) == pytest.approx(6.25)
    assert float(frame1["pedestrian"]["vr"]) == pytest.approx(1.25)
    assert float(frame1["car"]["t"]) == pytest.approx(0.015)
    assert frame1["car"]["sensor_id"] == "2"
    # Scan 2 holds only static detections: one empty-frame row keeps its time.
    frame2 = [r for r in rows if r["frame"] == "2"]
    assert len(frame2) == 1
    assert frame2[0]["class"] == "" and frame2[0]["x"] == "" and frame2[0]["gt_id"] == ""
    assert float(frame2[0]["t"]) == pytest.approx(0.031)
    # Scan 3: the truck is dropped; car-a keeps its id from scan 0.
    frame3 = [r for r in rows if r["frame"] == "3"]
    assert len(frame3) == 1 and frame3[0]["gt_id"] == car["gt_id"]
    # Ego pose from the linked odometry entry.
    assert float(frame3[0]["ego_x"]) == pytest.approx(30.0)
    assert float(frame3[0]["ego_y"]) == pytest.approx(-6.0)
    assert float(frame3[0]["ego_yaw"]) == pytest.approx(0.75)
    # Ids are distinct per track and assigned in order of first appearance.
    ids = {(r["class"], r["gt_id"]) for r in rows if r["gt_id"]}
    assert len({gid for _, gid in ids}) == 4
    assert car["gt_id"] == "0" and ped["gt_id"] == "1"
    # Frames and times never decrease.
    frames = [int(r["frame"]) for r in rows]
    assert frames == sorted(frames) and frames[-1] == 3
    times = [float(r["t"]) for r in rows]
    assert times == sorted(times)


def test_detections_are_written_one_row_each_with_their_own_label_and_track(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "detections"
    conv.convert(dataset, out, only={42}, detections_only=True)
    rows = read_csv(out / "validation" / "sequence_42.csv")
    averaged = read_csv(conv.convert(dataset, tmp_path / "averaged", only={42})[0])
    # Scan 0: both detections of car-a, one of ped-b, in the file's order; static and
    # bicycle dropped as in the averaged mode.
    frame0 = [r for r in rows if r["frame"] == "0"]
    assert [(r["class"], float(r["x"]), float(r["vr"]), float(r["rcs"])) for r in frame0] == [
        ("car", 10.0, -3.0, 5.0), ("car", 12.0, -1.0, 9.0), ("pedestrian", 5.0, 0.5, -8.0),
    ]
    assert frame0[0]["gt_id"] == frame0[1]["gt_id"] == "0" and frame0[2]["gt_id"] == "1"
    assert all(r["sensor_id"] == "1" and r["t"] == "0.0" and r["true_x"] == "" for r in frame0)
    # The mean of a track's detections is the averaged mode's measurement.
    car = next(r for r in averaged if r["frame"] == "0" and r["class"] == "car")
    assert float(car["x"]) == pytest.approx(np.mean([float(r["x"]) for r in frame0[:2]]))
    # Scan 1: the pedestrian group's two detections stay two rows of one track.
    group = [r for r in rows if r["frame"] == "1" and r["class"] == "pedestrian"]
    assert len(group) == 2 and group[0]["gt_id"] == group[1]["gt_id"]
    # Same track numbering, empty scans and frames as the averaged mode.
    assert {r["gt_id"] for r in rows} == {r["gt_id"] for r in averaged if r["gt_id"]} | {""}
    assert [r["frame"] for r in rows if r["class"] == ""] == ["2"]
    assert len(rows) == 8 and len(averaged) == 6
    # A labelled detection without a track id is kept without a ground-truth id.
    root = tmp_path / "untracked"
    write_sequence(root, 9, [(T0, 1, [detection(T0, 1, 4.0, 1.0, 0.5, -7.0, "", 7, 0)])])
    untracked = read_csv(conv.convert(root, tmp_path / "untracked_out", detections_only=True)[0])
    assert [(r["gt_id"], r["class"]) for r in untracked] == [("-1", "pedestrian")]
    # From the command line.
    script = TOOLS / "radarscenes_to_csv.py"
    done = subprocess.run([sys.executable, str(script), str(dataset), "-o", str(tmp_path / "cli"),
                           "--sequences", "42", "--detections"], capture_output=True, text=True, check=True)
    assert read_csv(Path(done.stdout.split()[0])) == rows


def test_split_lists_match_the_paper() -> None:
    assert len(conv.VALIDATION_SEQUENCES) == 6
    assert len(conv.EVALUATION_SEQUENCES) == 22
    assert not conv.VALIDATION_SEQUENCES & conv.EVALUATION_SEQUENCES
    train = [n for n in range(1, 159) if conv.split_of(n) == "train"]
    assert len(train) == 130
    assert conv.split_of(42) == "validation" and conv.split_of(146) == "evaluation"


def test_single_sequence_directory_and_filter(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "single"
    written = conv.convert(dataset / "data" / "sequence_7", out)
    assert [p.relative_to(out).as_posix() for p in written] == ["train/sequence_7.csv"]
    rows = read_csv(written[0])
    # Sequence 7 starts with the second scan: t is relative to its own first scan.
    assert float(rows[0]["t"]) == 0.0
    assert [r["frame"] for r in rows] == ["0", "0", "1"]
    filtered = conv.convert(dataset, tmp_path / "filtered", only={1})
    assert [p.name for p in filtered] == ["sequence_1.csv"]


def test_command_line(dataset: Path, tmp_path: Path) -> None:
    script = TOOLS / "radarscenes_to_csv.py"
    help_text = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, check=True)
    assert "--output" in help_text.stdout
    out = tmp_path / "cli"
    done = subprocess.run([sys.executable, str(script), str(dataset), "--output", str(out)],
                          capture_output=True, text=True, check=True)
    assert len(done.stdout.split()) == 3
    assert (out / "evaluation" / "sequence_1.csv").is_file()
    missing = subprocess.run([sys.executable, str(script), str(tmp_path / "nothing"), "-o", str(out)],
                             capture_output=True, text=True)
    assert missing.returncode == 1 and "error:" in missing.stderr
