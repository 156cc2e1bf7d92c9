//! `primm track`: offline tracking of a measurement CSV file into a track CSV file.

use super::track_mcap::OfflineRecording;
use super::TrackerArgs;
use clap::Args as ClapArgs;
use primm_core::mode::Method;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::{StepError, Tracker};
use primm_core::validation::FrameError;
use primm_predictor::onnx::ModelError;
use primm_predictor::split::{on_inference_threads, InferenceThreadsError};
use primm_predictor::{load_predictor, predictor_for};
use primm_record::transforms::RadarPose;
use primm_sim::io::association_csv::AssociationCsvWriter;
use primm_sim::io::track_csv::TrackCsvWriter;
use primm_sim::io::{read_sequence_file, CsvError, TooManyMeasurements};
use std::path::{Path, PathBuf};

/// Arguments of `primm track`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Track a measurement CSV file offline and write the track CSV file",
    after_help = "\
Examples:
  primm track --input data/evaluation/evaluation_0000.csv --output tracks.csv --method imm
  primm track --input scene.csv --output tracks.csv --config my.toml --associations assoc.csv
  primm track --input scene.csv --output tracks.csv --method pr-imm --timing steps.txt"
)]
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
    /// The tracker's configuration, model, engine and tracking frame.
    #[command(flatten)]
    pub tracker: TrackerArgs,
    /// Also write the association CSV (which track took each measurement; scored by
    /// `primm score`).
    #[arg(long, value_name = "FILE")]
    pub associations: Option<PathBuf>,
    /// Time every tracker step (the CSV reading and writing excluded; the speculation of
    /// `--inference-threads` included) and append one line per
    /// frame with its step time in nanoseconds to FILE; prints a one-line JSON summary (frames
    /// per second, percentiles) on stdout.
    #[arg(long, value_name = "FILE")]
    pub timing: Option<PathBuf>,
    /// Also write the run as an MCAP recording (the topics of `primm record`, the ground truth
    /// included; docs/recording.md), to open in Foxglove or replay with `primm replay`.
    #[arg(long, value_name = "FILE")]
    pub mcap: Option<PathBuf>,
    /// Run the PR model on COUNT inference threads (1 to 8) instead of on the tracking thread,
    /// each step handing them the next frame's requests ahead for its guessed time
    /// (speculation); the threads spin briefly before parking, so give each one a core of its
    /// own (on an oversubscribed host this is many times slower). Every frame waits for its
    /// answers (up to a minute, not the service's deadline), so the tracks are the same bit for
    /// bit as without.
    #[arg(long, value_name = "COUNT", value_parser = clap::value_parser!(u8).range(1..=8))]
    pub inference_threads: Option<u8>,
}

/// How long `primm track --inference-threads` waits for a frame's learned predictions: far
/// beyond any inference time, so that no frame goes without them and offline results do not
/// depend on timing.
const OFFLINE_INFERENCE_WAIT: std::time::Duration = std::time::Duration::from_secs(60);

/// How long the tracking and inference threads of `primm track --inference-threads` spin
/// before parking (`ThreadedPredictor::set_spin`): offline frames follow each other within
/// this, so no batch waits for a wake-up.
const OFFLINE_SPIN: std::time::Duration = std::time::Duration::from_micros(500);

/// The fewest requests each inference thread of `primm track --inference-threads` takes before a
/// batch is shared further: offline batches are small (a few pedestrians per radar scan), and
/// each row costs about as much as handing a thread its part.
const OFFLINE_MIN_REQUESTS_PER_PART: usize = 4;

