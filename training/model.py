"""The PR model (paper, Section III-C "PR Model Architecture") and its ONNX form.

Inputs (batch axis ``batch`` is the only dynamic one):

* ``features`` ``[batch, 5, 5]`` float32: ``eq:pr_input`` rows, oldest first; rows ``0..len``
  valid, rows ``len..`` zero (right padding), as ``primm_core::predictor::PredictionRequest``.
* ``valid`` ``[batch, 5]`` float32: 1 for rows ``0..len``, 0 for padding.

Outputs:

* ``displacement`` ``[batch, 2]`` float32: ``[dx, dy]`` in metres, the displacement of the object
  from the latest history measurement to the prediction time (the time the feature ``t_l - t_k``
  is relative to);
* ``displacement_cholesky`` ``[batch, 3]`` float32: ``[l_xx, l_yx, l_yy]``, the lower-triangular
  Cholesky factor ``L`` of the covariance ``Sigma = L L^T`` (m^2) of the error of that
  displacement (true minus predicted), in the same frame; ``l_xx`` and ``l_yy`` are at least
  ``CHOLESKY_FLOOR_M``.

:class:`PRModel` is the network as trained:

1. normalisation of the five features with constants from the training data;
2. two zero rows appended for the query tokens, linear embedding of the 5 features without
   bias, plus one learnable ``[7, d]`` table: rows 0-4 are the positional embeddings of the
   history rows, rows 5 and 6 the query tokens ``q_x`` and ``q_y`` (a zero row embeds to zero,
   so the query rows are exactly the learnable tokens);
3. an additive key mask from ``valid`` (0 for valid rows and the queries, -1e9 for padded
   rows) shared by all layers;
4. pre-LayerNorm Transformer encoder layers: multi-head self-attention and a ReLU
   feed-forward block, residual connections around both. Only the two query tokens' outputs
   are read, so the last layer computes attention queries, the feed-forward block and the
   residuals for those two tokens only (keys and values still come from all seven): the same
   function as the full layer restricted to the outputs that are used;
5. a final LayerNorm, ``dx`` from ``q_x``'s output and ``dy`` from ``q_y``'s output (one linear
   head each), scaled to metres;
6. the uncertainty head: one linear layer from both query outputs to three raw values ``r``,
   ``l_xx = softplus(r_0) s_x + floor``, ``l_yx = r_1 s_y``, ``l_yy = softplus(r_2) s_y + floor``
   with ``s`` the label's RMS per axis (``output_scale``) and ``floor = CHOLESKY_FLOOR_M``.

:class:`ExportGraph` computes the same function from the same weights with the heads merged
and the softmax rewritten; ``train.py`` uses it for the weight-derived attention-score bound.
The ONNX graph itself is written by ``onnx_graph.py`` in the forms tract (primm's ONNX runtime)
executes fastest.
"""

from __future__ import annotations

import math

import torch
from torch import nn
from torch.nn import functional as F

MAX_HISTORY = 5
FEATURES = 5
QUERIES = 2
TOKENS = MAX_HISTORY + QUERIES
MASK_VALUE = -1.0e9
# Smallest diagonal element of the Cholesky factor of the displacement covariance, metres.
CHOLESKY_FLOOR_M = 0.005


class Attention(nn.Module):
    """Multi-head attention over the seven tokens, with an additive key mask."""

    def __init__(self, d_model: int, heads: int):
        super().__init__()
        if d_model % heads:
            raise ValueError("d_model must be a multiple of heads")
        self.heads = heads
        self.head_dim = d_model // heads
        self.query = nn.Linear(d_model, d_model)
        self.key = nn.Linear(d_model, d_model)
        self.value = nn.Linear(d_model, d_model)
        self.output = nn.Linear(d_model, d_model)
        self.scale = 1.0 / math.sqrt(self.head_dim)

    def forward(self, queries: torch.Tensor, tokens: torch.Tensor, key_bias: torch.Tensor) -> torch.Tensor:
        # queries [B, Tq, d], tokens [B, 7, d], key_bias [B, 1, 1, 7]
        tq = queries.shape[1]
        h, dh = self.heads, self.head_dim
        q = self.query(queries).reshape(-1, tq, h, dh).transpose(1, 2)  # [B, H, Tq, dh]
        k = self.key(tokens).reshape(-1, TOKENS, h, dh).permute(0, 2, 3, 1)  # [B, H, dh, 7]
        v = self.value(tokens).reshape(-1, TOKENS, h, dh).transpose(1, 2)  # [B, H, 7, dh]
        scores = torch.matmul(q, k) * self.scale + key_bias  # [B, H, Tq, 7]
        weights = torch.softmax(scores, dim=-1)
        mixed = torch.matmul(weights, v).transpose(1, 2).reshape(-1, tq, h * dh)  # [B, Tq, d]
        return self.output(mixed)


