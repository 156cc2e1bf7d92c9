//! The position-space Interacting Multiple Model filter of the paper (Sections III-D and III-F).
//!
//! One step of a track:
//! 1. [`Imm::predict`]: prior mode probabilities `c` (`eq:prior_mode_prob`), mixing
//!    probabilities `β` (`eq:mixing_prob`), mixing of the posterior positions and position
//!    covariances with the spread-of-means term (`eq:mixed_pos`, `eq:mixed_pos_cov`), the mixed
//!    position written back into each mode while it keeps its own other states
//!    (`eq:mixed_state` … `eq:reconstructed_cov`), each mode's prediction, and the fused prior
//!    position (`eq:prior_fusion`) that association uses.
//! 2. [`Imm::update`] with the associated measurement: each mode's Kalman update and
//!    likelihood (`eq:innovation` … `eq:posterior_cov`), the tempered mode-probability update
//!    `μ ∝ Λ^τ c` (`eq:mode_update`) computed in log space, the probability floor; the fused
//!    posterior is [`Imm::fuse_posterior`] (`eq:posterior_fusion`).
//!    Without a measurement, [`Imm::coast`] keeps the priors and `μ = c`.
//!
//! The active mode set is configuration; with a single mode every step reduces to that mode's
//! own Kalman filter. If the learned predictor has no displacement for a step, the PR mode sits
//! the step out: its prior probability is spread over the other modes for fusion and the mode
//! update, and afterwards it gets back exactly its prior probability `c_PR` (no evidence either
//! way), the others sharing `1 − c_PR`. Its prior for that step is the fused prior of the other
//! modes (it has no motion of its own to add), so its position stays current for the next
//! mixing.

use crate::config::ImmConfig;
use crate::gaussian::{
    kalman_update_into, radial_velocity_update_in_place, replace_position, to_glam, to_nalgebra,
    PositionEstimate, RadialVelocityObservation, RadialVelocityOutcome, UpdateError,
};
use crate::measurement::Measurement;
use crate::mode::{Mode, ModeSet, MODE_COUNT};
use crate::motion::constant_velocity::index as cv;
use crate::motion::{ModeModels, MotionModel, PredictContext};
use crate::predictor::Displacement;
use glam::DVec2;
use nalgebra::Matrix2;

mod fusion;
mod state;

pub use fusion::{fused_prior, mix_positions, renormalised, ImmPrior, PositionVelocityEstimate};
use fusion::{mix, mode_positions};
use state::{for_mode, CopyMode, ModeOperation, ModeSlot};
pub use state::{ImmState, ModeProbabilities};

/// The IMM's configuration, prepared once: stateless and shared by all tracks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Imm {
    modes: ModeSet,
    transition: [[f64; MODE_COUNT]; MODE_COUNT],
    initial_probabilities: ModeProbabilities,
    temperature: f64,
    floor: f64,
}

/// One mode's Kalman update from `prior` into `posterior` and its log-likelihood; an inactive
/// mode is copied unchanged (its log-likelihood left as it was).
struct UpdateMode<'a> {
    models: &'a ModeModels,
    prior: &'a ImmState,
    posterior: &'a mut ImmState,
    z: DVec2,
    /// Added to each mode's measurement noise (an extended object's reflection spread), m².
    extra_noise_m2: &'a Matrix2<f64>,
    radial_velocity: Option<&'a RadialVelocityObservation>,
    active: bool,
    log_likelihood: &'a mut f64,
    radial_velocity_outcome: &'a mut Option<RadialVelocityOutcome>,
}

impl ModeOperation for UpdateMode<'_> {
    type Output = Result<(), UpdateError>;
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) -> Result<(), UpdateError> {
        let (prior, posterior) = (S::gaussian(self.prior), S::gaussian_mut(self.posterior));
        if !self.active {
            *posterior = *prior;
            return Ok(());
        }
        let noise = S::model(self.models).measurement_noise() + self.extra_noise_m2;
        *self.log_likelihood = kalman_update_into(prior, self.z, &noise, posterior)?.log_likelihood;
        // The radial-velocity row follows the position rows in the modes that carry a velocity
        // (PR's state is the position alone). The mode's likelihood stays that of the position
        // rows, so that all modes, PR included, are compared on the same evidence.
        if let (Some(observation), Some(velocity)) = (self.radial_velocity, S::VELOCITY_INDEX) {
            *self.radial_velocity_outcome =
                Some(radial_velocity_update_in_place(posterior, velocity, observation)?);
        }
        Ok(())
    }
}

