//! Target `ego_pose_frames`: measurement frames with ego poses as a publisher writes them
//! ([`MeasurementFrameWriter`]), through the service's frame path
//! ([`primm_service::frame_step`]) into a track frame ([`TrackFrameWriter`]).
//!
//! The ego vehicle drives, jumps (odometry reset), turns its yaw by whole turns, or reports
//! raw values (NaN, infinite, beyond [`MAX_EGO_POSITION_M`]); it sees a few objects fixed in
//! the world, whose positions reach it in its own frame. After every frame the target checks:
//!
//! * the tracker's invariants;
//! * a pose that is not valid rejects the frame with [`FrameStatus::RejectedInvalidEgoPose`]
//!   and leaves the tracker exactly as it was (its tracks and the number of frames tracked);
//! * a valid pose with an advancing time tracks the frame, and every track written with a
//!   world estimate is the same point in both frames: its vehicle-frame position moved by the
//!   frame's pose is its world position;
//! * a frame without a pose writes no world estimate, unless the tracker had found its sensors
//!   standing still (`frame.platform = "auto"`) when the frame came: the frame is then tracked
//!   in the world frame at the origin, and every world estimate is its vehicle-frame position.
//!
//! [`MAX_EGO_POSITION_M`]: primm_core::pose::MAX_EGO_POSITION_M

use crate::invariant_check::assert_tracker_invariants;
use primm_core::config::Config;
use primm_core::measurement::{Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::stage_timing::NoObserver;
use primm_core::tracker::{StepError, Tracker};
use primm_core::validation::FrameError;
use primm_service::frame_step::{starts_stream, step_received_frame};
use primm_wire::{
    FrameStatus, MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, TrackFrame,
    TrackFrameHeader, TrackFrameWriter, WireMeasurement, FRAME_FLAG_STREAM_START,
};
use std::f64::consts::TAU;

/// Most frames one input is turned into.
pub const MAX_FRAMES: usize = 48;

/// Objects fixed in the world, `(x_m, y_m)`, seen by the ego vehicle.
const WORLD_OBJECTS: [(f64, f64); 3] = [(30.0, 4.0), (18.0, -6.0), (45.0, 12.0)];

/// Where the ego vehicle is in one frame.
#[derive(Debug, Clone, Copy)]
enum PoseStep {
    /// Drives on: `forward_cm` along its heading, then turns by `turn_mrad`.
    Drive { forward_cm: i16, turn_mrad: i16 },
    /// Odometry jumps or resets to a new place, mm (up to ±2.1e6 m).
    Jump { x_mm: i32, y_mm: i32 },
    /// The same heading reported `turns` whole turns away (yaw wrapping).
    Wrap { turns: i8 },
    /// Raw values, NaN, infinite and far out included.
    Raw { x_m: f64, y_m: f64, yaw_rad: f64 },
    /// No pose in this frame.
    Missing,
}

/// One frame of the input.
#[derive(Debug, Clone, Copy)]
struct PoseFrame {
    /// Time since the previous frame, ms (0 is a frame that does not advance).
    advance_ms: u8,
    pose: PoseStep,
    /// How many of the world objects the frame carries (0 to 3).
    objects: usize,
    /// Whether the frame starts a new stream.
    stream_start: bool,
}

/// Reads one frame record: `advance_ms: u8`, a control byte (bits 0–2: the pose kind, mod 5,
/// in the order of [`PoseStep`]; bits 3–4: the number of objects; bit 5: stream start), then
/// the kind's little-endian fields (`i16 i16`, `i32 i32`, `i8`, `f64 f64 f64`, nothing).
/// `None` when the input ends before the record does.
fn read_frame(input: &mut &[u8]) -> Option<PoseFrame> {
    let [advance_ms, control] = *take::<2>(input)?;
    let pose = match (control & 0b111) % 5 {
        0 => PoseStep::Drive {
            forward_cm: i16::from_le_bytes(*take(input)?),
            turn_mrad: i16::from_le_bytes(*take(input)?),
        },
        1 => PoseStep::Jump {
            x_mm: i32::from_le_bytes(*take(input)?),
            y_mm: i32::from_le_bytes(*take(input)?),
        },
        2 => PoseStep::Wrap { turns: i8::from_le_bytes(*take(input)?) },
        3 => PoseStep::Raw {
            x_m: f64::from_le_bytes(*take(input)?),
            y_m: f64::from_le_bytes(*take(input)?),
            yaw_rad: f64::from_le_bytes(*take(input)?),
        },
        _ => PoseStep::Missing,
    };
    Some(PoseFrame {
        advance_ms,
        pose,
        objects: usize::from((control >> 3) & 0b11),
        stream_start: control & 0b10_0000 != 0,
    })
}

/// The next `N` bytes of `input`, consumed.
fn take<'a, const N: usize>(input: &mut &'a [u8]) -> Option<&'a [u8; N]> {
    let (head, tail) = input.split_first_chunk::<N>()?;
    *input = tail;
    Some(head)
}

