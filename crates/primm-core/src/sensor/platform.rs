//! Whether the sensors stand still (`frame.platform`), for frames without an ego pose.
//!
//! A frame without a pose is tracked in the vehicle frame: the sensor may be moving, so the
//! tracks' velocities are relative to it, the radial velocities (over ground) do not measure
//! them, and no speed bound applies. A roadside or intersection radar does not move; its
//! frames are then better tracked in the world frame at the origin, where the radial velocity
//! updates the tracks and the classes' speed bounds hold (docs/EVALUATION.md, "Dense scenes
//! from a roadside radar"). `"stationary"` says so, `"moving"` says the opposite, and `"auto"`
//! (the default) asks the data.
//!
//! The evidence is the radial-velocity innovation of the confirmed tracks that frames without a
//! pose update: `r = v_r − v⁻ · u`, with `v⁻` the track's prior velocity, `u` the line of sight
//! from the sensor and `σ² = σ_r² + uᵀ P_v u` its predicted variance (the class's
//! `radial_velocity_update.std_mps` and the prior's velocity covariance). Radial velocities are
//! over ground; tracked without a pose, velocities are relative to the sensor, so for a sensor
//! moving at `v_p` the innovation is `v_p · u` plus noise, and for one that stands still it is
//! noise. The platform's velocity is estimated by weighted least squares over the samples, the
//! way a radar's own motion is estimated from the Doppler of the objects around it:
//! `v̂_p = A⁻¹ b` with `A = Σ u uᵀ / σ²` and `b = Σ u r / σ²`, each `r / σ` clamped to
//! ±[`PLATFORM_RESIDUAL_CLAMP`] (a wrong pairing weighs little), both sums forgetting with a
//! memory of [`PLATFORM_WINDOW_SAMPLES`] samples. The sensors are taken to stand still once the
//! estimate's smaller information `λ_min(A)` reaches [`PLATFORM_MIN_INFORMATION`] (a standard
//! deviation of 0.3 m/s in every direction: lines of sight all abeam of a moving vehicle say
//! nothing of its speed) and `|v̂_p|` is below [`PLATFORM_STATIONARY_BELOW_MPS`]; to move again
//! once `|v̂_p|` exceeds [`PLATFORM_MOVING_ABOVE_MPS`]. Tracked as stationary, the radial
//! velocities update the tracks and pull their velocities towards themselves, so a sensor that
//! starts to move shows a smaller `|v̂_p|` than its speed (a part of it); the gap between the
//! two thresholds is kept small for that reason. A radar that reports no radial velocity
//! (zeros) reads as moving with its objects' velocities, so it keeps the vehicle frame, where
//! the radial velocity is not used.

use glam::{DMat2, DVec2};

/// What `frame.platform` says of the sensors' motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum PlatformModel {
    /// The sensors may move: frames without a pose are tracked in the vehicle frame.
    Moving,
    /// The sensors stand still: frames without a pose are tracked in the world frame at the
    /// origin.
    Stationary,
    /// As the data say ([`PlatformEstimate`]); moving until then. The default.
    #[default]
    Auto,
}

impl PlatformModel {
    /// Whether frames without a pose are tracked as of sensors that stand still now: as the
    /// model says, or, under `Auto`, as `estimate` decided.
    pub fn stationary(self, estimate: &PlatformEstimate) -> bool {
        match self {
            PlatformModel::Moving => false,
            PlatformModel::Stationary => true,
            PlatformModel::Auto => estimate.stationary,
        }
    }

    /// The short name used in configuration and output.
    pub fn name(self) -> &'static str {
        match self {
            PlatformModel::Moving => "moving",
            PlatformModel::Stationary => "stationary",
            PlatformModel::Auto => "auto",
        }
    }
}

