#!/usr/bin/env python3
"""Writes the point-cloud cost scene of ARCHITECTURE.md ("Points or objects", "Cost."): 64 cars on
lanes 4 m apart in y (x along the lane, 8-12 m/s), seen from a sensor at the origin every 40 ms
for 200 frames, each with POINTS detections over its box (1: one detection at its centre). A
measurement CSV for `primm track --input` and `cargo bench --bench step_growth -- --sequence`.
With `clutter` or `spot` instead of POINTS, the 200 frames are bad input (ARCHITECTURE.md, "Bad
input"): 1,024 clutter points each, over 200 m x 200 m with any radial velocity, or 1,024
detections at one spot.

    python3 tools/point_cloud_lanes.py OUT.csv POINTS|clutter|spot
"""
import csv
import math
import random
import sys

HEADER = ["frame", "t", "gt_id", "class", "x", "y", "vr", "rcs", "true_x", "true_y", "sensor_id", "ego_x",
          "ego_y", "ego_yaw"]


def bad_frames(out: str, kind: str) -> None:
    """200 frames of 1,024 detections each: clutter, or all at one spot."""
    rng = random.Random(11)
    with open(out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HEADER)
        for k in range(200):
            t = 0.04 * k
            for i in range(1024):
                if kind == "clutter":
                    x, y, vr = rng.uniform(-100, 100), rng.uniform(-100, 100), rng.uniform(-15, 15)
                    cls = "pedestrian" if i % 3 == 0 else "car"
                else:
                    x, y, vr, cls = 40.0, -20.0, 0.0, "car"
                w.writerow([k, f"{t:.4f}", "", cls, f"{x:.3f}", f"{y:.3f}", f"{vr:.3f}", 10.0,
                            "", "", "", 0.0, 0.0, 0.0])


def main() -> None:
    out = sys.argv[1]
    if sys.argv[2] in ("clutter", "spot"):
        bad_frames(out, sys.argv[2])
        return
    points = int(sys.argv[2])
    rng = random.Random(7)
    cars = [(-60.0 + (i % 3) * 10.0, -126.0 + 4.0 * i, 8.0 + (i % 5)) for i in range(64)]
    with open(out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HEADER)
        for k in range(200):
            t = 0.04 * k
            for gid, (x0, y0, v) in enumerate(cars):
                cx, cy = x0 + v * t, y0
                for p in range(points):
                    if points == 1:
                        dx, dy = 0.0, 0.0
                    else:
                        dx = rng.uniform(-2.25, 2.25)
                        dy = rng.choice([-0.9, 0.9]) if p % 2 else rng.uniform(-0.9, 0.9)
                    x, y = cx + dx + rng.gauss(0, 0.1), cy + dy + rng.gauss(0, 0.1)
                    r = math.hypot(x, y)
                    vr = v * x / r + rng.gauss(0, 0.1)
                    w.writerow([k, f"{t:.4f}", gid + 1, "car", f"{x:.3f}", f"{y:.3f}", f"{vr:.3f}", 10.0,
                                f"{cx:.3f}", f"{cy:.3f}", "", 0.0, 0.0, 0.0])


if __name__ == "__main__":
    main()
