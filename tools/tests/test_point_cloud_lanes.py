"""Tests of tools/point_cloud_lanes.py: the cost scenes and the bad-input frames it writes."""

from __future__ import annotations

import csv
import subprocess
import sys
from collections import Counter
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "point_cloud_lanes.py"


def rows(tmp_path: Path, kind: str) -> list[dict[str, str]]:
    out = tmp_path / f"{kind}.csv"
    subprocess.run([sys.executable, str(SCRIPT), str(out), kind], check=True)
    with open(out, newline="") as f:
        return list(csv.DictReader(f))


def test_the_lanes_give_each_of_sixty_four_cars_its_points_in_every_frame(tmp_path: Path) -> None:
    table = rows(tmp_path, "4")
    per_frame = Counter(row["frame"] for row in table)
    assert len(per_frame) == 200 and set(per_frame.values()) == {64 * 4}
    assert len({row["gt_id"] for row in table}) == 64


def test_a_clutter_frame_holds_a_full_frame_of_points_spread_over_the_square(tmp_path: Path) -> None:
    table = rows(tmp_path, "clutter")
    per_frame = Counter(row["frame"] for row in table)
    assert len(per_frame) == 200 and set(per_frame.values()) == {1024}
    xs = [float(row["x"]) for row in table if row["frame"] == "0"]
    assert min(xs) < -90 and max(xs) > 90
    assert all(row["gt_id"] == "" for row in table)


def test_a_spot_frame_holds_a_full_frame_of_detections_at_one_place(tmp_path: Path) -> None:
    table = rows(tmp_path, "spot")
    assert len(table) == 200 * 1024
    assert {(row["x"], row["y"], row["vr"]) for row in table} == {("40.000", "-20.000", "0.000")}
