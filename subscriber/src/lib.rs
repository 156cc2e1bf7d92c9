//! # primm-subscriber: the tracks from shared memory
//!
//! Reads `primm/tracks` and `primm/latency` (and `primm/measurements` for the ground truth),
//! shows a live view or records the track CSV format, and sums up accuracy and latency at the
//! end. The binary `primm-subscriber` and the `primm subscribe` subcommand both run [`run`];
//! [`subscribe`] returns the summary instead of printing it.
//!
//! It sleeps in an iceoryx2 `WaitSet` on the three event services (plus a 200 ms tick for the
//! view and time-outs), or spins with `--busy-poll`.
//!
//! ```no_run
//! use clap::Parser;
//!
//! #[derive(Parser)]
//! struct Cli {
//!     #[command(flatten)]
//!     args: primm_subscriber::Args,
//! }
//!
//! let cli = Cli::parse_from(["subscriber", "--frames", "100"]);
//! let summary = primm_subscriber::subscribe(&cli.args)?;
//! println!("{} track frames", summary.track_frames);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod accuracy;
pub mod track_csv;

use crate::accuracy::{AccuracyMonitor, AccuracySummary};
use crate::track_csv::write_track_frame;
use hdrhistogram::Histogram;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::ReceiveError;
use iceoryx2::prelude::{CallbackProgression, SignalHandlingMode, WaitSetBuilder};
use iceoryx2::waitset::{WaitSet, WaitSetAttachmentError, WaitSetCreateError, WaitSetGuard, WaitSetRunError};
use primm_core::measurement::ObjectClass;
use primm_service::catalog::{self, Ipc, SERVICE_PREFIX_ENV};
use primm_service::clock::monotonic_ns;
use primm_service::latency::{format_named_table, format_table, summarise, MAX_TRACKABLE_NS};
use primm_service::latency_files::{LatencyFiles, LatencyFilesError, StageDescription};
use primm_service::realtime::{RealtimeArgs, RealtimeRefused, RealtimeReport};
use primm_service::{ConnectError, ServiceNames, ShutdownFlag};
use primm_sim::io::track_csv::TrackCsvWriter;
use primm_wire::{
    FrameStatus, LatencyReport, MeasurementFrame, StageLatency, TrackFrame, WireTrack, TRACK_FLAG_STREAM_END,
    TRACK_FLAG_TRACKER_RESET,
};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of the subscriber.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Show or record the tracks published on primm/tracks, with accuracy and latency")]
pub struct Args {
    /// Record every track updated by a measurement to this CSV file
    /// (frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Exit after the answer to the last frame of a finite replay.
    #[arg(long)]
    pub until_end: bool,
    /// Exit after this many track frames.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Exit when no track frame arrived for this long, s.
    #[arg(long, value_name = "S")]
    pub idle_timeout_s: Option<f64>,
    /// No live view; only the summary at the end.
    #[arg(long)]
    pub quiet: bool,
    /// Also write the summary as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Do not read primm/measurements (no accuracy figures).
    #[arg(long)]
    pub no_truth: bool,
    /// Spin on the subscribers instead of sleeping in a WaitSet.
    #[arg(long)]
    pub busy_poll: bool,
    /// Prefix of the service names (`PREFIX/primm/...`).
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// Write the subscriber's latencies (publisher_to_subscriber, its coordinated-omission
    /// corrected twin, tracker_to_subscriber) into this directory: an HdrHistogram interval log
    /// (`.hlog`) and percentile distribution (`.hgrm`) each, and the plot `subscriber.svg`.
    #[arg(long, value_name = "DIR")]
    pub latency_out: Option<PathBuf>,
    /// Length of one interval of the `.hlog` files, s.
    #[arg(long, default_value_t = 1.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub latency_interval_s: f64,
    /// Real-time settings of the receiving thread (docs/realtime-tuning.md).
    #[command(flatten)]
    pub realtime: RealtimeArgs,
}