/// One mode's start (its posterior with the mixed position written in, `eq:mixed_state` …
/// `eq:reconstructed_cov`) written into `prior` and, for CV, CA and CT, predicted. PR's
/// prediction needs the learned displacement and waits for [`Imm::complete_prior_in_place`].
struct MixAndPredict<'a> {
    models: &'a ModeModels,
    posterior: &'a ImmState,
    mixed: &'a PositionEstimate,
    context: &'a PredictContext,
    prior: &'a mut ImmState,
}

impl ModeOperation for MixAndPredict<'_> {
    type Output = ();
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) {
        let prior = S::gaussian_mut(self.prior);
        *prior = *S::gaussian(self.posterior);
        // With nothing to mix (a single mode, or all weight on itself) the write-back is the
        // identity; skipping it keeps single-mode filtering bit-identical to a plain filter.
        if prior.position() != *self.mixed {
            replace_position(prior, self.mixed);
        }
        // PR's prediction waits for the learned displacement (`complete_prior_in_place`).
        if S::MODE != Mode::Learned {
            S::model(self.models).predict_in_place(prior, self.context);
        }
    }
}

impl Imm {
    /// Prepares the IMM from validated configuration: the transition matrix is restricted to
    /// the active modes and each row renormalised; so are the initial probabilities.
    pub fn new(config: &ImmConfig) -> Self {
        let modes = config.modes;
        let mut transition = [[0.0; MODE_COUNT]; MODE_COUNT];
        for from in modes.iter() {
            let row_sum: f64 = modes.iter().map(|to| config.transition[from.index()][to.index()]).sum();
            for to in modes.iter() {
                transition[from.index()][to.index()] = config.transition[from.index()][to.index()] / row_sum;
            }
        }
        let mut initial_probabilities = [0.0; MODE_COUNT];
        let initial_sum: f64 = modes.iter().map(|m| config.initial_mode_probabilities[m.index()]).sum();
        for mode in modes.iter() {
            initial_probabilities[mode.index()] =
                config.initial_mode_probabilities[mode.index()] / initial_sum;
        }
        let mut imm = Self {
            modes,
            transition,
            initial_probabilities,
            temperature: config.likelihood_temperature,
            floor: config.mode_probability_floor,
        };
        imm.initial_probabilities = imm.apply_floor(imm.initial_probabilities);
        imm
    }

    /// The active modes.
    pub fn modes(&self) -> ModeSet {
        self.modes
    }

    /// The prepared transition matrix over the active modes.
    pub fn transition(&self) -> &[[f64; MODE_COUNT]; MODE_COUNT] {
        &self.transition
    }

    /// A new track's state from its first measurement, seen from the frame's origin.
    pub fn initiate(&self, models: &ModeModels, measurement: &Measurement) -> ImmState {
        self.initiate_seen_from(models, measurement, DVec2::ZERO)
    }

    /// A new track's state from its first measurement, seen by a radar at `sensor_position_m`
    /// (same frame as the measurement): the line of sight of the radial velocity starts there.
    pub fn initiate_seen_from(
        &self,
        models: &ModeModels,
        measurement: &Measurement,
        sensor_position_m: DVec2,
    ) -> ImmState {
        let constant_velocity = models.constant_velocity.initiate_seen_from(measurement, sensor_position_m);
        ImmState {
            learned: models.learned.initiate_seen_from(measurement, sensor_position_m),
            constant_velocity,
            constant_acceleration: models
                .constant_acceleration
                .initiate_seen_from(measurement, sensor_position_m),
            coordinated_turn: models.coordinated_turn.initiate_seen_from(measurement, sensor_position_m),
            probabilities: self.initial_probabilities,
            learned_velocity_mps: DVec2::new(constant_velocity.mean[cv::VX], constant_velocity.mean[cv::VY]),
        }
    }

