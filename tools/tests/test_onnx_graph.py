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
    output, cholesky = session.run(None, {"features": features, "valid": valid})
    reference, reference_cholesky = onnx_graph.reference_forward(weights, features, valid, heads=4)
    assert np.abs(output - reference).max() < 1e-5
    assert np.abs(output - np.asarray(parity["displacement"])).max() < 1e-5
    # The uncertainty output: the same factors, with a positive diagonal.
    assert np.abs(cholesky - reference_cholesky).max() < 1e-5
    assert np.abs(cholesky - np.asarray(parity["cholesky"])).max() < 1e-5
    assert (cholesky[:, 0] > 0).all() and (cholesky[:, 2] > 0).all()
    assert any(node.op_type == "ReduceMax" for node in model.graph.node) == subtract_max


def test_folding_the_normalisations_keeps_the_function_and_is_idempotent():
    weights = onnx_graph.weights_from_onnx(str(ROOT / "models" / "pr.onnx"), heads=4)
    rng = np.random.default_rng(11)
    # Give every normalisation a scale and shift of its own, as a freshly trained model has.
    for name in [k for k in weights if k.endswith("norm_attention.weight") or k.endswith("norm_ff.weight")] + ["final_norm.weight"]:
        weights[name] = rng.uniform(0.5, 1.5, weights[name].shape).astype(np.float32)
        bias = name[: -len("weight")] + "bias"
        weights[bias] = rng.normal(0.0, 0.2, weights[bias].shape).astype(np.float32)
    weights["feature_mean"] = rng.normal(0.0, 2.0, weights["feature_mean"].shape).astype(np.float32)
    weights["feature_inv_std"] = rng.uniform(0.2, 2.0, weights["feature_inv_std"].shape).astype(np.float32)
    folded = onnx_graph.fold_normalisations(weights)
    parity = json.loads((ROOT / "models" / "pr_parity.json").read_text())
    features = np.asarray(parity["features"], np.float32)
    valid = np.asarray(parity["valid"], np.float32)
    before = onnx_graph.reference_forward(weights, features, valid, heads=4)
    after = onnx_graph.reference_forward(folded, features, valid, heads=4)
    for output_before, output_after in zip(before, after):
        assert np.abs(output_before - output_after).max() < 1e-9 * max(1.0, np.abs(output_before).max())
        assert np.abs(output_before).max() > 0.0
    twice = onnx_graph.fold_normalisations(folded)
    assert all(np.array_equal(twice[k], folded[k]) for k in folded)
    assert not any(node.op_type == "Sub" for node in onnx_graph.build_graph(weights, 4).graph.node)


def test_the_shipped_model_rebuilds_byte_for_byte():
    path = ROOT / "models" / "pr.onnx"
    weights = onnx_graph.weights_from_onnx(str(path), heads=4)
    metadata = json.loads((ROOT / "models" / "pr.json").read_text())
    subtract_max = bool(metadata.get("format", {}).get("softmax_subtracts_row_max", False))
    shipped = onnx.load(str(path))
    input_frame = onnx_graph.input_frame_of(shipped)
    assert input_frame == metadata["inputs"][0]["input_frame"] == "line_of_sight"
    model = onnx_graph.build_graph(weights, 4, subtract_max=subtract_max, input_frame=input_frame)
    assert model.SerializeToString() == path.read_bytes()
    # Without the entry the bytes differ, and the model reads as one of the latest motion.
    plain = onnx_graph.build_graph(weights, 4, subtract_max=subtract_max)
    assert plain.SerializeToString() != path.read_bytes()
    assert onnx_graph.input_frame_of(plain) is None
