//! What a sensor's data says about the sensor: running estimates, per class, of where its
//! detections lie on an object, how often it detects an object in view, and how much clutter it
//! reports (ARCHITECTURE.md, "Sensors and their estimates").
//!
//! Every estimate starts at its prior (the configured value) with the weight of
//! `prior_samples` samples, so that it moves halfway to what the data says after as many
//! samples, and forgets beyond `window_samples`, so that the gain never falls below
//! `1 / (prior_samples + window_samples)` and a sensor that changes is followed. Estimates are
//! kept inside fixed bounds; a step that would leave them is counted. Nothing here reads a
//! clock: the estimates are functions of the frames alone, so a replay reproduces them bit for
//! bit.

use crate::math;
use glam::DVec2;

/// The bounds of the reflection estimate: from the centre (0) to the outline (1).
pub const REFLECTION_BOUNDS: (f64, f64) = (0.0, 1.0);
/// The bounds of the detection-probability estimate.
pub const DETECTION_BOUNDS: (f64, f64) = (0.01, 0.999);
/// The bounds of the clutter-density estimate, 1/m².
pub const CLUTTER_BOUNDS_PER_M2: (f64, f64) = (0.0, 0.1);
/// The squared change of a track's outline offset, m², that counts as one sample of the
/// reflection estimate's weight (a change of 0.5 m between two updates).
pub const REFLECTION_SAMPLE_M2: f64 = 0.25;
/// The smallest change of the outline offset between two updates that counts as an
/// informative sample of the reflection estimate, m.
pub const REFLECTION_MIN_CHANGE_M: f64 = 0.1;

/// The section `frame.estimation`: how fast the sensors' estimates move.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct EstimationConfig {
    /// Weight of the configured reflection offset (the class's `extent.offset_scale`) in
    /// samples: informative updates of confirmed tracks, one sample per 0.5 m of change of the
    /// expected outline offset (absent: 50).
    #[cfg_attr(feature = "serde", serde(default = "default_reflection_prior_samples"))]
    pub reflection_prior_samples: f64,
    /// Memory of the reflection estimate, samples (absent: 400).
    #[cfg_attr(feature = "serde", serde(default = "default_reflection_window_samples"))]
    pub reflection_window_samples: f64,
    /// Weight of the configured detection probability, in opportunities: confirmed tracks in
    /// the field of view of a scanning sensor, not hidden from it by another where it missed
    /// them (absent: 2; the configured value is the existence
    /// model's, not the radar's rate, so the data take over at once).
    #[cfg_attr(feature = "serde", serde(default = "default_existence_prior_samples"))]
    pub detection_prior_samples: f64,
    /// Weight of the configured clutter density, in scans of the sensor (absent: 2).
    #[cfg_attr(feature = "serde", serde(default = "default_existence_prior_samples"))]
    pub clutter_prior_scans: f64,
    /// Memory of the detection-probability and clutter estimates, opportunities and scans
    /// (absent: 2000).
    #[cfg_attr(feature = "serde", serde(default = "default_existence_window_samples"))]
    pub existence_window_samples: f64,
}

#[cfg(feature = "serde")]
fn default_reflection_prior_samples() -> f64 {
    EstimationConfig::default().reflection_prior_samples
}
#[cfg(feature = "serde")]
fn default_reflection_window_samples() -> f64 {
    EstimationConfig::default().reflection_window_samples
}
#[cfg(feature = "serde")]
fn default_existence_prior_samples() -> f64 {
    EstimationConfig::default().detection_prior_samples
}
#[cfg(feature = "serde")]
fn default_existence_window_samples() -> f64 {
    EstimationConfig::default().existence_window_samples
}

impl Default for EstimationConfig {
    fn default() -> Self {
        EstimationConfig {
            reflection_prior_samples: 50.0,
            reflection_window_samples: 400.0,
            detection_prior_samples: 2.0,
            clutter_prior_scans: 2.0,
            existence_window_samples: 2000.0,
        }
    }
}