    /// Prior mode probabilities `c_j = Σ_i π_ij μ_i` (`eq:prior_mode_prob`).
    #[inline]
    pub fn prior_probabilities(&self, posterior: &ModeProbabilities) -> ModeProbabilities {
        let mut c = [0.0; MODE_COUNT];
        for to in self.modes.iter() {
            c[to.index()] = self
                .modes
                .iter()
                .map(|from| self.transition[from.index()][to.index()] * posterior[from.index()])
                .sum();
        }
        c
    }

    /// Mixing probabilities `β_ij = π_ij μ_i / c_j` (`eq:mixing_prob`) into mode `to`.
    #[inline]
    pub fn mixing_probabilities(
        &self,
        posterior: &ModeProbabilities,
        prior: &ModeProbabilities,
        to: Mode,
    ) -> ModeProbabilities {
        let mut beta = [0.0; MODE_COUNT];
        let c = prior[to.index()];
        if c > 0.0 {
            for from in self.modes.iter() {
                beta[from.index()] = self.transition[from.index()][to.index()] * posterior[from.index()] / c;
            }
        } else {
            beta[to.index()] = 1.0;
        }
        beta
    }

    /// Mixing, per-mode prediction and prior fusion in one call:
    /// [`predict_physics_into`](Self::predict_physics_into) followed by
    /// [`complete_prior_in_place`](Self::complete_prior_in_place).
    pub fn predict(&self, models: &ModeModels, posterior: &ImmState, context: &PredictContext) -> ImmPrior {
        let mut prior = ImmPrior::default();
        self.predict_physics_into(models, posterior, context.dt_s, &mut prior);
        let displacement = context.displacement_m.map(|mean_m| Displacement {
            mean_m,
            covariance_m2: context.displacement_covariance_m2.as_ref().map(to_glam),
            from_latest_m: None,
        });
        self.complete_prior_in_place(models, &mut prior, context.dt_s, displacement);
        prior
    }

    /// First half of the prediction, which needs no learned displacement, written into `prior`
    /// in place (no copy of the multi-mode state): prior mode probabilities, mixing of every
    /// mode, and the CV, CA and CT predictions. The PR mode is left at its mixed starting point.
    /// Lets the caller predict the physics modes while the learned predictor is still running.
    /// `prior.available` and `prior.fused` are only meaningful after
    /// [`complete_prior_in_place`](Self::complete_prior_in_place).
    #[inline(always)]
    pub fn predict_physics_into(
        &self,
        models: &ModeModels,
        posterior: &ImmState,
        dt_s: f64,
        prior: &mut ImmPrior,
    ) {
        let c = self.prior_probabilities(&posterior.probabilities);
        let positions = mode_positions(posterior, self.modes);
        let context = &PredictContext { dt_s, displacement_m: None, displacement_covariance_m2: None };
        let state = &mut prior.state;
        state.probabilities = c;
        state.learned_velocity_mps = posterior.learned_velocity_mps;
        for mode in self.modes.iter() {
            let beta = self.mixing_probabilities(&posterior.probabilities, &c, mode);
            let mixed = mix(&positions, self.modes, &beta);
            for_mode(mode, MixAndPredict { models, posterior, mixed: &mixed, context, prior: state });
        }
        // Inactive modes are carried along unchanged, so that no stale values linger.
        for mode in ModeSet::ALL.iter().filter(|mode| !self.modes.contains(*mode)) {
            for_mode(mode, CopyMode { from: posterior, to: state });
        }
        prior.available = self.modes;
    }

