//! Fusion in the shared position space: the mixing of mode positions (`eq:mixed_pos`,
//! `eq:mixed_pos_cov`), the fused prior that association uses (`eq:prior_fusion`), the fused
//! posterior (`eq:posterior_fusion`) and its extension to position and velocity.

use super::state::{ImmState, ModeProbabilities};
use super::Imm;
use crate::extent::ObjectPrior;
use crate::gaussian::{Gaussian, PositionEstimate};
use crate::mode::{Mode, ModeSet, MODE_COUNT};
use glam::{DMat2, DMat4, DVec2, DVec4};

/// The outcome of [`Imm::predict`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImmPrior {
    /// Each mode's prior; `probabilities` holds the prior mode probabilities `c`.
    pub state: ImmState,
    /// Modes that took part in this step (the active ones, less PR without a displacement).
    pub available: ModeSet,
    /// Fused prior position and covariance (`eq:prior_fusion`, covariance with the spread of
    /// the mode means), weights `c` renormalised over the available modes.
    pub fused: PositionEstimate,
}

impl ImmPrior {
    /// The fused prior velocity over the available modes, weights `c` renormalised over them,
    /// m/s (PR: its last displacement over the step), as [`Imm::fuse_velocity`] fuses a
    /// posterior's.
    pub fn fused_velocity_mps(&self) -> DVec2 {
        fused_velocity(&self.state, self.available)
    }

    /// The fused prior as an extended object's prior (`crate::extent`): position and its
    /// covariance, [`fused_velocity_mps`](Self::fused_velocity_mps), and the velocity
    /// covariance of the available physics modes (weights renormalised over them, with the
    /// spread of their means; PR has none of its own).
    pub fn object_prior(&self) -> ObjectPrior {
        let physics = self.available.without(Mode::Learned);
        let weights = renormalised(&self.state.probabilities, physics);
        let mean = fused_velocity(&self.state, physics);
        let mut velocity_covariance_m2 = DMat2::ZERO;
        for mode in physics.iter() {
            let marginal = match mode {
                Mode::ConstantVelocity => marginal4(&self.state.constant_velocity),
                Mode::ConstantAcceleration => marginal4(&self.state.constant_acceleration),
                Mode::CoordinatedTurn => marginal4(&self.state.coordinated_turn),
                Mode::Learned => continue,
            };
            let block = lower_right(&marginal.covariance);
            let spread = self.state.velocity(mode) - mean;
            velocity_covariance_m2 += (block + outer(spread, spread)) * weights[mode.index()];
        }
        ObjectPrior {
            centre_m: self.fused.mean,
            centre_covariance_m2: self.fused.covariance,
            velocity_mps: self.fused_velocity_mps(),
            velocity_covariance_m2,
        }
    }
}

/// The velocity over `modes`, weights `μ` (or `c`) renormalised over them, m/s.
pub(super) fn fused_velocity(state: &ImmState, modes: ModeSet) -> DVec2 {
    let weights = renormalised(&state.probabilities, modes);
    modes.iter().map(|mode| weights[mode.index()] * state.velocity(mode)).sum()
}

/// The fused prior position and covariance over the `available` modes (`eq:prior_fusion`,
/// covariance with the spread of the mode means), weights `c` renormalised over them.
#[inline]
pub fn fused_prior(state: &ImmState, available: ModeSet) -> PositionEstimate {
    mix_positions(state, available, &renormalised(&state.probabilities, available))
}

/// Weighted mean and covariance with the spread-of-means term
/// (`eq:mixed_pos`, `eq:mixed_pos_cov`); weights must sum to 1 over `modes`.
#[inline]
pub fn mix_positions(state: &ImmState, modes: ModeSet, weights: &ModeProbabilities) -> PositionEstimate {
    mix(&mode_positions(state, modes), modes, weights)
}

/// Every mode's position estimate (entries of modes outside `modes` are left at zero).
#[inline]
pub(super) fn mode_positions(state: &ImmState, modes: ModeSet) -> [PositionEstimate; MODE_COUNT] {
    let mut positions = [PositionEstimate::default(); MODE_COUNT];
    for mode in modes.iter() {
        positions[mode.index()] = state.position(mode);
    }
    positions
}

/// [`mix_positions`] on positions already extracted.
#[inline]
pub(super) fn mix(
    positions: &[PositionEstimate; MODE_COUNT],
    modes: ModeSet,
    weights: &ModeProbabilities,
) -> PositionEstimate {
    let mut mean = DVec2::ZERO;
    for mode in modes.iter() {
        mean += weights[mode.index()] * positions[mode.index()].mean;
    }
    let mut covariance = DMat2::ZERO;
    for mode in modes.iter() {
        let position = &positions[mode.index()];
        let spread = position.mean - mean;
        covariance += (position.covariance + outer(spread, spread)) * weights[mode.index()];
    }
    PositionEstimate { mean, covariance }
}

pub(super) fn outer(a: DVec2, b: DVec2) -> DMat2 {
    DMat2::from_cols(a * b.x, a * b.y)
}

impl Imm {
    /// The fused position and covariance of a posterior (`eq:posterior_fusion`, covariance with
    /// the spread of the mode means) over `modes`, weights `μ` renormalised over them.
    pub fn fuse_posterior(&self, state: &ImmState, modes: ModeSet) -> PositionEstimate {
        mix_positions(state, modes, &renormalised(&state.probabilities, modes))
    }

