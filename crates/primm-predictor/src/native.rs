//! primm's own forward pass of the shipped PR architecture, in fixed-size arrays.
//!
//! tract runs any ONNX graph, but for a model this small (two encoder layers of width 32, seven
//! tokens) most of its time goes to the work around the matrix products: ~40 small products
//! packed one at a time, element-wise operators run one element or row at a time
//! (`docs/BENCHMARKS.md`, section 1). [`NativeModel`] computes the same function directly: one
//! sample at a time, every tensor a stack array whose size is a constant, the linear layers as
//! fixed-size loops the compiler vectorises, two tokens at a time where a layer has two to
//! apply (each weight row loaded once for both, each output summed in the same order) (dispatched at run time to AVX2 or AVX-512 where
//! the CPU has them, with the portable build as the fallback), and no allocation at all.
//!
//! It reads its weights from the ONNX file's initializers, by the names
//! `training/onnx_graph.py` gives them, and accepts only that architecture: the widths below,
//! four heads whose query and output weights are the block-masked stacks that file writes,
//! ReLU feed-forward blocks, LayerNorms, and the optional uncertainty head. A model of any other
//! shape is [`Unsupported`] and runs on tract. [`PrModel`](crate::onnx::PrModel) also runs
//! both on probe inputs at load and uses this forward pass only when it agrees with tract
//! (`MAX_PROBE_DIFFERENCE_M`), so a graph with the right names but different arithmetic
//! cannot slip through.
//!
//! Differences from the graph, none of which changes the function beyond float32 rounding
//! (~2e-6 m against tract, `tests/predictor_native.rs`):
//! * padded history rows are not computed: the graph computes them and then gives them zero
//!   attention weight;
//! * each head's softmax subtracts its largest score first (the graph may skip that while the
//!   weights bound the scores, `models/pr.json`) and takes its exponentials from [`exp`], a
//!   polynomial the compiler vectorises, instead of the C library's `expf`;
//! * LayerNorm sums in eight lanes (a fixed order, see `sum`), not left to right;
//! * the heads' queries and outputs use only each head's own channels, which are the only
//!   non-zero entries of the graph's stacked weights (checked at load);
//! * the last layer updates only the two query tokens, as the graph does.

use multiversion::multiversion;
use primm_core::predictor::{FEATURES, MAX_HISTORY};
use std::collections::HashMap;
use tract_onnx::pb::ModelProto;
use tract_onnx::prelude::*;

/// Width of a token, the model's `d_model`.
pub const MODEL_WIDTH: usize = 32;
/// Attention heads.
pub const HEADS: usize = 4;
/// Channels per head.
pub const HEAD_WIDTH: usize = MODEL_WIDTH / HEADS;
/// Width of the feed-forward blocks' hidden layer.
pub const FEED_FORWARD_WIDTH: usize = 64;
/// Encoder layers.
pub const LAYERS: usize = 2;
/// Query tokens appended to the history; the model reads its answer from them.
pub const QUERIES: usize = 2;
/// Tokens of a sample: the history rows, then the query tokens.
pub const TOKENS: usize = MAX_HISTORY + QUERIES;
/// Values of the uncertainty output per sample, `[l_xx, l_yx, l_yy]`.
pub const CHOLESKY_VALUES: usize = 3;
/// LayerNorm's epsilon (`LayerNormalization`'s default, which `training/onnx_graph.py` writes).
pub const LAYER_NORM_EPSILON: f32 = 1e-5;

/// The ONNX operators a graph of this architecture is made of; a graph with any other is
/// [`Unsupported`].
pub const GRAPH_OPERATORS: [&str; 17] = [
    "Abs",
    "Add",
    "Div",
    "Exp",
    "LayerNormalization",
    "Log",
    "MatMul",
    "Mul",
    "Neg",
    "Pad",
    "Relu",
    "Reshape",
    "ReduceMax",
    "Slice",
    "Sub",
    "Transpose",
    "Unsqueeze",
];

