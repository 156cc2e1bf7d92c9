#!/usr/bin/env python3
"""An alternative PR graph for tract: attention without per-sample matrix products.

The shipped graph (``training/onnx_graph.py``) computes each sample's attention with small
batched products (``[28x32]@[32x7]`` and ``[28x7]@[7x32]`` per sample), which tract packs one by
one. This variant folds the batch into the products instead: keys and values are laid out key
first (``[7, B, d]``), repeated over the query rows with ``Expand``, multiplied element-wise with
the queries, and summed per head by one ``[7*B*Tq, d] @ [d, H]`` product; the softmax runs over the
leading key axis (``ReduceSum``), and the value mix is an element-wise product summed over that
axis. Same weights, same function (parity printed against ``models/pr_parity.json``).

    python3 benches/pr_graph_variant.py /tmp/pr_batch_folded.onnx
    cargo bench --bench inference_profile -- /tmp/pr_batch_folded.onnx 64

Needs numpy, onnx and onnxruntime (``training/requirements.txt``). BENCHMARKS.md section 1
has the result: slower in tract, because its broadcasting element-wise operators cost far more
per element than the products they replace.
"""

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "training"))
import onnx  # noqa: E402
import onnx_graph as og  # noqa: E402
from onnx import TensorProto, helper, numpy_helper  # noqa: E402

MAXH, F, Q, T = og.MAX_HISTORY, og.FEATURES, og.QUERIES, og.TOKENS


