//! `primm::TrackFrame`: the tracker's answer to one measurement frame, written by the tracker
//! straight into a loaned shared-memory sample.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;
use iceoryx2::prelude::ZeroCopySend;
use primm_core::track::TrackOutput;
use primm_core::track_table::MAX_TRACKS;
use primm_core::tracker::StepError;
use primm_core::validation::FrameError;

/// Number of track slots in a [`TrackFrame`]: every track the tracker can hold.
pub const TRACK_CAPACITY: usize = MAX_TRACKS;
const _: () = assert!(TRACK_CAPACITY >= MAX_TRACKS);

/// [`WireTrack::measurement_index`] of a track that coasted (no measurement in this frame).
pub const MEASUREMENT_INDEX_NONE: i32 = -1;

/// [`TrackFrame::flags`] bit: the tracker forgot all tracks before this frame (new stream,
/// new publisher, or a gap longer than `tracker.max_frame_interval_s`).
pub const TRACK_FLAG_TRACKER_RESET: u8 = 1 << 0;
/// [`TrackFrame::flags`] bit: input sequence numbers were skipped before this frame (frames
/// lost upstream or overwritten in the tracker's input buffer).
pub const TRACK_FLAG_SEQUENCE_GAP: u8 = 1 << 1;
/// [`TrackFrame::flags`] bit: the input frame was the last of a finite stream.
pub const TRACK_FLAG_STREAM_END: u8 = 1 << 2;
/// [`TrackFrame::flags`] bit: the input frame was late (older than the newest tracked frame)
/// and was tracked in its place; the tracks are those at `tracks_timestamp_s`, the newest
/// frame's time, and their measurement indices refer to that frame.
pub const TRACK_FLAG_LATE_FRAME: u8 = 1 << 3;
/// [`TrackFrame::flags`] bit: the tracks were predicted from the newest frame to
/// `tracks_timestamp_s` (`primm serve --publish-time now`); they carry no measurement index.
pub const TRACK_FLAG_PREDICTED: u8 = 1 << 4;

/// What the tracker did with an input frame ([`TrackFrame::status`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum FrameStatus {
    /// Tracked; `tracks` holds every live track.
    Tracked = 0,
    /// Rejected: the sensor timestamp is NaN or infinite. No track changed.
    RejectedNonFiniteTimestamp = 1,
    /// Rejected: the sensor timestamp does not advance. No track changed.
    RejectedTimestampNotIncreasing = 2,
    /// Rejected: the interval since the previous frame is too long (the service resets and
    /// tracks such a frame instead, so it does not publish this status).
    RejectedIntervalTooLong = 3,
    /// Rejected: the frame claims more measurements than it can carry. No track changed.
    RejectedTooManyMeasurements = 4,
    /// The association solver failed (a defect); no track changed.
    AssociationFailed = 5,
    /// Rejected: the frame's ego pose is not finite or absurdly far out (only when tracking in
    /// the world frame). No track changed.
    RejectedInvalidEgoPose = 6,
    /// Rejected: the frame is older than the newest tracked frame by more than the late-frame
    /// window reaches (`tracker.max_frame_delay_s`, `tracker.replay_frames`). No track changed.
    RejectedTooLate = 7,
}

impl FrameStatus {
    /// The status code on the wire.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The status of a wire code, `None` for an unknown code.
    pub fn from_code(code: u8) -> Option<Self> {
        [
            Self::Tracked,
            Self::RejectedNonFiniteTimestamp,
            Self::RejectedTimestampNotIncreasing,
            Self::RejectedIntervalTooLong,
            Self::RejectedTooManyMeasurements,
            Self::AssociationFailed,
            Self::RejectedInvalidEgoPose,
            Self::RejectedTooLate,
        ]
        .get(usize::from(code))
        .copied()
    }

    /// The status reporting a failed step.
    pub fn of_error(error: &StepError) -> Self {
        match error {
            StepError::InvalidFrame(FrameError::NonFiniteTimestamp { .. }) => {
                Self::RejectedNonFiniteTimestamp
            }
            StepError::InvalidFrame(FrameError::TimestampNotIncreasing { .. }) => {
                Self::RejectedTimestampNotIncreasing
            }
            StepError::InvalidFrame(FrameError::IntervalTooLong { .. }) => Self::RejectedIntervalTooLong,
            StepError::InvalidFrame(FrameError::TooManyMeasurements { .. }) => {
                Self::RejectedTooManyMeasurements
            }
            StepError::InvalidFrame(FrameError::InvalidEgoPose { .. }) => Self::RejectedInvalidEgoPose,
            StepError::InvalidFrame(FrameError::TooLate { .. }) => Self::RejectedTooLate,
            StepError::Association(_) => Self::AssociationFailed,
        }
    }

