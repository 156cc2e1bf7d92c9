//! All tracker parameters in one validated structure.
//!
//! Units are part of every key's name. [`Config::default`] holds the values of the documented
//! file `config/primm.toml`; `primm-config` reads TOML files into a [`Config`] and a test there
//! checks that the file and the defaults here are equal. [`Config::validate`] checks every
//! value and names the offending key.

pub use crate::existence::{ExistenceConfig, Lifecycle};
pub use crate::extent::ExtentConfig;
use crate::measurement::{ClassSet, ObjectClass};
use crate::mode::{ModeSet, MODE_COUNT};
use crate::readable_number::readable;
pub use crate::tracking_frame::{FrameConfig, TrackingFrame};
use alloc::format;
use alloc::string::String;
use nalgebra::Matrix2;

/// A 2×2 covariance as written in TOML (`[[xx, xy], [yx, yy]]`), m².
pub type Covariance2 = [[f64; 2]; 2];

/// Complete tracker configuration.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Config {
    /// Mode set, transition matrix and mode-probability settings.
    pub imm: ImmConfig,
    /// Association cost settings (`eq:association_cost`).
    pub association: AssociationConfig,
    /// Frame validation and track lifecycle.
    pub tracker: TrackerConfig,
    /// Per-class parameters.
    pub classes: ClassTable,
    /// How the service runs the learned predictor (absent: the defaults).
    #[cfg_attr(feature = "serde", serde(default))]
    pub predictor: PredictorConfig,
    /// The tracking frame and the sensors' mounting poses (absent: the defaults).
    #[cfg_attr(feature = "serde", serde(default))]
    pub frame: FrameConfig,
}

/// The learned predictor's runtime and the check of its answers.
///
/// * `deadline_ms` applies in the tracking service (`primm serve`): the model runs on a
///   dedicated inference thread while the tracker predicts the physics modes, and the tracker
///   waits for its batch at most this long. Offline tracking (`primm track`, `primm eval`) runs
///   the model synchronously and ignores the deadline, so that its results do not depend on
///   timing.
/// * `max_displacement_speed_mps` applies wherever the tracker runs: every displacement a
///   predictor returns is checked against it before the PR mode uses it
///   (`crates/primm-core/src/displacement_check.rs`).
/// * `process_noise` and `learned_process_noise_scale` choose the PR mode's `Q_PR`
///   (`eq:pr_cov`): the model's own covariance of each displacement, scaled, or the per-class
///   constant `classes.*.learned.process_noise_covariance_m2` of the paper.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct PredictorConfig {
    /// Longest wait for a frame's learned displacements, measured from the moment the batch is
    /// handed to the inference thread, ms. A frame whose batch is late is tracked without the
    /// PR mode (it sits the frame out; see `src/imm.rs`).
    pub deadline_ms: f64,
    /// Fastest motion a learned displacement may imply, m/s: a displacement longer than this
    /// speed times the step's duration (`prediction_time_s − step_start_s` of its request) is
    /// rejected as implausible and counted, and the PR mode sits the frame out for that track.
    pub max_displacement_speed_mps: f64,
    /// Where the PR mode's `Q_PR` comes from.
    pub process_noise: LearnedProcessNoise,
    /// Factor on the model's covariance when `process_noise` is
    /// [`Learned`](LearnedProcessNoise::Learned), dimensionless (> 0).
    pub learned_process_noise_scale: f64,
    /// Service only: inference threads that share each frame's batch (1 to
    /// [`MAX_INFERENCE_THREADS`]); batches below 16 requests per thread use fewer.
    pub inference_threads: usize,
    /// What runs the PR model's forward pass.
    pub engine: InferenceEngine,
    /// The classes whose tracks the learned model predicts when the PR mode is one of several
    /// active modes (PR-IMM). A track of another class gets no request, and the PR mode sits
    /// every step of it out exactly as after a missed deadline (see `src/imm.rs`): its prior
    /// probability is spread over the physics modes, and it keeps that probability afterwards.
    /// With PR as the only mode (the `pr` method) every class is predicted, since the tracker
    /// would otherwise have no motion model for the classes left out.
    pub classes: ClassSet,
}

/// Most inference threads `predictor.inference_threads` may ask for.
pub const MAX_INFERENCE_THREADS: usize = 8;

impl Default for PredictorConfig {
    fn default() -> Self {
        Self {
            deadline_ms: 5.0,
            max_displacement_speed_mps: 100.0,
            process_noise: LearnedProcessNoise::Constant,
            learned_process_noise_scale: 1.0,
            inference_threads: 2,
            engine: InferenceEngine::Native,
            classes: ClassSet::ALL.without(ObjectClass::Car),
        }
    }
}

/// What runs the PR model's forward pass (`predictor.engine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum InferenceEngine {
    /// primm's own fixed-size forward pass of the shipped architecture
    /// (`primm_predictor::native`), for models of that architecture that agree with tract on
    /// probe inputs at load; any other model runs on tract.
    #[default]
    Native,
    /// tract runs the ONNX graph.
    Tract,
}

/// An engine name that is neither `native` nor `tract`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown engine '{text}' (expected native or tract)")]
pub struct UnknownEngine {
    /// The text that names no engine.
    pub text: String,
}

impl core::str::FromStr for InferenceEngine {
    type Err = UnknownEngine;
    /// The names of `predictor.engine`: `native`, `tract`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "native" => Ok(InferenceEngine::Native),
            "tract" => Ok(InferenceEngine::Tract),
            _ => Err(UnknownEngine { text: s.into() }),
        }
    }
}

