//! The per-class sections `classes.<class>`: measurement noise, gates, existence, the
//! radial-velocity row, the extent, and each mode's noise.

use super::*;

/// Per-class parameter sections.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ClassTable {
    /// Cars (and large vehicles).
    pub car: ClassConfig,
    /// Pedestrians (and groups).
    pub pedestrian: ClassConfig,
    /// Two-wheelers.
    pub two_wheeler: ClassConfig,
}

impl ClassTable {
    /// The section of `class`.
    pub fn get(&self, class: ObjectClass) -> &ClassConfig {
        match class {
            ObjectClass::Car => &self.car,
            ObjectClass::Pedestrian => &self.pedestrian,
            ObjectClass::TwoWheeler => &self.two_wheeler,
        }
    }

    /// The section of `class`, to change.
    pub fn get_mut(&mut self, class: ObjectClass) -> &mut ClassConfig {
        match class {
            ObjectClass::Car => &mut self.car,
            ObjectClass::Pedestrian => &mut self.pedestrian,
            ObjectClass::TwoWheeler => &mut self.two_wheeler,
        }
    }
}

/// Parameters of one object class.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ClassConfig {
    /// Gate of the `paper` association cost (`eq:association_cost`: metres of distance plus
    /// the weighted radial-velocity difference), m. Unused by the `likelihood` cost, which is
    /// gated by `association.likelihood_gate_chi2`.
    pub paper_gate_m: f64,
    /// Measurement noise covariance `R` of the CV, CA and CT modes, m².
    pub measurement_noise_covariance_m2: Covariance2,
    /// Standard deviation of a new track's velocity along the line of sight (the measured
    /// radial velocity's error), m/s: the initial velocity covariance only.
    pub initial_radial_speed_std_mps: f64,
    /// Standard deviation of a new track's velocity across the line of sight (which one radar
    /// measurement does not observe), m/s.
    pub initial_tangential_speed_std_mps: f64,
    /// Highest speed over ground an object of this class reaches, m/s (absent: no bound). In
    /// steps with an ego pose, a mode's velocity estimate above it after an update or at a
    /// track's start is scaled back onto it (counted as
    /// [`TrackerStats::speeds_bounded`](crate::TrackerStats)): no measurement can make a car
    /// faster than cars drive.
    #[cfg_attr(feature = "serde", serde(default))]
    pub max_speed_mps: Option<f64>,
    /// Standard deviation of the difference between a measurement's radial velocity and the
    /// track's last one, as the `likelihood` association cost scores it (unused by the `paper`
    /// cost), m/s (absent: 1 m/s).
    /// Wider than the sensor's noise: the two may come from different sensors, whose lines of
    /// sight differ, and the object accelerates between them.
    #[cfg_attr(feature = "serde", serde(default = "default_radial_velocity_residual_std_mps"))]
    pub likelihood_radial_velocity_std_mps: f64,
    /// Detection probability and clutter density of this class, for the existence probability
    /// (absent: 0.9 and 1e-4 /m²).
    #[cfg_attr(feature = "serde", serde(default))]
    pub existence: ExistenceConfig,
    /// Largest distance between the fused positions of two tracks of one object of this class,
    /// for the duplicate check, m (absent: 2 m).
    #[cfg_attr(feature = "serde", serde(default = "default_duplicate_distance_m"))]
    pub duplicate_distance_m: f64,
    /// Largest difference between the fused velocities of two tracks of one object of this
    /// class, for the duplicate check, m/s (absent: 2 m/s).
    #[cfg_attr(feature = "serde", serde(default = "default_duplicate_speed_difference_mps"))]
    pub duplicate_speed_difference_mps: f64,
    /// The radial velocity as a measurement of the velocity in the CV, CA and CT updates
    /// (absent: off).
    #[cfg_attr(feature = "serde", serde(default))]
    pub radial_velocity_update: RadialVelocityUpdateConfig,
    /// The object's extent: with `enabled`, the state is the object's centre and each
    /// measurement the expected reflection on its outline (`crate::extent`; absent: a point).
    #[cfg_attr(feature = "serde", serde(default))]
    pub extent: ExtentConfig,
    /// Constant-velocity mode.
    pub constant_velocity: ConstantVelocityConfig,
    /// Constant-acceleration mode.
    pub constant_acceleration: ConstantAccelerationConfig,
    /// Coordinated-turn mode.
    pub coordinated_turn: CoordinatedTurnConfig,
    /// Learned-predictor (PR) mode.
    pub learned: LearnedConfig,
    /// This class's IMM transition matrix and initial mode probabilities, where they differ from
    /// the `imm` section's (absent: the `imm` section's).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "ClassImmConfig::is_empty"))]
    pub imm: ClassImmConfig,
}