    /// The fused velocity over `modes`, m/s, weights `μ` renormalised over them; PR's velocity is
    /// its last displacement divided by the step.
    pub fn fuse_velocity(&self, state: &ImmState, modes: ModeSet) -> DVec2 {
        fused_velocity(state, modes)
    }

    /// The fused position and velocity `[x, y, vx, vy]` of a posterior over `modes` and their
    /// 4×4 covariance (with the spread of the mode means), weights `μ` renormalised over them:
    /// `eq:posterior_fusion` extended from the position to the position and velocity. Each
    /// physics mode contributes the `[x, y, vx, vy]` marginal of its state. The PR mode has a
    /// position covariance but no velocity covariance: it contributes its position, its
    /// velocity (last displacement over the step), its position covariance, no
    /// position–velocity covariance, and as velocity covariance the physics modes' fused one
    /// (zero when PR is the only mode). The position block equals
    /// [`fuse_posterior`](Self::fuse_posterior)'s covariance.
    pub fn fuse_position_velocity(&self, state: &ImmState, modes: ModeSet) -> PositionVelocityEstimate {
        let weights = renormalised(&state.probabilities, modes);
        let physics = modes.without(Mode::Learned);
        let mut marginals = [PositionVelocityEstimate::default(); MODE_COUNT];
        for mode in physics.iter() {
            marginals[mode.index()] = match mode {
                Mode::ConstantVelocity => marginal4(&state.constant_velocity),
                Mode::ConstantAcceleration => marginal4(&state.constant_acceleration),
                Mode::CoordinatedTurn => marginal4(&state.coordinated_turn),
                Mode::Learned => unreachable!("left out of the physics modes"),
            };
        }
        if modes.contains(Mode::Learned) {
            let physics_weights = renormalised(&state.probabilities, physics);
            let velocity_covariance: DMat2 = physics
                .iter()
                .map(|mode| {
                    let covariance = marginals[mode.index()].covariance;
                    physics_weights[mode.index()] * lower_right(&covariance)
                })
                .fold(DMat2::ZERO, |sum, term| sum + term);
            let position = state.learned.position();
            let velocity = state.learned_velocity_mps;
            marginals[Mode::Learned.index()] = PositionVelocityEstimate {
                mean: DVec4::new(position.mean.x, position.mean.y, velocity.x, velocity.y),
                covariance: block_diagonal(position.covariance, velocity_covariance),
            };
        }
        let mean: DVec4 = modes.iter().map(|mode| weights[mode.index()] * marginals[mode.index()].mean).sum();
        let covariance = modes
            .iter()
            .map(|mode| {
                let marginal = &marginals[mode.index()];
                let spread = marginal.mean - mean;
                weights[mode.index()] * (marginal.covariance + outer4(spread, spread))
            })
            .fold(DMat4::ZERO, |sum, term| sum + term);
        PositionVelocityEstimate { mean, covariance }
    }
}

/// A position and velocity `[x, y, vx, vy]` (m, m/s) and its covariance (m², m²/s, m²/s²).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PositionVelocityEstimate {
    /// `[x, y, vx, vy]`.
    pub mean: DVec4,
    /// Covariance of `[x, y, vx, vy]`, symmetric.
    pub covariance: DMat4,
}

/// The `[x, y, vx, vy]` marginal of a state whose first four elements are those.
fn marginal4<const N: usize>(gaussian: &Gaussian<N>) -> PositionVelocityEstimate {
    let mean = DVec4::new(gaussian.mean[0], gaussian.mean[1], gaussian.mean[2], gaussian.mean[3]);
    let column = |c: usize| {
        DVec4::new(
            gaussian.covariance[(0, c)],
            gaussian.covariance[(1, c)],
            gaussian.covariance[(2, c)],
            gaussian.covariance[(3, c)],
        )
    };
    PositionVelocityEstimate {
        mean,
        covariance: DMat4::from_cols(column(0), column(1), column(2), column(3)),
    }
}

/// The lower-right 2×2 block of a 4×4 matrix (the velocity block).
fn lower_right(matrix: &DMat4) -> DMat2 {
    DMat2::from_cols(
        DVec2::new(matrix.z_axis.z, matrix.z_axis.w),
        DVec2::new(matrix.w_axis.z, matrix.w_axis.w),
    )
}

/// The 4×4 block-diagonal matrix `diag(upper_left, lower_right)`.
fn block_diagonal(upper_left: DMat2, lower_right: DMat2) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(upper_left.x_axis.x, upper_left.x_axis.y, 0.0, 0.0),
        DVec4::new(upper_left.y_axis.x, upper_left.y_axis.y, 0.0, 0.0),
        DVec4::new(0.0, 0.0, lower_right.x_axis.x, lower_right.x_axis.y),
        DVec4::new(0.0, 0.0, lower_right.y_axis.x, lower_right.y_axis.y),
    )
}

/// `a bᵀ`.
fn outer4(a: DVec4, b: DVec4) -> DMat4 {
    DMat4::from_cols(a * b.x, a * b.y, a * b.z, a * b.w)
}

/// `weights` restricted to `modes` and renormalised to sum to 1 (uniform if they sum to 0).
#[inline]
pub fn renormalised(weights: &ModeProbabilities, modes: ModeSet) -> ModeProbabilities {
    let sum: f64 = modes.iter().map(|m| weights[m.index()]).sum();
    let mut result = [0.0; MODE_COUNT];
    for mode in modes.iter() {
        result[mode.index()] = if sum > 0.0 { weights[mode.index()] / sum } else { 1.0 / modes.len() as f64 };
    }
    result
}