/// The source of the PR mode's process noise `Q_PR` (`eq:pr_cov`). The default configuration
/// uses [`Constant`](Self::Constant): on the validation splits it gave PR-IMM the lower error
/// (`config/primm.toml` has the figures).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LearnedProcessNoise {
    /// The model's covariance of each displacement, times `learned_process_noise_scale`: a
    /// per-track, per-step `Q_PR`. A model without an uncertainty output, or an answer without
    /// one, falls back to the constant.
    Learned,
    /// The per-class constant `classes.*.learned.process_noise_covariance_m2`, as in the paper.
    #[default]
    Constant,
}

impl PredictorConfig {
    /// Whether the learned model predicts the tracks of `class` under the active `modes` (see
    /// [`classes`](Self::classes)).
    pub fn predicts(&self, class: ObjectClass, modes: ModeSet) -> bool {
        modes.len() == 1 || self.classes.contains(class)
    }

    /// The deadline as a duration.
    pub fn deadline(&self) -> core::time::Duration {
        core::time::Duration::from_secs_f64(self.deadline_ms / 1000.0)
    }
}

/// IMM settings (paper, Sections III-D and III-F).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ImmConfig {
    /// Active modes.
    pub modes: ModeSet,
    /// Mode-transition probabilities `π[i][j]`, order PR, CV, CA, CT; rows sum to 1.
    pub transition: [[f64; MODE_COUNT]; MODE_COUNT],
    /// Mode probabilities of a new track (renormalised over the active modes).
    pub initial_mode_probabilities: [f64; MODE_COUNT],
    /// Exponent `τ` on the likelihoods in `eq:mode_update`; must be > 0.
    pub likelihood_temperature: f64,
    /// Lower bound on every active mode's probability; in `[0, 1/modes)`.
    pub mode_probability_floor: f64,
}

/// Association cost settings.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AssociationConfig {
    /// `λ_v`, metres of cost per m/s of radial-velocity difference (i.e. seconds).
    pub velocity_weight_s: f64,
    /// `v_max`, cap on the radial-velocity difference, m/s.
    pub velocity_cap_mps: f64,
    /// Which cost pairs tracks with measurements (absent: `paper`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub cost: AssociationCost,
    /// Whether confirmed tracks choose their measurements before tentative ones (absent:
    /// `joint`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub stages: AssociationStages,
    /// Gate of the `likelihood` cost: largest squared Mahalanobis distance of position and
    /// radial-velocity residual together (χ² with 3 degrees of freedom; 16.27 keeps 99.9 % of
    /// true pairs), dimensionless (absent: 16.27).
    #[cfg_attr(feature = "serde", serde(default = "default_likelihood_gate_chi2"))]
    pub likelihood_gate_chi2: f64,
}

/// The default of `association.likelihood_gate_chi2`: the 99.9 % quantile of χ² with 3 degrees
/// of freedom.
pub const DEFAULT_LIKELIHOOD_GATE_CHI2: f64 = 16.27;

#[cfg(feature = "serde")]
fn default_likelihood_gate_chi2() -> f64 {
    DEFAULT_LIKELIHOOD_GATE_CHI2
}

/// The association cost (`association.cost`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AssociationCost {
    /// `eq:association_cost`: Euclidean distance to the fused prior plus the capped, weighted
    /// radial-velocity difference, gated at `classes.<class>.gate_m`.
    #[default]
    Paper,
    /// Negative log-likelihood: the squared Mahalanobis distance of the position (innovation
    /// covariance `S = P⁻ + R`) and of the radial-velocity difference (variance
    /// `classes.<class>.radial_velocity_residual_std_mps²`), plus `ln det S`, gated at
    /// `association.likelihood_gate_chi2` on the distance.
    Likelihood,
}

/// The order in which tracks choose measurements (`association.stages`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AssociationStages {
    /// One optimal assignment per class over all tracks, tentative and confirmed alike.
    #[default]
    Joint,
    /// Per class, first an optimal assignment of the confirmed tracks, then one of the
    /// tentative tracks over the measurements left; what remains starts new tracks. A
    /// tentative track (often born of clutter) can no longer take a confirmed track's
    /// measurement.
    ConfirmedFirst,
}

