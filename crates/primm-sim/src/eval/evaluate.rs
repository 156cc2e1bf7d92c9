//! The evaluation driver: every method on every sequence of a data set, with the
//! missed-detection runs of Table V, into one [`Evaluation`].
//!
//! `primm eval` parses its arguments, reads the data, calls [`evaluate`] and prints; everything
//! else is here, so that the evaluation can be run (and tested) without the command line.

use super::document::ReportDocument;
use super::dropout::{sequence_seed, DropoutMask};
use super::ego_motion::ego_motion_labels;
use super::plots::{
    ground_truth_points, majority_ground_truth, write_mode_probability_svg, write_trajectory_svg,
    TrajectoryPanel, TrajectoryPlotOptions, TrajectoryPoint,
};
use super::record::{AssociationRecord, EvalError, Method};
use super::report::{EvaluationReport, MethodEvaluator, DEFAULT_MISS_PERCENTS};
use crate::io::Sequence;
use crate::offline::{association_records, track_sequence, OfflineError};
use crate::oracle::{DisplacementOracle, OracleError, SequenceTruth};
use primm_core::config::Config;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::Tracker;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Seed of the measurement removal for the missed-detection rows of Table V.
pub const DEFAULT_MISS_SEED: u64 = 2024;

/// What the one-step prior is scored against (RMSE, Tables II to VI).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
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

    /// The truth named `key` ([`key`](Self::key)), if any.
    pub fn from_key(key: &str) -> Option<Self> {
        [Truth::Centre, Truth::Measurement].into_iter().find(|truth| truth.key() == key)
    }

    /// A sentence saying what the RMSE is measured against.
    pub fn description(self) -> &'static str {
        match self {
            Truth::Centre => "the true object centre where the data has it (--truth centre)",
            Truth::Measurement => "the next measurement of the object (--truth measurement)",
        }
    }
}

/// How an evaluation runs.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluationSettings {
    /// The methods, in order.
    pub methods: Vec<Method>,
    /// What the prior is scored against.
    pub truth: Truth,
    /// Seed of the measurement removal of the missed-detection rows.
    pub miss_seed: u64,
    /// With `Some(noise_m)`, PR and PR-IMM get each track's true displacement plus Gaussian noise
    /// of `noise_m` per axis (m) instead of the PR model's ([`DisplacementOracle`]).
    pub displacement_oracle_noise_m: Option<f64>,
    /// Index of the sequence drawn in the trajectory figure.
    pub plot_sequence: usize,
}

impl Default for EvaluationSettings {
    fn default() -> Self {
        EvaluationSettings {
            methods: Method::ALL.to_vec(),
            truth: Truth::Centre,
            miss_seed: DEFAULT_MISS_SEED,
            displacement_oracle_noise_m: None,
            plot_sequence: 0,
        }
    }
}

