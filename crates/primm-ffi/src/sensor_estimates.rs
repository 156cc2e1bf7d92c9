//! What the tracker has learned of each sensor from its data (primm-core's `sensor` module):
//! per sensor and class, where its detections lie on an object, its detection probability and
//! its clutter density, with how many samples each rests on; per sensor, whether its data
//! look like a point cloud.

use crate::status::Failure;
use crate::tracker::{with_tracker, PrimmTracker};
use crate::types::PrimmObjectClass;
use primm_core::measurement::ObjectClass;
use primm_core::sensor::SensorSet;

/// The sensor id that asks for the radars without a configured mount (no sensor id, or one
/// not in `frame.sensors`), which share one set of estimates.
pub const PRIMM_UNMOUNTED_SENSOR: i32 = -1;

/// One sensor's estimates for one class.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PrimmSensorEstimates {
    /// Where the sensor's detections lie between the object's centre (0) and the outline (1).
    pub reflection: f64,
    /// The scale the tracker uses for this sensor's detections now: `reflection` for a sensor
    /// whose `reflection` is "auto", else the configured model's (outline: the class's
    /// `extent.offset_scale`; centre: 0).
    pub reflection_used: f64,
    /// Informative updates the reflection estimate has taken.
    pub reflection_samples: u64,
    /// The detection probability of objects in clear view of the sensor, dimensionless.
    pub detection_probability: f64,
    /// Opportunities the detection estimate has taken: confirmed tracks in view, less the
    /// misses of those another confirmed track hid from the sensor.
    pub detection_samples: u64,
    /// The clutter density, 1/m² per scan.
    pub clutter_density_per_m2: f64,
    /// Scans the clutter estimate has taken.
    pub clutter_scans: u64,
    /// Times any of the three would have left its bounds and was held at them.
    pub bounded: u64,
    /// The sensor's share of confirmed-track scans with several detections on the track's
    /// object (the same for every class).
    pub points_share: f64,
    /// Track scans the share has taken.
    pub points_samples: u64,
    /// 1 when the sensor's detections are grouped as a point cloud now (`detections` is
    /// "points", or "auto" and its data showed one), else 0.
    pub groups_points: u8,
}

/// How a sensor's detections came to be grouped or not (`detections = "auto"`, primm-core's
/// `sensor::points`): what its scans before its first confirmed vehicle track showed, and how
/// often the decision changed since. Queried with [`primm_tracker_sensor_points_evidence`]; the
/// share of multiples and the decision itself are in [`PrimmSensorEstimates`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PrimmSensorPointsEvidence {
    /// Vehicle detections in the sensor's scans before its first confirmed vehicle track scan.
    pub first_scans_vehicle_detections: u32,
    /// Of those, the detections in a cluster of at least three linked ones.
    pub first_scans_clustered: u32,
    /// 1 when the first scans' clusters (pooled over the `auto` radars) started the sensor as
    /// points, else 0.
    pub first_scans_showed_points: u8,
    /// Times the decision (points or objects) changed.
    pub decision_changes: u64,
}

/// The sensor `sensor_id` asks for: a configured id, or `PRIMM_UNMOUNTED_SENSOR`.
fn sensor_of(sensors: &SensorSet, sensor_id: i32) -> Result<&primm_core::sensor::Sensor, Failure> {
    if sensor_id == PRIMM_UNMOUNTED_SENSOR {
        return Ok(sensors.get(primm_core::sensor::UNMOUNTED));
    }
    let id = u16::try_from(sensor_id).map_err(|_| Failure::UnknownSensor(sensor_id))?;
    let slot = sensors.slot(Some(id));
    if slot == primm_core::sensor::UNMOUNTED {
        return Err(Failure::UnknownSensor(sensor_id));
    }
    Ok(sensors.get(slot))
}

impl PrimmSensorPointsEvidence {
    fn of(sensors: &SensorSet, sensor_id: i32) -> Result<Self, Failure> {
        let points = &sensor_of(sensors, sensor_id)?.points;
        Ok(PrimmSensorPointsEvidence {
            first_scans_vehicle_detections: points.scan_detections,
            first_scans_clustered: points.scan_clustered,
            first_scans_showed_points: u8::from(points.scan_points),
            decision_changes: points.switches,
        })
    }
}

