//! `primm track`: offline tracking of a measurement CSV file into a track CSV file.

use crate::cli::predictor::predictor_for;
use crate::config::Config;
use crate::io::read_sequence_file;
use crate::io::track_csv::TrackCsvWriter;
use crate::mode::Method;
use crate::offline::track_sequence;
use crate::tracker::Tracker;
use clap::Args as ClapArgs;
use std::path::PathBuf;

/// Arguments of `primm track`.
#[derive(Debug, Clone, ClapArgs)]
#[command(about = "Track a measurement CSV file offline and write the track CSV file")]
pub struct Args {
    /// Measurement CSV file.
    #[arg(long, value_name = "FILE")]
    pub input: PathBuf,
    /// Track CSV file to write.
    #[arg(long, value_name = "FILE")]
    pub output: PathBuf,
    /// Method: cv, ca, ct, pr, imm or pr-imm.
    #[arg(long, default_value = "pr-imm")]
    pub method: Method,
    /// Tracker configuration (TOML); the built-in defaults otherwise.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// ONNX model of the learned predictor.
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
}

/// Runs `primm track`.
pub fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let config = match &args.config {
        Some(path) => Config::from_file(path)?,
        None => Config::default(),
    }
    .with_modes(args.method.modes());
    let predictor = predictor_for(args.method, args.model.as_deref())?;
    let mut tracker = Tracker::with_predictor(config, predictor)?;
    let sequence = read_sequence_file(&args.input)?;
    let file = std::fs::File::create(&args.output)
        .map_err(|e| format!("cannot create {}: {e}", args.output.display()))?;
    let mut writer = TrackCsvWriter::new(std::io::BufWriter::new(file))?;
    let mut result = Ok(());
    track_sequence(&mut tracker, &sequence, |recorded, outputs| {
        if result.is_ok() {
            result = writer.write_frame(recorded.index, recorded.timestamp_s, outputs);
        }
    })?;
    result?;
    writer.finish()?;
    let stats = tracker.stats();
    eprintln!(
        "{}: {} frames, {} measurements, {} tracks started, {} deleted -> {}",
        args.method,
        stats.frames_tracked,
        stats.measurements_accepted,
        stats.tracks_initiated,
        stats.tracks_deleted,
        args.output.display()
    );
    Ok(())
}
