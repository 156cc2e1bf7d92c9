"""The PR model's ONNX graph, written node by node for tract (primm's runtime).

``build_graph`` takes the trained weights (the ``PRModel`` state dict as NumPy arrays) and writes
the same function as :class:`model.PRModel` in the operator forms tract executes fastest, measured
with ``cargo bench --bench inference_profile`` (``benches/results/pr_inference_compare.md``):

* **Heads without transposes.** Head ``h``'s queries are the full-width query vector with the
  other heads' channels zeroed (query weights masked per head and stacked side by side), so one
  product ``[B, Tq, d] @ [d, H*d]`` gives every head's query, and a *reshape* (no transpose) to
  ``[B, Tq*H, d]`` puts one (token, head) pair per row. Scores, softmax and the value mix then
  run on all heads at once, and the reshape back to ``[B, Tq, H*d]`` feeds an output projection
  whose per-head blocks (each head's input channels kept) sum the heads.
* **Key mask after the exponential.** ``exp(scores) * key_valid`` with ``key_valid`` ``[B, 1, 7]``
  (1 for valid history rows and the two query tokens, 0 for padding): masked keys get weight
  exactly 0, as the additive -1e9 mask of the trained model gives, without an extra key
  channel (which tract split into a second product and an add).
* **Softmax** as ``e / (e @ ones[7, 7])``: one element-wise ``Exp``, one ``MatMul`` for the row
  sums (already broadcast to every column), one ``Div``. No row maximum is subtracted while the
  weight-derived score bound (``model.score_bound``) stays below ``SCORE_BOUND_WITHOUT_MAX``;
  above it the graph subtracts each row's maximum.
* **Normalisations folded into weights** (``fold_normalisations``): each LayerNorm's scale and
  shift move into the linear layers that read it (queries, keys and values; the first
  feed-forward layer; the two output heads), and the input normalisation moves into the
  embedding and the token table. The graph's LayerNorms (``LayerNormalization``, opset 17) only
  normalise, which tract plans without the element-wise scale and shift, and the inputs go
  straight into the embedding product.
* Embedding, feed-forward blocks, residuals and the two heads as in the trained model; the last
  layer computes only the two query tokens.
* **Uncertainty output** ``displacement_cholesky`` ``[batch, 3]`` (models trained with the
  uncertainty head, ``head_cholesky.*``): ``[l_xx, l_yx, l_yy]`` of the lower-triangular Cholesky
  factor of the displacement error covariance, metres. A linear layer on both query outputs gives
  raw values ``r``; the graph computes ``softplus(r)`` in the overflow-free form
  ``max(r, 0) + log(1 + exp(-|r|))`` (``Relu``, ``Abs``, ``Neg``, ``Exp``, ``Add``, ``Log``, ``Add``:
  ONNX's ``Softplus`` is ``log(exp(r) + 1)``, which tract also computes literally and which
  overflows for ``r > 88``), then ``softplus(r) * [s_x, 0, s_y] + r * [0, s_y, 0] + [floor, 0,
  floor]``, so ``l_xx, l_yy >= floor > 0`` for any input. A model without that head gets the
  displacement output only.

``weights_from_onnx`` reads the weights back from an exported file of either graph form (from
this one, in their folded but equivalent form), so a model can be re-exported without
retraining; ``reference_forward`` is the plain NumPy forward pass of the trained model (the
check for both).
"""

from __future__ import annotations

import numpy as np

MAX_HISTORY = 5
FEATURES = 5
QUERIES = 2
TOKENS = MAX_HISTORY + QUERIES
OPSET = 17
SCORE_BOUND_WITHOUT_MAX = 60.0
EXPORTER = "training/onnx_graph.py build_graph (onnx.helper, node by node)"
GRAPH_DESCRIPTION = (
    "heads as reshaped rows of one product (no transposes), key mask multiplied after exp, "
    "softmax as exp / (exp @ ones), LayerNorm affines and input normalisation folded into the "
    "following linear layers; see training/onnx_graph.py"
)
INPUT_NAMES = ["features", "valid"]
OUTPUT_NAMES = ["displacement", "displacement_cholesky"]
# [l_xx, l_yx, l_yy]: which of the Cholesky factor's elements go through the softplus.
CHOLESKY_DIAGONAL = np.array([1.0, 0.0, 1.0])