impl PrimmSensorEstimates {
    fn of(
        sensors: &SensorSet,
        config: &primm_core::config::Config,
        sensor_id: i32,
        class: ObjectClass,
    ) -> Result<Self, Failure> {
        let sensor = sensor_of(sensors, sensor_id)?;
        let estimates = &sensor.estimates[class.index()];
        Ok(PrimmSensorEstimates {
            reflection: estimates.reflection.value,
            reflection_used: sensor.reflection_scale(class, &config.classes.get(class).extent),
            reflection_samples: estimates.reflection.samples,
            detection_probability: estimates.detection.value(),
            detection_samples: estimates.detection.samples,
            clutter_density_per_m2: estimates.clutter.value_per_m2(),
            clutter_scans: estimates.clutter.scans,
            bounded: estimates.reflection.bounded + estimates.detection.bounded + estimates.clutter.bounded,
            points_share: sensor.points.share(),
            points_samples: sensor.points.samples,
            groups_points: u8::from(sensor.groups_detections()),
        })
    }
}

/// Writes the estimates of sensor `sensor_id` (a configured id, or `PRIMM_UNMOUNTED_SENSOR`)
/// for `class_code` to `*out`. `PRIMM_STATUS_INVALID_ARGUMENT` for an id that is not
/// configured or an unknown class.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_sensor_estimates(
    tracker: *mut PrimmTracker,
    sensor_id: i32,
    class_code: PrimmObjectClass,
    out: *mut PrimmSensorEstimates,
) -> crate::status::PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out.is_null() {
            return Err(Failure::NullArgument("out"));
        }
        let class = ObjectClass::from_code(class_code).ok_or(Failure::UnknownClass(class_code))?;
        let tracker = &handle.tracker;
        let estimates = PrimmSensorEstimates::of(tracker.sensors(), tracker.config(), sensor_id, class)?;
        // SAFETY: writable (caller contract).
        unsafe { out.write(estimates) };
        Ok(())
    };
    // SAFETY: forwarded caller contract.
    unsafe { with_tracker(tracker, body) }
}