/// Frame validation and track lifecycle settings.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TrackerConfig {
    /// Largest accepted time between consecutive frames, s.
    pub max_frame_interval_s: f64,
    /// Hits that confirm a tentative track.
    pub confirmation_hits: u32,
    /// Consecutive misses after which a tentative track is deleted.
    pub tentative_max_misses: u32,
    /// Longest time a tentative track may coast without an update before it is deleted, s.
    pub tentative_max_coast_s: f64,
    /// Consecutive misses after which a confirmed track is deleted.
    pub confirmed_max_misses: u32,
    /// Longest time a track may coast without an update before it is deleted, s.
    pub max_coast_s: f64,
    /// How tracks are confirmed and deleted (absent: `counts`).
    #[cfg_attr(feature = "serde", serde(default = "counts"))]
    pub lifecycle: Lifecycle,
    /// Existence probability of a track started by one measurement, in (0, 1) (absent: 0.5).
    #[cfg_attr(feature = "serde", serde(default = "one_half"))]
    pub initial_existence_probability: f64,
    /// With `lifecycle = "existence"`: existence probability that confirms a tentative track,
    /// in (0, 1) (absent: 0.9).
    #[cfg_attr(feature = "serde", serde(default = "default_confirmation_existence"))]
    pub confirmation_existence_probability: f64,
    /// With `lifecycle = "existence"`: a track whose existence probability falls below this is
    /// deleted, in [0, confirmation) (absent: 0.05).
    #[cfg_attr(feature = "serde", serde(default = "default_deletion_existence"))]
    pub deletion_existence_probability: f64,
    /// Mean time an object goes on existing, s: the existence probability is multiplied by
    /// `exp(−Δt / T)` every frame (absent: 10 s).
    #[cfg_attr(feature = "serde", serde(default = "default_persistence_time_s"))]
    pub existence_persistence_time_s: f64,
    /// Consecutive updates of either of two overlapping tracks of one class, without an update
    /// of the other in the same frame, after which the younger is merged into the older
    /// (`crate::duplicates`); 0 turns the check off (absent: 0).
    #[cfg_attr(feature = "serde", serde(default))]
    pub duplicate_updates: u32,
    /// A frame up to this much older than the newest tracked frame is tracked in its place
    /// (`crate::replay`), s; an older one is rejected and counted. 0 turns late-frame tracking
    /// off (absent: 0).
    #[cfg_attr(feature = "serde", serde(default))]
    pub max_frame_delay_s: f64,
    /// How many of the most recent frames are kept for tracking a late frame in its place, from
    /// 0 (off) to 64; the window is the shorter of this and `max_frame_delay_s`. Each costs one
    /// frame copy and room for every track, allocated when the tracker is built (absent: 0).
    #[cfg_attr(feature = "serde", serde(default))]
    pub replay_frames: u32,
    /// Fastest plausible ego motion between two frames, m/s: an ego pose further from the
    /// previous one than this speed allows (plus 1 m) is an odometry reset, across which the
    /// tracks keep their place around the vehicle (absent: 100 m/s).
    #[cfg_attr(feature = "serde", serde(default = "default_max_ego_speed_mps"))]
    pub max_ego_speed_mps: f64,
    /// Fastest plausible ego turn between two frames, rad/s (yaw compared modulo 2π): a faster
    /// one is an odometry reset as above (absent: 3 rad/s).
    #[cfg_attr(feature = "serde", serde(default = "default_max_ego_yaw_rate_radps"))]
    pub max_ego_yaw_rate_radps: f64,
}

#[cfg(feature = "serde")]
fn default_max_ego_speed_mps() -> f64 {
    100.0
}

#[cfg(feature = "serde")]
fn default_max_ego_yaw_rate_radps() -> f64 {
    3.0
}

#[cfg(feature = "serde")]
fn counts() -> Lifecycle {
    Lifecycle::Counts
}

#[cfg(feature = "serde")]
fn one_half() -> f64 {
    0.5
}

#[cfg(feature = "serde")]
fn default_confirmation_existence() -> f64 {
    0.9
}

#[cfg(feature = "serde")]
fn default_deletion_existence() -> f64 {
    0.05
}

#[cfg(feature = "serde")]
fn default_persistence_time_s() -> f64 {
    10.0
}

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
    /// Association gate on the cost of `eq:association_cost`, m.
    pub gate_m: f64,
    /// Measurement noise covariance `R` of the CV, CA and CT modes, m².
    pub measurement_noise_covariance_m2: Covariance2,
    /// Standard deviation of the measured radial velocity, m/s.
    pub radial_velocity_std_mps: f64,
    /// Standard deviation of the velocity across the line of sight at initiation, m/s.
    pub initial_tangential_speed_std_mps: f64,
    /// Standard deviation of the difference between a measurement's radial velocity and the
    /// track's last one, as the `likelihood` association cost scores it, m/s (absent: 1 m/s).
    /// Wider than the sensor's noise: the two may come from different sensors, whose lines of
    /// sight differ, and the object accelerates between them.
    #[cfg_attr(feature = "serde", serde(default = "default_radial_velocity_residual_std_mps"))]
    pub radial_velocity_residual_std_mps: f64,
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
    /// velocity along the line of sight, m/s: the sensor's noise plus what the reflection
    /// point adds (an extended, turning object's points move differently), so at least the
    /// sensor's own `radial_velocity_std_mps`.
    pub std_mps: f64,
    /// Residuals beyond this many standard deviations of their innovation are not applied
    /// (counted): a radial velocity the track cannot explain, dimensionless.
    pub gate_std: f64,
}

impl Default for RadialVelocityUpdateConfig {
    /// Off; 0.5 m/s and a gate of 4 standard deviations when switched on.
    fn default() -> Self {
        RadialVelocityUpdateConfig { enabled: false, std_mps: 0.5, gate_std: 4.0 }
    }
}

/// Per-class overrides of the `imm` section (`classes.<class>.imm`): each key absent takes the
/// `imm` section's value. Same shapes and checks as there; the active modes, temperature and
/// floor are shared by all classes.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct ClassImmConfig {
    /// Mode-transition probabilities `π[i][j]` of this class, order PR, CV, CA, CT; rows sum to 1.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub transition: Option<[[f64; MODE_COUNT]; MODE_COUNT]>,
    /// Mode probabilities of a new track of this class (renormalised over the active modes).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub initial_mode_probabilities: Option<[f64; MODE_COUNT]>,
}

impl ClassImmConfig {
    /// No override at all.
    pub fn is_empty(&self) -> bool {
        self.transition.is_none() && self.initial_mode_probabilities.is_none()
    }
}

