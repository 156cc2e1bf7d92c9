//! Replaying recorded frames onto `primm/measurements`: each frame is written straight into a
//! loaned sample, paced at the recorded speed (times a factor) or sent as fast as possible,
//! optionally with flow control against the tracker's answers on `primm/tracks`.

use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::{LoanError, ReceiveError, SendError};
use primm_core::readable_number::readable;
use primm_ipc::catalog::{self, ConnectError, Ipc, ServiceNames, Stream};
use primm_ipc::clock::monotonic_ns;
use primm_ipc::log_limit::LogLimiter;
use primm_ipc::shutdown::ShutdownFlag;
use primm_sim::io::{RecordedFrame, Sequence};
use primm_wire::{
    MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, TrackFrame, WireMeasurement,
    FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START, MEASUREMENT_CAPACITY,
};
use std::time::{Duration, Instant};

/// How fast frames are sent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pacing {
    /// At the recorded frame times, divided by `speed` (2.0 replays twice as fast).
    Recorded {
        /// Speed factor, > 0.
        speed: f64,
    },
    /// Back to back.
    AsFastAsPossible,
}

/// Settings of a replay.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayOptions {
    /// How fast to send.
    pub pacing: Pacing,
    /// Start again at the first sequence after the last one, until stopped.
    pub repeat: bool,
    /// Stop after this many frames.
    pub frame_limit: Option<u64>,
    /// With `Some(n)`, never have more than `n` frames unanswered by the tracker (flow control
    /// for as-fast-as-possible replays and benchmarks; lossless with `n` ≤ 16).
    pub max_in_flight: Option<u64>,
    /// Longest wait for the tracker's answer when `max_in_flight` holds frames back.
    pub answer_timeout: Duration,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        Self {
            pacing: Pacing::Recorded { speed: 1.0 },
            repeat: false,
            frame_limit: None,
            max_in_flight: None,
            answer_timeout: Duration::from_secs(5),
        }
    }
}

/// What a replay sent.
///
/// Every frame the replay came to is either sent or dropped: `frames_sent + frames_dropped`
/// frames were attempted. A dropped frame consumes no sequence number, so the tracker's count of
/// lost frames (sequence gaps) covers only frames lost after they were sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ReplaySummary {
    /// Frames sent.
    pub frames_sent: u64,
    /// Frames dropped because no shared-memory sample could be loaned for them, or the loaned
    /// sample could not be sent (counted and logged; the replay goes on instead of waiting).
    pub frames_dropped: u64,
    /// Frames sent while no subscriber was connected (no tracker received them).
    pub frames_without_receiver: u64,
    /// Measurements sent.
    pub measurements_sent: u64,
    /// Passes through the sequences started.
    pub passes: u64,
    /// Whether the replay was stopped by a shutdown request.
    pub interrupted: bool,
}

/// Why a replay failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// A recorded frame holds more measurements than a wire frame can carry.
    #[error("frame {frame} of sequence '{sequence}' has {count} measurements, more than the {MEASUREMENT_CAPACITY} a frame can carry")]
    TooManyMeasurements {
        /// Sequence name.
        sequence: String,
        /// Frame index.
        frame: u64,
        /// Its measurement count.
        count: usize,
    },
    /// No sample could be loaned from shared memory.
    #[error("cannot loan a measurement sample: {0}")]
    Loan(LoanError),
    /// The sample could not be sent.
    #[error("cannot send a measurement frame: {0}")]
    Send(SendError),
    /// Reading the tracker's answers failed.
    #[error("cannot read the tracker's answers: {0}")]
    Receive(ReceiveError),
    /// Waiting for the tracker's answers failed.
    #[error("cannot wait for the tracker's answers: {0}")]
    Wait(ListenerWaitError),
    /// The tracker did not answer in time while frames were held back.
    #[error("the tracker did not answer frame {sequence} within {timeout:?}")]
    AnswerTimeout {
        /// The oldest unanswered frame.
        sequence: u64,
        /// The timeout.
        timeout: Duration,
    },
    /// The pacing speed is not a positive number.
    #[error("replay speed must be a positive number, got {}", readable(.0))]
    InvalidSpeed(f64),
}

/// A frame [`Replayer::send`] sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SentFrame {
    /// Its sequence number.
    pub sequence: u64,
    /// Subscribers it was delivered to (0: no tracker was connected).
    pub receivers: usize,
}

