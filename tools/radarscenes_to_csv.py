#!/usr/bin/env python3
"""Convert RadarScenes sequences into primm's measurement CSV format.

Object measurements are built the way the PR-IMM paper describes (Section III-A and
Section IV, "Dataset"): the detections of one radar scan (one RadarScenes "scene": one
timestamp of one sensor) that share a track id are averaged into one object measurement
(x_cc, y_cc, vr_compensated, rcs). Car and large vehicle become ``car``, pedestrian and
pedestrian group become ``pedestrian``; every other label and every detection without a
track id is dropped. Each sequence is written to ``OUTPUT/<split>/sequence_<n>.csv`` with the
paper's split lists.

The CSV format is documented in docs/scenario.md. In short: one row per object measurement
with columns frame, t, gt_id, class, x, y, vr, rcs, true_x, true_y, sensor_id, ego_x, ego_y,
ego_yaw; a scan without any kept object is written as one row with empty measurement
columns; ``t`` is seconds since the sequence's first scan; ``gt_id`` numbers the track ids of a
sequence in order of first appearance; true_x and true_y stay empty (RadarScenes has no
object boxes); the ego pose comes from the odometry entry linked to the scan.

With ``--detections`` nothing is averaged: every detection with one of the kept labels becomes
a row of its own (x_cc, y_cc, vr_compensated, rcs, in the file's order within the scan), its
class from its own label and its ``gt_id`` from its track id (``-1`` for a labelled detection
without one). This is what a radar gives a tracker in a car, several detections per object and
scan; the averaged mode needs the annotation's track ids, which no tracker has. Detections of
other labels (the static world among them) are left out in both modes.

Usage:
    radarscenes_to_csv.py RADARSCENES_DIR --output OUT
    radarscenes_to_csv.py RADARSCENES_DIR/data/sequence_42 --output OUT
    radarscenes_to_csv.py RADARSCENES_DIR --output OUT --detections
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from pathlib import Path

import h5py
import numpy as np

# Sequence numbers of the paper's validation and evaluation splits; all others are training.
VALIDATION_SEQUENCES = frozenset({6, 42, 58, 85, 99, 122})
EVALUATION_SEQUENCES = frozenset(
    {1, 2, 3, 4, 16, 33, 38, 41, 47, 49, 57, 71, 81, 98, 105, 112, 113, 120, 123, 125, 131, 146}
)

# RadarScenes label ids (radar_scenes.labels.Label) mapped to primm classes.
LABEL_TO_CLASS = {
    0: "car",  # CAR
    1: "car",  # LARGE_VEHICLE
    7: "pedestrian",  # PEDESTRIAN
    8: "pedestrian",  # PEDESTRIAN_GROUP
}

# Largest number of measurements primm accepts in one frame.
MAX_MEASUREMENTS_PER_FRAME = 1024

HEADER = [
    "frame", "t", "gt_id", "class", "x", "y", "vr", "rcs", "true_x", "true_y",
    "sensor_id", "ego_x", "ego_y", "ego_yaw",
]


class ConversionError(RuntimeError):
    """The input does not look like a RadarScenes sequence or violates the format limits."""


def split_of(sequence_number: int) -> str:
    """The paper's split of a RadarScenes sequence number."""
    if sequence_number in VALIDATION_SEQUENCES:
        return "validation"
    if sequence_number in EVALUATION_SEQUENCES:
        return "evaluation"
    return "train"


def sequence_number_of(sequence_dir: Path, scenes: dict) -> int:
    """Sequence number from scenes.json's sequence_name or, failing that, the directory name."""
    for name in (str(scenes.get("sequence_name", "")), sequence_dir.name):
        match = re.fullmatch(r"sequence_(\d+)", name)
        if match:
            return int(match.group(1))
    raise ConversionError(f"cannot tell the sequence number of {sequence_dir}")


def fmt(value: float) -> str:
    """Shortest text that parses back to the same double."""
    value = float(value)
    if not np.isfinite(value):
        raise ConversionError(f"non-finite value {value}")
    return repr(value)


def _text(value) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    return str(value)


def averaged_measurements(detections, frame: str, t: str, sensor: str, ego: list[str],
                          track_numbers: dict[str, int]) -> list[list[str]]:
    """One row per track id of a scan: its detections averaged (the paper's measurements)."""
    groups: dict[str, list[int]] = {}
    for index, detection in enumerate(detections):
        track = _text(detection["track_id"])
        if track:
            groups.setdefault(track, []).append(index)
    measurements = []
    for track, indices in groups.items():
        points = detections[indices]
        # A track's points carry one label; should they disagree, the majority decides.
        labels, counts = np.unique(points["label_id"], return_counts=True)
        label = int(labels[np.argmax(counts)])
        object_class = LABEL_TO_CLASS.get(label)
        if object_class is None:
            continue
        if track not in track_numbers:
            track_numbers[track] = len(track_numbers)
        measurements.append([
            frame, t, str(track_numbers[track]), object_class,
            fmt(np.mean(points["x_cc"], dtype=np.float64)),
            fmt(np.mean(points["y_cc"], dtype=np.float64)),
            fmt(np.mean(points["vr_compensated"], dtype=np.float64)),
            fmt(np.mean(points["rcs"], dtype=np.float64)),
            "", "", sensor, *ego,
        ])
    return measurements


