#!/usr/bin/env python3
"""Summarise detection-level measurement files: detections per object and scan, ghosts and
clutter per scan, the largest frame and the share of wrong class labels.

    point_cloud_summary.py DIR_OR_FILE [...]

Reads measurement CSV files (docs/scenario.md) and prints, over all of them:

* detections per detected car and per detected pedestrian and scan (mean and the 5th, 50th
  and 95th percentiles), over (frame, gt_id) pairs; an object's class is the majority of its
  detections' labels over its file, since single labels may be wrong;
* ghost and clutter detections per scan (rows whose ``origin`` is ``ghost`` or ``clutter``;
  without the column, rows with ``gt_id`` -1 count as clutter);
* the largest number of detections in one frame;
* the share of object detections whose label differs from their object's class.
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import Counter, defaultdict
from pathlib import Path


def files_of(paths: list[Path]) -> list[Path]:
    """The CSV files named, or directly inside the directories named, in sorted order."""
    found = []
    for path in paths:
        found.extend(sorted(path.glob("*.csv")) if path.is_dir() else [path])
    return found


def percentile(values: list[int], fraction: float) -> float:
    """The nearest-rank percentile of `values` (not empty)."""
    ordered = sorted(values)
    return float(ordered[min(len(ordered) - 1, max(0, round(fraction * (len(ordered) - 1))))])


def summarise(files: list[Path]) -> dict:
    """The statistics of the measurement files `files`."""
    per_object: dict[str, list[int]] = defaultdict(list)
    frames = ghosts = clutter = largest = labels = wrong = 0
    for path in files:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(line for line in handle if not line.startswith("#")))
        frame_sizes: Counter = Counter()
        object_rows: dict[tuple[str, str], list[str]] = defaultdict(list)
        for row in rows:
            frame_sizes[row["frame"]] += 0
            if not row["class"]:
                continue
            frame_sizes[row["frame"]] += 1
            origin = row.get("origin") or ""
            gt = row["gt_id"]
            if origin == "ghost":
                ghosts += 1
            elif origin == "clutter" or (not origin and gt in ("", "-1")):
                clutter += 1
            elif gt not in ("", "-1"):
                object_rows[(row["frame"], gt)].append(row["class"])
        frames += len(frame_sizes)
        largest = max([largest, *frame_sizes.values()])
        votes: dict[str, Counter] = defaultdict(Counter)
        for (_, gt), classes in object_rows.items():
            votes[gt].update(classes)
        majority = {gt: counter.most_common(1)[0][0] for gt, counter in votes.items()}
        for (_, gt), classes in object_rows.items():
            per_object[majority[gt]].append(len(classes))
            labels += len(classes)
            wrong += sum(label != majority[gt] for label in classes)
    summary = {
        "files": len(files), "frames": frames, "largest_frame": largest,
        "ghosts_per_scan": ghosts / frames if frames else 0.0,
        "clutter_per_scan": clutter / frames if frames else 0.0,
        "wrong_label_share": wrong / labels if labels else 0.0,
    }
    for name, counts in sorted(per_object.items()):
        summary[name] = {
            "object_scans": len(counts), "mean": sum(counts) / len(counts),
            "p5": percentile(counts, 0.05), "p50": percentile(counts, 0.5),
            "p95": percentile(counts, 0.95),
        }
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("paths", type=Path, nargs="+", help="measurement CSV files or directories")
    args = parser.parse_args(argv)
    files = files_of(args.paths)
    if not files:
        print("error: no measurement CSV file found", file=sys.stderr)
        return 1
    try:
        s = summarise(files)
    except (OSError, KeyError, ValueError, csv.Error) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"{s['files']} files, {s['frames']} frames")
    print("| class | object scans | detections per scan: mean | p5 | p50 | p95 |")
    print("|---|---|---|---|---|---|")
    for name in ("car", "pedestrian", "two_wheeler"):
        if name in s:
            c = s[name]
            print(f"| {name} | {c['object_scans']} | {c['mean']:.2f} | {c['p5']:.0f} | {c['p50']:.0f} | {c['p95']:.0f} |")
    print(f"ghost detections per scan: {s['ghosts_per_scan']:.2f}")
    print(f"clutter detections per scan: {s['clutter_per_scan']:.2f}")
    print(f"largest frame: {s['largest_frame']} detections")
    print(f"wrong class labels: {100 * s['wrong_label_share']:.1f} % of object detections")
    return 0


if __name__ == "__main__":
    sys.exit(main())
