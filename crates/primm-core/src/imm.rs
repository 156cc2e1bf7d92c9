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
//! way), the others sharing `1 − c_PR`.

use crate::config::ImmConfig;
use crate::extent::ObjectPrior;
use crate::gaussian::{
    kalman_update_into, radial_velocity_update_in_place, replace_position, to_glam, to_nalgebra, Gaussian,
    PositionEstimate, RadialVelocityObservation, RadialVelocityOutcome, UpdateError,
};
use crate::measurement::Measurement;
use crate::mode::{Mode, ModeSet, MODE_COUNT};
use crate::motion::constant_acceleration::index as ca;
use crate::motion::constant_velocity::index as cv;
use crate::motion::coordinated_turn::index as ct;
use crate::motion::{
    ConstantAcceleration, ConstantVelocity, CoordinatedTurn, LearnedDisplacement, ModeModels, MotionModel,
    PredictContext,
};
use crate::pose::RigidTransform;
use crate::predictor::Displacement;
use glam::{DMat2, DMat4, DVec2, DVec4};
use nalgebra::Matrix2;

/// Mode probabilities in primm's mode order (PR, CV, CA, CT); inactive modes hold 0.
pub type ModeProbabilities = [f64; MODE_COUNT];

/// A track's estimate in every mode plus the mode probabilities: a small `Copy` value.
/// Inactive modes are carried but never read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImmState {
    /// PR mode, `[x, y]`.
    pub learned: Gaussian<2>,
    /// CV mode, `[x, y, vx, vy]`.
    pub constant_velocity: Gaussian<4>,
    /// CA mode, `[x, y, vx, vy, ax, ay]`.
    pub constant_acceleration: Gaussian<6>,
    /// CT mode, `[x, y, vx, vy, ω]`.
    pub coordinated_turn: Gaussian<5>,
    /// Mode probabilities `μ` (posterior) or `c` (in a prior).
    pub probabilities: ModeProbabilities,
    /// Velocity implied by the last learned displacement, m/s (PR's only velocity estimate).
    pub learned_velocity_mps: DVec2,
}

impl ImmState {
    /// The position marginal of one mode.
    pub fn position(&self, mode: Mode) -> PositionEstimate {
        for_mode(mode, Position(self))
    }

    /// The velocity estimate of one mode, m/s (PR: displacement over the last step).
    pub fn velocity(&self, mode: Mode) -> DVec2 {
        for_mode(mode, Velocity(self))
    }

    /// Adds `covariance_m2` to every mode's position covariance (the cross terms unchanged):
    /// a new extended object's reflection spread.
    pub fn add_position_covariance(&mut self, covariance_m2: &Matrix2<f64>) {
        fn add<const N: usize>(gaussian: &mut Gaussian<N>, covariance_m2: &Matrix2<f64>) {
            let mut block = gaussian.covariance.fixed_view_mut::<2, 2>(0, 0);
            block += covariance_m2;
        }
        add(&mut self.learned, covariance_m2);
        add(&mut self.constant_velocity, covariance_m2);
        add(&mut self.constant_acceleration, covariance_m2);
        add(&mut self.coordinated_turn, covariance_m2);
    }

    /// This state in another frame (see [`Gaussian::transformed`]): positions mapped,
    /// velocities and accelerations rotated, turn rate and mode probabilities unchanged.
    pub fn transformed(&self, transform: &RigidTransform) -> Self {
        ImmState {
            learned: self.learned.transformed(transform, &[]),
            constant_velocity: self.constant_velocity.transformed(transform, &[cv::VX]),
            constant_acceleration: self.constant_acceleration.transformed(transform, &[ca::VX, ca::AX]),
            coordinated_turn: self.coordinated_turn.transformed(transform, &[ct::VX]),
            probabilities: self.probabilities,
            learned_velocity_mps: transform.apply_vector(self.learned_velocity_mps),
        }
    }
}

/// Where one mode lives, for a state of size `N`: its Gaussian in an [`ImmState`] and its model
/// in [`ModeModels`]. One zero-sized type per mode implements it, so that [`for_mode`] can hand
/// a [`ModeOperation`] the mode's state size, model and fields at compile time.
trait ModeSlot<const N: usize> {
    /// The mode.
    const MODE: Mode;
    /// The mode's motion model.
    type Model: MotionModel<N>;
    /// The mode's model among a class's models.
    fn model(models: &ModeModels) -> &Self::Model;
    /// The mode's Gaussian in `state`.
    fn gaussian(state: &ImmState) -> &Gaussian<N>;
    /// The mode's Gaussian in `state`, to write.
    fn gaussian_mut(state: &mut ImmState) -> &mut Gaussian<N>;
    /// The mode's velocity estimate in `state`, m/s.
    fn velocity(state: &ImmState) -> DVec2;
    /// Where the mode's state holds its velocity `[vx, vy]` (`None`: it has none).
    const VELOCITY_INDEX: Option<usize>;
}

