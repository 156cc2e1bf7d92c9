//! Which engine runs a model's batches: primm's native forward pass
//! ([`NativeModel`]) where the model has the shipped architecture and agrees with tract on
//! probe inputs at load, else tract (`TractEngine`).
//!
//! The probe batch is deterministic and spans what the tracker sends and beyond it; a model
//! whose native answers differ from tract's by more than [`MAX_PROBE_DIFFERENCE_M`] anywhere on
//! it runs on tract ([`Unsupported::Disagrees`]), so a graph with the right names but different
//! arithmetic cannot slip through.

use super::contract::{InferenceError, CHOLESKY_VALUES};
use super::tract_engine::TractEngine;
use crate::native::{NativeModel, Unsupported};
use primm_config::InferenceEngine;
use primm_core::predictor::{FEATURES, MAX_HISTORY};
use std::sync::Arc;

/// Largest difference, in any output value, between [`NativeModel`] and tract on the probe
/// inputs that a model may show and still run natively, m. float32 rounding in the two
/// summation orders gives ~1e-6 m on the shipped model.
pub const MAX_PROBE_DIFFERENCE_M: f32 = 1e-4;

/// The engine a model's batches run on, and the native forward pass it may choose, or why the
/// model cannot have one.
#[derive(Clone)]
pub(crate) struct EngineChoice {
    /// The native forward pass, or why the model cannot have one.
    native: Result<Arc<NativeModel>, Unsupported>,
    /// The engine batches run on.
    engine: InferenceEngine,
}

impl EngineChoice {
    /// On tract, with `native` (not yet [probed](Self::probe)) to choose from.
    pub(crate) fn on_tract(native: Result<NativeModel, Unsupported>) -> Self {
        EngineChoice { native: native.map(Arc::new), engine: InferenceEngine::Tract }
    }

    /// Runs the probe batch on `tract` and on the native forward pass, if the model has one, and
    /// gives the native one up ([`Unsupported::Disagrees`]) where they differ by more than
    /// [`MAX_PROBE_DIFFERENCE_M`]. Fails where tract fails on the probe batch.
    pub(crate) fn probe(
        &mut self,
        tract: &mut TractEngine,
        has_uncertainty: bool,
    ) -> Result<(), InferenceError> {
        if let Ok(native) = self.native.clone() {
            self.engine = InferenceEngine::Tract;
            let difference = probe_difference(tract, &native, has_uncertainty)?;
            if difference > MAX_PROBE_DIFFERENCE_M {
                self.native = Err(Unsupported::Disagrees {
                    difference_m: difference,
                    tolerance_m: MAX_PROBE_DIFFERENCE_M,
                });
            }
        }
        Ok(())
    }

    /// Chooses `engine` where the model allows it, else tract; returns the one in use.
    pub(crate) fn set(&mut self, engine: InferenceEngine) -> InferenceEngine {
        self.engine = match engine {
            InferenceEngine::Native if self.native.is_ok() => InferenceEngine::Native,
            _ => InferenceEngine::Tract,
        };
        self.engine
    }

    /// The engine batches run on.
    pub(crate) fn engine(&self) -> InferenceEngine {
        self.engine
    }

    /// Why the model has no native forward pass; `None` where it has one.
    pub(crate) fn native_unsupported(&self) -> Option<&Unsupported> {
        self.native.as_ref().err()
    }

    /// Whether the model has a native forward pass, or why not.
    pub(crate) fn native_status(&self) -> Result<(), &Unsupported> {
        self.native.as_ref().map(|_| ())
    }

    /// The native forward pass where batches run on it; `None` where they run on tract.
    pub(crate) fn native_in_use(&self) -> Option<&NativeModel> {
        match (self.engine, &self.native) {
            (InferenceEngine::Native, Ok(native)) => Some(native),
            _ => None,
        }
    }
}

/// The largest difference between `tract`'s and `native`'s outputs on the probe batch
/// ([`probe_batch`]), m; infinite where either answer is not finite.
fn probe_difference(
    tract: &mut TractEngine,
    native: &NativeModel,
    has_uncertainty: bool,
) -> Result<f32, InferenceError> {
    let (features, valid) = probe_batch();
    let rows = valid.len() / MAX_HISTORY;
    let (mut tract_out, mut native_out) = (vec![0.0f32; rows * 2], vec![0.0f32; rows * 2]);
    let (mut tract_factor, mut native_factor) =
        (vec![0.0f32; rows * CHOLESKY_VALUES], vec![0.0f32; rows * CHOLESKY_VALUES]);
    let cholesky = has_uncertainty.then_some(&mut tract_factor[..]);
    tract.run(&features, &valid, &mut tract_out, cholesky)?;
    native.run(&features, &valid, &mut native_out, has_uncertainty.then_some(&mut native_factor[..]));
    Ok(tract_out
        .iter()
        .zip(&native_out)
        .chain(tract_factor.iter().zip(&native_factor))
        .map(|(a, b)| if a.is_finite() && b.is_finite() { (a - b).abs() } else { f32::INFINITY })
        .fold(0.0f32, f32::max))
}

/// Rows of the probe batch: every history length, at several speeds, headings, ranges of
/// radial velocity and RCS, and measurement intervals.
const PROBE_ROWS: usize = 60;

/// The inputs [`PrModel`](super::PrModel) compares tract and the native forward pass on: deterministic,
/// spanning what the tracker sends (history lengths 1 to 5, speeds to ~40 m/s, intervals of
/// 15 to 80 ms) and beyond it.
fn probe_batch() -> (Vec<f32>, Vec<f32>) {
    let mut features = vec![0.0f32; PROBE_ROWS * MAX_HISTORY * FEATURES];
    let mut valid = vec![0.0f32; PROBE_ROWS * MAX_HISTORY];
    // A small linear congruential generator: the probe must not depend on a crate's stream.
    let mut state = 0x2545_f491_u32;
    let mut uniform = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for row in 0..PROBE_ROWS {
        let len = 1 + row % MAX_HISTORY;
        let speed = 40.0 * uniform();
        let heading = std::f32::consts::TAU * uniform();
        let interval = 0.015 + 0.065 * uniform();
        let radial = 60.0 * uniform() - 30.0;
        let rcs = 40.0 * uniform() - 10.0;
        let prediction_gap = interval * (0.5 + uniform());
        for index in 0..len {
            let steps_back = (len - 1 - index) as f32;
            let base = (row * MAX_HISTORY + index) * FEATURES;
            let back = speed * interval * steps_back;
            features[base] = -back * heading.cos() + (uniform() - 0.5) * 0.6;
            features[base + 1] = -back * heading.sin() + (uniform() - 0.5) * 0.6;
            features[base + 2] = radial + (uniform() - 0.5);
            features[base + 3] = rcs + 4.0 * (uniform() - 0.5);
            features[base + 4] = -(prediction_gap + interval * steps_back);
            valid[row * MAX_HISTORY + index] = 1.0;
        }
    }
    (features, valid)
}
