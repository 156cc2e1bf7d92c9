#!/usr/bin/env python3
"""Where a tracker's velocity error comes from: by class, by track age, along and across the line
of sight.

For every measurement row with a true velocity that a track took (the rows ``primm eval``
scores as "Table II, velocity", ``docs/evaluation-metrics.md``), the error ``e = v - v_true`` of
the track's fused velocity after that update is split into its component along the line of
sight (from the measuring radar's mount to the object's true centre, vehicle frame) and across
it, and its squared length is summed per group:

* per class (``car``, ``pedestrian``, ...);
* per track age: how many updates the track had before this one (1, 2, 3, 4-5, 6-10, 11-20, >20;
  0 is the track's first row, which has no prior and is not scored);
* the share of the total squared error the worst 1 %, 5 % and 10 % of rows hold.

Each group reports its rows, its share of the squared error, and the RMSE overall, along and
across the line of sight (m/s).

Input: the measurement CSV files (``primm generate``) and, per file, the track CSV and the
association CSV that ``primm track --output DIR/NAME.csv --associations DIR/NAME.assoc`` writes.
Sensor mounts come from the configuration's ``[[frame.sensors]]`` (default: config/primm.toml).

Usage:
    for f in DATA/*.csv; do n=$(basename $f .csv)
        primm track --input $f --output TRACKS/$n.csv --associations TRACKS/$n.assoc --method imm
    done
    python3 tools/velocity_breakdown.py --data DATA --tracks TRACKS [--config FILE] [--json FILE]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
AGE_BUCKETS = [("1", 1, 1), ("2", 2, 2), ("3", 3, 3), ("4-5", 4, 5), ("6-10", 6, 10), ("11-20", 11, 20), (">20", 21, None)]


def sensor_mounts(config: Path) -> dict[int, tuple[float, float]]:
    """Sensor id -> mount position (x, y) in the vehicle frame, m."""
    with open(config, "rb") as handle:
        sensors = tomllib.load(handle).get("frame", {}).get("sensors", [])
    return {int(s["id"]): (float(s["x_m"]), float(s["y_m"])) for s in sensors}


def rows_of(measurements: Path, tracks: Path, associations: Path, mounts: dict[int, tuple[float, float]]):
    """(class, age, e_along, e_across) of every scored row of one sequence."""
    with open(tracks, newline="") as handle:
        track_rows = {(row["frame"], row["track_id"]): row for row in csv.DictReader(handle)}
    with open(associations, newline="") as handle:
        taken = {(row["frame"], int(row["measurement"])): row for row in csv.DictReader(handle)}
    updates: dict[str, int] = {}
    index_in_frame: dict[str, int] = {}
    with open(measurements, newline="") as handle:
        for row in csv.DictReader(handle):
            frame = row["frame"]
            index = index_in_frame.get(frame, 0)
            index_in_frame[frame] = index + 1
            association = taken.get((frame, index))
            if association is None or association["track_id"] == "":
                continue
            track_id = association["track_id"]
            age = updates.get(track_id, 0)
            updates[track_id] = age + 1
            track = track_rows.get((frame, track_id))
            scored = track is not None and association["prior_x"] != "" and row["gt_id"] != ""
            if not scored or "" in (row.get("true_vx", ""), row.get("true_vy", ""), track["vx"], track["vy"]):
                continue
            mount = mounts.get(int(row["sensor_id"]), (0.0, 0.0)) if row.get("sensor_id") else (0.0, 0.0)
            los_x, los_y = float(row["true_x"]) - mount[0], float(row["true_y"]) - mount[1]
            length = math.hypot(los_x, los_y)
            if length == 0.0:
                continue
            ux, uy = los_x / length, los_y / length
            ex, ey = float(track["vx"]) - float(row["true_vx"]), float(track["vy"]) - float(row["true_vy"])
            yield row["class"], age, ex * ux + ey * uy, -ex * uy + ey * ux


def summarise(rows: list[tuple[str, int, float, float]]) -> dict:
    """The groups of the module documentation."""
    total = sum(a * a + c * c for _, _, a, c in rows)

    def group(selected):
        n = len(selected)
        along = sum(a * a for _, _, a, _ in selected)
        across = sum(c * c for _, _, _, c in selected)
        return {
            "rows": n,
            "share": (along + across) / total if total > 0 else float("nan"),
            "rmse_mps": math.sqrt((along + across) / n) if n else float("nan"),
            "rmse_along_mps": math.sqrt(along / n) if n else float("nan"),
            "rmse_across_mps": math.sqrt(across / n) if n else float("nan"),
        }

    classes = sorted({r[0] for r in rows})
    ages = {label: group([r for r in rows if r[1] >= low and (high is None or r[1] <= high)]) for label, low, high in AGE_BUCKETS}
    squared = sorted((a * a + c * c for _, _, a, c in rows), reverse=True)
    top = {f"{int(p * 100)}%": (sum(squared[: int(p * len(squared))]) / total if total > 0 else float("nan")) for p in (0.01, 0.05, 0.10)}
    return {
        "all": group(rows),
        "by_class": {name: group([r for r in rows if r[0] == name]) for name in classes},
        "by_age": ages,
        "by_class_and_age": {
            name: {label: group([r for r in rows if r[0] == name and r[1] >= low and (high is None or r[1] <= high)]) for label, low, high in AGE_BUCKETS}
            for name in classes
        },
        "worst_rows_share": top,
    }


def table(title: str, groups: dict[str, dict]) -> str:
    lines = [f"{title}:", "  group      rows   share   RMSE  along  across (m/s)"]
    for name, g in groups.items():
        lines.append(f"  {name:<8} {g['rows']:6d} {100 * g['share']:6.1f}% {g['rmse_mps']:6.3f} {g['rmse_along_mps']:6.3f} {g['rmse_across_mps']:6.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, required=True, help="directory of measurement CSV files")
    parser.add_argument("--tracks", type=Path, required=True, help="directory of NAME.csv and NAME.assoc from primm track")
    parser.add_argument("--config", type=Path, default=ROOT / "config" / "primm.toml", help="configuration with the sensor mounts")
    parser.add_argument("--json", type=Path, help="also write the groups as JSON")
    args = parser.parse_args(argv)
    mounts = sensor_mounts(args.config)
    rows = []
    for measurements in sorted(args.data.glob("*.csv")):
        tracks, associations = args.tracks / measurements.name, args.tracks / (measurements.stem + ".assoc")
        if not (tracks.exists() and associations.exists()):
            print(f"no track files for {measurements.name} in {args.tracks}", file=sys.stderr)
            return 2
        rows.extend(rows_of(measurements, tracks, associations, mounts))
    if not rows:
        print("no scored rows (no true velocities, or no track took a measurement)", file=sys.stderr)
        return 1
    result = summarise(rows)
    print(table("all", {"all": result["all"]}))
    print(table("by class", result["by_class"]))
    print(table("by updates before the row", result["by_age"]))
    for name, groups in result["by_class_and_age"].items():
        print(table(f"{name}, by updates before the row", groups))
    print("worst rows' share of the squared error: " + ", ".join(f"{k} {100 * v:.1f}%" for k, v in result["worst_rows_share"].items()))
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
