//! `primm::LatencyReport`: the tracker service's latency percentiles and counters, published
//! every few frames.

use iceoryx2::prelude::ZeroCopySend;
use primm_core::stage_timing::Stage;

/// Bytes of a stage name, NUL-padded ASCII.
pub const STAGE_NAME_LEN: usize = 24;
/// Number of stage slots in a [`LatencyReport`].
pub const STAGE_CAPACITY: usize = 12;

const _: () = assert!(Stage::COUNT <= STAGE_CAPACITY);

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
    /// Per-stage latencies, entry `i` for the [`Stage`] of index `i` (its name in the entry).
    pub stages: [StageLatency; STAGE_CAPACITY],
}

impl LatencyReport {
    /// The valid stage entries (count clamped to the capacity).
    pub fn valid_stages(&self) -> &[StageLatency] {
        &self.stages[..(self.stage_count as usize).min(STAGE_CAPACITY)]
    }
}