def build(weights, heads):
    w = {k: np.asarray(v, np.float32) for k, v in weights.items()}
    d = w["token_table"].shape[1]; dh = d // heads
    scale = np.float32(1 / np.sqrt(dh))
    nodes, inits = [], []
    def const(name, value):
        inits.append(numpy_helper.from_array(np.asarray(value), name)); return name
    def node(op, inputs, name, **a):
        nodes.append(helper.make_node(op, inputs, [name], name=name, **a)); return name
    def ln(x, p, out):
        return node("LayerNormalization", [x, const(p+".weight", w[p+".weight"]), const(p+".bias", w[p+".bias"])], out, axis=-1, epsilon=1e-5)
    def linear(x, p, out, weight=None, bias=None):
        weight = w[p+".weight"].T if weight is None else weight
        bias = w[p+".bias"] if bias is None else bias
        pr = node("MatMul", [x, const(p+".weight_t", np.ascontiguousarray(weight))], out+"_product")
        return node("Add", [pr, const(p+".bias_row", np.asarray(bias, np.float32))], out)
    x = node("Sub", ["features", const("feature_mean", w["feature_mean"])], "centred")
    x = node("Mul", [x, const("feature_inv_std", w["feature_inv_std"])], "normalised")
    x = node("Pad", [x, const("token_pad", np.array([0,0,0,0,Q,0], np.int64))], "padded")
    x = node("MatMul", [x, const("embedding.weight_t", np.ascontiguousarray(w["embedding.weight"].T))], "embedded")
    tokens = node("Add", [x, const("token_table", w["token_table"])], "tokens_0")
    kv = node("Pad", ["valid", const("key_pad", np.array([0,0,0,Q], np.int64)), const("one", np.float32(1))], "key_valid_rows")
    kv = node("Transpose", [kv], "key_valid_t", perm=[1,0])  # [7,B]
    kv = node("Unsqueeze", [kv, const("axes_23", np.array([2,3], np.int64))], "key_valid")  # [7,B,1,1]
    head_sum = np.zeros((d, heads), np.float32)
    for h in range(heads): head_sum[h*dh:(h+1)*dh, h] = 1
    L = og.layer_count(weights)
    for i in range(L):
        p = f"layers.{i}"; last = i == L-1; tq = Q if last else T
        normed = ln(tokens, f"{p}.norm_attention", f"{p}.normed")
        if last:
            s, e, ax = const(f"{p}.qs", np.array([MAXH], np.int64)), const(f"{p}.qe", np.array([T], np.int64)), const(f"{p}.qa", np.array([1], np.int64))
            queries = node("Slice", [normed, s, e, ax], f"{p}.query_rows")
            tokens = node("Slice", [tokens, s, e, ax], f"{p}.query_tokens")
        else:
            queries = normed
        q = linear(queries, f"{p}.attention.query", f"{p}.q", w[f"{p}.attention.query.weight"].T*scale, w[f"{p}.attention.query.bias"]*scale)  # [B,tq,d]
        nt = node("Transpose", [normed], f"{p}.normed_t", perm=[1,0,2])  # [7,B,d]
        k = linear(nt, f"{p}.attention.key", f"{p}.k")  # [7,B,d]
        v = linear(nt, f"{p}.attention.value", f"{p}.v")
        k = node("Unsqueeze", [k, const(f"{p}.ax2", np.array([2], np.int64))], f"{p}.k4")  # [7,B,1,d]
        v = node("Unsqueeze", [v, const(f"{p}.ax2v", np.array([2], np.int64))], f"{p}.v4")
        # Keys and values repeated once per query row: [7, B, Tq, d].
        shape = node("Shape", [q], f"{p}.qshape")  # [B, Tq, d]
        full = node("Concat", [const(f"{p}.seven", np.array([T], np.int64)), shape], f"{p}.repshape", axis=0)
        k = node("Expand", [k, full], f"{p}.k_rep")
        v = node("Expand", [v, full], f"{p}.v_rep")
        prod = node("Mul", [k, q], f"{p}.qk")  # [7,B,tq,d]
        scores = node("MatMul", [prod, const(f"{p}.head_sum", head_sum)], f"{p}.scores")  # [7,B,tq,H]
        ex = node("Exp", [scores], f"{p}.exp")
        ex = node("Mul", [ex, kv], f"{p}.exp_masked")
        tot = node("ReduceSum", [ex, const(f"{p}.ax0", np.array([0], np.int64))], f"{p}.total", keepdims=1)
        att = node("Div", [ex, tot], f"{p}.weights")
        att = node("MatMul", [att, const(f"{p}.head_expand", np.ascontiguousarray(head_sum.T))], f"{p}.weights_c")  # [7,B,tq,d]
        mixed = node("Mul", [att, v], f"{p}.weighted_values")
        mixed = node("ReduceSum", [mixed, const(f"{p}.ax0b", np.array([0], np.int64))], f"{p}.mixed4", keepdims=0)  # [B,tq,d]
        attended = linear(mixed, f"{p}.attention.output", f"{p}.attended")
        tokens = node("Add", [tokens, attended], f"{p}.residual_attention")
        hidden = linear(ln(tokens, f"{p}.norm_ff", f"{p}.normed_ff"), f"{p}.ff_in", f"{p}.ff_hidden")
        hidden = node("Relu", [hidden], f"{p}.ff_relu")
        tokens = node("Add", [tokens, linear(hidden, f"{p}.ff_out", f"{p}.ff_output")], f"{p}.residual_ff")
    out = ln(tokens, "final_norm", "final_normed")
    out = node("Reshape", [out, const("flat_shape", np.array([-1, Q*d], np.int64))], "flat")
    head = np.zeros((Q*d, 2), np.float32); head[:d,0] = w["head_x.weight"][0]; head[d:,1] = w["head_y.weight"][0]
    bias = np.array([w["head_x.bias"][0], w["head_y.bias"][0]], np.float32)
    out = linear(out, "head", "head_output", head, bias)
    node("Mul", [out, const("output_scale", w["output_scale"])], "displacement")
    g = helper.make_graph(nodes, "pr", [helper.make_tensor_value_info("features", TensorProto.FLOAT, ["batch", MAXH, F]), helper.make_tensor_value_info("valid", TensorProto.FLOAT, ["batch", MAXH])], [helper.make_tensor_value_info("displacement", TensorProto.FLOAT, ["batch", 2])], inits)
    m = helper.make_model(g, opset_imports=[helper.make_opsetid("", 17)]); m.ir_version = 8
    onnx.checker.check_model(m, full_check=True)
    return m


def main() -> int:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/tmp/pr_batch_folded.onnx")
    weights = og.weights_from_onnx(str(ROOT / "models" / "pr.onnx"), 4)
    model = build(weights, 4)
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
