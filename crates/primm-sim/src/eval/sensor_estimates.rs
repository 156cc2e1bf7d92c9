//! How close the tracker's online estimates of its sensors come to the simulated truth: each
//! sequence of a split is generated, its truth taken ([`super::sensor_truth`]) and tracked from
//! scratch with the IMM, and the estimates the tracker holds at the sequence's end
//! ([`primm_core::tracker::Tracker::sensors`]) are compared with that sequence's truth.
//!
//! * **Detection probability**: the estimate against the truth within the class's detection
//!   range (the tracker only learns where it can hold a track) and in clear view of the sensor
//!   (the tracker leaves out the tracks another confirmed track hides).
//! * **Clutter density**: the estimate against the false detections of the class per scan and
//!   m² of the field of view.
//!
//! A (sequence, sensor, class) cell is scored once the estimate rests on at least
//! [`MIN_SAMPLES`] samples (opportunities or scans); it is *within tolerance* when it lies within
//! [`RELATIVE_TOLERANCE`] of the truth, or, for a clutter density, within
//! [`CLUTTER_RESOLUTION_PER_M2`] of it (a truth of zero has no relative scale). Sensors the
//! tracker does not know by id are compared with its unmounted sensor, which then holds every
//! frame without a known id.

use std::collections::BTreeMap;

use serde::Serialize;

use super::sensor_truth::{SensorClassTruth, SensorTruthAccumulator, UnknownSensor};
use crate::offline::{track_sequence, OfflineError};
use crate::scenario::{ScenarioGenerator, Split};
use primm_core::config::{Config, ConfigError};
use primm_core::measurement::ObjectClass;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;

/// Samples (opportunities for the detection probability, scans for the clutter density) an
/// estimate needs before its cell is scored.
pub const MIN_SAMPLES: u64 = 100;
/// The relative tolerance of a converged estimate.
pub const RELATIVE_TOLERANCE: f64 = 0.1;
/// The absolute tolerance of a clutter density, 1/m²: a tenth of a false detection per scan of
/// a 10,000 m² field of view.
pub const CLUTTER_RESOLUTION_PER_M2: f64 = 1e-5;

/// The quantity a row compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EstimatedQuantity {
    /// The detection probability, dimensionless.
    DetectionProbability,
    /// The clutter density, 1/m² per scan.
    ClutterDensity,
}

impl EstimatedQuantity {
    /// The short name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            EstimatedQuantity::DetectionProbability => "detection_probability",
            EstimatedQuantity::ClutterDensity => "clutter_density_per_m2",
        }
    }
}

/// One sensor, class and quantity over the sequences of a split.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimateComparison {
    /// The sensor (the generator's id).
    pub sensor_id: u16,
    /// The class.
    pub class: ObjectClass,
    /// What is compared.
    pub quantity: EstimatedQuantity,
    /// Sequences whose estimate rests on at least [`MIN_SAMPLES`] samples and has a truth.
    pub scored: u32,
    /// Of those, the ones within tolerance.
    pub within_tolerance: u32,
    /// Mean truth over the scored sequences.
    pub mean_truth: f64,
    /// Mean estimate over the scored sequences.
    pub mean_estimate: f64,
    /// Mean of |estimate − truth| / truth over the scored sequences with a truth above zero
    /// (NaN without one).
    pub mean_relative_error: f64,
}