/// Age below which a confirmed track gives no sample, s: its velocity still holds the radial
/// velocity it was started with, which agrees with the radial velocities whether the sensors
/// move or not.
pub const PLATFORM_MIN_TRACK_AGE_S: f64 = 1.0;
/// Largest `|r| / σ` of one sample.
pub const PLATFORM_RESIDUAL_CLAMP: f64 = 5.0;
/// Memory of the sums, in samples.
pub const PLATFORM_WINDOW_SAMPLES: f64 = 1000.0;
/// Information the estimate needs in every direction before it turns stationary, s²/m²
/// (1 / 0.3²).
pub const PLATFORM_MIN_INFORMATION: f64 = 1.0 / (0.3 * 0.3);
/// The sensors are taken to stand still once the estimated speed is below this, m/s.
pub const PLATFORM_STATIONARY_BELOW_MPS: f64 = 0.5;
/// ... and to move again once it is above this, m/s.
pub const PLATFORM_MOVING_ABOVE_MPS: f64 = 1.0;

/// The least-squares estimate of the sensors' velocity from the radial-velocity innovations of
/// frames without a pose, and the decision it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformEstimate {
    /// `A = Σ u uᵀ / σ²`, s²/m².
    pub information: DMat2,
    /// `b = Σ u r / σ²`, s/m.
    pub weighted_residuals: DVec2,
    /// Samples taken in all.
    pub samples: u64,
    /// Whether the sensors are taken to stand still.
    pub stationary: bool,
    /// Times the decision changed.
    pub switches: u64,
}

impl Default for PlatformEstimate {
    fn default() -> Self {
        Self::new()
    }
}

impl PlatformEstimate {
    /// The estimate without samples: moving.
    pub const fn new() -> Self {
        PlatformEstimate {
            information: DMat2::ZERO,
            weighted_residuals: DVec2::ZERO,
            samples: 0,
            stationary: false,
            switches: 0,
        }
    }

    /// The smaller eigenvalue of the information, s²/m².
    pub fn least_information(&self) -> f64 {
        let a = self.information;
        let (xx, xy, yy) = (a.x_axis.x, a.x_axis.y, a.y_axis.y);
        let half_trace = 0.5 * (xx + yy);
        let root = crate::math::sqrt(0.25 * (xx - yy) * (xx - yy) + xy * xy);
        half_trace - root
    }

    /// The estimated velocity of the sensors in the tracking frame, m/s; `None` until the
    /// information is enough in every direction.
    pub fn velocity_mps(&self) -> Option<DVec2> {
        (self.least_information() >= PLATFORM_MIN_INFORMATION)
            .then(|| self.information.inverse() * self.weighted_residuals)
            .filter(|velocity| velocity.is_finite())
    }

