//! Per-stream counters of a tunnel: what this side sent to the peers, what arrived from them.

use iceoryx2::identifiers::UniqueNodeId;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::ZeroCopySend;
use iceoryx2::service::header::payload_header::PayloadHeader;
use iceoryx2::service::header::publish_subscribe::Header;
use primm_ipc::catalog::Ipc;
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame};
use std::fmt::Debug;

/// A payload that numbers itself, so that gaps in what arrives can be counted.
pub trait Sequenced {
    /// The sample's sequence number; consecutive samples of one sender count up by one.
    fn sequence(&self) -> u64;
}

impl Sequenced for MeasurementFrame {
    fn sequence(&self) -> u64 {
        self.sequence
    }
}

impl Sequenced for TrackFrame {
    /// The measurement frame's sequence number the track frame answers.
    fn sequence(&self) -> u64 {
        self.input_sequence
    }
}

impl Sequenced for LatencyReport {
    fn sequence(&self) -> u64 {
        self.sequence
    }
}

/// What one stream moved through a tunnel.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Samples published on this side (by anyone but the tunnel): what the tunnel sends to its
    /// peers.
    pub sent: u64,
    /// Samples the tunnel published here from its peers.
    pub arrived: u64,
    /// Sequence numbers skipped between consecutive arrivals: lost on the way (between the
    /// sender's publisher and this side), or never published by the sender.
    pub arrival_gaps: u64,
    /// Arrivals whose sequence number was not above the previous one's (reordered, repeated,
    /// or a restarted sender).
    pub arrived_out_of_order: u64,
}

/// Watches one of primm's streams in the local domain through a subscriber of its own and tells
/// the samples the tunnel published (those of the link's node) from everyone else's.
///
/// The subscriber sees a sample only once it is in this domain's shared memory, so `arrived`
/// counts what really got here, and `sent` what was there to send.
#[derive(Debug)]
pub struct StreamWatch<T: Debug + ZeroCopySend + Sequenced + 'static> {
    name: String,
    subscriber: Subscriber<Ipc, T, ()>,
    counts: StreamCounts,
    last_arrived: Option<u64>,
}

impl<T: Debug + ZeroCopySend + Sequenced + 'static> StreamWatch<T> {
    /// Watches `name` through `subscriber`.
    pub fn new(name: impl Into<String>, subscriber: Subscriber<Ipc, T, ()>) -> Self {
        Self { name: name.into(), subscriber, counts: StreamCounts::default(), last_arrived: None }
    }

    /// The stream's service name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The counts so far.
    pub fn counts(&self) -> StreamCounts {
        self.counts
    }

    /// Takes every pending sample and counts it; `link_node` is the node the tunnel publishes
    /// with. Returns how many samples were taken.
    pub fn drain(&mut self, link_node: &UniqueNodeId) -> Result<u64, iceoryx2::port::ReceiveError> {
        let mut taken = 0;
        while let Some(sample) = self.subscriber.receive()? {
            taken += 1;
            let header: &Header = sample.header();
            if header.node_id() == *link_node {
                self.count_arrival(sample.payload().sequence());
            } else {
                self.counts.sent += 1;
            }
        }
        Ok(taken)
    }

    fn count_arrival(&mut self, sequence: u64) {
        count(&mut self.counts, &mut self.last_arrived, sequence);
    }
}

/// Counts one arrival with sequence number `sequence` after the arrival `last` (if any).
fn count(counts: &mut StreamCounts, last: &mut Option<u64>, sequence: u64) {
    counts.arrived += 1;
    match *last {
        Some(previous) if sequence > previous => {
            counts.arrival_gaps = counts.arrival_gaps.saturating_add(sequence - previous - 1)
        }
        Some(_) => counts.arrived_out_of_order += 1,
        None => {}
    }
    *last = Some(sequence);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The counting alone, without a subscriber.
    fn counts_of(sequences: &[u64]) -> StreamCounts {
        let mut counts = StreamCounts::default();
        let mut last = None;
        for &sequence in sequences {
            count(&mut counts, &mut last, sequence);
        }
        counts
    }

    #[test]
    fn consecutive_arrivals_count_no_gap() {
        assert_eq!(counts_of(&[3, 4, 5, 6]), StreamCounts { arrived: 4, ..StreamCounts::default() });
    }

    #[test]
    fn skipped_sequence_numbers_are_counted_as_gaps() {
        let counts = counts_of(&[0, 1, 4, 5, 9]);
        assert_eq!((counts.arrived, counts.arrival_gaps, counts.arrived_out_of_order), (5, 5, 0));
    }

    #[test]
    fn a_repeated_or_restarted_sequence_counts_as_out_of_order_and_never_overflows() {
        let counts = counts_of(&[0, u64::MAX, 0, 1, 1]);
        assert_eq!(counts.arrived, 5);
        assert_eq!(counts.arrived_out_of_order, 2);
        assert_eq!(counts.arrival_gaps, u64::MAX - 1);
    }
}