/// Why a model cannot run on [`NativeModel`] (it then runs on tract).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unsupported {
    /// A weight the architecture needs is not among the file's initializers.
    #[error("no initializer `{name}`")]
    MissingWeight {
        /// The initializer's name.
        name: String,
    },
    /// A weight has another element type or shape than the architecture's.
    #[error("initializer `{name}` has shape {found:?} ({datum}), expected {expected:?} of F32")]
    WeightShape {
        /// The initializer's name.
        name: String,
        /// The shape the file has.
        found: Vec<usize>,
        /// The element type the file has.
        datum: String,
        /// The shape the architecture needs.
        expected: Vec<usize>,
    },
    /// The file has weights of a layer beyond the architecture's [`LAYERS`].
    #[error("initializer `{name}` belongs to a layer beyond the {LAYERS} of this architecture")]
    ExtraLayer {
        /// The initializer's name.
        name: String,
    },
    /// A stacked query or output weight has a non-zero entry outside its head's channels.
    #[error("`{name}` mixes channels across heads")]
    HeadsNotSeparated {
        /// The initializer's name.
        name: String,
    },
    /// The graph uses an operator this architecture does not.
    #[error("the graph uses `{operator}`")]
    Operator {
        /// The ONNX operator type.
        operator: String,
    },
    /// A weight could not be decoded.
    #[error("initializer `{name}` cannot be read: {reason}")]
    Unreadable {
        /// The initializer's name.
        name: String,
        /// tract's description of the problem.
        reason: String,
    },
    /// On the probe inputs, the forward pass and tract differ by more than the tolerance.
    #[error("differs from tract by {difference_m:.3e} m on probe inputs (tolerance {tolerance_m:.0e} m)")]
    Disagrees {
        /// The largest difference of any output value, m.
        difference_m: f32,
        /// The tolerance.
        tolerance_m: f32,
    },
}

/// A linear layer `y = x W + b`, `W` stored input-major so that the inner loop runs along the
/// contiguous outputs.
#[derive(Debug, Clone)]
struct Linear<const IN: usize, const OUT: usize> {
    weight: [[f32; OUT]; IN],
    bias: [f32; OUT],
}

impl<const IN: usize, const OUT: usize> Linear<IN, OUT> {
    #[inline(always)]
    fn apply(&self, input: &[f32; IN]) -> [f32; OUT] {
        let mut output = self.bias;
        for (value, row) in input.iter().zip(&self.weight) {
            for (out, weight) in output.iter_mut().zip(row) {
                *out += value * weight;
            }
        }
        output
    }

    /// [`apply`](Self::apply) to two inputs at once: each weight row is loaded once for both,
    /// and the two sums are independent, so they overlap instead of waiting on each other.
    /// Each output is summed in the same order as by `apply`, so the values are identical.
    #[inline(always)]
    fn apply_pair(&self, first: &[f32; IN], second: &[f32; IN]) -> [[f32; OUT]; 2] {
        let (mut output_a, mut output_b) = (self.bias, self.bias);
        for ((a, b), row) in first.iter().zip(second).zip(&self.weight) {
            for ((out_a, out_b), weight) in output_a.iter_mut().zip(output_b.iter_mut()).zip(row) {
                *out_a += a * weight;
                *out_b += b * weight;
            }
        }
        [output_a, output_b]
    }
}

/// Applies `linear` to the inputs `inputs[i]` for `i` in `indices`, two at a time, writing
/// `outputs[i]`.
#[inline(always)]
fn apply_to<const IN: usize, const OUT: usize, const N: usize>(
    linear: &Linear<IN, OUT>,
    inputs: &[[f32; IN]; N],
    indices: &[usize],
    outputs: &mut [[f32; OUT]; N],
) {
    let mut pairs = indices.chunks_exact(2);
    for pair in &mut pairs {
        let [a, b] = linear.apply_pair(&inputs[pair[0]], &inputs[pair[1]]);
        outputs[pair[0]] = a;
        outputs[pair[1]] = b;
    }
    if let [last] = pairs.remainder() {
        outputs[*last] = linear.apply(&inputs[*last]);
    }
}