/// Writes what decided whether sensor `sensor_id` (a configured id, or
/// `PRIMM_UNMOUNTED_SENSOR`) groups its detections to `*out`. `PRIMM_STATUS_INVALID_ARGUMENT`
/// for an id that is not configured.
///
/// # Safety
/// `tracker` is NULL or a live handle used by no other thread; `out` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn primm_tracker_sensor_points_evidence(
    tracker: *mut PrimmTracker,
    sensor_id: i32,
    out: *mut PrimmSensorPointsEvidence,
) -> crate::status::PrimmStatus {
    let body = |handle: &mut PrimmTracker| {
        if out.is_null() {
            return Err(Failure::NullArgument("out"));
        }
        let evidence = PrimmSensorPointsEvidence::of(handle.tracker.sensors(), sensor_id)?;
        // SAFETY: writable (caller contract).
        unsafe { out.write(evidence) };
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
    fn a_configured_sensor_reports_its_estimates_and_bad_arguments_are_refused() {
        let mut tracker = null_mut();
        // SAFETY: NULL options (the defaults) and a valid out-pointer.
        assert_eq!(unsafe { primm_tracker_create(null(), &mut tracker) }, PrimmStatus::Ok);
        for k in 0..40 {
            let measurement = PrimmMeasurement {
                x_m: 20.0 + 0.5 * k as f64,
                y_m: -10.0,
                radial_velocity_mps: 5.0,
                rcs_dbsm: 10.0,
                ground_truth_id: 1,
                sensor_id: 1,
                class_code: PRIMM_OBJECT_CLASS_CAR,
            };
            let mut summary = PrimmStepSummary::default();
            // SAFETY: a live tracker, one measurement, a writable summary.
            let status =
                unsafe { primm_tracker_step(tracker, 0.05 * k as f64, &measurement, 1, &mut summary) };
            assert_eq!(status, PrimmStatus::Ok);
        }
        let mut out = PrimmSensorEstimates::default();
        // SAFETY: a live tracker and a writable out-pointer, here and below.
        let status = unsafe { primm_tracker_sensor_estimates(tracker, 1, PRIMM_OBJECT_CLASS_CAR, &mut out) };
        assert_eq!(status, PrimmStatus::Ok);
        assert!(out.clutter_scans == 40, "{out:?}");
        assert!(out.detection_samples > 0, "{out:?}");
        assert!((0.0..=1.0).contains(&out.reflection) && (0.0..=1.0).contains(&out.detection_probability));
        // The shipped model is the outline's: the class's offset scale.
        assert_eq!(out.reflection_used, 0.5);
        let status = unsafe {
            primm_tracker_sensor_estimates(tracker, PRIMM_UNMOUNTED_SENSOR, PRIMM_OBJECT_CLASS_CAR, &mut out)
        };
        assert_eq!(status, PrimmStatus::Ok);
        assert_eq!(out.clutter_scans, 0, "no radar without a mount scanned");
        for (sensor_id, class_code) in [(99, PRIMM_OBJECT_CLASS_CAR), (-2, PRIMM_OBJECT_CLASS_CAR), (1, 7)] {
            let status = unsafe { primm_tracker_sensor_estimates(tracker, sensor_id, class_code, &mut out) };
            assert_eq!(status, PrimmStatus::InvalidArgument, "{sensor_id} {class_code}");
        }
        let status =
            unsafe { primm_tracker_sensor_estimates(tracker, 1, PRIMM_OBJECT_CLASS_CAR, null_mut()) };
        assert_eq!(status, PrimmStatus::NullArgument);
        // SAFETY: the handle is live and not used again.
        unsafe { primm_tracker_destroy(tracker) };
    }

    #[test]
    fn a_sensor_reports_what_its_first_scans_showed_and_bad_arguments_are_refused() {
        let mut tracker = null_mut();
        // SAFETY: NULL options (the defaults) and a valid out-pointer.
        assert_eq!(unsafe { primm_tracker_create(null(), &mut tracker) }, PrimmStatus::Ok);
        // Sensor 1 sees four points of one car in each of its first scans, linked: a point
        // cloud. Sensor 2 sees one detection of a car.
        for k in 0..3 {
            let point = |sensor_id: i32, x_m: f64, y_m: f64| PrimmMeasurement {
                x_m,
                y_m,
                radial_velocity_mps: 0.0,
                rcs_dbsm: 10.0,
                ground_truth_id: 1,
                sensor_id,
                class_code: PRIMM_OBJECT_CLASS_CAR,
            };
            let measurements = [
                point(1, 10.0, -20.0),
                point(1, 11.0, -20.0),
                point(1, 12.0, -20.0),
                point(1, 13.0, -20.0),
                point(2, 40.0, -5.0),
            ];
            let mut summary = PrimmStepSummary::default();
            // SAFETY: a live tracker, five measurements, a writable summary.
            let status = unsafe {
                primm_tracker_step(tracker, 0.05 * k as f64, measurements.as_ptr(), 5, &mut summary)
            };
            assert_eq!(status, PrimmStatus::Ok);
        }
        let mut out = PrimmSensorPointsEvidence::default();
        // SAFETY: a live tracker and a writable out-pointer, here and below.
        let status = unsafe { primm_tracker_sensor_points_evidence(tracker, 1, &mut out) };
        assert_eq!(status, PrimmStatus::Ok);
        assert_eq!((out.first_scans_vehicle_detections, out.first_scans_clustered), (12, 12), "{out:?}");
        let status = unsafe { primm_tracker_sensor_points_evidence(tracker, 2, &mut out) };
        assert_eq!(status, PrimmStatus::Ok);
        assert_eq!((out.first_scans_vehicle_detections, out.first_scans_clustered), (3, 0), "{out:?}");
        let status = unsafe { primm_tracker_sensor_points_evidence(tracker, 99, &mut out) };
        assert_eq!(status, PrimmStatus::InvalidArgument);
        let status = unsafe { primm_tracker_sensor_points_evidence(tracker, 1, null_mut()) };
        assert_eq!(status, PrimmStatus::NullArgument);
        // SAFETY: the handle is live and not used again.
        unsafe { primm_tracker_destroy(tracker) };
    }
}