/// Why a comparison could not be made.
#[derive(Debug, thiserror::Error)]
pub enum EstimateComparisonError {
    /// The tracker configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A frame came from a sensor the generator does not mount.
    #[error(transparent)]
    UnknownSensor(#[from] UnknownSensor),
    /// The tracker refused a sequence.
    #[error(transparent)]
    Tracking(#[from] OfflineError),
}

#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    scored: u32,
    within: u32,
    truth: f64,
    estimate: f64,
    relative_error: f64,
    relative_count: u32,
}

impl Sums {
    fn add(&mut self, quantity: EstimatedQuantity, truth: f64, estimate: f64) {
        let error = (estimate - truth).abs();
        let tolerance = match quantity {
            EstimatedQuantity::DetectionProbability => RELATIVE_TOLERANCE * truth,
            EstimatedQuantity::ClutterDensity => (RELATIVE_TOLERANCE * truth).max(CLUTTER_RESOLUTION_PER_M2),
        };
        self.scored += 1;
        self.within += u32::from(error <= tolerance);
        self.truth += truth;
        self.estimate += estimate;
        if truth > 0.0 {
            self.relative_error += error / truth;
            self.relative_count += 1;
        }
    }
}

/// Compares the estimates of an IMM tracker of configuration `config` with the truth on
/// `sequences` sequences (all when `None`) of `split` of `generator`.
pub fn compare_estimates_of_split(
    generator: &ScenarioGenerator,
    split: Split,
    sequences: Option<u32>,
    config: &Config,
) -> Result<Vec<EstimateComparison>, EstimateComparisonError> {
    let count = sequences.unwrap_or_else(|| generator.sequence_count(split));
    let mut tracker = Tracker::new(config.clone().with_modes(Method::Imm.modes()))?;
    let mut sums: BTreeMap<(u16, usize, EstimatedQuantity), Sums> = BTreeMap::new();
    for index in 0..count {
        let generated = generator.generate(split, index);
        let mut truth = SensorTruthAccumulator::new(generator.config(), config);
        truth.add_sequence(&generated)?;
        track_sequence(&mut tracker, &generated.sequence, |_, _| {})?;
        for row in truth.finish() {
            for (quantity, truth, estimate, samples) in cells(&tracker, &row) {
                if samples >= MIN_SAMPLES {
                    sums.entry((row.sensor_id, row.class.index(), quantity))
                        .or_default()
                        .add(quantity, truth, estimate);
                }
            }
        }
    }
    Ok(sums
        .into_iter()
        .map(|((sensor_id, class_index, quantity), sums)| {
            let scored = f64::from(sums.scored.max(1));
            EstimateComparison {
                sensor_id,
                class: ObjectClass::ALL[class_index],
                quantity,
                scored: sums.scored,
                within_tolerance: sums.within,
                mean_truth: sums.truth / scored,
                mean_estimate: sums.estimate / scored,
                mean_relative_error: if sums.relative_count > 0 {
                    sums.relative_error / f64::from(sums.relative_count)
                } else {
                    f64::NAN
                },
            }
        })
        .collect())
}

/// The tracker's estimates of `row`'s sensor and class next to the truth: (quantity, truth,
/// estimate, samples) for each quantity with a truth.
fn cells<P: primm_core::predictor::DisplacementPredictor>(
    tracker: &Tracker<P>,
    row: &SensorClassTruth,
) -> impl Iterator<Item = (EstimatedQuantity, f64, f64, u64)> {
    let sensors = tracker.sensors();
    let estimates = sensors.get(sensors.slot(Some(row.sensor_id))).estimates[row.class.index()];
    let detection = row.detection_probability_in_clear_view.map(|truth| {
        (
            EstimatedQuantity::DetectionProbability,
            truth,
            estimates.detection.value(),
            estimates.detection.samples,
        )
    });
    let clutter = row.clutter_density_per_m2.map(|truth| {
        (EstimatedQuantity::ClutterDensity, truth, estimates.clutter.value_per_m2(), estimates.clutter.scans)
    });
    detection.into_iter().chain(clutter)
}

/// The comparison as plain text, one row per sensor, class and quantity.
pub fn format_estimate_comparison(rows: &[EstimateComparison]) -> String {
    let mut text = format!(
        "{:>6} {:<11} {:<23} {:>7} {:>7} {:>11} {:>11} {:>9}\n",
        "sensor", "class", "quantity", "scored", "within", "truth", "estimate", "rel.err"
    );
    for row in rows {
        text.push_str(&format!(
            "{:>6} {:<11} {:<23} {:>7} {:>7} {:>11.4e} {:>11.4e} {:>9.3}\n",
            row.sensor_id,
            row.class.name(),
            row.quantity.name(),
            row.scored,
            row.within_tolerance,
            row.mean_truth,
            row.mean_estimate,
            row.mean_relative_error,
        ));
    }
    let (scored, within) = rows.iter().fold((0, 0), |(s, w), row| (s + row.scored, w + row.within_tolerance));
    text.push_str(&format!(
        "{within} of {scored} scored cells within {:.0} % of the truth (clutter: or within {CLUTTER_RESOLUTION_PER_M2:e} /m²)\n",
        100.0 * RELATIVE_TOLERANCE
    ));
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Preset;

    #[test]
    fn a_tolerance_counts_relative_errors_and_a_clutter_resolution() {
        let mut sums = Sums::default();
        sums.add(EstimatedQuantity::DetectionProbability, 0.8, 0.85);
        sums.add(EstimatedQuantity::DetectionProbability, 0.8, 0.95);
        sums.add(EstimatedQuantity::ClutterDensity, 0.0, 5e-6);
        assert_eq!((sums.scored, sums.within, sums.relative_count), (3, 2, 2));
    }

    #[test]
    fn the_detection_probability_of_a_well_seen_sensor_converges_within_the_tolerance() {
        // One default validation sequence, in memory: the sensors that see most cars.
        let generator = ScenarioGenerator::new(Preset::Default.config()).unwrap();
        let rows =
            compare_estimates_of_split(&generator, Split::Validation, Some(1), &Config::default()).unwrap();
        let cars: Vec<_> = rows
            .iter()
            .filter(|row| {
                row.class == ObjectClass::Car && row.quantity == EstimatedQuantity::DetectionProbability
            })
            .collect();
        assert!(cars.iter().map(|row| row.scored).sum::<u32>() >= 2, "{rows:?}");
        for row in cars {
            assert_eq!(row.within_tolerance, row.scored, "{row:?}");
        }
    }
}
