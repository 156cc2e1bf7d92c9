//! The lines of the service's end-of-run summary that describe the tracker: its counters and
//! what it learned of the sensors.

use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::{Tracker, TrackerStats};

/// The sensors' estimates for the summary, one line each after a newline (nothing before any
/// sensor took a sample).
pub(crate) fn sensor_lines<P: DisplacementPredictor>(tracker: &Tracker<P>) -> String {
    let report = tracker.sensors().report(tracker.config()).to_string();
    if report.is_empty() {
        report
    } else {
        format!("\nsensors (estimated from the data):\n{report}")
    }
}

/// The tracker's counters that are not zero, by name: `tracker: name value, ...` (every counter
/// not named is zero).
pub(crate) fn tracker_counters_line(stats: &TrackerStats) -> String {
    let counted: Vec<String> = stats
        .named_values()
        .iter()
        .filter(|(_, value)| *value > 0)
        .map(|(name, value)| format!("{name} {value}"))
        .collect();
    format!("tracker: {} (the other counters are zero)", counted.join(", "))
}