/// Why `primm track` failed.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The configuration file could not be read or is invalid.
    #[error(transparent)]
    Config(#[from] primm_config::ConfigError),
    /// The learned predictor's model could not be loaded.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The inference threads could not be started.
    #[error(transparent)]
    InferenceThreads(#[from] InferenceThreadsError),
    /// The configuration is invalid for the tracker.
    #[error(transparent)]
    Tracker(#[from] primm_core::config::ConfigError),
    /// The measurement CSV file could not be read.
    #[error(transparent)]
    Input(#[from] CsvError),
    /// A recorded frame carries more measurements than a frame may.
    #[error(transparent)]
    TooManyMeasurements(#[from] TooManyMeasurements),
    /// An output file (tracks or associations) could not be created.
    #[error("cannot create {}: {source}", path.display())]
    Create {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The timing file could not be opened for appending.
    #[error("cannot open {}: {source}", path.display())]
    Open {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Writing an output file failed.
    #[error(transparent)]
    Write(#[from] std::io::Error),
    /// The MCAP file could not be written.
    #[error(transparent)]
    Mcap(#[from] primm_record::McapFileError),
    /// A message could not be written into the MCAP file.
    #[error(transparent)]
    McapMessage(#[from] primm_record::SinkError),
    /// The tracker rejected a frame.
    #[error("frame {frame}: {source}")]
    Step {
        /// The frame's index in the recording.
        frame: u64,
        /// The tracker's error.
        source: StepError,
    },
}

/// Creates the output file `path`.
fn create(path: &Path) -> Result<std::fs::File, TrackError> {
    std::fs::File::create(path).map_err(|source| TrackError::Create { path: path.to_owned(), source })
}

/// The predictor of `primm track`: the method's, synchronous, or the PR model on `threads`
/// inference threads without a deadline in practice.
fn track_predictor(
    args: &Args,
    threads: Option<u8>,
    engine: primm_config::InferenceEngine,
) -> Result<Box<dyn DisplacementPredictor + Send>, TrackError> {
    let model = args.tracker.model.as_deref();
    let Some(threads) = threads else { return Ok(predictor_for(args.method, model, engine)?) };
    let mut split =
        on_inference_threads(load_predictor(model, engine)?, usize::from(threads), OFFLINE_INFERENCE_WAIT)?
            .with_min_requests_per_part(OFFLINE_MIN_REQUESTS_PER_PART);
    for part in split.parts_mut() {
        part.set_spin(OFFLINE_SPIN);
    }
    Ok(Box::new(split))
}

/// `--mcap`'s recording of `frames` frames, drawing the tracker's configured radars.
fn offline_recording<P: DisplacementPredictor>(
    path: Option<&Path>,
    tracker: &Tracker<P>,
    frames: usize,
) -> Result<Option<OfflineRecording>, TrackError> {
    let Some(path) = path else { return Ok(None) };
    let radars = tracker.config().frame.sensors.iter().map(RadarPose::from).collect();
    Ok(Some(OfflineRecording::create(path, radars, frames)?))
}

/// Runs `primm track`.
pub fn run(args: &Args) -> Result<(), TrackError> {
    let settings = args.tracker.load_settings()?;
    let config = settings.tracker.with_modes(args.method.modes());
    let threads = args.inference_threads.filter(|_| args.method.needs_predictor());
    let predictor = track_predictor(args, threads, settings.inference.engine)?;
    let mut tracker = Tracker::with_predictor(config, predictor)?;
    let sequence = read_sequence_file(&args.input)?;
    let file = create(&args.output)?;
    let tracking_frame = tracker.config().frame.tracking_frame;
    let mut writer = TrackCsvWriter::for_sequence(std::io::BufWriter::new(file), &sequence, tracking_frame)?;
    let mut associations = match &args.associations {
        Some(path) => {
            let file = create(path)?;
            Some(AssociationCsvWriter::new(std::io::BufWriter::new(file))?)
        }
        None => None,
    };
    let frames = sequence.to_frames()?;
    let mut recording = offline_recording(args.mcap.as_deref(), &tracker, frames.len())?;
    let mut step_ns: Vec<u64> = Vec::with_capacity(frames.len());
    tracker.reset();
    // Frames in file order, which is arrival order: a late frame (within
    // `tracker.max_frame_delay_s`) is tracked in its place and writes the rows of the tracks as
    // they were right after it (the rows of the newer frames, written when they came, stay);
    // one older than that is rejected, counted and skipped.
    for (recorded, frame) in sequence.frames.iter().zip(&frames) {
        let start = std::time::Instant::now();
        match tracker.step(frame) {
            Ok(_) => {}
            Err(StepError::InvalidFrame(error @ FrameError::TooLate { .. })) => {
                eprintln!("frame {}: older than the late-frame window reaches; skipped", recorded.index);
                if let Some(recording) = recording.as_mut() {
                    recording.write_rejected(recorded, &StepError::InvalidFrame(error))?;
                }
                continue;
            }
            Err(source) => return Err(TrackError::Step { frame: recorded.index, source }),
        };
        if threads.is_some() {
            tracker.speculate();
        }
        step_ns.push(start.elapsed().as_nanos() as u64);
        if let Some(recording) = recording.as_mut() {
            recording.write_tracked(recorded, &tracker)?;
        }
        let outputs =
            if tracker.last_step().late() { tracker.late_frame_outputs() } else { tracker.last_outputs() };
        writer.write_frame(recorded.index, recorded.timestamp_s, outputs)?;
        if let Some(associations) = associations.as_mut() {
            associations.write_frame(recorded.index, recorded.measurements.len(), outputs)?;
        }
    }
    writer.finish()?;
    if let Some(recording) = recording {
        recording.finish()?;
    }
    if let Some(associations) = associations {
        associations.finish()?;
    }
    if let Some(path) = &args.timing {
        write_timing(path, args.method, &mut step_ns)?;
    }
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
    let sensors = tracker.sensors().report(tracker.config()).to_string();
    if !sensors.is_empty() {
        eprintln!("sensors (estimated from the data):\n{sensors}");
    }
    Ok(())
}

/// Appends the step times to `path`, one per line in ns, and prints their summary.
fn write_timing(
    path: &Path,
    method: primm_core::mode::Method,
    step_ns: &mut [u64],
) -> Result<(), TrackError> {
    use std::io::Write as _;
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|source| TrackError::Open { path: path.to_owned(), source })?;
    let mut out = std::io::BufWriter::new(file);
    for ns in step_ns.iter() {
        writeln!(out, "{ns}")?;
    }
    out.flush()?;
    println!("{}", timing_json(method, step_ns));
    Ok(())
}

/// Frames per second of the tracker steps alone and their percentiles, as JSON.
fn timing_json(method: primm_core::mode::Method, step_ns: &mut [u64]) -> String {
    step_ns.sort_unstable();
    let total_ns: u64 = step_ns.iter().sum();
    let percentile = |q: f64| -> f64 {
        if step_ns.is_empty() {
            return 0.0;
        }
        let rank = ((q * step_ns.len() as f64).ceil() as usize).clamp(1, step_ns.len());
        step_ns[rank - 1] as f64 / 1000.0
    };
    serde_json::json!({
        "tracker": format!("primm {method}"),
        "frames": step_ns.len(),
        "step_seconds": total_ns as f64 * 1e-9,
        "frames_per_second": if total_ns > 0 { step_ns.len() as f64 / (total_ns as f64 * 1e-9) } else { 0.0 },
        "step_p50_us": percentile(0.5),
        "step_p99_us": percentile(0.99),
        "step_max_us": percentile(1.0),
    })
    .to_string()
}
