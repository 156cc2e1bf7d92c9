//! What the tracker has learned of each sensor from its data (primm-core's `sensor` module):
//! per sensor and class, where its detections lie on an object, its detection probability and
//! its clutter density, with how many samples each rests on.

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
    /// The detection probability, dimensionless.
    pub detection_probability: f64,
    /// Opportunities (confirmed tracks in view) the detection estimate has taken.
    pub detection_samples: u64,
    /// The clutter density, 1/m² per scan.
    pub clutter_density_per_m2: f64,
    /// Scans the clutter estimate has taken.
    pub clutter_scans: u64,
    /// Times any of the three would have left its bounds and was held at them.
    pub bounded: u64,
}

impl PrimmSensorEstimates {
    fn of(
        sensors: &SensorSet,
        config: &primm_core::config::Config,
        sensor_id: i32,
        class: ObjectClass,
    ) -> Result<Self, Failure> {
        let sensor = if sensor_id == PRIMM_UNMOUNTED_SENSOR {
            sensors.get(primm_core::sensor::UNMOUNTED)
        } else {
            let id = u16::try_from(sensor_id).map_err(|_| Failure::UnknownSensor(sensor_id))?;
            let slot = sensors.slot(Some(id));
            if slot == primm_core::sensor::UNMOUNTED {
                return Err(Failure::UnknownSensor(sensor_id));
            }
            sensors.get(slot)
        };
        let estimates = &sensor.estimates[class.index()];
        let estimation = &config.frame.estimation;
        Ok(PrimmSensorEstimates {
            reflection: estimates.reflection.value,
            reflection_used: sensor.reflection_scale(class, &config.classes.get(class).extent),
            reflection_samples: estimates.reflection.samples,
            detection_probability: estimates.detection.value(estimation),
            detection_samples: estimates.detection.samples,
            clutter_density_per_m2: estimates.clutter.value_per_m2(estimation),
            clutter_scans: estimates.clutter.scans,
            bounded: estimates.reflection.bounded + estimates.detection.bounded + estimates.clutter.bounded,
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