impl EstimationConfig {
    /// The first problem of the section, as (key, reason).
    pub(crate) fn problem(&self) -> Option<(&'static str, &'static str)> {
        let positive = |value: f64| value > 0.0 && value <= 1e9;
        if !positive(self.reflection_prior_samples) || !positive(self.reflection_window_samples) {
            return Some((
                "frame.estimation",
                "reflection_prior_samples and reflection_window_samples must lie in (0, 1e9]",
            ));
        }
        if !positive(self.detection_prior_samples)
            || !positive(self.clutter_prior_scans)
            || !positive(self.existence_window_samples)
        {
            return Some((
                "frame.estimation",
                "detection_prior_samples, clutter_prior_scans and existence_window_samples must lie in (0, 1e9]",
            ));
        }
        None
    }
}

/// Where a sensor's detections of a class lie between the object's centre (0) and the expected
/// reflection on its outline (1).
///
/// A track's filter absorbs any constant error of the reflection model into its centre, so the
/// innovation says nothing about the offset while the offset stays the same; it says so when
/// the offset changes (the aspect turns, another sensor sees another face). With `o_k` the
/// expected outline offset of the track's object at this update, `Δo = o_k − o_(k−1)` its change
/// since the track's previous update and `ν = z − p⁻ − s·o_k` the innovation under the scale
/// `s` the step used, a wrong scale leaves `E[ν] ≈ g (s_true − s) Δo` (g ∈ (0, 1] the share of
/// the previous offset the centre absorbed). The estimate is the weighted stochastic
/// approximation
///
/// ```text
/// s ← clamp(s + (ν·Δo / σ²) / (W₀ + W),   W ← min(W + |Δo|² / σ², W_max))
/// ```
///
/// with σ² half the trace of the innovation covariance, `W₀` the prior's weight and `W_max` the
/// window; its fixed point is `E[ν·Δo] = 0`, the true scale, whatever g is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReflectionEstimate {
    /// The estimate, dimensionless in [0, 1].
    pub value: f64,
    /// Accumulated weight of the samples, in samples (see [`REFLECTION_SAMPLE_M2`]), at most the
    /// window.
    pub weight_samples: f64,
    /// Informative samples taken (a change of the outline offset of at least
    /// [`REFLECTION_MIN_CHANGE_M`]).
    pub samples: u64,
    /// Steps that would have left the bounds.
    pub bounded: u64,
}

impl ReflectionEstimate {
    /// The estimate at its prior.
    pub fn new(prior: f64) -> Self {
        ReflectionEstimate {
            value: prior.clamp(REFLECTION_BOUNDS.0, REFLECTION_BOUNDS.1),
            weight_samples: 0.0,
            samples: 0,
            bounded: 0,
        }
    }

    /// Takes one update of a confirmed track under the estimate's own scale: its innovation
    /// `innovation_m`, the change of its expected outline offset that the geometry alone made
    /// since the track's previous update `offset_change_m`, and the innovation's variance
    /// `variance_m2`.
    pub fn observe(
        &mut self,
        config: &EstimationConfig,
        innovation_m: DVec2,
        offset_change_m: DVec2,
        variance_m2: f64,
    ) {
        let change_m2 = offset_change_m.length_squared();
        if !(change_m2 >= REFLECTION_MIN_CHANGE_M * REFLECTION_MIN_CHANGE_M)
            || !(variance_m2 > 0.0)
            || !innovation_m.is_finite()
            || !offset_change_m.is_finite()
        {
            return;
        }
        // Weights in samples: a sample is REFLECTION_SAMPLE_M2 of squared change at an
        // innovation variance of REFLECTION_SAMPLE_M2.
        let weight = change_m2 / variance_m2;
        let prior_weight = config.reflection_prior_samples;
        self.weight_samples = (self.weight_samples + weight).min(config.reflection_window_samples);
        let step = innovation_m.dot(offset_change_m) / variance_m2 / (prior_weight + self.weight_samples);
        let proposed = self.value + step;
        let (low, high) = REFLECTION_BOUNDS;
        if proposed < low || proposed > high || !proposed.is_finite() {
            self.bounded += 1;
        }
        self.value = if proposed.is_finite() { proposed.clamp(low, high) } else { self.value };
        self.samples += 1;
    }
}

