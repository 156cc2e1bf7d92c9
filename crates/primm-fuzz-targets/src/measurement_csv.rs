//! Target `measurement_csv`: the measurement CSV reader of `primm_sim::io` on arbitrary bytes;
//! whatever it reads is turned into frames and tracked.

use crate::invariant_check::assert_tracker_invariants;
use primm_core::config::Config;
use primm_core::mode::Method;
use primm_core::tracker::{StepError, Tracker};
use primm_core::validation::FrameError;
use primm_sim::io::read_sequence;

/// Reads `data` as a measurement CSV file. A file the reader accepts is converted to frames
/// (a frame over capacity is an error, not a panic) and stepped through an IMM tracker, resetting
/// it after a gap as a replay does, with the invariants checked after every step.
pub fn run(data: &[u8]) {
    let Ok(sequence) = read_sequence(data, "fuzz") else { return };
    let Ok(frames) = sequence.to_frames() else { return };
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes()))
        .expect("the default configuration is valid");
    for frame in &frames {
        if let Err(StepError::InvalidFrame(FrameError::IntervalTooLong { .. })) = tracker.step(frame) {
            tracker.reset();
            let _ = tracker.step(frame);
        }
        assert_tracker_invariants(&tracker, "measurement CSV replay");
    }
}
