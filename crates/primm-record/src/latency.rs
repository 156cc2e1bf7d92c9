//! The tracker's latencies as JSON messages that Foxglove's Plot panel reads: the per-stage
//! percentiles of each `LatencyReport` (`/primm/latency/stages`, e.g. the path
//! `/primm/latency/stages.stages.end_to_end.p99_us`) and one track frame's own latencies
//! (`/primm/latency/frame`). Every time is in microseconds.

use primm_wire::{LatencyReport, TrackFrame};
use serde_json::{json, Map, Value};

/// JSON schema of `/primm/latency/stages`.
pub const STAGES_JSON_SCHEMA: &str = r#"{
  "title": "primm.LatencyStages",
  "description": "The tracker's latency percentiles since it started, per stage, in microseconds, and its frame counters (from primm/latency).",
  "type": "object",
  "properties": {
    "sequence": {"type": "integer"},
    "frames_received": {"type": "integer"},
    "frames_tracked": {"type": "integer"},
    "frames_rejected": {"type": "integer"},
    "frames_lost": {"type": "integer"},
    "measurements_rejected": {"type": "integer"},
    "resets": {"type": "integer"},
    "stages": {
      "type": "object",
      "additionalProperties": {
        "type": "object",
        "properties": {
          "count": {"type": "integer"},
          "p50_us": {"type": "number"},
          "p90_us": {"type": "number"},
          "p99_us": {"type": "number"},
          "p999_us": {"type": "number"},
          "max_us": {"type": "number"},
          "mean_us": {"type": "number"}
        }
      }
    }
  }
}"#;

/// JSON schema of `/primm/latency/frame`.
pub const FRAME_JSON_SCHEMA: &str = r#"{
  "title": "primm.FrameLatency",
  "description": "One track frame: its counts and, where the clocks are known, its latencies in microseconds (CLOCK_MONOTONIC differences on one host).",
  "type": "object",
  "properties": {
    "input_sequence": {"type": "integer"},
    "source_frame": {"type": "integer"},
    "status": {"type": "integer"},
    "tracks": {"type": "integer"},
    "confirmed_tracks": {"type": "integer"},
    "measurements_accepted": {"type": "integer"},
    "measurements_rejected": {"type": "integer"},
    "publisher_to_tracker_us": {"type": ["number", "null"]},
    "receive_to_publish_us": {"type": ["number", "null"]},
    "publisher_to_tracks_us": {"type": ["number", "null"]}
  }
}"#;

fn microseconds(ns: u64) -> f64 {
    ns as f64 / 1000.0
}

/// `/primm/latency/stages` of `report`.
pub fn stages_json(report: &LatencyReport) -> Vec<u8> {
    let mut stages = Map::new();
    for stage in report.valid_stages() {
        stages.insert(
            stage.name_str().to_owned(),
            json!({
                "count": stage.count,
                "p50_us": microseconds(stage.p50_ns),
                "p90_us": microseconds(stage.p90_ns),
                "p99_us": microseconds(stage.p99_ns),
                "p999_us": microseconds(stage.p999_ns),
                "max_us": microseconds(stage.max_ns),
                "mean_us": microseconds(stage.mean_ns),
            }),
        );
    }
    let message = json!({
        "sequence": report.sequence,
        "frames_received": report.frames_received,
        "frames_tracked": report.frames_tracked,
        "frames_rejected": report.frames_rejected,
        "frames_lost": report.frames_lost,
        "measurements_rejected": report.measurements_rejected,
        "resets": report.resets,
        "stages": Value::Object(stages),
    });
    serde_json::to_vec(&message).expect("JSON values serialise")
}

/// The difference `later - earlier` in µs when both clocks are known and in order.
fn span_us(earlier_ns: u64, later_ns: u64) -> Value {
    if earlier_ns != 0 && later_ns >= earlier_ns {
        json!(microseconds(later_ns - earlier_ns))
    } else {
        Value::Null
    }
}

/// `/primm/latency/frame` of `frame`.
pub fn frame_json(frame: &TrackFrame) -> Vec<u8> {
    let tracks = frame.valid_tracks();
    let message = json!({
        "input_sequence": frame.input_sequence,
        "source_frame": frame.source_frame,
        "status": frame.status,
        "tracks": tracks.len(),
        "confirmed_tracks": tracks.iter().filter(|t| t.status == 1).count(),
        "measurements_accepted": frame.measurements_accepted,
        "measurements_rejected": frame.measurements_rejected,
        "publisher_to_tracker_us": span_us(frame.input_publish_time_ns, frame.receive_time_ns),
        "receive_to_publish_us": span_us(frame.receive_time_ns, frame.publish_time_ns),
        "publisher_to_tracks_us": span_us(frame.input_publish_time_ns, frame.publish_time_ns),
    });
    serde_json::to_vec(&message).expect("JSON values serialise")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raw::zeroed_box;
    use primm_wire::StageLatency;

    #[test]
    fn stage_percentiles_are_keyed_by_stage_name_in_microseconds() {
        let mut report = zeroed_box::<LatencyReport>();
        report.stage_count = 1;
        report.stages[0] = StageLatency { p99_ns: 12_500, count: 3, ..StageLatency::named("end_to_end") };
        let value: Value = serde_json::from_slice(&stages_json(&report)).unwrap();
        assert_eq!(value["stages"]["end_to_end"]["p99_us"], 12.5);
        assert_eq!(value["stages"]["end_to_end"]["count"], 3);
    }

    #[test]
    fn unknown_clocks_give_no_latency() {
        let mut frame = zeroed_box::<TrackFrame>();
        frame.receive_time_ns = 1_000;
        frame.publish_time_ns = 3_000;
        let value: Value = serde_json::from_slice(&frame_json(&frame)).unwrap();
        assert_eq!(value["receive_to_publish_us"], 2.0);
        assert_eq!(value["publisher_to_tracker_us"], Value::Null);
    }
}
