//! `primm replay`: the measurement frames of a recording (`primm record`, `primm track --mcap`)
//! published again on `primm/measurements`, at the recorded pace, faster or slower, or as fast
//! as the tracker answers them.

use primm_publisher::replay::{ReplayError, Replayer};
use primm_record::reading::{read_frames, ReadRecordingError};
use primm_record::Topic;
use primm_service::catalog::SERVICE_PREFIX_ENV;
use primm_service::clock::monotonic_ns;
use primm_service::{ConnectError, ServiceNames, ShutdownFlag};
use primm_wire::{MeasurementFrame, FRAME_FLAG_STREAM_START};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Frames in flight with `--as-fast-as-possible` (the tracker's answers hold the rest back;
/// lossless up to 16).
const MAX_IN_FLIGHT: u64 = 8;
/// The longest pause between two frames at the recorded pace, s: a gap in the recording (or a
/// new stream) is not waited out.
const LONGEST_PAUSE_S: f64 = 5.0;

/// Arguments of `primm replay`.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Publish the measurement frames of an MCAP recording on primm/measurements")]
pub struct Args {
    /// The recording (`primm record` or `primm track --mcap`).
    #[arg(value_name = "FILE")]
    pub input: PathBuf,
    /// Speed factor on the recorded pace (2: twice as fast).
    #[arg(long, default_value_t = 1.0, value_name = "X", value_parser = parse_rate)]
    pub rate: f64,
    /// Send each frame as soon as the tracker has answered all but a few of the frames before
    /// it: as fast as the tracker takes them, without losing one.
    #[arg(long, conflicts_with = "rate")]
    pub as_fast_as_possible: bool,
    /// Prefix of the service names (`PREFIX/primm/...`).
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// How long to wait for a tracker to serve before sending, s.
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    pub wait_for_tracker_s: f64,
}

/// Parses `--rate`: a positive, finite factor.
fn parse_rate(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(rate) if rate.is_finite() && rate > 0.0 => Ok(rate),
        _ => Err(format!("`{text}` is not a positive speed factor")),
    }
}

/// Why `primm replay` failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayCommandError {
    /// The recording could not be read.
    #[error(transparent)]
    Read(#[from] ReadRecordingError),
    /// The recording holds no measurement frame.
    #[error("{} holds no measurement frame (topic {})", .0.display(), Topic::Measurements.name())]
    NoFrames(PathBuf),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The streams could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// No tracker served in time.
    #[error("no tracker serves {0} (start `primm serve` first)")]
    NoTracker(String),
    /// Sending failed.
    #[error(transparent)]
    Send(#[from] ReplayError),
}

/// Runs `primm replay`.
pub fn run(args: &Args) -> Result<(), ReplayCommandError> {
    let frames = read_frames::<MeasurementFrame>(&args.input, Topic::Measurements)?;
    if frames.is_empty() {
        return Err(ReplayCommandError::NoFrames(args.input.clone()));
    }
    let shutdown = ShutdownFlag::on_signals().map_err(ReplayCommandError::Signals)?;
    let names = ServiceNames::new(&args.service_prefix);
    let mut replayer = Replayer::new(&names, args.as_fast_as_possible)?;
    if !replayer.wait_for_tracker(Duration::from_secs_f64(args.wait_for_tracker_s.max(0.0)), &shutdown) {
        return Err(ReplayCommandError::NoTracker(names.tracks()));
    }
    let answer_timeout = Duration::from_secs(10);
    let (start, start_ns) = (Instant::now(), monotonic_ns());
    let mut offset_s = 0.0;
    let (mut sent, mut dropped, mut unheard) = (0u64, 0u64, 0u64);
    for (index, frame) in frames.iter().enumerate() {
        if shutdown.is_requested() {
            break;
        }
        let mut scheduled_time_ns = 0;
        if !args.as_fast_as_possible {
            if let Some(previous) = index.checked_sub(1).map(|i| &frames[i]) {
                let step = frame.sensor_timestamp_s - previous.sensor_timestamp_s;
                if frame.flags & FRAME_FLAG_STREAM_START == 0 && step.is_finite() {
                    offset_s += step.clamp(0.0, LONGEST_PAUSE_S) / args.rate;
                }
            }
            let due = start + Duration::from_secs_f64(offset_s);
            scheduled_time_ns = start_ns + (offset_s * 1e9) as u64;
            if let Some(wait) = due.checked_duration_since(Instant::now()) {
                std::thread::sleep(wait);
            }
        } else {
            replayer.wait_in_flight(MAX_IN_FLIGHT - 1, answer_timeout, &shutdown)?;
        }
        match replayer.send_recorded(frame, scheduled_time_ns) {
            Ok(frame) => {
                sent += 1;
                unheard += u64::from(frame.receivers == 0);
            }
            Err(error @ (ReplayError::Loan(_) | ReplayError::Send(_))) => {
                dropped += 1;
                tracing::warn!(%error, "measurement frame dropped");
            }
            Err(error) => return Err(error.into()),
        }
    }
    if args.as_fast_as_possible {
        replayer.wait_all_answered(answer_timeout, &shutdown)?;
    }
    println!(
        "replayed {sent} of {} measurement frames from {} ({dropped} dropped, {unheard} sent with no tracker listening)",
        frames.len(),
        args.input.display()
    );
    Ok(())
}