    /// Second half of the prediction, in place on a prior filled by
    /// [`predict_physics_into`](Self::predict_physics_into) for the same `dt_s`: the PR prior
    /// from the learned displacement (`eq:pr_prior`, `eq:pr_cov`) and the fused prior
    /// (`eq:prior_fusion`). Without a displacement the PR mode sits the step out (see the
    /// module documentation).
    #[inline(always)]
    pub fn complete_prior_in_place(
        &self,
        models: &ModeModels,
        prior: &mut ImmPrior,
        dt_s: f64,
        displacement: Option<Displacement>,
    ) {
        let state = &mut prior.state;
        if self.modes.contains(Mode::Learned) {
            let context = PredictContext {
                dt_s,
                displacement_m: displacement.map(|d| d.mean_m),
                displacement_covariance_m2: displacement
                    .and_then(|d| d.covariance_m2)
                    .map(|q| to_nalgebra(&q)),
            };
            state.learned = models.learned.predict(&state.learned, &context);
            if let Some(displacement) = displacement {
                state.learned_velocity_mps = displacement.mean_m / dt_s;
            }
        }
        let mut available = self.modes;
        if displacement.is_none() && self.modes.len() > 1 {
            available = available.without(Mode::Learned);
        }
        prior.available = available;
        prior.fused = fused_prior(state, available);
        if available != self.modes && self.modes.contains(Mode::Learned) {
            // Sitting out, the PR mode takes the fused physics prior instead of its own
            // position of the previous step, which nothing moved: it stays current, and no
            // stale position reaches the other modes through the next mixing.
            replace_position(&mut state.learned, &prior.fused);
        }
    }

    /// Kalman update of every active mode with measurement `z`, tempered mode-probability
    /// update and floor. On a numerical failure of any mode the prior is left as it was.
    pub fn update(&self, models: &ModeModels, prior: &ImmPrior, z: DVec2) -> Result<ImmState, UpdateError> {
        let mut state = ImmState::default();
        self.update_into(models, prior, z, &mut state)?;
        Ok(state)
    }

    /// [`update`](Self::update) written into `posterior` in place. On error `posterior` holds
    /// the prior's state (the track coasts; nothing half-updated is left behind).
    #[inline(always)]
    pub fn update_into(
        &self,
        models: &ModeModels,
        prior: &ImmPrior,
        z: DVec2,
        posterior: &mut ImmState,
    ) -> Result<(), UpdateError> {
        self.update_with_radial_velocity_into(models, prior, z, &Matrix2::zeros(), None, posterior)
            .map(|_| ())
    }

    /// [`update_into`](Self::update_into) with `extra_noise_m2` added to every mode's
    /// measurement noise (the reflection spread of an extended object, `crate::extent`; zero
    /// for a point), followed, in every active mode with a velocity (CV,
    /// CA, CT), by the extended Kalman row of the measurement's radial velocity
    /// ([`radial_velocity_update_in_place`]) when `radial_velocity` is given. Returns what the
    /// row did: `Applied` if it was applied in any mode, else `Gated` if any mode gated it, else
    /// `NoLineOfSight`; `None` without a row (or without an active mode with a velocity).
    #[inline(always)]
    pub fn update_with_radial_velocity_into(
        &self,
        models: &ModeModels,
        prior: &ImmPrior,
        z: DVec2,
        extra_noise_m2: &Matrix2<f64>,
        radial_velocity: Option<&RadialVelocityObservation>,
        posterior: &mut ImmState,
    ) -> Result<Option<RadialVelocityOutcome>, UpdateError> {
        match self.update_modes(models, prior, z, extra_noise_m2, radial_velocity, posterior) {
            Ok((log_likelihood, outcomes)) => {
                posterior.probabilities =
                    self.updated_probabilities(&prior.state.probabilities, prior.available, &log_likelihood);
                posterior.learned_velocity_mps = prior.state.learned_velocity_mps;
                let outcome = [
                    RadialVelocityOutcome::Applied,
                    RadialVelocityOutcome::Gated,
                    RadialVelocityOutcome::NoLineOfSight,
                ]
                .into_iter()
                .find(|wanted| outcomes.contains(&Some(*wanted)));
                Ok(outcome)
            }
            Err(error) => {
                *posterior = prior.state;
                Err(error)
            }
        }
    }

