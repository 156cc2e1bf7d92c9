//! `primm generate`: writes simulated radar sequences as measurement CSV files.

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, ValueEnum};

use primm_sim::io::{write_sequence_file, CsvError};
use primm_sim::scenario::{
    format_table, ConfigError, Preset, ScenarioConfig, ScenarioGenerator, ScenarioTomlError, Split,
    SplitSummary,
};

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
    /// The default scene with false detections: about 1.5 per scan, mostly static, some
    /// moving-looking, a few multipath ghosts.
    Clutter,
    /// The turning scene with the clutter preset's false detections.
    #[value(name = "clutter_turning", alias = "clutter-turning")]
    ClutterTurning,
    /// The default scene with vehicles measured as extended objects: detections from the
    /// visible contour and corners of each box, now and then several per vehicle and scan.
    Extended,
    /// The turning scene with extended vehicles.
    #[value(name = "extended_turning", alias = "extended-turning")]
    ExtendedTurning,
    /// The clutter scene with extended vehicles.
    #[value(name = "extended_clutter", alias = "extended-clutter")]
    ExtendedClutter,
    /// The clutter-turning scene with extended vehicles.
    #[value(name = "extended_clutter_turning", alias = "extended-clutter-turning")]
    ExtendedClutterTurning,
    /// The default scene seen by object-list radars: each detected object at its true centre
    /// plus noise.
    Centroid,
    /// One static roadside radar in dense traffic (25 to 45 objects in view), frames every 50
    /// to 80 ms without ego pose or sensor id, a little clutter.
    #[value(name = "dense_static", alias = "dense-static")]
    DenseStatic,
    /// The turning clutter scene seen by detection-level radars: several detections per car
    /// over its faces and wheels, one or two per pedestrian, multipath ghosts behind walls,
    /// about three clutter points per scan, a tenth of the class labels wrong.
    #[value(name = "point_cloud", alias = "point-cloud")]
    PointCloud,
    /// The point_cloud scene from radars that resolve range finer than azimuth: a car's near
    /// side as densely populated as its rear or front.
    #[value(name = "point_cloud_range", alias = "point-cloud-range")]
    PointCloudRange,
}

impl From<PresetChoice> for Preset {
    fn from(choice: PresetChoice) -> Self {
        match choice {
            PresetChoice::Default => Preset::Default,
            PresetChoice::Robustness => Preset::Robustness,
            PresetChoice::Turning => Preset::Turning,
            PresetChoice::Clutter => Preset::Clutter,
            PresetChoice::ClutterTurning => Preset::ClutterTurning,
            PresetChoice::Extended => Preset::Extended,
            PresetChoice::ExtendedTurning => Preset::ExtendedTurning,
            PresetChoice::ExtendedClutter => Preset::ExtendedClutter,
            PresetChoice::ExtendedClutterTurning => Preset::ExtendedClutterTurning,
            PresetChoice::Centroid => Preset::Centroid,
            PresetChoice::DenseStatic => Preset::DenseStatic,
            PresetChoice::PointCloud => Preset::PointCloud,
            PresetChoice::PointCloudRange => Preset::PointCloudRange,
        }
    }
}

/// Arguments of `primm generate`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Generate simulated radar sequences (one CSV file per sequence in DIR/<split>/)",
    after_help = "\
Examples:
  primm generate --output data                                   # train, validation and evaluation splits
  primm generate --output clutter --split evaluation --preset clutter
  primm generate --output short --split evaluation --sequences 2 --duration-s 5"
)]
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
    /// Read the whole scenario configuration from this TOML file instead of a preset (fields
    /// it leaves out take the default preset's values; docs/scenario.md lists them).
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    pub scenario: Option<PathBuf>,
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
    /// The scenario file could not be read.
    #[error("cannot read scenario file {}: {source}", path.display())]
    ReadScenario {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The scenario file is not a valid scenario configuration.
    #[error("scenario file {}: {source}", path.display())]
    Scenario {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        source: ScenarioTomlError,
    },
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

/// Reads a complete scenario configuration from a TOML file (validated; missing fields take
/// the default preset's values).
pub fn read_scenario_file(path: &Path) -> Result<ScenarioConfig, GenerateError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| GenerateError::ReadScenario { path: path.to_path_buf(), source })?;
    ScenarioConfig::from_toml_str(&text)
        .map_err(|source| GenerateError::Scenario { path: path.to_path_buf(), source })
}

