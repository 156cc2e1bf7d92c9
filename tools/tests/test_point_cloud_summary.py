"""Tests of the point-cloud summary of measurement files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import point_cloud_summary as summary  # noqa: E402

HEADER = "frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw,true_vx,true_vy,origin\n"


def row(frame: int, gt: int, label: str, origin: str) -> str:
    return f"{frame},{frame * 0.1},{gt},{label},1,2,3,4,,,1,0,0,0,,,{origin}\n"


def test_detections_per_object_ghosts_clutter_and_wrong_labels_are_counted(tmp_path: Path) -> None:
    text = HEADER
    # Frame 0: car 1 with three detections (one labelled pedestrian), pedestrian 2 with one,
    # a ghost and two clutter points.
    text += row(0, 1, "car", "object") + row(0, 1, "car", "object") + row(0, 1, "pedestrian", "object")
    text += row(0, 2, "pedestrian", "object") + row(0, -1, "car", "ghost")
    text += row(0, -1, "car", "clutter") + row(0, -1, "pedestrian", "clutter")
    # Frame 1: car 1 with five detections, pedestrian 2 with two; frame 2 empty.
    text += "".join(row(1, 1, "car", "object") for _ in range(5))
    text += row(1, 2, "pedestrian", "object") + row(1, 2, "pedestrian", "object")
    text += "2,0.2,,,,,,,,,1,0,0,0,,,\n"
    (tmp_path / "a.csv").write_text(text, encoding="utf-8")
    s = summary.summarise(summary.files_of([tmp_path]))
    assert s["frames"] == 3 and s["largest_frame"] == 7
    assert s["car"]["object_scans"] == 2 and s["car"]["mean"] == pytest.approx(4.0)
    assert s["pedestrian"]["mean"] == pytest.approx(1.5)
    assert s["ghosts_per_scan"] == pytest.approx(1 / 3)
    assert s["clutter_per_scan"] == pytest.approx(2 / 3)
    assert s["wrong_label_share"] == pytest.approx(1 / 11)
    # Without the origin column, rows without a ground-truth id count as clutter.
    old = "".join(line.rsplit(",", 1)[0] + "\n" for line in text.splitlines())
    (tmp_path / "a.csv").write_text(old, encoding="utf-8")
    s = summary.summarise(summary.files_of([tmp_path]))
    assert (s["ghosts_per_scan"], s["clutter_per_scan"]) == (0.0, pytest.approx(1.0))
    done = subprocess.run([sys.executable, str(TOOLS / "point_cloud_summary.py"), str(tmp_path)],
                          capture_output=True, text=True, check=True)
    assert "| car | 2 | 4.00 |" in done.stdout and "largest frame: 7" in done.stdout
    missing = subprocess.run([sys.executable, str(TOOLS / "point_cloud_summary.py"), str(tmp_path / "none")],
                             capture_output=True, text=True)
    assert missing.returncode == 1 and "error:" in missing.stderr
    (tmp_path / "b.csv").write_text("frame,t\n0,0\n", encoding="utf-8")
    broken = subprocess.run([sys.executable, str(TOOLS / "point_cloud_summary.py"), str(tmp_path / "b.csv")],
                            capture_output=True, text=True)
    assert broken.returncode == 1 and "error:" in broken.stderr and "Traceback" not in broken.stderr