    /// Each mode's Kalman update from `prior` into `posterior` (inactive modes are copied);
    /// the log-likelihoods. Stops at the first failing mode.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn update_modes(
        &self,
        models: &ModeModels,
        prior: &ImmPrior,
        z: DVec2,
        extra_noise_m2: &Matrix2<f64>,
        radial_velocity: Option<&RadialVelocityObservation>,
        posterior: &mut ImmState,
    ) -> Result<(ModeProbabilities, [Option<RadialVelocityOutcome>; MODE_COUNT]), UpdateError> {
        let mut log_likelihood = [f64::NEG_INFINITY; MODE_COUNT];
        let mut outcomes = [None; MODE_COUNT];
        for mode in ModeSet::ALL.iter() {
            for_mode(
                mode,
                UpdateMode {
                    models,
                    prior: &prior.state,
                    posterior: &mut *posterior,
                    z,
                    extra_noise_m2,
                    radial_velocity,
                    active: self.modes.contains(mode),
                    log_likelihood: &mut log_likelihood[mode.index()],
                    radial_velocity_outcome: &mut outcomes[mode.index()],
                },
            )?;
        }
        Ok((log_likelihood, outcomes))
    }

    /// `μ_i ∝ Λ_i^τ c_i` over the available modes (`eq:mode_update`), in log space; a mode that
    /// sat the step out keeps its prior probability; then the floor.
    #[inline(always)]
    pub fn updated_probabilities(
        &self,
        prior: &ModeProbabilities,
        available: ModeSet,
        log_likelihood: &ModeProbabilities,
    ) -> ModeProbabilities {
        let weights = renormalised(prior, available);
        // μ_i ∝ exp(τ ℓ_i − max_j τ ℓ_j) · c_i: the shift by the largest tempered
        // log-likelihood keeps the exponentials in range, and the mode attaining it keeps a
        // positive weight, so the sum cannot vanish.
        let mut largest = f64::NEG_INFINITY;
        for mode in available.iter() {
            let i = mode.index();
            if weights[i] > 0.0 {
                largest = largest.max(self.temperature * log_likelihood[i]);
            }
        }
        let mut mu = [0.0; MODE_COUNT];
        let mut sum = 0.0;
        for mode in available.iter() {
            let i = mode.index();
            if weights[i] > 0.0 {
                mu[i] = crate::math::exp(self.temperature * log_likelihood[i] - largest) * weights[i];
                sum += mu[i];
            }
        }
        let sitting_out: f64 =
            self.modes.iter().filter(|m| !available.contains(*m)).map(|m| prior[m.index()]).sum();
        for mode in self.modes.iter() {
            let i = mode.index();
            mu[i] = if available.contains(mode) { mu[i] / sum * (1.0 - sitting_out) } else { prior[i] };
        }
        self.apply_floor(mu)
    }

    /// A step without measurement: the priors become the posteriors and `μ = c`.
    pub fn coast(&self, prior: &ImmPrior) -> ImmState {
        prior.state
    }

    /// Raises every active mode's probability to at least the floor and renormalises, keeping
    /// the floored modes at exactly the floor.
    #[inline]
    pub fn apply_floor(&self, mut mu: ModeProbabilities) -> ModeProbabilities {
        if self.floor <= 0.0 || self.modes.iter().all(|mode| mu[mode.index()] >= self.floor) {
            return mu;
        }
        let mut floored = ModeSet::EMPTY;
        for _ in 0..MODE_COUNT {
            let mut changed = false;
            for mode in self.modes.iter() {
                if !floored.contains(mode) && mu[mode.index()] < self.floor {
                    floored = floored.with(mode);
                    changed = true;
                }
            }
            let free: f64 = self.modes.iter().filter(|m| !floored.contains(*m)).map(|m| mu[m.index()]).sum();
            let target = 1.0 - self.floor * floored.len() as f64;
            for mode in self.modes.iter() {
                let i = mode.index();
                mu[i] = if floored.contains(mode) { self.floor } else { mu[i] * target / free };
            }
            if !changed {
                break;
            }
        }
        mu
    }
}