/// The configuration the options select: the scenario file's, else the preset's, with the
/// command-line overrides of seed base and duration applied.
fn base_config(args: &Args) -> Result<ScenarioConfig, GenerateError> {
    let mut config = match &args.scenario {
        Some(path) => read_scenario_file(path)?,
        None => Preset::from(args.preset).config(),
    };
    if let Some(seed_base) = args.seed_base {
        config.splits.seed_base = seed_base;
    }
    if let Some(duration_s) = args.duration_s {
        config.sequence.duration_s = duration_s;
    }
    Ok(config)
}

/// Runs `primm generate`: writes the CSV files and prints the per-split counts.
pub fn run(args: &Args) -> Result<(), GenerateError> {
    let mut config = base_config(args)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(arguments: &[&str]) -> Result<Args, clap::Error> {
        Cli::try_parse_from(std::iter::once("generate").chain(arguments.iter().copied())).map(|cli| cli.args)
    }

    fn scratch_file(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("primm-generate-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch directory");
        let path = dir.join(name);
        std::fs::write(&path, text).expect("scratch file");
        path
    }

    #[test]
    fn scenario_file_replaces_the_preset() {
        let path = scratch_file(
            "fast.toml",
            "[splits]\nseed_base = 12345\n[car]\ndesired_speed_mps = [12.0, 18.0]\nmax_speed_mps = 20.0\n\
             [radar]\nscan_jitter_s = 0.004\n",
        );
        let args = parse(&["--output", "out", "--scenario", path.to_str().unwrap()]).expect("arguments");
        let config = base_config(&args).expect("configuration");
        let mut expected = ScenarioConfig::default();
        expected.splits.seed_base = 12345;
        expected.car.desired_speed_mps = [12.0, 18.0];
        expected.car.limits.max_speed_mps = 20.0;
        expected.radar.scan_jitter_s = 0.004;
        assert_eq!(config, expected);
        // The command-line overrides still apply on top of the file.
        let args = parse(&[
            "--output",
            "out",
            "--scenario",
            path.to_str().unwrap(),
            "--seed-base",
            "7",
            "--duration-s",
            "3",
        ])
        .expect("arguments");
        let config = base_config(&args).expect("configuration");
        assert_eq!((config.splits.seed_base, config.sequence.duration_s), (7, 3.0));
        // A whole configuration written out reads back unchanged.
        let turning = ScenarioConfig::turning();
        let path = scratch_file("turning.toml", &toml::to_string(&turning).expect("serialise"));
        let args = parse(&["--output", "out", "--scenario", path.to_str().unwrap()]).expect("arguments");
        assert_eq!(base_config(&args).expect("configuration"), turning);
    }

    #[test]
    fn every_preset_can_be_chosen_by_its_name() {
        for preset in Preset::ALL {
            let args = parse(&["--output", "out", "--preset", preset.name()]).expect("arguments");
            assert_eq!(Preset::from(args.preset), preset);
            assert_eq!(base_config(&args).expect("configuration"), preset.config());
        }
        let args = parse(&["--output", "out", "--preset", "clutter-turning"]).expect("arguments");
        assert_eq!(Preset::from(args.preset), Preset::ClutterTurning);
    }

    #[test]
    fn scenario_and_preset_are_exclusive() {
        let error = parse(&["--output", "out", "--scenario", "a.toml", "--preset", "turning"]).unwrap_err();
        assert_eq!(error.kind(), clap::error::ErrorKind::ArgumentConflict);
        // Without an explicit --preset the default preset does not conflict.
        assert!(parse(&["--output", "out", "--scenario", "a.toml"]).is_ok());
    }

    #[test]
    fn bad_scenario_files_are_reported_with_their_path() {
        let missing = std::env::temp_dir().join("primm-generate-test-no-such-file.toml");
        let error = read_scenario_file(&missing).unwrap_err();
        assert!(matches!(error, GenerateError::ReadScenario { .. }), "{error:?}");
        assert!(error.to_string().contains("no-such-file.toml"), "{error}");

        let unknown = scratch_file("unknown.toml", "[car]\ntop_speed = 3.0\n");
        let error = read_scenario_file(&unknown).unwrap_err();
        assert!(
            matches!(error, GenerateError::Scenario { source: ScenarioTomlError::Parse(_), .. }),
            "{error:?}"
        );
        let message = error.to_string();
        assert!(message.contains("unknown.toml") && message.contains("top_speed"), "{message}");

        let invalid = scratch_file("invalid.toml", "[sequence]\nduration_s = -1.0\n");
        let error = read_scenario_file(&invalid).unwrap_err();
        assert!(
            matches!(error, GenerateError::Scenario { source: ScenarioTomlError::Invalid(_), .. }),
            "{error:?}"
        );
        assert!(error.to_string().contains("sequence.duration_s"), "{error}");
    }
}