/// Turns `data` into up to [`MAX_FRAMES`] frames and puts each through the service's path.
/// Each frame is a record: `advance_ms: u8`, a control byte (bits 0–2: the pose kind, mod 5:
/// drive, jump, whole turns, raw, none; bits 3–4: the number of objects; bit 5: stream start),
/// then the kind's little-endian fields (`i16` cm and `i16` mrad; `i32` mm twice; `i8` turns;
/// `f64` x, y and yaw; nothing).
pub fn run(data: &[u8]) {
    let mut input = data;
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes()))
        .expect("the default configuration is valid");
    let mut frame = Box::<MeasurementFrame>::new_uninit();
    let mut answer = Box::<TrackFrame>::new_zeroed();
    let mut timestamp_s = 0.0;
    let mut pose = EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 };
    for sequence in 0..MAX_FRAMES as u64 {
        let Some(step) = read_frame(&mut input) else { break };
        timestamp_s += f64::from(step.advance_ms) * 1e-3;
        let reported = next_pose(&mut pose, &step.pose);
        write_frame(&mut frame, sequence, timestamp_s, &pose, reported, &step);
        // SAFETY: `write_frame` initialised the header and the first `count` measurements; the
        // rest of the array is never read (the tracker reads `count` entries, bounded by the
        // capacity), and every field is a plain number.
        let frame = unsafe { frame.assume_init_ref() };
        receive(&mut tracker, frame, &mut answer, reported, step.advance_ms);
    }
}

/// Moves the ego vehicle by `step` and returns the pose the frame reports.
fn next_pose(pose: &mut EgoPose, step: &PoseStep) -> Option<EgoPose> {
    match *step {
        PoseStep::Drive { forward_cm, turn_mrad } => {
            let forward_m = f64::from(forward_cm) * 0.01;
            pose.x_m += forward_m * pose.yaw_rad.cos();
            pose.y_m += forward_m * pose.yaw_rad.sin();
            pose.yaw_rad = (pose.yaw_rad + f64::from(turn_mrad) * 1e-3) % TAU;
            Some(*pose)
        }
        PoseStep::Jump { x_mm, y_mm } => {
            pose.x_m = f64::from(x_mm) * 1e-3;
            pose.y_m = f64::from(y_mm) * 1e-3;
            Some(*pose)
        }
        PoseStep::Wrap { turns } => Some(EgoPose { yaw_rad: pose.yaw_rad + f64::from(turns) * TAU, ..*pose }),
        PoseStep::Raw { x_m, y_m, yaw_rad } => Some(EgoPose { x_m, y_m, yaw_rad }),
        PoseStep::Missing => None,
    }
}