    /// Short name (`tracked`, `non_finite_timestamp`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Self::Tracked => "tracked",
            Self::RejectedNonFiniteTimestamp => "non_finite_timestamp",
            Self::RejectedTimestampNotIncreasing => "timestamp_not_increasing",
            Self::RejectedIntervalTooLong => "interval_too_long",
            Self::RejectedTooManyMeasurements => "too_many_measurements",
            Self::AssociationFailed => "association_failed",
            Self::RejectedInvalidEgoPose => "invalid_ego_pose",
            Self::RejectedTooLate => "too_late",
        }
    }
}

/// One track's fused state: 424 bytes, alignment 8.
///
/// When the frame was tracked in the world frame (`world_valid` 1), the position, velocity,
/// covariance and prior are in the vehicle frame of the input frame (the velocity is the
/// velocity over ground in the vehicle's axes) and the `world_*` fields hold the world-frame
/// position, velocity and covariance; otherwise everything is in the vehicle frame and
/// `world_*` are 0.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("primm::WireTrack")]
pub struct WireTrack {
    /// Track id, unique within one tracker run.
    pub id: u64,
    /// Fused posterior position, m.
    pub x_m: f64,
    /// Fused posterior position, m.
    pub y_m: f64,
    /// Fused velocity, m/s.
    pub vx_mps: f64,
    /// Fused velocity, m/s.
    pub vy_mps: f64,
    /// Covariance of `[x, y, vx, vy]`, row-major 4×4 (m², m²/s, m²/s²); its upper-left 2×2
    /// block is the position covariance.
    pub state_covariance: [f64; 16],
    /// Fused one-step prior used for association, m (valid when `prior_valid` is 1).
    pub prior_x_m: f64,
    /// Fused one-step prior used for association, m (valid when `prior_valid` is 1).
    pub prior_y_m: f64,
    /// Posterior mode probabilities, order PR, CV, CA, CT (inactive modes 0).
    pub mode_probabilities: [f64; 4],
    /// Fused position in the world frame, m (valid when `world_valid` is 1).
    pub world_x_m: f64,
    /// Fused position in the world frame, m (valid when `world_valid` is 1).
    pub world_y_m: f64,
    /// Fused velocity over ground in the world frame, m/s (valid when `world_valid` is 1).
    pub world_vx_mps: f64,
    /// Fused velocity over ground in the world frame, m/s (valid when `world_valid` is 1).
    pub world_vy_mps: f64,
    /// Covariance of the world-frame `[x, y, vx, vy]`, row-major 4×4 (valid when `world_valid`
    /// is 1).
    pub world_state_covariance: [f64; 16],
    /// Probability that the track's object exists, in (0, 1).
    pub existence_probability: f64,
    /// Time since the track's first measurement, s.
    pub age_s: f64,
    /// Ground-truth id of the measurement that updated or started the track in this frame;
    /// -1 when none (coasting, or no ground truth).
    pub gt_id: i64,
    /// Frames since the track started.
    pub age_frames: u32,
    /// Associated measurements so far.
    pub hits: u32,
    /// Consecutive frames without a measurement.
    pub misses: u32,
    /// Index in the input frame of the measurement that updated or started the track;
    /// [`MEASUREMENT_INDEX_NONE`] when it coasted.
    pub measurement_index: i32,
    /// Object class code (0 car, 1 pedestrian, 2 two-wheeler).
    pub class_code: u8,
    /// Lifecycle status (0 tentative, 1 confirmed, 2 coasting: confirmed but missed the last
    /// time a sensor had it in view).
    pub status: u8,
    /// 1 when `prior_x_m`/`prior_y_m` are valid (0 for a track started in this frame).
    pub prior_valid: u8,
    /// 1 when the `world_*` fields are valid (the frame was tracked in the world frame).
    pub world_valid: u8,
    /// Explicit padding, written as zero.
    pub _pad0: [u8; 4],
}

/// A 4×4 matrix as 16 values, row-major.
#[inline]
pub fn row_major(matrix: &glam::DMat4) -> [f64; 16] {
    matrix.transpose().to_cols_array()
}

