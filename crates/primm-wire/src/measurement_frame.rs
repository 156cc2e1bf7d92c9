//! `primm::MeasurementFrame`: one radar frame of object-level measurements, read by the tracker
//! in place through [`FrameView`].

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;
use iceoryx2::prelude::ZeroCopySend;
use primm_core::measurement::{
    FrameView, Measurement, ObjectClass, UnknownClass, MAX_MEASUREMENTS_PER_FRAME,
};
use primm_core::pose::EgoPose;

/// Number of measurement slots in a [`MeasurementFrame`].
pub const MEASUREMENT_CAPACITY: usize = MAX_MEASUREMENTS_PER_FRAME;

/// [`WireMeasurement::gt_id`] of a measurement without ground truth (any negative value means
/// unknown).
pub const GROUND_TRUTH_UNKNOWN: i64 = -1;

/// [`WireMeasurement::sensor_id`] of a measurement whose sensor is not known.
pub const SENSOR_UNKNOWN: u16 = u16::MAX;

/// [`MeasurementFrame::flags`] bit: the frame starts a new stream (first frame of a replay or of
/// a new loop through it); the tracker forgets its tracks before tracking it.
pub const FRAME_FLAG_STREAM_START: u32 = 1 << 0;
/// [`MeasurementFrame::flags`] bit: the `ego_*` fields hold the vehicle pose.
pub const FRAME_FLAG_EGO_VALID: u32 = 1 << 1;
/// [`MeasurementFrame::flags`] bit: the last frame of a finite stream; the tracker copies it to
/// its track frame so that subscribers know the stream is complete.
pub const FRAME_FLAG_STREAM_END: u32 = 1 << 2;

/// One object-level measurement: 64 bytes, alignment 8.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("primm::WireMeasurement")]
pub struct WireMeasurement {
    /// Longitudinal position in the vehicle frame, m.
    pub x_m: f64,
    /// Lateral position in the vehicle frame, m.
    pub y_m: f64,
    /// Ego-motion compensated radial velocity, m/s, positive moving away.
    pub vr_mps: f64,
    /// Radar cross section, dBsm.
    pub rcs_dbsm: f64,
    /// True longitudinal position of the object, m; valid when `truth_valid` is 1.
    pub true_x_m: f64,
    /// True lateral position of the object, m; valid when `truth_valid` is 1.
    pub true_y_m: f64,
    /// Ground-truth object id; [`GROUND_TRUTH_UNKNOWN`] (any negative value) when unknown.
    pub gt_id: i64,
    /// Sensor that produced the measurement; [`SENSOR_UNKNOWN`] when unknown.
    pub sensor_id: u16,
    /// Object class code ([`ObjectClass::code`]: 0 car, 1 pedestrian, 2 two-wheeler).
    pub class_code: u8,
    /// 1 when `true_x_m`/`true_y_m` hold the true position, else 0.
    pub truth_valid: u8,
    /// Explicit padding, written as zero.
    pub _pad0: [u8; 4],
}

impl WireMeasurement {
    /// The wire form of `measurement`, with its true position if known.
    pub fn new(measurement: &Measurement, true_position_m: Option<[f64; 2]>) -> Self {
        let [true_x_m, true_y_m] = true_position_m.unwrap_or([0.0, 0.0]);
        Self {
            x_m: measurement.x_m,
            y_m: measurement.y_m,
            vr_mps: measurement.radial_velocity_mps,
            rcs_dbsm: measurement.rcs_dbsm,
            true_x_m,
            true_y_m,
            gt_id: measurement
                .ground_truth_id
                .and_then(|id| i64::try_from(id).ok())
                .unwrap_or(GROUND_TRUTH_UNKNOWN),
            sensor_id: measurement.sensor_id.unwrap_or(SENSOR_UNKNOWN),
            class_code: measurement.class.code(),
            truth_valid: u8::from(true_position_m.is_some()),
            _pad0: [0; 4],
        }
    }

