//! The tracking loop: take a measurement sample, track it in place, write the tracks straight
//! into a loaned track sample, send, notify; record latencies; report them every few frames.
//!
//! primm's code on this path allocates nothing per frame (`tests/service_allocation.rs` counts
//! it). What remains: iceoryx2 0.10's `Publisher::loan_uninit` allocates one 48-byte
//! reference-counted handle per loaned sample (every loan path of 0.10 does; see
//! `docs/service.md`), and, off the normal path, a logged warning (bounded by [`LogLimiter`])
//! and the setup of a connection when a port joins.
//!
//! The loop waits on the measurement stream's iceoryx2 listener (event-driven, the default) or
//! spins on the subscriber ([`WaitMode::BusyPoll`]). It does not use a `WaitSet` because
//! iceoryx2 0.10's `WaitSet` collects the ready attachments into a fresh `Vec` on every
//! wake-up; with a single source the listener's own timed wait does the same job without it.
//!
//! Rejected frames are answered, not dropped: the service publishes a [`TrackFrame`] with no
//! tracks and a [`FrameStatus`] naming the reason, so a subscriber can tell a rejected frame from
//! a lost one and every input sequence number gets exactly one answer.

use super::catalog::{self, ConnectError, Ipc, ServiceNames};
use super::clock::monotonic_ns;
use super::frame_step::{starts_stream, step_received_frame};
use super::latency::{LatencyHistograms, StageTimer};
use super::latency_files::{LatencyFiles, LatencyFilesError, StageDescription};
use super::log_limit::LogLimiter;
use super::shutdown::ShutdownFlag;
use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::ConnectionFailure;
use iceoryx2::port::ReceiveError;
use iceoryx2::sample::Sample;
use iceoryx2::sample_mut::SampleMut;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use primm_core::predictor::DisplacementPredictor;
use primm_core::stage_timing::Stage;
use primm_core::track::TrackOutput;
use primm_core::tracker::{StepError, StepSummary, Tracker};
use primm_wire::{
    FrameStatus, LatencyReport, MeasurementFrame, StageLatency, TrackFrame, TrackFrameHeader,
    TrackFrameWriter, FRAME_FLAG_STREAM_END, STAGE_CAPACITY, TRACK_FLAG_LATE_FRAME, TRACK_FLAG_PREDICTED,
    TRACK_FLAG_SEQUENCE_GAP, TRACK_FLAG_STREAM_END, TRACK_FLAG_TRACKER_RESET,
};
use std::mem::MaybeUninit;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How the tracking loop waits for measurement frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WaitMode {
    /// Sleep on the measurement stream's event service until a publisher notifies (default;
    /// costs a wake-up, ~10-30 µs, but no CPU while idle).
    #[default]
    Event,
    /// Spin on the subscriber: lowest latency, one core busy all the time.
    BusyPoll,
}

/// The time the published tracks describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PublishTime {
    /// The newest tracked frame's time (the input frame's, unless it was late): the tracks as
    /// the step left them, written straight into the loaned sample (default).
    #[default]
    Frame,
    /// The publish time: the tracks predicted from the newest frame over the time since the
    /// input frame was published ([`Tracker::predict_to`]), so that a consumer receives them at
    /// the time they describe. Costs one prediction per track and a copy, after the step; the
    /// learned mode sits the prediction out. The publish time on the sensor clock is taken as
    /// the input frame's sensor time plus the time since its publisher sent it (monotonic
    /// clock of this host), clamped to `[0, tracker.max_frame_interval_s]` ahead of the newest
    /// frame.
    Now,
}

/// Settings of the tracking loop.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrackingOptions {
    /// Service-name prefix.
    pub names: ServiceNames,
    /// How to wait for input.
    pub wait: WaitMode,
    /// A latency report is published after every this many received frames (0: never, only at
    /// shutdown).
    pub latency_report_interval_frames: u64,
    /// Longest single wait, after which the loop checks for shutdown.
    pub poll_timeout: Duration,
    /// The time the published tracks describe.
    pub publish_time: PublishTime,
    /// After each answer, hand the predictor the next frame's requests ([`Tracker::speculate`]).
    pub speculate: bool,
}