impl ImmConfig {
    /// These settings with a class's overrides applied.
    pub fn with_overrides(&self, overrides: &ClassImmConfig) -> ImmConfig {
        ImmConfig {
            transition: overrides.transition.unwrap_or(self.transition),
            initial_mode_probabilities: overrides
                .initial_mode_probabilities
                .unwrap_or(self.initial_mode_probabilities),
            ..self.clone()
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

/// An invalid configuration value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    /// A value is out of its valid range.
    #[error("configuration key `{key}` is invalid: {reason}")]
    Invalid {
        /// Dotted path of the key, e.g. `classes.car.gate_m`.
        key: String,
        /// What is wrong with it.
        reason: String,
    },
}

impl Default for Config {
    /// The values of `config/primm.toml`.
    fn default() -> Self {
        let off = 0.01;
        let stay = 0.97;
        Config {
            imm: ImmConfig {
                modes: ModeSet::ALL,
                transition: [
                    [stay, off, off, off],
                    [off, stay, off, off],
                    [off, off, stay, off],
                    [off, off, off, stay],
                ],
                // PR starts at 1/13 (odds 1:12), chosen on validation data
                // (`config/primm.toml` says how).
                initial_mode_probabilities: [0.07692001, 0.30769333, 0.30769333, 0.30769333],
                likelihood_temperature: 0.1,
                mode_probability_floor: 0.001,
            },
            association: AssociationConfig {
                velocity_weight_s: 0.1,
                velocity_cap_mps: 5.0,
                // Chosen on validation data (`config/primm.toml` says how).
                cost: AssociationCost::Likelihood,
                stages: AssociationStages::ConfirmedFirst,
                likelihood_gate_chi2: 112.0,
            },
            tracker: TrackerConfig {
                max_frame_interval_s: 1.0,
                confirmation_hits: 3,
                tentative_max_misses: 20,
                tentative_max_coast_s: 0.3,
                confirmed_max_misses: 100,
                max_coast_s: 1.0,
                lifecycle: Lifecycle::Existence,
                initial_existence_probability: 0.2,
                confirmation_existence_probability: 0.973,
                deletion_existence_probability: 0.01299,
                existence_persistence_time_s: 40.0,
                duplicate_updates: 4,
                max_frame_delay_s: 0.15,
                replay_frames: 16,
                max_ego_speed_mps: 100.0,
                max_ego_yaw_rate_radps: 3.0,
            },
            classes: ClassTable {
                car: ClassConfig {
                    gate_m: 8.4,
                    measurement_noise_covariance_m2: diagonal(0.36, 0.36),
                    radial_velocity_std_mps: 0.5,
                    initial_tangential_speed_std_mps: 2.0,
                    radial_velocity_residual_std_mps: 0.5,
                    existence: ExistenceConfig { detection_probability: 0.2, clutter_density_per_m2: 0.0004 },
                    duplicate_distance_m: 3.0,
                    duplicate_speed_difference_mps: 2.0,
                    radial_velocity_update: RadialVelocityUpdateConfig {
                        enabled: true,
                        ..RadialVelocityUpdateConfig::default()
                    },
                    extent: ExtentConfig {
                        enabled: true,
                        offset_scale: 0.5,
                        absorb_extra_detections: true,
                        ..ExtentConfig::default()
                    },
                    constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 1.0 },
                    constant_acceleration: ConstantAccelerationConfig {
                        jerk_psd_m2_per_s5: 5.0,
                        initial_acceleration_std_mps2: 2.0,
                    },
                    coordinated_turn: CoordinatedTurnConfig {
                        acceleration_psd_m2_per_s3: 0.5,
                        turn_rate_psd_rad2_per_s3: 0.3,
                        initial_turn_rate_std_radps: 0.3,
                        max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
                    },
                    learned: LearnedConfig {
                        process_noise_covariance_m2: diagonal(0.011, 0.011),
                        measurement_noise_covariance_m2: diagonal(0.18, 0.18),
                    },
                    // PR all but off for cars, chosen on validation (`config/primm.toml`).
                    imm: ClassImmConfig {
                        transition: Some([
                            [0.52, 0.16, 0.16, 0.16],
                            [0.000625, 0.9791856, 0.0100947, 0.0100947],
                            [0.000625, 0.0100947, 0.9791856, 0.0100947],
                            [0.000625, 0.0100947, 0.0100947, 0.9791856],
                        ]),
                        initial_mode_probabilities: Some([0.005182, 0.331606, 0.331606, 0.331606]),
                    },
                },
                pedestrian: ClassConfig {
                    gate_m: 4.2,
                    measurement_noise_covariance_m2: diagonal(0.09, 0.09),
                    radial_velocity_std_mps: 0.3,
                    initial_tangential_speed_std_mps: 0.525,
                    radial_velocity_residual_std_mps: 0.7,
                    existence: ExistenceConfig {
                        detection_probability: 0.15,
                        clutter_density_per_m2: 0.0004,
                    },
                    duplicate_distance_m: 1.0,
                    duplicate_speed_difference_mps: 1.0,
                    radial_velocity_update: RadialVelocityUpdateConfig {
                        enabled: true,
                        ..RadialVelocityUpdateConfig::default()
                    },
                    extent: ExtentConfig::default(),
                    constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 0.25 },
                    constant_acceleration: ConstantAccelerationConfig {
                        jerk_psd_m2_per_s5: 1.75,
                        initial_acceleration_std_mps2: 1.0,
                    },
                    coordinated_turn: CoordinatedTurnConfig {
                        acceleration_psd_m2_per_s3: 0.25,
                        turn_rate_psd_rad2_per_s3: 0.25,
                        initial_turn_rate_std_radps: 0.5,
                        max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
                    },
                    learned: LearnedConfig {
                        process_noise_covariance_m2: diagonal(0.00015, 0.00015),
                        measurement_noise_covariance_m2: diagonal(0.09, 0.09),
                    },
                    // Chosen on validation with the car's (`config/primm.toml`).
                    imm: ClassImmConfig {
                        transition: Some([
                            [0.985, 0.005, 0.005, 0.005],
                            [off, stay, off, off],
                            [off, off, stay, off],
                            [off, off, off, stay],
                        ]),
                        initial_mode_probabilities: Some([0.04, 0.32, 0.32, 0.32]),
                    },
                },
                two_wheeler: ClassConfig {
                    gate_m: 4.0,
                    measurement_noise_covariance_m2: diagonal(0.16, 0.16),
                    radial_velocity_std_mps: 0.4,
                    initial_tangential_speed_std_mps: 5.0,
                    radial_velocity_residual_std_mps: 1.0,
                    existence: ExistenceConfig { detection_probability: 0.2, clutter_density_per_m2: 0.0004 },
                    duplicate_distance_m: 1.5,
                    duplicate_speed_difference_mps: 2.0,
                    radial_velocity_update: RadialVelocityUpdateConfig {
                        enabled: true,
                        ..RadialVelocityUpdateConfig::default()
                    },
                    extent: ExtentConfig {
                        enabled: true,
                        length_m: 2.0,
                        width_m: 0.8,
                        contour_std_m: 0.3,
                        offset_scale: 0.5,
                        absorb_extra_detections: true,
                        ..ExtentConfig::default()
                    },
                    constant_velocity: ConstantVelocityConfig { acceleration_psd_m2_per_s3: 3.0 },
                    constant_acceleration: ConstantAccelerationConfig {
                        jerk_psd_m2_per_s5: 15.0,
                        initial_acceleration_std_mps2: 1.5,
                    },
                    coordinated_turn: CoordinatedTurnConfig {
                        acceleration_psd_m2_per_s3: 1.5,
                        turn_rate_psd_rad2_per_s3: 0.5,
                        initial_turn_rate_std_radps: 0.4,
                        max_turn_rate_radps: DEFAULT_MAX_TURN_RATE_RADPS,
                    },
                    learned: LearnedConfig {
                        process_noise_covariance_m2: diagonal(0.05, 0.05),
                        measurement_noise_covariance_m2: diagonal(0.16, 0.16),
                    },
                    imm: ClassImmConfig::default(),
                },
            },
            predictor: PredictorConfig::default(),
            frame: FrameConfig::default(),
        }
    }
}

