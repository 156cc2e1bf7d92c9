//! `primm eval`: every method on every sequence of a data set, printed as the paper's tables and
//! the metrics on confirmed tracks. The evaluation itself is [`primm_sim::eval::evaluate`]; this
//! reads the arguments and the data, and prints and writes what it returns.

use super::TrackerArgs;
use clap::Args as ClapArgs;
use primm_core::mode::Method;
use primm_predictor::predictor_for;
use primm_sim::eval::{
    evaluate, EvalError, EvaluateError as EvaluationError, EvaluationSettings, Progress, Truth,
};
use primm_sim::io::{read_dataset_dir, CsvError, Sequence};
use std::path::PathBuf;

pub use primm_sim::eval::DEFAULT_MISS_SEED;

/// `--truth`: `centre` or `measurement` ([`Truth`]).
fn parse_truth(text: &str) -> Result<Truth, String> {
    Truth::from_key(text).ok_or_else(|| format!("`{text}` is neither `centre` nor `measurement`"))
}

/// Arguments of `primm eval`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Evaluate methods on a data set (a directory of measurement CSV files) and print the paper's tables",
    after_help = "\
Examples:
  primm eval --data data/evaluation                              # all six methods, text tables
  primm eval --data data/evaluation --methods imm,pr-imm --json eval.json --plots plots
  primm eval --data data/validation --methods imm,pr,pr-imm --displacement-oracle"
)]
pub struct Args {
    /// Directory of measurement CSV files (one sequence per file).
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// Methods to evaluate (comma separated); all six by default.
    #[arg(long, value_delimiter = ',', default_values_t = Method::ALL.to_vec())]
    pub methods: Vec<Method>,
    /// Write the results as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write SVG figures (trajectories per method, mean mode probabilities) into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Sequence drawn in the trajectory figure (file stem); the first one by default.
    #[arg(long, value_name = "NAME")]
    pub plot_sequence: Option<String>,
    /// The tracker's configuration, model, engine and tracking frame.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Seed of the measurement removal for the missed-detection rows.
    #[arg(long, default_value_t = DEFAULT_MISS_SEED)]
    pub miss_seed: u64,
    /// Reference of the RMSE: `centre` (the true object centre where the data has it) or
    /// `measurement` (the next measurement, the paper's RadarScenes protocol).
    #[arg(long, value_parser = parse_truth, default_value = "centre", value_name = "centre|measurement")]
    pub truth: Truth,
    /// PR and PR-IMM get each track's true displacement from the data's true centres instead of
    /// the PR model's (a diagnostic: how far a perfect learned predictor would go; simulated
    /// data only). See `primm_sim::oracle`.
    #[arg(long)]
    pub displacement_oracle: bool,
    /// With `--displacement-oracle`: Gaussian noise of this standard deviation per axis added to
    /// every true displacement (independent per request, seeded), m.
    #[arg(long, value_name = "M", requires = "displacement_oracle", value_parser = parse_noise_std)]
    pub displacement_oracle_noise_m: Option<f64>,
}

/// A standard deviation: finite and not negative.
fn parse_noise_std(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() && value >= 0.0 => Ok(value),
        _ => Err(format!("`{text}` is not a standard deviation in metres (a finite number >= 0)")),
    }
}

/// Why `primm eval` failed.
#[derive(Debug, thiserror::Error)]
pub enum EvaluateError {
    /// The configuration file could not be read or is invalid.
    #[error(transparent)]
    Config(#[from] primm_config::ConfigError),
    /// The data set could not be read.
    #[error(transparent)]
    Data(#[from] CsvError),
    /// The data directory holds no measurement CSV file.
    #[error("no measurement CSV files in {}", dir.display())]
    NoData {
        /// The data directory.
        dir: PathBuf,
    },
    /// `--plot-sequence` names no sequence of the data set.
    #[error("no sequence named {0}")]
    NoSequence(String),
    /// The evaluation failed.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// The JSON file could not be made.
    #[error(transparent)]
    Json(#[from] EvalError),
    /// The JSON file could not be written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Runs `primm eval`.
pub fn run(args: &Args) -> Result<(), EvaluateError> {
    let primm_config::Settings { tracker: config, inference } = args.tracker.load_settings()?;
    let sequences = read_dataset_dir(&args.data)?;
    if sequences.is_empty() {
        return Err(EvaluateError::NoData { dir: args.data.clone() });
    }
    let measurements: usize = sequences.iter().map(Sequence::measurement_count).sum();
    eprintln!("{} sequences, {} measurements from {}", sequences.len(), measurements, args.data.display());
    let plot_sequence = match &args.plot_sequence {
        Some(name) => {
            sequences.iter().position(|s| &s.name == name).ok_or(EvaluateError::NoSequence(name.clone()))?
        }
        None => 0,
    };
    let settings = EvaluationSettings {
        methods: args.methods.clone(),
        truth: args.truth,
        miss_seed: args.miss_seed,
        displacement_oracle_noise_m: args
            .displacement_oracle
            .then(|| args.displacement_oracle_noise_m.unwrap_or(0.0)),
        plot_sequence,
    };
    let engine = inference.engine;
    let mut predictor = |method: Method| {
        predictor_for(method, args.tracker.model.as_deref(), engine).map_err(|reason| reason.to_string())
    };
    let evaluation = evaluate(sequences, &config, &settings, &mut predictor, &mut print_progress)?;

    println!("{}", evaluation.to_text());
    if let Some(path) = &args.json {
        std::fs::write(path, evaluation.to_json_text()?)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.plots {
        for path in evaluation.write_plots(dir)? {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

/// A line on stderr per method.
fn print_progress(progress: Progress) {
    match progress {
        Progress::Unavailable { method, reason } => eprintln!("{method}: unavailable: {reason}"),
        Progress::MethodDone { method, sequences, seconds, predictor_report } => {
            eprintln!("{method}: {sequences} sequences in {seconds:.1} s");
            if let Some(summary) = predictor_report {
                eprintln!("{method}: {summary}");
            }
        }
    }
}