impl Default for TrackingOptions {
    fn default() -> Self {
        Self {
            names: ServiceNames::new(""),
            wait: WaitMode::Event,
            latency_report_interval_frames: 100,
            poll_timeout: Duration::from_millis(50),
            publish_time: PublishTime::Frame,
            speculate: true,
        }
    }
}

/// Counters of the service (the tracker keeps its own, [`Tracker::stats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ServiceCounters {
    /// Measurement frames taken from the input buffer.
    pub frames_received: u64,
    /// Frames tracked.
    pub frames_tracked: u64,
    /// Frames rejected (answered with a rejection status).
    pub frames_rejected: u64,
    /// Input sequence numbers skipped: frames a publisher sent that this tracker never took
    /// (dropped from its full input buffer, or sent before it subscribed).
    pub frames_lost: u64,
    /// Resets because a frame started a new stream.
    pub resets_stream_start: u64,
    /// Resets because frames came from a new publisher.
    pub resets_new_publisher: u64,
    /// Resets because the interval since the previous frame was too long (the frame was then
    /// tracked as the first of a new stream).
    pub resets_interval_too_long: u64,
    /// Track frames that could not be loaned or sent.
    pub publish_failures: u64,
    /// Latency reports that could not be loaned or sent.
    pub latency_report_failures: u64,
    /// Latency reports sent.
    pub latency_reports: u64,
    /// Failures to write the latency files (after the first, no more intervals are written).
    pub latency_file_failures: u64,
}

impl ServiceCounters {
    /// All resets.
    pub fn resets(&self) -> u64 {
        self.resets_stream_start + self.resets_new_publisher + self.resets_interval_too_long
    }
}

/// Why the tracking loop stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum TrackingLoopError {
    /// Receiving from the measurement stream failed.
    #[error("cannot receive measurement frames: {0}")]
    Receive(ReceiveError),
    /// Checking the measurement stream for samples failed (busy-poll mode).
    #[error("cannot poll the measurement stream: {0}")]
    Poll(ConnectionFailure),
    /// Waiting on the measurement stream's event service failed.
    #[error("cannot wait for measurement frames: {0}")]
    Wait(ListenerWaitError),
}

/// Which rejections and failures have been logged how often.
#[derive(Debug, Default)]
struct LogLimits {
    rejected: LogLimiter,
    lost: LogLimiter,
    publish: LogLimiter,
    latency: LogLimiter,
    notify: LogLimiter,
    /// Frames in which learned displacements were rejected (NaN, infinite, implausible or with
    /// an invalid covariance).
    learned_rejected: LogLimiter,
}

/// Where the current input stream stands.
#[derive(Debug, Default)]
struct StreamState {
    origin: Option<UniquePublisherId>,
    last_sequence: Option<u64>,
    /// Whether the tracker has tracked a frame since it was built or last reset.
    tracker_dirty: bool,
}

/// The tracker behind its iceoryx2 ports.
#[derive(Debug)]
pub struct TrackingService<P: DisplacementPredictor> {
    input: Subscriber<Ipc, MeasurementFrame, ()>,
    input_listener: Option<Listener<Ipc>>,
    output: Publisher<Ipc, TrackFrame, ()>,
    output_notifier: Notifier<Ipc>,
    latency_output: Publisher<Ipc, LatencyReport, ()>,
    latency_notifier: Notifier<Ipc>,
    tracker: Tracker<P>,
    histograms: LatencyHistograms,
    /// Room for every track predicted to the publish time ([`PublishTime::Now`]), allocated
    /// once.
    predicted: Box<[TrackOutput]>,
    latency_files: Option<LatencyFiles>,
    counters: ServiceCounters,
    stream: StreamState,
    logs: LogLimits,
    options: TrackingOptions,
    node: Node<Ipc>,
}

