//! Target `config_toml`: configuration parsing and validation, and a tracker built from
//! whatever validates.

use crate::invariant_check::assert_tracker_invariants;
use crate::scripted_predictor::ScriptedPredictor;
use glam::DVec2;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::tracker::Tracker;

/// Frames stepped through a tracker built from a valid configuration.
pub const FRAMES: usize = 6;

/// Parses `data` as a primm TOML configuration ([`primm_config::from_toml_str`], which runs
/// [`Config::validate`](primm_core::config::Config::validate)). A configuration that validates
/// must build a tracker (with a predictor, whatever modes it activates) and track a few frames
/// of one object per class, spaced within its own `tracker.max_frame_interval_s`, with the
/// invariants holding after every step.
pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(config) = primm_config::from_toml_str(text) else { return };
    assert_eq!(config.validate(), Ok(()), "a parsed configuration validates again");
    let interval_s = (config.tracker.max_frame_interval_s / 2.0).min(0.05);
    let predictor = ScriptedPredictor::new(vec![Some(DVec2::new(0.4, 0.0).into()), None]);
    let mut tracker = match Tracker::with_predictor(config, predictor) {
        Ok(tracker) => tracker,
        Err(error) => panic!("a validated configuration is refused by the tracker: {error}"),
    };
    for k in 0..FRAMES {
        let mut frame = Frame::new(interval_s * k as f64);
        for (row, class) in ObjectClass::ALL.into_iter().enumerate() {
            frame.measurements.push(Measurement {
                x_m: 10.0 + 8.0 * k as f64 * interval_s,
                y_m: -5.0 + 5.0 * row as f64,
                radial_velocity_mps: 8.0,
                rcs_dbsm: 5.0,
                class,
                sensor_id: Some(0),
                ground_truth_id: None,
            });
        }
        let _ = tracker.step(&frame);
        assert_tracker_invariants(&tracker, "tracker from a fuzzed configuration");
    }
}