    /// Takes one radial velocity `radial_velocity_mps` seen along `line_of_sight` (a unit
    /// vector) of a track with prior velocity `velocity_mps` and its covariance, the class's
    /// radial-velocity noise `noise_std_mps`. Non-finite inputs are ignored.
    pub fn observe(
        &mut self,
        radial_velocity_mps: f64,
        line_of_sight: DVec2,
        (velocity_mps, velocity_covariance_m2): (DVec2, DMat2),
        noise_std_mps: f64,
    ) {
        let innovation_mps = radial_velocity_mps - velocity_mps.dot(line_of_sight);
        let variance =
            noise_std_mps * noise_std_mps + line_of_sight.dot(velocity_covariance_m2 * line_of_sight);
        let std_mps = crate::math::sqrt(variance);
        if !(innovation_mps.is_finite() && std_mps > 0.0 && std_mps.is_finite() && line_of_sight.is_finite())
        {
            return;
        }
        let clamped_mps =
            innovation_mps.clamp(-PLATFORM_RESIDUAL_CLAMP * std_mps, PLATFORM_RESIDUAL_CLAMP * std_mps);
        let keep = 1.0 - 1.0 / PLATFORM_WINDOW_SAMPLES;
        let outer = DMat2::from_cols(line_of_sight * line_of_sight.x, line_of_sight * line_of_sight.y);
        self.information = self.information * keep + outer * (1.0 / variance);
        self.weighted_residuals = self.weighted_residuals * keep + line_of_sight * (clamped_mps / variance);
        self.samples += 1;
        let Some(velocity) = self.velocity_mps() else { return };
        let speed_mps = velocity.length();
        let decided = if self.stationary {
            speed_mps <= PLATFORM_MOVING_ABOVE_MPS
        } else {
            speed_mps < PLATFORM_STATIONARY_BELOW_MPS
        };
        if decided != self.stationary {
            self.stationary = decided;
            self.switches += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(k: u64) -> f64 {
        // A deterministic spread in [-1, 1).
        ((k.wrapping_mul(2_654_435_761) % 1000) as f64) / 500.0 - 1.0
    }

    #[test]
    fn without_samples_the_sensors_are_taken_to_move() {
        let estimate = PlatformEstimate::new();
        assert!(!estimate.stationary);
        assert_eq!(estimate.velocity_mps(), None);
    }

    #[test]
    fn radial_velocities_that_match_the_tracks_turn_it_stationary_and_a_moving_sensor_back() {
        let mut estimate = PlatformEstimate::new();
        let covariance = DMat2::from_diagonal(DVec2::splat(0.25));
        let velocity = DVec2::new(8.0, 3.0);
        let mut samples_to_stationary = None;
        for k in 0..400u64 {
            let line_of_sight = DVec2::from_angle(0.05 * k as f64);
            // Over ground, as the tracks: the innovation is noise of about 0.5 m/s.
            estimate.observe(
                velocity.dot(line_of_sight) + 0.5 * noise(k),
                line_of_sight,
                (velocity, covariance),
                0.5,
            );
            if estimate.stationary && samples_to_stationary.is_none() {
                samples_to_stationary = Some(k + 1);
            }
        }
        // Information 2 per sample (σ² = 0.5), half of it in each direction: about 11 samples.
        let needed = samples_to_stationary.expect("it turns stationary");
        assert!((8..40).contains(&needed), "{needed}");
        assert!(estimate.velocity_mps().unwrap().length() < 0.2);
        // The sensor starts to move at 6 m/s: radial velocities over ground, tracks relative.
        let platform = DVec2::new(6.0, 0.0);
        for k in 0..400u64 {
            let line_of_sight = DVec2::from_angle(0.05 * k as f64);
            estimate.observe(
                velocity.dot(line_of_sight),
                line_of_sight,
                (velocity - platform, covariance),
                0.5,
            );
        }
        assert!(!estimate.stationary);
        assert_eq!(estimate.switches, 2);
        // Half the memory still stands still: the estimate points along the motion, short of it.
        let estimated = estimate.velocity_mps().unwrap();
        assert!(estimated.x > 2.0 && estimated.x < 6.5 && estimated.y.abs() < 1.0, "{estimated}");
    }

    #[test]
    fn lines_of_sight_all_abeam_of_a_moving_sensor_decide_nothing() {
        // Every line of sight across the sensor's motion: the innovations are noise, but they
        // say nothing of its speed along its path.
        let mut estimate = PlatformEstimate::new();
        let covariance = DMat2::from_diagonal(DVec2::splat(0.25));
        for k in 0..1000u64 {
            let line_of_sight = if k % 2 == 0 { DVec2::Y } else { -DVec2::Y };
            estimate.observe(0.5 * noise(k), line_of_sight, (DVec2::ZERO, covariance), 0.5);
        }
        assert_eq!(estimate.velocity_mps(), None);
        assert!(!estimate.stationary);
    }

    #[test]
    fn zero_radial_velocities_of_moving_objects_read_as_a_moving_sensor() {
        let mut estimate = PlatformEstimate::new();
        let covariance = DMat2::from_diagonal(DVec2::splat(0.25));
        for k in 0..1000u64 {
            let line_of_sight = DVec2::from_angle(0.05 * k as f64);
            estimate.observe(0.0, line_of_sight, (DVec2::new(6.0, 0.0), covariance), 0.5);
        }
        assert!(!estimate.stationary);
        assert!(estimate.velocity_mps().unwrap().length() > PLATFORM_MOVING_ABOVE_MPS);
    }

    #[test]
    fn non_finite_samples_are_ignored() {
        let mut estimate = PlatformEstimate::new();
        estimate.observe(f64::NAN, DVec2::X, (DVec2::ZERO, DMat2::ZERO), 0.5);
        estimate.observe(1.0, DVec2::X, (DVec2::ZERO, DMat2::ZERO), 0.0);
        estimate.observe(1.0, DVec2::new(f64::INFINITY, 0.0), (DVec2::ZERO, DMat2::ZERO), 0.5);
        assert_eq!(estimate, PlatformEstimate::new());
    }
}
