//! Duplicate tracks of one object, and merging them.
//!
//! A radar sees a car from where each sensor stands: its reflections come from the part of the
//! body facing that sensor, a metre or two from where another sensor sees it. When a
//! measurement falls outside the gate of the object's track, it starts a second track, and the
//! two then trade the object's measurements, each taking those nearer to it. Two tracks are
//! taken for one object when, in the same class,
//!
//! * their fused positions lie within `classes.<class>.duplicate_distance_m` and their fused
//!   velocities within `classes.<class>.duplicate_speed_difference_mps` of each other, and
//! * for `tracker.duplicate_updates` consecutive updates of either track, the other one was not
//!   updated in the same frame.
//!
//! The second condition tells a duplicate from two real objects side by side (two pedestrians
//! walking together): a scan that sees two objects measures both, so their tracks are updated
//! in the same frame and the count starts again, while one object gives one measurement per
//! scan. The younger track is then merged into the older one: the older keeps its id, age and
//! hit count, and takes the younger's state if the younger was updated more recently.

use crate::config::Config;
use glam::DVec2;

/// A live track as the duplicate check sees it: fused position and velocity after the frame,
/// and whether a measurement updated it in this frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DuplicateView {
    /// Fused posterior position, m (tracking frame).
    pub position_m: DVec2,
    /// Fused velocity, m/s.
    pub velocity_mps: DVec2,
    /// Whether a measurement updated (or started) the track in this frame.
    pub updated: bool,
}

/// Whether tracks `a` and `b` of one class overlap: within the class's duplicate distance and
/// speed difference.
pub fn overlap(a: &DuplicateView, b: &DuplicateView, distance_m: f64, speed_difference_mps: f64) -> bool {
    a.position_m.distance_squared(b.position_m) <= distance_m * distance_m
        && a.velocity_mps.distance_squared(b.velocity_mps) <= speed_difference_mps * speed_difference_mps
}

/// The new exclusive-update count of a track paired with the same older track as before:
/// unchanged in a frame that updated neither, restarted when both were updated, one more when
/// one of them was.
pub fn next_exclusive_updates(count: u32, younger_updated: bool, older_updated: bool) -> u32 {
    match (younger_updated, older_updated) {
        (false, false) => count,
        (true, true) => 0,
        _ => count.saturating_add(1),
    }
}

/// Whether the duplicate check is on (`tracker.duplicate_updates` > 0).
pub fn enabled(config: &Config) -> bool {
    config.tracker.duplicate_updates > 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(x: f64, vx: f64, updated: bool) -> DuplicateView {
        DuplicateView { position_m: DVec2::new(x, 0.0), velocity_mps: DVec2::new(vx, 0.0), updated }
    }

    #[test]
    fn tracks_overlap_within_distance_and_speed_difference_only() {
        assert!(overlap(&view(0.0, 5.0, true), &view(2.0, 6.0, false), 2.5, 1.5));
        assert!(!overlap(&view(0.0, 5.0, true), &view(3.0, 5.0, false), 2.5, 1.5));
        assert!(!overlap(&view(0.0, 5.0, true), &view(1.0, 7.0, false), 2.5, 1.5));
    }

    #[test]
    fn joint_updates_restart_the_count_and_exclusive_ones_add_to_it() {
        assert_eq!(next_exclusive_updates(3, true, false), 4);
        assert_eq!(next_exclusive_updates(3, false, true), 4);
        assert_eq!(next_exclusive_updates(3, false, false), 3);
        assert_eq!(next_exclusive_updates(3, true, true), 0);
        assert_eq!(next_exclusive_updates(u32::MAX, true, false), u32::MAX);
    }
}