/// A LayerNorm's affine part (identity once `training/onnx_graph.py` has folded it into the
/// following layers, but applied as the file says).
#[derive(Debug, Clone)]
struct Norm {
    scale: [f32; MODEL_WIDTH],
    shift: [f32; MODEL_WIDTH],
}

impl Norm {
    #[inline(always)]
    fn apply(&self, token: &[f32; MODEL_WIDTH]) -> [f32; MODEL_WIDTH] {
        let mean = sum(token) / MODEL_WIDTH as f32;
        let mut centred = [0.0f32; MODEL_WIDTH];
        let mut squares = [0.0f32; MODEL_WIDTH];
        for index in 0..MODEL_WIDTH {
            centred[index] = token[index] - mean;
            squares[index] = centred[index] * centred[index];
        }
        let variance = sum(&squares) / MODEL_WIDTH as f32;
        let inverse = 1.0 / (variance + LAYER_NORM_EPSILON).sqrt();
        let mut out = [0.0f32; MODEL_WIDTH];
        for index in 0..MODEL_WIDTH {
            out[index] = centred[index] * inverse * self.scale[index] + self.shift[index];
        }
        out
    }
}

/// Lanes of the partial sums of [`sum`]: one AVX register of single-precision values.
const LANES: usize = 8;
const _: () = assert!(TOKENS <= LANES && MODEL_WIDTH.is_multiple_of(LANES));

/// The sum of a token's values in a fixed order the compiler vectorises: eight partial sums
/// (lane `l` adds values `l, l+8, l+16, l+24`), then the lanes pairwise. A plain left-to-right
/// sum is one chain of 32 dependent additions, which float semantics forbid reordering.
#[inline(always)]
fn sum(values: &[f32; MODEL_WIDTH]) -> f32 {
    let mut lanes = [0.0f32; LANES];
    for chunk in values.chunks_exact(LANES) {
        for (lane, value) in lanes.iter_mut().zip(chunk) {
            *lane += value;
        }
    }
    ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]))
}

/// One encoder layer (pre-norm attention, then a pre-norm ReLU feed-forward block).
#[derive(Debug, Clone)]
struct Layer {
    norm_attention: Norm,
    /// Every head's queries side by side (head `h` in channels `h·8..h·8+8`), scaled by
    /// `1/√8` as in the file.
    query: Linear<MODEL_WIDTH, MODEL_WIDTH>,
    key: Linear<MODEL_WIDTH, MODEL_WIDTH>,
    value: Linear<MODEL_WIDTH, MODEL_WIDTH>,
    output: Linear<MODEL_WIDTH, MODEL_WIDTH>,
    norm_feed_forward: Norm,
    feed_forward_in: Linear<MODEL_WIDTH, FEED_FORWARD_WIDTH>,
    feed_forward_out: Linear<FEED_FORWARD_WIDTH, MODEL_WIDTH>,
}

/// The uncertainty head: `[l_xx, l_yx, l_yy]` from the raw values `r` as
/// `softplus(r)·diagonal_scale + r·off_diagonal_scale + floor`.
#[derive(Debug, Clone)]
struct CholeskyHead {
    linear: Linear<{ QUERIES * MODEL_WIDTH }, CHOLESKY_VALUES>,
    diagonal_scale: [f32; CHOLESKY_VALUES],
    off_diagonal_scale: [f32; CHOLESKY_VALUES],
    floor: [f32; CHOLESKY_VALUES],
}

/// The PR model's weights in the fixed shapes of the shipped architecture, and its forward pass
/// (see the [module documentation](self)). Read-only once built; share it between threads.
#[derive(Debug, Clone)]
pub struct NativeModel {
    embedding: [[f32; MODEL_WIDTH]; FEATURES],
    token_table: [[f32; MODEL_WIDTH]; TOKENS],
    layers: [Layer; LAYERS],
    final_norm: Norm,
    head: Linear<{ QUERIES * MODEL_WIDTH }, 2>,
    output_scale: [f32; 2],
    cholesky: Option<CholeskyHead>,
}

