//! The PR model on tract: its ONNX file parsed, checked against the
//! [model contract](super::contract) and planned for fixed batch sizes.
//!
//! `TractEngine` types the graph with a symbolic batch dimension, then optimises one plan per
//! batch size of [`PLAN_BATCH_SIZES`] and runs batches of any size through them: full chunks of
//! the largest size, the rest padded up to the next planned size. tract runs a plan whose batch
//! is a constant in about a quarter less time than the same graph with a symbolic batch (it then
//! fuses more operations into the matrix products and fixes shapes and packing when the plan is
//! made), which is more than padding to the next size costs (`docs/BENCHMARKS.md`).

use super::contract::{
    InferenceError, ModelError, ModelSource, BATCH_SYMBOL, CHOLESKY_OUTPUT, CHOLESKY_VALUES,
    DISPLACEMENT_OUTPUT, FEATURES_INPUT, VALID_INPUT,
};
use primm_core::predictor::{FEATURES, MAX_HISTORY};
use std::sync::Arc;
use tract_onnx::pb::ModelProto;
use tract_onnx::prelude::*;
use tract_onnx::tract_hir::infer::GenericFactoid;

/// The batch sizes [`PrModel`](super::PrModel) plans for, ascending. A batch runs as chunks of
/// the largest size, and the rest is padded with empty rows up to the next size on this list: at
/// most 7 padded rows above 8, whose cost (~14 µs each) stays below what a fixed-size plan saves
/// (about a quarter of the run).
pub const PLAN_BATCH_SIZES: [usize; 11] = [1, 2, 4, 8, 16, 24, 32, 40, 48, 56, 64];

/// One optimised plan for a fixed batch size, with its execution state.
struct BatchPlan {
    batch: usize,
    plan: Arc<TypedRunnableModel>,
    state: TypedSimpleState,
}

/// A model file as tract read it: its plans, whether it has the covariance output, and the
/// parsed protobuf (the native forward pass reads its weights from it).
pub(crate) struct ParsedModel {
    pub(crate) proto: ModelProto,
    pub(crate) has_uncertainty: bool,
    pub(crate) tract: TractEngine,
}

/// tract's optimised plans of a model, one per size of [`PLAN_BATCH_SIZES`], each with its
/// execution state.
pub(crate) struct TractEngine {
    /// Ascending batch sizes, as [`PLAN_BATCH_SIZES`].
    plans: Vec<BatchPlan>,
}

impl TractEngine {
    /// Parses the bytes of an ONNX file, checks its signature against the model contract, binds
    /// the batch axis to the symbol [`BATCH_SYMBOL`], then optimises and plans the graph once
    /// for each size of [`PLAN_BATCH_SIZES`]; `source` names the model in errors.
    pub(crate) fn parse(bytes: &[u8], source: &ModelSource) -> Result<ParsedModel, ModelError> {
        let onnx = tract_onnx::onnx();
        let not_onnx =
            |error: TractError| ModelError::NotOnnx { model: source.clone(), reason: format!("{error:#}") };
        let proto = onnx.proto_model_for_read(&mut &bytes[..]).map_err(not_onnx)?;
        let mut model = onnx.model_for_proto_model(&proto).map_err(not_onnx)?;
        let has_uncertainty = check_signature(source, &model)?;
        let batch = model.symbols.sym(BATCH_SYMBOL).to_dim();
        let prepare = |error: TractError| ModelError::Preparation {
            model: source.clone(),
            reason: format!("{error:#}"),
        };
        model
            .set_input_fact(0, f32::fact([batch.clone(), MAX_HISTORY.to_dim(), FEATURES.to_dim()]).into())
            .map_err(prepare)?;
        model.set_input_fact(1, f32::fact([batch, MAX_HISTORY.to_dim()]).into()).map_err(prepare)?;
        let typed = model.into_typed().map_err(prepare)?;
        check_output(source, &typed, 0, DISPLACEMENT_OUTPUT, 2)?;
        if has_uncertainty {
            check_output(source, &typed, 1, CHOLESKY_OUTPUT, CHOLESKY_VALUES)?;
        }
        let symbol = typed.symbols.sym(BATCH_SYMBOL);
        let mut plans = Vec::with_capacity(PLAN_BATCH_SIZES.len());
        for batch in PLAN_BATCH_SIZES {
            let values = std::collections::HashMap::from([(symbol.clone(), (batch as i64).to_dim())]);
            let plan = typed
                .clone()
                .set_symbols(&values)
                .and_then(|fixed| fixed.into_optimized())
                .and_then(|optimized| optimized.into_runnable())
                .map_err(prepare)?;
            let state = plan.spawn().map_err(prepare)?;
            plans.push(BatchPlan { batch, plan, state });
        }
        Ok(ParsedModel { proto, has_uncertainty, tract: TractEngine { plans } })
    }