    /// Decodes the measurement; an unknown class code is an error.
    pub fn decode(&self) -> Result<Measurement, UnknownClass> {
        let class = ObjectClass::from_code(self.class_code).ok_or(UnknownClass { code: self.class_code })?;
        Ok(Measurement {
            x_m: self.x_m,
            y_m: self.y_m,
            radial_velocity_mps: self.vr_mps,
            rcs_dbsm: self.rcs_dbsm,
            class,
            sensor_id: (self.sensor_id != SENSOR_UNKNOWN).then_some(self.sensor_id),
            ground_truth_id: u64::try_from(self.gt_id).ok(),
        })
    }

    /// The true position, when the publisher knew it.
    pub fn true_position_m(&self) -> Option<[f64; 2]> {
        (self.truth_valid != 0).then_some([self.true_x_m, self.true_y_m])
    }
}

/// One radar frame: 16 456 bytes, alignment 8.
///
/// `count` comes from another process and is not trusted: [`FrameView::len`] reports it as it
/// is, so that a frame claiming more than [`MEASUREMENT_CAPACITY`] measurements is rejected by
/// the tracker's validation (`FrameError::TooManyMeasurements`) instead of being silently
/// truncated, and slots past the capacity are never read.
#[repr(C)]
#[derive(Debug, ZeroCopySend)]
#[type_name("primm::MeasurementFrame")]
pub struct MeasurementFrame {
    /// Publisher's frame counter, starting at 0 for each publisher.
    pub sequence: u64,
    /// Index of the frame in its recording (the `frame` column of a measurement CSV file);
    /// carried through to the track frame.
    pub source_frame: u64,
    /// Sensor time of the frame, s (the only time the tracker reads).
    pub sensor_timestamp_s: f64,
    /// `CLOCK_MONOTONIC` time at which the publisher sent the frame, ns (0 if unknown).
    pub publish_time_ns: u64,
    /// `CLOCK_MONOTONIC` time at which the publisher was due to send the frame by its schedule
    /// (its pacing), ns; 0 when it sends without a schedule. A publisher that falls behind sends
    /// after this time; latencies measured from it are corrected for coordinated omission.
    pub scheduled_time_ns: u64,
    /// Ego vehicle position in the world frame, m (valid with [`FRAME_FLAG_EGO_VALID`]).
    pub ego_x_m: f64,
    /// Ego vehicle position in the world frame, m (valid with [`FRAME_FLAG_EGO_VALID`]).
    pub ego_y_m: f64,
    /// Ego vehicle heading in the world frame, rad (valid with [`FRAME_FLAG_EGO_VALID`]).
    pub ego_yaw_rad: f64,
    /// Number of valid entries at the start of `measurements`; untrusted.
    pub count: u32,
    /// `FRAME_FLAG_*` bits; unknown bits are ignored.
    pub flags: u32,
    /// The measurements; entries at `count` and beyond are unused.
    pub measurements: [WireMeasurement; MEASUREMENT_CAPACITY],
}

impl MeasurementFrame {
    /// The valid measurements, or `None` when `count` exceeds the capacity.
    pub fn valid_measurements(&self) -> Option<&[WireMeasurement]> {
        self.measurements.get(..self.count as usize)
    }

    /// The ego pose `(x_m, y_m, yaw_rad)` when the frame carries one.
    pub fn ego_pose(&self) -> Option<(f64, f64, f64)> {
        (self.flags & FRAME_FLAG_EGO_VALID != 0).then_some((self.ego_x_m, self.ego_y_m, self.ego_yaw_rad))
    }

    /// A boxed frame with every field zero, for tests and tools that build frames on the heap.
    pub fn boxed_zeroed() -> Box<Self> {
        let mut frame = Box::<Self>::new_uninit();
        // SAFETY: every field is an integer, a float or an array of them, for which the all-zero
        // bit pattern is a valid value.
        unsafe {
            frame.as_mut_ptr().write_bytes(0, 1);
            frame.assume_init()
        }
    }
}

impl FrameView for MeasurementFrame {
    fn timestamp_s(&self) -> f64 {
        self.sensor_timestamp_s
    }

    /// The claimed count, unclamped (see the type's documentation).
    fn len(&self) -> usize {
        self.count as usize
    }

