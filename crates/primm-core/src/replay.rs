//! Late frames: a ring of the most recent frames, each with the tracker's state before it.
//!
//! Radars on a vehicle bus do not deliver in timestamp order: a scan may arrive a few
//! milliseconds after a newer scan of another sensor was tracked. The tracker keeps the last
//! `tracker.replay_frames` frames it tracked, each with a snapshot of its state from just before
//! that frame (`TrackerSnapshot`). A frame no more than `tracker.max_frame_delay_s` older than
//! the newest one is put in its place: the tracker goes back to the snapshot of the first newer
//! frame, tracks the late frame, then tracks the newer frames again from their recorded copies.
//! The result is exactly what in-order arrival would have given (the tracker is deterministic
//! and reads no clock), which is why primm replays rather than retrodicts: an out-of-sequence
//! update (Bar-Shalom's retrodiction) approximates that result for one filter, but not the
//! association, initiation, deletion and merging decisions the newer frames made without the
//! late one.
//!
//! Every buffer is allocated when the tracker is built: `replay_frames + 1` slots, each with a
//! frame copy and room for [`MAX_TRACKS`] tracks. Taking a snapshot copies the live tracks
//! only. With `replay_frames = 0` (or `max_frame_delay_s = 0`) nothing is kept and a late frame
//! is rejected as before.

use crate::coordinates::CoordinateFrame;
use crate::limits::{MAX_REPLAY_FRAMES, MAX_TRACKS};
use crate::measurement::FrameView;
use crate::pose::EgoPose;
use crate::recorded_frame::RecordedFrame;
use crate::track::Track;
use crate::tracker::TrackerStats;
use alloc::boxed::Box;
use alloc::vec::Vec;
use arrayvec::ArrayVec;

/// Everything about a tracker that one frame changes and the next frame reads.
#[derive(Debug)]
pub(crate) struct TrackerSnapshot {
    /// The live tracks (capacity [`MAX_TRACKS`], reserved once).
    pub tracks: Vec<Track>,
    /// The track table's next id.
    pub next_id: u64,
    /// The newest tracked frame's time, s.
    pub last_timestamp_s: Option<f64>,
    /// The frame the tracks were in.
    pub tracks_frame: CoordinateFrame,
    /// The ego pose of the newest frame tracked in the world frame.
    pub last_pose: Option<EgoPose>,
    /// The ego's motion as the poses tell it.
    pub ego_motion: crate::pose::EgoMotion,
    /// The counters.
    pub stats: TrackerStats,
    /// The sensors' estimates (`None` before the first save).
    pub sensors: Option<crate::sensor::SensorSet>,
}

impl TrackerSnapshot {
    fn new() -> Self {
        Self {
            tracks: Vec::with_capacity(MAX_TRACKS),
            next_id: 1,
            last_timestamp_s: None,
            tracks_frame: CoordinateFrame::Vehicle,
            last_pose: None,
            ego_motion: crate::pose::EgoMotion::default(),
            stats: TrackerStats::default(),
            sensors: None,
        }
    }
}

/// One recorded frame and the state before it.
#[derive(Debug)]
pub(crate) struct ReplaySlot {
    /// The tracker's state just before `frame` was tracked.
    pub before: TrackerSnapshot,
    /// The frame, as read from the caller.
    pub frame: Box<RecordedFrame>,
}

/// Where a late frame goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Placement {
    /// Not late: newer than every tracked frame (or the ring is off, or nothing was tracked).
    InOrder,
    /// Late, to be tracked before the recorded frame at this position (0 = oldest kept).
    Before(usize),
    /// Older than the window or than the oldest recorded frame can reach.
    TooLate,
    /// Its time equals a tracked frame's: rejected like any frame that does not advance.
    Duplicate,
}

/// The ring of recent frames (see the module documentation).
#[derive(Debug)]
pub(crate) struct ReplayRing {
    /// `capacity + 1` slots: the recorded ones plus one being filled.
    slots: Vec<ReplaySlot>,
    /// Indices into `slots` of the recorded frames, oldest first.
    order: ArrayVec<u8, { MAX_REPLAY_FRAMES + 1 }>,
    capacity: usize,
    max_delay_s: f64,
}

