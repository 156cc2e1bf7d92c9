#!/usr/bin/env python3
"""How much of a new object's velocity its first detections carry, against what the tracker
estimates from them.

For every object of one class (default ``car``), its detections in arrival order are taken with
their true identity (perfect association, no clutter) and, after each of the first ``--max-k``
detections, its velocity over ground is fitted by weighted least squares with a constant
velocity, from

* its positions alone (world frame, through the ego pose of each frame), and
* its positions and radial velocities: one row ``u_i . v = v_r,i`` per detection, ``u_i`` the
  unit line of sight from the measuring radar's mount to the detection (the radial velocity is
  compensated for the ego's motion, as primm's input is).

No prior on the velocity enters the fits: they show what the measurements themselves say. The
weights are the data's own: the RMS distance of the class's detections from the objects' true
centres per axis, and the RMS of ``v_r - u . v_true``, both printed.

The tracker's rows (those ``primm eval`` scores as "Table II, velocity", as
``tools/velocity_breakdown.py`` takes them) of tracks that began on the object's first detection
are set beside the fits after the same number of detections of that object. The errors are split
along and across the line of sight of the latest detection. Last, an oracle that takes, on every
such row with at least two detections, the better of the tracker's velocity and the fit with radial
velocities shows how far any estimator without prior knowledge of the traffic could lower the
velocity RMSE over all rows and classes; an estimator that knows which is better on each row does
not exist, so that is a loose bound. A realisable one replaces the tracker's velocity by the fit on
every such row from ``--fit-from`` detections on, where the fit is the better on average.

Input: as ``tools/velocity_breakdown.py`` (measurement CSVs with true velocities and ego poses,
and ``primm track --output DIR/NAME.csv --associations DIR/NAME.assoc`` per file).

Usage:
    python3 tools/velocity_information.py --data DATA --tracks TRACKS [--class car] [--json FILE]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from velocity_breakdown import ROOT, sensor_mounts  # noqa: E402

BUCKETS = [("2", 2, 2), ("3", 3, 3), ("4-5", 4, 5), ("6-10", 6, 10), ("11-20", 11, 20)]


def detections_of(measurements: Path, mounts):
    """Per measurement row, in file order: (frame, index in its frame, (sequence, object id) or
    None, class, detection or None). A detection holds its time, world position, world unit line
    of sight, radial velocity, true world velocity, vehicle-frame line of sight and true velocity,
    its distance from the object's true centre and its radial velocity's error."""
    index_in_frame: dict[str, int] = defaultdict(int)
    with open(measurements, newline="") as handle:
        for row in csv.DictReader(handle):
            frame = row["frame"]
            index = index_in_frame[frame]
            index_in_frame[frame] += 1
            if row["gt_id"] in ("", "-1") or "" in (row.get("true_vx", ""), row.get("ego_yaw", ""), row["true_x"]):
                yield frame, index, None, row["class"], None
                continue
            yaw = float(row["ego_yaw"])
            c, s = math.cos(yaw), math.sin(yaw)
            x, y = float(row["x"]), float(row["y"])
            mount = mounts.get(int(row["sensor_id"]), (0.0, 0.0)) if row.get("sensor_id") else (0.0, 0.0)
            lx, ly = x - mount[0], y - mount[1]
            length = math.hypot(lx, ly)
            if length == 0.0:
                yield frame, index, None, row["class"], None
                continue
            lx, ly = lx / length, ly / length
            vx, vy = float(row["true_vx"]), float(row["true_vy"])
            yield frame, index, (measurements.stem, row["gt_id"]), row["class"], {
                "t": float(row["t"]),
                "p": (float(row["ego_x"]) + c * x - s * y, float(row["ego_y"]) + s * x + c * y),
                "u": (c * lx - s * ly, s * lx + c * ly),
                "vr": float(row["vr"]),
                "v": (c * vx - s * vy, s * vx + c * vy),
                "u_vehicle": (lx, ly),
                "v_vehicle": (vx, vy),
                "offset_m2": (x - float(row["true_x"])) ** 2 + (y - float(row["true_y"])) ** 2,
                "vr_error": float(row["vr"]) - (lx * vx + ly * vy),
            }


def fit(history: list[dict], position_std: float, radial_std: float, with_radial: bool):
    """World velocity (m/s) of the weighted least-squares constant-velocity fit of `history`, at
    its latest time; None when the rows do not determine it."""
    t_last = history[-1]["t"]
    rows, rhs = [], []
    for d in history:
        dt = d["t"] - t_last
        rows += [[1 / position_std, 0, dt / position_std, 0], [0, 1 / position_std, 0, dt / position_std]]
        rhs += [d["p"][0] / position_std, d["p"][1] / position_std]
        if with_radial:
            rows.append([0, 0, d["u"][0] / radial_std, d["u"][1] / radial_std])
            rhs.append(d["vr"] / radial_std)
    a = np.array(rows)
    if np.linalg.matrix_rank(a) < 4 or np.linalg.cond(a) > 1e10:
        return None
    solution = np.linalg.lstsq(a, np.array(rhs), rcond=None)[0]
    return float(solution[2]), float(solution[3])


def along_across(error, u):
    """Squared components of `error` along and across the unit line of sight `u`."""
    along = error[0] * u[0] + error[1] * u[1]
    across = -error[0] * u[1] + error[1] * u[0]
    return along * along, across * across


def collect(data: Path, tracks: Path, mounts):
    """Every object's detections, and every scored tracker row as (class, object, detections of
    the object so far, whether the track began on the object's first detection and took all of
    them, squared tracker error along and across the line of sight)."""
    objects: dict[tuple, list[dict]] = defaultdict(list)
    rows = []
    for measurements in sorted(data.glob("*.csv")):
        with open(tracks / measurements.name, newline="") as handle:
            track_rows = {(r["frame"], r["track_id"]): r for r in csv.DictReader(handle)}
        with open(tracks / (measurements.stem + ".assoc"), newline="") as handle:
            taken = {(r["frame"], int(r["measurement"])): r for r in csv.DictReader(handle)}
        updates: dict[str, int] = defaultdict(int)
        for frame, index, key, cls, detection in detections_of(measurements, mounts):
            if detection is not None:
                objects[key].append(detection)
            association = taken.get((frame, index))
            if association is None or association["track_id"] == "":
                continue
            track_id = association["track_id"]
            updates[track_id] += 1
            track = track_rows.get((frame, track_id))
            if detection is None or track is None or association["prior_x"] == "" or "" in (track["vx"], track["vy"]):
                continue
            k = len(objects[key])
            error = (float(track["vx"]) - detection["v_vehicle"][0], float(track["vy"]) - detection["v_vehicle"][1])
            rows.append((cls, key, k, updates[track_id] == k, along_across(error, detection["u_vehicle"])))
    return objects, rows


def noise_of(objects, wanted: str, classes: dict) -> tuple[float, float]:
    """The class's position standard deviation per axis (m) and radial-velocity standard
    deviation (m/s), from the detections' own errors."""
    detections = [d for key, ds in objects.items() if classes.get(key) == wanted for d in ds]
    position = math.sqrt(sum(d["offset_m2"] for d in detections) / (2 * len(detections)))
    radial = math.sqrt(sum(d["vr_error"] ** 2 for d in detections) / len(detections))
    # Floors keep the weights finite on noiseless data.
    return max(position, 1e-3), max(radial, 1e-3)