/// The section `classes.<class>.radial_velocity_update`: each assigned measurement's radial
/// velocity as an extended Kalman row `h(x) = û·v` of the CV, CA and CT modes (after the
/// position rows; ARCHITECTURE.md, "Radial velocity in the update").
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RadialVelocityUpdateConfig {
    /// Whether the row is applied.
    pub enabled: bool,
    /// Standard deviation of a measured radial velocity as a measurement of the object's
    /// velocity along the line of sight, in the Kalman row of the CV, CA and CT updates, m/s:
    /// the sensor's noise plus what the reflection point adds (an extended, turning object's
    /// points move differently).
    pub std_mps: f64,
    /// Residuals beyond this many standard deviations of their innovation are not applied
    /// (counted): a radial velocity the track cannot explain, dimensionless.
    pub gate_std: f64,
    /// Along which direction the radial velocity is taken to measure the velocity (absent:
    /// `predicted`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub line_of_sight: RadialLineOfSight,
}

/// The direction `û` of the radial-velocity row `h(x) = û·v`
/// (`classes.<class>.radial_velocity_update.line_of_sight`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum RadialLineOfSight {
    /// From the sensor to the track's estimated position (the object's centre): an extended
    /// Kalman row, whose Jacobian also reaches the position.
    #[default]
    Predicted,
    /// From the sensor to the detection itself, whose azimuth the radar measured: where the
    /// reflection that gave the radial velocity lies. Every point of a body that does not turn
    /// moves with the same velocity, so the row is linear (`∂h/∂p = 0`) and exact for a
    /// reflection off an extended object's contour, whose direction differs from the centre's.
    /// The direction carries the detection's position noise, which at short range is large.
    Measured,
    /// From the sensor to the expected reflection: the track's estimated centre plus the
    /// extended-object model's expected offset of the reflection (`crate::extent`), an extended
    /// Kalman row like `predicted` (the offset held fixed in the Jacobian). For a point class the
    /// offset is zero and this is `predicted`.
    Reflection,
}

impl Default for RadialVelocityUpdateConfig {
    /// Off; 0.5 m/s and a gate of 4 standard deviations when switched on, along the predicted
    /// line of sight.
    fn default() -> Self {
        RadialVelocityUpdateConfig {
            enabled: false,
            std_mps: 0.5,
            gate_std: 4.0,
            line_of_sight: RadialLineOfSight::Predicted,
        }
    }
}

#[cfg(feature = "serde")]
fn default_radial_velocity_residual_std_mps() -> f64 {
    1.0
}

#[cfg(feature = "serde")]
fn default_duplicate_distance_m() -> f64 {
    2.0
}

#[cfg(feature = "serde")]
fn default_duplicate_speed_difference_mps() -> f64 {
    2.0
}

/// Constant-velocity noise.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ConstantVelocityConfig {
    /// Power spectral density of the continuous white-noise acceleration, m²/s³.
    pub acceleration_psd_m2_per_s3: f64,
}

/// Constant-acceleration noise and initiation.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ConstantAccelerationConfig {
    /// Power spectral density of the continuous white-noise jerk, m²/s⁵.
    pub jerk_psd_m2_per_s5: f64,
    /// Standard deviation of the initial acceleration, m/s².
    pub initial_acceleration_std_mps2: f64,
}

/// Coordinated-turn noise and initiation.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CoordinatedTurnConfig {
    /// Power spectral density of the continuous white-noise acceleration, m²/s³.
    pub acceleration_psd_m2_per_s3: f64,
    /// Power spectral density of the turn-rate random walk, rad²/s³.
    pub turn_rate_psd_rad2_per_s3: f64,
    /// Standard deviation of the initial turn rate, rad/s.
    pub initial_turn_rate_std_radps: f64,
    /// Largest turn rate the model predicts with, rad/s: a larger estimate is clamped to it
    /// before each prediction (absent: [`DEFAULT_MAX_TURN_RATE_RADPS`]).
    #[cfg_attr(feature = "serde", serde(default = "default_max_turn_rate_radps"))]
    pub max_turn_rate_radps: f64,
}

/// The default of `coordinated_turn.max_turn_rate_radps`, rad/s: a car turning on a 3 m radius
/// at 6 m/s, and well above what pedestrians and two-wheelers sustain over a radar frame.
pub const DEFAULT_MAX_TURN_RATE_RADPS: f64 = 2.0;

#[cfg(feature = "serde")]
fn default_max_turn_rate_radps() -> f64 {
    DEFAULT_MAX_TURN_RATE_RADPS
}

/// Learned-predictor (PR) noise (`eq:pr_cov`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LearnedConfig {
    /// `Q_PR`, added to the PR covariance at every prediction, m².
    pub process_noise_covariance_m2: Covariance2,
    /// `R_PR`, measurement noise covariance of the PR mode, m².
    pub measurement_noise_covariance_m2: Covariance2,
}
