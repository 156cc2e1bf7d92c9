//! `primm sensor-truth`: the true reflection offset fraction, detection probability and clutter
//! density of each simulated sensor and class ([`primm_sim::eval::sensor_truth`]), from a
//! preset's or a scenario file's sequences generated in memory with their ground truth; with
//! `--estimates`, also how close an IMM tracker's online estimates of its sensors come to it
//! ([`primm_sim::eval::sensor_estimates`]).

use std::path::PathBuf;

use clap::Args as ClapArgs;

use super::generate::{read_scenario_file, GenerateError, PresetChoice};
use primm_sim::eval::{
    compare_estimates_of_split, format_estimate_comparison, format_sensor_truth, sensor_truth_of_split,
    EstimateComparisonError, UnknownSensor,
};
use primm_sim::scenario::{ConfigError, Preset, ScenarioGenerator, Split};

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
    /// Also track every sequence with the IMM (the configuration of `--config`) and compare the
    /// tracker's estimates of its sensors with the truth.
    #[arg(long)]
    pub estimates: bool,
    /// Write the comparison of `--estimates` as CSV to this file.
    #[arg(long, value_name = "FILE", requires = "estimates")]
    pub estimates_csv: Option<PathBuf>,
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
    /// The estimates could not be compared.
    #[error(transparent)]
    Estimates(#[from] EstimateComparisonError),
    /// The CSV file could not be written.
    #[error("cannot write CSV: {0}")]
    Csv(#[from] csv::Error),
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
    let generator = ScenarioGenerator::new(scenario)?;
    let rows = sensor_truth_of_split(&generator, args.split, args.sequences, &tracker)?;
    print!("{}", format_sensor_truth(&rows));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&rows)?;
        std::fs::write(path, text)
            .map_err(|source| SensorTruthError::Write { path: path.clone(), source })?;
        eprintln!("wrote {}", path.display());
    }
    if args.estimates {
        let comparison = compare_estimates_of_split(&generator, args.split, args.sequences, &tracker)?;
        print!("{}", format_estimate_comparison(&comparison));
        if let Some(path) = &args.estimates_csv {
            let mut writer = csv::Writer::from_path(path)?;
            for row in &comparison {
                writer.serialize(row)?;
            }
            writer.flush().map_err(|source| SensorTruthError::Write { path: path.clone(), source })?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}