    /// The same plans with new execution states; `source` names the model in errors.
    pub(crate) fn fork(&self, source: &ModelSource) -> Result<Self, ModelError> {
        let mut plans = Vec::with_capacity(self.plans.len());
        for plan in &self.plans {
            let state = plan.plan.spawn().map_err(|error| ModelError::Preparation {
                model: source.clone(),
                reason: format!("{error:#}"),
            })?;
            plans.push(BatchPlan { batch: plan.batch, plan: Arc::clone(&plan.plan), state });
        }
        Ok(TractEngine { plans })
    }

    /// The planned batch sizes, ascending.
    pub(crate) fn batch_sizes(&self) -> Vec<usize> {
        self.plans.iter().map(|p| p.batch).collect()
    }

    /// Nodes of the largest plan's optimised graph.
    pub(crate) fn nodes(&self) -> Option<usize> {
        self.plans.last().map(|p| p.plan.model().nodes().len())
    }

    /// Runs a batch of at least one row whose buffers agree on its size (laid out as
    /// [`PrModel::run`](super::PrModel::run) takes them), chunk by chunk.
    pub(crate) fn run(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        mut cholesky: Option<&mut [f32]>,
    ) -> Result<(), InferenceError> {
        let batch = valid.len() / MAX_HISTORY;
        let mut done = 0;
        while done < batch {
            let rows = self.run_chunk(
                &features[done * MAX_HISTORY * FEATURES..],
                &valid[done * MAX_HISTORY..],
                &mut displacements[done * 2..],
                cholesky.as_deref_mut().map(|values| &mut values[done * CHOLESKY_VALUES..]),
            )?;
            done += rows;
        }
        Ok(())
    }

    /// Runs the first rows of `valid` (at most the largest planned batch) through the smallest
    /// plan that holds them, padded with empty rows; returns how many rows it ran.
    fn run_chunk(
        &mut self,
        features: &[f32],
        valid: &[f32],
        displacements: &mut [f32],
        cholesky: Option<&mut [f32]>,
    ) -> Result<usize, InferenceError> {
        let remaining = valid.len() / MAX_HISTORY;
        let index = self.plans.iter().position(|p| p.batch >= remaining).unwrap_or(self.plans.len() - 1);
        let plan = &mut self.plans[index];
        let (size, rows) = (plan.batch, remaining.min(plan.batch));
        let features = padded_tensor(&[size, MAX_HISTORY, FEATURES], features)?;
        let valid = padded_tensor(&[size, MAX_HISTORY], valid)?;
        let outputs = plan.state.run(tvec!(features.into_tvalue(), valid.into_tvalue()))?;
        let output = outputs.first().ok_or(InferenceError::NoOutput)?;
        if output.shape() != [size, 2] {
            return Err(InferenceError::OutputShape { found: output.shape().to_vec(), batch: size });
        }
        let view = output.try_as_plain_ram()?;
        displacements[..rows * 2].copy_from_slice(&view.as_slice::<f32>()?[..rows * 2]);
        if let Some(cholesky) = cholesky {
            let output = outputs
                .get(1)
                .filter(|output| output.shape() == [size, CHOLESKY_VALUES])
                .ok_or_else(|| InferenceError::CholeskyShape {
                    found: outputs.get(1).map(|output| output.shape().to_vec()).unwrap_or_default(),
                    batch: size,
                })?;
            let view = output.try_as_plain_ram()?;
            let values = rows * CHOLESKY_VALUES;
            cholesky[..values].copy_from_slice(&view.as_slice::<f32>()?[..values]);
        }
        Ok(rows)
    }
}

/// A zero tensor of `shape` whose leading values are copied from `values` (as many as fit):
/// the rows of a chunk, followed by empty padding rows.
fn padded_tensor(shape: &[usize], values: &[f32]) -> TractResult<Tensor> {
    let mut tensor = Tensor::zero::<f32>(shape)?;
    let mut view = tensor.try_as_plain_ram_mut()?;
    let slots = view.as_slice_mut::<f32>()?;
    let count = slots.len().min(values.len());
    slots[..count].copy_from_slice(&values[..count]);
    Ok(tensor)
}

