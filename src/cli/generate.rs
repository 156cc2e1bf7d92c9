//! `primm generate`: writes simulated radar sequences as measurement CSV files.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};

use primm_sim::io::{write_sequence_file, CsvError};
use primm_sim::scenario::{format_table, ConfigError, Preset, ScenarioGenerator, Split, SplitSummary};

/// Which splits to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SplitChoice {
    /// Training split only.
    Train,
    /// Validation split only.
    Validation,
    /// Evaluation split only.
    Evaluation,
    /// All three splits.
    All,
}

impl SplitChoice {
    /// The splits selected.
    pub fn splits(self) -> Vec<Split> {
        match self {
            SplitChoice::Train => vec![Split::Train],
            SplitChoice::Validation => vec![Split::Validation],
            SplitChoice::Evaluation => vec![Split::Evaluation],
            SplitChoice::All => Split::ALL.to_vec(),
        }
    }
}

/// Configuration preset names accepted on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PresetChoice {
    /// The reference configuration.
    Default,
    /// Faster objects, more erratic pedestrians, noisier sensors.
    Robustness,
    /// An ego vehicle that turns at most junctions (yaw rates up to about 0.5 rad/s).
    Turning,
}

impl From<PresetChoice> for Preset {
    fn from(choice: PresetChoice) -> Self {
        match choice {
            PresetChoice::Default => Preset::Default,
            PresetChoice::Robustness => Preset::Robustness,
            PresetChoice::Turning => Preset::Turning,
        }
    }
}

/// Arguments of `primm generate`.
#[derive(Debug, Clone, ClapArgs)]
#[command(about = "Generate simulated radar sequences (one CSV file per sequence in DIR/<split>/)")]
pub struct Args {
    /// Output directory; sequences go to DIR/train, DIR/validation and DIR/evaluation.
    #[arg(long, value_name = "DIR")]
    pub output: PathBuf,
    /// Base of the sequence seeds (default: the preset's).
    #[arg(long, value_name = "N")]
    pub seed_base: Option<u64>,
    /// Split to generate.
    #[arg(long, value_enum, default_value = "all")]
    pub split: SplitChoice,
    /// Configuration preset.
    #[arg(long, value_enum, default_value = "default")]
    pub preset: PresetChoice,
    /// Number of sequences per selected split (default: the preset's 130 / 6 / 22).
    #[arg(long, value_name = "N")]
    pub sequences: Option<u32>,
    /// Recorded duration of each sequence, seconds (default: the preset's).
    #[arg(long, value_name = "S")]
    pub duration_s: Option<f64>,
}

/// Why `primm generate` failed.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// The options make an invalid scenario configuration.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A split's output directory could not be created.
    #[error("cannot create {}: {source}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A sequence could not be written.
    #[error(transparent)]
    Write(#[from] CsvError),
}

/// Runs `primm generate`: writes the CSV files and prints the per-split counts.
pub fn run(args: &Args) -> Result<(), GenerateError> {
    let mut config = Preset::from(args.preset).config();
    if let Some(seed_base) = args.seed_base {
        config.splits.seed_base = seed_base;
    }
    if let Some(duration_s) = args.duration_s {
        config.sequence.duration_s = duration_s;
    }
    let splits = args.split.splits();
    if let Some(count) = args.sequences {
        for split in &splits {
            match split {
                Split::Train => config.splits.train_sequences = count,
                Split::Validation => config.splits.validation_sequences = count,
                Split::Evaluation => config.splits.evaluation_sequences = count,
            }
        }
    }
    let generator = ScenarioGenerator::new(config)?;
    let mut summaries = Vec::new();
    for split in splits {
        let dir = args.output.join(split.name());
        std::fs::create_dir_all(&dir)
            .map_err(|source| GenerateError::CreateDir { path: dir.clone(), source })?;
        let mut summary = SplitSummary::new(split);
        for generated in generator.split_sequences(split) {
            let path = dir.join(format!("{}.csv", generated.sequence.name));
            write_sequence_file(&path, &generated.sequence)?;
            summary.add_generated(&generated);
        }
        eprintln!("wrote {} sequences to {}", summary.sequences, dir.display());
        summaries.push(summary);
    }
    print!("{}", format_table(&summaries));
    Ok(())
}