/// The initializers of an ONNX file by name.
struct Weights<'a> {
    onnx: &'a tract_onnx::Onnx,
    by_name: HashMap<&'a str, &'a tract_onnx::pb::TensorProto>,
}

impl Weights<'_> {
    /// The values of initializer `name`, which must be F32 of `shape` (a scalar where the
    /// shape is empty).
    fn values(&self, name: &str, shape: &[usize]) -> Result<Vec<f32>, Unsupported> {
        let proto = self.by_name.get(name).ok_or_else(|| Unsupported::MissingWeight { name: name.into() })?;
        let tensor = tract_onnx::tensor::load_tensor(&*self.onnx.provider, proto, None)
            .map_err(|error| Unsupported::Unreadable { name: name.into(), reason: format!("{error:#}") })?;
        if tensor.datum_type() != DatumType::F32 || tensor.shape() != shape {
            return Err(Unsupported::WeightShape {
                name: name.into(),
                found: tensor.shape().to_vec(),
                datum: format!("{:?}", tensor.datum_type()),
                expected: shape.to_vec(),
            });
        }
        let plain = tensor
            .try_as_plain_ram()
            .and_then(|view| view.as_slice::<f32>().map(<[f32]>::to_vec))
            .map_err(|error| Unsupported::Unreadable { name: name.into(), reason: format!("{error:#}") })?;
        Ok(plain)
    }

    fn vector<const N: usize>(&self, name: &str) -> Result<[f32; N], Unsupported> {
        let values = self.values(name, &[N])?;
        Ok(std::array::from_fn(|index| values[index]))
    }

    fn matrix<const ROWS: usize, const COLUMNS: usize>(
        &self,
        name: &str,
    ) -> Result<[[f32; COLUMNS]; ROWS], Unsupported> {
        let values = self.values(name, &[ROWS, COLUMNS])?;
        Ok(std::array::from_fn(|row| std::array::from_fn(|column| values[row * COLUMNS + column])))
    }

    /// `{prefix}.weight_t` and `{prefix}.bias_row`, the names of
    /// `training/onnx_graph.py`'s linear layers.
    fn linear<const IN: usize, const OUT: usize>(
        &self,
        prefix: &str,
    ) -> Result<Linear<IN, OUT>, Unsupported> {
        Ok(Linear {
            weight: self.matrix(&format!("{prefix}.weight_t"))?,
            bias: self.vector(&format!("{prefix}.bias_row"))?,
        })
    }

    fn norm(&self, prefix: &str) -> Result<Norm, Unsupported> {
        Ok(Norm {
            scale: self.vector(&format!("{prefix}.weight"))?,
            shift: self.vector(&format!("{prefix}.bias"))?,
        })
    }

    /// The stacked query projection `[d, H·d]` (head `h`'s block: the queries masked to that
    /// head's channels) as one `[d, d]` projection; an entry outside the heads' own channels
    /// must be zero.
    fn stacked_query(&self, prefix: &str) -> Result<Linear<MODEL_WIDTH, MODEL_WIDTH>, Unsupported> {
        let name = format!("{prefix}.weight_t");
        let weight = self.values(&name, &[MODEL_WIDTH, HEADS * MODEL_WIDTH])?;
        let bias_name = format!("{prefix}.bias_row");
        let bias = self.values(&bias_name, &[HEADS * MODEL_WIDTH])?;
        let own = |column: usize| column / MODEL_WIDTH == (column % MODEL_WIDTH) / HEAD_WIDTH;
        let separated = |values: &[f32], columns: usize| {
            values.iter().enumerate().all(|(index, value)| own(index % columns) || *value == 0.0)
        };
        if !separated(&weight, HEADS * MODEL_WIDTH) {
            return Err(Unsupported::HeadsNotSeparated { name });
        }
        if !separated(&bias, HEADS * MODEL_WIDTH) {
            return Err(Unsupported::HeadsNotSeparated { name: bias_name });
        }
        // Channel c belongs to head c / 8, whose block starts at column (c / 8)·d.
        let column = |channel: usize| (channel / HEAD_WIDTH) * MODEL_WIDTH + channel;
        Ok(Linear {
            weight: std::array::from_fn(|row| {
                std::array::from_fn(|channel| weight[row * HEADS * MODEL_WIDTH + column(channel)])
            }),
            bias: std::array::from_fn(|channel| bias[column(channel)]),
        })
    }

    /// The stacked output projection `[H·d, d]` (head `h`'s block of rows: the projection
    /// restricted to that head's channels) as one `[d, d]` projection; a row outside the heads'
    /// own channels must be zero.
    fn stacked_output(&self, prefix: &str) -> Result<Linear<MODEL_WIDTH, MODEL_WIDTH>, Unsupported> {
        let name = format!("{prefix}.weight_t");
        let weight = self.values(&name, &[HEADS * MODEL_WIDTH, MODEL_WIDTH])?;
        let own = |row: usize| row / MODEL_WIDTH == (row % MODEL_WIDTH) / HEAD_WIDTH;
        let separated =
            weight.iter().enumerate().all(|(index, value)| own(index / MODEL_WIDTH) || *value == 0.0);
        if !separated {
            return Err(Unsupported::HeadsNotSeparated { name });
        }
        let row = |channel: usize| (channel / HEAD_WIDTH) * MODEL_WIDTH + channel;
        Ok(Linear {
            weight: std::array::from_fn(|channel| {
                std::array::from_fn(|out| weight[row(channel) * MODEL_WIDTH + out])
            }),
            bias: self.vector(&format!("{prefix}.bias_row"))?,
        })
    }
}

