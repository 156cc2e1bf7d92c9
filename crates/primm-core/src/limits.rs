//! Every capacity of the tracker in one place.
//!
//! All buffers are sized from these constants once, when a tracker is built; nothing grows
//! per frame. Overflowing a capacity is returned or counted as a value, never a panic:
//! a frame with more than [`MAX_MEASUREMENTS_PER_FRAME`] measurements is rejected
//! (`FrameError`), and a full track table refuses new tracks
//! (`TrackerStats::initiations_refused_table_full`) without evicting a live one.

/// Largest number of live tracks (confirmed and tentative).
pub const MAX_TRACKS: usize = 512;

/// Largest number of measurements one frame may carry.
pub const MAX_MEASUREMENTS_PER_FRAME: usize = 1024;

/// Longest measurement history the learned predictor reads (`L` in `eq:pr_input`); also the
/// capacity of each track's history buffer.
pub const MAX_HISTORY: usize = 5;

/// Largest number of gated track–measurement pairs the association considers in one class of
/// one frame: every track with every measurement.
pub const MAX_ASSOCIATION_PAIRS: usize = MAX_TRACKS * MAX_MEASUREMENTS_PER_FRAME;

/// Largest number of radar sensors whose mounting poses a configuration can hold.
pub const MAX_SENSORS: usize = 16;

/// Largest number of recent frames the tracker keeps for tracking a late frame in its place
/// (`tracker.replay_frames`; see `crate::replay`).
pub const MAX_REPLAY_FRAMES: usize = 64;