/// Writes the frame as a publisher does: the objects as the vehicle at `actual` sees them, the
/// `reported` pose in the header.
fn write_frame(
    frame: &mut std::mem::MaybeUninit<MeasurementFrame>,
    sequence: u64,
    timestamp_s: f64,
    actual: &EgoPose,
    reported: Option<EgoPose>,
    step: &PoseFrame,
) {
    let mut writer = MeasurementFrameWriter::new(frame);
    let seen_from = actual;
    let (sin, cos) = seen_from.yaw_rad.sin_cos();
    for (index, (world_x_m, world_y_m)) in WORLD_OBJECTS.iter().take(step.objects).enumerate() {
        let (dx, dy) = (world_x_m - seen_from.x_m, world_y_m - seen_from.y_m);
        let measurement = Measurement {
            x_m: cos * dx + sin * dy,
            y_m: -sin * dx + cos * dy,
            radial_velocity_mps: 0.0,
            rcs_dbsm: 10.0,
            class: ObjectClass::Car,
            sensor_id: Some(0),
            ground_truth_id: Some(index as u64),
        };
        writer.push(WireMeasurement::new(&measurement, None)).expect("a few measurements fit");
    }
    let flags = if step.stream_start { FRAME_FLAG_STREAM_START } else { 0 };
    writer.finish(&MeasurementFrameHeader {
        sequence,
        source_frame: sequence,
        sensor_timestamp_s: timestamp_s,
        publish_time_ns: 0,
        scheduled_time_ns: 0,
        flags,
        ego: reported.map(|pose| (pose.x_m, pose.y_m, pose.yaw_rad)),
    });
}

/// The tracks as text, to compare states exactly (NaN priors compare unequal as numbers).
fn snapshot(tracker: &Tracker<primm_core::predictor::NoPredictor>) -> String {
    format!("{:?}", tracker.tracks())
}

/// Puts one frame through the service's path and checks what came out.
fn receive(
    tracker: &mut Tracker<primm_core::predictor::NoPredictor>,
    frame: &MeasurementFrame,
    answer: &mut Box<std::mem::MaybeUninit<TrackFrame>>,
    pose: Option<EgoPose>,
    advance_ms: u8,
) {
    if starts_stream(frame) {
        tracker.reset();
    }
    let before = snapshot(tracker);
    let frames_before = tracker.stats().frames_tracked;
    // What a frame without a pose is taken as is decided when the frame comes.
    let stationary = tracker.config().frame.platform.stationary(tracker.sensors().platform());
    let mut writer = Some(TrackFrameWriter::new(answer));
    let stepped = step_received_frame(tracker, frame, &mut NoObserver, &mut writer);
    let status = stepped.result.as_ref().map_or_else(FrameStatus::of_error, |_| FrameStatus::Tracked);
    let count = writer.take().expect("the writer is kept").finish(&TrackFrameHeader {
        input_sequence: frame.sequence,
        source_frame: frame.source_frame,
        sensor_timestamp_s: frame.sensor_timestamp_s,
        tracks_timestamp_s: tracker.newest_timestamp_s().unwrap_or(frame.sensor_timestamp_s),
        input_publish_time_ns: 0,
        input_scheduled_time_ns: 0,
        receive_time_ns: 0,
        publish_time_ns: 0,
        status,
        flags: 0,
        measurements_accepted: 0,
        measurements_rejected: 0,
    });
    assert_tracker_invariants(tracker, "ego pose frames");

    if pose.is_some_and(|pose| !pose.is_valid()) {
        assert!(
            matches!(stepped.result, Err(StepError::InvalidFrame(FrameError::InvalidEgoPose { .. }))),
            "an invalid pose {pose:?} gave {:?}",
            stepped.result
        );
        assert_eq!(status, FrameStatus::RejectedInvalidEgoPose);
        assert_eq!(snapshot(tracker), before, "a frame with an invalid pose changed the tracks");
        assert_eq!(tracker.stats().frames_tracked, frames_before);
        return;
    }
    if let Err(error) = &stepped.result {
        // With a valid pose (or none) only a time that does not advance rejects the frame: the
        // times only grow, and the service path bridges a long gap with a reset.
        assert!(
            advance_ms == 0
                && matches!(error, StepError::InvalidFrame(FrameError::TimestampNotIncreasing { .. })),
            "a frame with a valid pose {pose:?}, {advance_ms} ms after the last, was rejected: {error}"
        );
        assert_eq!(snapshot(tracker), before, "a rejected frame changed the tracks");
        return;
    }
    // SAFETY: the answer started zeroed (every field of a `TrackFrame` is a plain number, for
    // which zero bytes are a valid value) and the writer wrote only whole values into it.
    let answer = unsafe { answer.assume_init_ref() };
    assert_eq!(answer.count as usize, count);
    for track in answer.valid_tracks() {
        check_world_estimate(track, pose, stationary);
    }
}

