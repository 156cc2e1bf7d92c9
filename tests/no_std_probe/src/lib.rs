//! Builds and steps a tracker with `core` and `alloc` only.

#![no_std]

extern crate alloc;

use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::tracker::Tracker;

/// Tracks one measurement; returns the number of tracks, or `None` on an error.
pub fn track_one(x_m: f64, y_m: f64) -> Option<usize> {
    let mut tracker = Tracker::new(Config::default()).ok()?;
    let mut frame = Frame::new(0.0);
    frame
        .measurements
        .try_push(Measurement {
            x_m,
            y_m,
            radial_velocity_mps: 1.0,
            rcs_dbsm: 5.0,
            class: ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: None,
        })
        .ok()?;
    tracker.step(&frame).ok().map(|tracks| tracks.len())
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
