#!/usr/bin/env python3
"""How far a measurement lies from the object's true centre, split into what persists and what
does not: the room any one-step prior has on simulated data.

For every measurement with a true centre (measurement CSV files, ``docs/scenario.md``), the
offset ``e = z - centre`` (vehicle frame, m) is grouped by object and sensor: each radar sees an
object from its own side, so the reflections' centroid sits on that side. Per class and overall
the script prints, as root mean squares in metres:

* ``offset``: |e|, the measurement's whole error against the centre;
* ``persistent``: the mean offset of the measurement's (object, sensor) pair over the sequence,
  i.e. the part that stays while the pair is observed;
* ``per_scan``: e about that mean;
* ``scan_to_scan``: the change of e between consecutive measurements of the same object by the
  same sensor, divided by sqrt(2): the per-scan part if scans are independent and the persistent
  part drifts slowly.

Against the next measurement (``primm eval --truth measurement``) no prior can do better than
the per-scan part on average, even one that knows the true centre and each sensor's offset; the
two per-scan estimates bracket that floor. Against the centre (``--truth centre``), a filter whose
measurement model has no offset cannot tell the persistent part from the object's position.

With ``--motion`` it also splits each object's true motion from one measurement to its next (at
most 1 s later) along and across the line of sight of the first one (from the ego vehicle's
position to the measurement, world frame), and gives what is left along the line of sight after
the measured radial velocity times the interval: how much of the one-step motion the Doppler
measurement explains, and how much a predictor must get from positions.

Usage:
    python3 tools/measurement_floor.py --data out/evaluation/data/evaluation [--motion] [--json FILE]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from collections import defaultdict
from pathlib import Path


class Sums:
    """Sums of squares for one class (or all)."""

    def __init__(self) -> None:
        self.count = 0
        self.offset = 0.0
        self.persistent = 0.0
        self.per_scan = 0.0
        self.changes = 0
        self.change = 0.0

    def result(self) -> dict[str, float | int]:
        if self.count == 0:
            return {"measurements": 0}
        rms = lambda total, n: math.sqrt(total / n)  # noqa: E731
        return {
            "measurements": self.count,
            "offset_m": rms(self.offset, self.count),
            "persistent_m": rms(self.persistent, self.count),
            "per_scan_m": rms(self.per_scan, self.count),
            "scan_to_scan_m": rms(self.change, 2 * self.changes) if self.changes else float("nan"),
        }


def read_offsets(path: Path) -> dict[tuple[str, str, str], list[tuple[float, float]]]:
    """The offsets of one sequence, in file order, keyed by (object, sensor, class)."""
    groups: dict[tuple[str, str, str], list[tuple[float, float]]] = defaultdict(list)
    with path.open(newline="") as handle:
        for row in csv.DictReader(handle):
            if not row.get("gt_id") or not row.get("true_x") or not row.get("x"):
                continue
            offset = (float(row["x"]) - float(row["true_x"]), float(row["y"]) - float(row["true_y"]))
            groups[(row["gt_id"], row.get("sensor_id") or "", row["class"])].append(offset)
    return groups


def to_world(row: dict, x: float, y: float) -> tuple[float, float]:
    """A vehicle-frame point of ``row`` in the world frame of its ego pose (as is without one)."""
    if not row.get("ego_x"):
        return x, y
    yaw = float(row["ego_yaw"])
    c, s = math.cos(yaw), math.sin(yaw)
    return float(row["ego_x"]) + c * x - s * y, float(row["ego_y"]) + s * x + c * y


def motion_budget(files: list[Path], max_interval_s: float = 1.0) -> dict[str, dict[str, float | int]]:
    """Per class and overall: RMS of the true one-step motion along and across the line of sight,
    and of the part along it that the radial velocity times the interval leaves (m)."""
    sums: dict[str, list[float]] = defaultdict(lambda: [0, 0.0, 0.0, 0.0])
    for path in files:
        objects: dict[str, list[tuple]] = defaultdict(list)
        with path.open(newline="") as handle:
            for row in csv.DictReader(handle):
                if not row.get("gt_id") or not row.get("true_x") or not row.get("x"):
                    continue
                ego = (float(row["ego_x"]), float(row["ego_y"])) if row.get("ego_x") else (0.0, 0.0)
                measured = to_world(row, float(row["x"]), float(row["y"]))
                centre = to_world(row, float(row["true_x"]), float(row["true_y"]))
                objects[row["gt_id"]].append((float(row["t"]), measured, centre, ego, float(row["vr"]), row["class"]))
        for rows in objects.values():
            rows.sort(key=lambda r: r[0])
            for (t0, z0, c0, ego, vr, cls), (t1, _, c1, _, _, _) in zip(rows, rows[1:]):
                dt = t1 - t0
                sight = (z0[0] - ego[0], z0[1] - ego[1])
                norm = math.hypot(*sight)
                if not (0.0 < dt <= max_interval_s) or norm == 0.0:
                    continue
                u = (sight[0] / norm, sight[1] / norm)
                motion = (c1[0] - c0[0], c1[1] - c0[1])
                along = motion[0] * u[0] + motion[1] * u[1]
                across = -motion[0] * u[1] + motion[1] * u[0]
                for key in (cls, "all"):
                    s = sums[key]
                    s[0] += 1
                    s[1] += along * along
                    s[2] += across * across
                    s[3] += (along - vr * dt) ** 2
    result = {}
    for key in sorted(sums, key=lambda k: (k == "all", k)):
        n, along, across, left = sums[key]
        result[key] = {"steps": n, "along_sight_m": math.sqrt(along / n), "across_sight_m": math.sqrt(across / n),
                       "along_after_radial_velocity_m": math.sqrt(left / n)}
    return result


def decompose(files: list[Path]) -> dict[str, dict[str, float | int]]:
    """The decomposition per class and over all classes (key ``all``)."""
    sums: dict[str, Sums] = defaultdict(Sums)
    for path in files:
        for (_, _, cls), offsets in read_offsets(path).items():
            mean_x = sum(o[0] for o in offsets) / len(offsets)
            mean_y = sum(o[1] for o in offsets) / len(offsets)
            for key in (cls, "all"):
                s = sums[key]
                for index, (x, y) in enumerate(offsets):
                    s.count += 1
                    s.offset += x * x + y * y
                    s.persistent += mean_x * mean_x + mean_y * mean_y
                    s.per_scan += (x - mean_x) ** 2 + (y - mean_y) ** 2
                    if index > 0:
                        px, py = offsets[index - 1]
                        s.changes += 1
                        s.change += (x - px) ** 2 + (y - py) ** 2
    return {key: sums[key].result() for key in sorted(sums, key=lambda k: (k == "all", k))}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="directory of measurement CSV files")
    parser.add_argument("--motion", action="store_true", help="also split the one-step motion along the line of sight")
    parser.add_argument("--json", type=Path, help="also write the figures as JSON here")
    args = parser.parse_args(argv)
    files = sorted(args.data.glob("*.csv"))
    if not files:
        print(f"measurement_floor: no CSV files in {args.data}", file=sys.stderr)
        return 2
    result = decompose(files)
    if result.get("all", {}).get("measurements", 0) == 0:
        print(f"measurement_floor: no measurement in {args.data} has a true centre", file=sys.stderr)
        return 2
    print(f"{len(files)} files from {args.data}; RMS in m")
    print(f"{'class':<12}{'measurements':>13}{'offset':>9}{'persistent':>12}{'per_scan':>10}{'scan_to_scan':>14}")
    for key, r in result.items():
        print(
            f"{key:<12}{r['measurements']:>13,}{r['offset_m']:>9.3f}{r['persistent_m']:>12.3f}"
            f"{r['per_scan_m']:>10.3f}{r['scan_to_scan_m']:>14.3f}"
        )
    if args.motion:
        motion = motion_budget(files)
        print("one-step true motion, RMS in m")
        print(f"{'class':<12}{'steps':>9}{'along_sight':>13}{'across_sight':>14}{'along_after_vr_dt':>19}")
        for key, r in motion.items():
            print(f"{key:<12}{r['steps']:>9,}{r['along_sight_m']:>13.3f}{r['across_sight_m']:>14.3f}"
                  f"{r['along_after_radial_velocity_m']:>19.3f}")
        result = {"measurement": result, "motion": motion}
    if args.json:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