impl<P: DisplacementPredictor> TrackingService<P> {
    /// Opens the three streams (creating them if needed) and their ports.
    pub fn new(tracker: Tracker<P>, options: TrackingOptions) -> Result<Self, ConnectError> {
        let node = catalog::create_node("primm-serve")?;
        let measurements = catalog::measurements(&node, &options.names)?;
        let tracks = catalog::tracks(&node, &options.names)?;
        let latency = catalog::latency(&node, &options.names)?;
        let input = measurements.subscriber()?;
        let input_listener = match options.wait {
            WaitMode::Event => Some(measurements.listener()?),
            WaitMode::BusyPoll => None,
        };
        Ok(Self {
            input,
            input_listener,
            output: tracks.publisher()?,
            output_notifier: tracks.notifier()?,
            latency_output: latency.publisher()?,
            latency_notifier: latency.notifier()?,
            tracker,
            histograms: LatencyHistograms::new(),
            predicted: vec![TrackOutput::default(); primm_core::track_table::MAX_TRACKS].into_boxed_slice(),
            latency_files: None,
            counters: ServiceCounters::default(),
            stream: StreamState::default(),
            logs: LogLimits::default(),
            options,
            node,
        })
    }

    /// Runs until `shutdown` is raised, then tracks the frames already in the input buffer (at
    /// most its 64, so that every frame delivered is either tracked or counted as lost) and
    /// publishes a last latency report.
    pub fn run(&mut self, shutdown: &ShutdownFlag) -> Result<(), TrackingLoopError> {
        while !shutdown.is_requested() {
            self.poll(self.options.poll_timeout)?;
        }
        self.drain()?;
        self.publish_latency_report();
        Ok(())
    }

    /// Waits up to `timeout` for input, then tracks every frame in the buffer. Returns the
    /// number of frames processed.
    pub fn poll(&mut self, timeout: Duration) -> Result<usize, TrackingLoopError> {
        match &self.input_listener {
            Some(listener) => match listener.timed_wait(|_| {}, timeout) {
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(error) => return Err(TrackingLoopError::Wait(error)),
            },
            None => {
                let deadline = Instant::now() + timeout;
                while !self.input.has_samples().map_err(TrackingLoopError::Poll)? && Instant::now() < deadline
                {
                    std::hint::spin_loop();
                }
            }
        }
        self.drain()
    }

    /// Tracks every frame in the input buffer without waiting.
    pub fn drain(&mut self) -> Result<usize, TrackingLoopError> {
        let mut processed = 0;
        while let Some(sample) = self.input.receive().map_err(TrackingLoopError::Receive)? {
            self.process(sample);
            processed += 1;
        }
        Ok(processed)
    }