/// Why [`evaluate`] failed.
#[derive(Debug, thiserror::Error)]
pub enum EvaluateError {
    /// The configuration is invalid for the tracker.
    #[error(transparent)]
    Tracker(#[from] primm_core::config::ConfigError),
    /// The data set holds no sequence.
    #[error("the data set holds no sequence")]
    NoSequences,
    /// The sequence to plot is not in the data set.
    #[error("no sequence {index} to plot: the data set holds {count}")]
    NoPlotSequence {
        /// The index asked for.
        index: usize,
        /// Sequences in the data set.
        count: usize,
    },
    /// Tracking a sequence failed.
    #[error(transparent)]
    Tracking(#[from] OfflineError),
    /// The evaluation library failed (measurement removal, JSON or figures).
    #[error(transparent)]
    Evaluation(#[from] EvalError),
    /// A figure's directory could not be created.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The displacement oracle needs true centres in the tracker's frame.
    #[error("displacement oracle: {0}")]
    Oracle(#[from] OracleError),
    /// The tracked rows of a sequence with measurements removed did not match the measurements
    /// kept (an internal error).
    #[error("missed-detection rows out of step")]
    MissedDetectionRows,
}

/// The outcome of [`evaluate`]: the report, the settings it was made with, and what the
/// trajectory figure draws.
#[derive(Debug)]
pub struct Evaluation {
    /// Every method's results.
    pub report: EvaluationReport,
    /// What the prior was scored against.
    pub truth: Truth,
    /// The displacement oracle's noise per axis (m), when the oracle replaced the PR model.
    pub displacement_oracle_noise_m: Option<f64>,
    /// Name of the sequence of the trajectory figure.
    pub plot_sequence: String,
    /// The true objects of that sequence.
    pub ground_truth: Vec<TrajectoryPoint>,
    /// Each evaluated method's tracks in that sequence.
    pub panels: Vec<TrajectoryPanel>,
}

/// The JSON document of an [`Evaluation`]: the report's, plus the run's settings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvaluationDocument {
    /// The report.
    #[serde(flatten)]
    pub report: ReportDocument,
    /// What the prior was scored against.
    pub truth: Truth,
    /// Whether the displacement oracle replaced the PR model.
    pub displacement_oracle: bool,
    /// The oracle's noise per axis, m (only with the oracle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displacement_oracle_noise_m: Option<f64>,
}

/// Something [`evaluate`] reports while it runs (for a progress line).
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    /// A method could not be evaluated (no model, say); the report marks it unavailable.
    Unavailable {
        /// The method.
        method: Method,
        /// Why.
        reason: String,
    },
    /// A method is done.
    MethodDone {
        /// The method.
        method: Method,
        /// Sequences evaluated.
        sequences: usize,
        /// Wall-clock time it took, s.
        seconds: f64,
        /// The predictor's own summary, if it gives one (the oracle's counts).
        predictor_report: Option<String>,
    },
}

/// A predictor for a method, or why there is none.
pub type PredictorFactory<'a> =
    dyn FnMut(Method) -> Result<Box<dyn DisplacementPredictor + Send>, String> + 'a;

/// Evaluates every method of `settings` on `sequences` with the tracker configuration `config`.
///
/// `predictor_for` gives each method its displacement predictor (the PR model for PR and
/// PR-IMM); a method it refuses is marked unavailable and the others go on. With the oracle the
/// PR model is not asked for. `progress` hears of each method as it finishes.
pub fn evaluate(
    mut sequences: Vec<Sequence>,
    config: &Config,
    settings: &EvaluationSettings,
    predictor_for: &mut PredictorFactory<'_>,
    progress: &mut dyn FnMut(Progress),
) -> Result<Evaluation, EvaluateError> {
    if sequences.is_empty() {
        return Err(EvaluateError::NoSequences);
    }
    if settings.plot_sequence >= sequences.len() {
        return Err(EvaluateError::NoPlotSequence { index: settings.plot_sequence, count: sequences.len() });
    }
    // The oracle's truth is read before a measurement protocol drops it from the rows.
    let oracle_truths = match settings.displacement_oracle_noise_m {
        Some(_) => sequences
            .iter()
            .map(|sequence| SequenceTruth::new(sequence, config.frame.tracking_frame))
            .collect::<Result<Vec<_>, _>>()?,
        None => Vec::new(),
    };
    if settings.truth == Truth::Measurement {
        forget_true_positions(&mut sequences);
    }
    let mut evaluation = Evaluation {
        report: EvaluationReport::new(),
        truth: settings.truth,
        displacement_oracle_noise_m: settings.displacement_oracle_noise_m,
        plot_sequence: sequences[settings.plot_sequence].name.clone(),
        ground_truth: Vec::new(),
        panels: Vec::new(),
    };
    for &method in &settings.methods {
        let oracle = settings
            .displacement_oracle_noise_m
            .filter(|_| method.needs_predictor())
            .map(|noise_m| DisplacementOracle::with_noise(noise_m, settings.miss_seed));
        let predictor = match &oracle {
            Some(oracle) => Ok(Box::new(oracle.clone()) as Box<dyn DisplacementPredictor + Send>),
            None => predictor_for(method),
        };
        let predictor = match predictor {
            Ok(predictor) => predictor,
            Err(reason) => {
                evaluation.report.mark_unavailable(method, reason.clone());
                progress(Progress::Unavailable { method, reason });
                continue;
            }
        };
        let started = std::time::Instant::now();
        let mut tracker = Tracker::with_predictor(config.clone().with_modes(method.modes()), predictor)?;
        let mut evaluator = MethodEvaluator::new(method);
        for (index, sequence) in sequences.iter().enumerate() {
            if let Some(oracle) = &oracle {
                oracle.set_truth(oracle_truths[index].clone());
            }
            let plotted = index == settings.plot_sequence;
            evaluate_sequence(
                &mut tracker,
                sequence,
                method,
                settings.miss_seed,
                &mut evaluator,
                plotted.then_some(&mut evaluation),
            )?;
        }
        evaluation.report.insert(evaluator.finish());
        progress(Progress::MethodDone {
            method,
            sequences: sequences.len(),
            seconds: started.elapsed().as_secs_f64(),
            predictor_report: oracle.as_ref().and_then(|oracle| oracle.report()),
        });
    }
    Ok(evaluation)
}

/// Tracks one sequence with every measurement and with each removal of the missed-detection
/// rows, adding its rows to `evaluator`; `figure` collects the trajectories of the plotted
/// sequence.
fn evaluate_sequence<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    sequence: &Sequence,
    method: Method,
    miss_seed: u64,
    evaluator: &mut MethodEvaluator,
    figure: Option<&mut Evaluation>,
) -> Result<(), EvaluateError> {
    let plotted = figure.is_some();
    let mut records = Vec::with_capacity(sequence.measurement_count());
    let mut points = Vec::new();
    track_sequence(tracker, sequence, |recorded, outputs| {
        association_records(recorded, outputs, method, &mut records);
        if plotted {
            points.extend(
                outputs.iter().filter(|o| o.measurement_index.is_some()).map(|o| TrajectoryPoint {
                    id: o.id,
                    frame: recorded.index,
                    position: o.position_m,
                }),
            );
        }
    })?;
    evaluator.add_sequence(&records);
    evaluator.add_ego_motion(&records, &ego_motion_labels(sequence, &records));
    if let Some(evaluation) = figure {
        evaluation.ground_truth = ground_truth_points(&records);
        evaluation.panels.push(TrajectoryPanel {
            title: method.label().to_string(),
            tracks: points,
            track_to_ground_truth: majority_ground_truth(&records),
        });
    }
    for percent in DEFAULT_MISS_PERCENTS {
        let records = missed_detection_records(tracker, sequence, method, percent, miss_seed)?;
        evaluator.add_missed_detection_sequence(percent, &records);
    }
    Ok(())
}

impl Evaluation {
    /// The JSON document (see [`super::document`]).
    pub fn document(&self) -> EvaluationDocument {
        EvaluationDocument {
            report: ReportDocument::of(&self.report),
            truth: self.truth,
            displacement_oracle: self.displacement_oracle_noise_m.is_some(),
            displacement_oracle_noise_m: self.displacement_oracle_noise_m,
        }
    }