impl WireTrack {
    /// The wire form of a tracker output.
    #[inline]
    pub fn from_output(output: &TrackOutput) -> Self {
        let prior = output.prior_position_m;
        let (world_position, world_velocity) = match (output.world_position_m, output.world_velocity_mps) {
            (Some(position), Some(velocity)) => (Some(position), Some(velocity)),
            _ => (None, None),
        };
        Self {
            id: output.id,
            x_m: output.position_m.x,
            y_m: output.position_m.y,
            state_covariance: row_major(&output.state_covariance),
            vx_mps: output.velocity_mps.x,
            vy_mps: output.velocity_mps.y,
            prior_x_m: prior.map_or(0.0, |p| p.x),
            prior_y_m: prior.map_or(0.0, |p| p.y),
            mode_probabilities: output.mode_probabilities,
            world_x_m: world_position.map_or(0.0, |p| p.x),
            world_y_m: world_position.map_or(0.0, |p| p.y),
            world_vx_mps: world_velocity.map_or(0.0, |v| v.x),
            world_vy_mps: world_velocity.map_or(0.0, |v| v.y),
            world_state_covariance: match (world_position, output.world_state_covariance) {
                (Some(_), Some(covariance)) => row_major(&covariance),
                _ => [0.0; 16],
            },
            existence_probability: output.existence_probability,
            age_s: output.age_s,
            gt_id: output.ground_truth_id.and_then(|id| i64::try_from(id).ok()).unwrap_or(-1),
            age_frames: output.age_frames,
            hits: output.hits,
            misses: output.misses,
            measurement_index: output.measurement_index.map_or(MEASUREMENT_INDEX_NONE, i32::from),
            class_code: output.class.code(),
            status: output.status as u8,
            prior_valid: u8::from(prior.is_some()),
            world_valid: u8::from(world_position.is_some()),
            _pad0: [0; 4],
        }
    }

    /// The prior position, when valid.
    pub fn prior_m(&self) -> Option<[f64; 2]> {
        (self.prior_valid != 0).then_some([self.prior_x_m, self.prior_y_m])
    }

    /// The world-frame position and velocity `[x, y, vx, vy]`, when valid.
    pub fn world(&self) -> Option<[f64; 4]> {
        (self.world_valid != 0).then_some([
            self.world_x_m,
            self.world_y_m,
            self.world_vx_mps,
            self.world_vy_mps,
        ])
    }

    /// The position covariance `[xx, xy, yx, yy]`, m² (the upper-left block of
    /// `state_covariance`).
    pub fn position_covariance_m2(&self) -> [f64; 4] {
        let c = &self.state_covariance;
        [c[0], c[1], c[4], c[5]]
    }

    /// The measurement index, `None` when the track coasted.
    pub fn measurement_index(&self) -> Option<usize> {
        usize::try_from(self.measurement_index).ok()
    }
}

/// The tracker's output for one input frame: 217 168 bytes, alignment 8.
#[repr(C)]
#[derive(Debug, ZeroCopySend)]
#[type_name("primm::TrackFrame")]
pub struct TrackFrame {
    /// `sequence` of the input measurement frame.
    pub input_sequence: u64,
    /// `source_frame` of the input frame (its index in the recording).
    pub source_frame: u64,
    /// Sensor time of the input frame, s.
    pub sensor_timestamp_s: f64,
    /// The time the tracks describe, s on the sensor clock: the input frame's time, the newest
    /// tracked frame's after a late frame ([`TRACK_FLAG_LATE_FRAME`]), or the publish time the
    /// tracks were predicted to ([`TRACK_FLAG_PREDICTED`]).
    pub tracks_timestamp_s: f64,
    /// `publish_time_ns` of the input frame (publisher send time), `CLOCK_MONOTONIC` ns.
    pub input_publish_time_ns: u64,
    /// `scheduled_time_ns` of the input frame (when its publisher was due to send it), ns; 0
    /// when it was sent without a schedule.
    pub input_scheduled_time_ns: u64,
    /// When the tracker took the input frame from its buffer, `CLOCK_MONOTONIC` ns.
    pub receive_time_ns: u64,
    /// When the tracker sent this frame, `CLOCK_MONOTONIC` ns.
    pub publish_time_ns: u64,
    /// Number of valid entries at the start of `tracks`.
    pub count: u32,
    /// [`FrameStatus`] code.
    pub status: u8,
    /// `TRACK_FLAG_*` bits.
    pub flags: u8,
    /// Measurements of the input frame accepted by validation.
    pub measurements_accepted: u16,
    /// Measurements of the input frame rejected by validation (unknown class, NaN, out of range).
    pub measurements_rejected: u16,
    /// [`WIRE_VERSION`](crate::WIRE_VERSION) of the writer.
    pub wire_version: u16,
    /// Explicit padding, written as zero.
    pub _pad0: [u8; 4],
    /// Every live track after the frame; entries at `count` and beyond are unused.
    pub tracks: [WireTrack; TRACK_CAPACITY],
}

impl TrackFrame {
    /// The valid tracks (`count` is clamped to the capacity: a track frame comes from the
    /// tracker, but a reader should not trust shared memory blindly).
    pub fn valid_tracks(&self) -> &[WireTrack] {
        &self.tracks[..(self.count as usize).min(TRACK_CAPACITY)]
    }

