#!/usr/bin/env python3
"""onnxruntime on models/pr.onnx, one thread, the batch sizes of benches/inference.rs.

Prints one JSON object {batch: median µs per run}. Inputs are the parity inputs of
models/pr_parity.json, repeated to fill the batch, as in the Rust bench.
Usage: inference_onnxruntime.py [MODEL]
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
import onnxruntime as ort

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    model = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "models" / "pr.onnx")
    parity = json.loads((ROOT / "models" / "pr_parity.json").read_text())
    features = np.array(parity["features"], dtype=np.float32)
    valid = np.array(parity["valid"], dtype=np.float32)
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    session = ort.InferenceSession(model, options, providers=["CPUExecutionProvider"])
    result = {"onnxruntime": ort.__version__}
    for batch in [1, 16, 64, 256]:
        index = np.arange(batch) % len(features)
        inputs = {"features": features[index], "valid": valid[index]}
        for _ in range(100):
            session.run(None, inputs)
        samples = []
        deadline = time.perf_counter() + 2.0
        while time.perf_counter() < deadline or len(samples) < 50:
            start = time.perf_counter_ns()
            session.run(None, inputs)
            samples.append(time.perf_counter_ns() - start)
        result[str(batch)] = float(np.median(samples)) / 1000.0
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
