//! Stateless motion models, one per IMM mode, shared by all tracks of a class.
//!
//! Each model turns a posterior into a prior over a time step `Δt` taken from frame timestamps
//! (`eq:kf_state_pred`, `eq:kf_cov_pred`) and initiates its state from a first measurement.
//! Every state puts position first so that `H = [I₂ 0]` for all modes.
//!
//! Process noise is continuous-time white noise integrated over `Δt` (Bar-Shalom, Li and
//! Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, §6.2), so it
//! scales correctly when `Δt` varies from frame to frame:
//!
//! | mode | noise | per axis `Q(Δt)` |
//! |---|---|---|
//! | CV | white acceleration, PSD `q` m²/s³ | `q·[Δt³/3 Δt²/2; Δt²/2 Δt]` |
//! | CA | white jerk, PSD `q` m²/s⁵ | `q·[Δt⁵/20 Δt⁴/8 Δt³/6; Δt⁴/8 Δt³/3 Δt²/2; Δt³/6 Δt²/2 Δt]` |
//! | CT | white acceleration on x, y, vx, vy as CV; turn-rate random walk PSD `q_ω` rad²/s³ | `q_ω·Δt` on ω |
//! | PR | `Q_PR` per prediction, as in `eq:pr_cov` | constant |

pub mod constant_acceleration;
pub mod constant_velocity;
pub mod coordinated_turn;
pub mod learned;

pub use constant_acceleration::ConstantAcceleration;
pub use constant_velocity::ConstantVelocity;
pub use coordinated_turn::CoordinatedTurn;
pub use learned::LearnedDisplacement;

use crate::config::{ClassConfig, RadialLineOfSight, RadialVelocityUpdateConfig};
use crate::extent::{ExpectedReflection, ExtentConfig, ObjectPrior};
use crate::gaussian::{Gaussian, RadialVelocityObservation};
use crate::measurement::Measurement;
use crate::sensor_noise::MeasurementSensor;
use glam::DVec2;
use index::{VX, VY, X, Y};
use nalgebra::{Matrix2, Vector2};

/// Named indices of the position-velocity layout `[x, y, vx, vy, …]` with which the CV, CA
/// and CT states begin (each model's own `index` module re-exports these and names the rest).
pub mod index {
    pub use crate::gaussian::index::{X, Y};
    /// x velocity, m/s.
    pub const VX: usize = 2;
    /// y velocity, m/s.
    pub const VY: usize = 3;
}

/// What a prediction needs besides the posterior.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictContext {
    /// Time step, s (> 0).
    pub dt_s: f64,
    /// Displacement predicted by the learned predictor for this track and step, m; `None` when
    /// no prediction is available (the PR mode then sits this step out).
    pub displacement_m: Option<DVec2>,
    /// The learned predictor's covariance of that displacement, m², to be used as this track's
    /// `Q_PR` for this step (`eq:pr_cov`); `None`: the PR model's configured constant.
    pub displacement_covariance_m2: Option<Matrix2<f64>>,
}

/// A stateless motion model of state size `N` (position first).
pub trait MotionModel<const N: usize> {
    /// The state of a new track from its first measurement, seen by a radar at
    /// `sensor_position_m` (in the frame of the measurement's position): the origin of the line
    /// of sight along which the radial velocity was measured.
    fn initiate_seen_from(&self, measurement: &Measurement, sensor_position_m: DVec2) -> Gaussian<N>;
    /// [`initiate_seen_from`](Self::initiate_seen_from) a radar at the frame's origin.
    fn initiate(&self, measurement: &Measurement) -> Gaussian<N> {
        self.initiate_seen_from(measurement, DVec2::ZERO)
    }
    /// The prior after `context.dt_s` (`eq:kf_state_pred`, `eq:kf_cov_pred`).
    fn predict(&self, posterior: &Gaussian<N>, context: &PredictContext) -> Gaussian<N>;
    /// [`predict`](Self::predict) in place: turns a posterior into the prior. Linear models
    /// override it to avoid temporary copies of the state.
    fn predict_in_place(&self, estimate: &mut Gaussian<N>, context: &PredictContext) {
        *estimate = self.predict(estimate, context);
    }
    /// The measurement noise covariance `R` of this mode, m².
    fn measurement_noise(&self) -> Matrix2<f64>;
}

/// The four mode models of one object class.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeModels {
    /// PR.
    pub learned: LearnedDisplacement,
    /// CV.
    pub constant_velocity: ConstantVelocity,
    /// CA.
    pub constant_acceleration: ConstantAcceleration,
    /// CT.
    pub coordinated_turn: CoordinatedTurn,
    /// The radial velocity as a measurement of the CV, CA and CT velocities.
    pub radial_velocity_update: RadialVelocityUpdateConfig,
    /// The class's extent, when it is tracked as an extended object (`None`: a point).
    pub extent: Option<ExtentConfig>,
}

