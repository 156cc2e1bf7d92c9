#!/usr/bin/env python3
"""Alternative PR graphs for tract, to compare with the shipped form.

``batch-folded`` (the default): attention without per-sample matrix products. The shipped graph (``training/onnx_graph.py``) computes each sample's attention with small
batched products (``[28x32]@[32x7]`` and ``[28x7]@[7x32]`` per sample), which tract packs one by
one. This variant folds the batch into the products instead: keys and values are laid out key
first (``[7, B, d]``), repeated over the query rows with ``Expand``, multiplied element-wise with
the queries, and summed per head by one ``[7*B*Tq, d] @ [d, H]`` product; the softmax runs over the
leading key axis (``ReduceSum``), and the value mix is an element-wise product summed over that
axis.

``transposed-heads``: the textbook layout. Queries, keys and values reshaped to
``[B, T, H, d/H]`` and transposed to one ``[T, d/H]`` block per head, so the attention products
do a quarter of the shipped form's arithmetic (no zeroed channels), at the price of four
transposes per layer.

Same weights and function as the shipped model (parity printed against ``models/pr_parity.json``).

    python3 benches/pr_graph_variant.py /tmp/pr_batch_folded.onnx [batch-folded|transposed-heads]
    cargo bench --bench inference_profile -- /tmp/pr_batch_folded.onnx 64

Needs numpy, onnx and onnxruntime (``training/requirements.txt``). docs/BENCHMARKS.md section 1
has the results: both are slower in tract than the shipped form.
"""

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "training"))
import onnx  # noqa: E402
import onnx_graph as og  # noqa: E402

QUERIES, TOKENS = og.QUERIES, og.TOKENS


def build(weights, heads):
    """The batch-folded graph of the trained ``weights`` (same inputs and output as the shipped one)."""
    g = og.GraphBuilder(weights)
    w, d, node, const = g.w, g.d, g.node, g.const
    dh = d // heads
    scale = np.float32(1 / np.sqrt(dh))
    tokens = g.embedded_tokens()
    key_valid = node("Transpose", [g.key_valid_rows()], "key_valid_t", perm=[1, 0])  # [7, B]
    key_valid = node("Unsqueeze", [key_valid, const("axes_23", np.array([2, 3], np.int64))], "key_valid")  # [7, B, 1, 1]
    head_sum = np.zeros((d, heads), np.float32)  # channel -> its head
    for h in range(heads):
        head_sum[h * dh : (h + 1) * dh, h] = 1
    layers = og.layer_count(weights)
    for index in range(layers):
        p = f"layers.{index}"
        normed = g.layer_norm(tokens, f"{p}.norm_attention", f"{p}.normed")
        queries, tokens = g.query_rows(normed, tokens, p) if index == layers - 1 else (normed, tokens)
        q = g.linear(queries, f"{p}.attention.query", f"{p}.q", w[f"{p}.attention.query.weight"].T * scale, w[f"{p}.attention.query.bias"] * scale)  # [B, Tq, d]
        key_first = node("Transpose", [normed], f"{p}.normed_t", perm=[1, 0, 2])  # [7, B, d]
        k = g.linear(key_first, f"{p}.attention.key", f"{p}.k")
        v = g.linear(key_first, f"{p}.attention.value", f"{p}.v")
        k = node("Unsqueeze", [k, const(f"{p}.ax2", np.array([2], np.int64))], f"{p}.k4")  # [7, B, 1, d]
        v = node("Unsqueeze", [v, const(f"{p}.ax2v", np.array([2], np.int64))], f"{p}.v4")
        # Keys and values repeated once per query row: [7, B, Tq, d].
        shape = node("Shape", [q], f"{p}.qshape")  # [B, Tq, d]
        full = node("Concat", [const(f"{p}.seven", np.array([TOKENS], np.int64)), shape], f"{p}.repshape", axis=0)
        k = node("Expand", [k, full], f"{p}.k_rep")
        v = node("Expand", [v, full], f"{p}.v_rep")
        product = node("Mul", [k, q], f"{p}.qk")  # [7, B, Tq, d]
        scores = node("MatMul", [product, const(f"{p}.head_sum", head_sum)], f"{p}.scores")  # [7, B, Tq, H]
        e = node("Exp", [scores], f"{p}.exp")
        e = node("Mul", [e, key_valid], f"{p}.exp_masked")
        total = node("ReduceSum", [e, const(f"{p}.ax0", np.array([0], np.int64))], f"{p}.total", keepdims=1)
        attention = node("Div", [e, total], f"{p}.weights")
        attention = node("MatMul", [attention, const(f"{p}.head_expand", np.ascontiguousarray(head_sum.T))], f"{p}.weights_c")  # [7, B, Tq, d]
        mixed = node("Mul", [attention, v], f"{p}.weighted_values")
        mixed = node("ReduceSum", [mixed, const(f"{p}.ax0b", np.array([0], np.int64))], f"{p}.mixed4", keepdims=0)  # [B, Tq, d]
        tokens = g.feed_forward(tokens, g.linear(mixed, f"{p}.attention.output", f"{p}.attended"), p)
    return g.model(tokens)