/// Sends recorded frames to `primm/measurements`.
#[derive(Debug)]
pub struct Replayer {
    publisher: Publisher<Ipc, MeasurementFrame, ()>,
    notifier: Notifier<Ipc>,
    tracks: Stream<TrackFrame>,
    answers: Option<(Subscriber<Ipc, TrackFrame, ()>, Listener<Ipc>)>,
    next_sequence: u64,
    answered_up_to: Option<u64>,
    drop_log: LogLimiter,
    _measurements: Stream<MeasurementFrame>,
    _node: Node<Ipc>,
}

impl Replayer {
    /// Opens the measurement stream for sending; with `flow_control`, also subscribes to the
    /// tracker's answers (needed for [`ReplayOptions::max_in_flight`]).
    pub fn new(names: &ServiceNames, flow_control: bool) -> Result<Self, ConnectError> {
        let node = catalog::create_node("primm-publisher")?;
        let measurements = catalog::measurements(&node, names)?;
        let tracks = catalog::tracks(&node, names)?;
        let answers = if flow_control { Some((tracks.subscriber()?, tracks.listener()?)) } else { None };
        Ok(Self {
            publisher: measurements.publisher()?,
            notifier: measurements.notifier()?,
            tracks,
            answers,
            next_sequence: 0,
            answered_up_to: None,
            drop_log: LogLimiter::default(),
            _measurements: measurements,
            _node: node,
        })
    }