impl ModeModels {
    /// Models from a class's configuration section.
    pub fn from_config(class: &ClassConfig) -> Self {
        let initial_velocity = InitialVelocity {
            radial_std_mps: class.initial_radial_speed_std_mps,
            tangential_std_mps: class.initial_tangential_speed_std_mps,
        };
        let r = crate::config::to_matrix(&class.measurement_noise_covariance_m2);
        Self {
            learned: LearnedDisplacement::new(
                crate::config::to_matrix(&class.learned.process_noise_covariance_m2),
                crate::config::to_matrix(&class.learned.measurement_noise_covariance_m2),
            ),
            constant_velocity: ConstantVelocity::new(
                class.constant_velocity.acceleration_psd_m2_per_s3,
                r,
                initial_velocity,
            ),
            constant_acceleration: ConstantAcceleration::new(
                class.constant_acceleration.jerk_psd_m2_per_s5,
                class.constant_acceleration.initial_acceleration_std_mps2,
                r,
                initial_velocity,
            ),
            coordinated_turn: CoordinatedTurn::new(
                class.coordinated_turn.acceleration_psd_m2_per_s3,
                class.coordinated_turn.turn_rate_psd_rad2_per_s3,
                class.coordinated_turn.initial_turn_rate_std_radps,
                r,
                initial_velocity,
            )
            .with_max_turn_rate(class.coordinated_turn.max_turn_rate_radps),
            radial_velocity_update: class.radial_velocity_update,
            extent: class.extent.enabled.then_some(class.extent),
        }
    }

    /// Where the reflection of a track of this class is expected (a point class: no offset, no
    /// spread), for its fused prior `object` and a sensor at `sensor_position_m` whose
    /// measurement model scales the outline offset by `scale`.
    pub fn expected_reflection(
        &self,
        object: &ObjectPrior,
        sensor_position_m: DVec2,
        scale: f64,
    ) -> ExpectedReflection {
        match &self.extent {
            Some(extent) => crate::extent::expected_reflection(extent, object, sensor_position_m, scale),
            None => ExpectedReflection::POINT,
        }
    }

    /// The radial-velocity row for `measurement` seen by the radar `sensor` (position in the
    /// frame of the state, and the detection's own noise), with the expected reflection's
    /// offset from the object's centre `reflection_offset_m` (zero for a point), or `None` when
    /// this class's `radial_velocity_update` is off.
    pub fn radial_velocity_observation(
        &self,
        measurement: &Measurement,
        sensor: &MeasurementSensor,
        reflection_offset_m: DVec2,
    ) -> Option<RadialVelocityObservation> {
        let sensor_position_m = sensor.position_m;
        let update = &self.radial_velocity_update;
        if !update.enabled {
            return None;
        }
        let (measured_line_of_sight, line_of_sight_variance_rad2, reflection_offset_m) =
            match update.line_of_sight {
                RadialLineOfSight::Predicted => (None, 0.0, DVec2::ZERO),
                RadialLineOfSight::Reflection => (None, 0.0, reflection_offset_m),
                RadialLineOfSight::Measured => {
                    let offset = DVec2::new(measurement.x_m, measurement.y_m) - sensor_position_m;
                    let range = offset.length();
                    if !(range >= crate::gaussian::MIN_LINE_OF_SIGHT_RANGE_M) {
                        return None;
                    }
                    let along = offset / range;
                    // The detection's noise across the line of sight, over the range: the
                    // direction's variance (the class's noise and the radar's own).
                    let across = Vector2::new(-along.y, along.x);
                    let noise = self.constant_velocity.measurement_noise()
                        + crate::gaussian::to_nalgebra(&sensor.noise_m2);
                    let across_variance_m2 = (across.transpose() * noise * across)[(0, 0)];
                    (Some(along), across_variance_m2 / (range * range), DVec2::ZERO)
                }
            };
        Some(RadialVelocityObservation {
            radial_velocity_mps: measurement.radial_velocity_mps,
            sensor_position_m,
            variance_mps2: crate::math::square(update.std_mps),
            gate_std: update.gate_std,
            measured_line_of_sight,
            line_of_sight_variance_rad2,
            reflection_offset_m,
        })
    }
}

/// How a new track's velocity is initialised from one measurement (paper, Section III-B:
/// "initialised from the measured radial velocity").
///
/// The radial velocity measures the velocity component along the line of sight, so the initial
/// velocity is `v_r·û` with `û` the unit vector from the sensor to the measurement; its
/// covariance is `σ_r²ûûᵀ + σ_t²ŵŵᵀ` with `ŵ ⟂ û`: tight along the line of sight, wide across it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialVelocity {
    /// Standard deviation along the line of sight (the radial-velocity noise), m/s.
    pub radial_std_mps: f64,
    /// Standard deviation across the line of sight (unobserved), m/s.
    pub tangential_std_mps: f64,
}

