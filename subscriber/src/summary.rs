//! What the subscriber saw: the summary it prints and writes as JSON.

use crate::accuracy::AccuracySummary;
use primm_ipc::latency::{format_named_table, format_table};
use primm_wire::StageLatency;
use std::path::PathBuf;

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