def has_cholesky(weights: dict) -> bool:
    """Whether the weights include the uncertainty head (``displacement_cholesky``)."""
    return "head_cholesky.weight" in weights


def layer_count(weights: dict) -> int:
    return len({key.split(".")[1] for key in weights if key.startswith("layers.")})


def fold_normalisations(weights: dict) -> dict:
    """The same function with fewer element-wise steps: every LayerNorm's scale ``g`` and shift
    ``b`` folded into the linear layers that read the normalised tokens (``W x + c`` of
    ``g * n + b`` is ``(W * g) n + (W b + c)``), and the input normalisation ``(x - mean) *
    inv_std`` folded into the embedding and the history rows of the token table (the two query
    rows are zero after normalisation, so theirs stay). In float64, and idempotent: folding
    folded weights changes nothing."""
    w = {k: np.asarray(v, np.float64).copy() for k, v in weights.items()}

    def fold(norm, readers):
        scale, shift = w[norm + ".weight"], w[norm + ".bias"]
        for reader in readers:
            matrix = w[reader + ".weight"]  # [out, in]
            w[reader + ".bias"] = w[reader + ".bias"] + matrix @ shift
            w[reader + ".weight"] = matrix * scale[None, :]
        w[norm + ".weight"], w[norm + ".bias"] = np.ones_like(scale), np.zeros_like(shift)

    for index in range(layer_count(weights)):
        p = f"layers.{index}"
        fold(f"{p}.norm_attention", [f"{p}.attention.query", f"{p}.attention.key", f"{p}.attention.value"])
        fold(f"{p}.norm_ff", [f"{p}.ff_in"])
    if has_cholesky(weights):
        # The uncertainty head reads both query tokens' normalised outputs side by side ([2d]).
        scale, shift = np.tile(w["final_norm.weight"], QUERIES), np.tile(w["final_norm.bias"], QUERIES)
        matrix = w["head_cholesky.weight"]  # [3, 2d]
        w["head_cholesky.bias"] = w["head_cholesky.bias"] + matrix @ shift
        w["head_cholesky.weight"] = matrix * scale[None, :]
    fold("final_norm", ["head_x", "head_y"])
    mean, inv_std = w["feature_mean"], w["feature_inv_std"]
    embedding = w["embedding.weight"]  # [d, features]
    w["token_table"][:MAX_HISTORY] -= embedding @ (mean * inv_std)
    w["embedding.weight"] = embedding * inv_std[None, :]
    w["feature_mean"], w["feature_inv_std"] = np.zeros_like(mean), np.ones_like(inv_std)
    return w


def softplus(x: np.ndarray) -> np.ndarray:
    """``log(1 + exp(x))`` without overflow, as the graph computes it."""
    return np.maximum(x, 0.0) + np.log1p(np.exp(-np.abs(x)))


