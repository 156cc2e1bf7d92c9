//! Late frames, the full state and prediction to a time through the C API, called as C would
//! call it.

use core::ptr::{null, null_mut};
use primm_ffi::*;

const IMM: u32 = 5;

fn tracker() -> *mut PrimmTracker {
    let options = PrimmTrackerOptions { method: IMM, ..primm_tracker_options_default() };
    let mut tracker = null_mut();
    // SAFETY: valid options and out-pointer.
    assert_eq!(unsafe { primm_tracker_create(&options, &mut tracker) }, PrimmStatus::Ok);
    tracker
}

/// Two cars along x, frame at `t`.
fn cars(t: f64) -> [PrimmMeasurement; 2] {
    [(10.0, 3.0, 5.0), (30.0, -4.0, -3.0)].map(|(x0, y, vx)| PrimmMeasurement {
        x_m: x0 + vx * t,
        y_m: y,
        radial_velocity_mps: vx,
        rcs_dbsm: 10.0,
        ground_truth_id: -1,
        sensor_id: -1,
        class_code: 0,
    })
}

fn step(tracker: *mut PrimmTracker, t: f64) -> (PrimmStatus, PrimmStepSummary) {
    let frame = cars(t);
    let mut summary = PrimmStepSummary::default();
    // SAFETY: a live tracker, two readable measurements, a writable summary.
    let status = unsafe { primm_tracker_step(tracker, t, frame.as_ptr(), frame.len(), &mut summary) };
    (status, summary)
}

fn tracks(tracker: *mut PrimmTracker) -> Vec<PrimmTrack> {
    let mut count = 0;
    // SAFETY: a count query.
    unsafe { primm_tracker_tracks(tracker, null_mut(), 0, &mut count) };
    let mut out = vec![tracks_filler(); count];
    // SAFETY: a buffer of `count` entries.
    assert_eq!(
        unsafe { primm_tracker_tracks(tracker, out.as_mut_ptr(), count, &mut count) },
        PrimmStatus::Ok
    );
    out
}

/// The tracks as text, to compare them exactly (NaN fields compare unequal as numbers).
fn text(tracks: &[PrimmTrack]) -> String {
    format!("{tracks:?}")
}

fn tracks_filler() -> PrimmTrack {
    // SAFETY: every field of PrimmTrack is plain data, for which zero is a valid value.
    unsafe { core::mem::zeroed() }
}

fn stats(tracker: *mut PrimmTracker) -> PrimmStats {
    let mut stats = PrimmStats::default();
    // SAFETY: a live tracker and a writable struct.
    assert_eq!(unsafe { primm_tracker_stats(tracker, &mut stats) }, PrimmStatus::Ok);
    stats
}

#[test]
fn a_late_frame_is_tracked_in_its_place_and_an_older_one_is_rejected_and_counted() {
    let (late, in_order) = (tracker(), tracker());
    for k in 0..20 {
        let t = k as f64 * 0.05;
        assert_eq!(step(in_order, t).0, PrimmStatus::Ok);
        if k != 18 {
            assert_eq!(step(late, t).0, PrimmStatus::Ok);
        }
    }
    // Frame 18 arrives after frame 19.
    let (status, summary) = step(late, 18.0 * 0.05);
    assert_eq!(status, PrimmStatus::Ok);
    assert!(summary.late_frame);
    assert_eq!(summary.frames_replayed, 1);
    let mut newest = 0.0;
    // SAFETY: a live tracker and a writable double.
    assert_eq!(unsafe { primm_tracker_newest_timestamp(late, &mut newest) }, PrimmStatus::Ok);
    assert_eq!(newest, 19.0 * 0.05);
    assert_eq!(text(&tracks(late)), text(&tracks(in_order)));
    assert_eq!(stats(late).late_frames_tracked, 1);
    // Half a second back is beyond the 0.15 s window.
    assert_eq!(step(late, 0.45).0, PrimmStatus::InvalidFrame);
    assert_eq!(stats(late).frames_rejected_too_late, 1);
    assert_eq!(text(&tracks(late)), text(&tracks(in_order)));
    // SAFETY: live handles, not used again.
    unsafe {
        primm_tracker_destroy(late);
        primm_tracker_destroy(in_order);
    }
}

#[test]
fn every_track_carries_its_position_velocity_covariance_and_age() {
    let tracker = tracker();
    for k in 0..20 {
        assert_eq!(step(tracker, k as f64 * 0.05).0, PrimmStatus::Ok);
    }
    for track in tracks(tracker) {
        let c = &track.state_covariance;
        assert_eq!(c[0], track.position_covariance_xx_m2);
        assert_eq!(c[1], track.position_covariance_xy_m2);
        assert_eq!(c[5], track.position_covariance_yy_m2);
        for row in 0..4 {
            assert!(c[5 * row] > 0.0, "variance {row}: {c:?}");
            for column in 0..4 {
                assert!((c[4 * row + column] - c[4 * column + row]).abs() < 1e-12);
            }
        }
        assert!(track.world_state_covariance.iter().all(|v| v.is_nan()), "no pose, no world estimate");
        assert!((track.age_s - 19.0 * 0.05).abs() < 1e-9);
    }
    // SAFETY: a live handle, not used again.
    unsafe { primm_tracker_destroy(tracker) };
}

#[test]
fn a_prediction_to_a_time_changes_nothing_and_refuses_a_time_out_of_range() {
    let tracker = tracker();
    for k in 0..20 {
        assert_eq!(step(tracker, k as f64 * 0.05).0, PrimmStatus::Ok);
    }
    let before = tracks(tracker);
    let mut out = vec![tracks_filler(); 8];
    let mut count = 0;
    // SAFETY: a live tracker, a buffer of 8, a writable count; NULL pose allowed.
    let status = unsafe {
        primm_tracker_predict_to(tracker, 0.95 + 0.2, null(), out.as_mut_ptr(), out.len(), &mut count)
    };
    assert_eq!(status, PrimmStatus::Ok);
    assert_eq!(count, 2);
    for (predicted, now) in out[..count].iter().zip(&before) {
        assert_eq!(predicted.id, now.id);
        assert!(
            predicted.x_m > now.x_m - 3.0 && (predicted.x_m - now.x_m - 0.2 * now.velocity_x_mps).abs() < 0.2
        );
        assert!(predicted.position_covariance_xx_m2 > now.position_covariance_xx_m2);
        assert_eq!(predicted.measurement_index, PRIMM_NO_MEASUREMENT_INDEX);
    }
    assert_eq!(text(&tracks(tracker)), text(&before), "nothing changed");
    // Too small a buffer: the count needed, nothing written.
    // SAFETY: as above, with a capacity of 1.
    let status = unsafe { primm_tracker_predict_to(tracker, 1.0, null(), out.as_mut_ptr(), 1, &mut count) };
    assert_eq!((status, count), (PrimmStatus::BufferTooSmall, 2));
    // Before the newest frame, or NaN: refused with a message.
    for bad in [0.5, f64::NAN, 10.0] {
        // SAFETY: as above.
        let status =
            unsafe { primm_tracker_predict_to(tracker, bad, null(), out.as_mut_ptr(), 8, &mut count) };
        assert_eq!(status, PrimmStatus::InvalidArgument, "{bad}");
    }
    // SAFETY: a live handle, not used again.
    unsafe { primm_tracker_destroy(tracker) };
}
