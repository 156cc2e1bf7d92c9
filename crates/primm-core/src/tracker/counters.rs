//! The tracker's counters, listed once.
//!
//! [`tracker_counters!`](crate::tracker_counters) holds every counter: its name, what it counts
//! and its kind. [`TrackerStats`](super::TrackerStats) (the totals since the tracker was built)
//! and the counts of one step ([`StepSummary::counts`](super::StepSummary::counts), of the same
//! type) are generated from it, and so is every other view that lists the counters by name: the
//! service's summary, the C API's `PrimmStats` mapping. A new counter is one entry here (and,
//! since `PrimmStats` is then a field longer, the C ABI version and the header).
//!
//! Kinds:
//! * `tracked`: counted while a frame is tracked. When a late frame sends the tracker back to
//!   the state before newer frames, these go back with it, and the newer frames count them
//!   again as they are tracked once more.
//! * `kept`: counted about a frame's fate or a call outside tracking (frame rejections, late
//!   frames, replays, resets); never taken back.

/// Calls `$callback! { ... }` with the list of the tracker's counters: for each, its doc
/// comment, its name and its kind (`tracked` or `kept`; see the module documentation of
/// `primm_core::tracker::counters`). The callback is any `macro_rules!` macro in scope at the
/// call that accepts
/// `$( $(#[$doc:meta])* $name:ident : $kind:ident, )*`.
///
/// ```
/// macro_rules! counter_names {
///     ($( $(#[$doc:meta])* $name:ident : $kind:ident, )*) => {
///         [$(stringify!($name)),*]
///     };
/// }
/// let names = primm_core::tracker_counters!(counter_names);
/// assert!(names.contains(&"tracks_initiated"));
/// assert_eq!(names.len(), primm_core::tracker::TrackerStats::COUNT);
/// ```
#[macro_export]
macro_rules! tracker_counters {
    ($callback:ident) => {
        $callback! {
            /// Frames tracked.
            frames_tracked: tracked,
            /// Frames rejected because the timestamp was not finite.
            frames_rejected_non_finite_timestamp: kept,
            /// Frames rejected because time did not advance.
            frames_rejected_timestamp_not_increasing: kept,
            /// Frames rejected because the interval was too long.
            frames_rejected_interval_too_long: kept,
            /// Frames rejected because they carried too many measurements.
            frames_rejected_too_many_measurements: kept,
            /// Frames rejected because their ego pose was not finite or absurdly far out (only
            /// when tracking in the world frame).
            frames_rejected_invalid_ego_pose: kept,
            /// Frames tracked in the world frame (they carried an ego pose and the configuration
            /// asks for the world frame).
            frames_in_world_frame: tracked,
            /// Frames tracked in the vehicle frame although the configuration asks for the world
            /// frame, because they carried no ego pose.
            frames_without_ego_pose: tracked,
            /// Times the live tracks were moved between the world and the vehicle frame, because
            /// a stream started or stopped carrying ego poses.
            tracking_frame_changes: tracked,
            /// Tracks started in the world frame by a measurement whose sensor has no configured
            /// mount: their line of sight starts at the vehicle's reference point.
            initiations_from_unknown_sensor: tracked,
            /// Unassigned measurements that started no track because they lie where a wall
            /// along a confirmed track's heading would mirror it, moving as its image
            /// (multipath ghosts; ARCHITECTURE.md, "Point clouds").
            initiations_refused_as_ghost: tracked,
            /// Tentative tracks ended as multipath ghosts: their measurement of the step was the
            /// mirror image of a confirmed track (as `initiations_refused_as_ghost`), or their
            /// fused state was, weaker than it (`tracker/ghosts.rs`).
            tentative_tracks_ended_as_ghost: tracked,
            /// Measurements tracked (accepted by validation).
            measurements_accepted: tracked,
            /// Measurements rejected for an unknown class code.
            measurements_rejected_unknown_class: tracked,
            /// Measurements rejected for a NaN or infinite value.
            measurements_rejected_non_finite: tracked,
            /// Measurements rejected for an absurd magnitude.
            measurements_rejected_out_of_range: tracked,
            /// Tracks started.
            tracks_initiated: tracked,
            /// Tracks confirmed (a track started and confirmed at once included).
            tracks_confirmed: tracked,
            /// Tracks deleted.
            tracks_deleted: tracked,
            /// Unassigned measurements that could not start a track because the table was full.
            initiations_refused_table_full: tracked,
            /// Track-frames in which the PR mode had no usable learned displacement and sat out:
            /// the predictor gave none (missed deadline, failed or hung inference) or its answer
            /// was rejected (the three `learned_predictions_rejected_*` counters). Tracks of a
            /// class outside `predictor.classes` are never requested and not counted.
            learned_predictions_missing: tracked,
            /// Frames in which at least one track had no usable learned displacement.
            frames_with_learned_predictions_missing: tracked,
            /// Learned displacements rejected for a NaN or infinite component (included in
            /// `learned_predictions_missing`).
            learned_predictions_rejected_non_finite: tracked,
            /// Learned displacements rejected as faster than
            /// `predictor.max_displacement_speed_mps` (included in `learned_predictions_missing`).
            learned_predictions_rejected_implausible: tracked,
            /// Learned displacements rejected for a covariance that is not finite, symmetric,
            /// positive definite and of plausible size (included in
            /// `learned_predictions_missing`).
            learned_predictions_rejected_invalid_covariance: tracked,
            /// Kalman updates refused for numerical reasons (the track coasted instead).
            update_failures: tracked,
            /// Calls to `Tracker::reset`.
            resets: kept,
            /// Frames with a measurement whose sensor has no configured mount (or no sensor id):
            /// such a radar is taken to look where its detections of the frame lie
            /// (`frame.unknown_sensor_*`), and a track there that it missed loses existence.
            frames_with_unknown_sensor: tracked,
            /// Tracks merged into an older track of the same object (`crate::duplicates`).
            duplicate_tracks_merged: tracked,
            /// Late frames tracked in their place (`crate::replay`): older than the newest
            /// tracked frame, within `tracker.max_frame_delay_s` and the recorded frames.
            late_frames_tracked: kept,
            /// Newer frames tracked again after a late frame (each late frame replays the frames
            /// it went before).
            frames_replayed: kept,
            /// Frames rejected because they were older than the newest tracked frame by more
            /// than the late-frame window (`tracker.max_frame_delay_s`, `tracker.replay_frames`)
            /// reaches.
            frames_rejected_too_late: kept,
            /// Ego poses that jumped further or turned faster than `tracker.max_ego_speed_mps`
            /// and `tracker.max_ego_yaw_rate_radps` allow since the previous frame: odometry
            /// resets, across which the tracks kept their place around the vehicle.
            odometry_resets: tracked,
            /// Track updates in which the measurement's radial velocity was applied as a
            /// measurement of the velocity (`classes.<class>.radial_velocity_update`).
            radial_velocity_updates: tracked,
            /// Track updates whose radial-velocity row lay beyond
            /// `radial_velocity_update.gate_std` in every mode and was left out.
            radial_velocity_updates_gated: tracked,
            /// Track updates and initiations after which a velocity estimate was faster than the
            /// class's `max_speed_mps` and was scaled back onto it (steps with an ego pose only).
            speeds_bounded: tracked,
            /// Updates and initiations of a class with a radial-velocity row or an extent whose
            /// measurement's sensor has no configured mount: seen from the vehicle's reference
            /// point.
            updates_from_unknown_sensor: tracked,
            /// Unassigned measurements absorbed as extra detections of a confirmed track's
            /// extended object (`classes.<class>.extent.absorb_extra_detections`): they started
            /// no track.
            detections_absorbed: tracked,
            /// Detections of point-cloud radars that joined another detection's group
            /// (`crate::grouping`): the accepted detections of grouped frames less the
            /// measurements their groups became.
            detections_grouped: tracked,
            /// Existing tracks updated by an assigned measurement.
            tracks_updated: tracked,
            /// Tracks without a measurement while a sensor of the frame had them in view (their
            /// existence fell); tracks out of every scanning sensor's view are not counted.
            tracks_missed_in_view: tracked,
        }
    };
}