/// A written track's position is finite, and its world estimate is where the frame's pose puts
/// its vehicle-frame position: with a pose, always present; without one, present only when the
/// sensors were found `stationary` as the frame came (the frame is then at the world origin).
fn check_world_estimate(track: &primm_wire::WireTrack, pose: Option<EgoPose>, stationary: bool) {
    assert!(track.x_m.is_finite() && track.y_m.is_finite(), "a track with a non-finite position: {track:?}");
    let Some([world_x_m, world_y_m, _, _]) = track.world() else {
        assert!(pose.is_none(), "a track tracked with a valid pose has no world estimate: {track:?}");
        return;
    };
    let frame_pose = pose.unwrap_or_else(|| {
        assert!(stationary, "a world estimate without a pose, the sensors not found standing: {track:?}");
        EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 }
    });
    let (sin, cos) = frame_pose.yaw_rad.sin_cos();
    let moved_x_m = frame_pose.x_m + cos * track.x_m - sin * track.y_m;
    let moved_y_m = frame_pose.y_m + sin * track.x_m + cos * track.y_m;
    let scale = 1.0 + frame_pose.x_m.abs().max(frame_pose.y_m.abs()) + track.x_m.abs().max(track.y_m.abs());
    let difference = (moved_x_m - world_x_m).abs().max((moved_y_m - world_y_m).abs());
    assert!(
        difference <= 1e-9 * scale,
        "vehicle and world positions disagree by {difference} m: pose {frame_pose:?}, track {track:?}"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame record of [`read_frame`].
    fn record(advance_ms: u8, kind: u8, objects: u8, payload: &[u8]) -> Vec<u8> {
        let mut bytes = vec![advance_ms, kind | (objects << 3)];
        bytes.extend_from_slice(payload);
        bytes
    }

    #[test]
    fn records_decode_as_documented() {
        let data = record(50, 1, 2, &[1, 0, 0, 0, 0xff, 0xff, 0xff, 0xff]);
        let frame = read_frame(&mut &data[..]).unwrap();
        assert_eq!(frame.advance_ms, 50);
        assert_eq!(frame.objects, 2);
        assert!(!frame.stream_start);
        assert!(matches!(frame.pose, PoseStep::Jump { x_mm: 1, y_mm: -1 }));
        assert!(read_frame(&mut &data[..5]).is_none(), "a cut record is the end");
    }

    #[test]
    fn driving_wrapping_jumping_and_missing_poses_are_tracked_and_a_nan_pose_is_rejected() {
        let drive = [0xe8, 0x03, 0x0a, 0x00]; // 10 m forward, 10 mrad left
        let mut data = Vec::new();
        for _ in 0..4 {
            data.extend(record(50, 0, 3, &drive));
        }
        data.extend(record(50, 2, 3, &[3])); // three whole turns
        data.extend(record(50, 1, 3, &[0x40, 0x42, 0x0f, 0x00, 0x00, 0x00, 0x00, 0x00])); // jump to 1 km
        let nan_pose: Vec<u8> = [f64::NAN, 0.0, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        data.extend(record(50, 3, 3, &nan_pose));
        let far_pose: Vec<u8> = [2.0e7f64, 0.0, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        data.extend(record(50, 3, 3, &far_pose));
        data.extend(record(0, 0, 3, &drive)); // does not advance
        data.extend(record(50, 4, 3, &[])); // no pose
        for _ in 0..3 {
            data.extend(record(50, 0, 3, &drive));
        }
        run(&data);
    }
}
