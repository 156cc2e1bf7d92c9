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

Usage:
    python3 tools/measurement_floor.py --data out/evaluation/data/evaluation [--json FILE]
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
    if args.json:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