    /// Waits until a tracker serves the track stream (it then also reads measurements); whether
    /// one did within `timeout`.
    pub fn wait_for_tracker(&self, timeout: Duration, shutdown: &ShutdownFlag) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            if self.tracks.publisher_count() > 0 {
                return true;
            }
            if shutdown.is_requested() || Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Subscribers of the track stream now (the tracker's answers are read by each).
    pub fn track_subscribers(&self) -> usize {
        self.tracks.subscriber_count()
    }

    /// The sequence number the next frame will carry.
    pub fn next_sequence(&self) -> u64 {
        self.next_sequence
    }

    /// Sends one frame with the given `FRAME_FLAG_*` bits, without a schedule; returns its
    /// sequence number and how many subscribers received it. Never waits: with safe overflow a
    /// full subscriber buffer drops its oldest frame instead.
    pub fn send(
        &mut self,
        sequence_name: &str,
        frame: &RecordedFrame,
        flags: u32,
    ) -> Result<SentFrame, ReplayError> {
        self.send_scheduled(sequence_name, frame, flags, 0)
    }

    /// [`send`](Self::send) for a frame that was due at `scheduled_time_ns`
    /// (`CLOCK_MONOTONIC`, ns; 0: no schedule), which the frame carries so that latencies can
    /// be measured from the schedule too (corrected for coordinated omission).
    pub fn send_scheduled(
        &mut self,
        sequence_name: &str,
        frame: &RecordedFrame,
        flags: u32,
        scheduled_time_ns: u64,
    ) -> Result<SentFrame, ReplayError> {
        if frame.measurements.len() > MEASUREMENT_CAPACITY {
            return Err(ReplayError::TooManyMeasurements {
                sequence: sequence_name.to_owned(),
                frame: frame.index,
                count: frame.measurements.len(),
            });
        }
        let mut loan = self.publisher.loan_uninit().map_err(ReplayError::Loan)?;
        let mut writer = MeasurementFrameWriter::new(loan.payload_mut());
        for recorded in &frame.measurements {
            let mut measurement = recorded.measurement;
            if measurement.sensor_id.is_none() {
                measurement.sensor_id = frame.sensor_id;
            }
            let truth = recorded.true_position.map(|p| [p.x, p.y]);
            // Cannot fail: the count was checked above.
            let _ = writer.push(WireMeasurement::new(&measurement, truth));
        }
        let sequence = self.next_sequence;
        writer.finish(&MeasurementFrameHeader {
            sequence,
            source_frame: frame.index,
            sensor_timestamp_s: frame.timestamp_s,
            publish_time_ns: monotonic_ns(),
            scheduled_time_ns,
            flags,
            ego: frame.ego_pose.map(|pose| (pose.x_m, pose.y_m, pose.yaw_rad)),
        });
        // SAFETY: the writer initialised the header and the first `count` measurements; the
        // other slots hold bytes left in the shared-memory chunk, and every field of
        // `WireMeasurement` is a plain integer or float, valid for any bit pattern.
        let sample = unsafe { loan.assume_init() };
        let receivers = sample.send().map_err(ReplayError::Send)?;
        // A missing listener is not an error: the tracker may poll.
        let _ = self.notifier.notify();
        self.next_sequence += 1;
        Ok(SentFrame { sequence, receivers })
    }

    /// Sends a frame recorded from the wire again (`primm replay`): its source frame, sensor
    /// time, flags, ego pose and measurements as recorded (at most [`MEASUREMENT_CAPACITY`]),
    /// with this replayer's next sequence number, the current publish time and
    /// `scheduled_time_ns` (0: no schedule). Never waits, as [`send`](Self::send).
    pub fn send_recorded(
        &mut self,
        recorded: &MeasurementFrame,
        scheduled_time_ns: u64,
    ) -> Result<SentFrame, ReplayError> {
        let mut loan = self.publisher.loan_uninit().map_err(ReplayError::Loan)?;
        let mut writer = MeasurementFrameWriter::new(loan.payload_mut());
        let count = (recorded.count as usize).min(MEASUREMENT_CAPACITY);
        for measurement in &recorded.measurements[..count] {
            // Cannot fail: at most the capacity.
            let _ = writer.push(*measurement);
        }
        let sequence = self.next_sequence;
        writer.finish(&MeasurementFrameHeader {
            sequence,
            source_frame: recorded.source_frame,
            sensor_timestamp_s: recorded.sensor_timestamp_s,
            publish_time_ns: monotonic_ns(),
            scheduled_time_ns,
            flags: recorded.flags,
            ego: recorded.ego_pose(),
        });
        // SAFETY: as in `send_scheduled`: the header and the first `count` measurements are
        // written, and every other slot holds plain integers and floats.
        let sample = unsafe { loan.assume_init() };
        let receivers = sample.send().map_err(ReplayError::Send)?;
        let _ = self.notifier.notify();
        self.next_sequence += 1;
        Ok(SentFrame { sequence, receivers })
    }

    /// Reads the tracker's answers that arrived so far.
    fn collect_answers(&mut self) -> Result<(), ReplayError> {
        self.receive_answers(|_| {}).map(|_| ())
    }

    /// Hands every answer that arrived so far to `on_answer` (only with flow control, see
    /// [`new`](Self::new)); returns how many.
    pub fn receive_answers(&mut self, mut on_answer: impl FnMut(&TrackFrame)) -> Result<usize, ReplayError> {
        let Some((subscriber, _)) = &self.answers else { return Ok(0) };
        let mut received = 0;
        while let Some(answer) = subscriber.receive().map_err(ReplayError::Receive)? {
            received += 1;
            on_answer(&answer);
            let sequence = answer.input_sequence;
            if sequence < self.next_sequence {
                self.answered_up_to = Some(self.answered_up_to.map_or(sequence, |up_to| up_to.max(sequence)));
            }
        }
        Ok(received)
    }

    /// Frames sent and not yet answered.
    fn in_flight(&self) -> u64 {
        match self.answered_up_to {
            Some(up_to) => self.next_sequence - 1 - up_to.min(self.next_sequence - 1),
            None => self.next_sequence,
        }
    }

    /// Waits until at most `max` frames are unanswered (flow control only; without it, returns
    /// at once).
    pub fn wait_in_flight(
        &mut self,
        max: u64,
        timeout: Duration,
        shutdown: &ShutdownFlag,
    ) -> Result<(), ReplayError> {
        let deadline = Instant::now() + timeout;
        loop {
            self.collect_answers()?;
            if self.in_flight() <= max || shutdown.is_requested() || self.answers.is_none() {
                return Ok(());
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(ReplayError::AnswerTimeout {
                    sequence: self.next_sequence - self.in_flight(),
                    timeout,
                });
            }
            if let Some((_, listener)) = &self.answers {
                match listener.timed_wait(|_| {}, (deadline - now).min(Duration::from_millis(20))) {
                    Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                    Err(error) => return Err(ReplayError::Wait(error)),
                }
            }
        }
    }

    /// Waits until every frame sent so far is answered (flow control only).
    pub fn wait_all_answered(
        &mut self,
        timeout: Duration,
        shutdown: &ShutdownFlag,
    ) -> Result<(), ReplayError> {
        self.wait_in_flight(0, timeout, shutdown)
    }

    /// Replays `sequences` in order (each one starting a new stream), as `options` say, until
    /// done, the frame limit, or `shutdown`.
    pub fn replay(
        &mut self,
        sequences: &[Sequence],
        options: &ReplayOptions,
        shutdown: &ShutdownFlag,
    ) -> Result<ReplaySummary, ReplayError> {
        if let Pacing::Recorded { speed } = options.pacing {
            if !(speed.is_finite() && speed > 0.0) {
                return Err(ReplayError::InvalidSpeed(speed));
            }
        }
        let mut summary = ReplaySummary::default();
        let total_frames: usize = sequences.iter().map(|s| s.frames.len()).sum();
        if total_frames == 0 {
            return Ok(summary);
        }
        loop {
            summary.passes += 1;
            for (sequence_index, sequence) in sequences.iter().enumerate() {
                let Some(first) = sequence.frames.first() else { continue };
                let start = Instant::now();
                let start_ns = monotonic_ns();
                for (frame_index, frame) in sequence.frames.iter().enumerate() {
                    if shutdown.is_requested() {
                        summary.interrupted = true;
                        return Ok(summary);
                    }
                    let scheduled_time_ns = wait_for_schedule(
                        options.pacing,
                        (start, start_ns),
                        frame.timestamp_s - first.timestamp_s,
                    );
                    if let Some(max) = options.max_in_flight {
                        self.wait_in_flight(max.saturating_sub(1), options.answer_timeout, shutdown)?;
                    }
                    let last_of_replay = !options.repeat
                        && sequence_index + 1 == sequences.len()
                        && frame_index + 1 == sequence.frames.len();
                    let last_of_limit =
                        options.frame_limit.is_some_and(|limit| summary.frames_sent + 1 >= limit);
                    let mut flags = 0;
                    if frame_index == 0 {
                        flags |= FRAME_FLAG_STREAM_START;
                    }
                    if last_of_replay || last_of_limit {
                        flags |= FRAME_FLAG_STREAM_END;
                    }
                    self.send_counted(&sequence.name, frame, flags, scheduled_time_ns, &mut summary)?;
                    if last_of_limit {
                        return Ok(summary);
                    }
                }
            }
            if !options.repeat {
                return Ok(summary);
            }
        }
    }

    /// Sends one frame and counts it in `summary`: sent (and whether anyone received it), or
    /// dropped for want of a sample or a send (counted and logged; the replay goes on). Any
    /// other error ends the replay.
    fn send_counted(
        &mut self,
        name: &str,
        frame: &RecordedFrame,
        flags: u32,
        scheduled_time_ns: u64,
        summary: &mut ReplaySummary,
    ) -> Result<(), ReplayError> {
        match self.send_scheduled(name, frame, flags, scheduled_time_ns) {
            Ok(sent) => {
                summary.frames_sent += 1;
                summary.measurements_sent += frame.measurements.len() as u64;
                if sent.receivers == 0 {
                    summary.frames_without_receiver += 1;
                }
                Ok(())
            }
            Err(error @ (ReplayError::Loan(_) | ReplayError::Send(_))) => {
                summary.frames_dropped += 1;
                if self.drop_log.occur() {
                    tracing::warn!(%error, occurrences = self.drop_log.occurrences(), "measurement frame dropped");
                }
                Ok(())
            }
            Err(error) => Err(error),
        }
    }
}

/// With recorded pacing, sleeps until the frame recorded `since_first_s` after the sequence's
/// first is due (`start` plus that time over the speed) and returns its scheduled send time,
/// ns (at least 1); as fast as possible: 0 (no schedule) at once.
fn wait_for_schedule(pacing: Pacing, (start, start_ns): (Instant, u64), since_first_s: f64) -> u64 {
    let Pacing::Recorded { speed } = pacing else { return 0 };
    let offset = Duration::from_secs_f64((since_first_s / speed).clamp(0.0, 1.0e9));
    let due = start + offset;
    let scheduled_time_ns = start_ns.saturating_add(offset.as_nanos() as u64).max(1);
    let now = Instant::now();
    if due > now {
        std::thread::sleep(due - now);
    }
    scheduled_time_ns
}
