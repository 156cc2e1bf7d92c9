//! `primm record`: the service's three streams into one MCAP file (the wire payloads and
//! Foxglove's messages for viewing; docs/recording.md).

use super::latency_out::parse_positive_seconds;
use primm_config::{ConfigError, Settings};
use primm_record::recorder::{record, RecordError, RecordLimits, RecordSummary, StreamPorts};
use primm_record::transforms::RadarPose;
use primm_record::{FrameEncoder, McapFile, McapFileError, Topic};
use primm_service::catalog::SERVICE_PREFIX_ENV;
use primm_service::{ConnectError, ServiceNames, ShutdownFlag};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `primm record`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    about = "Record primm/measurements, primm/tracks and primm/latency into an MCAP file (for Foxglove and `primm replay`)"
)]
pub struct Args {
    /// The MCAP file to write (replaced if it exists).
    #[arg(long, value_name = "FILE")]
    pub output: PathBuf,
    /// Stop after this long, s (otherwise on Ctrl-C or a stop condition below).
    #[arg(long, value_name = "S", value_parser = parse_positive_seconds)]
    pub duration_s: Option<f64>,
    /// Stop after this many track frames.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Stop after the tracker's answer to the last frame of a finite replay.
    #[arg(long)]
    pub until_end: bool,
    /// Prefix of the service names (`PREFIX/primm/...`).
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// The iceoryx2 domain to record from (default: that of PRIMM_ICEORYX2_DOMAIN, else
    /// iceoryx2's own).
    #[arg(long, value_name = "NAME")]
    pub domain: Option<String>,
    /// The configuration whose sensor mounts (`frame.sensors`) are drawn as radar frames
    /// (default: the built-in configuration).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

/// Why `primm record` failed.
#[derive(Debug, thiserror::Error)]
pub enum RecordCommandError {
    /// The configuration could not be read.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The streams could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The file could not be created or finished.
    #[error(transparent)]
    File(#[from] McapFileError),
    /// Recording stopped with an error (the file so far stays readable with `mcap recover`).
    #[error("recording into {}: {source}", path.display())]
    Record {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: RecordError,
    },
}

/// The radars of the configuration at `config` (the built-in one when `None`).
pub fn configured_radars(config: Option<&Path>) -> Result<Vec<RadarPose>, ConfigError> {
    let settings = match config {
        Some(path) => primm_config::settings_from_file(path)?,
        None => Settings::default(),
    };
    Ok(settings.tracker.frame.sensors.iter().map(RadarPose::from).collect())
}

/// Runs `primm record`.
pub fn run(args: &Args) -> Result<(), RecordCommandError> {
    let shutdown = ShutdownFlag::on_signals().map_err(RecordCommandError::Signals)?;
    let radars = configured_radars(args.config.as_deref())?;
    let names = ServiceNames::new(&args.service_prefix);
    let ports = StreamPorts::open(&names, args.domain.as_deref(), "primm-record")?;
    let mut file = McapFile::create(&args.output)?;
    eprintln!(
        "recording {}, {} and {} into {} (Ctrl-C stops)",
        names.measurements(),
        names.tracks(),
        names.latency(),
        args.output.display()
    );
    let limits = RecordLimits {
        duration: args.duration_s.map(Duration::from_secs_f64),
        track_frames: args.frames,
        until_end: args.until_end,
    };
    let mut encoder = FrameEncoder::new(radars);
    let summary = record(&ports, &mut encoder, &mut file, &limits, &|| shutdown.is_requested())
        .map_err(|source| RecordCommandError::Record { path: args.output.clone(), source })?;
    file.finish()?;
    print!("{}", summary_text(&summary, &args.output));
    Ok(())
}

/// What was recorded, as text.
fn summary_text(summary: &RecordSummary, path: &Path) -> String {
    let bytes = std::fs::metadata(path).map_or(0, |metadata| metadata.len());
    let mut text = format!(
        "recorded {} measurement frames ({} missed), {} track frames ({} missed), {} latency reports into {} ({bytes} bytes)\n",
        summary.measurement_frames,
        summary.measurement_frames_missed,
        summary.track_frames,
        summary.track_frames_missed,
        summary.latency_reports,
        path.display(),
    );
    for topic in Topic::ALL {
        text.push_str(&format!("  {:<28} {:>8} messages\n", topic.name(), summary.messages[topic.index()]));
    }
    text
}
