//! What a tunnel did in one run.

use crate::watch::StreamCounts;

/// The counters of one tunnel run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TunnelReport {
    /// Wake-ups that moved pending samples.
    pub cycles: u64,
    /// Discovery cycles run (one per [`DISCOVERY_PERIOD`](crate::tunnel::DISCOVERY_PERIOD)).
    pub discoveries: u64,
    /// Discovery cycles that failed (logged, retried in the next cycle).
    pub discovery_failures: u64,
    /// Propagation cycles in which at least one bridge failed to move its samples (logged;
    /// iceoryx2's link says which bridge).
    pub propagation_failures: u64,
    /// The most zenoh sessions (peers, routers or clients) connected at once.
    pub peers_max: usize,
    /// Per stream, by service name.
    pub streams: Vec<(String, StreamCounts)>,
}

impl TunnelReport {
    /// The counts of the stream whose service name ends with `suffix` (e.g. `primm/tracks`).
    pub fn stream(&self, suffix: &str) -> Option<StreamCounts> {
        self.streams.iter().find(|(name, _)| name.ends_with(suffix)).map(|(_, counts)| *counts)
    }
}

impl std::fmt::Display for TunnelReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "tunnel: {} cycles, {} discoveries ({} failed), {} propagation failures, at most {} zenoh session(s) connected",
            self.cycles, self.discoveries, self.discovery_failures, self.propagation_failures, self.peers_max
        )?;
        writeln!(
            f,
            "{:<48} {:>10} {:>10} {:>10} {:>12}",
            "stream", "sent", "arrived", "gaps", "out of order"
        )?;
        for (name, counts) in &self.streams {
            writeln!(
                f,
                "{:<48} {:>10} {:>10} {:>10} {:>12}",
                name, counts.sent, counts.arrived, counts.arrival_gaps, counts.arrived_out_of_order
            )?;
        }
        Ok(())
    }
}
