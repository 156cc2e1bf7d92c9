//! Reading `primm/measurements`, `primm/tracks` and `primm/latency` from shared memory into a
//! [`MessageSink`], on the calling thread: `primm record` runs it with an MCAP file, the live
//! view on a thread of its own with a WebSocket server.
//!
//! The recorder is one more subscriber of each stream. Safe overflow on every stream means that
//! a recorder that falls behind loses its own oldest frames (counted as sequence gaps) and
//! never holds up the tracker or the publishers.

use crate::encoder::FrameEncoder;
use crate::topics::{MessageSink, SinkError, Topic};
use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::ReceiveError;
use primm_ipc::catalog::{self, Ipc, Stream};
use primm_ipc::{ConnectError, ServiceNames};
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame, TRACK_FLAG_STREAM_END};
use std::time::{Duration, Instant};

/// How long the recorder sleeps at most between looks at its streams.
const WAKE_INTERVAL: Duration = Duration::from_millis(20);

/// The recorder's subscriptions.
#[derive(Debug)]
pub struct StreamPorts {
    measurements: Subscriber<Ipc, MeasurementFrame, ()>,
    tracks: Subscriber<Ipc, TrackFrame, ()>,
    track_listener: Listener<Ipc>,
    latency: Subscriber<Ipc, LatencyReport, ()>,
    track_stream: Stream<TrackFrame>,
    _measurement_stream: Stream<MeasurementFrame>,
    _latency_stream: Stream<LatencyReport>,
    _node: Node<Ipc>,
}

impl StreamPorts {
    /// Subscribes to the three streams of `names`, in the iceoryx2 domain `domain` (that of
    /// `PRIMM_ICEORYX2_DOMAIN`, or iceoryx2's default, when `None`).
    pub fn open(names: &ServiceNames, domain: Option<&str>, node_name: &str) -> Result<Self, ConnectError> {
        let config = match domain {
            Some(domain) => catalog::iceoryx2_config_in(Some(domain))?,
            None => catalog::iceoryx2_config()?,
        };
        let node = catalog::create_node_with(node_name, &config)?;
        let measurement_stream = catalog::measurements(&node, names)?;
        let track_stream = catalog::tracks(&node, names)?;
        let latency_stream = catalog::latency(&node, names)?;
        Ok(Self {
            measurements: measurement_stream.subscriber()?,
            tracks: track_stream.subscriber()?,
            track_listener: track_stream.listener()?,
            latency: latency_stream.subscriber()?,
            track_stream,
            _measurement_stream: measurement_stream,
            _latency_stream: latency_stream,
            _node: node,
        })
    }

    /// Whether a tracker publishes the track stream.
    pub fn tracker_connected(&self) -> bool {
        self.track_stream.publisher_count() > 0
    }
}

/// When a recording stops (besides a stop request).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RecordLimits {
    /// After this long.
    pub duration: Option<Duration>,
    /// After this many track frames.
    pub track_frames: Option<u64>,
    /// After the track frame that ends a finite replay.
    pub until_end: bool,
}

/// What a recording received.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct RecordSummary {
    /// Measurement frames received.
    pub measurement_frames: u64,
    /// Track frames received.
    pub track_frames: u64,
    /// Latency reports received.
    pub latency_reports: u64,
    /// Measurement frames missing from the sequence numbers the recorder saw (lost before or in
    /// its buffer).
    pub measurement_frames_missed: u64,
    /// Track frames missing from the input sequence numbers the recorder saw.
    pub track_frames_missed: u64,
    /// Whether the end of a finite replay was recorded.
    pub stream_end_seen: bool,
    /// Messages written per topic ([`Topic::index`]).
    pub messages: [u64; Topic::COUNT],
}

/// Why a recording stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// A sample could not be received.
    #[error("cannot receive from shared memory: {0}")]
    Receive(ReceiveError),
    /// Waiting for the tracker's next frame failed.
    #[error("cannot wait for track frames: {0}")]
    Wait(ListenerWaitError),
    /// The sink refused a message (the disk may be full).
    #[error(transparent)]
    Sink(#[from] SinkError),
}

/// Counts the sequence numbers skipped between `last` and `next`.
fn count_gap(last: &mut Option<u64>, next: u64, missed: &mut u64) {
    if let Some(previous) = *last {
        if next > previous + 1 {
            *missed += next - previous - 1;
        }
    }
    *last = Some(next);
}

/// Encodes every measurement frame received so far.
fn drain_measurements(
    ports: &StreamPorts,
    encoder: &mut FrameEncoder,
    sink: &mut dyn MessageSink,
    summary: &mut RecordSummary,
    last_measurement: &mut Option<u64>,
) -> Result<(), RecordError> {
    while let Some(sample) = ports.measurements.receive().map_err(RecordError::Receive)? {
        summary.measurement_frames += 1;
        count_gap(last_measurement, sample.sequence, &mut summary.measurement_frames_missed);
        encoder.on_measurements(&sample, sink)?;
    }
    Ok(())
}

/// Records until `stop()` says so or a limit is reached; returns what was received.
pub fn record(
    ports: &StreamPorts,
    encoder: &mut FrameEncoder,
    sink: &mut dyn MessageSink,
    limits: &RecordLimits,
    stop: &dyn Fn() -> bool,
) -> Result<RecordSummary, RecordError> {
    let started = Instant::now();
    let mut summary = RecordSummary::default();
    let (mut last_measurement, mut last_track) = (None, None);
    loop {
        match ports.track_listener.timed_wait(|_| {}, WAKE_INTERVAL) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
            Err(error) => return Err(RecordError::Wait(error)),
        }
        drain_measurements(ports, encoder, sink, &mut summary, &mut last_measurement)?;
        let mut done = false;
        while let Some(sample) = ports.tracks.receive().map_err(RecordError::Receive)? {
            // The answer to a frame that came after the last look: take that frame first, so
            // that the detections are drawn with what the tracker made of them.
            if last_measurement.is_none_or(|last| sample.input_sequence > last) {
                drain_measurements(ports, encoder, sink, &mut summary, &mut last_measurement)?;
            }
            summary.track_frames += 1;
            count_gap(&mut last_track, sample.input_sequence, &mut summary.track_frames_missed);
            encoder.on_tracks(&sample, sink)?;
            if sample.flags & TRACK_FLAG_STREAM_END != 0 {
                summary.stream_end_seen = true;
                done |= limits.until_end;
            }
            if limits.track_frames.is_some_and(|limit| summary.track_frames >= limit) {
                done = true;
            }
            if done {
                break;
            }
        }
        while let Some(sample) = ports.latency.receive().map_err(RecordError::Receive)? {
            summary.latency_reports += 1;
            encoder.on_latency(&sample, sink)?;
        }
        if done || stop() || limits.duration.is_some_and(|duration| started.elapsed() >= duration) {
            break;
        }
    }
    summary.messages = encoder.message_counts();
    Ok(summary)
}
