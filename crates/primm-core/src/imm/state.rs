//! The multi-mode state of one track ([`ImmState`]) and the one per-mode dispatch of the IMM:
//! each mode's Gaussian has its own size, so an operation on "a mode" is generic over that
//! size, and [`for_mode`] picks the instance at run time.

use crate::gaussian::{Gaussian, PositionEstimate};
use crate::mode::{Mode, MODE_COUNT};
use crate::motion::constant_acceleration::index as ca;
use crate::motion::constant_velocity::index as cv;
use crate::motion::coordinated_turn::index as ct;
use crate::motion::{
    ConstantAcceleration, ConstantVelocity, CoordinatedTurn, LearnedDisplacement, ModeModels, MotionModel,
};
use crate::pose::{RigidTransform, RigidVelocity};
use glam::DVec2;
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

    /// Adds the velocity field `field` (times `sign`), taken at each mode's own position, to
    /// every mode's velocity (PR: the velocity of its last displacement).
    pub fn add_velocity_field(&mut self, field: &RigidVelocity, sign: f64) {
        fn add<const N: usize>(gaussian: &mut Gaussian<N>, vx: usize, field: &RigidVelocity, sign: f64) {
            let delta = sign * field.at(DVec2::new(gaussian.mean[0], gaussian.mean[1]));
            gaussian.mean[vx] += delta.x;
            gaussian.mean[vx + 1] += delta.y;
        }
        add(&mut self.constant_velocity, cv::VX, field, sign);
        add(&mut self.constant_acceleration, ca::VX, field, sign);
        add(&mut self.coordinated_turn, ct::VX, field, sign);
        let learned = DVec2::new(self.learned.mean[0], self.learned.mean[1]);
        self.learned_velocity_mps += sign * field.at(learned);
    }

    /// Scales every velocity faster than `max_speed_mps` (CV, CA, CT and PR's last displacement)
    /// back onto that speed, keeping its direction; the covariances are left as they are. Whether
    /// any was.
    pub fn bound_speed(&mut self, max_speed_mps: f64) -> bool {
        fn bound(velocity: DVec2, max_speed_mps: f64) -> Option<DVec2> {
            let speed = velocity.length();
            (speed > max_speed_mps).then(|| velocity * (max_speed_mps / speed))
        }
        fn bound_mode<const N: usize>(gaussian: &mut Gaussian<N>, vx: usize, max_speed_mps: f64) -> bool {
            let velocity = DVec2::new(gaussian.mean[vx], gaussian.mean[vx + 1]);
            let Some(bounded) = bound(velocity, max_speed_mps) else { return false };
            gaussian.mean[vx] = bounded.x;
            gaussian.mean[vx + 1] = bounded.y;
            true
        }
        let mut any = bound_mode(&mut self.constant_velocity, cv::VX, max_speed_mps);
        any |= bound_mode(&mut self.constant_acceleration, ca::VX, max_speed_mps);
        any |= bound_mode(&mut self.coordinated_turn, ct::VX, max_speed_mps);
        if let Some(bounded) = bound(self.learned_velocity_mps, max_speed_mps) {
            self.learned_velocity_mps = bounded;
            any = true;
        }
        any
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
pub(super) trait ModeSlot<const N: usize> {
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
        pub(super) struct $slot;

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
pub(super) trait ModeOperation {
    /// What the operation returns.
    type Output;
    /// Applies the operation to the mode of `S`.
    fn apply<const N: usize, S: ModeSlot<N>>(self) -> Self::Output;
}

/// Applies `operation` to `mode`: the IMM's one per-mode dispatch.
#[inline(always)]
pub(super) fn for_mode<O: ModeOperation>(mode: Mode, operation: O) -> O::Output {
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
pub(super) struct CopyMode<'a> {
    pub(super) from: &'a ImmState,
    pub(super) to: &'a mut ImmState,
}

impl ModeOperation for CopyMode<'_> {
    type Output = ();
    #[inline(always)]
    fn apply<const N: usize, S: ModeSlot<N>>(self) {
        *S::gaussian_mut(self.to) = *S::gaussian(self.from);
    }
}