    /// Decodes measurement `index`. Panics (bounds check) rather than reading past the
    /// capacity if a caller ignores `len()`; the tracker validates `len()` first.
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        self.measurements[index].decode()
    }

    /// The pose of the header when [`FRAME_FLAG_EGO_VALID`] is set (the tracker checks it).
    fn ego_pose(&self) -> Option<EgoPose> {
        (self.flags & FRAME_FLAG_EGO_VALID != 0).then_some(EgoPose {
            x_m: self.ego_x_m,
            y_m: self.ego_y_m,
            yaw_rad: self.ego_yaw_rad,
        })
    }
}

/// A frame already holds [`MEASUREMENT_CAPACITY`] measurements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("measurement frame is full ({MEASUREMENT_CAPACITY} measurements)")]
pub struct FrameFull;

/// Fills a [`MeasurementFrame`] in place, e.g. an uninitialised sample loaned from shared
/// memory, writing only the header and the measurements it is given.
#[derive(Debug)]
pub struct MeasurementFrameWriter<'a> {
    frame: &'a mut MaybeUninit<MeasurementFrame>,
    count: usize,
}

impl<'a> MeasurementFrameWriter<'a> {
    /// A writer with no measurement written yet.
    pub fn new(frame: &'a mut MaybeUninit<MeasurementFrame>) -> Self {
        Self { frame, count: 0 }
    }

    /// Appends a measurement.
    pub fn push(&mut self, measurement: WireMeasurement) -> Result<(), FrameFull> {
        if self.count == MEASUREMENT_CAPACITY {
            return Err(FrameFull);
        }
        let frame = self.frame.as_mut_ptr();
        // SAFETY: `frame` points to a live, aligned `MeasurementFrame` allocation and
        // `self.count < MEASUREMENT_CAPACITY`; only raw pointers are formed, no reference to
        // possibly uninitialised memory.
        unsafe {
            addr_of_mut!((*frame).measurements).cast::<WireMeasurement>().add(self.count).write(measurement);
        }
        self.count += 1;
        Ok(())
    }

    /// Measurements written so far.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether no measurement was written.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Writes the header (with `count` set to the measurements written) and returns the count.
    /// The frame's header and first `count` measurements are then initialised.
    pub fn finish(self, header: &MeasurementFrameHeader) -> usize {
        let frame = self.frame.as_mut_ptr();
        let (ego_x_m, ego_y_m, ego_yaw_rad) = header.ego.unwrap_or((0.0, 0.0, 0.0));
        let flags = if header.ego.is_some() {
            header.flags | FRAME_FLAG_EGO_VALID
        } else {
            header.flags & !FRAME_FLAG_EGO_VALID
        };
        // SAFETY: as in `push`: raw field pointers into a live, aligned allocation.
        unsafe {
            addr_of_mut!((*frame).sequence).write(header.sequence);
            addr_of_mut!((*frame).source_frame).write(header.source_frame);
            addr_of_mut!((*frame).sensor_timestamp_s).write(header.sensor_timestamp_s);
            addr_of_mut!((*frame).publish_time_ns).write(header.publish_time_ns);
            addr_of_mut!((*frame).scheduled_time_ns).write(header.scheduled_time_ns);
            addr_of_mut!((*frame).ego_x_m).write(ego_x_m);
            addr_of_mut!((*frame).ego_y_m).write(ego_y_m);
            addr_of_mut!((*frame).ego_yaw_rad).write(ego_yaw_rad);
            addr_of_mut!((*frame).count).write(self.count as u32);
            addr_of_mut!((*frame).flags).write(flags);
        }
        self.count
    }
}

/// The header fields of a [`MeasurementFrame`] other than `count`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeasurementFrameHeader {
    /// See [`MeasurementFrame::sequence`].
    pub sequence: u64,
    /// See [`MeasurementFrame::source_frame`].
    pub source_frame: u64,
    /// See [`MeasurementFrame::sensor_timestamp_s`].
    pub sensor_timestamp_s: f64,
    /// See [`MeasurementFrame::publish_time_ns`].
    pub publish_time_ns: u64,
    /// See [`MeasurementFrame::scheduled_time_ns`].
    pub scheduled_time_ns: u64,
    /// `FRAME_FLAG_*` bits; [`FRAME_FLAG_EGO_VALID`] follows `ego`.
    pub flags: u32,
    /// Ego pose `(x_m, y_m, yaw_rad)`, if known.
    pub ego: Option<(f64, f64, f64)>,
}