    /// The frame status, `None` for an unknown code.
    pub fn frame_status(&self) -> Option<FrameStatus> {
        FrameStatus::from_code(self.status)
    }
}

/// The header fields of a [`TrackFrame`] other than `count`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackFrameHeader {
    /// See [`TrackFrame::input_sequence`].
    pub input_sequence: u64,
    /// See [`TrackFrame::source_frame`].
    pub source_frame: u64,
    /// See [`TrackFrame::sensor_timestamp_s`].
    pub sensor_timestamp_s: f64,
    /// See [`TrackFrame::tracks_timestamp_s`].
    pub tracks_timestamp_s: f64,
    /// See [`TrackFrame::input_publish_time_ns`].
    pub input_publish_time_ns: u64,
    /// See [`TrackFrame::input_scheduled_time_ns`].
    pub input_scheduled_time_ns: u64,
    /// See [`TrackFrame::receive_time_ns`].
    pub receive_time_ns: u64,
    /// See [`TrackFrame::publish_time_ns`].
    pub publish_time_ns: u64,
    /// See [`TrackFrame::status`].
    pub status: FrameStatus,
    /// See [`TrackFrame::flags`].
    pub flags: u8,
    /// See [`TrackFrame::measurements_accepted`].
    pub measurements_accepted: u16,
    /// See [`TrackFrame::measurements_rejected`].
    pub measurements_rejected: u16,
}

/// Fills a [`TrackFrame`] in place (an uninitialised sample loaned from shared memory): each
/// pushed output is converted straight into its slot; nothing is collected elsewhere.
#[derive(Debug)]
pub struct TrackFrameWriter<'a> {
    frame: &'a mut MaybeUninit<TrackFrame>,
    count: usize,
    overflowed: usize,
}

impl<'a> TrackFrameWriter<'a> {
    /// A writer with no track written yet.
    pub fn new(frame: &'a mut MaybeUninit<TrackFrame>) -> Self {
        Self { frame, count: 0, overflowed: 0 }
    }

    /// Writes `output` into the next slot. Outputs beyond [`TRACK_CAPACITY`] cannot occur with
    /// the tracker's table size; they would be counted in [`overflowed`](Self::overflowed) and
    /// dropped.
    #[inline]
    pub fn push(&mut self, output: &TrackOutput) {
        if self.count == TRACK_CAPACITY {
            self.overflowed += 1;
            return;
        }
        let frame = self.frame.as_mut_ptr();
        // SAFETY: `frame` points to a live, aligned `TrackFrame` allocation and
        // `self.count < TRACK_CAPACITY`; only raw pointers are formed.
        unsafe {
            addr_of_mut!((*frame).tracks)
                .cast::<WireTrack>()
                .add(self.count)
                .write(WireTrack::from_output(output));
        }
        self.count += 1;
    }

    /// Forgets the tracks written so far (e.g. before resubmitting a frame after a reset).
    pub fn clear(&mut self) {
        self.count = 0;
        self.overflowed = 0;
    }

    /// Tracks written so far.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether no track was written.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Outputs dropped because the frame was full.
    pub fn overflowed(&self) -> usize {
        self.overflowed
    }

    /// Writes the header, `count` and padding; the header and the first `count` tracks are then
    /// initialised. Returns `count`.
    pub fn finish(self, header: &TrackFrameHeader) -> usize {
        let frame = self.frame.as_mut_ptr();
        // SAFETY: raw field pointers into a live, aligned allocation.
        unsafe {
            addr_of_mut!((*frame).input_sequence).write(header.input_sequence);
            addr_of_mut!((*frame).source_frame).write(header.source_frame);
            addr_of_mut!((*frame).sensor_timestamp_s).write(header.sensor_timestamp_s);
            addr_of_mut!((*frame).tracks_timestamp_s).write(header.tracks_timestamp_s);
            addr_of_mut!((*frame).input_publish_time_ns).write(header.input_publish_time_ns);
            addr_of_mut!((*frame).input_scheduled_time_ns).write(header.input_scheduled_time_ns);
            addr_of_mut!((*frame).receive_time_ns).write(header.receive_time_ns);
            addr_of_mut!((*frame).publish_time_ns).write(header.publish_time_ns);
            addr_of_mut!((*frame).count).write(self.count as u32);
            addr_of_mut!((*frame).status).write(header.status.code());
            addr_of_mut!((*frame).flags).write(header.flags);
            addr_of_mut!((*frame).measurements_accepted).write(header.measurements_accepted);
            addr_of_mut!((*frame).measurements_rejected).write(header.measurements_rejected);
            addr_of_mut!((*frame).wire_version).write(crate::WIRE_VERSION);
            addr_of_mut!((*frame)._pad0).write([0; 4]);
        }
        self.count
    }
}
