//! The shared sections: `imm`, `association` and `tracker` (frame validation and the track
//! lifecycle), and the per-class overrides of `imm`.

use super::*;

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
    /// Second gate of the `likelihood` cost, in metres: the largest distance of a measurement
    /// from a track's predicted centre, beyond the largest offset of a reflection on its
    /// extent, m (absent: no such gate). The χ² gate widens with the track's covariance, so a
    /// track whose velocity ran away would otherwise reach any measurement.
    #[cfg_attr(feature = "serde", serde(default = "default_likelihood_gate_distance_m"))]
    pub likelihood_gate_distance_m: f64,
}

#[cfg(feature = "serde")]
fn default_likelihood_gate_distance_m() -> f64 {
    f64::INFINITY
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
    /// radial-velocity difference, gated at `classes.<class>.paper_gate_m`.
    #[default]
    Paper,
    /// Negative log-likelihood: the squared Mahalanobis distance of the position (innovation
    /// covariance `S = P⁻ + R`) and of the radial-velocity difference (variance
    /// `classes.<class>.likelihood_radial_velocity_std_mps²`), plus `ln det S`, gated at
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
    /// The transition matrix of this class in steps whose ego motion is compensated (the frame
    /// has an ego pose and is tracked in the world frame; absent: `transition`). Without the
    /// ego's motion the state follows the scene as the ego turns and brakes, which a manoeuvre
    /// mode can follow; with it, the object's own motion remains.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub compensated_transition: Option<[[f64; MODE_COUNT]; MODE_COUNT]>,
    /// The initial mode probabilities of a track started in such a step (absent:
    /// `initial_mode_probabilities`).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub compensated_initial_mode_probabilities: Option<[f64; MODE_COUNT]>,
}

impl ClassImmConfig {
    /// No override at all.
    pub fn is_empty(&self) -> bool {
        self.transition.is_none()
            && self.initial_mode_probabilities.is_none()
            && self.compensated_transition.is_none()
            && self.compensated_initial_mode_probabilities.is_none()
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

    /// These settings with a class's overrides for ego-motion-compensated steps applied (each
    /// absent one falling back to [`with_overrides`](Self::with_overrides)'s).
    pub fn with_compensated_overrides(&self, overrides: &ClassImmConfig) -> ImmConfig {
        let plain = self.with_overrides(overrides);
        ImmConfig {
            transition: overrides.compensated_transition.unwrap_or(plain.transition),
            initial_mode_probabilities: overrides
                .compensated_initial_mode_probabilities
                .unwrap_or(plain.initial_mode_probabilities),
            ..plain
        }
    }
}