impl NativeModel {
    /// The weights of `proto`, a model written by `training/onnx_graph.py`; [`Unsupported`] for
    /// a model of any other architecture. `has_uncertainty`: whether the model has the
    /// covariance output (whose weights are then required).
    pub fn from_proto(proto: &ModelProto, has_uncertainty: bool) -> Result<Self, Unsupported> {
        let graph =
            proto.graph.as_ref().ok_or_else(|| Unsupported::MissingWeight { name: "graph".into() })?;
        if let Some(node) = graph.node.iter().find(|node| !GRAPH_OPERATORS.contains(&node.op_type.as_str())) {
            return Err(Unsupported::Operator { operator: node.op_type.clone() });
        }
        let onnx = tract_onnx::onnx();
        let weights = Weights {
            onnx: &onnx,
            by_name: graph.initializer.iter().map(|tensor| (tensor.name.as_str(), tensor)).collect(),
        };
        let layer = |index: usize| -> Result<Layer, Unsupported> {
            let p = format!("layers.{index}");
            Ok(Layer {
                norm_attention: weights.norm(&format!("{p}.norm_attention"))?,
                query: weights.stacked_query(&format!("{p}.attention.query_heads"))?,
                key: weights.linear(&format!("{p}.attention.key"))?,
                value: weights.linear(&format!("{p}.attention.value"))?,
                output: weights.stacked_output(&format!("{p}.attention.output"))?,
                norm_feed_forward: weights.norm(&format!("{p}.norm_ff"))?,
                feed_forward_in: weights.linear(&format!("{p}.ff_in"))?,
                feed_forward_out: weights.linear(&format!("{p}.ff_out"))?,
            })
        };
        // A third layer would be silently ignored: refuse it.
        let extra_layer = format!("layers.{LAYERS}.ff_in.weight_t");
        if weights.by_name.contains_key(extra_layer.as_str()) {
            return Err(Unsupported::ExtraLayer { name: extra_layer });
        }
        let cholesky = if has_uncertainty {
            let floor = match weights.values("cholesky_floor", &[CHOLESKY_VALUES]) {
                Ok(values) => std::array::from_fn(|index| values[index]),
                Err(_) => [weights.values("cholesky_floor", &[])?[0]; CHOLESKY_VALUES],
            };
            Some(CholeskyHead {
                linear: weights.linear("head_cholesky")?,
                diagonal_scale: weights.vector("cholesky_diagonal_scale")?,
                off_diagonal_scale: weights.vector("cholesky_off_diagonal_scale")?,
                floor,
            })
        } else {
            None
        };
        Ok(NativeModel {
            embedding: weights.matrix("embedding.weight_t")?,
            token_table: weights.matrix("token_table")?,
            layers: [layer(0)?, layer(1)?],
            final_norm: weights.norm("final_norm")?,
            head: weights.linear("head")?,
            output_scale: weights.vector("output_scale")?,
            cholesky,
        })
    }