/// Parses a positive, finite number of seconds (at most a day).
fn parse_positive_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.parse().map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0 {
        Ok(seconds)
    } else {
        Err(format!("`{text}`: the interval must be more than 0 and at most 86400 s"))
    }
}

/// Why the subscriber failed.
#[derive(Debug, thiserror::Error)]
pub enum SubscribeError {
    /// The services could not be opened.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The WaitSet could not be created.
    #[error("cannot create the WaitSet: {0}")]
    WaitSetCreate(WaitSetCreateError),
    /// A listener could not be attached to the WaitSet.
    #[error("cannot attach to the WaitSet: {0}")]
    WaitSetAttach(WaitSetAttachmentError),
    /// Waiting in the WaitSet failed.
    #[error("cannot wait in the WaitSet: {0}")]
    WaitSetRun(WaitSetRunError),
    /// Receiving a sample failed.
    #[error("cannot receive: {0}")]
    Receive(ReceiveError),
    /// The latency files could not be written.
    #[error(transparent)]
    LatencyFiles(#[from] LatencyFilesError),
    /// The CSV or JSON output could not be written.
    #[error("cannot write {path}: {source}")]
    Output {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A real-time setting could not be applied and `--require-realtime` was given.
    #[error(transparent)]
    Realtime(#[from] RealtimeRefused),
}

/// Percentiles of one latency, for the JSON summary.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct LatencyRow {
    /// What was measured.
    pub name: String,
    /// Samples.
    pub count: u64,
    /// Median, ns.
    pub p50_ns: u64,
    /// 90th percentile, ns.
    pub p90_ns: u64,
    /// 99th percentile, ns.
    pub p99_ns: u64,
    /// 99.9th percentile, ns.
    pub p999_ns: u64,
    /// Maximum, ns.
    pub max_ns: u64,
    /// Mean, ns.
    pub mean_ns: u64,
}

impl From<&StageLatency> for LatencyRow {
    fn from(stage: &StageLatency) -> Self {
        Self {
            name: stage.name_str().to_owned(),
            count: stage.count,
            p50_ns: stage.p50_ns,
            p90_ns: stage.p90_ns,
            p99_ns: stage.p99_ns,
            p999_ns: stage.p999_ns,
            max_ns: stage.max_ns,
            mean_ns: stage.mean_ns,
        }
    }
}

/// What the subscriber saw.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct SubscriberSummary {
    /// Track frames received.
    pub track_frames: u64,
    /// Of which tracked.
    pub frames_tracked: u64,
    /// Of which rejected by the tracker.
    pub frames_rejected: u64,
    /// Input sequence numbers with no track frame received.
    pub input_sequence_gaps: u64,
    /// Track frames flagged as following a tracker reset.
    pub tracker_resets: u64,
    /// Whether the answer to the last frame of a finite replay arrived.
    pub stream_end_seen: bool,
    /// Confirmed tracks in the last track frame.
    pub confirmed_tracks_last_frame: u64,
    /// CSV rows written.
    pub csv_rows: u64,
    /// Accuracy against the ground truth (absent with `--no-truth`).
    pub accuracy: Option<AccuracySummary>,
    /// From the tracker's send to this subscriber's receive.
    pub delivery_latency: Option<LatencyRow>,
    /// From the publisher's send of the measurement frame to this subscriber's receive of the
    /// answer.
    pub end_to_end_latency: Option<LatencyRow>,
    /// From the time the publisher was due to send the measurement frame (its schedule) to this
    /// subscriber's receive of the answer: the end-to-end latency corrected for coordinated
    /// omission (equal to it for frames sent without a schedule).
    pub end_to_end_corrected_latency: Option<LatencyRow>,
    /// The tracker's last latency report.
    pub tracker_latency: Vec<LatencyRow>,
    /// Frames the tracker received, per its last report.
    pub tracker_frames_received: u64,
    /// Frames the tracker rejected, per its last report.
    pub tracker_frames_rejected: u64,
    /// Measurements the tracker rejected, per its last report.
    pub tracker_measurements_rejected: u64,
    /// The latency files written (`--latency-out`).
    pub latency_files: Vec<PathBuf>,
}

impl SubscriberSummary {
    /// A plain-text rendering.
    pub fn text(&self) -> String {
        let mut text = format!(
            "track frames: {} ({} tracked, {} rejected), input sequence gaps {}, tracker resets {}, stream end {}\n",
            self.track_frames,
            self.frames_tracked,
            self.frames_rejected,
            self.input_sequence_gaps,
            self.tracker_resets,
            if self.stream_end_seen { "seen" } else { "not seen" }
        );
        if let Some(accuracy) = &self.accuracy {
            let metres = |value: Option<f64>| value.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.3} m"));
            text += &format!(
                "accuracy over {} measurements with ground truth: prior RMSE {} ({} samples), posterior RMSE {} ({} samples), IDSW {}, IDF1 {}\n",
                accuracy.ground_truth_measurements,
                metres(accuracy.prior_rmse_m),
                accuracy.prior_samples,
                metres(accuracy.posterior_rmse_m),
                accuracy.posterior_samples,
                accuracy.identity.idsw,
                accuracy.idf1.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.3}"))
            );
        }
        let mut rows: Vec<(&str, StageLatency)> = Vec::new();
        for (row, name) in [
            (&self.end_to_end_latency, "publisher_to_subscriber"),
            (&self.end_to_end_corrected_latency, "publisher_to_subscriber_corrected"),
            (&self.delivery_latency, "tracker_to_subscriber"),
        ] {
            if let Some(row) = row {
                let mut stage = StageLatency::named(name);
                stage.count = row.count;
                stage.p50_ns = row.p50_ns;
                stage.p90_ns = row.p90_ns;
                stage.p99_ns = row.p99_ns;
                stage.p999_ns = row.p999_ns;
                stage.max_ns = row.max_ns;
                stage.mean_ns = row.mean_ns;
                rows.push((name, stage));
            }
        }
        if !rows.is_empty() {
            text += "latency seen by the subscriber:\n";
            text += &format_named_table(rows.iter().map(|(name, stage)| (*name, stage)));
        }
        if !self.tracker_latency.is_empty() {
            let stages: Vec<StageLatency> = self
                .tracker_latency
                .iter()
                .map(|row| {
                    let mut stage = StageLatency::named(&row.name);
                    stage.count = row.count;
                    stage.p50_ns = row.p50_ns;
                    stage.p90_ns = row.p90_ns;
                    stage.p99_ns = row.p99_ns;
                    stage.p999_ns = row.p999_ns;
                    stage.max_ns = row.max_ns;
                    stage.mean_ns = row.mean_ns;
                    stage
                })
                .collect();
            text += "tracker latency (its last report):\n";
            text += &format_table(&stages);
        }
        text
    }
}

