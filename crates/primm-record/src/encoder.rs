//! [`FrameEncoder`]: wire frames in, the messages of every topic out.

use crate::detections::{detection_scene, ground_truth_scene, taken_detections};
use crate::latency::{frame_json, stages_json};
use crate::raw::{payload_bytes, read_payload};
use crate::scene::track_scene;
use crate::topics::{log_time_ns, Message, MessageSink, SinkError, Topic};
use crate::transforms::{frame_transforms, RadarPose};
use foxglove::Encode;
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame};
use std::collections::VecDeque;

/// Measurement frames kept until the track frame that answers them arrives (as deep as the
/// tracker's input buffer).
const PENDING_FRAMES: usize = 64;

/// Turns the frames of the three streams into messages for a sink. Measurement frames are
/// written as they come and kept until the tracker's answer, which says which detections its
/// tracks took; latency reports take the log time of the latest track frame.
#[derive(Debug)]
pub struct FrameEncoder {
    radars: Vec<RadarPose>,
    pending: VecDeque<(u64, Vec<u8>)>,
    spare: Vec<Vec<u8>>,
    measurements: Box<MeasurementFrame>,
    buffer: Vec<u8>,
    last_log_time_ns: u64,
    counts: [u64; Topic::COUNT],
}

impl FrameEncoder {
    /// An encoder drawing the given radars in the transforms.
    pub fn new(radars: Vec<RadarPose>) -> Self {
        Self {
            radars,
            pending: VecDeque::with_capacity(PENDING_FRAMES),
            spare: Vec::new(),
            measurements: MeasurementFrame::boxed_zeroed(),
            buffer: Vec::with_capacity(64 * 1024),
            last_log_time_ns: 0,
            counts: [0; Topic::COUNT],
        }
    }

    /// Messages written per topic so far, indexed by [`Topic::index`].
    pub fn message_counts(&self) -> [u64; Topic::COUNT] {
        self.counts
    }

    fn write(
        &mut self,
        sink: &mut dyn MessageSink,
        topic: Topic,
        log_time_ns: u64,
        publish_time_ns: u64,
        data: &[u8],
    ) -> Result<(), SinkError> {
        sink.write(&Message { topic, log_time_ns, publish_time_ns, data })?;
        self.counts[topic.index()] += 1;
        Ok(())
    }

    /// Encodes a protobuf message into the buffer and writes it.
    fn write_encoded(
        &mut self,
        sink: &mut dyn MessageSink,
        topic: Topic,
        log_time_ns: u64,
        publish_time_ns: u64,
        message: &impl Encode,
    ) -> Result<(), SinkError> {
        let mut buffer = std::mem::take(&mut self.buffer);
        buffer.clear();
        // Encoding into a growing Vec cannot run out of room.
        message.encode(&mut buffer).expect("protobuf encodes into a Vec");
        let result = self.write(sink, topic, log_time_ns, publish_time_ns, &buffer);
        self.buffer = buffer;
        result
    }

    /// A measurement frame: its payload, the transforms and the ground truth it carries.
    pub fn on_measurements(
        &mut self,
        frame: &MeasurementFrame,
        sink: &mut dyn MessageSink,
    ) -> Result<(), SinkError> {
        let log = log_time_ns(frame.sensor_timestamp_s);
        let publish = frame.publish_time_ns;
        let bytes = payload_bytes(frame);
        self.write(sink, Topic::Measurements, log, publish, bytes)?;
        let mut kept = self.spare.pop().unwrap_or_default();
        kept.clear();
        kept.extend_from_slice(bytes);
        if self.pending.len() == PENDING_FRAMES {
            if let Some((_, old)) = self.pending.pop_front() {
                self.spare.push(old);
            }
        }
        self.pending.push_back((frame.sequence, kept));
        if let Some(transforms) = frame_transforms(frame, &self.radars, log) {
            self.write_encoded(sink, Topic::Transforms, log, publish, &transforms)?;
        }
        if let Some(truth) = ground_truth_scene(frame, log) {
            self.write_encoded(sink, Topic::GroundTruthScene, log, publish, &truth)?;
        }
        Ok(())
    }

    /// A track frame: its payload, the track scene, the scene of the detections it answers
    /// (when that measurement frame was seen) and its latencies.
    pub fn on_tracks(&mut self, frame: &TrackFrame, sink: &mut dyn MessageSink) -> Result<(), SinkError> {
        let log = log_time_ns(frame.sensor_timestamp_s);
        let scene_log = log_time_ns(frame.tracks_timestamp_s);
        let publish = frame.publish_time_ns;
        self.write(sink, Topic::Tracks, log, publish, payload_bytes(frame))?;
        self.write_encoded(sink, Topic::TrackScene, scene_log, publish, &track_scene(frame, scene_log))?;
        if let Some(position) =
            self.pending.iter().rposition(|(sequence, _)| *sequence == frame.input_sequence)
        {
            let answered = read_payload(&self.pending[position].1, &mut *self.measurements).is_ok();
            for (_, bytes) in self.pending.drain(..=position) {
                self.spare.push(bytes);
            }
            if answered {
                let taken = taken_detections(&self.measurements, frame);
                let scene = detection_scene(&self.measurements, taken.as_deref(), log);
                self.write_encoded(sink, Topic::DetectionScene, log, publish, &scene)?;
            }
        }
        self.write(sink, Topic::FrameLatency, log, publish, &frame_json(frame))?;
        self.last_log_time_ns = scene_log;
        Ok(())
    }

    /// A latency report, logged at the latest track frame's time.
    pub fn on_latency(
        &mut self,
        report: &LatencyReport,
        sink: &mut dyn MessageSink,
    ) -> Result<(), SinkError> {
        let log = self.last_log_time_ns;
        self.write(sink, Topic::Latency, log, report.publish_time_ns, payload_bytes(report))?;
        self.write(sink, Topic::LatencyStages, log, report.publish_time_ns, &stages_json(report))
    }
}
