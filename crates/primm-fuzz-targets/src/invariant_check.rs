//! The check every target runs after every step.

use primm_core::invariants::check_tracker;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::Tracker;

/// Panics, naming the broken invariant and `context`, when `tracker` violates one of
/// [`primm_core::invariants`]. A panic is what the fuzzer reports as a crash.
pub fn assert_tracker_invariants<P: DisplacementPredictor>(tracker: &Tracker<P>, context: &str) {
    if let Err(violation) = check_tracker(tracker) {
        panic!("tracker invariant broken ({context}): {violation}");
    }
}