/// State of one subscriber run.
#[derive(Debug)]
struct Viewer {
    summary: SubscriberSummary,
    accuracy: Option<AccuracyMonitor>,
    csv: Option<CsvOutput>,
    /// Indexed by [`SubscriberLatency`].
    latencies: [Histogram<u64>; SubscriberLatency::COUNT],
    files: Option<LatencyFiles>,
    last_sequence: Option<u64>,
    last_report: Option<LatencyReport>,
    live: bool,
    last_draw: Instant,
    last_frame_at: Instant,
}

impl Viewer {
    fn new(args: &Args, truth: bool, csv: Option<CsvOutput>) -> Self {
        Self {
            summary: SubscriberSummary::default(),
            accuracy: truth.then(AccuracyMonitor::new),
            csv,
            latencies: std::array::from_fn(|_| histogram()),
            files: None,
            last_sequence: None,
            last_report: None,
            live: !args.quiet && std::io::stdout().is_terminal(),
            last_draw: Instant::now(),
            last_frame_at: Instant::now(),
        }
    }

    /// Without the live view (and unless `--quiet`), a progress line on stderr every second.
    fn report_progress(&mut self, args: &Args) {
        if !self.live
            && !args.quiet
            && self.summary.track_frames > 0
            && self.last_draw.elapsed() >= Duration::from_secs(1)
        {
            eprintln!(
                "track frames {} (rejected {}), confirmed tracks {}",
                self.summary.track_frames,
                self.summary.frames_rejected,
                self.summary.confirmed_tracks_last_frame
            );
            self.last_draw = Instant::now();
        }
    }

