//! `primm::LatencyReport`: the tracker service's latency percentiles and counters, published
//! every few frames.

use iceoryx2::prelude::ZeroCopySend;
use primm_core::stage_timing::Stage;

/// Bytes of a stage name, NUL-padded ASCII.
pub const STAGE_NAME_LEN: usize = 24;
/// Number of stage slots in a [`LatencyReport`].
pub const STAGE_CAPACITY: usize = 12;

/// The latencies the service measures, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum LatencyStage {
    /// Tracker stage [`Stage::Validate`].
    Validate = 0,
    /// Tracker stage [`Stage::Predict`]: mixing and physics predictions.
    Predict = 1,
    /// Tracker stage [`Stage::LearnedWait`]: waiting for the learned predictor, prior fusion.
    LearnedWait = 2,
    /// Tracker stage [`Stage::Associate`].
    Associate = 3,
    /// Tracker stage [`Stage::Update`].
    Update = 4,
    /// Tracker stage [`Stage::Report`]: writing the tracks into the loaned sample.
    Report = 5,
    /// Sending the track frame and notifying its listeners.
    Publish = 6,
    /// From taking the input sample to the track frame sent.
    ReceiveToPublish = 7,
    /// From the publisher's send of the input frame to the tracker's send of its track frame
    /// (same host, `CLOCK_MONOTONIC`).
    EndToEnd = 8,
}

impl LatencyStage {
    /// Number of measured stages.
    pub const COUNT: usize = 9;
    /// All stages in report order.
    pub const ALL: [LatencyStage; Self::COUNT] = [
        Self::Validate,
        Self::Predict,
        Self::LearnedWait,
        Self::Associate,
        Self::Update,
        Self::Report,
        Self::Publish,
        Self::ReceiveToPublish,
        Self::EndToEnd,
    ];

    /// Index in per-stage tables.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Name in reports and tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Validate => "validate",
            Self::Predict => "predict",
            Self::LearnedWait => "learned_wait",
            Self::Associate => "associate",
            Self::Update => "update",
            Self::Report => "report",
            Self::Publish => "publish",
            Self::ReceiveToPublish => "receive_to_publish",
            Self::EndToEnd => "end_to_end",
        }
    }

    /// The service stage of a tracker stage.
    pub fn of_tracker_stage(stage: Stage) -> Self {
        match stage {
            Stage::Validate => Self::Validate,
            Stage::Predict => Self::Predict,
            Stage::LearnedWait => Self::LearnedWait,
            Stage::Associate => Self::Associate,
            Stage::Update => Self::Update,
            Stage::Report => Self::Report,
        }
    }
}
const _: () = assert!(LatencyStage::COUNT <= STAGE_CAPACITY);

/// Percentiles of one stage's latency: 80 bytes, alignment 8.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("primm::StageLatency")]
pub struct StageLatency {
    /// Stage name, ASCII, NUL-padded.
    pub name: [u8; STAGE_NAME_LEN],
    /// Samples recorded.
    pub count: u64,
    /// Median, ns.
    pub p50_ns: u64,
    /// 90th percentile, ns.
    pub p90_ns: u64,
    /// 99th percentile, ns.
    pub p99_ns: u64,
    /// 99.9th percentile, ns.
    pub p999_ns: u64,
    /// Largest sample, ns.
    pub max_ns: u64,
    /// Mean, ns.
    pub mean_ns: u64,
}

impl StageLatency {
    /// An empty entry named `name` (truncated to [`STAGE_NAME_LEN`] bytes).
    pub fn named(name: &str) -> Self {
        let mut bytes = [0u8; STAGE_NAME_LEN];
        let len = name.len().min(STAGE_NAME_LEN);
        bytes[..len].copy_from_slice(&name.as_bytes()[..len]);
        Self { name: bytes, count: 0, p50_ns: 0, p90_ns: 0, p99_ns: 0, p999_ns: 0, max_ns: 0, mean_ns: 0 }
    }

    /// The name as text (up to the first NUL; invalid UTF-8 yields `"?"`).
    pub fn name_str(&self) -> &str {
        let end = self.name.iter().position(|&b| b == 0).unwrap_or(STAGE_NAME_LEN);
        core::str::from_utf8(&self.name[..end]).unwrap_or("?")
    }
}

/// Latency percentiles since the service started, and its counters: 1 032 bytes, alignment 8.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("primm::LatencyReport")]
pub struct LatencyReport {
    /// Report counter, from 0.
    pub sequence: u64,
    /// When the report was sent, `CLOCK_MONOTONIC` ns.
    pub publish_time_ns: u64,
    /// Measurement frames taken from the input buffer.
    pub frames_received: u64,
    /// Frames tracked.
    pub frames_tracked: u64,
    /// Frames rejected by validation (published with a rejection status).
    pub frames_rejected: u64,
    /// Input frames missing from the sequence (lost upstream or overwritten in the buffer).
    pub frames_lost: u64,
    /// Measurements rejected by validation.
    pub measurements_rejected: u64,
    /// Tracker resets (new stream, new publisher, interval too long).
    pub resets: u64,
    /// Valid entries at the start of `stages`.
    pub stage_count: u32,
    /// Explicit padding, written as zero.
    pub _pad0: [u8; 4],
    /// Per-stage latencies, in [`LatencyStage`] order.
    pub stages: [StageLatency; STAGE_CAPACITY],
}

impl LatencyReport {
    /// The valid stage entries (count clamped to the capacity).
    pub fn valid_stages(&self) -> &[StageLatency] {
        &self.stages[..(self.stage_count as usize).min(STAGE_CAPACITY)]
    }
}
