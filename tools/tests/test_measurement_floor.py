"""Tests of tools/measurement_floor.py on a hand-made measurement file."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import measurement_floor as floor  # noqa: E402

HEADER = "frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw\n"


def row(frame: int, gt: str, cls: str, offset: tuple[float, float], sensor: int, centre=(10.0, 5.0)) -> str:
    x, y = centre[0] + offset[0], centre[1] + offset[1]
    return f"{frame},{frame * 0.05},{gt},{cls},{x},{y},0.0,1.0,{centre[0]},{centre[1]},{sensor},0,0,0\n"


def write_sequence(directory: Path) -> None:
    rows = [HEADER]
    # Car 1 from sensor 0: a persistent offset (1, 0) and a per-scan +-0.3 m in y.
    for k, dy in enumerate([0.3, -0.3, 0.3, -0.3]):
        rows.append(row(2 * k, "1", "car", (1.0, dy), 0, centre=(10.0 + k, 5.0)))
    # The same car from sensor 1: a persistent (0, -2) and nothing else.
    for k in range(2):
        rows.append(row(2 * k + 1, "1", "car", (0.0, -2.0), 1))
    # A pedestrian measured exactly; a clutter row and a row without a true centre are skipped.
    rows.append(row(9, "7", "pedestrian", (0.0, 0.0), 0))
    rows.append("10,0.5,,car,3.0,4.0,0.0,1.0,,,0,0,0,0\n")
    rows.append("11,0.55,7,pedestrian,3.0,4.0,0.0,1.0,,,0,0,0,0\n")
    (directory / "evaluation_0000.csv").write_text("".join(rows))


def test_the_offset_splits_into_its_persistent_and_per_scan_parts(tmp_path: Path) -> None:
    write_sequence(tmp_path)
    result = floor.decompose(sorted(tmp_path.glob("*.csv")))
    car = result["car"]
    assert car["measurements"] == 6
    assert math.isclose(car["offset_m"], math.sqrt((4 * 1.09 + 2 * 4.0) / 6))
    assert math.isclose(car["persistent_m"], math.sqrt((4 * 1.0 + 2 * 4.0) / 6))
    assert math.isclose(car["per_scan_m"], math.sqrt(4 * 0.09 / 6))
    # Three changes of 0.6 m from sensor 0, one of zero from sensor 1, over 2 x 4.
    assert math.isclose(car["scan_to_scan_m"], math.sqrt(3 * 0.36 / 8))
    # Squares add up: the mean and the spread about it are orthogonal.
    assert math.isclose(car["offset_m"] ** 2, car["persistent_m"] ** 2 + car["per_scan_m"] ** 2)
    assert result["pedestrian"]["measurements"] == 1
    assert result["pedestrian"]["offset_m"] == 0.0
    assert result["all"]["measurements"] == 7
    assert list(result) == ["car", "pedestrian", "all"]


def test_the_command_prints_and_writes_json_and_refuses_data_without_truth(tmp_path: Path, capsys) -> None:
    write_sequence(tmp_path)
    out = tmp_path / "floor.json"
    assert floor.main(["--data", str(tmp_path), "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "car" in printed and "scan_to_scan" in printed
    assert json.loads(out.read_text())["car"]["measurements"] == 6

    empty = tmp_path / "empty"
    empty.mkdir()
    assert floor.main(["--data", str(empty)]) == 2
    (empty / "a.csv").write_text(HEADER + "0,0.0,,car,3.0,4.0,0.0,1.0,,,0,0,0,0\n")
    assert floor.main(["--data", str(empty)]) == 2
    assert "no measurement" in capsys.readouterr().err


def test_the_one_step_motion_splits_along_and_across_the_line_of_sight(tmp_path: Path) -> None:
    # A car measured at its centre, moving at (2, 1) m/s from (10, 0); the ego stands at the
    # origin; each row's radial velocity is the true one along its own line of sight, so the
    # radial velocity explains the motion along the line of sight up to the sight's turning.
    rows = [HEADER]
    velocity = (2.0, 1.0)
    expected_along, expected_across, expected_left = [], [], []
    positions = [(10.0 + velocity[0] * 0.1 * k, velocity[1] * 0.1 * k) for k in range(3)]
    for k, (x, y) in enumerate(positions):
        norm = math.hypot(x, y)
        u = (x / norm, y / norm)
        vr = velocity[0] * u[0] + velocity[1] * u[1]
        rows.append(f"{k},{0.1 * k},3,car,{x},{y},{vr},1.0,{x},{y},0,0,0,0\n")
        if k + 1 < len(positions):
            motion = (positions[k + 1][0] - x, positions[k + 1][1] - y)
            along = motion[0] * u[0] + motion[1] * u[1]
            expected_along.append(along)
            expected_across.append(-motion[0] * u[1] + motion[1] * u[0])
            expected_left.append(along - vr * 0.1)
    (tmp_path / "s.csv").write_text("".join(rows))
    budget = floor.motion_budget(sorted(tmp_path.glob("*.csv")))
    rms = lambda values: math.sqrt(sum(v * v for v in values) / len(values))  # noqa: E731
    car = budget["car"]
    assert car["steps"] == 2
    assert math.isclose(car["along_sight_m"], rms(expected_along))
    assert math.isclose(car["across_sight_m"], rms(expected_across))
    assert math.isclose(car["along_after_radial_velocity_m"], rms(expected_left), abs_tol=1e-12)
    assert car["along_after_radial_velocity_m"] < 1e-12 and car["across_sight_m"] > 0.09
    assert budget["all"] == car