/// Declares a mode's [`ModeSlot`]: `slot: mode, field (of ImmState and ModeModels), N, model,
/// |state| velocity`.
macro_rules! mode_slot {
    ($(#[$doc:meta])* $slot:ident: $mode:ident, $field:ident, $n:literal, $model:ty, $velocity_index:expr,
     |$state:ident| $velocity:expr) => {
        $(#[$doc])*
        struct $slot;

        impl ModeSlot<$n> for $slot {
            const MODE: Mode = Mode::$mode;
            const VELOCITY_INDEX: Option<usize> = $velocity_index;
            type Model = $model;
            #[inline(always)]
            fn model(models: &ModeModels) -> &$model {
                &models.$field
            }
            #[inline(always)]
            fn gaussian(state: &ImmState) -> &Gaussian<$n> {
                &state.$field
            }
            #[inline(always)]
            fn gaussian_mut(state: &mut ImmState) -> &mut Gaussian<$n> {
                &mut state.$field
            }
            #[inline(always)]
            fn velocity($state: &ImmState) -> DVec2 {
                $velocity
            }
        }
    };
}

mode_slot!(
    /// PR, whose state has no velocity: the velocity of its last displacement.
    LearnedSlot: Learned, learned, 2, LearnedDisplacement, None, |state| state.learned_velocity_mps
);
mode_slot!(
    /// CV.
    ConstantVelocitySlot: ConstantVelocity, constant_velocity, 4, ConstantVelocity, Some(cv::VX),
    |state| DVec2::new(state.constant_velocity.mean[cv::VX], state.constant_velocity.mean[cv::VY])
);
mode_slot!(
    /// CA.
    ConstantAccelerationSlot: ConstantAcceleration, constant_acceleration, 6, ConstantAcceleration, Some(ca::VX),
    |state| DVec2::new(state.constant_acceleration.mean[ca::VX], state.constant_acceleration.mean[ca::VY])
);
mode_slot!(
    /// CT.
    CoordinatedTurnSlot: CoordinatedTurn, coordinated_turn, 5, CoordinatedTurn, Some(ct::VX),
    |state| DVec2::new(state.coordinated_turn.mean[ct::VX], state.coordinated_turn.mean[ct::VY])
);

/// An operation on one mode, generic over the mode's state size and [`ModeSlot`].
trait ModeOperation {
    /// What the operation returns.
    type Output;
    /// Applies the operation to the mode of `S`.
    fn apply<const N: usize, S: ModeSlot<N>>(self) -> Self::Output;
}

/// Applies `operation` to `mode`: the IMM's one per-mode dispatch.
#[inline(always)]
fn for_mode<O: ModeOperation>(mode: Mode, operation: O) -> O::Output {
    match mode {
        Mode::Learned => operation.apply::<2, LearnedSlot>(),
        Mode::ConstantVelocity => operation.apply::<4, ConstantVelocitySlot>(),
        Mode::ConstantAcceleration => operation.apply::<6, ConstantAccelerationSlot>(),
        Mode::CoordinatedTurn => operation.apply::<5, CoordinatedTurnSlot>(),
    }
}

/// A mode's position marginal.
struct Position<'a>(&'a ImmState);

impl ModeOperation for Position<'_> {
    type Output = PositionEstimate;
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) -> PositionEstimate {
        S::gaussian(self.0).position()
    }
}

/// A mode's velocity estimate, m/s.
struct Velocity<'a>(&'a ImmState);

impl ModeOperation for Velocity<'_> {
    type Output = DVec2;
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) -> DVec2 {
        S::velocity(self.0)
    }
}

/// A mode's Gaussian copied from one state into another.
struct CopyMode<'a> {
    from: &'a ImmState,
    to: &'a mut ImmState,
}

impl ModeOperation for CopyMode<'_> {
    type Output = ();
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) {
        *S::gaussian_mut(self.to) = *S::gaussian(self.from);
    }
}

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
fn fused_velocity(state: &ImmState, modes: ModeSet) -> DVec2 {
    let weights = renormalised(&state.probabilities, modes);
    modes.iter().map(|mode| weights[mode.index()] * state.velocity(mode)).sum()
}

/// The IMM's configuration, prepared once: stateless and shared by all tracks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Imm {
    modes: ModeSet,
    transition: [[f64; MODE_COUNT]; MODE_COUNT],
    initial_probabilities: ModeProbabilities,
    temperature: f64,
    floor: f64,
}

/// Weighted mean and covariance with the spread-of-means term
/// (`eq:mixed_pos`, `eq:mixed_pos_cov`); weights must sum to 1 over `modes`.
#[inline]
pub fn mix_positions(state: &ImmState, modes: ModeSet, weights: &ModeProbabilities) -> PositionEstimate {
    mix(&mode_positions(state, modes), modes, weights)
}

/// Every mode's position estimate (entries of modes outside `modes` are left at zero).
#[inline]
fn mode_positions(state: &ImmState, modes: ModeSet) -> [PositionEstimate; MODE_COUNT] {
    let mut positions = [PositionEstimate::default(); MODE_COUNT];
    for mode in modes.iter() {
        positions[mode.index()] = state.position(mode);
    }
    positions
}

/// [`mix_positions`] on positions already extracted.
#[inline]
fn mix(
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

fn outer(a: DVec2, b: DVec2) -> DMat2 {
    DMat2::from_cols(a * b.x, a * b.y)
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
        prior.fused = mix_positions(state, available, &renormalised(&state.probabilities, available));
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
