#!/usr/bin/env bash
# tract (primm's runtime) against onnxruntime on the same ONNX file, one thread each, measured
# one after the other in one run. Writes benches/results/pr_inference_compare.md.
#   benches/inference_compare.sh
set -euo pipefail
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1
if [ ! -x .venv-peers/bin/python ]; then
    python3 -m venv .venv-peers
fi
.venv-peers/bin/python -m pip install --quiet -r benches/peers/requirements.txt
cargo bench --bench inference -- --warm-up-time 1 --measurement-time 4 pr_model > /dev/null
ort=$(.venv-peers/bin/python benches/inference_onnxruntime.py)
.venv-peers/bin/python - "$ort" <<'PY' | tee benches/results/pr_inference_compare.md
import json, sys, datetime
from pathlib import Path
ort = json.loads(sys.argv[1])
print("# PR model inference: tract against onnxruntime\n")
print(f"{datetime.date.today()}, `benches/inference_compare.sh`, one thread each, models/pr.onnx, "
      f"tract 0.23 (criterion median of `cargo bench --bench inference`), onnxruntime {ort['onnxruntime']} (median).\n")
print("| batch | tract µs/run | tract µs/sample | onnxruntime µs/run | onnxruntime µs/sample | tract / onnxruntime |")
print("|---|---|---|---|---|---|")
for batch in [1, 16, 64, 256]:
    estimates = json.loads(Path(f"target/criterion/pr_model/{batch}/new/estimates.json").read_text())
    tract = estimates["median"]["point_estimate"] / 1000.0
    o = ort[str(batch)]
    print(f"| {batch} | {tract:.1f} | {tract / batch:.2f} | {o:.1f} | {o / batch:.2f} | {tract / o:.2f} |")
PY
