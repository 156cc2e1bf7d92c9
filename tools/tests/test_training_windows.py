"""training/dataset.py: where each window's line of sight comes from (the radar's mount mapped with
the ego pose, as the tracker places it), one measurement per object and scan, and the rotation
into the line-of-sight axes."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "training"))

import dataset  # noqa: E402

HEADER = "frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw\n"


def test_the_sensor_mounts_come_from_the_tracker_configuration() -> None:
    mounts = dataset.read_sensor_mounts()
    assert sorted(mounts) == [1, 2, 3, 4]
    assert mounts[1] == (3.66, -0.87)
    assert mounts[4] == (3.66, 0.87)


def write_sequence(path: Path) -> Path:
    yaw = 0.5
    rows = [
        # One pedestrian, measured by radar 3 in three scans; the ego vehicle moves and turns.
        f"0,0.00,7,pedestrian,10.0,2.0,-1.0,0.0,10.0,2.0,3,100.0,50.0,{yaw}",
        f"1,0.06,7,pedestrian,10.0,2.1,-1.0,0.0,10.0,2.1,3,100.5,50.1,{yaw}",
        # A second reflection of the same object in scan 1: left out.
        f"1,0.06,7,pedestrian,10.5,2.6,-1.0,0.0,10.0,2.1,3,100.5,50.1,{yaw}",
        f"2,0.12,7,pedestrian,10.0,2.2,-1.0,0.0,10.0,2.2,,101.0,50.2,{yaw}",
    ]
    path.write_text(HEADER + "\n".join(rows) + "\n")
    return path


def world(x: float, y: float, ego: tuple[float, float, float]) -> np.ndarray:
    c, s = math.cos(ego[2]), math.sin(ego[2])
    return np.array([ego[0] + c * x - s * y, ego[1] + s * x + c * y])


def test_each_window_carries_the_line_of_sight_of_its_latest_measurement(tmp_path: Path) -> None:
    directory = tmp_path / "split"
    directory.mkdir()
    write_sequence(directory / "sequence_0000.csv")
    mounts = {3: (3.86, 0.70)}
    windows, _ = dataset.load_split(str(directory), max_horizon=3, max_horizon_s=1.0, mounts=mounts)
    # Two anchors (scans 0 and 1) with one and two horizons: the duplicate of scan 1 is gone.
    assert sorted(zip(windows.length.tolist(), windows.horizon.tolist())) == [(1, 1), (1, 2), (2, 1)]
    anchor_1 = windows.length == 2
    ego = (100.5, 50.1, 0.5)
    expected = world(10.0, 2.1, ego) - world(3.86, 0.70, ego)
    expected /= np.linalg.norm(expected)
    assert np.allclose(windows.line_of_sight[anchor_1][0], expected, atol=1e-12)
    # In the vehicle frame the radar stays at its mount.
    vehicle, _ = dataset.load_split(str(directory), 3, 1.0, frame="vehicle", mounts=mounts)
    offset = np.array([10.0 - 3.86, 2.1 - 0.70])
    assert np.allclose(vehicle.line_of_sight[vehicle.length == 2][0], offset / np.linalg.norm(offset))


def test_a_measurement_without_a_known_radar_is_seen_from_the_reference_point(tmp_path: Path) -> None:
    path = write_sequence(tmp_path / "s.csv")
    objects = dataset.read_objects(str(path), "world", mounts={})
    latest = objects[0][-1]
    ego = (101.0, 50.2, 0.5)
    assert np.allclose(latest[9:11], world(0.0, 0.0, ego))
    assert np.allclose(latest[1:3], world(10.0, 2.2, ego))


def test_the_line_of_sight_axes_put_the_line_of_sight_on_x() -> None:
    line_of_sight = np.array([[0.6, 0.8], [np.nan, np.nan], [-1.0, 0.0]])
    cos, sin = dataset.line_of_sight_frames(line_of_sight)
    along = dataset.vectors_to_model_frame(np.array([[3.0, 4.0], [3.0, 4.0], [-2.0, 0.0]]), cos, sin)
    assert np.allclose(along[0], [5.0, 0.0], atol=1e-6)
    assert np.allclose(along[1], [3.0, 4.0])  # no line of sight: unrotated
    assert np.allclose(along[2], [2.0, 0.0], atol=1e-6)
    back = dataset.vectors_from_model_frame(along, cos, sin)
    assert np.allclose(back, [[3.0, 4.0], [3.0, 4.0], [-2.0, 0.0]], atol=1e-6)
    # Training turns windows without a line of sight to random axes.
    cos_r, sin_r = dataset.line_of_sight_frames(line_of_sight, np.random.default_rng(1))
    assert (cos_r[0], sin_r[0]) == (cos[0], sin[0])
    assert math.isclose(cos_r[1] ** 2 + sin_r[1] ** 2, 1.0) and (cos_r[1], sin_r[1]) != (1.0, 0.0)


def test_input_frames_names_both_axes_and_refuses_others() -> None:
    features = np.zeros((1, dataset.MAX_HISTORY, dataset.FEATURES), np.float32)
    features[0, 0, :2] = [-1.0, 0.0]  # moved +x from the row before
    line_of_sight = np.array([[0.0, 1.0]])
    cos, sin = dataset.input_frames("latest_motion", features, np.array([2]), line_of_sight)
    assert (float(cos[0]), float(sin[0])) == (1.0, 0.0)
    cos, sin = dataset.input_frames("line_of_sight", features, np.array([2]), line_of_sight)
    assert (float(cos[0]), float(sin[0])) == (0.0, 1.0)
    try:
        dataset.input_frames("sideways", features, np.array([2]), line_of_sight)
    except ValueError as error:
        assert "sideways" in str(error)
    else:
        raise AssertionError("an unknown input frame was accepted")
