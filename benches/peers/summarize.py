#!/usr/bin/env python3
"""Table of benches/peers/run.sh: throughput from the step-time files, accuracy from primm score."""

import datetime
import importlib.metadata
import json
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np

ROWS = [
    ("primm cv", "cv"),
    ("primm imm (CV+CA+CT)", "imm"),
    ("primm pr-imm (CV+CA+CT+PR)", "pr-imm"),
    ("filterpy IMM (CV+CA) + scipy", "filterpy"),
    ("Stone Soup KF (CV) + GNN", "stonesoup"),
]


def main() -> int:
    out = Path(sys.argv[1])
    sequences = sys.argv[2]
    steps = {key: np.loadtxt(out / f"{key}.steps", dtype=float, ndmin=1) for _, key in ROWS}
    scores = {key: json.loads((out / f"{key}.score.json").read_text()) for _, key in ROWS}
    reference = steps["imm"].sum() / len(steps["imm"])
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")), platform.processor())
    print(f"# primm against Python trackers\n")
    print(f"Measured {datetime.date.today()} on {cpu}, {len(Path('/proc/cpuinfo').read_text().split('processor')) - 1} cores, "
          f"Python {platform.python_version()}, "
          + ", ".join(f"{name} {importlib.metadata.version(name)}" for name in ["numpy", "scipy", "filterpy", "stonesoup"])
          + f"; {sequences} sequences of the evaluation split ({len(steps['imm'])} frames).\n")
    print("Command: `benches/peers/run.sh`. Step times cover the per-frame tracking loop (prediction, association,")
    print("update, track lifecycle) of one thread, file I/O excluded; accuracy is `primm score` on each tracker's")
    print("association files (the metrics of `primm eval`).\n")
    print("| tracker | frames/s | step p50 µs | step p99 µs | mean step vs primm imm | prior RMSE_xy m | IDSW | IDF1 |")
    print("|---|---|---|---|---|---|---|---|")
    for name, key in ROWS:
        s = steps[key] / 1000.0
        score = scores[key]
        mean = steps[key].sum() / len(steps[key])
        print(
            f"| {name} | {len(s) / (s.sum() * 1e-6):,.0f} | {np.percentile(s, 50):.1f} | {np.percentile(s, 99):.1f} | "
            f"{mean / reference:.1f}x | {score['rmse_xy_m']:.3f} | {score['idsw']} | {score['idf1']:.4f} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
