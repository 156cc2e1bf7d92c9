//! A deterministic stand-in for the learned predictor whose answers the fuzzer chooses.

use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};

/// Answers every request with the next entry of a fixed script, cycling; an empty script
/// answers `None` (no prediction). Entries may be anything, NaN and infinities included, in the
/// displacement and in its covariance (asymmetric, indefinite, huge): the
/// tracker must survive whatever a predictor returns.
#[derive(Debug, Clone, Default)]
pub struct ScriptedPredictor {
    script: Vec<Option<Displacement>>,
    next: usize,
    batch_len: usize,
}

impl ScriptedPredictor {
    /// A predictor answering `script` in order, then from its start again.
    pub fn new(script: Vec<Option<Displacement>>) -> Self {
        Self { script, next: 0, batch_len: 0 }
    }
}

impl DisplacementPredictor for ScriptedPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.batch_len = requests.len();
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        debug_assert_eq!(displacements.len(), self.batch_len);
        for displacement in displacements {
            *displacement = if self.script.is_empty() {
                None
            } else {
                let answer = self.script[self.next % self.script.len()];
                self.next = self.next.wrapping_add(1);
                answer
            };
        }
    }
}
