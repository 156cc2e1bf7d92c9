//! The tracker allocates nothing per frame.

use crate::common;
use crate::common::counting_allocator;

use counting_allocator::count_allocations;
use primm_core::config::Config;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::tracker::Tracker;

/// 10 000 frames of 64 objects, built before counting; frames cycle through 500 recorded ones
/// with timestamps shifted so that time keeps advancing.
fn run_counted<P: primm_core::predictor::DisplacementPredictor>(mut tracker: Tracker<P>) -> (u64, u64) {
    let base = common::scene_frames(&common::lanes(64), 500, 0.04, 0.2, 21);
    let mut frame: Frame = base[0].clone();
    let mut updates = 0u64;
    let allocations = count_allocations(|| {
        for k in 0..10_000usize {
            let source = &base[k % base.len()];
            frame.timestamp_s = k as f64 * 0.04;
            frame.measurements.clone_from(&source.measurements);
            // Restart the scene every 500 frames; the old tracks are deleted after coasting.
            let outputs = tracker.step(&frame).expect("valid frame");
            updates += outputs.iter().filter(|o| o.measurement_index.is_some()).count() as u64;
        }
    });
    (allocations, updates)
}

#[test]
fn ten_thousand_frames_of_sixty_four_objects_allocate_nothing_without_the_learned_mode() {
    let tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    let (allocations, updates) = run_counted(tracker);
    assert_eq!(allocations, 0);
    assert_eq!(updates, 640_000);
}

#[test]
fn ten_thousand_frames_of_sixty_four_objects_allocate_nothing_with_an_oracle_predictor() {
    let oracle = common::LaneOracle { objects: common::lanes(64) };
    let tracker = Tracker::with_predictor(Config::default(), oracle).unwrap();
    let (allocations, updates) = run_counted(tracker);
    assert_eq!(allocations, 0);
    assert_eq!(updates, 640_000);
}