def reference_forward(weights: dict, features: np.ndarray, valid: np.ndarray, heads: int):
    """The trained model's forward pass in float64 NumPy (``model.PRModel.forward``):
    ``(displacement [B, 2], displacement_cholesky [B, 3])``, the second ``None`` for weights
    without the uncertainty head."""
    w = {k: np.asarray(v, np.float64) for k, v in weights.items()}
    x = (features.astype(np.float64) - w["feature_mean"]) * w["feature_inv_std"]
    x = np.concatenate([x, np.zeros((x.shape[0], QUERIES, FEATURES))], axis=1)
    tokens = x @ w["embedding.weight"].T + w["token_table"]
    key_valid = np.concatenate([valid, np.ones((valid.shape[0], QUERIES))], axis=1)
    key_bias = (key_valid - 1.0)[:, None, None, :] * 1e9

    def layer_norm(v, name):
        mean = v.mean(-1, keepdims=True)
        var = ((v - mean) ** 2).mean(-1, keepdims=True)
        return (v - mean) / np.sqrt(var + 1e-5) * w[name + ".weight"] + w[name + ".bias"]

    def linear(v, name):
        return v @ w[name + ".weight"].T + w[name + ".bias"]

    layers = layer_count(weights)
    for index in range(layers):
        p = f"layers.{index}."
        normed = layer_norm(tokens, p + "norm_attention")
        queries = normed[:, MAX_HISTORY:] if index == layers - 1 else normed
        if index == layers - 1:
            tokens = tokens[:, MAX_HISTORY:]
        d = normed.shape[-1]
        dh = d // heads
        tq = queries.shape[1]
        q = linear(queries, p + "attention.query").reshape(-1, tq, heads, dh).transpose(0, 2, 1, 3)
        k = linear(normed, p + "attention.key").reshape(-1, TOKENS, heads, dh).transpose(0, 2, 3, 1)
        v = linear(normed, p + "attention.value").reshape(-1, TOKENS, heads, dh).transpose(0, 2, 1, 3)
        scores = q @ k / np.sqrt(dh) + key_bias
        scores = scores - scores.max(-1, keepdims=True)
        e = np.exp(scores)
        mixed = (e / e.sum(-1, keepdims=True)) @ v
        mixed = mixed.transpose(0, 2, 1, 3).reshape(-1, tq, d)
        tokens = tokens + linear(mixed, p + "attention.output")
        hidden = np.maximum(linear(layer_norm(tokens, p + "norm_ff"), p + "ff_in"), 0.0)
        tokens = tokens + linear(hidden, p + "ff_out")
    out = layer_norm(tokens, "final_norm").reshape(-1, QUERIES * tokens.shape[-1])
    d = tokens.shape[-1]
    head = np.zeros((2 * d, 2))
    head[:d, 0] = w["head_x.weight"][0]
    head[d:, 1] = w["head_y.weight"][0]
    bias = np.array([w["head_x.bias"][0], w["head_y.bias"][0]])
    displacement = (out @ head + bias) * w["output_scale"]
    if not has_cholesky(weights):
        return displacement, None
    raw = out @ w["head_cholesky.weight"].T + w["head_cholesky.bias"]
    return displacement, cholesky_from_raw(w, raw)


def cholesky_scale(w: dict) -> np.ndarray:
    """Per-element scale of ``[l_xx, l_yx, l_yy]``: the label RMS of x, y, y."""
    scale = np.asarray(w["output_scale"], np.float64)
    return np.array([scale[0], scale[1], scale[1]])


def cholesky_from_raw(w: dict, raw: np.ndarray) -> np.ndarray:
    """``[l_xx, l_yx, l_yy]`` from the head's raw values (``model.PRModel.forward``)."""
    scale = cholesky_scale(w)
    floor = np.asarray(w["cholesky_floor"], np.float64)
    return softplus(raw) * (scale * CHOLESKY_DIAGONAL) + raw * (scale * (1.0 - CHOLESKY_DIAGONAL)) + floor