impl ReplayRing {
    /// A ring of `capacity` frames (at most [`MAX_REPLAY_FRAMES`]) reaching `max_delay_s` back;
    /// off when either is zero.
    pub(crate) fn new(capacity: usize, max_delay_s: f64) -> Self {
        let capacity = if max_delay_s > 0.0 { capacity.min(MAX_REPLAY_FRAMES) } else { 0 };
        let slot_count = if capacity == 0 { 0 } else { capacity + 1 };
        let slots = (0..slot_count)
            .map(|_| ReplaySlot { before: TrackerSnapshot::new(), frame: Box::new(RecordedFrame::new()) })
            .collect();
        Self { slots, order: ArrayVec::new(), capacity, max_delay_s }
    }

    /// Whether late frames are kept at all.
    pub(crate) fn is_enabled(&self) -> bool {
        self.capacity > 0
    }

    /// Forgets every recorded frame.
    pub(crate) fn clear(&mut self) {
        self.order.clear();
    }

    /// Number of recorded frames.
    pub(crate) fn len(&self) -> usize {
        self.order.len()
    }

    /// Where a frame at `timestamp_s` goes, given the newest tracked frame's time.
    pub(crate) fn place(&self, timestamp_s: f64, newest_s: Option<f64>) -> Placement {
        let Some(newest_s) = newest_s else { return Placement::InOrder };
        if !self.is_enabled() || !timestamp_s.is_finite() || timestamp_s > newest_s {
            return Placement::InOrder;
        }
        if timestamp_s == newest_s {
            return Placement::Duplicate;
        }
        if newest_s - timestamp_s > self.max_delay_s {
            return Placement::TooLate;
        }
        let Some(position) = self
            .order
            .iter()
            .position(|&slot| self.slots[usize::from(slot)].frame.timestamp_s() > timestamp_s)
        else {
            // Cannot happen (the newest frame is recorded and later); refuse rather than guess.
            return Placement::TooLate;
        };
        match self.slots[usize::from(self.order[position])].before.last_timestamp_s {
            Some(previous_s) if previous_s == timestamp_s => Placement::Duplicate,
            Some(previous_s) if previous_s > timestamp_s => Placement::TooLate,
            _ => Placement::Before(position),
        }
    }

    /// A slot not holding a recorded frame, to fill with the next frame.
    pub(crate) fn spare(&self) -> usize {
        (0..self.slots.len())
            .find(|&index| !self.order.iter().any(|&used| usize::from(used) == index))
            .expect("the ring has one slot more than it records")
    }

    /// The slot at `index`.
    pub(crate) fn slot_mut(&mut self, index: usize) -> &mut ReplaySlot {
        &mut self.slots[index]
    }

    /// The slot index of the recorded frame at `position` (0 = oldest).
    pub(crate) fn slot_at(&self, position: usize) -> usize {
        usize::from(self.order[position])
    }

    /// Records slot `slot` at `position` among the recorded frames (call
    /// [`trim`](Self::trim) after).
    pub(crate) fn insert(&mut self, slot: usize, position: usize) {
        // `slot` < capacity + 1 <= MAX_REPLAY_FRAMES + 1 fits in u8, and `order` has room for
        // one more than the capacity (the spare slot is the only one not in it).
        self.order.insert(position.min(self.order.len()), slot as u8);
    }

    /// Drops the oldest recorded frames beyond the capacity, and those older than the window
    /// behind `newest_s` (no late frame can go before them any more).
    pub(crate) fn trim(&mut self, newest_s: f64) {
        while self.order.len() > self.capacity {
            self.order.remove(0);
        }
        while self.order.len() > 1 {
            let oldest = &self.slots[usize::from(self.order[0])];
            if newest_s - oldest.frame.timestamp_s() > self.max_delay_s {
                self.order.remove(0);
            } else {
                break;
            }
        }
    }

    /// The slot at `index`.
    pub(crate) fn slot(&self, index: usize) -> &ReplaySlot {
        &self.slots[index]
    }

    /// Drops the recorded frame at `position` (one that could not be tracked again).
    pub(crate) fn remove(&mut self, position: usize) {
        self.order.remove(position);
    }