    /// Whether the model has the uncertainty head.
    pub fn has_uncertainty(&self) -> bool {
        self.cholesky.is_some()
    }

    /// Runs a batch laid out as [`PrModel::run`](crate::onnx::PrModel::run) takes it:
    /// `features` `batch × 5 × 5`, `valid` `batch × 5`, `displacements` `batch × 2` and, for a
    /// model with the uncertainty head, `cholesky` `batch × 3`. The caller checks that the
    /// buffers agree; extra values are ignored.
    pub fn run(
        &self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        cholesky: Option<&mut [f32]>,
    ) {
        run_batch(self, features, valid, displacements, cholesky);
    }

    /// One sample: the history `features` (rows oldest first) and their `valid` flags; returns
    /// the displacement and the Cholesky factor (zero without the uncertainty head).
    #[inline(always)]
    fn forward(&self, features: &[f32], valid: &[f32]) -> ([f32; 2], [f32; CHOLESKY_VALUES]) {
        // Attention weight of each token as a key: the history rows' flags, 1 for the queries.
        let mut key_weight = [1.0f32; TOKENS];
        key_weight[..MAX_HISTORY].copy_from_slice(&valid[..MAX_HISTORY]);
        let mut tokens = self.token_table;
        for (row, token) in tokens.iter_mut().enumerate().take(MAX_HISTORY) {
            if key_weight[row] == 0.0 {
                continue;
            }
            for (feature, embedding) in
                features[row * FEATURES..(row + 1) * FEATURES].iter().zip(&self.embedding)
            {
                for (out, weight) in token.iter_mut().zip(embedding) {
                    *out += feature * weight;
                }
            }
        }
        for (index, layer) in self.layers.iter().enumerate() {
            // The last layer updates only the query tokens.
            let first_query = if index + 1 == LAYERS { MAX_HISTORY } else { 0 };
            layer.apply(&mut tokens, &key_weight, first_query);
        }
        let mut flat = [0.0f32; QUERIES * MODEL_WIDTH];
        for query in 0..QUERIES {
            let normed = self.final_norm.apply(&tokens[MAX_HISTORY + query]);
            flat[query * MODEL_WIDTH..(query + 1) * MODEL_WIDTH].copy_from_slice(&normed);
        }
        let head = self.head.apply(&flat);
        let displacement = [head[0] * self.output_scale[0], head[1] * self.output_scale[1]];
        let mut factor = [0.0f32; CHOLESKY_VALUES];
        if let Some(cholesky) = &self.cholesky {
            let raw = cholesky.linear.apply(&flat);
            for index in 0..CHOLESKY_VALUES {
                let r = raw[index];
                let softplus = r.max(0.0) + (1.0 + (-r.abs()).exp()).ln();
                factor[index] = softplus * cholesky.diagonal_scale[index]
                    + r * cholesky.off_diagonal_scale[index]
                    + cholesky.floor[index];
            }
        }
        (displacement, factor)
    }
}