/// A diagonal 2×2 covariance.
fn diagonal(xx: f64, yy: f64) -> Covariance2 {
    [[xx, 0.0], [0.0, yy]]
}

fn invalid(key: impl Into<String>, reason: impl Into<String>) -> ConfigError {
    ConfigError::Invalid { key: key.into(), reason: reason.into() }
}

fn positive(key: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, format!("must be a finite number > 0, got {}", readable(value))))
    }
}

/// A probability strictly between 0 and 1.
fn open_probability(key: &str, value: f64) -> Result<(), ConfigError> {
    if value > 0.0 && value < 1.0 {
        Ok(())
    } else {
        Err(invalid(key, format!("must be a probability in (0, 1), got {}", readable(value))))
    }
}

/// Checks that a 2×2 covariance is finite, symmetric and positive definite.
fn covariance(key: &str, value: &Covariance2) -> Result<(), ConfigError> {
    let m = to_matrix(value);
    if m.iter().any(|v| !v.is_finite()) {
        return Err(invalid(key, "entries must be finite"));
    }
    if (m[(0, 1)] - m[(1, 0)]).abs() > 1e-12 * m.abs().max().max(1.0) {
        return Err(invalid(key, "must be symmetric"));
    }
    if m[(0, 0)] <= 0.0 || m.determinant() <= 0.0 {
        return Err(invalid(key, "must be positive definite"));
    }
    Ok(())
}

/// A TOML covariance as a nalgebra matrix.
pub fn to_matrix(value: &Covariance2) -> Matrix2<f64> {
    Matrix2::new(value[0][0], value[0][1], value[1][0], value[1][1])
}

impl Config {
    /// This configuration with another set of active modes.
    pub fn with_modes(mut self, modes: ModeSet) -> Self {
        self.imm.modes = modes;
        self
    }

    /// This configuration with every class tracked as a point (`classes.<class>.extent` off):
    /// for detections that are already object centres (or a scene built of points).
    pub fn with_point_objects(mut self) -> Self {
        for class in ObjectClass::ALL {
            self.classes.get_mut(class).extent.enabled = false;
        }
        self
    }

    /// The IMM settings of `class`: the `imm` section with `classes.<class>.imm` applied.
    pub fn imm_for(&self, class: ObjectClass) -> ImmConfig {
        self.imm.with_overrides(&self.classes.get(class).imm)
    }

    /// Checks every value; the error names the first offending key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        validate_imm(&self.imm)?;
        validate_association(&self.association)?;
        validate_tracker_and_predictor(&self.tracker, &self.predictor)?;
        if let Some((key, reason)) = self.frame.problem() {
            return Err(invalid(key, reason));
        }
        for class in ObjectClass::ALL {
            validate_class(class, self.classes.get(class))?;
            validate_class_imm(class, &self.imm, &self.classes.get(class).imm)?;
        }
        Ok(())
    }
}

