//! `primm eval`: every method on every sequence of a data set, printed as the paper's tables and
//! the metrics on confirmed tracks (each row records whether its track was confirmed after the
//! frame, from the tracker output's status).

use clap::{Args as ClapArgs, ValueEnum};
use primm_core::config::{Config, TrackingFrame};
use primm_core::mode::Method;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::Tracker;
use primm_predictor::predictor_for;
use primm_sim::eval::dropout::{sequence_seed, DropoutMask};
use primm_sim::eval::ego_motion::ego_motion_labels;
use primm_sim::eval::plots::{
    ground_truth_points, majority_ground_truth, write_mode_probability_svg, write_trajectory_svg,
    TrajectoryPanel, TrajectoryPlotOptions, TrajectoryPoint,
};
use primm_sim::eval::record::{AssociationRecord, EvalError};
use primm_sim::eval::report::{EvaluationReport, MethodEvaluator, DEFAULT_MISS_PERCENTS};
use primm_sim::io::{read_dataset_dir, CsvError, Sequence};
use primm_sim::offline::{association_records, track_sequence, OfflineError};
use primm_sim::oracle::{DisplacementOracle, OracleError, SequenceTruth};
use std::path::{Path, PathBuf};

/// Seed of the measurement removal for the missed-detection rows of Table V.
pub const DEFAULT_MISS_SEED: u64 = 2024;

/// What the one-step prior is scored against (RMSE, Tables II to VI).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum Truth {
    /// The true object centre, where the data knows it (simulated data); the measurement
    /// elsewhere.
    #[default]
    Centre,
    /// The measurement that updated the track, i.e. the next measurement after the prior: the
    /// paper's protocol on RadarScenes, where object-level measurements are the only truth.
    /// True positions in the data are ignored altogether (also for the scenario subsets).
    Measurement,
}

impl Truth {
    /// The name used on the command line and in the JSON.
    pub fn key(self) -> &'static str {
        match self {
            Truth::Centre => "centre",
            Truth::Measurement => "measurement",
        }
    }
}

