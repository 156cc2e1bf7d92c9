//! A clutter flood: frames of 240 false detections around 16 real objects neither lose nor
//! corrupt the tracks of the real objects, and allocate nothing.

use crate::common;
use crate::common::counting_allocator::count_allocations;
use primm_core::config::Config;
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// The object measurements of `frame` plus false detections up to [`FLOODED_FRAME`], spread
/// over sensor 1's field of view (where the lanes are) with random classes, radial velocities and RCS.
/// Measurements of a flooded frame: 240 false detections with the 16 objects, about a hundred
/// times the clutter of a busy road scene.
const FLOODED_FRAME: usize = 256;

fn flooded(frame: &Frame, rng: &mut ChaCha8Rng) -> Frame {
    let mut flooded = frame.clone();
    while flooded.measurements.len() < FLOODED_FRAME {
        let range = rng.random_range(2.0..130.0);
        let bearing = rng.random_range(-145f64..-25.0).to_radians();
        flooded.measurements.push(Measurement {
            x_m: 3.66 + range * bearing.cos(),
            y_m: -0.87 + range * bearing.sin(),
            radial_velocity_mps: if rng.random_bool(0.8) {
                rng.random_range(-0.3..0.3)
            } else {
                rng.random_range(-10.0..10.0)
            },
            rcs_dbsm: rng.random_range(-15.0..10.0),
            class: if rng.random_bool(0.7) { ObjectClass::Car } else { ObjectClass::Pedestrian },
            sensor_id: Some(1),
            ground_truth_id: None,
        });
    }
    flooded
}

#[test]
fn a_flood_of_false_detections_loses_no_confirmed_track_and_allocates_nothing() {
    // The lane objects are measured at their centres: point objects.
    let mut config = Config::default().with_modes(Method::Imm.modes()).with_point_objects();
    config.frame.tracking_frame = primm_core::config::CoordinateFrame::Vehicle;
    let mut tracker = Tracker::new(config).unwrap();
    let mut frames = common::scene_frames(&common::lanes(16), 160, 0.04, 0.2, 5);
    for frame in &mut frames {
        for m in &mut frame.measurements {
            m.sensor_id = Some(1);
        }
    }
    // Settle: every lane object has a confirmed track.
    let mut track_of: HashMap<u64, u64> = HashMap::new();
    for frame in &frames[..40] {
        for output in tracker.step(frame).unwrap() {
            if output.status.is_confirmed() && output.measurement_index.is_some() {
                track_of.insert(output.ground_truth_id.unwrap(), output.id);
            }
        }
    }
    assert_eq!(track_of.len(), 16, "every object is tracked before the flood");
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let flood: Vec<Frame> = frames[40..].iter().map(|frame| flooded(frame, &mut rng)).collect();
    let mut kept = 0usize;
    let allocations = count_allocations(|| {
        for frame in &flood {
            let outputs = tracker.step(frame).expect("a full frame is valid");
            for output in outputs.iter().filter(|o| o.measurement_index.is_some()) {
                if let Some(gt) = output.ground_truth_id {
                    kept += usize::from(track_of.get(&gt) == Some(&output.id));
                }
            }
        }
    });
    assert_eq!(allocations, 0);
    // Nearly every object measurement still goes to its object's track (a false detection
    // nearer the prior may win a frame now and then).
    let object_measurements = 16 * flood.len();
    assert!(kept as f64 > 0.97 * object_measurements as f64, "{kept} of {object_measurements}");
    let live: Vec<u64> = tracker.tracks().iter().map(|t| t.id).collect();
    assert!(track_of.values().all(|id| live.contains(id)), "a tracked object's track was lost");
    assert!(tracker.tracks().iter().all(|t| t.existence_probability.is_finite()));
}