    fn on_tracks(&mut self, frame: &TrackFrame) -> Result<(), SubscribeError> {
        let now_ns = monotonic_ns();
        self.last_frame_at = Instant::now();
        let summary = &mut self.summary;
        summary.track_frames += 1;
        match frame.frame_status() {
            Some(FrameStatus::Tracked) => summary.frames_tracked += 1,
            _ => summary.frames_rejected += 1,
        }
        if frame.flags & TRACK_FLAG_TRACKER_RESET != 0 {
            summary.tracker_resets += 1;
        }
        if frame.flags & TRACK_FLAG_STREAM_END != 0 {
            summary.stream_end_seen = true;
        }
        match self.last_sequence {
            Some(last) if frame.input_sequence > last + 1 => {
                summary.input_sequence_gaps += frame.input_sequence - last - 1
            }
            _ => {}
        }
        self.last_sequence = Some(frame.input_sequence);
        summary.confirmed_tracks_last_frame =
            frame.valid_tracks().iter().filter(|t| t.status == 1).count() as u64;
        if frame.publish_time_ns != 0 && now_ns >= frame.publish_time_ns {
            self.latencies[SubscriberLatency::TrackerToSubscriber as usize]
                .saturating_record(now_ns - frame.publish_time_ns);
        }
        if frame.input_publish_time_ns != 0 && now_ns >= frame.input_publish_time_ns {
            self.latencies[SubscriberLatency::PublisherToSubscriber as usize]
                .saturating_record(now_ns - frame.input_publish_time_ns);
            let due_ns = match frame.input_scheduled_time_ns {
                0 => frame.input_publish_time_ns,
                scheduled => scheduled,
            };
            if now_ns >= due_ns {
                self.latencies[SubscriberLatency::PublisherToSubscriberCorrected as usize]
                    .saturating_record(now_ns - due_ns);
            }
        }
        if let Some(files) = &mut self.files {
            let latencies = &self.latencies;
            if let Err(error) = files.write_due(now_ns, |index| &latencies[index]) {
                tracing::warn!(%error, "cannot write the latency files; no more intervals are written");
                self.files = None;
            }
        }
        if let Some(accuracy) = &mut self.accuracy {
            accuracy.add_tracks(frame);
        }
        if let Some((path, csv)) = &mut self.csv {
            write_track_frame(csv, frame)
                .map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
            self.summary.csv_rows = csv.rows();
        }
        if self.live && self.last_draw.elapsed() >= Duration::from_millis(200) {
            self.draw(frame);
            self.last_draw = Instant::now();
        }
        Ok(())
    }