def build_transposed_heads(weights, heads):
    """The textbook multi-head layout: one ``[T, d/H]`` block per head, reached by transposes."""
    g = og.GraphBuilder(og.fold_normalisations(weights))
    w, d, node, const = g.w, g.d, g.node, g.const
    dh = d // heads
    scale = 1.0 / np.sqrt(dh)
    tokens = g.embedded_tokens()
    axes = const("axes_12", np.array([1, 2], np.int64))
    key_valid = node("Unsqueeze", [g.key_valid_rows(), axes], "key_valid")  # [B, 1, 1, 7]
    ones = const("ones_7x7", np.ones((TOKENS, TOKENS), np.float32))
    layers = og.layer_count(weights)
    for index in range(layers):
        p = f"layers.{index}"
        normed = g.layer_norm(tokens, f"{p}.norm_attention", f"{p}.normed")
        queries, tokens = g.query_rows(normed, tokens, p) if index == layers - 1 else (normed, tokens)
        q = g.linear(queries, f"{p}.attention.query", f"{p}.q", w[f"{p}.attention.query.weight"].T * scale, w[f"{p}.attention.query.bias"] * scale)
        head_shape = const(f"{p}.head_shape", np.array([0, -1, heads, dh], np.int64))  # [B, T, H, d/H]
        q = node("Transpose", [node("Reshape", [q, head_shape], f"{p}.q4")], f"{p}.qh", perm=[0, 2, 1, 3])
        k = g.linear(normed, f"{p}.attention.key", f"{p}.k")
        k = node("Transpose", [node("Reshape", [k, head_shape], f"{p}.k4")], f"{p}.kh", perm=[0, 2, 3, 1])
        v = g.linear(normed, f"{p}.attention.value", f"{p}.v")
        v = node("Transpose", [node("Reshape", [v, head_shape], f"{p}.v4")], f"{p}.vh", perm=[0, 2, 1, 3])
        e = node("Mul", [node("Exp", [node("MatMul", [q, k], f"{p}.scores")], f"{p}.exp"), key_valid], f"{p}.exp_masked")
        attention = node("Div", [e, node("MatMul", [e, ones], f"{p}.row_sums")], f"{p}.weights")
        mixed = node("Transpose", [node("MatMul", [attention, v], f"{p}.mixed")], f"{p}.mixed_t", perm=[0, 2, 1, 3])
        mixed = node("Reshape", [mixed, const(f"{p}.mixed_shape", np.array([0, -1, d], np.int64))], f"{p}.mixed_tokens")
        tokens = g.feed_forward(tokens, g.linear(mixed, f"{p}.attention.output", f"{p}.attended"), p)
    return g.model(tokens)


def main() -> int:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/tmp/pr_batch_folded.onnx")
    form = sys.argv[2] if len(sys.argv) > 2 else "batch-folded"
    builders = {"batch-folded": build, "transposed-heads": build_transposed_heads}
    if form not in builders:
        raise SystemExit(f"unknown form {form!r}: one of {', '.join(builders)}")
    weights = og.weights_from_onnx(str(ROOT / "models" / "pr.onnx"), 4)
    model = builders[form](weights, 4)
    onnx.save(model, out)
    parity = json.loads((ROOT / "models" / "pr_parity.json").read_text())
    import onnxruntime as ort

    session = ort.InferenceSession(str(out), providers=["CPUExecutionProvider"])
    inputs = {"features": np.array(parity["features"], np.float32), "valid": np.array(parity["valid"], np.float32)}
    result = session.run(None, inputs)[0]
    difference = float(np.abs(result - np.array(parity["displacement"])).max())
    print(f"wrote {out}: {len(model.graph.node)} ONNX nodes, parity against PyTorch {difference:.1e} m")
    return 0 if difference < 1e-4 else 1


if __name__ == "__main__":
    sys.exit(main())