/// How often a sensor detects an object of a class in its field of view and in clear view:
/// detections of confirmed tracks over opportunities (confirmed tracks in view of the scanning
/// sensor, less the misses of those another confirmed track hides from it). The
/// configured probability enters as `detection_prior_samples` pseudo-opportunities with that
/// rate, `p = (n₀ p₀ + hits) / (n₀ + opportunities)`; beyond the window both counts, the prior's
/// included, are scaled down together, so the prior is forgotten like any old sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectionEstimate {
    /// The configured probability (the prior).
    pub prior: f64,
    /// Opportunities, the prior's pseudo-opportunities included, within the window (0 before
    /// the first).
    pub opportunities: f64,
    /// Detections among them.
    pub detections: f64,
    /// Opportunities taken in all.
    pub samples: u64,
    /// Times the estimate lay outside its bounds and was held at them.
    pub bounded: u64,
}

impl DetectionEstimate {
    /// The estimate at its prior.
    pub fn new(prior: f64) -> Self {
        DetectionEstimate { prior, opportunities: 0.0, detections: 0.0, samples: 0, bounded: 0 }
    }

    /// The estimate, within [`DETECTION_BOUNDS`].
    pub fn value(&self) -> f64 {
        if !(self.opportunities > 0.0) {
            return self.prior;
        }
        (self.detections / self.opportunities).clamp(DETECTION_BOUNDS.0, DETECTION_BOUNDS.1)
    }

    /// Takes one opportunity: a confirmed track in view, `detected` or not.
    pub fn observe(&mut self, config: &EstimationConfig, detected: bool) {
        if self.samples == 0 {
            self.opportunities = config.detection_prior_samples;
            self.detections = config.detection_prior_samples * self.prior;
        }
        self.opportunities += 1.0;
        self.detections += f64::from(u8::from(detected));
        self.samples += 1;
        let window = config.existence_window_samples.max(config.detection_prior_samples);
        if self.opportunities > window {
            let scale = window / self.opportunities;
            self.opportunities = window;
            self.detections *= scale;
        }
        let raw = self.detections / self.opportunities;
        if !(DETECTION_BOUNDS.0..=DETECTION_BOUNDS.1).contains(&raw) {
            self.bounded += 1;
        }
    }
}

/// How much clutter a sensor reports of a class, per scan and square metre of its field of
/// view: the detections that started tracks which ended without being confirmed, over the
/// scans' field-of-view areas. The configured density enters as `clutter_prior_scans`
/// pseudo-scans of the first scan's area at that density, `λ = (E₀ λ₀ + false detections) /
/// (E₀ + Σ areas)`; beyond the window, exposure and count, the prior's included, are scaled down
/// together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClutterEstimate {
    /// The configured density (the prior), 1/m².
    pub prior_per_m2: f64,
    /// Sum of the scans' areas within the window, the prior's pseudo-scans included, m².
    pub exposure_m2: f64,
    /// False detections within the window, the prior's included.
    pub false_detections: f64,
    /// Scans taken in all.
    pub scans: u64,
    /// Times the estimate lay outside its bounds and was held at them.
    pub bounded: u64,
}

impl ClutterEstimate {
    /// The estimate at its prior.
    pub fn new(prior_per_m2: f64) -> Self {
        ClutterEstimate { prior_per_m2, exposure_m2: 0.0, false_detections: 0.0, scans: 0, bounded: 0 }
    }

    /// The estimate, 1/m², within [`CLUTTER_BOUNDS_PER_M2`].
    pub fn value_per_m2(&self) -> f64 {
        if !(self.exposure_m2 > 0.0) {
            return self.prior_per_m2;
        }
        (self.false_detections / self.exposure_m2).clamp(CLUTTER_BOUNDS_PER_M2.0, CLUTTER_BOUNDS_PER_M2.1)
    }

