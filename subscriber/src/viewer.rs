//! The state of one subscriber run: what it does with each track frame (counters, latencies,
//! accuracy, CSV rows, the live view) and the summary it makes of them at the end.

use crate::accuracy::AccuracyMonitor;
use crate::summary::{LatencyRow, SubscriberSummary};
use crate::track_csv::write_track_frame;
use crate::{Args, SubscribeError};
use hdrhistogram::Histogram;
use primm_core::measurement::ObjectClass;
use primm_ipc::clock::monotonic_ns;
use primm_ipc::latency::{format_table, summarise, MAX_TRACKABLE_NS};
use primm_ipc::latency_files::LatencyFiles;
use primm_sim::io::track_csv::TrackCsvWriter;
use primm_wire::{
    FrameStatus, LatencyReport, TrackFrame, WireTrack, TRACK_FLAG_STREAM_END, TRACK_FLAG_TRACKER_RESET,
};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// State of one subscriber run.
#[derive(Debug)]
pub(crate) struct Viewer {
    pub(crate) summary: SubscriberSummary,
    pub(crate) accuracy: Option<AccuracyMonitor>,
    csv: Option<CsvOutput>,
    /// Indexed by [`SubscriberLatency`].
    latencies: [Histogram<u64>; SubscriberLatency::COUNT],
    pub(crate) files: Option<LatencyFiles>,
    last_sequence: Option<u64>,
    pub(crate) last_report: Option<LatencyReport>,
    live: bool,
    last_draw: Instant,
    pub(crate) last_frame_at: Instant,
}

impl Viewer {
    pub(crate) fn new(args: &Args, truth: bool, csv: Option<CsvOutput>) -> Self {
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
    pub(crate) fn report_progress(&mut self, args: &Args) {
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

    pub(crate) fn on_tracks(&mut self, frame: &TrackFrame) -> Result<(), SubscribeError> {
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

    pub(crate) fn finish(mut self) -> Result<SubscriberSummary, SubscribeError> {
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
pub(crate) enum SubscriberLatency {
    PublisherToSubscriber = 0,
    PublisherToSubscriberCorrected = 1,
    TrackerToSubscriber = 2,
}

impl SubscriberLatency {
    const COUNT: usize = 3;
    pub(crate) const ALL: [SubscriberLatency; Self::COUNT] =
        [Self::PublisherToSubscriber, Self::PublisherToSubscriberCorrected, Self::TrackerToSubscriber];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher_to_subscriber",
            Self::PublisherToSubscriberCorrected => "publisher_to_subscriber_corrected",
            Self::TrackerToSubscriber => "tracker_to_subscriber",
        }
    }

    pub(crate) fn description(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher send of the measurement frame to subscriber receive of its answer",
            Self::PublisherToSubscriberCorrected => {
                "corrected for coordinated omission: publisher's scheduled send time of the measurement frame to subscriber receive of its answer"
            }
            Self::TrackerToSubscriber => "tracker send of the track frame to subscriber receive",
        }
    }
}

pub(crate) fn histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, MAX_TRACKABLE_NS, 3).expect("valid histogram bounds")
}

/// The track CSV file of `--csv` and its writer.
pub(crate) type CsvOutput = (PathBuf, TrackCsvWriter<std::io::BufWriter<std::fs::File>>);

/// Creates the track CSV file of `--csv`, header written.
pub(crate) fn open_csv(args: &Args) -> Result<Option<CsvOutput>, SubscribeError> {
    let Some(path) = &args.csv else { return Ok(None) };
    let file = std::fs::File::create(path)
        .map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    let writer = TrackCsvWriter::new(std::io::BufWriter::new(file))
        .map_err(|source| SubscribeError::Output { path: path.clone(), source })?;
    Ok(Some((path.clone(), writer)))
}