impl Layer {
    /// Updates `tokens[first_query..]` (those with a non-zero key weight) by attention over
    /// every token of non-zero key weight, then the feed-forward block.
    #[inline(always)]
    fn apply(
        &self,
        tokens: &mut [[f32; MODEL_WIDTH]; TOKENS],
        key_weight: &[f32; TOKENS],
        first_query: usize,
    ) {
        // The tokens that take part (non-zero key weight), and those of them updated here.
        let mut active = [0usize; TOKENS];
        let mut active_count = 0;
        let mut normed = [[0.0f32; MODEL_WIDTH]; TOKENS];
        for token in 0..TOKENS {
            if key_weight[token] != 0.0 {
                normed[token] = self.norm_attention.apply(&tokens[token]);
                active[active_count] = token;
                active_count += 1;
            }
        }
        let active = &active[..active_count];
        let updated = &active[active.partition_point(|&token| token < first_query)..];
        let mut keys = [[0.0f32; MODEL_WIDTH]; TOKENS];
        let mut values = [[0.0f32; MODEL_WIDTH]; TOKENS];
        let mut queries = [[0.0f32; MODEL_WIDTH]; TOKENS];
        apply_to(&self.key, &normed, active, &mut keys);
        apply_to(&self.value, &normed, active, &mut values);
        apply_to(&self.query, &normed, updated, &mut queries);
        // Keys channel-major, the tokens along a row of LANES (masked and empty lanes zero): a
        // head's scores for one query are LANES-wide products summed over its 8 channels.
        let mut keys_by_channel = [[0.0f32; LANES]; MODEL_WIDTH];
        for (token, key) in keys.iter().enumerate() {
            for (channel, value) in key.iter().enumerate() {
                keys_by_channel[channel][token] = *value;
            }
        }
        let mut key_weights = [0.0f32; LANES];
        key_weights[..TOKENS].copy_from_slice(key_weight);
        // Every query attends to the keys and values above, none to another's update, so the
        // queries' attention is computed first and their updates two at a time.
        let mut mixed = [[0.0f32; MODEL_WIDTH]; TOKENS];
        for &query in updated {
            for head in 0..HEADS {
                attend_head(
                    head,
                    &queries[query],
                    &keys_by_channel,
                    &key_weights,
                    &values,
                    &mut mixed[query],
                );
            }
        }
        let mut attended = [[0.0f32; MODEL_WIDTH]; TOKENS];
        apply_to(&self.output, &mixed, updated, &mut attended);
        let mut normed = [[0.0f32; MODEL_WIDTH]; TOKENS];
        for &query in updated {
            let token = &mut tokens[query];
            for (value, add) in token.iter_mut().zip(&attended[query]) {
                *value += add;
            }
            normed[query] = self.norm_feed_forward.apply(token);
        }
        let mut hidden = [[0.0f32; FEED_FORWARD_WIDTH]; TOKENS];
        apply_to(&self.feed_forward_in, &normed, updated, &mut hidden);
        for &query in updated {
            for value in &mut hidden[query] {
                *value = value.max(0.0);
            }
        }
        let mut out = [[0.0f32; MODEL_WIDTH]; TOKENS];
        apply_to(&self.feed_forward_out, &hidden, updated, &mut out);
        for &query in updated {
            for (value, add) in tokens[query].iter_mut().zip(&out[query]) {
                *value += add;
            }
        }
    }
}

/// Adds one head's attention of `query` over the keys of non-zero weight into that head's
/// channels of `mixed`: scores against `keys_by_channel` (channel-major, one lane per token),
/// a softmax with the largest visible score subtracted first, the values weighted by it.
#[inline(always)]
fn attend_head(
    head: usize,
    query: &[f32; MODEL_WIDTH],
    keys_by_channel: &[[f32; LANES]; MODEL_WIDTH],
    key_weights: &[f32; LANES],
    values: &[[f32; MODEL_WIDTH]; TOKENS],
    mixed: &mut [f32; MODEL_WIDTH],
) {
    let channels = head * HEAD_WIDTH..(head + 1) * HEAD_WIDTH;
    let mut scores = [0.0f32; LANES];
    for channel in channels.clone() {
        let value = query[channel];
        for (score, key) in scores.iter_mut().zip(&keys_by_channel[channel]) {
            *score += value * key;
        }
    }
    // The largest score among the keys the head may see is subtracted first.
    let mut peak = f32::NEG_INFINITY;
    for (score, weight) in scores.iter().zip(key_weights) {
        if *weight != 0.0 {
            peak = peak.max(*score);
        }
    }
    let mut weights = [0.0f32; LANES];
    for lane in 0..LANES {
        weights[lane] = exp(scores[lane] - peak) * key_weights[lane];
    }
    let total = ((weights[0] + weights[1]) + (weights[2] + weights[3]))
        + ((weights[4] + weights[5]) + (weights[6] + weights[7]));
    for key in 0..TOKENS {
        if key_weights[key] != 0.0 {
            let share = weights[key] / total;
            for channel in channels.clone() {
                mixed[channel] += share * values[key][channel];
            }
        }
    }
}

