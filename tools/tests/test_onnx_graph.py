"""The PR graph writer (training/onnx_graph.py): both softmax forms compute the trained model.

The shipped model skips the row maximum in its softmax (its scores are bounded); a model whose
scores could overflow ``exp`` gets the ``ReduceMax`` form instead. Both must build as valid opset-17
graphs and match the NumPy reference forward pass and the PyTorch outputs of
``models/pr_parity.json``.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "training"))
onnx = pytest.importorskip("onnx")
onnxruntime = pytest.importorskip("onnxruntime")
import onnx_graph  # noqa: E402


@pytest.mark.parametrize("subtract_max", [False, True])
def test_both_softmax_forms_reproduce_the_trained_model(subtract_max, tmp_path):
    weights = onnx_graph.weights_from_onnx(str(ROOT / "models" / "pr.onnx"), heads=4)
    model = onnx_graph.build_graph(weights, 4, subtract_max=subtract_max)
    path = tmp_path / "pr.onnx"
    onnx.save(model, path)
    parity = json.loads((ROOT / "models" / "pr_parity.json").read_text())
    features = np.asarray(parity["features"], np.float32)
    valid = np.asarray(parity["valid"], np.float32)
    session = onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    output = session.run(None, {"features": features, "valid": valid})[0]
    reference = onnx_graph.reference_forward(weights, features, valid, heads=4)
    assert np.abs(output - reference).max() < 1e-5
    assert np.abs(output - np.asarray(parity["displacement"])).max() < 1e-5
    assert any(node.op_type == "ReduceMax" for node in model.graph.node) == subtract_max