def detection_rows(detections, frame: str, t: str, sensor: str, ego: list[str],
                   track_numbers: dict[str, int]) -> list[list[str]]:
    """One row per detection of a scan with a kept label, class and gt_id its own."""
    rows = []
    for detection in detections:
        object_class = LABEL_TO_CLASS.get(int(detection["label_id"]))
        if object_class is None:
            continue
        track = _text(detection["track_id"])
        if track and track not in track_numbers:
            track_numbers[track] = len(track_numbers)
        rows.append([
            frame, t, str(track_numbers[track]) if track else "-1", object_class,
            fmt(detection["x_cc"]), fmt(detection["y_cc"]), fmt(detection["vr_compensated"]),
            fmt(detection["rcs"]), "", "", sensor, *ego,
        ])
    return rows


def convert_sequence(sequence_dir: Path, detections_only: bool = False) -> tuple[int, list[list[str]]]:
    """Converts one sequence directory; returns its number and the CSV rows (no header). With
    `detections_only`, one row per detection instead of one per track and scan."""
    scenes_path = sequence_dir / "scenes.json"
    h5_path = sequence_dir / "radar_data.h5"
    if not scenes_path.is_file() or not h5_path.is_file():
        raise ConversionError(f"{sequence_dir} lacks scenes.json or radar_data.h5")
    with open(scenes_path, "r", encoding="utf-8") as handle:
        scenes = json.load(handle)
    number = sequence_number_of(sequence_dir, scenes)
    with h5py.File(h5_path, "r") as h5:
        radar = h5["radar_data"][:]
        odometry = h5["odometry"][:] if "odometry" in h5 else None

    scene_items = sorted(((int(ts), scene) for ts, scene in scenes["scenes"].items()), key=lambda item: item[0])
    if not scene_items:
        return number, []
    first_timestamp = scene_items[0][0]
    track_numbers: dict[str, int] = {}
    rows: list[list[str]] = []
    for frame, (timestamp, scene) in enumerate(scene_items):
        t = fmt((timestamp - first_timestamp) / 1e6)
        sensor = str(int(scene["sensor_id"]))
        ego = ["", "", ""]
        odometry_index = scene.get("odometry_index")
        if odometry is not None and odometry_index is not None:
            pose = odometry[int(odometry_index)]
            ego = [fmt(pose["x_seq"]), fmt(pose["y_seq"]), fmt(pose["yaw_seq"])]
        start, end = (int(i) for i in scene["radar_indices"])
        detections = radar[start:end]
        build = detection_rows if detections_only else averaged_measurements
        measurements = build(detections, str(frame), t, sensor, ego, track_numbers)
        if len(measurements) > MAX_MEASUREMENTS_PER_FRAME:
            what = "detections" if detections_only else "objects"
            raise ConversionError(
                f"{sequence_dir}: scan at {timestamp} has {len(measurements)} {what}, "
                f"more than {MAX_MEASUREMENTS_PER_FRAME}"
            )
        if not measurements:
            rows.append([str(frame), t, "", "", "", "", "", "", "", "", sensor, *ego])
        rows.extend(measurements)
    return number, rows


def find_sequences(root: Path) -> list[Path]:
    """Sequence directories under `root`: `root` itself, `root/*`, or `root/data/*`."""
    if (root / "scenes.json").is_file():
        return [root]
    for base in (root / "data", root):
        found = sorted(
            (p for p in base.glob("sequence_*") if (p / "scenes.json").is_file()),
            key=lambda p: int(re.sub(r"\D", "", p.name) or 0),
        )
        if found:
            return found
    raise ConversionError(f"no RadarScenes sequence found under {root}")


def write_rows(path: Path, rows: list[list[str]]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(HEADER)
        writer.writerows(rows)


def convert(root: Path, output: Path, only: set[int] | None = None,
            detections_only: bool = False) -> list[Path]:
    """Converts every sequence found under `root`; returns the files written. With
    `detections_only`, one row per detection (see the module's description)."""
    written = []
    for sequence_dir in find_sequences(root):
        if only is not None:
            with open(sequence_dir / "scenes.json", "r", encoding="utf-8") as handle:
                if sequence_number_of(sequence_dir, json.load(handle)) not in only:
                    continue
        number, rows = convert_sequence(sequence_dir, detections_only)
        path = output / split_of(number) / f"sequence_{number}.csv"
        write_rows(path, rows)
        written.append(path)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Convert RadarScenes sequences (radar_data.h5 + scenes.json) into primm "
        "measurement CSV files, placed in OUTPUT/train, OUTPUT/validation and "
        "OUTPUT/evaluation according to the PR-IMM paper's split.",
    )
    parser.add_argument(
        "input", type=Path,
        help="a RadarScenes sequence directory, or the data set root (with data/sequence_*/)",
    )
    parser.add_argument("--output", "-o", type=Path, required=True, help="output directory")
    parser.add_argument(
        "--sequences", type=int, nargs="+", metavar="N",
        help="convert only these sequence numbers",
    )
    parser.add_argument(
        "--detections", action="store_true",
        help="write every detection as a row of its own instead of averaging each track's "
        "detections per scan (gt_id from the track id, class from the detection's label)",
    )
    args = parser.parse_args(argv)
    try:
        only = set(args.sequences) if args.sequences else None
        written = convert(args.input, args.output, only, args.detections)
    except (ConversionError, OSError, KeyError, ValueError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
