//! Track frames received from the service as rows of the track file format of
//! [`primm_sim::io::track_csv`], written by its [`TrackCsvWriter`].

use primm_core::measurement::ObjectClass;
use primm_core::track::TrackStatus;
use primm_sim::io::track_csv::{TrackCsvWriter, TrackRow};
use primm_wire::{FrameStatus, TrackFrame, TRACK_FLAG_LATE_FRAME, TRACK_FLAG_PREDICTED};
use std::io::Write;

/// Writes the rows of one received track frame to `csv`: one per track updated by a measurement,
/// none for a rejected frame, a late frame (its tracks are those of a newer frame) or tracks
/// predicted to the publish time (they carry no measurement).
pub fn write_track_frame<W: Write>(csv: &mut TrackCsvWriter<W>, frame: &TrackFrame) -> std::io::Result<()> {
    if frame.frame_status() != Some(FrameStatus::Tracked)
        || frame.flags & (TRACK_FLAG_LATE_FRAME | TRACK_FLAG_PREDICTED) != 0
    {
        return Ok(());
    }
    for track in frame.valid_tracks().iter().filter(|track| track.measurement_index().is_some()) {
        let class_code = track.class_code.to_string();
        let class = match ObjectClass::from_code(track.class_code) {
            Some(class) => class.name(),
            None => class_code.as_str(),
        };
        let status_code = track.status.to_string();
        let status = match TrackStatus::from_code(track.status) {
            Some(status) => status.name(),
            None => status_code.as_str(),
        };
        csv.write(&TrackRow {
            frame: frame.source_frame,
            timestamp_s: frame.sensor_timestamp_s,
            track_id: track.id,
            class,
            position_m: [track.x_m, track.y_m],
            prior_position_m: track.prior_m(),
            ground_truth_id: u64::try_from(track.gt_id).ok(),
            mode_probabilities: track.mode_probabilities,
            status,
            existence_probability: track.existence_probability,
            velocity_mps: [track.vx_mps, track.vy_mps],
            age_s: track.age_s,
            state_covariance: track.state_covariance,
            world: track.world().map(|world| (world, track.world_state_covariance)),
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_core::config::Config;
    use primm_core::measurement::{Frame, Measurement};
    use primm_core::tracker::Tracker;
    use primm_wire::{TrackFrameHeader, TrackFrameWriter};
    use std::mem::MaybeUninit;

    fn header(frame: u64, timestamp_s: f64, status: FrameStatus) -> TrackFrameHeader {
        TrackFrameHeader {
            input_sequence: frame,
            source_frame: frame,
            sensor_timestamp_s: timestamp_s,
            tracks_timestamp_s: timestamp_s,
            input_publish_time_ns: 0,
            input_scheduled_time_ns: 0,
            receive_time_ns: 0,
            publish_time_ns: 0,
            status,
            flags: 0,
            measurements_accepted: 0,
            measurements_rejected: 0,
        }
    }

    #[test]
    fn a_received_frame_gives_the_bytes_of_the_offline_writer_and_a_rejected_one_none() {
        let mut tracker = Tracker::new(Config::default()).unwrap();
        let mut offline = TrackCsvWriter::new(Vec::new()).unwrap();
        let mut received = TrackCsvWriter::new(Vec::new()).unwrap();
        let mut sample: Box<MaybeUninit<TrackFrame>> = Box::new_zeroed();
        for index in 0..30u64 {
            let t = index as f64 * 0.05;
            let mut frame = Frame::new(t);
            for (j, class) in [ObjectClass::Car, ObjectClass::Pedestrian].into_iter().enumerate() {
                // The pedestrian is missed every third frame, so its track coasts (no row).
                if j == 1 && index % 3 == 2 {
                    continue;
                }
                frame.measurements.push(Measurement {
                    x_m: 10.0 + 20.0 * j as f64 + 8.0 * t,
                    y_m: -2.0 + 4.0 * j as f64 + 0.3 * t * t,
                    radial_velocity_mps: 7.5,
                    rcs_dbsm: 3.0,
                    class,
                    sensor_id: Some(1),
                    ground_truth_id: (j == 0).then_some(40),
                });
            }
            let outputs = tracker.step(&frame).unwrap();
            offline.write_frame(index, t, outputs).unwrap();
            let mut writer = TrackFrameWriter::new(&mut sample);
            outputs.iter().for_each(|output| writer.push(output));
            writer.finish(&header(index, t, FrameStatus::Tracked));
            // SAFETY: zeroed, then header and tracks written; every field is plain data.
            write_track_frame(&mut received, unsafe { sample.assume_init_ref() }).unwrap();
        }
        let rows = received.rows();
        assert!(rows > 40, "{rows} rows");
        TrackFrameWriter::new(&mut sample).finish(&header(99, 9.9, FrameStatus::RejectedNonFiniteTimestamp));
        // SAFETY: as above.
        write_track_frame(&mut received, unsafe { sample.assume_init_ref() }).unwrap();
        assert_eq!(received.rows(), rows);
        assert_eq!(received.finish().unwrap(), offline.finish().unwrap());
    }
}