class GraphBuilder:
    """Nodes and initializers of a PR graph under construction, plus the parts every graph form
    shares: input normalisation and embedding, LayerNorm, linear layers, the feed-forward half of
    an encoder layer, the output heads and the finished, checked model."""

    def __init__(self, weights: dict):
        # float64 while the graph is built; initializers are written as float32 (``const``).
        self.w = {k: np.asarray(v, np.float64) for k, v in weights.items()}
        self.d = self.w["token_table"].shape[1]
        self.nodes, self.initializers = [], []

    def const(self, name, value):
        from onnx import numpy_helper

        value = np.asarray(value)
        if value.dtype == np.float64:
            value = value.astype(np.float32)
        self.initializers.append(numpy_helper.from_array(value, name))
        return name

    def node(self, op, inputs, name, **attributes):
        from onnx import helper

        self.nodes.append(helper.make_node(op, inputs, [name], name=name, **attributes))
        return name

    def layer_norm(self, x, prefix, out):
        w = self.w
        return self.node("LayerNormalization", [x, self.const(prefix + ".weight", w[prefix + ".weight"]), self.const(prefix + ".bias", w[prefix + ".bias"])], out, axis=-1, epsilon=1e-5)

    def linear(self, x, prefix, out, weight=None, bias=None):
        weight = self.w[prefix + ".weight"].T if weight is None else weight
        bias = self.w[prefix + ".bias"] if bias is None else bias
        product = self.node("MatMul", [x, self.const(prefix + ".weight_t", np.ascontiguousarray(weight))], out + "_product")
        return self.node("Add", [product, self.const(prefix + ".bias_row", bias)], out)

    def embedded_tokens(self):
        """Normalisation (none once folded), two zero query rows, embedding plus the token
        table: ``[B, 7, d]``."""
        w, node, const = self.w, self.node, self.const
        x = "features"
        if np.any(w["feature_mean"] != 0.0) or np.any(w["feature_inv_std"] != 1.0):
            x = node("Sub", [x, const("feature_mean", w["feature_mean"])], "centred")
            x = node("Mul", [x, const("feature_inv_std", w["feature_inv_std"])], "normalised")
        x = node("Pad", [x, const("token_pad", np.array([0, 0, 0, 0, QUERIES, 0], np.int64))], "padded")
        x = node("MatMul", [x, const("embedding.weight_t", np.ascontiguousarray(w["embedding.weight"].T))], "embedded")
        return node("Add", [x, const("token_table", w["token_table"])], "tokens_0")

    def key_valid_rows(self):
        """1 for valid history rows and the two queries, 0 for padding: ``[B, 7]``."""
        return self.node("Pad", ["valid", self.const("key_pad", np.array([0, 0, 0, QUERIES], np.int64)), self.const("one", np.float32(1.0))], "key_valid_rows")

    def query_rows(self, normed, tokens, p):
        """The last layer's two query rows of ``normed`` and ``tokens`` (axis 1)."""
        starts, ends, axes = (self.const(f"{p}.q_start", np.array([MAX_HISTORY], np.int64)), self.const(f"{p}.q_end", np.array([TOKENS], np.int64)), self.const(f"{p}.q_axis", np.array([1], np.int64)))
        queries = self.node("Slice", [normed, starts, ends, axes], f"{p}.query_rows")
        return queries, self.node("Slice", [tokens, starts, ends, axes], f"{p}.query_tokens")

    def feed_forward(self, tokens, attended, p):
        """The attention residual, then LayerNorm, feed-forward block and its residual."""
        node, linear = self.node, self.linear
        tokens = node("Add", [tokens, attended], f"{p}.residual_attention")
        hidden = linear(self.layer_norm(tokens, f"{p}.norm_ff", f"{p}.normed_ff"), f"{p}.ff_in", f"{p}.ff_hidden")
        hidden = node("Relu", [hidden], f"{p}.ff_relu")
        return node("Add", [tokens, linear(hidden, f"{p}.ff_out", f"{p}.ff_output")], f"{p}.residual_ff")

    def model(self, tokens, doc: str = ""):
        """Final LayerNorm, the two heads, the output scale; the checked opset-17 model with a
        symbolic batch axis ``batch``."""
        import onnx
        from onnx import TensorProto, helper

        w, d = self.w, self.d
        out = self.layer_norm(tokens, "final_norm", "final_normed")
        out = self.node("Reshape", [out, self.const("flat_shape", np.array([-1, QUERIES * d], np.int64))], "flat")
        head = np.zeros((QUERIES * d, 2), np.float32)
        head[:d, 0] = w["head_x.weight"][0]
        head[d:, 1] = w["head_y.weight"][0]
        bias = np.array([w["head_x.bias"][0], w["head_y.bias"][0]], np.float32)
        flat = out
        out = self.linear(out, "head", "head_output", head, bias)
        self.node("Mul", [out, self.const("output_scale", w["output_scale"])], "displacement")
        batch = "batch"
        outputs = [helper.make_tensor_value_info("displacement", TensorProto.FLOAT, [batch, 2])]
        if has_cholesky(w):
            self.cholesky(flat)
            outputs.append(helper.make_tensor_value_info("displacement_cholesky", TensorProto.FLOAT, [batch, 3]))
        graph = helper.make_graph(
            self.nodes,
            "pr",
            [
                helper.make_tensor_value_info("features", TensorProto.FLOAT, [batch, MAX_HISTORY, FEATURES]),
                helper.make_tensor_value_info("valid", TensorProto.FLOAT, [batch, MAX_HISTORY]),
            ],
            outputs,
            self.initializers,
        )
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="primm training/onnx_graph.py", doc_string=doc)
        model.ir_version = 8
        onnx.checker.check_model(model, full_check=True)
        return model


    def cholesky(self, flat):
        """``displacement_cholesky`` from the flattened, normalised query outputs ``[B, 2d]``:
        the uncertainty head's raw values ``r``, a softplus that cannot overflow, and
        ``softplus(r) * diag_scale + r * off_scale + floor``."""
        w, node, const = self.w, self.node, self.const
        raw = self.linear(flat, "head_cholesky", "cholesky_raw")
        positive = node("Relu", [raw], "cholesky_raw_positive")
        magnitude = node("Abs", [raw], "cholesky_raw_abs")
        negative = node("Neg", [magnitude], "cholesky_raw_minus_abs")
        small = node("Exp", [negative], "cholesky_exp")
        small = node("Add", [small, const("cholesky_one", np.float32(1.0))], "cholesky_one_plus_exp")
        small = node("Log", [small], "cholesky_log")
        soft = node("Add", [positive, small], "cholesky_softplus")
        scale = cholesky_scale(w)
        soft = node("Mul", [soft, const("cholesky_diagonal_scale", scale * CHOLESKY_DIAGONAL)], "cholesky_diagonal")
        off = node("Mul", [raw, const("cholesky_off_diagonal_scale", scale * (1.0 - CHOLESKY_DIAGONAL))], "cholesky_off_diagonal")
        total = node("Add", [soft, off], "cholesky_unfloored")
        return node("Add", [total, const("cholesky_floor", w["cholesky_floor"])], "displacement_cholesky")


