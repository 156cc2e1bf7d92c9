//! `primm track --mcap FILE`: the offline run written as a recording, the same topics as
//! `primm record` writes from the service (with no latencies: nothing crossed a process), the
//! ground truth of the measurement file included.

use primm_core::predictor::DisplacementPredictor;
use primm_core::track::TrackOutput;
use primm_core::tracker::{StepError, StepSummary, Tracker};
use primm_record::transforms::RadarPose;
use primm_record::{FrameEncoder, McapFile, McapFileError, SinkError};
use primm_sim::io::RecordedFrame;
use primm_wire::{
    FrameStatus, MeasurementFrame, MeasurementFrameHeader, MeasurementFrameWriter, TrackFrame,
    TrackFrameHeader, TrackFrameWriter, WireMeasurement, FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START,
    TRACK_FLAG_LATE_FRAME, TRACK_FLAG_STREAM_END, TRACK_FLAG_TRACKER_RESET,
};
use std::mem::MaybeUninit;
use std::path::Path;

/// What the tracker made of one frame, for the recording.
#[derive(Debug)]
pub struct StepRecord<'a> {
    /// The tracker's outputs (empty when the frame was rejected).
    pub outputs: &'a [TrackOutput],
    /// The step's counts.
    pub step: Option<&'a StepSummary>,
    /// The frame's status.
    pub status: FrameStatus,
    /// The time the outputs describe, s.
    pub tracks_timestamp_s: f64,
    /// Whether the frame was late (tracked in its place).
    pub late: bool,
}

/// An offline run being written as an MCAP recording.
#[derive(Debug)]
pub struct OfflineRecording {
    file: McapFile,
    encoder: FrameEncoder,
    measurements: Box<MaybeUninit<MeasurementFrame>>,
    tracks: Box<MaybeUninit<TrackFrame>>,
    sequence: u64,
    frames: u64,
}

impl OfflineRecording {
    /// Creates `path` for a run of `frames` frames.
    pub fn create(path: &Path, radars: Vec<RadarPose>, frames: usize) -> Result<Self, McapFileError> {
        Ok(Self {
            file: McapFile::create(path)?,
            encoder: FrameEncoder::new(radars),
            measurements: Box::new_zeroed(),
            tracks: Box::new_zeroed(),
            sequence: 0,
            frames: frames as u64,
        })
    }

    /// Writes a frame the tracker took and its answer (the tracker's latest outputs).
    pub fn write_tracked<P: DisplacementPredictor>(
        &mut self,
        recorded: &RecordedFrame,
        tracker: &Tracker<P>,
    ) -> Result<(), SinkError> {
        let answer = StepRecord {
            outputs: tracker.last_outputs(),
            step: Some(tracker.last_step()),
            status: FrameStatus::Tracked,
            tracks_timestamp_s: tracker.newest_timestamp_s().unwrap_or(recorded.timestamp_s),
            late: tracker.last_step().late(),
        };
        self.write(recorded, &answer)
    }

    /// Writes a frame the tracker refused, answered with no tracks and the refusal's status.
    pub fn write_rejected(&mut self, recorded: &RecordedFrame, error: &StepError) -> Result<(), SinkError> {
        let status = FrameStatus::of_error(error);
        let answer = StepRecord {
            outputs: &[],
            step: None,
            status,
            tracks_timestamp_s: recorded.timestamp_s,
            late: false,
        };
        self.write(recorded, &answer)
    }

    /// Writes one recorded frame and the tracker's answer to it.
    fn write(&mut self, recorded: &RecordedFrame, answer: &StepRecord<'_>) -> Result<(), SinkError> {
        let first = self.sequence == 0;
        let last = self.sequence + 1 == self.frames;
        let mut writer = MeasurementFrameWriter::new(&mut self.measurements);
        for measurement in &recorded.measurements {
            let mut decoded = measurement.measurement;
            if decoded.sensor_id.is_none() {
                decoded.sensor_id = recorded.sensor_id;
            }
            // The tracker took the frame, so it fits.
            let _ =
                writer.push(WireMeasurement::new(&decoded, measurement.true_position.map(|p| [p.x, p.y])));
        }
        let mut flags = 0;
        if first {
            flags |= FRAME_FLAG_STREAM_START;
        }
        if last {
            flags |= FRAME_FLAG_STREAM_END;
        }
        writer.finish(&MeasurementFrameHeader {
            sequence: self.sequence,
            source_frame: recorded.index,
            sensor_timestamp_s: recorded.timestamp_s,
            flags,
            ego: recorded.ego_pose.map(|pose| (pose.x_m, pose.y_m, pose.yaw_rad)),
            ..Default::default()
        });
        // SAFETY: the buffer started zeroed (plain data) and the writer wrote the header and
        // the measurements.
        let measurements = unsafe { self.measurements.assume_init_ref() };
        self.encoder.on_measurements(measurements, &mut self.file)?;
        self.write_tracks(recorded, answer, first, last)?;
        self.sequence += 1;
        Ok(())
    }

    /// Writes the track frame answering the current measurement frame.
    fn write_tracks(
        &mut self,
        recorded: &RecordedFrame,
        answer: &StepRecord<'_>,
        first: bool,
        last: bool,
    ) -> Result<(), SinkError> {
        let mut writer = TrackFrameWriter::new(&mut self.tracks);
        for output in answer.outputs {
            writer.push(output);
        }
        let saturating = |count: u64| u16::try_from(count).unwrap_or(u16::MAX);
        let mut flags = 0;
        if first {
            flags |= TRACK_FLAG_TRACKER_RESET;
        }
        if last {
            flags |= TRACK_FLAG_STREAM_END;
        }
        if answer.late {
            flags |= TRACK_FLAG_LATE_FRAME;
        }
        writer.finish(&TrackFrameHeader {
            input_sequence: self.sequence,
            source_frame: recorded.index,
            sensor_timestamp_s: recorded.timestamp_s,
            tracks_timestamp_s: answer.tracks_timestamp_s,
            input_publish_time_ns: 0,
            input_scheduled_time_ns: 0,
            receive_time_ns: 0,
            publish_time_ns: 0,
            status: answer.status,
            flags,
            measurements_accepted: answer
                .step
                .map_or(0, |step| saturating(step.counts.measurements_accepted)),
            measurements_rejected: answer.step.map_or(0, |step| saturating(step.measurements_rejected())),
        });
        // SAFETY: as for the measurements: zeroed plain data, header and tracks written.
        let tracks = unsafe { self.tracks.assume_init_ref() };
        self.encoder.on_tracks(tracks, &mut self.file)
    }

    /// Finishes the file.
    pub fn finish(self) -> Result<(), McapFileError> {
        self.file.finish()
    }
}
