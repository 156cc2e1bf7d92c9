//! # primm-wire: the shared-memory payloads
//!
//! Payload types exchanged over shared memory between the tracker service, publishers,
//! subscribers and clients written in other languages.
//!
//! Every type is `#[repr(C)]` with fixed-size arrays plus a count, explicit padding fields and
//! no implicit padding, so that the C header `include/primm_wire.h` and the Python `ctypes`
//! module `python/primm_wire.py` (the pip package `primm-wire`) describe the same bytes; a
//! test compares sizes, alignments and every field offset of the three declarations. Every field is a plain integer
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
//!
//! A [`MeasurementFrame`] is written in place (here into a zeroed heap buffer; in the service,
//! into a sample loaned from shared memory) and read in place by the tracker, which takes any
//! `FrameView`:
//!
//! ```
//! use primm_core::config::Config;
//! use primm_core::measurement::{Measurement, ObjectClass};
//! use primm_core::tracker::Tracker;
//! use primm_wire::{MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, WireMeasurement};
//! use std::mem::MaybeUninit;
//!
//! let mut sample: Box<MaybeUninit<MeasurementFrame>> = Box::new_zeroed();
//! let mut writer = MeasurementFrameWriter::new(&mut sample);
//! let measurement = Measurement {
//!     x_m: 12.0,
//!     y_m: -3.0,
//!     radial_velocity_mps: 2.5,
//!     rcs_dbsm: 4.0,
//!     class: ObjectClass::TwoWheeler,
//!     sensor_id: Some(1),
//!     ground_truth_id: None,
//! };
//! writer.push(WireMeasurement::new(&measurement, None))?;
//! let header = MeasurementFrameHeader { sensor_timestamp_s: 0.25, ..Default::default() };
//! writer.finish(&header);
//! // Sound: the buffer started zeroed (every field is plain data) and `finish` wrote the
//! // header and the measurement.
//! let frame = unsafe { sample.assume_init() };
//! assert_eq!(frame.count, 1);
//!
//! let mut tracker = Tracker::new(Config::default())?;
//! assert_eq!(tracker.step(&*frame)?.len(), 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

/// Version of the payload layouts. It changes whenever a layout changes; the tracker writes it
/// into every [`TrackFrame`] (`wire_version`), and the C header (`PRIMM_WIRE_VERSION`) and the
/// Python module (`WIRE_VERSION`) declare it beside their layouts. Version 2 added the
/// world-frame fields of [`WireTrack`] and [`FrameStatus::RejectedInvalidEgoPose`]; version 3
/// its `existence_probability` and the status code 2 (coasting); version 4 the 4×4
/// position–velocity covariances (in place of the 2×2 position covariance) and `age_s` of
/// [`WireTrack`], [`TrackFrame::tracks_timestamp_s`], the flags for late frames and predicted
/// tracks, [`FrameStatus::RejectedTooLate`], and the publisher's schedule
/// (`MeasurementFrame::scheduled_time_ns`, `TrackFrame::input_scheduled_time_ns`); version 5 the capacity of a [`MeasurementFrame`],
/// 1,024 measurements (from 256), to hold a radar's point cloud. (iceoryx2
/// also refuses to connect a publisher and a subscriber whose payload sizes differ.)
pub const WIRE_VERSION: u16 = 5;

mod latency_report;
mod measurement_frame;
mod track_frame;

pub use latency_report::{LatencyReport, StageLatency, STAGE_CAPACITY, STAGE_NAME_LEN};
pub use measurement_frame::{
    FrameFull, MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, WireMeasurement,
    FRAME_FLAG_EGO_VALID, FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START, GROUND_TRUTH_UNKNOWN,
    MEASUREMENT_CAPACITY, SENSOR_UNKNOWN,
};
pub use track_frame::{
    row_major, FrameStatus, TrackFrame, TrackFrameHeader, TrackFrameWriter, WireTrack,
    MEASUREMENT_INDEX_NONE, TRACK_CAPACITY, TRACK_FLAG_LATE_FRAME, TRACK_FLAG_PREDICTED,
    TRACK_FLAG_SEQUENCE_GAP, TRACK_FLAG_STREAM_END, TRACK_FLAG_TRACKER_RESET,
};
