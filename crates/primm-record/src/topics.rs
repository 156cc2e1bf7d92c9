//! The topics of a recording or live view, their schemas, and what a message is.

use foxglove::schemas::{FrameTransforms, SceneUpdate};
use foxglove::{Encode, Schema};
use primm_wire::WIRE_VERSION;
use std::collections::BTreeMap;

/// Message encoding of the wire payloads: the `#[repr(C)]` bytes (little-endian) of a primm
/// wire type, cut after the last valid entry (see [`crate::raw`]).
pub const WIRE_ENCODING: &str = "primm-wire";

/// One topic of a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Topic {
    /// `primm::MeasurementFrame` wire payloads.
    Measurements,
    /// `primm::TrackFrame` wire payloads.
    Tracks,
    /// `primm::LatencyReport` wire payloads.
    Latency,
    /// `foxglove.SceneUpdate`: a box, arrow, ellipse and label per track.
    TrackScene,
    /// `foxglove.SceneUpdate`: the detections of the frame.
    DetectionScene,
    /// `foxglove.SceneUpdate`: the true object positions, where the frames carry them.
    GroundTruthScene,
    /// `foxglove.FrameTransforms`: world → vehicle (ego pose) and vehicle → each radar.
    Transforms,
    /// JSON: the tracker's latency percentiles per stage (from `primm/latency`).
    LatencyStages,
    /// JSON: one track frame's latencies and counts.
    FrameLatency,
}

impl Topic {
    /// Number of topics.
    pub const COUNT: usize = 9;
    /// Every topic, in index order.
    pub const ALL: [Topic; Self::COUNT] = [
        Self::Measurements,
        Self::Tracks,
        Self::Latency,
        Self::TrackScene,
        Self::DetectionScene,
        Self::GroundTruthScene,
        Self::Transforms,
        Self::LatencyStages,
        Self::FrameLatency,
    ];

    /// Index in [`ALL`](Self::ALL).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The topic name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Measurements => "/primm/measurements",
            Self::Tracks => "/primm/tracks",
            Self::Latency => "/primm/latency",
            Self::TrackScene => "/primm/scene/tracks",
            Self::DetectionScene => "/primm/scene/detections",
            Self::GroundTruthScene => "/primm/scene/ground_truth",
            Self::Transforms => "/tf",
            Self::LatencyStages => "/primm/latency/stages",
            Self::FrameLatency => "/primm/latency/frame",
        }
    }

    /// The topic of `name`, if it is one of primm's.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|topic| topic.name() == name)
    }

    /// The message encoding: `primm-wire`, `protobuf` or `json`.
    pub fn message_encoding(self) -> &'static str {
        match self {
            Self::Measurements | Self::Tracks | Self::Latency => WIRE_ENCODING,
            Self::TrackScene | Self::DetectionScene | Self::GroundTruthScene | Self::Transforms => "protobuf",
            Self::LatencyStages | Self::FrameLatency => "json",
        }
    }

    /// The schema: for the wire payloads a text naming the type, the wire version and the
    /// layout's definition; Foxglove's published protobuf descriptors for the scene and the
    /// transforms; a JSON schema for the latencies.
    pub fn schema(self) -> Schema {
        match self {
            Self::Measurements => wire_schema("primm::MeasurementFrame", "measurements"),
            Self::Tracks => wire_schema("primm::TrackFrame", "tracks"),
            Self::Latency => wire_schema("primm::LatencyReport", "stages"),
            Self::TrackScene | Self::DetectionScene | Self::GroundTruthScene => {
                SceneUpdate::get_schema().expect("foxglove.SceneUpdate has a schema")
            }
            Self::Transforms => FrameTransforms::get_schema().expect("foxglove.FrameTransforms has a schema"),
            Self::LatencyStages => Schema::new(
                "primm.LatencyStages",
                "jsonschema",
                crate::latency::STAGES_JSON_SCHEMA.as_bytes().to_vec(),
            ),
            Self::FrameLatency => Schema::new(
                "primm.FrameLatency",
                "jsonschema",
                crate::latency::FRAME_JSON_SCHEMA.as_bytes().to_vec(),
            ),
        }
    }

    /// Channel metadata: the wire version for the wire payloads, nothing for the others.
    pub fn metadata(self) -> BTreeMap<String, String> {
        let mut metadata = BTreeMap::new();
        if self.message_encoding() == WIRE_ENCODING {
            metadata.insert("wire_version".to_owned(), WIRE_VERSION.to_string());
        }
        metadata
    }
}

/// The schema text of a wire payload.
fn wire_schema(type_name: &str, entries: &str) -> Schema {
    let text = format!(
        "{type_name}: primm wire version {WIRE_VERSION}, #[repr(C)], little-endian; the header and the \
         first `count` entries of `{entries}` (the unused slots are left out). Layout: \
         crates/primm-wire/include/primm_wire.h (C), crates/primm-wire/python/primm_wire.py (Python).\n"
    );
    Schema::new(type_name.to_owned(), WIRE_ENCODING, text.into_bytes())
}

/// One message for a sink.
#[derive(Debug, Clone, Copy)]
pub struct Message<'a> {
    /// Its topic.
    pub topic: Topic,
    /// The frame's sensor time, ns (see [`log_time_ns`]).
    pub log_time_ns: u64,
    /// When its sender published the frame, `CLOCK_MONOTONIC` ns (0: unknown).
    pub publish_time_ns: u64,
    /// The encoded message.
    pub data: &'a [u8],
}

/// A sensor time in seconds as a log time in nanoseconds: negative, NaN or infinite times
/// become 0, times past 2^64 ns saturate.
pub fn log_time_ns(sensor_time_s: f64) -> u64 {
    if sensor_time_s.is_finite() && sensor_time_s > 0.0 {
        // `as` saturates at u64::MAX.
        (sensor_time_s * 1.0e9).round() as u64
    } else {
        0
    }
}

/// Why a sink could not take a message.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    /// The MCAP file could not be written.
    #[error(transparent)]
    File(#[from] crate::mcap_file::McapFileError),
}

/// Where encoded messages go: an MCAP file, a WebSocket server.
pub trait MessageSink {
    /// Takes one message.
    fn write(&mut self, message: &Message<'_>) -> Result<(), SinkError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_are_distinct_and_found_back() {
        for topic in Topic::ALL {
            assert_eq!(Topic::from_name(topic.name()), Some(topic));
            assert_eq!(Topic::ALL[topic.index()], topic);
        }
        assert_eq!(Topic::from_name("/other"), None);
    }

    #[test]
    fn log_times_are_the_sensor_time_in_nanoseconds_and_never_negative() {
        assert_eq!(log_time_ns(1.25), 1_250_000_000);
        assert_eq!(log_time_ns(-3.0), 0);
        assert_eq!(log_time_ns(f64::NAN), 0);
        assert_eq!(log_time_ns(1.0e30), u64::MAX);
    }

    #[test]
    fn wire_topics_name_the_wire_version() {
        let schema = Topic::Tracks.schema();
        assert_eq!(schema.name, "primm::TrackFrame");
        assert!(String::from_utf8_lossy(&schema.data).contains(&format!("wire version {WIRE_VERSION}")));
        assert_eq!(Topic::Tracks.metadata()["wire_version"], WIRE_VERSION.to_string());
        assert!(Topic::TrackScene.metadata().is_empty());
    }
}
