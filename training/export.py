#!/usr/bin/env python3
"""Re-exports a trained PR model in the graph form of ``onnx_graph.py``, without retraining.

    python3 training/export.py [--from models/pr.onnx] [--out models/pr.onnx] [--heads 4]

Reads the weights back from the ONNX file (either graph form), writes the new graph, and checks
it three ways before anything is overwritten: the NumPy reference forward pass and onnxruntime on
the new file against the PyTorch outputs of ``models/pr_parity.json`` (at most 1e-5 m; the
displacement and, for a model with the uncertainty head, its Cholesky factor), and the new file
against the old one on the same inputs (every output). Then updates ``model_sha256`` and the format
notes in ``models/pr.json``. Needs numpy and onnx (onnxruntime for the runtime checks).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import onnx_graph  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TOLERANCE_M = 1e-5


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--from", dest="source", type=Path, default=ROOT / "models" / "pr.onnx")
    parser.add_argument("--out", type=Path, default=ROOT / "models" / "pr.onnx")
    parser.add_argument("--heads", type=int, default=4)
    parser.add_argument("--parity", type=Path, default=ROOT / "models" / "pr_parity.json")
    parser.add_argument("--metadata", type=Path, default=ROOT / "models" / "pr.json")
    args = parser.parse_args()

    import onnx

    weights = onnx_graph.weights_from_onnx(str(args.source), args.heads)
    parity = json.loads(args.parity.read_text())
    features = np.asarray(parity["features"], np.float32)
    valid = np.asarray(parity["valid"], np.float32)
    expected = np.asarray(parity["displacement"], np.float64)
    reference, reference_cholesky = onnx_graph.reference_forward(weights, features, valid, args.heads)
    difference = float(np.abs(reference - expected).max())
    if reference_cholesky is not None:
        if "cholesky" not in parity:
            raise SystemExit(f"{args.parity} has no cholesky outputs for this model's uncertainty head")
        expected_cholesky = np.asarray(parity["cholesky"], np.float64)
        difference = max(difference, float(np.abs(reference_cholesky - expected_cholesky).max()))
    print(f"weights read from {args.source}: reference forward vs PyTorch {difference:.2e} m")
    if difference > TOLERANCE_M:
        raise SystemExit("the weights read back do not reproduce the PyTorch outputs")
    metadata = json.loads(args.metadata.read_text()) if args.metadata.exists() else {}
    subtract_max = bool(metadata.get("format", {}).get("softmax_subtracts_row_max", False))
    input_frame = onnx_graph.input_frame_of(onnx.load(str(args.source)))
    model = onnx_graph.build_graph(weights, args.heads, subtract_max=subtract_max, input_frame=input_frame)
    with tempfile.TemporaryDirectory() as scratch:
        candidate = Path(scratch) / "pr.onnx"
        onnx.save(model, candidate)
        try:
            import onnxruntime
        except ImportError:
            onnxruntime = None
            print("onnxruntime not installed: runtime checks skipped")
        if onnxruntime is not None:
            def run(path):
                session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
                return session.run(None, {"features": features, "valid": valid})

            new = run(candidate)
            old = run(args.source)
            if len(new) != len(old):
                raise SystemExit("the new graph has different outputs")
            to_torch = float(np.abs(new[0] - expected).max())
            if len(new) > 1:
                to_torch = max(to_torch, float(np.abs(new[1] - expected_cholesky).max()))
            to_old = max(float(np.abs(a - b).max()) for a, b in zip(new, old))
            print(f"onnxruntime, new graph vs PyTorch: {to_torch:.2e} m; new vs old graph: {to_old:.2e} m")
            if to_torch > TOLERANCE_M or to_old > TOLERANCE_M:
                raise SystemExit("the new graph does not compute the same function")
        data = candidate.read_bytes()
    args.out.write_bytes(data)
    print(f"wrote {args.out} ({len(data)} bytes, {len(model.graph.node)} nodes)")
    if metadata:
        metadata["model_sha256"] = hashlib.sha256(data).hexdigest()
        metadata.setdefault("format", {})["exporter"] = onnx_graph.EXPORTER
        metadata["format"]["graph"] = onnx_graph.GRAPH_DESCRIPTION
        args.metadata.write_text(json.dumps(metadata, indent=2) + "\n")
        print(f"updated {args.metadata}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