    /// Copies one slot's snapshot into another's (no allocation: both have room for every
    /// track).
    pub(crate) fn copy_snapshot(&mut self, from: usize, to: usize) {
        if from == to {
            return;
        }
        let (source, target) = if from < to {
            let (left, right) = self.slots.split_at_mut(to);
            (&left[from], &mut right[0])
        } else {
            let (left, right) = self.slots.split_at_mut(from);
            (&right[0], &mut left[to])
        };
        target.before.tracks.clear();
        target.before.tracks.extend_from_slice(&source.before.tracks);
        target.before.next_id = source.before.next_id;
        target.before.last_timestamp_s = source.before.last_timestamp_s;
        target.before.tracks_frame = source.before.tracks_frame;
        target.before.last_pose = source.before.last_pose;
        target.before.ego_motion = source.before.ego_motion;
        target.before.stats = source.before.stats;
        target.before.sensors = source.before.sensors;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::Frame;

    /// A ring holding frames at `times`, each recorded after the one before.
    fn ring_with(capacity: usize, max_delay_s: f64, times: &[f64]) -> ReplayRing {
        let mut ring = ReplayRing::new(capacity, max_delay_s);
        let mut previous = None;
        for &t in times {
            let slot = ring.spare();
            ring.slot_mut(slot).frame.read_from(&Frame::new(t));
            ring.slot_mut(slot).before.last_timestamp_s = previous;
            ring.insert(slot, ring.len());
            ring.trim(t);
            previous = Some(t);
        }
        ring
    }

    #[test]
    fn a_frame_goes_before_the_first_newer_recorded_frame() {
        let ring = ring_with(8, 0.15, &[1.00, 1.02, 1.04, 1.06]);
        assert_eq!(ring.place(1.07, Some(1.06)), Placement::InOrder);
        assert_eq!(ring.place(1.05, Some(1.06)), Placement::Before(3));
        assert_eq!(ring.place(1.01, Some(1.06)), Placement::Before(1));
        assert_eq!(ring.place(0.99, Some(1.06)), Placement::Before(0));
        assert_eq!(ring.place(f64::NAN, Some(1.06)), Placement::InOrder);
    }

    #[test]
    fn repeated_times_and_frames_beyond_the_window_or_the_ring_are_refused() {
        let ring = ring_with(8, 0.15, &[1.00, 1.02, 1.04, 1.06]);
        assert_eq!(ring.place(1.06, Some(1.06)), Placement::Duplicate);
        assert_eq!(ring.place(1.02, Some(1.06)), Placement::Duplicate);
        assert_eq!(ring.place(0.90, Some(1.06)), Placement::TooLate);
        // A ring of two keeps 1.04 and 1.06: 1.01 falls before the frame the ring starts from.
        let short = ring_with(2, 0.15, &[1.00, 1.02, 1.04, 1.06]);
        assert_eq!(short.len(), 2);
        assert_eq!(short.place(1.03, Some(1.06)), Placement::Before(0));
        assert_eq!(short.place(1.01, Some(1.06)), Placement::TooLate);
    }

    #[test]
    fn frames_older_than_the_window_are_dropped_and_a_ring_that_is_off_places_everything_in_order() {
        let ring = ring_with(8, 0.05, &[1.00, 1.02, 1.04, 1.06, 1.08]);
        assert_eq!(ring.len(), 3, "1.04, 1.06 and 1.08 are within 0.05 s of 1.08");
        let off = ReplayRing::new(8, 0.0);
        assert!(!off.is_enabled());
        assert_eq!(off.place(0.5, Some(1.0)), Placement::InOrder);
        let none = ReplayRing::new(0, 0.15);
        assert!(!none.is_enabled());
        assert_eq!(none.place(0.5, Some(1.0)), Placement::InOrder);
    }

    #[test]
    fn a_snapshot_copy_carries_every_field() {
        let mut ring = ReplayRing::new(2, 0.15);
        ring.slot_mut(0).before.next_id = 42;
        ring.slot_mut(0).before.last_timestamp_s = Some(3.0);
        ring.slot_mut(0).before.stats.frames_tracked = 7;
        ring.copy_snapshot(0, 2);
        let copy = &ring.slot(2).before;
        assert_eq!((copy.next_id, copy.last_timestamp_s, copy.stats.frames_tracked), (42, Some(3.0), 7));
        ring.copy_snapshot(2, 1);
        assert_eq!(ring.slot(1).before.next_id, 42);
    }
}
