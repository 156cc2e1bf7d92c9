//! Whether the tracker takes the sensors to stand still (primm-core's `sensor::platform`): for
//! frames without an ego pose, under `frame.platform = "auto"`, from the radial velocities.

use crate::status::Failure;
use crate::tracker::{with_tracker, PrimmTracker};

/// The platform estimate.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PrimmPlatformEstimate {
    /// The estimated velocity of the sensors along x, m/s (0 while `velocity_known` is 0).
    pub velocity_x_mps: f64,
    /// ... along y, m/s.
    pub velocity_y_mps: f64,
    /// Updates without a pose the estimate has taken.
    pub samples: u64,
    /// Times the decision changed.
    pub switches: u64,
    /// 1 when frames without a pose are tracked as of sensors that stand still now (the
    /// configuration says "stationary", or "auto" and the data showed it), else 0.
    pub stationary: u8,
    /// 1 once the estimate has enough information in every direction to give a velocity.
    pub velocity_known: u8,
}

/// Writes the platform estimate to `*out`.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_platform(
    tracker: *mut PrimmTracker,
    out: *mut PrimmPlatformEstimate,
) -> crate::status::PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out.is_null() {
            return Err(Failure::NullArgument("out"));
        }
        let tracker = &handle.tracker;
        let estimate = tracker.sensors().platform();
        let velocity = estimate.velocity_mps();
        let stationary = tracker.config().frame.platform.stationary(estimate);
        let value = PrimmPlatformEstimate {
            velocity_x_mps: velocity.map_or(0.0, |v| v.x),
            velocity_y_mps: velocity.map_or(0.0, |v| v.y),
            samples: estimate.samples,
            switches: estimate.switches,
            stationary: u8::from(stationary),
            velocity_known: u8::from(velocity.is_some()),
        };
        // SAFETY: writable (caller contract).
        unsafe { out.write(value) };
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::status::PrimmStatus;
    use crate::tracker::{primm_tracker_create, primm_tracker_destroy, primm_tracker_step};
    use crate::types::{PrimmMeasurement, PrimmStepSummary, PRIMM_OBJECT_CLASS_CAR};
    use core::ptr::{null, null_mut};

    #[test]
    fn a_roadside_radars_frames_without_a_pose_are_found_stationary() {
        let mut tracker = null_mut();
        // SAFETY: NULL options (the defaults) and a valid out-pointer.
        assert_eq!(unsafe { primm_tracker_create(null(), &mut tracker) }, PrimmStatus::Ok);
        let mut out = PrimmPlatformEstimate::default();
        // SAFETY: a live tracker and a writable out-pointer.
        assert_eq!(unsafe { primm_tracker_platform(tracker, &mut out) }, PrimmStatus::Ok);
        assert_eq!((out.stationary, out.velocity_known, out.samples), (0, 0, 0));
        // Four cars crossing at several bearings for 4 s, no sensor id, no pose: a sensor that
        // stands still, whose radial velocities are those of the cars' motion.
        let cars = [
            ((30.0, -20.0), (0.0, 8.0)),
            ((-25.0, 15.0), (6.0, 0.0)),
            ((10.0, 35.0), (-5.0, -3.0)),
            ((40.0, 10.0), (0.0, -7.0)),
        ];
        for k in 0..80 {
            let t = 0.05 * k as f64;
            let measurements: Vec<PrimmMeasurement> = cars
                .iter()
                .enumerate()
                .map(|(id, &((x, y), (vx, vy)))| {
                    let (px, py) = (x + vx * t, y + vy * t);
                    let range = (px * px + py * py).sqrt();
                    PrimmMeasurement {
                        x_m: px,
                        y_m: py,
                        radial_velocity_mps: (vx * px + vy * py) / range,
                        rcs_dbsm: 10.0,
                        ground_truth_id: id as i64 + 1,
                        sensor_id: -1,
                        class_code: PRIMM_OBJECT_CLASS_CAR,
                    }
                })
                .collect();
            let mut summary = PrimmStepSummary::default();
            // SAFETY: a live tracker, the measurements, a writable summary.
            let status = unsafe {
                primm_tracker_step(tracker, t, measurements.as_ptr(), measurements.len(), &mut summary)
            };
            assert_eq!(status, PrimmStatus::Ok);
        }
        // SAFETY: as above.
        assert_eq!(unsafe { primm_tracker_platform(tracker, &mut out) }, PrimmStatus::Ok);
        assert_eq!((out.stationary, out.velocity_known), (1, 1), "{out:?}");
        assert!(out.velocity_x_mps.hypot(out.velocity_y_mps) < 0.5, "{out:?}");
        assert!(out.samples > 0 && out.switches == 1, "{out:?}");
        // SAFETY: a live tracker and a NULL out-pointer.
        assert_eq!(unsafe { primm_tracker_platform(tracker, null_mut()) }, PrimmStatus::NullArgument);
        // SAFETY: the handle is live and not used again.
        unsafe { primm_tracker_destroy(tracker) };
    }
}