    /// Tracks one frame and publishes the answer.
    fn process(&mut self, sample: Sample<Ipc, MeasurementFrame, ()>) {
        let receive_ns = monotonic_ns();
        self.counters.frames_received += 1;
        let origin = sample.header().publisher_id();
        let frame: &MeasurementFrame = &sample;
        let mut flags = self.follow_stream(origin, frame);

        let mut loan = self.loan_track_sample();
        let mut writer = loan.as_mut().map(|loan| TrackFrameWriter::new(loan.payload_mut()));
        let result = self.track(frame, receive_ns, &mut writer, &mut flags);
        let (status, step) = self.count_outcome(frame, &result);
        if frame.flags & FRAME_FLAG_STREAM_END != 0 {
            flags |= TRACK_FLAG_STREAM_END;
        }
        if step.late() {
            flags |= TRACK_FLAG_LATE_FRAME;
        }
        let mut tracks_timestamp_s = self.tracker.newest_timestamp_s().unwrap_or(frame.sensor_timestamp_s);
        if result.is_ok() && self.options.publish_time == PublishTime::Now {
            if let Some(predicted_s) = self.write_predicted(frame, tracks_timestamp_s, &mut writer) {
                tracks_timestamp_s = predicted_s;
                flags |= TRACK_FLAG_PREDICTED;
            }
        }
        let mut header = track_frame_header(frame, receive_ns, status, flags, &step);
        header.tracks_timestamp_s = tracks_timestamp_s;
        // The input sample goes back to its publisher before the answer is sent.
        drop(sample);

        let publish_start = monotonic_ns();
        header.publish_time_ns = publish_start;
        let written = writer.map(|writer| writer.finish(&header));
        if let (Some(loan), Some(_)) = (loan, written) {
            // SAFETY: the writer initialised the header and the first `count` tracks; the
            // remaining slots hold bytes left in the shared-memory chunk by earlier samples (or
            // the zeroes the OS mapped), and every field of `WireTrack` is a plain integer or
            // float for which any bit pattern is a valid value.
            self.send_track_frame(unsafe { loan.assume_init() });
            self.record_publish_latencies(
                receive_ns,
                publish_start,
                header.input_publish_time_ns,
                header.input_scheduled_time_ns,
            );
        }
        if self.options.speculate {
            self.tracker.speculate();
        }
        self.write_latency_interval();

        let interval = self.options.latency_report_interval_frames;
        if interval > 0 && self.counters.frames_received.is_multiple_of(interval) {
            self.publish_latency_report();
        }
    }

    /// Loans the sample of the answer; `None` (counted and logged) when none is available: the
    /// frame is then tracked but not answered.
    fn loan_track_sample(&mut self) -> Option<SampleMutUninit<Ipc, MaybeUninit<TrackFrame>, ()>> {
        match self.output.loan_uninit() {
            Ok(loan) => Some(loan),
            Err(error) => {
                self.counters.publish_failures += 1;
                if self.logs.publish.occur() {
                    tracing::warn!(%error, occurrences = self.logs.publish.occurrences(), "cannot loan a track sample; frame tracked but not published");
                }
                None
            }
        }
    }

    /// With [`PublishTime::Now`]: writes the tracks predicted from the newest frame
    /// (`newest_s`) to the publish time; returns that time, or `None` (nothing written) when
    /// the prediction was refused.
    fn write_predicted(
        &mut self,
        frame: &MeasurementFrame,
        newest_s: f64,
        writer: &mut Option<TrackFrameWriter<'_>>,
    ) -> Option<f64> {
        let since_publish_s = monotonic_ns().saturating_sub(frame.publish_time_ns) as f64 * 1e-9;
        let max_ahead_s = self.tracker.config().tracker.max_frame_interval_s;
        let ahead_s = (frame.sensor_timestamp_s + since_publish_s - newest_s).clamp(0.0, max_ahead_s);
        let predicted_s = newest_s + ahead_s;
        let count = self.tracker.predict_to(predicted_s, &mut self.predicted[..]).ok()?;
        if let Some(writer) = writer.as_mut() {
            writer.clear();
            self.predicted[..count].iter().for_each(|output| writer.push(output));
        }
        Some(predicted_s)
    }

    /// Tracks `frame`, its tracks written by `writer` (unless they are published predicted) and
    /// its stages timed from `receive_ns`. A frame after too long a gap is tracked again after a
    /// reset, which `flags` then records.
    fn track(
        &mut self,
        frame: &MeasurementFrame,
        receive_ns: u64,
        writer: &mut Option<TrackFrameWriter<'_>>,
        flags: &mut u8,
    ) -> Result<StepSummary, StepError> {
        let mut timer = StageTimer::new(&mut self.histograms, receive_ns);
        let mut no_writer = None;
        let writer = if self.options.publish_time == PublishTime::Now { &mut no_writer } else { writer };
        let stepped = step_received_frame(&mut self.tracker, frame, &mut timer, writer);
        if stepped.reset_for_interval {
            self.counters.resets_interval_too_long += 1;
            *flags |= TRACK_FLAG_TRACKER_RESET;
        }
        stepped.result
    }