    fn draw(&self, frame: &TrackFrame) {
        let mut screen = String::from("\x1b[H\x1b[2J");
        let status = frame.frame_status().map_or("unknown", FrameStatus::name);
        screen += &format!(
            "primm tracks  frame {}  seq {}  t {:.3} s  status {}  tracks {}  (frames {}, rejected {}, gaps {})\n\n",
            frame.source_frame,
            frame.input_sequence,
            frame.sensor_timestamp_s,
            status,
            frame.count,
            self.summary.track_frames,
            self.summary.frames_rejected,
            self.summary.input_sequence_gaps
        );
        screen += &format!(
            "{:>6} {:<11} {:<5} {:>8} {:>8} {:>7} {:>7} {:>5} {:>5} {:>5} {:>5} {:>5}\n",
            "id", "class", "stat", "x m", "y m", "vx m/s", "vy m/s", "PR", "CV", "CA", "CT", "hits"
        );
        let mut tracks: Vec<&WireTrack> = frame.valid_tracks().iter().filter(|t| t.status == 1).collect();
        tracks.sort_by_key(|t| t.id);
        for track in tracks.iter().take(25) {
            let [pr, cv, ca, ct] = track.mode_probabilities;
            screen += &format!(
                "{:>6} {:<11} {:<5} {:>8.2} {:>8.2} {:>7.2} {:>7.2} {:>5.2} {:>5.2} {:>5.2} {:>5.2} {:>5}\n",
                track.id,
                ObjectClass::from_code(track.class_code).map_or("?", ObjectClass::name),
                "conf",
                track.x_m,
                track.y_m,
                track.vx_mps,
                track.vy_mps,
                pr,
                cv,
                ca,
                ct,
                track.hits
            );
        }
        if tracks.len() > 25 {
            screen += &format!("... {} more confirmed tracks\n", tracks.len() - 25);
        }
        if let Some(report) = &self.last_report {
            screen += &format!(
                "\ntracker latency (report {}, {} frames):\n",
                report.sequence, report.frames_received
            );
            screen += &format_table(report.valid_stages());
        }
        let mut stdout = std::io::stdout().lock();
        let _ = stdout.write_all(screen.as_bytes());
        let _ = stdout.flush();
    }

    fn finish(mut self) -> Result<SubscriberSummary, SubscribeError> {
        if let Some((path, csv)) = &mut self.csv {
            csv.flush().map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
        }
        let mut summary = self.summary;
        summary.accuracy = self.accuracy.as_mut().map(AccuracyMonitor::summary);
        let row = |latency: SubscriberLatency| {
            let histogram = &self.latencies[latency as usize];
            (!histogram.is_empty()).then(|| LatencyRow {
                name: latency.name().to_owned(),
                ..LatencyRow::from(&summarise(latency.name(), histogram))
            })
        };
        summary.delivery_latency = row(SubscriberLatency::TrackerToSubscriber);
        summary.end_to_end_latency = row(SubscriberLatency::PublisherToSubscriber);
        summary.end_to_end_corrected_latency = row(SubscriberLatency::PublisherToSubscriberCorrected);
        if let Some(files) = self.files.take() {
            let latencies = &self.latencies;
            summary.latency_files = files.finish(monotonic_ns(), |index| &latencies[index])?;
        }
        if let Some(report) = &self.last_report {
            summary.tracker_latency = report.valid_stages().iter().map(LatencyRow::from).collect();
            summary.tracker_frames_received = report.frames_received;
            summary.tracker_frames_rejected = report.frames_rejected;
            summary.tracker_measurements_rejected = report.measurements_rejected;
        }
        Ok(summary)
    }
}

/// The latencies the subscriber measures, in the order of its histograms and files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SubscriberLatency {
    PublisherToSubscriber = 0,
    PublisherToSubscriberCorrected = 1,
    TrackerToSubscriber = 2,
}

impl SubscriberLatency {
    const COUNT: usize = 3;
    const ALL: [SubscriberLatency; Self::COUNT] =
        [Self::PublisherToSubscriber, Self::PublisherToSubscriberCorrected, Self::TrackerToSubscriber];

    fn name(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher_to_subscriber",
            Self::PublisherToSubscriberCorrected => "publisher_to_subscriber_corrected",
            Self::TrackerToSubscriber => "tracker_to_subscriber",
        }
    }

    fn description(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher send of the measurement frame to subscriber receive of its answer",
            Self::PublisherToSubscriberCorrected => {
                "corrected for coordinated omission: publisher's scheduled send time of the measurement frame to subscriber receive of its answer"
            }
            Self::TrackerToSubscriber => "tracker send of the track frame to subscriber receive",
        }
    }
}

fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, MAX_TRACKABLE_NS, 3).expect("valid histogram bounds")
}

/// Runs the subscriber until a stop condition or SIGINT/SIGTERM; prints the summary.
pub fn run(args: Args) -> Result<(), SubscribeError> {
    let summary = subscribe(&args)?;
    print!("{}", summary.text());
    if !summary.latency_files.is_empty() {
        println!("latency files:");
        for file in &summary.latency_files {
            println!("  {}", file.display());
        }
    }
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&summary).expect("the summary serialises");
        std::fs::write(path, json).map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    }
    Ok(())
}

/// Receives until a stop condition; returns what was seen.
pub fn subscribe(args: &Args) -> Result<SubscriberSummary, SubscribeError> {
    let shutdown = ShutdownFlag::on_signals().map_err(SubscribeError::Signals)?;
    let names = ServiceNames::new(&args.service_prefix);
    let node = catalog::create_node("primm-subscriber")?;
    let ports = Ports::open(&node, &names, !args.no_truth)?;
    tracing::info!(service = %names.tracks(), "subscribed");
    let mut viewer = Viewer::new(args, ports.truth.is_some(), open_csv(args)?);
    if let Some(directory) = &args.latency_out {
        let stages: Vec<StageDescription> = SubscriberLatency::ALL
            .iter()
            .map(|latency| StageDescription::new(latency.name(), latency.description()))
            .collect();
        viewer.files = Some(LatencyFiles::create(
            directory,
            "subscriber",
            &stages,
            &histogram(),
            Duration::from_secs_f64(args.latency_interval_s),
            monotonic_ns(),
        )?);
    }
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Ipc>()
        .map_err(SubscribeError::WaitSetCreate)?;
    let mut guards = Vec::new();
    let mut tick = None;
    if !args.busy_poll {
        guards = ports.attach(&waitset)?;
        // For the view and time-outs.
        tick =
            Some(waitset.attach_interval(Duration::from_millis(200)).map_err(SubscribeError::WaitSetAttach)?);
    }
    let idle_timeout = args.idle_timeout_s.map(Duration::from_secs_f64);
    let realtime = args.realtime.settings();
    let mut report = RealtimeReport::default();
    realtime.apply_to_current_thread("receiving thread", &mut report);
    realtime.lock_memory_now(&mut report);
    report.finish(realtime.require_realtime)?;
    loop {
        if args.busy_poll {
            std::hint::spin_loop();
        } else {
            ports.wait(&waitset)?;
        }
        let done = ports.receive(&mut viewer, args)?;
        viewer.report_progress(args);
        if done
            || shutdown.is_requested()
            || idle_timeout.is_some_and(|timeout| viewer.last_frame_at.elapsed() >= timeout)
        {
            break;
        }
    }
    ports.take_late_latency_report(&mut viewer)?;
    drop(tick);
    drop(guards);
    viewer.finish()
}

/// The track CSV file of `--csv` and its writer.
type CsvOutput = (PathBuf, TrackCsvWriter<std::io::BufWriter<std::fs::File>>);

/// Creates the track CSV file of `--csv`, header written.
fn open_csv(args: &Args) -> Result<Option<CsvOutput>, SubscribeError> {
    let Some(path) = &args.csv else { return Ok(None) };
    let file = std::fs::File::create(path)
        .map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    let writer = TrackCsvWriter::new(std::io::BufWriter::new(file))
        .map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    Ok(Some((path.clone(), writer)))
}

/// The subscriber's ports: tracks, latency reports and (for the accuracy view) measurements.
struct Ports {
    tracks: Subscriber<Ipc, TrackFrame, ()>,
    track_listener: Listener<Ipc>,
    latency: Subscriber<Ipc, LatencyReport, ()>,
    latency_listener: Listener<Ipc>,
    truth: Option<(Subscriber<Ipc, MeasurementFrame, ()>, Listener<Ipc>)>,
}