impl InitialVelocity {
    /// Mean and covariance of the initial velocity for `measurement` seen by a radar at
    /// `sensor_position_m` (same frame as the measurement).
    pub fn estimate(
        &self,
        measurement: &Measurement,
        sensor_position_m: DVec2,
    ) -> (Vector2<f64>, Matrix2<f64>) {
        let position =
            Vector2::new(measurement.x_m - sensor_position_m.x, measurement.y_m - sensor_position_m.y);
        let range = position.norm();
        let along = if range > 1e-6 { position / range } else { Vector2::new(1.0, 0.0) };
        let across = Vector2::new(-along.y, along.x);
        let mean = along * measurement.radial_velocity_mps;
        let covariance = along * along.transpose() * crate::math::square(self.radial_std_mps)
            + across * across.transpose() * crate::math::square(self.tangential_std_mps);
        (mean, covariance)
    }
}

/// A state of size `N` with the measured position (covariance `R`) and the line-of-sight
/// velocity of [`InitialVelocity`] at [`VX`](index::VX) and [`VY`](index::VY); every other
/// element zero.
pub(crate) fn initiate_position_velocity<const N: usize>(
    measurement: &Measurement,
    sensor_position_m: DVec2,
    measurement_noise_m2: &Matrix2<f64>,
    initial_velocity: &InitialVelocity,
) -> Gaussian<N> {
    let (velocity, velocity_covariance) = initial_velocity.estimate(measurement, sensor_position_m);
    let mut gaussian: Gaussian<N> = Gaussian::new(nalgebra::SVector::zeros(), nalgebra::SMatrix::zeros());
    gaussian.mean[X] = measurement.x_m;
    gaussian.mean[Y] = measurement.y_m;
    gaussian.mean[VX] = velocity.x;
    gaussian.mean[VY] = velocity.y;
    gaussian.covariance.fixed_view_mut::<2, 2>(X, X).copy_from(measurement_noise_m2);
    gaussian.covariance.fixed_view_mut::<2, 2>(VX, VX).copy_from(&velocity_covariance);
    gaussian
}

/// `F x` and `F P Fᵀ` in place for a transition `F = I + Σ c·e_target·e_sourceᵀ` given as its
/// off-diagonal terms `(target, source, c)`, in `O(N·terms)` instead of the `O(N³)` of two
/// dense products (CV has 2 such terms, CA 6), for terms in which no source is the target of an
/// earlier term (then every term still reads unpropagated values; true for CV and CA in their natural
/// order: position from velocity and acceleration first, then velocity from acceleration).
#[inline(always)]
pub fn propagate_linear_in_place<const N: usize>(gaussian: &mut Gaussian<N>, terms: &[(usize, usize, f64)]) {
    debug_assert!(
        terms
            .iter()
            .enumerate()
            .all(|(i, &(_, source, _))| terms[..i].iter().all(|&(target, _, _)| target != source)),
        "a term reads a value an earlier term changed"
    );
    let (mean, p) = (&mut gaussian.mean, &mut gaussian.covariance);
    for &(target, source, c) in terms {
        mean[target] += c * mean[source];
        for column in 0..N {
            p[(target, column)] += c * p[(source, column)];
        }
    }
    for &(target, source, c) in terms {
        for row in 0..N {
            p[(row, target)] += c * p[(row, source)];
        }
    }
}

/// `covariance += q·Q_axis(Δt)` on both axes' `[position, velocity]` pairs (`X`/`VX` and
/// `Y`/`VY` of [`index`], as CV and CT lay out their states), for acceleration PSD `q` m²/s³.
#[inline]
pub(crate) fn add_white_acceleration<const N: usize>(
    covariance: &mut nalgebra::SMatrix<f64, N, N>,
    q: f64,
    dt: f64,
) {
    let block = white_acceleration_block(dt);
    for (position, velocity) in [(X, VX), (Y, VY)] {
        covariance[(position, position)] += q * block[0][0];
        covariance[(position, velocity)] += q * block[0][1];
        covariance[(velocity, position)] += q * block[1][0];
        covariance[(velocity, velocity)] += q * block[1][1];
    }
}

/// Continuous white-noise acceleration covariance of one axis' `[position, velocity]`, per unit PSD.
#[inline]
pub(crate) fn white_acceleration_block(dt: f64) -> [[f64; 2]; 2] {
    let dt2 = dt * dt;
    [[dt2 * dt / 3.0, dt2 / 2.0], [dt2 / 2.0, dt]]
}
