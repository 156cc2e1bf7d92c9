"""Tests of tools/velocity_breakdown.py on hand-made measurement, track and association files."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import velocity_breakdown as breakdown  # noqa: E402

CONFIG = """
[[frame.sensors]]
id = 1
x_m = 0.0
y_m = 0.0
yaw_rad = 0.0
"""


def write(directory: Path) -> None:
    """One car seen along +x from sensor 1 at the origin, four frames; track 7 takes rows 0-3.
    Errors after each update: frame 0 (first row, no prior: not scored), then (1, 0) along the
    line of sight, (0, 2) across it, (0, -2) across. A pedestrian row no track took, and one
    without a true velocity, are left out."""
    measurements = ["frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,true_vx,true_vy"]
    tracks = ["frame,track_id,vx,vy"]
    associations = ["frame,measurement,track_id,prior_x,prior_y,confirmed"]
    errors = [(0.0, 0.0), (1.0, 0.0), (0.0, 2.0), (0.0, -2.0)]
    for frame, (ex, ey) in enumerate(errors):
        measurements.append(f"{frame},{0.05 * frame},3,car,20,0,5,10,20,0,1,5,0")
        tracks.append(f"{frame},7,{5 + ex},{ey}")
        prior = "" if frame == 0 else "20"
        associations.append(f"{frame},0,7,{prior},{prior},1")
        # A pedestrian nobody took.
        measurements.append(f"{frame},{0.05 * frame},4,pedestrian,5,5,0,0,5,5,1,1,0")
        associations.append(f"{frame},1,,,,0")
    (directory / "data").mkdir()
    (directory / "tracks").mkdir()
    (directory / "data" / "s.csv").write_text("\n".join(measurements) + "\n")
    (directory / "tracks" / "s.csv").write_text("\n".join(tracks) + "\n")
    (directory / "tracks" / "s.assoc").write_text("\n".join(associations) + "\n")
    (directory / "config.toml").write_text(CONFIG)


def test_errors_are_split_along_and_across_the_line_of_sight_and_grouped_by_age(tmp_path: Path) -> None:
    write(tmp_path)
    out = tmp_path / "out.json"
    code = breakdown.main(
        ["--data", str(tmp_path / "data"), "--tracks", str(tmp_path / "tracks"), "--config", str(tmp_path / "config.toml"), "--json", str(out)]
    )
    assert code == 0
    result = json.loads(out.read_text())
    everything = result["all"]
    assert everything["rows"] == 3
    assert math.isclose(everything["rmse_mps"], math.sqrt((1 + 4 + 4) / 3))
    assert math.isclose(everything["rmse_along_mps"], math.sqrt(1 / 3))
    assert math.isclose(everything["rmse_across_mps"], math.sqrt(8 / 3))
    assert list(result["by_class"]) == ["car"]
    ages = result["by_age"]
    assert (ages["1"]["rows"], ages["2"]["rows"], ages["3"]["rows"], ages[">20"]["rows"]) == (1, 1, 1, 0)
    assert math.isclose(ages["1"]["share"], 1 / 9) and math.isclose(ages["2"]["share"], 4 / 9)
    assert math.isclose(ages["2"]["rmse_across_mps"], 2.0) and ages["2"]["rmse_along_mps"] == 0.0
    # 1 % of three rows is no row.
    assert result["worst_rows_share"]["1%"] == 0.0


def test_missing_track_files_are_an_error(tmp_path: Path) -> None:
    write(tmp_path)
    (tmp_path / "tracks" / "s.assoc").unlink()
    assert breakdown.main(["--data", str(tmp_path / "data"), "--tracks", str(tmp_path / "tracks"), "--config", str(tmp_path / "config.toml")]) == 2
