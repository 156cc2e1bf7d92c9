//! The likelihood cost's gate in metres (`association.likelihood_gate_distance_m`): however
//! wide a track's covariance makes the χ² gate, a measurement farther than the gate from the
//! track's predicted centre (beyond its extent's reflections) is not paired with it.

use primm_core::config::{AssociationCost, Config, ConfigError};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::tracker::Tracker;

fn pedestrian(x_m: f64, ground_truth_id: u64) -> Measurement {
    Measurement {
        x_m,
        y_m: 10.0,
        radial_velocity_mps: 0.0,
        rcs_dbsm: 0.0,
        class: ObjectClass::Pedestrian,
        sensor_id: None,
        ground_truth_id: Some(ground_truth_id),
    }
}

/// A pedestrian standing at x = 20 m for ten scans, then one detection `jump_m` farther along x,
/// under a χ² gate so wide that only the gate in metres can refuse the pair. Returns the ids of
/// the tracks after the jump.
fn tracks_after_jump(gate_distance_m: f64, jump_m: f64) -> Vec<u64> {
    let mut config = Config::default().with_modes(Method::Imm.modes());
    config.association.cost = AssociationCost::Likelihood;
    config.association.likelihood_gate_chi2 = 1e12;
    config.association.likelihood_gate_distance_m = gate_distance_m;
    let mut tracker = Tracker::new(config).unwrap();
    for k in 0..10 {
        let mut frame = Frame::new(0.05 * k as f64);
        frame.measurements.push(pedestrian(20.0, 1));
        tracker.step(&frame).unwrap();
    }
    let mut frame = Frame::new(0.5);
    frame.measurements.push(pedestrian(20.0 + jump_m, 2));
    let outputs = tracker.step(&frame).unwrap();
    let mut ids: Vec<u64> = outputs.iter().map(|output| output.id).collect();
    ids.sort_unstable();
    ids
}

#[test]
fn a_measurement_beyond_the_gate_in_metres_starts_a_track_of_its_own() {
    let before = tracks_after_jump(f64::INFINITY, 0.0);
    assert_eq!(before.len(), 1, "{before:?}");
    // Without a gate in metres the far detection updates the pedestrian's track; with a 10 m
    // gate it cannot, and starts a second track.
    assert_eq!(tracks_after_jump(f64::INFINITY, 15.0).len(), 1);
    assert_eq!(tracks_after_jump(10.0, 15.0).len(), 2);
    // Within the gate it is still the pedestrian's.
    assert_eq!(tracks_after_jump(10.0, 5.0).len(), 1);
}

#[test]
fn a_gate_in_metres_that_is_not_a_positive_number_is_refused() {
    for bad in [0.0, -1.0, f64::NAN] {
        let mut config = Config::default();
        config.association.likelihood_gate_distance_m = bad;
        match Tracker::new(config) {
            Err(ConfigError::Invalid { key, .. }) => {
                assert_eq!(key, "association.likelihood_gate_distance_m")
            }
            other => panic!("expected the gate to be refused, got {other:?}"),
        }
    }
}