    /// Counts (and logs, for a rejected frame) the outcome of tracking `frame`; returns the
    /// answer's status and the step's summary.
    fn count_outcome(
        &mut self,
        frame: &MeasurementFrame,
        result: &Result<StepSummary, StepError>,
    ) -> (FrameStatus, StepSummary) {
        match result {
            Ok(step) => {
                self.counters.frames_tracked += 1;
                self.stream.tracker_dirty = true;
                let rejected = step.learned_predictions_rejected();
                if rejected > 0 && self.logs.learned_rejected.occur() {
                    tracing::warn!(
                        sequence = frame.sequence,
                        non_finite = step.counts.learned_predictions_rejected_non_finite,
                        implausible = step.counts.learned_predictions_rejected_implausible,
                        invalid_covariance = step.counts.learned_predictions_rejected_invalid_covariance,
                        occurrences = self.logs.learned_rejected.occurrences(),
                        "learned displacements rejected; the PR mode sat out for those tracks"
                    );
                }
                (FrameStatus::Tracked, *step)
            }
            Err(error) => {
                self.counters.frames_rejected += 1;
                if self.logs.rejected.occur() {
                    tracing::warn!(
                        sequence = frame.sequence,
                        %error,
                        occurrences = self.logs.rejected.occurrences(),
                        "measurement frame rejected"
                    );
                }
                // What the failed step counted before it failed.
                (FrameStatus::of_error(error), *self.tracker.last_step())
            }
        }
    }

    /// Sends the answer and notifies its listeners; counts and logs failures.
    fn send_track_frame(&mut self, sample: SampleMut<Ipc, TrackFrame, ()>) {
        match sample.send() {
            Ok(_) => {
                if let Err(error) = self.output_notifier.notify() {
                    if self.logs.notify.occur() {
                        tracing::warn!(%error, "cannot notify track listeners");
                    }
                }
            }
            Err(error) => {
                self.counters.publish_failures += 1;
                if self.logs.publish.occur() {
                    tracing::warn!(%error, occurrences = self.logs.publish.occurrences(), "cannot send a track frame");
                }
            }
        }
    }

    /// Records the host's stages of an answer sent now: [`Stage::Publish`] from `publish_start`,
    /// [`Stage::ReceiveToPublish`] from `receive_ns`, and [`Stage::EndToEnd`] from the input's
    /// publish time to `publish_start` (when the publisher stamped one that is not later), and
    /// [`Stage::EndToEndCorrected`] from the input's scheduled send time (its publish time when
    /// it was sent without a schedule).
    fn record_publish_latencies(
        &mut self,
        receive_ns: u64,
        publish_start: u64,
        input_publish_time_ns: u64,
        input_scheduled_time_ns: u64,
    ) {
        let done_ns = monotonic_ns();
        self.histograms.record(Stage::Publish, done_ns.saturating_sub(publish_start));
        self.histograms.record(Stage::ReceiveToPublish, done_ns.saturating_sub(receive_ns));
        if input_publish_time_ns != 0 && input_publish_time_ns <= publish_start {
            self.histograms.record(Stage::EndToEnd, publish_start - input_publish_time_ns);
            let due_ns =
                if input_scheduled_time_ns != 0 { input_scheduled_time_ns } else { input_publish_time_ns };
            if due_ns <= publish_start {
                self.histograms.record(Stage::EndToEndCorrected, publish_start - due_ns);
            }
        }
    }

