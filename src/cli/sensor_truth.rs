//! `primm sensor-truth`: the true reflection offset fraction, detection probability and clutter
//! density of each simulated sensor and class ([`primm_sim::eval::sensor_truth`]), from a
//! preset's or a scenario file's sequences generated in memory with their ground truth.

use std::path::PathBuf;

use clap::Args as ClapArgs;

use super::generate::{read_scenario_file, GenerateError, PresetChoice};
use primm_sim::eval::{format_sensor_truth, SensorClassTruth, SensorTruthAccumulator, UnknownSensor};
use primm_sim::scenario::{ConfigError, Preset, ScenarioConfig, ScenarioGenerator, Split};

/// `--split`: `train`, `validation` or `evaluation`.
fn parse_split(text: &str) -> Result<Split, String> {
    Split::ALL
        .into_iter()
        .find(|split| split.name() == text)
        .ok_or_else(|| format!("`{text}` is not one of `train`, `validation`, `evaluation`"))
}

/// Arguments of `primm sensor-truth`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "The true reflection offset fraction, detection probability and clutter density per simulated sensor and class"
)]
pub struct Args {
    /// Configuration preset whose sequences are generated (in memory).
    #[arg(long, value_enum, default_value = "default")]
    pub preset: PresetChoice,
    /// Read the scenario configuration from this TOML file instead of a preset.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub scenario: Option<PathBuf>,
    /// Split whose sequences are used.
    #[arg(long, value_parser = parse_split, default_value = "validation", value_name = "SPLIT")]
    pub split: Split,
    /// Number of sequences (default: the split's size in the configuration).
    #[arg(long, value_name = "N")]
    pub sequences: Option<u32>,
    /// Tracker configuration whose `classes.<class>.extent` gives the outline offsets (the
    /// shipped configuration otherwise).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Write the table as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// Why `primm sensor-truth` failed.
#[derive(Debug, thiserror::Error)]
pub enum SensorTruthError {
    /// The scenario file could not be read or is invalid.
    #[error(transparent)]
    Scenario(#[from] GenerateError),
    /// The scenario configuration is invalid.
    #[error(transparent)]
    Invalid(#[from] ConfigError),
    /// The tracker configuration could not be read or is invalid.
    #[error(transparent)]
    Config(#[from] primm_config::ConfigError),
    /// A frame came from a sensor without a mount.
    #[error(transparent)]
    UnknownSensor(#[from] UnknownSensor),
    /// The JSON file could not be made.
    #[error("cannot encode the table as JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// The JSON file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// The truth table of `sequences` sequences (all when `None`) of `split` of `scenario`, with
/// the class extents of `tracker`.
pub fn sensor_truth(
    scenario: ScenarioConfig,
    split: Split,
    sequences: Option<u32>,
    tracker: &primm_core::config::Config,
) -> Result<Vec<SensorClassTruth>, SensorTruthError> {
    let mounts = scenario.radar.sensor_layout();
    let generator = ScenarioGenerator::new(scenario)?;
    let count = sequences.unwrap_or_else(|| generator.sequence_count(split));
    let mut accumulator = SensorTruthAccumulator::new(&mounts, tracker);
    for index in 0..count {
        accumulator.add_sequence(&generator.generate(split, index))?;
    }
    Ok(accumulator.finish())
}

/// Runs `primm sensor-truth`: prints the table and writes the JSON file.
pub fn run(args: &Args) -> Result<(), SensorTruthError> {
    let scenario = match &args.scenario {
        Some(path) => read_scenario_file(path)?,
        None => Preset::from(args.preset).config(),
    };
    let tracker = match &args.config {
        Some(path) => primm_config::from_file(path)?,
        None => primm_core::config::Config::default(),
    };
    let rows = sensor_truth(scenario, args.split, args.sequences, &tracker)?;
    print!("{}", format_sensor_truth(&rows));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows)?;
        std::fs::write(path, text)
            .map_err(|source| SensorTruthError::Write { path: path.clone(), source })?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_core::measurement::ObjectClass;

    /// The truth of `count` short validation sequences of `preset`, with the shipped tracker
    /// configuration.
    fn truth_of(preset: Preset, count: u32) -> Vec<SensorClassTruth> {
        let mut scenario = preset.config();
        scenario.sequence.duration_s = 3.0;
        sensor_truth(scenario, Split::Validation, Some(count), &primm_core::config::Config::default())
            .expect("the truth of a preset")
    }

    /// The detection-weighted mean reflection offset fraction of the cars over every sensor.
    fn car_reflection_fraction(rows: &[SensorClassTruth]) -> f64 {
        let cars: Vec<&SensorClassTruth> = rows.iter().filter(|row| row.class == ObjectClass::Car).collect();
        let detections: u64 = cars.iter().map(|row| row.detections).sum();
        assert!(detections > 100, "{detections} car detections");
        cars.iter().map(|row| row.reflection_offset_fraction.unwrap() * row.detections as f64).sum::<f64>()
            / detections as f64
    }

    #[test]
    fn centre_reports_lie_at_no_fraction_of_the_outline_and_extended_reflections_further_out_than_echoes() {
        let centroid = car_reflection_fraction(&truth_of(Preset::Centroid, 2));
        let default = car_reflection_fraction(&truth_of(Preset::Default, 2));
        let extended = car_reflection_fraction(&truth_of(Preset::Extended, 2));
        assert!(centroid.abs() < 0.05, "centroid {centroid}");
        assert!(default > centroid + 0.2, "default {default}, centroid {centroid}");
        assert!(extended > default + 0.1, "extended {extended}, default {default}");
    }

    #[test]
    fn detection_probability_and_clutter_follow_the_preset() {
        let default = truth_of(Preset::Default, 1);
        let clutter = truth_of(Preset::Clutter, 1);
        for row in &default {
            assert_eq!(row.false_detections, 0, "{row:?}");
            assert_eq!(row.clutter_density_per_m2, Some(0.0), "{row:?}");
            let probability = row.detection_probability.expect("objects in view");
            assert!(probability > 0.3 && probability < 1.0, "{row:?}");
            assert!(row.objects_detected <= row.objects_in_view);
        }
        // About 1.5 false detections per scan over the sector up to 80 m of a 100 m sensor.
        let false_detections: u64 = clutter.iter().map(|row| row.false_detections).sum();
        let scans: u64 =
            clutter.iter().filter(|row| row.class == ObjectClass::Car).map(|row| row.scans).sum();
        let per_scan = false_detections as f64 / scans as f64;
        assert!((1.2..2.0).contains(&per_scan), "{per_scan} false detections per scan");
        assert!(clutter.iter().all(|row| row.clutter_density_per_m2.unwrap() > 0.0));
    }

    #[test]
    fn a_frame_of_a_sensor_without_a_mount_is_refused() {
        let scenario = Preset::Default.config();
        let mut short = scenario.clone();
        short.sequence.duration_s = 0.5;
        let generated = ScenarioGenerator::new(short).unwrap().generate(Split::Validation, 0);
        let mut accumulator = SensorTruthAccumulator::new(
            &scenario.radar.sensor_layout()[..1],
            &primm_core::config::Config::default(),
        );
        let error = accumulator.add_sequence(&generated).unwrap_err();
        assert_ne!(error.sensor_id, scenario.radar.sensors[0].layout.id);
    }
}