class EncoderLayer(nn.Module):
    """Pre-LayerNorm encoder layer: x + MHA(LN(x)), then x + FF(LN(x))."""

    def __init__(self, d_model: int, heads: int, d_ff: int):
        super().__init__()
        self.norm_attention = nn.LayerNorm(d_model)
        self.attention = Attention(d_model, heads)
        self.norm_ff = nn.LayerNorm(d_model)
        self.ff_in = nn.Linear(d_model, d_ff)
        self.ff_out = nn.Linear(d_ff, d_model)

    def forward(self, x: torch.Tensor, key_bias: torch.Tensor, queries_only: bool) -> torch.Tensor:
        normed = self.norm_attention(x)
        if queries_only:
            x = x[:, MAX_HISTORY:]
            attended = self.attention(normed[:, MAX_HISTORY:], normed, key_bias)
        else:
            attended = self.attention(normed, normed, key_bias)
        x = x + attended
        return x + self.ff_out(F.relu(self.ff_in(self.norm_ff(x))))


class PRModel(nn.Module):
    """PR: history of up to five measurements -> displacement [dx, dy] in metres."""

    def __init__(
        self,
        d_model: int = 32,
        heads: int = 4,
        layers: int = 2,
        d_ff: int = 64,
        feature_mean=None,
        feature_std=None,
        output_scale=None,
    ):
        super().__init__()
        if layers < 1:
            raise ValueError("at least one encoder layer")
        mean = torch.zeros(FEATURES) if feature_mean is None else torch.as_tensor(feature_mean, dtype=torch.float32)
        std = torch.ones(FEATURES) if feature_std is None else torch.as_tensor(feature_std, dtype=torch.float32)
        scale = torch.ones(QUERIES) if output_scale is None else torch.as_tensor(output_scale, dtype=torch.float32)
        # The input axes the model is trained in (dataset.INPUT_FRAMES); train.py sets it.
        self.input_frame = "latest_motion"
        self.register_buffer("feature_mean", mean.clone())
        self.register_buffer("feature_inv_std", 1.0 / std.clone())
        self.register_buffer("output_scale", scale.clone())
        self.embedding = nn.Linear(FEATURES, d_model, bias=False)
        # Rows 0-4: positional embeddings of the history rows; rows 5-6: query tokens q_x, q_y.
        self.token_table = nn.Parameter(torch.randn(TOKENS, d_model) * 0.02)
        self.layers = nn.ModuleList(EncoderLayer(d_model, heads, d_ff) for _ in range(layers))
        self.final_norm = nn.LayerNorm(d_model)
        self.head_x = nn.Linear(d_model, 1)
        self.head_y = nn.Linear(d_model, 1)
        # [l_xx, l_yx, l_yy] before the softplus and scaling, from both query outputs.
        self.head_cholesky = nn.Linear(QUERIES * d_model, 3)
        self.register_buffer("cholesky_scale", torch.stack([scale[0], scale[1], scale[1]]).clone())
        self.register_buffer("cholesky_floor", torch.tensor([CHOLESKY_FLOOR_M, 0.0, CHOLESKY_FLOOR_M]))
        self.d_model = d_model

    def forward(self, features: torch.Tensor, valid: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """``(displacement [B, 2], displacement_cholesky [B, 3])``, metres."""
        x = (features - self.feature_mean) * self.feature_inv_std  # [B, 5, 5]
        x = F.pad(x, (0, 0, 0, QUERIES))  # [B, 7, 5], query rows zero
        tokens = self.embedding(x) + self.token_table  # [B, 7, d]
        key_valid = F.pad(valid, (0, QUERIES), value=1.0)  # [B, 7]
        key_bias = ((key_valid - 1.0) * -MASK_VALUE).reshape(-1, 1, 1, TOKENS)
        last = len(self.layers) - 1
        for index, layer in enumerate(self.layers):
            tokens = layer(tokens, key_bias, queries_only=index == last)
        out = self.final_norm(tokens).reshape(-1, QUERIES * self.d_model)  # [B, 2d]: q_x then q_y
        zeros = torch.zeros_like(self.head_x.weight[0])
        head = torch.stack(
            [torch.cat([self.head_x.weight[0], zeros]), torch.cat([zeros, self.head_y.weight[0]])], dim=1
        )  # [2d, 2], block diagonal
        bias = torch.cat([self.head_x.bias, self.head_y.bias])
        displacement = (out @ head + bias) * self.output_scale
        raw = self.head_cholesky(out)
        diagonal = torch.tensor([True, False, True])
        positive = torch.where(diagonal, F.softplus(raw), raw)
        return displacement, positive * self.cholesky_scale + self.cholesky_floor

    def parameter_count(self) -> int:
        return sum(p.numel() for p in self.parameters() if p.requires_grad)


class ExportGraph(nn.Module):
    """The trained :class:`PRModel` rewritten for a fast ONNX graph; same function, same weights.

    tract runs many tiny per-head matrix products and a per-row softmax of length 7 slowly, so:

    * Heads are merged into the rows of one product per sample. Head ``h``'s queries are the
      full-width query vectors with the other heads' channels zeroed (the query weights masked
      per head and stacked), so ``[B, H*Tq, d] @ [B, d, 7]`` yields every head's scores at once.
      Each head's output is the full-width value mix; the output projection, with each head's
      block of input channels kept and the rest zeroed, sums the heads' contributions.
    * The key mask enters the same product: every query row carries one extra constant 1 (a
      zero weight with bias 1) and the keys one extra row holding the additive mask.
    * Softmax is ``e / (e @ ones[7, 7])`` with ``e = exp(scores)``: an element-wise ``Exp``, one
      ``MatMul`` giving each row's sum in every column, and an element-wise ``Div``. The row
      maximum is subtracted only when ``subtract_max`` is set: :meth:`logit_bound` bounds every
      score from the weights (LayerNorm bounds every token's norm), and while that bound stays
      well below ``log(f32::MAX) = 88.7`` no ``exp`` can overflow. Masked scores are about -1e9
      and give exactly 0.
    * The normalisation constants stay explicit as the first two operations.
    """

    def __init__(self, model: PRModel, subtract_max: bool = False):
        super().__init__()
        self.model = model
        self.subtract_max = subtract_max

    def head_masks(self, attention: Attention) -> torch.Tensor:
        d = attention.heads * attention.head_dim
        mask = torch.zeros(attention.heads, d)
        for h in range(attention.heads):
            mask[h, h * attention.head_dim : (h + 1) * attention.head_dim] = 1.0
        return mask

    def attention(self, attention: Attention, queries: torch.Tensor, tokens: torch.Tensor, key_row: torch.Tensor):
        tq = queries.shape[1]
        heads, d = attention.heads, attention.heads * attention.head_dim
        mask = self.head_masks(attention)
        weight = attention.query.weight * attention.scale
        bias = attention.query.bias * attention.scale
        stacked_w = torch.cat(
            [torch.cat([weight * mask[h][:, None], torch.zeros(1, d)], 0) for h in range(heads)], 0
        )  # [H*(d+1), d]
        stacked_b = torch.cat([torch.cat([bias * mask[h], torch.ones(1)]) for h in range(heads)])
        q = F.linear(queries, stacked_w, stacked_b)  # [B, Tq, H*(d+1)]
        q = q.reshape(-1, tq, heads, d + 1).transpose(1, 2).reshape(-1, heads * tq, d + 1)
        k = torch.cat([attention.key(tokens).transpose(1, 2), key_row], 1)  # [B, d+1, 7]
        scores = torch.matmul(q, k)  # [B, H*Tq, 7]
        if self.subtract_max:
            scores = scores - scores.amax(dim=-1, keepdim=True)
        e = torch.exp(scores)
        weights = e / torch.matmul(e, torch.ones(TOKENS, TOKENS))
        mixed = torch.matmul(weights, attention.value(tokens))  # [B, H*Tq, d]
        mixed = mixed.reshape(-1, heads, tq, d).transpose(1, 2).reshape(-1, tq, heads * d)
        output_w = torch.cat([attention.output.weight * mask[h][None, :] for h in range(heads)], 1)  # [d, H*d]
        return F.linear(mixed, output_w, attention.output.bias)

    def forward(self, features: torch.Tensor, valid: torch.Tensor) -> torch.Tensor:
        """The displacement only (this form is kept for the score bound)."""
        m = self.model
        x = (features - m.feature_mean) * m.feature_inv_std
        x = F.pad(x, (0, 0, 0, QUERIES))
        tokens = m.embedding(x) + m.token_table
        key_row = ((F.pad(valid, (0, QUERIES), value=1.0) - 1.0) * -MASK_VALUE).reshape(-1, 1, TOKENS)
        last = len(m.layers) - 1
        for index, layer in enumerate(m.layers):
            normed = layer.norm_attention(tokens)
            if index == last:
                tokens = tokens[:, MAX_HISTORY:]
                attended = self.attention(layer.attention, normed[:, MAX_HISTORY:], normed, key_row)
            else:
                attended = self.attention(layer.attention, normed, normed, key_row)
            tokens = tokens + attended
            tokens = tokens + layer.ff_out(F.relu(layer.ff_in(layer.norm_ff(tokens))))
        out = m.final_norm(tokens).reshape(-1, QUERIES * m.d_model)
        zeros = torch.zeros_like(m.head_x.weight[0])
        head = torch.stack([torch.cat([m.head_x.weight[0], zeros]), torch.cat([zeros, m.head_y.weight[0]])], dim=1)
        return (out @ head + torch.cat([m.head_x.bias, m.head_y.bias])) * m.output_scale

    def logit_bound(self) -> float:
        """An upper bound on every attention score for any input, from the weights alone."""
        with torch.no_grad():
            return float(score_bound(self.model))


def score_bound(model: PRModel) -> torch.Tensor:
    """An upper bound on every attention score of ``model`` for any input (differentiable, so
    training can keep it small).

    A LayerNorm output is ``y = gamma * u + beta`` with ``u`` of zero mean and norm ``sqrt(d)``.
    With ``W_q' = W_q diag(gamma)`` and ``q0 = W_q beta + b_q`` (likewise for keys), a head's score
    between tokens ``u`` and ``v`` is ``scale * (u' A v + u . a + b . v + q0 . k0)`` with
    ``A = W_q'^T W_k'``, ``a = W_q'^T k0``, ``b = W_k'^T q0``. Restricted to zero-mean vectors
    (projection ``P``), ``|u' A v| <= |P A P| d`` and ``|u . a| <= |P a| sqrt(d)``.
    """
    bound = torch.zeros(())
    for layer in model.layers:
        norm = layer.norm_attention
        gamma, beta = norm.weight, norm.bias
        d = gamma.numel()
        projection = torch.eye(d) - torch.full((d, d), 1.0 / d)
        a = layer.attention
        for h in range(a.heads):
            rows = slice(h * a.head_dim, (h + 1) * a.head_dim)
            wq = a.query.weight[rows] * gamma
            wk = a.key.weight[rows] * gamma
            q0 = a.query.weight[rows] @ beta + a.query.bias[rows]
            k0 = a.key.weight[rows] @ beta + a.key.bias[rows]
            bilinear = torch.linalg.matrix_norm(projection @ wq.T @ wk @ projection, 2) * d
            linear = (projection @ (wq.T @ k0)).norm() * math.sqrt(d) + (projection @ (wk.T @ q0)).norm() * math.sqrt(d)
            value = (bilinear + linear + (q0 @ k0).abs()) * a.scale
            bound = torch.maximum(bound, value)
    return bound