    /// Writes every stage's histogram into interval logs and, at
    /// [`finish_latency_files`](Self::finish_latency_files), percentile distributions and a
    /// plot, in `directory` (see [`latency_files`](super::latency_files)); an interval ends
    /// every `interval`. The files are written on the tracking thread after a frame's answer
    /// has been sent, once per interval.
    pub fn write_latency_files(
        &mut self,
        directory: &Path,
        interval: Duration,
    ) -> Result<(), LatencyFilesError> {
        let stages: Vec<StageDescription> =
            Stage::ALL.iter().map(|stage| StageDescription::new(stage.name(), stage.description())).collect();
        let files = LatencyFiles::create(
            directory,
            "tracker",
            &stages,
            self.histograms.histogram(Stage::Validate),
            interval,
            monotonic_ns(),
        )?;
        self.latency_files = Some(files);
        Ok(())
    }

    /// Appends an interval to the latency files if one has ended; a failure is counted and
    /// logged, and the files are given up.
    fn write_latency_interval(&mut self) {
        let Some(files) = &mut self.latency_files else { return };
        let now_ns = monotonic_ns();
        if !files.due(now_ns) {
            return;
        }
        let histograms = &self.histograms;
        if let Err(error) = files.write_due(now_ns, |index| histograms.histogram(Stage::ALL[index])) {
            self.counters.latency_file_failures += 1;
            tracing::warn!(%error, "cannot write the latency files; no more intervals are written");
            self.latency_files = None;
        }
    }

    /// Writes the last interval, the percentile distributions and the plot of the latency files
    /// (if [`write_latency_files`](Self::write_latency_files) was called); returns the files.
    pub fn finish_latency_files(&mut self) -> Result<Vec<PathBuf>, LatencyFilesError> {
        let Some(files) = self.latency_files.take() else { return Ok(Vec::new()) };
        let histograms = &self.histograms;
        files.finish(monotonic_ns(), |index| histograms.histogram(Stage::ALL[index]))
    }

    /// Resets the tracker when a new stream or publisher starts; counts sequence gaps. Returns
    /// the track-frame flags this implies.
    ///
    /// A publisher numbers its frames from 0 without a break, across the streams it sends, and
    /// a frame it could not send takes no number; so every number missing before the frame in
    /// hand (since the previous frame of the same publisher, or since 0 for its first frame
    /// here) is a frame sent but never taken by this tracker: dropped from the full input
    /// buffer, or sent before this tracker subscribed.
    fn follow_stream(&mut self, origin: UniquePublisherId, frame: &MeasurementFrame) -> u8 {
        let mut flags = 0;
        let first_from_publisher = self.stream.origin != Some(origin);
        let new_publisher = self.stream.origin.is_some() && first_from_publisher;
        let stream_start = starts_stream(frame);
        if (stream_start || new_publisher) && self.stream.tracker_dirty {
            self.tracker.reset();
            self.stream.tracker_dirty = false;
            flags |= TRACK_FLAG_TRACKER_RESET;
            if new_publisher {
                self.counters.resets_new_publisher += 1;
                tracing::info!(sequence = frame.sequence, "frames from a new publisher: tracker reset");
            } else {
                self.counters.resets_stream_start += 1;
                tracing::info!(sequence = frame.sequence, "new stream: tracker reset");
            }
        }
        if first_from_publisher {
            self.stream.last_sequence = None;
        }
        self.stream.origin = Some(origin);
        let expected = self.stream.last_sequence.map_or(0, |last| last.saturating_add(1));
        if frame.sequence > expected {
            let lost = frame.sequence - expected;
            self.counters.frames_lost += lost;
            flags |= TRACK_FLAG_SEQUENCE_GAP;
            if self.logs.lost.occur() {
                tracing::warn!(
                    lost,
                    expected,
                    received = frame.sequence,
                    occurrences = self.logs.lost.occurrences(),
                    "measurement frames lost"
                );
            }
        }
        self.stream.last_sequence = Some(frame.sequence);
        flags
    }