def fitted_errors(history, position_std, radial_std):
    """Squared (along, across) errors of both fits after `history`; None where undetermined."""
    latest = history[-1]
    result = {}
    for name, with_radial in (("positions", False), ("positions_and_radial_velocities", True)):
        velocity = fit(history, position_std, radial_std, with_radial)
        result[name] = None if velocity is None else along_across(
            (velocity[0] - latest["v"][0], velocity[1] - latest["v"][1]), latest["u"])
    return result


def by_detections(rows, fits, wanted: str) -> list[dict]:
    """RMSE along and across the line of sight of the tracker and of both fits, per bucket of
    detections so far, over the `wanted` rows of tracks that began on the object's first
    detection and where both fits are determined."""
    names = ("tracker", "positions", "positions_and_radial_velocities")
    buckets = []
    for label, low, high in BUCKETS:
        sums = {name: [0, 0.0, 0.0] for name in names}
        for cls, key, k, from_first, errors in rows:
            fitted = fits.get((key, k)) if cls == wanted and from_first and low <= k <= high else None
            if not fitted or None in fitted.values():
                continue
            for name, (along, across) in zip(names, (errors, fitted["positions"], fitted["positions_and_radial_velocities"])):
                sums[name][0] += 1
                sums[name][1] += along
                sums[name][2] += across
        rmse = lambda total, n: math.sqrt(total / n) if n else float("nan")  # noqa: E731
        buckets.append({"detections": label, "rows": sums["tracker"][0], **{
            name: {"rmse_along_mps": rmse(a, n), "rmse_across_mps": rmse(c, n)} for name, (n, a, c) in sums.items()}})
    return buckets