/// Arguments of `primm eval`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Evaluate methods on a data set (a directory of measurement CSV files) and print the paper's tables"
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
    /// Tracker configuration (TOML); the built-in defaults otherwise.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Overrides the configuration's `frame.tracking_frame`: `world` (tracks in the world
    /// frame when frames carry an ego pose) or `vehicle` (always the vehicle frame).
    #[arg(long, value_name = "FRAME", value_parser = super::parse_tracking_frame)]
    pub tracking_frame: Option<TrackingFrame>,
    /// ONNX model of the learned predictor (default: the model built into primm,
    /// models/pr.onnx).
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Seed of the measurement removal for the missed-detection rows.
    #[arg(long, default_value_t = DEFAULT_MISS_SEED)]
    pub miss_seed: u64,
    /// Reference of the RMSE: `centre` (the true object centre where the data has it) or
    /// `measurement` (the next measurement, the paper's RadarScenes protocol).
    #[arg(long, value_enum, default_value_t = Truth::Centre)]
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
    /// The configuration is invalid for the tracker.
    #[error(transparent)]
    Tracker(#[from] primm_core::config::ConfigError),
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
    /// Tracking a sequence failed.
    #[error(transparent)]
    Tracking(#[from] OfflineError),
    /// The evaluation library failed (measurement removal, JSON or figures).
    #[error(transparent)]
    Evaluation(#[from] EvalError),
    /// The directory of the figures could not be created.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// `--displacement-oracle` needs true centres in the tracker's frame.
    #[error("--displacement-oracle: {0}")]
    Oracle(#[from] OracleError),
    /// The tracked rows of a sequence with measurements removed did not match the measurements
    /// kept (an internal error).
    #[error("missed-detection rows out of step")]
    MissedDetectionRows,
}

/// Runs `primm eval`.
pub fn run(args: &Args) -> Result<(), EvaluateError> {
    let base_config = super::with_tracking_frame(
        match &args.config {
            Some(path) => primm_config::from_file(path)?,
            None => Config::default(),
        },
        args.tracking_frame,
    );
    let mut sequences = read_dataset_dir(&args.data)?;
    if sequences.is_empty() {
        return Err(EvaluateError::NoData { dir: args.data.clone() });
    }
    // The oracle's truth is read before a measurement protocol drops it from the rows.
    let oracle_truths = if args.displacement_oracle {
        let frame = base_config.frame.tracking_frame;
        sequences.iter().map(|sequence| SequenceTruth::new(sequence, frame)).collect::<Result<Vec<_>, _>>()?
    } else {
        Vec::new()
    };
    if args.truth == Truth::Measurement {
        forget_true_positions(&mut sequences);
    }
    let measurements: usize = sequences.iter().map(Sequence::measurement_count).sum();
    eprintln!("{} sequences, {} measurements from {}", sequences.len(), measurements, args.data.display());
    let plot_sequence = match &args.plot_sequence {
        Some(name) => {
            sequences.iter().position(|s| &s.name == name).ok_or(EvaluateError::NoSequence(name.clone()))?
        }
        None => 0,
    };

    let oracle_noise_m = args.displacement_oracle_noise_m.unwrap_or(0.0);
    let mut report = EvaluationReport::new();
    let mut panels = Vec::new();
    let mut ground_truth = Vec::new();
    for &method in &args.methods {
        let oracle = (args.displacement_oracle && method.needs_predictor())
            .then(|| DisplacementOracle::with_noise(oracle_noise_m, args.miss_seed));
        let predictor = match &oracle {
            Some(oracle) => Ok(Box::new(oracle.clone()) as Box<dyn DisplacementPredictor + Send>),
            None => predictor_for(method, args.model.as_deref(), base_config.predictor.engine),
        };
        let predictor = match predictor {
            Ok(predictor) => predictor,
            Err(reason) => {
                eprintln!("{method}: unavailable: {reason}");
                report.mark_unavailable(method, reason.to_string());
                continue;
            }
        };
        let started = std::time::Instant::now();
        let mut tracker = Tracker::with_predictor(base_config.clone().with_modes(method.modes()), predictor)?;
        let mut evaluator = MethodEvaluator::new(method);
        for (index, sequence) in sequences.iter().enumerate() {
            if let Some(oracle) = &oracle {
                oracle.set_truth(oracle_truths[index].clone());
            }
            let mut records = Vec::with_capacity(sequence.measurement_count());
            let mut points = Vec::new();
            track_sequence(&mut tracker, sequence, |recorded, outputs| {
                association_records(recorded, outputs, method, &mut records);
                if index == plot_sequence {
                    points.extend(outputs.iter().filter(|o| o.measurement_index.is_some()).map(|o| {
                        TrajectoryPoint { id: o.id, frame: recorded.index, position: o.position_m }
                    }));
                }
            })?;
            evaluator.add_sequence(&records);
            evaluator.add_ego_motion(&records, &ego_motion_labels(sequence, &records));
            if index == plot_sequence {
                ground_truth = ground_truth_points(&records);
                panels.push(TrajectoryPanel {
                    title: method.label().to_string(),
                    tracks: points,
                    track_to_ground_truth: majority_ground_truth(&records),
                });
            }
            for percent in DEFAULT_MISS_PERCENTS {
                let records =
                    missed_detection_records(&mut tracker, sequence, method, percent, args.miss_seed)?;
                evaluator.add_missed_detection_sequence(percent, &records);
            }
        }
        report.insert(evaluator.finish());
        eprintln!("{method}: {} sequences in {:.1} s", sequences.len(), started.elapsed().as_secs_f64());
        if let Some(summary) = oracle.as_ref().and_then(|oracle| oracle.report()) {
            eprintln!("{method}: {summary}");
        }
    }

    println!("RMSE reference: {}", truth_description(args.truth));
    if args.displacement_oracle {
        let noise = if oracle_noise_m > 0.0 {
            format!(" plus {oracle_noise_m} m noise per axis")
        } else {
            String::new()
        };
        println!(
            "PR and PR-IMM: the PR model replaced by the true displacement{noise} (--displacement-oracle)"
        );
    }
    println!();
    println!("{}", report.to_text());
    if let Some(path) = &args.json {
        let mut json = report.to_json();
        json["truth"] = serde_json::Value::from(args.truth.key());
        json["displacement_oracle"] = serde_json::Value::from(args.displacement_oracle);
        if args.displacement_oracle {
            json["displacement_oracle_noise_m"] = serde_json::Value::from(oracle_noise_m);
        }
        let text = serde_json::to_string_pretty(&json).map_err(EvalError::from)?;
        std::fs::write(path, text + "\n")?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.plots {
        write_plots(dir, &report, &ground_truth, &panels, &sequences[plot_sequence].name)?;
    }
    Ok(())
}

/// Drops every true position, so that every measurement is its own reference.
fn forget_true_positions(sequences: &mut [Sequence]) {
    for frame in sequences.iter_mut().flat_map(|sequence| sequence.frames.iter_mut()) {
        for measurement in &mut frame.measurements {
            measurement.true_position = None;
        }
    }
}

fn truth_description(truth: Truth) -> &'static str {
    match truth {
        Truth::Centre => "the true object centre where the data has it (--truth centre)",
        Truth::Measurement => "the next measurement of the object (--truth measurement)",
    }
}

/// Re-tracks `sequence` with `percent` % of its measurements removed (the same removal for every
/// method) and returns one row per ORIGINAL measurement: a removed one is a ground-truth object
/// frame without a track.
fn missed_detection_records<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    sequence: &Sequence,
    method: Method,
    percent: u32,
    seed: u64,
) -> Result<Vec<AssociationRecord>, EvaluateError> {
    let mask = DropoutMask::new(
        sequence.measurement_count(),
        f64::from(percent) / 100.0,
        sequence_seed(seed, &sequence.name),
    )?;
    let mut reduced = sequence.clone();
    let mut flat = 0;
    for frame in &mut reduced.frames {
        frame.measurements.retain(|_| {
            let keep = !mask.is_dropped(flat);
            flat += 1;
            keep
        });
    }
    let mut kept_records = Vec::with_capacity(sequence.measurement_count());
    track_sequence(tracker, &reduced, |recorded, outputs| {
        association_records(recorded, outputs, method, &mut kept_records)
    })?;
    let mut kept = kept_records.into_iter();
    let mut records = Vec::with_capacity(sequence.measurement_count());
    let mut flat = 0;
    for frame in &sequence.frames {
        for measurement in &frame.measurements {
            if mask.is_dropped(flat) {
                records.push(frame.unassigned_record(measurement));
            } else {
                records.push(kept.next().ok_or(EvaluateError::MissedDetectionRows)?);
            }
            flat += 1;
        }
    }
    Ok(records)
}

fn write_plots(
    dir: &Path,
    report: &EvaluationReport,
    ground_truth: &[TrajectoryPoint],
    panels: &[TrajectoryPanel],
    sequence: &str,
) -> Result<(), EvaluateError> {
    std::fs::create_dir_all(dir)?;
    if !panels.is_empty() {
        let path = dir.join("trajectories.svg");
        let options = TrajectoryPlotOptions {
            title: Some(format!("Ground truth (light, thick) and estimated tracks (dark, thin): {sequence}")),
            ..TrajectoryPlotOptions::default()
        };
        write_trajectory_svg(&path, ground_truth, panels, &options)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(result) = report.result(Method::PrImm) {
        if let Some(means) = result.modes.mean() {
            let path = dir.join("mode_probabilities.svg");
            write_mode_probability_svg(&path, means, result.modes.count())?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}
