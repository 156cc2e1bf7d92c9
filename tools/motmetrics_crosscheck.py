#!/usr/bin/env python3
"""Independent cross-check of primm's identity metrics (IDSW, IDF1) with py-motmetrics 1.4.0.

The fixture ``tests/fixtures/identity_fixture.csv`` lists, per sequence and frame, which track
(if any) took the measurement of which ground-truth object (if any):

    sequence,frame,gt_id,track_id

An empty ``gt_id`` is a measurement without ground truth (a false track update); an empty
``track_id`` is a ground-truth object frame that no track took. Within one frame every gt_id and
every track_id occurs at most once.

For each sequence a ``motmetrics.MOTAccumulator`` is fed frame by frame with distance 0 for the
(gt, track) pair of each row and NaN for every other pair, so motmetrics can only match what the
rows say is matched. IDTP/IDFP/IDFN are summed over sequences before the global IDF1 is formed.

Besides the default accumulator (no limit on the time since an object was last seen), the script
runs one with ``max_switch_time = SWITCH_WINDOW_FRAMES``. That variant ignores a switch when the
object was absent for more than the window before re-appearing, which the paper's IDSW
definition does not; the Rust test checks the documented difference.

Usage:
    python3 tools/motmetrics_crosscheck.py              # compute, write the JSON next to the CSV
    python3 tools/motmetrics_crosscheck.py --regenerate # also rewrite the CSV from the generator
    python3 tools/motmetrics_crosscheck.py --check      # compute and compare with the stored JSON
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import random
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIXTURE = ROOT / "tests" / "fixtures" / "identity_fixture.csv"
RESULT = ROOT / "tests" / "fixtures" / "identity_fixture_motmetrics.json"

GENERATOR_SEED = 20240611
RANDOM_SEQUENCES = 4
SWITCH_WINDOW_FRAMES = 3


# --------------------------------------------------------------------------------------------
# Fixture generator
# --------------------------------------------------------------------------------------------

def handmade_sequence() -> list[tuple[int, int | None, int | None]]:
    """Rows (frame, gt, track) of a small sequence whose every event is spelled out.

    Object 1, frames 0..11:
      0-2 track 10; 3 missed; 4 track 10 again (gap, same track: no switch);
      5-6 track 11 (switch); 7 back to track 10 (switch: return to an older track);
      8-11 track 10.
    Object 2, frames 0..5 on track 20, absent 6..10, re-appears 11..13 on track 21
      (switch after a 6-frame absence: counted by the paper's rule, not by a 3-frame window).
    Object 3, frames 2..6 on track 30; object 4 takes over track 30 at frames 7..9
      (a track that jumps between objects; object 4's first match is no switch).
    Objects 5 and 6 swap tracks 50 and 60 at frame 4 (two switches in one frame).
    Track 90 updates on measurements without ground truth at frames 1..3 (false track frames).
    Object 7, frames 0..2, never tracked.
    """
    rows: list[tuple[int, int | None, int | None]] = []
    track_of_1 = {0: 10, 1: 10, 2: 10, 3: None, 4: 10, 5: 11, 6: 11, 7: 10, 8: 10, 9: 10, 10: 10, 11: 10}
    rows += [(f, 1, t) for f, t in track_of_1.items()]
    rows += [(f, 2, 20) for f in range(0, 6)] + [(f, 2, 21) for f in range(11, 14)]
    rows += [(f, 3, 30) for f in range(2, 7)] + [(f, 4, 30) for f in range(7, 10)]
    rows += [(f, 5, 50 if f < 4 else 60) for f in range(0, 8)]
    rows += [(f, 6, 60 if f < 4 else 50) for f in range(0, 8)]
    rows += [(f, None, 90) for f in range(1, 4)]
    rows += [(f, 7, None) for f in range(0, 3)]
    return rows


def random_sequence(rng: random.Random, frames: int) -> list[tuple[int, int | None, int | None]]:
    """A random sequence with misses, switches, returns, absences, swaps and false tracks."""
    next_track = 100

    def fresh() -> int:
        nonlocal next_track
        next_track += 1
        return next_track

    objects = []
    for gt in range(1, rng.randint(4, 7) + 1):
        start = rng.randint(0, frames // 3)
        end = rng.randint(start + 10, frames)
        absent = set()
        if rng.random() < 0.6:  # one absence of 2..8 frames
            gap_start = rng.randint(start + 3, max(start + 3, end - 3))
            absent = set(range(gap_start, gap_start + rng.randint(2, 8)))
        objects.append({"gt": gt, "start": start, "end": end, "absent": absent,
                        "track": fresh(), "older": [], "seen_gap": False})

    rows: list[tuple[int, int | None, int | None]] = []
    clutter_track = None
    for frame in range(frames):
        used: set[int] = set()
        present = [o for o in objects if o["start"] <= frame < o["end"] and frame not in o["absent"]]
        for o in objects:
            if frame in o["absent"]:
                o["seen_gap"] = True
        # Occasionally two present objects swap their tracks.
        if len(present) >= 2 and rng.random() < 0.03:
            a, b = rng.sample(present, 2)
            a["older"].append(a["track"])
            b["older"].append(b["track"])
            a["track"], b["track"] = b["track"], a["track"]
        for o in present:
            if o["seen_gap"]:
                o["seen_gap"] = False
                if rng.random() < 0.5:
                    o["older"].append(o["track"])
                    o["track"] = fresh()
            r = rng.random()
            if r < 0.04:
                o["older"].append(o["track"])
                o["track"] = fresh()
            elif r < 0.07 and o["older"]:
                previous = o["older"].pop()
                o["older"].append(o["track"])
                o["track"] = previous
            if o["track"] in used:
                o["older"].append(o["track"])
                o["track"] = fresh()
            if rng.random() < 0.08:
                rows.append((frame, o["gt"], None))
            else:
                used.add(o["track"])
                rows.append((frame, o["gt"], o["track"]))
        # A clutter track living for a few frames on measurements without ground truth.
        if clutter_track is None and rng.random() < 0.08:
            clutter_track = fresh()
        if clutter_track is not None:
            if clutter_track not in used:
                rows.append((frame, None, clutter_track))
            if rng.random() < 0.3:
                clutter_track = None
    return rows


def generate() -> list[tuple[str, int, int | None, int | None]]:
    rng = random.Random(GENERATOR_SEED)
    table = [("handmade", f, g, t) for f, g, t in handmade_sequence()]
    for index in range(RANDOM_SEQUENCES):
        frames = rng.randint(40, 80)
        table += [(f"random_{index}", f, g, t) for f, g, t in random_sequence(rng, frames)]
    table.sort(key=lambda row: (row[0], row[1], row[2] if row[2] is not None else -1,
                                row[3] if row[3] is not None else -1))
    return table


def write_fixture(table) -> None:
    FIXTURE.parent.mkdir(parents=True, exist_ok=True)
    with FIXTURE.open("w", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(["sequence", "frame", "gt_id", "track_id"])
        for sequence, frame, gt, track in table:
            writer.writerow([sequence, frame, "" if gt is None else gt, "" if track is None else track])


def read_fixture() -> dict[str, list[tuple[int, int | None, int | None]]]:
    sequences: dict[str, list[tuple[int, int | None, int | None]]] = {}
    with FIXTURE.open(newline="") as handle:
        for row in csv.DictReader(handle):
            gt = int(row["gt_id"]) if row["gt_id"] else None
            track = int(row["track_id"]) if row["track_id"] else None
            sequences.setdefault(row["sequence"], []).append((int(row["frame"]), gt, track))
    return sequences


# --------------------------------------------------------------------------------------------
# motmetrics evaluation
# --------------------------------------------------------------------------------------------

def accumulate(rows, max_switch_time: float):
    import motmetrics as mm
    import numpy as np

    accumulator = mm.MOTAccumulator(auto_id=False, max_switch_time=max_switch_time)
    frames: dict[int, list[tuple[int | None, int | None]]] = {}
    for frame, gt, track in rows:
        frames.setdefault(frame, []).append((gt, track))
    for frame in sorted(frames):
        entries = frames[frame]
        gts = [gt for gt, _ in entries if gt is not None]
        tracks = [track for _, track in entries if track is not None]
        if len(set(gts)) != len(gts) or len(set(tracks)) != len(tracks):
            raise ValueError(f"frame {frame}: an id occurs twice")
        distances = np.full((len(gts), len(tracks)), np.nan)
        for gt, track in entries:
            if gt is not None and track is not None:
                distances[gts.index(gt), tracks.index(track)] = 0.0
        accumulator.update(gts, tracks, distances, frameid=frame)
    return accumulator


METRICS = ["idf1", "num_switches", "idtp", "idfp", "idfn", "num_objects", "num_predictions"]


def evaluate(sequences) -> dict:
    import motmetrics as mm

    host = mm.metrics.create()
    names = sorted(sequences)
    accumulators = [accumulate(sequences[name], math.inf) for name in names]
    summary = host.compute_many(accumulators, metrics=METRICS, names=names, generate_overall=True)
    windowed = host.compute_many(
        [accumulate(sequences[name], SWITCH_WINDOW_FRAMES) for name in names],
        metrics=["num_switches"], names=names, generate_overall=True)

    per_sequence = {}
    totals = {"idtp": 0, "idfp": 0, "idfn": 0, "num_switches": 0, "num_switches_window": 0,
              "num_objects": 0, "num_predictions": 0}
    for name in names:
        row = summary.loc[name]
        entry = {
            "idtp": int(row["idtp"]),
            "idfp": int(row["idfp"]),
            "idfn": int(row["idfn"]),
            "idf1": float(row["idf1"]),
            "num_switches": int(row["num_switches"]),
            "num_switches_window": int(windowed.loc[name]["num_switches"]),
            "num_objects": int(row["num_objects"]),
            "num_predictions": int(row["num_predictions"]),
        }
        per_sequence[name] = entry
        for key in totals:
            totals[key] += entry[key]
    denominator = 2 * totals["idtp"] + totals["idfp"] + totals["idfn"]
    overall = dict(totals)
    overall["idf1"] = 2 * totals["idtp"] / denominator if denominator else None
    overall["idf1_motmetrics_overall"] = float(summary.loc["OVERALL"]["idf1"])
    overall["num_switches_motmetrics_overall"] = int(summary.loc["OVERALL"]["num_switches"])
    return {
        "motmetrics_version": mm.__version__,
        "generator_seed": GENERATOR_SEED,
        "switch_window_frames": SWITCH_WINDOW_FRAMES,
        "sequences": per_sequence,
        "overall": overall,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--regenerate", action="store_true", help="rewrite the CSV fixture from the generator")
    parser.add_argument("--check", action="store_true", help="compare with the stored JSON instead of writing it")
    args = parser.parse_args()

    if args.regenerate or not FIXTURE.exists():
        write_fixture(generate())
    result = evaluate(read_fixture())
    text = json.dumps(result, indent=2, sort_keys=True) + "\n"
    if args.check:
        stored = RESULT.read_text() if RESULT.exists() else ""
        if stored != text:
            print(f"{RESULT} differs from a fresh motmetrics run", file=sys.stderr)
            return 1
        print("motmetrics results match the stored JSON")
        return 0
    RESULT.write_text(text)
    overall = result["overall"]
    print(f"IDF1 {overall['idf1']:.6f}  IDTP {overall['idtp']}  IDFP {overall['idfp']}  "
          f"IDFN {overall['idfn']}  IDSW {overall['num_switches']} "
          f"(window {SWITCH_WINDOW_FRAMES}: {overall['num_switches_window']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