def analyse(objects, rows, wanted: str, max_k: int, fit_from: int) -> dict:
    classes = {key: cls for cls, key, *_ in rows}
    position_std, radial_std = noise_of(objects, wanted, classes)
    fits = {}
    for key, detections in objects.items():
        if classes.get(key) != wanted:
            continue
        for k in range(2, min(max_k, len(detections)) + 1):
            fits[(key, k)] = fitted_errors(detections[:k], position_std, radial_std)
    buckets = by_detections(rows, fits, wanted)
    total = oracle = replaced = 0.0
    for cls, key, k, from_first, (along, across) in rows:
        fitted = fits.get((key, k)) if cls == wanted and from_first else None
        fitted = fitted and fitted["positions_and_radial_velocities"]
        total += along + across
        oracle += min(along + across, sum(fitted)) if fitted else along + across
        replaced += sum(fitted) if fitted and k >= fit_from else along + across
    return {
        "class": wanted,
        "position_std_m": position_std,
        "radial_velocity_std_mps": radial_std,
        "by_detections": buckets,
        "rows": len(rows),
        "tracker_rmse_mps": math.sqrt(total / len(rows)),
        "oracle_rmse_mps": math.sqrt(oracle / len(rows)),
        "fit_from_detections": fit_from,
        "replaced_rmse_mps": math.sqrt(replaced / len(rows)),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="directory of measurement CSV files")
    parser.add_argument("--tracks", type=Path, required=True, help="directory of NAME.csv and NAME.assoc from primm track")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "primm.toml", help="configuration with the sensor mounts")
    parser.add_argument("--class", dest="wanted", default="car", help="class whose objects are fitted")
    parser.add_argument("--max-k", type=int, default=20, help="fit after each of an object's first K detections")
    parser.add_argument("--fit-from", type=int, default=6, help="replace the tracker's velocity by the fit from this many detections on")
    parser.add_argument("--json", type=Path, help="also write the result as JSON")
    args = parser.parse_args(argv)
    for measurements in sorted(args.data.glob("*.csv")):
        if not (args.tracks / measurements.name).exists() or not (args.tracks / (measurements.stem + ".assoc")).exists():
            print(f"no track files for {measurements.name} in {args.tracks}", file=sys.stderr)
            return 2
    objects, rows = collect(args.data, args.tracks, sensor_mounts(args.config))
    if not rows or not any(cls == args.wanted for cls, *_ in rows):
        print(f"no scored {args.wanted} rows (no true velocities or ego poses, or no track took a measurement)", file=sys.stderr)
        return 1
    result = analyse(objects, rows, args.wanted, args.max_k, args.fit_from)
    print(f"{args.wanted}: detections' position error {result['position_std_m']:.3f} m per axis, "
          f"radial-velocity error {result['radial_velocity_std_mps']:.3f} m/s")
    print("detections  rows   RMSE along / across the line of sight (m/s): tracker | fit, positions | fit, positions + radial velocities")
    for b in result["by_detections"]:
        cells = " | ".join(f"{b[n]['rmse_along_mps']:6.3f} / {b[n]['rmse_across_mps']:6.3f}" for n in ("tracker", "positions", "positions_and_radial_velocities"))
        print(f"  {b['detections']:<8} {b['rows']:6d}   {cells}")
    change = 100 * (result["oracle_rmse_mps"] / result["tracker_rmse_mps"] - 1)
    print(f"all {result['rows']} rows, every class: tracker {result['tracker_rmse_mps']:.3f} m/s, "
          f"better of tracker and fit on each {args.wanted} row {result['oracle_rmse_mps']:.3f} m/s ({change:+.1f} %)")
    change = 100 * (result["replaced_rmse_mps"] / result["tracker_rmse_mps"] - 1)
    print(f"the fit in place of the tracker on {args.wanted} rows from {args.fit_from} to {args.max_k} detections: "
          f"{result['replaced_rmse_mps']:.3f} m/s ({change:+.1f} %)")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