    /// Takes one scan of the sensor over `area_m2`.
    pub fn observe_scan(&mut self, config: &EstimationConfig, area_m2: f64) {
        if !(area_m2 > 0.0 && area_m2.is_finite()) {
            return;
        }
        if self.scans == 0 {
            self.exposure_m2 = config.clutter_prior_scans * area_m2;
            self.false_detections = self.exposure_m2 * self.prior_per_m2;
        }
        self.exposure_m2 += area_m2;
        self.scans += 1;
        let window = config.existence_window_samples.max(config.clutter_prior_scans) * area_m2;
        if self.exposure_m2 > window {
            let scale = window / self.exposure_m2;
            self.exposure_m2 = window;
            self.false_detections *= scale;
        }
    }

    /// Takes `count` detections found to be false (a tentative track ended unconfirmed).
    pub fn observe_false(&mut self, count: u32) {
        if !(self.exposure_m2 > 0.0) {
            // No scan of the sensor yet to hold them against.
            return;
        }
        self.false_detections += f64::from(count);
        if self.false_detections / self.exposure_m2 > CLUTTER_BOUNDS_PER_M2.1 {
            self.bounded += 1;
        }
    }
}

/// The area of a sector of half opening angle `half_angle_rad` out to `range_m`, m².
pub fn sector_area_m2(half_angle_rad: f64, range_m: f64) -> f64 {
    half_angle_rad * math::square(range_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reflection_estimate_without_evidence_stays_at_its_prior() {
        let config = EstimationConfig::default();
        let mut estimate = ReflectionEstimate::new(0.5);
        // Offsets that do not change carry no information.
        for _ in 0..1000 {
            estimate.observe(&config, DVec2::new(0.3, -0.2), DVec2::new(0.01, 0.0), 0.5);
        }
        assert_eq!(estimate.value, 0.5);
        assert_eq!(estimate.samples, 0);
    }

    #[test]
    fn a_reflection_estimate_follows_innovations_that_follow_the_offset_change() {
        let config = EstimationConfig::default();
        let mut estimate = ReflectionEstimate::new(0.5);
        // Data made with scale 0: the innovation is minus the used scale times the change.
        let mut rng = 12345u64;
        for k in 0..4000 {
            let angle = f64::from(k) * 0.7;
            let change = DVec2::new(angle.cos(), angle.sin()) * 0.8;
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let noise = ((rng >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.6;
            let innovation = -estimate.value * 0.7 * change + DVec2::new(noise, -noise);
            estimate.observe(&config, innovation, change, 0.5);
        }
        assert!(estimate.value < 0.05, "{}", estimate.value);
    }

    #[test]
    fn a_reflection_estimate_pushed_beyond_its_bounds_is_held_and_counted() {
        let config = EstimationConfig::default();
        let mut estimate = ReflectionEstimate::new(0.9);
        for _ in 0..200 {
            estimate.observe(&config, DVec2::new(5.0, 0.0), DVec2::X, 0.1);
        }
        assert_eq!(estimate.value, 1.0);
        assert!(estimate.bounded > 0);
    }

    #[test]
    fn a_detection_estimate_moves_from_its_prior_to_the_observed_rate() {
        let config = EstimationConfig::default();
        let mut estimate = DetectionEstimate::new(0.2);
        assert_eq!(estimate.value(), 0.2);
        for k in 0..10_000 {
            estimate.observe(&config, k % 10 != 0);
        }
        assert!((estimate.value() - 0.9).abs() < 0.02, "{}", estimate.value());
    }

    #[test]
    fn a_clutter_estimate_counts_false_detections_per_area_and_scan() {
        let config = EstimationConfig::default();
        let mut estimate = ClutterEstimate::new(1e-4);
        assert_eq!(estimate.value_per_m2(), 1e-4);
        for _ in 0..20_000 {
            estimate.observe_scan(&config, 1000.0);
            estimate.observe_false(2);
        }
        let value = estimate.value_per_m2();
        assert!((value - 2e-3).abs() < 1e-4, "{value}");
    }

    #[test]
    fn a_flood_of_clutter_is_held_at_the_bound_and_counted() {
        let config = EstimationConfig::default();
        let mut estimate = ClutterEstimate::new(1e-4);
        for _ in 0..3000 {
            estimate.observe_scan(&config, 10.0);
            estimate.observe_false(50);
        }
        assert_eq!(estimate.value_per_m2(), CLUTTER_BOUNDS_PER_M2.1);
        assert!(estimate.bounded > 0);
    }
}