/// Defines [`TrackerStats`](super::TrackerStats) from the list: the struct, its names and
/// values, sums, and the restore of a late frame.
macro_rules! define_tracker_stats {
    ($( $(#[$doc:meta])* $name:ident : $kind:ident, )*) => {
        /// The tracker's counters (the list is in `crate::tracker::counters`): the totals since
        /// the tracker was built ([`Tracker::stats`](super::Tracker::stats)), or what one step
        /// counted ([`StepSummary::counts`](super::StepSummary::counts)).
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize))]
        pub struct TrackerStats {
            $( $(#[$doc])* pub $name: u64, )*
        }

        impl TrackerStats {
            /// The number of counters.
            pub const COUNT: usize = [$(stringify!($name)),*].len();

            /// The counters' names, in the order of the list.
            pub const NAMES: [&'static str; Self::COUNT] = [$(stringify!($name)),*];

            /// Every counter with its name, in the order of the list.
            pub fn named_values(&self) -> [(&'static str, u64); Self::COUNT] {
                [$((stringify!($name), self.$name)),*]
            }

            /// Counters with the values `values`, in the order of the list.
            pub fn from_values(values: [u64; Self::COUNT]) -> Self {
                let [$($name),*] = values;
                TrackerStats { $($name),* }
            }

            /// Adds `other`'s counts to these.
            pub fn add(&mut self, other: &TrackerStats) {
                $( self.$name += other.$name; )*
            }

            /// Goes back to `before` for every `tracked` counter, keeping the `kept` ones: used
            /// when a late frame sends the tracker back to the state before newer frames that are
            /// then tracked again (and counted again).
            pub(super) fn restore_tracked_counts(&mut self, before: &TrackerStats) {
                *self = TrackerStats {
                    $( $name: counter_after_restore!($kind, self.$name, before.$name), )*
                };
            }
        }
    };
}

/// The value of a counter of kind `tracked` or `kept` after a restore: `before`'s, or the
/// current one.
macro_rules! counter_after_restore {
    (tracked, $now:expr, $before:expr) => {
        $before
    };
    (kept, $now:expr, $before:expr) => {
        $now
    };
}

pub(super) use {counter_after_restore, define_tracker_stats};