# The ONNX metadata entry that names the model's input axes (primm-predictor's InputFrame):
# "line_of_sight" or "latest_motion"; a file without it was trained in "latest_motion".
INPUT_FRAME_KEY = "primm.input_frame"


def input_frame_of(model) -> str | None:
    """The input axes an ONNX model declares in its metadata, ``None`` if it declares none."""
    for entry in model.metadata_props:
        if entry.key == INPUT_FRAME_KEY:
            return entry.value
    return None


def build_graph(weights: dict, heads: int, subtract_max: bool = False, doc: str = "", input_frame: str | None = None):
    """The ONNX model (opset 17, symbolic batch axis ``batch``) of the trained ``weights``; with
    ``input_frame``, the metadata entry ``INPUT_FRAME_KEY`` names the model's input axes."""
    g = GraphBuilder(fold_normalisations(weights))
    w, d, node, const = g.w, g.d, g.node, g.const
    dh = d // heads
    scale = 1.0 / np.sqrt(dh)

    tokens = g.embedded_tokens()
    # Key weights: [B, 1, 7].
    key_valid = node("Unsqueeze", [g.key_valid_rows(), const("axis_1", np.array([1], np.int64))], "key_valid")
    ones = const("ones_7x7", np.ones((TOKENS, TOKENS), np.float32))
    head_mask = np.zeros((heads, d), np.float32)
    for h in range(heads):
        head_mask[h, h * dh : (h + 1) * dh] = 1.0

    layers = layer_count(weights)
    for index in range(layers):
        p = f"layers.{index}"
        last = index == layers - 1
        tq = QUERIES if last else TOKENS
        normed = g.layer_norm(tokens, f"{p}.norm_attention", f"{p}.normed")
        queries, tokens = g.query_rows(normed, tokens, p) if last else (normed, tokens)
        wq = w[f"{p}.attention.query.weight"].T * scale  # [d_in, d_out]
        bq = w[f"{p}.attention.query.bias"] * scale
        stacked_w = np.concatenate([wq * head_mask[h][None, :] for h in range(heads)], axis=1)  # [d, H*d]
        stacked_b = np.concatenate([bq * head_mask[h] for h in range(heads)])
        q = g.linear(queries, f"{p}.attention.query_heads", f"{p}.q", stacked_w, stacked_b)
        q = node("Reshape", [q, const(f"{p}.q_shape", np.array([-1, tq * heads, d], np.int64))], f"{p}.q_rows")
        k = g.linear(normed, f"{p}.attention.key", f"{p}.k")
        k = node("Transpose", [k], f"{p}.k_t", perm=[0, 2, 1])
        v = g.linear(normed, f"{p}.attention.value", f"{p}.v")
        scores = node("MatMul", [q, k], f"{p}.scores")
        if subtract_max:
            # Opset 17's ReduceMax takes its axes as an attribute (an input only from opset 18).
            peak = node("ReduceMax", [scores], f"{p}.peak", axes=[-1], keepdims=1)
            scores = node("Sub", [scores, peak], f"{p}.shifted")
        e = node("Exp", [scores], f"{p}.exp")
        e = node("Mul", [e, key_valid], f"{p}.exp_masked")
        total = node("MatMul", [e, ones], f"{p}.row_sums")
        attention = node("Div", [e, total], f"{p}.weights")
        mixed = node("MatMul", [attention, v], f"{p}.mixed")
        mixed = node("Reshape", [mixed, const(f"{p}.mixed_shape", np.array([-1, tq, heads * d], np.int64))], f"{p}.mixed_heads")
        wo = w[f"{p}.attention.output.weight"].T  # [d_in, d_out]
        stacked_o = np.concatenate([wo * head_mask[h][:, None] for h in range(heads)], axis=0)  # [H*d, d]
        attended = g.linear(mixed, f"{p}.attention.output", f"{p}.attended", stacked_o, w[f"{p}.attention.output.bias"])
        tokens = g.feed_forward(tokens, attended, p)
    model = g.model(tokens, doc)
    if input_frame is not None:
        import onnx
        from onnx import helper

        helper.set_model_props(model, {INPUT_FRAME_KEY: input_frame})
        onnx.checker.check_model(model, full_check=True)
    return model