/// The `imm` section: mode set, transition matrix, initial probabilities, temperature, floor.
fn validate_imm(imm: &ImmConfig) -> Result<(), ConfigError> {
    if imm.modes.is_empty() {
        return Err(invalid("imm.modes", "at least one mode must be active"));
    }
    validate_transition("imm.transition", imm.modes, &imm.transition)?;
    validate_initial_probabilities(
        "imm.initial_mode_probabilities",
        imm.modes,
        &imm.initial_mode_probabilities,
    )?;
    positive("imm.likelihood_temperature", imm.likelihood_temperature)?;
    let floor = imm.mode_probability_floor;
    if !(floor >= 0.0 && floor < 1.0 / imm.modes.len() as f64) {
        return Err(invalid(
            "imm.mode_probability_floor",
            format!("must be in [0, 1/number of active modes), got {}", readable(floor)),
        ));
    }
    Ok(())
}

/// The section `classes.<class>.imm`: each override present is checked as its `imm` key is,
/// against the `imm` section's active modes.
fn validate_class_imm(
    class: ObjectClass,
    imm: &ImmConfig,
    overrides: &ClassImmConfig,
) -> Result<(), ConfigError> {
    let prefix = format!("classes.{}.imm", class.name());
    if let Some(transition) = &overrides.transition {
        validate_transition(&format!("{prefix}.transition"), imm.modes, transition)?;
    }
    if let Some(initial) = &overrides.initial_mode_probabilities {
        validate_initial_probabilities(&format!("{prefix}.initial_mode_probabilities"), imm.modes, initial)?;
    }
    Ok(())
}

/// Initial mode probabilities (key `key`): probabilities with mass on the active modes.
fn validate_initial_probabilities(
    key: &str,
    modes: ModeSet,
    initial: &[f64; MODE_COUNT],
) -> Result<(), ConfigError> {
    for (i, &p) in initial.iter().enumerate() {
        if !(0.0..=1.0).contains(&p) {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("must be a probability in [0, 1], got {}", readable(p)),
            ));
        }
    }
    if modes.iter().map(|m| initial[m.index()]).sum::<f64>() <= 0.0 {
        return Err(invalid(key, "no probability mass on the active modes"));
    }
    Ok(())
}

/// A transition matrix (key `key`, e.g. `imm.transition`): probabilities, rows summing to 1,
/// and mass on the active modes in the row of every active mode.
fn validate_transition(
    key: &str,
    modes: ModeSet,
    transition: &[[f64; MODE_COUNT]; MODE_COUNT],
) -> Result<(), ConfigError> {
    for (i, row) in transition.iter().enumerate() {
        for (j, &p) in row.iter().enumerate() {
            if !(0.0..=1.0).contains(&p) {
                return Err(invalid(
                    format!("{key}[{i}][{j}]"),
                    format!("must be a probability in [0, 1], got {}", readable(p)),
                ));
            }
        }
        let sum: f64 = row.iter().sum();
        if (sum - 1.0).abs() > 1e-9 {
            return Err(invalid(
                format!("{key}[{i}]"),
                format!("row must sum to 1, sums to {}", readable(sum)),
            ));
        }
    }
    for mode in modes.iter() {
        let i = mode.index();
        let active_sum: f64 = modes.iter().map(|to| transition[i][to.index()]).sum();
        if active_sum <= 0.0 {
            return Err(invalid(format!("{key}[{i}]"), "row has no probability mass on the active modes"));
        }
    }
    Ok(())
}

/// The `association` section.
fn validate_association(association: &AssociationConfig) -> Result<(), ConfigError> {
    if !(association.velocity_weight_s.is_finite() && association.velocity_weight_s >= 0.0) {
        return Err(invalid("association.velocity_weight_s", "must be a finite number >= 0"));
    }
    if !(association.velocity_cap_mps.is_finite() && association.velocity_cap_mps >= 0.0) {
        return Err(invalid("association.velocity_cap_mps", "must be a finite number >= 0"));
    }
    positive("association.likelihood_gate_chi2", association.likelihood_gate_chi2)?;
    Ok(())
}

/// The `tracker` and `predictor` sections; the deadline is checked between the frame interval
/// and the coast times, so that the first offending key named stays what it was.
fn validate_tracker_and_predictor(
    tracker: &TrackerConfig,
    predictor: &PredictorConfig,
) -> Result<(), ConfigError> {
    positive("tracker.max_frame_interval_s", tracker.max_frame_interval_s)?;
    positive("predictor.deadline_ms", predictor.deadline_ms)?;
    if predictor.deadline_ms > 1000.0 {
        return Err(invalid("predictor.deadline_ms", "must be at most 1000 ms (one second)"));
    }
    positive("predictor.max_displacement_speed_mps", predictor.max_displacement_speed_mps)?;
    positive("predictor.learned_process_noise_scale", predictor.learned_process_noise_scale)?;
    if !(1..=MAX_INFERENCE_THREADS).contains(&predictor.inference_threads) {
        return Err(invalid("predictor.inference_threads", "must be from 1 to 8"));
    }
    positive("tracker.max_coast_s", tracker.max_coast_s)?;
    positive("tracker.tentative_max_coast_s", tracker.tentative_max_coast_s)?;
    if tracker.confirmation_hits == 0 {
        return Err(invalid("tracker.confirmation_hits", "must be at least 1"));
    }
    open_probability("tracker.initial_existence_probability", tracker.initial_existence_probability)?;
    open_probability(
        "tracker.confirmation_existence_probability",
        tracker.confirmation_existence_probability,
    )?;
    let deletion = tracker.deletion_existence_probability;
    if !(deletion >= 0.0 && deletion < tracker.confirmation_existence_probability) {
        return Err(invalid(
            "tracker.deletion_existence_probability",
            format!("must be in [0, tracker.confirmation_existence_probability), got {}", readable(deletion)),
        ));
    }
    positive("tracker.existence_persistence_time_s", tracker.existence_persistence_time_s)?;
    if !(tracker.max_frame_delay_s >= 0.0 && tracker.max_frame_delay_s <= tracker.max_frame_interval_s) {
        return Err(invalid(
            "tracker.max_frame_delay_s",
            format!(
                "must be in [0, tracker.max_frame_interval_s], got {}",
                readable(tracker.max_frame_delay_s)
            ),
        ));
    }
    if tracker.replay_frames as usize > crate::limits::MAX_REPLAY_FRAMES {
        return Err(invalid("tracker.replay_frames", "must be at most 64"));
    }
    positive("tracker.max_ego_speed_mps", tracker.max_ego_speed_mps)?;
    positive("tracker.max_ego_yaw_rate_radps", tracker.max_ego_yaw_rate_radps)?;
    Ok(())
}

