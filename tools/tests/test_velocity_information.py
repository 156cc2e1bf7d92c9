"""Tests of tools/velocity_information.py on hand-made measurement, track and association files."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import velocity_information as information  # noqa: E402

CONFIG = """
[[frame.sensors]]
id = 1
x_m = 0.0
y_m = 0.0
yaw_rad = 0.0
"""


def write(directory: Path) -> None:
    """The ego stands at world (10, 0) facing world +y (yaw 90 degrees). A car drives away from
    it at 5 m/s over ground: world velocity (0, 5), in the vehicle frame (5, 0) along the line of
    sight of sensor 1 at the origin. Its detections lie 0.5 m beyond its centre, a
    constant offset that no velocity fit sees, and its radial velocities are exact, so both fits
    find the true velocity from two detections on. Track 7 takes every car detection with errors
    (0, 2), (0, 2), (0, 1), (0, 1), (0, 0) after the first; track 8 takes a standing pedestrian with
    error (1, 0) after its first detection."""
    measurements = ["frame,t,gt_id,class,x,y,vr,rcs,true_x,true_y,sensor_id,ego_x,ego_y,ego_yaw,true_vx,true_vy"]
    tracks = ["frame,track_id,vx,vy"]
    associations = ["frame,measurement,track_id,prior_x,prior_y,confirmed"]
    car_errors = [(0.0, 0.0), (0.0, 2.0), (0.0, 2.0), (0.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
    pose = f"10,0,{math.pi / 2}"
    for frame, (ex, ey) in enumerate(car_errors):
        t = 0.05 * frame
        x = 20 + 5 * t
        measurements.append(f"{frame},{t},3,car,{x + 0.5},0,5,10,{x},0,1,{pose},5,0")
        measurements.append(f"{frame},{t},4,pedestrian,5,5,0,0,5,5,1,{pose},0,0")
        tracks.append(f"{frame},7,{5 + ex},{ey}")
        tracks.append(f"{frame},8,{0.0 if frame == 0 else 1.0},0")
        prior = "" if frame == 0 else "1"
        associations.append(f"{frame},0,7,{prior},{prior},1")
        associations.append(f"{frame},1,8,{prior},{prior},1")
    (directory / "data").mkdir()
    (directory / "tracks").mkdir()
    (directory / "data" / "s.csv").write_text("\n".join(measurements) + "\n")
    (directory / "tracks" / "s.csv").write_text("\n".join(tracks) + "\n")
    (directory / "tracks" / "s.assoc").write_text("\n".join(associations) + "\n")
    (directory / "config.toml").write_text(CONFIG)


def run(directory: Path) -> dict:
    out = directory / "out.json"
    code = information.main(
        ["--data", str(directory / "data"), "--tracks", str(directory / "tracks"), "--config", str(directory / "config.toml"), "--json", str(out)]
    )
    assert code == 0
    return json.loads(out.read_text())


def test_fits_find_the_true_velocity_through_the_ego_pose_and_the_tracker_is_set_beside_them(tmp_path: Path) -> None:
    write(tmp_path)
    result = run(tmp_path)
    assert math.isclose(result["position_std_m"], math.sqrt(0.25 / 2))
    buckets = {b["detections"]: b for b in result["by_detections"]}
    assert (buckets["2"]["rows"], buckets["3"]["rows"], buckets["4-5"]["rows"], buckets["6-10"]["rows"]) == (1, 1, 2, 1)
    for bucket in buckets.values():
        if bucket["rows"]:
            for fit in ("positions", "positions_and_radial_velocities"):
                assert bucket[fit]["rmse_along_mps"] < 1e-6 and bucket[fit]["rmse_across_mps"] < 1e-6
    assert math.isclose(buckets["2"]["tracker"]["rmse_across_mps"], 2.0)
    assert math.isclose(buckets["4-5"]["tracker"]["rmse_across_mps"], 1.0)
    assert buckets["2"]["tracker"]["rmse_along_mps"] == 0.0
    # Ten scored rows: the car's (4 + 4 + 1 + 1 + 0) and the pedestrian's five of 1; the oracle
    # takes the fit's zero on every car row and keeps the pedestrian's.
    assert result["rows"] == 10
    assert math.isclose(result["tracker_rmse_mps"], math.sqrt(15 / 10))
    assert math.isclose(result["oracle_rmse_mps"], math.sqrt(5 / 10), abs_tol=1e-9)
    # From six detections on only the last car row is replaced, and its error was zero already.
    assert math.isclose(result["replaced_rmse_mps"], result["tracker_rmse_mps"])


def test_the_fit_replaces_the_tracker_from_the_asked_detection_on(tmp_path: Path) -> None:
    write(tmp_path)
    out = tmp_path / "out.json"
    arguments = ["--data", str(tmp_path / "data"), "--tracks", str(tmp_path / "tracks"), "--config", str(tmp_path / "config.toml")]
    assert information.main(arguments + ["--fit-from", "4", "--json", str(out)]) == 0
    # Rows of 4, 5 and 6 detections (errors 1, 1, 0) take the fit's zero.
    assert math.isclose(json.loads(out.read_text())["replaced_rmse_mps"], math.sqrt(13 / 10), abs_tol=1e-9)


def test_a_track_that_did_not_start_on_the_objects_first_detection_is_not_compared(tmp_path: Path) -> None:
    write(tmp_path)
    association_file = tmp_path / "tracks" / "s.assoc"
    lines = association_file.read_text().splitlines()
    # The car's first detection goes to no track: track 7 starts on its second.
    lines[1] = "0,0,,,,0"
    association_file.write_text("\n".join(lines) + "\n")
    result = run(tmp_path)
    assert all(b["rows"] == 0 for b in result["by_detections"])
    assert result["oracle_rmse_mps"] == result["tracker_rmse_mps"]


def test_missing_track_files_are_an_error(tmp_path: Path) -> None:
    write(tmp_path)
    (tmp_path / "tracks" / "s.assoc").unlink()
    assert information.main(["--data", str(tmp_path / "data"), "--tracks", str(tmp_path / "tracks"), "--config", str(tmp_path / "config.toml")]) == 2