def weights_from_onnx(path: str, heads: int) -> dict:
    """The trained weights (``PRModel`` state-dict names, NumPy) from an exported PR model: this
    module's graph, or the earlier ``ExportGraph`` export of ``torch.onnx.export``."""
    import onnx
    from onnx import numpy_helper

    model = onnx.load(path)
    init = {i.name: numpy_helper.to_array(i) for i in model.graph.initializer}
    if "embedding.weight_t" in init:
        return _weights_from_this_graph(init, heads)
    return _weights_from_torch_export(model, init, heads)


def _weights_from_this_graph(init: dict, heads: int) -> dict:
    w = {name: init[name] for name in ["output_scale", "token_table", "final_norm.weight", "final_norm.bias"]}
    # A graph with the input normalisation folded into the embedding has no normalisation nodes.
    features = init["embedding.weight_t"].shape[0]
    w["feature_mean"] = init.get("feature_mean", np.zeros(features, np.float32))
    w["feature_inv_std"] = init.get("feature_inv_std", np.ones(features, np.float32))
    w["embedding.weight"] = init["embedding.weight_t"].T
    d = w["token_table"].shape[1]
    dh = d // heads
    scale = 1.0 / np.sqrt(dh)
    index = 0
    while f"layers.{index}.norm_attention.weight" in init:
        p = f"layers.{index}"
        for name in ["norm_attention", "norm_ff"]:
            w[f"{p}.{name}.weight"], w[f"{p}.{name}.bias"] = init[f"{p}.{name}.weight"], init[f"{p}.{name}.bias"]
        for name in ["attention.key", "attention.value", "ff_in", "ff_out"]:
            w[f"{p}.{name}.weight"], w[f"{p}.{name}.bias"] = init[f"{p}.{name}.weight_t"].T, init[f"{p}.{name}.bias_row"]
        stacked = init[f"{p}.attention.query_heads.weight_t"]  # [d, H*d], head h's block keeps its channels
        stacked_b = init[f"{p}.attention.query_heads.bias_row"]
        # In float64, so that writing the graph again (times the scale, rounded to float32)
        # gives back the same float32 values.
        stacked, stacked_b = stacked.astype(np.float64), stacked_b.astype(np.float64)
        w[f"{p}.attention.query.weight"] = (sum(stacked[:, h * d : (h + 1) * d] for h in range(heads)) / scale).T
        w[f"{p}.attention.query.bias"] = sum(stacked_b[h * d : (h + 1) * d] for h in range(heads)) / scale
        stacked_o = init[f"{p}.attention.output.weight_t"]  # [H*d, d]
        w[f"{p}.attention.output.weight"] = sum(stacked_o[h * d : (h + 1) * d] for h in range(heads)).T
        w[f"{p}.attention.output.bias"] = init[f"{p}.attention.output.bias_row"]
        index += 1
    head = init["head.weight_t"]
    w["head_x.weight"], w["head_y.weight"] = head[:d, 0][None, :], head[d:, 1][None, :]
    w["head_x.bias"], w["head_y.bias"] = init["head.bias_row"][:1], init["head.bias_row"][1:]
    if "head_cholesky.weight_t" in init:
        w["head_cholesky.weight"] = init["head_cholesky.weight_t"].T
        w["head_cholesky.bias"] = init["head_cholesky.bias_row"]
        w["cholesky_floor"] = init["cholesky_floor"]
        # cholesky_scale is rebuilt from output_scale; a file whose constants disagree is not
        # this graph form.
        stored = init["cholesky_diagonal_scale"] + init["cholesky_off_diagonal_scale"]
        if not np.allclose(stored, cholesky_scale(w), rtol=1e-6):
            raise ValueError("displacement_cholesky scale does not match output_scale")
    return w


