//! Payload types exchanged over shared memory between the tracker service, publishers,
//! subscribers and clients written in other languages.
//!
//! Every type is `#[repr(C)]` with fixed-size arrays plus a count, explicit padding fields and
//! no implicit padding, so that the C header `include/primm_wire.h` and the Python `ctypes`
//! module `examples/python/primm_wire.py` describe the same bytes; a test compares sizes,
//! alignments and every field offset of the three declarations. Every field is a plain integer
//! or float (every bit pattern is a valid value), so a reader never meets an invalid value, only
//! a wrong one, and the bytes past `count` in an array are stale but harmless.
//!
//! Each type carries an explicit iceoryx2 `type_name` (`primm::MeasurementFrame`,
//! `primm::TrackFrame`, `primm::LatencyReport`): separately compiled programs and foreign
//! clients that declare the same layout under the same name can open the same service.
//!
//! Units are part of every field name. Times are either sensor time in seconds (`_s`, from the
//! recording, the only time the tracker reads) or `CLOCK_MONOTONIC` nanoseconds (`_ns`, for
//! latency measurements between processes on the same host).

mod latency_report;
mod measurement_frame;
mod track_frame;

pub use latency_report::{LatencyReport, LatencyStage, StageLatency, STAGE_CAPACITY, STAGE_NAME_LEN};
pub use measurement_frame::{
    FrameFull, MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, WireMeasurement,
    FRAME_FLAG_EGO_VALID, FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START, GROUND_TRUTH_UNKNOWN,
    MEASUREMENT_CAPACITY, SENSOR_UNKNOWN,
};
pub use track_frame::{
    FrameStatus, TrackFrame, TrackFrameHeader, TrackFrameWriter, WireTrack, MEASUREMENT_INDEX_NONE,
    TRACK_CAPACITY, TRACK_FLAG_SEQUENCE_GAP, TRACK_FLAG_STREAM_END, TRACK_FLAG_TRACKER_RESET,
};