/// `e^x` in single precision from arithmetic alone (so that the compiler can vectorise it over
/// a row of scores, which a call to the C library's `expf` prevents): `x = n·ln 2 + r` with `n`
/// the nearest integer and `|r| ≤ ln 2 / 2` (ln 2 in two parts, so `r` is exact), `e^r` by
/// the degree-6 polynomial of Cephes' `expf` (relative error ~1e-7), `2^n` written into the
/// exponent bits. `x` is clamped to `[-87, 88]`: below, the result is ~1e-38 instead of 0,
/// which a softmax weight of a score 87 below the largest does not notice.
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    const SHIFT: f32 = 12_582_912.0; // 1.5 · 2^23: adding it rounds to an integer
    let x = x.clamp(-87.0, 88.0);
    let n = (x * std::f32::consts::LOG2_E + SHIFT) - SHIFT;
    let r = x - n * 0.693_359_4 - n * -2.121_944_4e-4;
    let mut p = 1.987_569_1e-4f32;
    p = p * r + 1.398_199_9e-3;
    p = p * r + 8.333_452e-3;
    p = p * r + 4.166_579_6e-2;
    p = p * r + 1.666_666_5e-1;
    p = p * r + 0.5;
    let e = p * r * r + r + 1.0;
    e * f32::from_bits(((n as i32 + 127) << 23) as u32)
}

/// The batch loop, compiled for AVX-512 and AVX2 besides the portable baseline and dispatched
/// at run time; every step below is inlined into it. Rust does not fuse multiplications and
/// additions on its own, so every version computes the same values in the same order.
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq+avx+avx2+fma", "x86_64+avx+avx2+fma"))]
fn run_batch(
    model: &NativeModel,
    features: &[f32],
    valid: &[f32],
    displacements: &mut [f32],
    mut cholesky: Option<&mut [f32]>,
) {
    let samples = features
        .chunks_exact(MAX_HISTORY * FEATURES)
        .zip(valid.chunks_exact(MAX_HISTORY))
        .zip(displacements.chunks_exact_mut(2))
        .enumerate();
    for (index, ((features, valid), displacement)) in samples {
        let (answer, factor) = model.forward(features, valid);
        displacement.copy_from_slice(&answer);
        if let Some(out) = cholesky
            .as_deref_mut()
            .and_then(|values| values.get_mut(index * CHOLESKY_VALUES..(index + 1) * CHOLESKY_VALUES))
        {
            out.copy_from_slice(&factor);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::exp;

    #[test]
    fn the_polynomial_exponential_is_within_three_ten_millionths_of_the_library_one() {
        let mut largest = 0.0f64;
        for step in 0..=200_000 {
            let x = -87.0 + 175.0 * step as f32 / 200_000.0;
            let want = f64::from(x).exp();
            let relative = ((f64::from(exp(x)) - want) / want).abs();
            largest = largest.max(relative);
        }
        assert!(largest < 3e-7, "largest relative error {largest:e}");
        assert_eq!(exp(0.0), 1.0);
        // Clamped, never zero, infinite or NaN.
        assert!(exp(-1000.0) > 0.0 && exp(-1000.0) < 1e-37);
        assert!(exp(1000.0).is_finite());
        assert!(exp(f32::NEG_INFINITY) > 0.0);
    }
}