def _weights_from_torch_export(model, init: dict, heads: int) -> dict:
    """``torch.onnx.export`` of ``ExportGraph`` keeps the LayerNorm and bias parameters under
    their state-dict names and folds the other matrices into anonymous constants; they are
    recovered from the MatMul / Mul nodes that consume them, in graph order."""
    w = {k[len("model."):]: v for k, v in init.items() if k.startswith("model.")}
    w.setdefault("feature_inv_std", init.get("model.feature_inv_std"))
    consumers = []
    for node in model.graph.node:
        for name in node.input:
            if name.startswith("onnx::") and name in init and name not in [c[1] for c in consumers]:
                consumers.append((node.op_type, name))
    anonymous = [init[name] for _, name in consumers]
    # Order of first use: embedding^T; per layer: query weight and bias (both already multiplied
    # by the attention scale 1/sqrt(head_dim)), key^T, value^T, ff_in^T, ff_out^T; then the
    # block-diagonal head [2d, 2] and its bias.
    scale = 1.0 / np.sqrt(w["token_table"].shape[1] // heads)
    position = 0
    w["embedding.weight"] = anonymous[position].T
    position += 1
    index = 0
    while f"layers.{index}.norm_attention.weight" in w:
        p = f"layers.{index}"
        w[f"{p}.attention.query.weight"] = anonymous[position] / scale
        w[f"{p}.attention.query.bias"] = anonymous[position + 1] / scale
        w[f"{p}.attention.key.weight"] = anonymous[position + 2].T
        w[f"{p}.attention.value.weight"] = anonymous[position + 3].T
        w[f"{p}.ff_in.weight"] = anonymous[position + 4].T
        w[f"{p}.ff_out.weight"] = anonymous[position + 5].T
        position += 6
        index += 1
    d = w["token_table"].shape[1]
    head, bias = anonymous[position], anonymous[position + 1]
    w["head_x.weight"], w["head_y.weight"] = head[:d, 0][None, :], head[d:, 1][None, :]
    w["head_x.bias"], w["head_y.bias"] = bias[:1], bias[1:]
    return w