impl Ports {
    /// Opens the streams and their ports; the measurements' only when `truth`.
    fn open(node: &Node<Ipc>, names: &ServiceNames, truth: bool) -> Result<Self, SubscribeError> {
        let tracks = catalog::tracks(node, names)?;
        let latency = catalog::latency(node, names)?;
        let track_subscriber = tracks.subscriber()?;
        let track_listener = tracks.listener()?;
        let latency_subscriber = latency.subscriber()?;
        let latency_listener = latency.listener()?;
        let truth = if truth {
            let measurements = catalog::measurements(node, names)?;
            Some((measurements.subscriber()?, measurements.listener()?))
        } else {
            None
        };
        Ok(Self {
            tracks: track_subscriber,
            track_listener,
            latency: latency_subscriber,
            latency_listener,
            truth,
        })
    }

    /// Attaches every listener to `waitset`.
    fn attach<'w, 'a>(
        &'a self,
        waitset: &'w WaitSet<Ipc>,
    ) -> Result<Vec<WaitSetGuard<'w, 'a, Ipc>>, SubscribeError> {
        let mut guards = Vec::new();
        guards
            .push(waitset.attach_notification(&self.track_listener).map_err(SubscribeError::WaitSetAttach)?);
        guards.push(
            waitset.attach_notification(&self.latency_listener).map_err(SubscribeError::WaitSetAttach)?,
        );
        if let Some((_, listener)) = &self.truth {
            guards.push(waitset.attach_notification(listener).map_err(SubscribeError::WaitSetAttach)?);
        }
        Ok(guards)
    }

    /// Sleeps in `waitset` until a notification or the tick, then consumes the notifications
    /// (the data is read by [`receive`](Self::receive)).
    fn wait(&self, waitset: &WaitSet<Ipc>) -> Result<(), SubscribeError> {
        waitset
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, Duration::from_millis(200))
            .map_err(SubscribeError::WaitSetRun)?;
        let _ = self.track_listener.try_wait(|_| {});
        let _ = self.latency_listener.try_wait(|_| {});
        if let Some((_, listener)) = &self.truth {
            let _ = listener.try_wait(|_| {});
        }
        Ok(())
    }

    /// Hands every waiting sample to `viewer`: measurements first (a track frame's measurement
    /// frame was sent before it), then track frames, then latency reports. Returns whether the
    /// subscriber is done (`--frames` reached, or the end of the stream with `--until-end`).
    fn receive(&self, viewer: &mut Viewer, args: &Args) -> Result<bool, SubscribeError> {
        if let (Some((subscriber, _)), Some(accuracy)) = (&self.truth, viewer.accuracy.as_mut()) {
            while let Some(sample) = subscriber.receive().map_err(SubscribeError::Receive)? {
                accuracy.add_measurements(&sample);
            }
        }
        let mut done = false;
        while let Some(sample) = self.tracks.receive().map_err(SubscribeError::Receive)? {
            viewer.on_tracks(&sample)?;
            if args.frames.is_some_and(|limit| viewer.summary.track_frames >= limit)
                || (args.until_end && sample.flags & TRACK_FLAG_STREAM_END != 0)
            {
                done = true;
                break;
            }
        }
        while let Some(sample) = self.latency.receive().map_err(SubscribeError::Receive)? {
            viewer.last_report = Some(*sample);
        }
        Ok(done)
    }

    /// The tracker may send its latency report right after the last frame: takes it if it comes
    /// within 100 ms.
    fn take_late_latency_report(&self, viewer: &mut Viewer) -> Result<(), SubscribeError> {
        let deadline = Instant::now() + Duration::from_millis(100);
        while Instant::now() < deadline {
            match self.latency.receive().map_err(SubscribeError::Receive)? {
                Some(sample) => viewer.last_report = Some(*sample),
                None => std::thread::sleep(Duration::from_millis(5)),
            }
        }
        Ok(())
    }
}
