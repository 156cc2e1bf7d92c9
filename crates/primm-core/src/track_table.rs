//! The fixed-capacity table of live tracks.
//!
//! Capacity is [`MAX_TRACKS`], allocated once when the tracker is built. When the table is
//! full a new track is refused: the refusal is returned as a value and counted by the
//! tracker, and no live track, confirmed or tentative, is ever evicted to make room. The
//! unassigned measurement that could not start a track is simply not tracked; capacity is
//! freed as stale tracks are deleted.

use crate::track::Track;
use alloc::boxed::Box;
use arrayvec::ArrayVec;

pub use crate::limits::MAX_TRACKS;

/// The table is full; the new track was not created.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("track table is full ({MAX_TRACKS} tracks)")]
pub struct TableFull;

/// Live tracks in creation order, plus the id counter.
#[derive(Debug)]
pub struct TrackTable {
    tracks: Box<ArrayVec<Track, MAX_TRACKS>>,
    next_id: u64,
}

impl Default for TrackTable {
    fn default() -> Self {
        Self::new()
    }
}

impl TrackTable {
    /// An empty table; ids start at 1.
    pub fn new() -> Self {
        Self { tracks: Box::new(ArrayVec::new()), next_id: 1 }
    }

    /// The live tracks.
    pub fn tracks(&self) -> &[Track] {
        &self.tracks
    }

    /// The live tracks, mutable.
    pub fn tracks_mut(&mut self) -> &mut [Track] {
        &mut self.tracks
    }

    /// Number of live tracks.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    /// Whether no track is live.
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// Whether another track fits.
    pub fn is_full(&self) -> bool {
        self.tracks.is_full()
    }

    /// Adds a track built by `make` from a fresh id; ids are consumed only on success.
    pub fn insert(&mut self, make: impl FnOnce(u64) -> Track) -> Result<&mut Track, TableFull> {
        if self.tracks.is_full() {
            return Err(TableFull);
        }
        let track = make(self.next_id);
        self.next_id += 1;
        self.tracks.push(track);
        Ok(self.tracks.last_mut().expect("just pushed"))
    }

    /// Keeps the tracks for which `keep` is true, in order; returns how many were removed.
    pub fn retain(&mut self, mut keep: impl FnMut(&Track) -> bool) -> usize {
        let before = self.tracks.len();
        self.tracks.retain(|track| keep(track));
        before - self.tracks.len()
    }

    /// Removes every track; ids keep counting.
    pub fn clear(&mut self) {
        self.tracks.clear();
    }

    /// Copies the live tracks into `tracks` (which must have room for [`MAX_TRACKS`], so that
    /// nothing is allocated) and returns the next id: what [`restore`](Self::restore) needs.
    pub(crate) fn save(&self, tracks: &mut alloc::vec::Vec<Track>) -> u64 {
        tracks.clear();
        tracks.extend_from_slice(&self.tracks);
        self.next_id
    }

    /// Puts the table back as [`save`](Self::save) found it.
    pub(crate) fn restore(&mut self, tracks: &[Track], next_id: u64) {
        self.tracks.clear();
        for track in tracks.iter().take(MAX_TRACKS) {
            self.tracks.push(track.clone());
        }
        self.next_id = next_id;
    }
}