/// Formats an inference-time shape, `?` for an unknown dimension, `..` for an unknown rank.
fn describe(fact: &InferenceFact) -> String {
    let dims: Vec<String> = fact.shape.dims().map(|d| d.to_string()).collect();
    let open = if fact.shape.is_open() { ", .." } else { "" };
    format!("type {:?}, shape [{}{open}]", fact.datum_type, dims.join(", "))
}

/// Checks the inputs and outputs by name and the inputs' shapes; returns whether the model has
/// the covariance output.
fn check_signature(source: &ModelSource, model: &InferenceModel) -> Result<bool, ModelError> {
    // An outlet's ONNX tensor name where tract kept it, else the name of the node producing it.
    let names = |outlets: &[OutletId]| -> Vec<String> {
        outlets
            .iter()
            .map(|outlet| {
                model
                    .outlet_label(*outlet)
                    .map_or_else(|| model.node(outlet.node).name.clone(), str::to_string)
            })
            .collect()
    };
    let inputs = names(model.input_outlets().unwrap_or(&[]));
    if inputs != [FEATURES_INPUT, VALID_INPUT] {
        return Err(ModelError::Signature {
            model: source.clone(),
            expected: format!("inputs [{FEATURES_INPUT}, {VALID_INPUT}]"),
            found: format!("inputs {inputs:?}"),
        });
    }
    let outputs = names(model.output_outlets().unwrap_or(&[]));
    let has_uncertainty = match outputs.len() {
        1 => false,
        2 if outputs[1] == CHOLESKY_OUTPUT => true,
        _ => {
            return Err(ModelError::Signature {
                model: source.clone(),
                expected: format!(
                    "outputs [{DISPLACEMENT_OUTPUT}] or [{DISPLACEMENT_OUTPUT}, {CHOLESKY_OUTPUT}]"
                ),
                found: format!("outputs {outputs:?}"),
            });
        }
    };
    for (index, (name, fixed)) in
        [(FEATURES_INPUT, &[MAX_HISTORY, FEATURES][..]), (VALID_INPUT, &[MAX_HISTORY][..])]
            .into_iter()
            .enumerate()
    {
        let fact = model
            .input_fact(index)
            .map_err(|e| ModelError::NotOnnx { model: source.clone(), reason: format!("{e:#}") })?;
        let expected_dims: Vec<String> =
            std::iter::once(BATCH_SYMBOL.to_string()).chain(fixed.iter().map(|d| d.to_string())).collect();
        let dims: Vec<&GenericFactoid<TDim>> = fact.shape.dims().collect();
        let type_ok = matches!(fact.datum_type, GenericFactoid::Only(DatumType::F32) | GenericFactoid::Any);
        let rank_ok = !fact.shape.is_open() && dims.len() == 1 + fixed.len();
        let dims_ok = rank_ok
            && fixed.iter().zip(&dims[1..]).all(|(want, got)| **got == GenericFactoid::Only(want.to_dim()))
            && !matches!(dims[0], GenericFactoid::Only(d) if d.to_i64().is_ok());
        if !(type_ok && dims_ok) {
            return Err(ModelError::Shape {
                model: source.clone(),
                name: name.to_string(),
                expected: format!(
                    "type F32, shape [{}] with a symbolic batch axis",
                    expected_dims.join(", ")
                ),
                found: describe(fact),
            });
        }
    }
    Ok(has_uncertainty)
}

/// Checks that output `index`, called `name`, is F32 of shape `[batch, columns]`.
fn check_output(
    source: &ModelSource,
    model: &TypedModel,
    index: usize,
    name: &str,
    columns: usize,
) -> Result<(), ModelError> {
    let fact = model
        .output_fact(index)
        .map_err(|e| ModelError::Preparation { model: source.clone(), reason: format!("{e:#}") })?;
    let dims = fact.shape.dims();
    let ok = fact.datum_type == DatumType::F32
        && dims.len() == 2
        && dims[1] == columns.to_dim()
        && dims[0] == model.symbols.sym(BATCH_SYMBOL).to_dim();
    if ok {
        return Ok(());
    }
    Err(ModelError::Shape {
        model: source.clone(),
        name: name.to_string(),
        expected: format!("type F32, shape [{BATCH_SYMBOL}, {columns}]"),
        found: format!(
            "type {:?}, shape [{}]",
            fact.datum_type,
            dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")
        ),
    })
}