    /// The JSON text of [`document`](Self::document): pretty-printed, keys in alphabetical
    /// order, with a final newline.
    pub fn to_json_text(&self) -> Result<String, EvalError> {
        let value = serde_json::to_value(self.document())?;
        Ok(serde_json::to_string_pretty(&value)? + "\n")
    }

    /// What `primm eval` prints: the RMSE reference, the oracle (if any) and every table.
    pub fn to_text(&self) -> String {
        let mut text = format!("RMSE reference: {}\n", self.truth.description());
        if let Some(noise_m) = self.displacement_oracle_noise_m {
            let noise =
                if noise_m > 0.0 { format!(" plus {noise_m} m noise per axis") } else { String::new() };
            text.push_str(&format!(
                "PR and PR-IMM: the PR model replaced by the true displacement{noise} (--displacement-oracle)\n"
            ));
        }
        text.push('\n');
        text.push_str(&self.report.to_text());
        text
    }

    /// Writes the SVG figures into `dir` (created if needed): the trajectories of the plotted
    /// sequence per method, and PR-IMM's mean mode probabilities when it was evaluated. Returns
    /// the files written.
    pub fn write_plots(&self, dir: &Path) -> Result<Vec<PathBuf>, EvaluateError> {
        std::fs::create_dir_all(dir)?;
        let mut written = Vec::new();
        if !self.panels.is_empty() {
            let path = dir.join("trajectories.svg");
            let options = TrajectoryPlotOptions {
                title: Some(format!(
                    "Ground truth (light, thick) and estimated tracks (dark, thin): {}",
                    self.plot_sequence
                )),
                ..TrajectoryPlotOptions::default()
            };
            write_trajectory_svg(&path, &self.ground_truth, &self.panels, &options)?;
            written.push(path);
        }
        let pr_imm_modes = self.report.result(Method::PrImm).map(|result| &result.modes);
        if let Some((means, modes)) = pr_imm_modes.and_then(|modes| Some((modes.mean()?, modes))) {
            let path = dir.join("mode_probabilities.svg");
            write_mode_probability_svg(&path, means, modes.count())?;
            written.push(path);
        }
        Ok(written)
    }
}

/// Drops every true position, so that every measurement is its own reference.
fn forget_true_positions(sequences: &mut [Sequence]) {
    for frame in sequences.iter_mut().flat_map(|sequence| sequence.frames.iter_mut()) {
        for measurement in &mut frame.measurements {
            measurement.true_position = None;
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{Preset, ScenarioGenerator, Split};

    fn sequences(count: u32) -> Vec<Sequence> {
        let mut config = Preset::Default.config();
        config.sequence.duration_s = 4.0;
        let generator = ScenarioGenerator::new(config).unwrap();
        (0..count).map(|index| generator.generate(Split::Validation, index).sequence).collect()
    }

    #[test]
    fn a_method_without_a_predictor_is_marked_unavailable_and_the_others_are_evaluated() {
        let settings = EvaluationSettings {
            methods: vec![Method::ConstantVelocity, Method::Learned, Method::Imm],
            ..Default::default()
        };
        let refuse = |_: Method| Err::<Box<dyn DisplacementPredictor + Send>, _>("no model here".to_string());
        let mut heard = Vec::new();
        let evaluation = evaluate(
            sequences(2),
            &Config::default(),
            &settings,
            &mut |method| {
                if method.needs_predictor() {
                    refuse(method)
                } else {
                    Ok(Box::new(primm_core::predictor::NoPredictor))
                }
            },
            &mut |progress| heard.push(progress),
        )
        .unwrap();
        assert_eq!(evaluation.report.unavailable_reason(Method::Learned), Some("no model here"));
        for method in [Method::ConstantVelocity, Method::Imm] {
            let result = evaluation.report.result(method).expect("evaluated");
            assert_eq!(result.sequences, 2);
            assert!(result.rmse.count() > 0);
        }
        assert_eq!(heard.len(), 3, "{heard:?}");
        assert!(matches!(heard[1], Progress::Unavailable { method: Method::Learned, .. }));
        let document = serde_json::to_value(evaluation.document()).unwrap();
        assert_eq!(document["truth"], "centre");
        assert_eq!(document["displacement_oracle"], false);
        assert!(document.get("displacement_oracle_noise_m").is_none());
        assert_eq!(document["methods"]["pr"]["available"], false);
        assert_eq!(document["methods"]["imm"]["counts"]["sequences"], 2);
        assert!(evaluation.to_json_text().unwrap().ends_with("}\n"));
    }

    #[test]
    fn the_measurement_protocol_scores_against_the_measurements_and_says_so() {
        let data = sequences(1);
        let settings = |truth| EvaluationSettings {
            methods: vec![Method::ConstantVelocity],
            truth,
            ..Default::default()
        };
        let mut none = |_: Method| {
            Ok::<Box<dyn DisplacementPredictor + Send>, String>(Box::new(primm_core::predictor::NoPredictor))
        };
        let centre =
            evaluate(data.clone(), &Config::default(), &settings(Truth::Centre), &mut none, &mut |_| {})
                .unwrap();
        let measured =
            evaluate(data, &Config::default(), &settings(Truth::Measurement), &mut none, &mut |_| {})
                .unwrap();
        let rmse = |evaluation: &Evaluation| {
            evaluation.report.result(Method::ConstantVelocity).unwrap().rmse.rmse_xy().unwrap()
        };
        assert_ne!(rmse(&centre), rmse(&measured));
        assert!(measured.to_text().starts_with("RMSE reference: the next measurement"));
        assert_eq!(serde_json::to_value(measured.document()).unwrap()["truth"], "measurement");
    }

    #[test]
    fn an_empty_data_set_or_a_missing_plot_sequence_is_refused() {
        let mut none = |_: Method| {
            Ok::<Box<dyn DisplacementPredictor + Send>, String>(Box::new(primm_core::predictor::NoPredictor))
        };
        let settings = EvaluationSettings::default();
        assert!(matches!(
            evaluate(Vec::new(), &Config::default(), &settings, &mut none, &mut |_| {}),
            Err(EvaluateError::NoSequences)
        ));
        let settings = EvaluationSettings { plot_sequence: 3, ..Default::default() };
        assert!(matches!(
            evaluate(sequences(1), &Config::default(), &settings, &mut none, &mut |_| {}),
            Err(EvaluateError::NoPlotSequence { index: 3, count: 1 })
        ));
    }
}