    /// Sends a latency report (cumulative since start) and notifies its listeners.
    pub fn publish_latency_report(&mut self) {
        let loan = match self.latency_output.loan_uninit() {
            Ok(loan) => loan,
            Err(error) => {
                self.counters.latency_report_failures += 1;
                if self.logs.latency.occur() {
                    tracing::warn!(%error, "cannot loan a latency report");
                }
                return;
            }
        };
        let report = self.latency_report();
        match loan.write_payload(report).send() {
            Ok(_) => {
                self.counters.latency_reports += 1;
                let _ = self.latency_notifier.notify();
            }
            Err(error) => {
                self.counters.latency_report_failures += 1;
                if self.logs.latency.occur() {
                    tracing::warn!(%error, "cannot send a latency report");
                }
            }
        }
    }

    /// The current latency report.
    pub fn latency_report(&self) -> LatencyReport {
        let stats = self.tracker.stats();
        let mut report = LatencyReport {
            sequence: self.counters.latency_reports,
            publish_time_ns: monotonic_ns(),
            frames_received: self.counters.frames_received,
            frames_tracked: self.counters.frames_tracked,
            frames_rejected: self.counters.frames_rejected,
            frames_lost: self.counters.frames_lost,
            measurements_rejected: stats.measurements_rejected_unknown_class
                + stats.measurements_rejected_non_finite
                + stats.measurements_rejected_out_of_range,
            resets: self.counters.resets(),
            stage_count: 0,
            _pad0: [0; 4],
            stages: [StageLatency::named(""); STAGE_CAPACITY],
        };
        self.histograms.fill_report(&mut report);
        report
    }

    /// The service's counters.
    pub fn counters(&self) -> &ServiceCounters {
        &self.counters
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker<P> {
        &self.tracker
    }

    /// The latency histograms.
    pub fn histograms(&self) -> &LatencyHistograms {
        &self.histograms
    }

    /// The options.
    pub fn options(&self) -> &TrackingOptions {
        &self.options
    }

    /// The iceoryx2 node.
    pub fn node(&self) -> &Node<Ipc> {
        &self.node
    }

    /// A plain-text summary for the end of a run: the service's counters, the tracker's
    /// counters by their names (those not zero; the list is primm-core's `tracker_counters!`)
    /// and the latency table.
    pub fn summary(&self) -> String {
        let c = &self.counters;
        format!(
            "frames: {} received, {} tracked, {} rejected, {} lost; resets: {} (stream start {}, new publisher {}, interval too long {}); \
             publish failures: {}\n{}\n{}",
            c.frames_received,
            c.frames_tracked,
            c.frames_rejected,
            c.frames_lost,
            c.resets(),
            c.resets_stream_start,
            c.resets_new_publisher,
            c.resets_interval_too_long,
            c.publish_failures,
            crate::summary_lines::tracker_counters_line(self.tracker.stats()),
            self.histograms.table()
        ) + &self.tracker.predictor().report().map(|line| format!("\n{line}")).unwrap_or_default()
            + &crate::summary_lines::sensor_lines(&self.tracker)
    }
}

/// The header of the answer to `frame` (its publish time is stamped when it is sent).
fn track_frame_header(
    frame: &MeasurementFrame,
    receive_ns: u64,
    status: FrameStatus,
    flags: u8,
    step: &StepSummary,
) -> TrackFrameHeader {
    let saturating_u16 = |count: u64| u16::try_from(count).unwrap_or(u16::MAX);
    TrackFrameHeader {
        input_sequence: frame.sequence,
        source_frame: frame.source_frame,
        sensor_timestamp_s: frame.sensor_timestamp_s,
        tracks_timestamp_s: frame.sensor_timestamp_s,
        input_publish_time_ns: frame.publish_time_ns,
        input_scheduled_time_ns: frame.scheduled_time_ns,
        receive_time_ns: receive_ns,
        publish_time_ns: 0,
        status,
        flags,
        measurements_accepted: saturating_u16(step.counts.measurements_accepted),
        measurements_rejected: saturating_u16(step.measurements_rejected()),
    }
}
