//! `primm score`: the metrics of `primm eval` for associations written by any tracker.
//!
//! For each measurement CSV of `--data`, the association CSV of the same file name in
//! `--associations` (format: `src/io/association_csv.rs`) says which track took each
//! measurement and with which prior. The rows go through the same evaluator as `primm eval`
//! (`MethodEvaluator`), so a tracker outside primm is scored exactly like primm's own methods:
//! prior RMSE against the true object centre (Table II), ID switches and IDF1 (Table IV).
//! When every association file has the `confirmed` column, the metrics on confirmed tracks
//! (`primm_sim::eval::confirmed`) are added under `confirmed_tracks`; otherwise that key is
//! `null` and a message on standard error names the first file without it.

use clap::Args as ClapArgs;
use primm_core::mode::Method;
use primm_sim::eval::{confirmed_track_counts, ConfirmedTrackCounts, MethodEvaluator, MethodResult};
use primm_sim::io::association_csv::{
    association_records_from_rows, read_association_rows, AssociationCsvError,
};
use primm_sim::io::{dataset_files, read_sequence_file, CsvError};
use std::path::PathBuf;

/// Arguments of `primm score`.
#[derive(Debug, Clone, ClapArgs)]
#[command(about = "Score association CSV files (from any tracker) with the metrics of primm eval")]
pub struct Args {
    /// Directory of measurement CSV files (the data set that was tracked).
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// Directory with one association CSV per measurement CSV, under the same file name.
    #[arg(long, value_name = "DIR")]
    pub associations: PathBuf,
    /// Name of the tracker, for the output.
    #[arg(long, default_value = "tracker")]
    pub name: String,
    /// Score only the first N sequences (in file-name order).
    #[arg(long, value_name = "N")]
    pub sequences: Option<usize>,
}

/// The scores as a JSON object; `confirmed_tracks` is `null` when the track status was not
/// recorded.
pub fn summary_json(name: &str, result: &MethodResult) -> serde_json::Value {
    serde_json::json!({
        "tracker": name,
        "sequences": result.sequences,
        "prior_rows": result.rmse.count(),
        "rmse_x_m": result.rmse.rmse_x(),
        "rmse_y_m": result.rmse.rmse_y(),
        "rmse_xy_m": result.rmse.rmse_xy(),
        "idsw": result.identity.idsw,
        "idf1": result.identity.idf1(),
        "gt_object_frames": result.identity.gt_object_frames,
        "confirmed_tracks": result.confirmed.as_ref().map(ConfirmedTrackCounts::to_json),
    })
}

/// Why `primm score` failed.
#[derive(Debug, thiserror::Error)]
pub enum ScoreError {
    /// A measurement CSV file (or the data directory) could not be read.
    #[error(transparent)]
    Data(#[from] CsvError),
    /// The data directory holds no measurement CSV file.
    #[error("no measurement CSV files in {}", dir.display())]
    NoData {
        /// The data directory.
        dir: PathBuf,
    },
    /// A data file path without a file name.
    #[error("a data file without a name")]
    Unnamed,
    /// An association CSV file could not be opened.
    #[error("cannot open {}: {source}", path.display())]
    Open {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// An association CSV file is malformed or does not fit its sequence.
    #[error("{}: {source}", path.display())]
    Associations {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        source: AssociationCsvError,
    },
}

/// Runs `primm score`: prints one JSON line.
pub fn run(args: &Args) -> Result<(), ScoreError> {
    let mut files = dataset_files(&args.data)?;
    if let Some(limit) = args.sequences {
        files.truncate(limit);
    }
    if files.is_empty() {
        return Err(ScoreError::NoData { dir: args.data.clone() });
    }
    // The method only labels the result; association rows carry no mode probabilities.
    let mut evaluator = MethodEvaluator::new(Method::Imm);
    let mut without_status = None;
    for file in &files {
        let sequence = read_sequence_file(file)?;
        let name = file.file_name().ok_or(ScoreError::Unnamed)?;
        let path = args.associations.join(name);
        let reader =
            std::fs::File::open(&path).map_err(|source| ScoreError::Open { path: path.clone(), source })?;
        let associations = |source| ScoreError::Associations { path: path.clone(), source };
        let rows = read_association_rows(std::io::BufReader::new(reader)).map_err(associations)?;
        let records = association_records_from_rows(&sequence, &rows).map_err(associations)?;
        if without_status.is_none() {
            without_status = confirmed_track_counts(&records).err().map(|error| (path.clone(), error));
        }
        evaluator.add_sequence(&records);
    }
    if let Some((path, error)) = without_status {
        eprintln!(
            "metrics on confirmed tracks skipped: {}: {error} (the file has no `confirmed` column or an \
             empty one)",
            path.display()
        );
    }
    println!("{}", summary_json(&args.name, evaluator.result()));
    Ok(())
}