/// The section `classes.<class>`.
fn validate_class(class: ObjectClass, section: &ClassConfig) -> Result<(), ConfigError> {
    let key = |name: &str| format!("classes.{}.{}", class.name(), name);
    positive(&key("gate_m"), section.gate_m)?;
    covariance(&key("measurement_noise_covariance_m2"), &section.measurement_noise_covariance_m2)?;
    positive(&key("radial_velocity_std_mps"), section.radial_velocity_std_mps)?;
    positive(&key("initial_tangential_speed_std_mps"), section.initial_tangential_speed_std_mps)?;
    positive(&key("radial_velocity_residual_std_mps"), section.radial_velocity_residual_std_mps)?;
    positive(&key("duplicate_distance_m"), section.duplicate_distance_m)?;
    positive(&key("duplicate_speed_difference_mps"), section.duplicate_speed_difference_mps)?;
    positive(&key("radial_velocity_update.std_mps"), section.radial_velocity_update.std_mps)?;
    positive(&key("radial_velocity_update.gate_std"), section.radial_velocity_update.gate_std)?;
    let extent = &section.extent;
    positive(&key("extent.length_m"), extent.length_m)?;
    positive(&key("extent.width_m"), extent.width_m)?;
    if extent.width_m > extent.length_m || extent.length_m > 50.0 {
        return Err(invalid(
            key("extent.width_m"),
            format!(
                "must be at most extent.length_m, itself at most 50 m; got {} x {} m",
                readable(extent.length_m),
                readable(extent.width_m)
            ),
        ));
    }
    positive(&key("extent.contour_std_m"), extent.contour_std_m)?;
    positive(&key("extent.min_heading_speed_mps"), extent.min_heading_speed_mps)?;
    if !(extent.offset_scale > 0.0 && extent.offset_scale <= 1.0) {
        return Err(invalid(
            key("extent.offset_scale"),
            format!("must be in (0, 1], got {}", readable(extent.offset_scale)),
        ));
    }
    if !(extent.absorb_margin_m >= 0.0 && extent.absorb_margin_m <= 10.0) {
        return Err(invalid(
            key("extent.absorb_margin_m"),
            format!("must be in [0, 10] m, got {}", readable(extent.absorb_margin_m)),
        ));
    }
    open_probability(&key("existence.detection_probability"), section.existence.detection_probability)?;
    let clutter = section.existence.clutter_density_per_m2;
    if !(clutter.is_finite() && clutter >= 0.0) {
        return Err(invalid(
            key("existence.clutter_density_per_m2"),
            format!("must be a finite number >= 0, got {}", readable(clutter)),
        ));
    }
    positive(
        &key("constant_velocity.acceleration_psd_m2_per_s3"),
        section.constant_velocity.acceleration_psd_m2_per_s3,
    )?;
    positive(
        &key("constant_acceleration.jerk_psd_m2_per_s5"),
        section.constant_acceleration.jerk_psd_m2_per_s5,
    )?;
    positive(
        &key("constant_acceleration.initial_acceleration_std_mps2"),
        section.constant_acceleration.initial_acceleration_std_mps2,
    )?;
    positive(
        &key("coordinated_turn.acceleration_psd_m2_per_s3"),
        section.coordinated_turn.acceleration_psd_m2_per_s3,
    )?;
    positive(
        &key("coordinated_turn.turn_rate_psd_rad2_per_s3"),
        section.coordinated_turn.turn_rate_psd_rad2_per_s3,
    )?;
    positive(
        &key("coordinated_turn.initial_turn_rate_std_radps"),
        section.coordinated_turn.initial_turn_rate_std_radps,
    )?;
    positive(&key("coordinated_turn.max_turn_rate_radps"), section.coordinated_turn.max_turn_rate_radps)?;
    covariance(&key("learned.process_noise_covariance_m2"), &section.learned.process_noise_covariance_m2)?;
    covariance(
        &key("learned.measurement_noise_covariance_m2"),
        &section.learned.measurement_noise_covariance_m2,
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn invalid_key(config: &Config) -> String {
        match config.validate() {
            Err(ConfigError::Invalid { key, .. }) => key,
            Ok(()) => panic!("expected an invalid-key error"),
        }
    }

    #[test]
    fn the_default_configuration_is_valid() {
        Config::default().validate().unwrap();
    }

    #[test]
    fn a_transition_row_that_does_not_sum_to_one_is_named() {
        let mut config = Config::default();
        config.imm.transition[1][1] = 0.96;
        assert_eq!(invalid_key(&config), "imm.transition[1]");
    }

    #[test]
    fn a_negative_probability_is_named() {
        let mut config = Config::default();
        config.imm.transition[0] = [1.01, -0.01, 0.0, 0.0];
        assert_eq!(invalid_key(&config), "imm.transition[0][0]");
    }

    #[test]
    fn a_bad_class_override_is_named_with_its_key() {
        let mut config = Config::default();
        let mut transition = config.imm.transition;
        transition[0] = [0.9, 0.2, 0.0, 0.0];
        config.classes.car.imm.transition = Some(transition);
        assert_eq!(invalid_key(&config), "classes.car.imm.transition[0]");
        let mut config = Config::default();
        config.classes.pedestrian.imm.initial_mode_probabilities = Some([-0.1, 0.5, 0.3, 0.3]);
        assert_eq!(invalid_key(&config), "classes.pedestrian.imm.initial_mode_probabilities[0]");
    }

    #[test]
    fn class_overrides_apply_to_their_class_only() {
        let mut config = Config::default();
        for class in ObjectClass::ALL {
            config.classes.get_mut(class).imm = ClassImmConfig::default();
        }
        config.classes.car.imm.initial_mode_probabilities = Some([0.01, 0.33, 0.33, 0.33]);
        config.validate().unwrap();
        assert_eq!(config.imm_for(ObjectClass::Car).initial_mode_probabilities, [0.01, 0.33, 0.33, 0.33]);
        assert_eq!(config.imm_for(ObjectClass::Car).transition, config.imm.transition);
        assert_eq!(config.imm_for(ObjectClass::Pedestrian), config.imm);
        assert_eq!(Config::default().imm_for(ObjectClass::TwoWheeler), Config::default().imm);
        // The shipped overrides: cars' and pedestrians' own, whole.
        let shipped = Config::default();
        for class in [ObjectClass::Car, ObjectClass::Pedestrian] {
            let own = &shipped.classes.get(class).imm;
            let imm = shipped.imm_for(class);
            assert_eq!(Some(imm.transition), own.transition);
            assert_eq!(Some(imm.initial_mode_probabilities), own.initial_mode_probabilities);
            assert_eq!(imm.likelihood_temperature, shipped.imm.likelihood_temperature);
        }
    }

    #[test]
    fn a_non_positive_temperature_is_named() {
        let mut config = Config::default();
        config.imm.likelihood_temperature = 0.0;
        assert_eq!(invalid_key(&config), "imm.likelihood_temperature");
    }

    #[test]
    fn an_asymmetric_covariance_is_named() {
        let mut config = Config::default();
        config.classes.pedestrian.measurement_noise_covariance_m2 = [[0.09, 0.01], [0.0, 0.09]];
        assert_eq!(invalid_key(&config), "classes.pedestrian.measurement_noise_covariance_m2");
    }

    #[test]
    fn an_indefinite_covariance_is_named() {
        let mut config = Config::default();
        config.classes.car.learned.process_noise_covariance_m2 = [[0.01, 0.5], [0.5, 0.017]];
        assert_eq!(invalid_key(&config), "classes.car.learned.process_noise_covariance_m2");
    }

    #[test]
    fn a_floor_too_high_for_the_mode_count_is_named() {
        let mut config = Config::default();
        config.imm.mode_probability_floor = 0.3;
        assert_eq!(invalid_key(&config), "imm.mode_probability_floor");
    }

    #[test]
    fn an_empty_mode_set_is_rejected() {
        let config = Config::default().with_modes(ModeSet::EMPTY);
        assert_eq!(invalid_key(&config), "imm.modes");
    }

    #[test]
    fn engine_names_parse_and_another_name_is_refused_with_it() {
        assert_eq!("native".parse::<InferenceEngine>(), Ok(InferenceEngine::Native));
        assert_eq!("tract".parse::<InferenceEngine>(), Ok(InferenceEngine::Tract));
        assert_eq!("onnx".parse::<InferenceEngine>(), Err(UnknownEngine { text: "onnx".into() }));
    }

    #[test]
    fn no_or_too_many_inference_threads_are_rejected() {
        for bad in [0, MAX_INFERENCE_THREADS + 1, usize::MAX] {
            let mut config = Config::default();
            config.predictor.inference_threads = bad;
            assert_eq!(invalid_key(&config), "predictor.inference_threads", "threads {bad}");
        }
        let mut config = Config::default();
        config.predictor.inference_threads = MAX_INFERENCE_THREADS;
        assert!(config.validate().is_ok());
    }

    #[test]
    fn a_non_positive_or_huge_predictor_deadline_is_rejected() {
        for bad in [0.0, -1.0, f64::NAN, 5000.0] {
            let mut config = Config::default();
            config.predictor.deadline_ms = bad;
            assert_eq!(invalid_key(&config), "predictor.deadline_ms", "deadline {bad}");
        }
        assert_eq!(Config::default().predictor.deadline(), core::time::Duration::from_millis(5));
    }

    #[test]
    fn a_non_positive_or_non_finite_displacement_speed_bound_is_rejected() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let mut config = Config::default();
            config.predictor.max_displacement_speed_mps = bad;
            assert_eq!(invalid_key(&config), "predictor.max_displacement_speed_mps", "bound {bad}");
        }
    }
}
