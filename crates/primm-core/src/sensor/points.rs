//! Whether a radar delivers a point cloud or objects (`detections = "auto"`), from its data.
//!
//! A confirmed track of a class with an extent (a vehicle) in a scan of the radar is one *track
//! scan* when at least one of the scan's detections lies on the track's object
//! (`crate::grouping`); it is a *multiple* when several do. Pedestrians do not count: a point
//! cloud gives one of them one or two detections, an object list one, so their scans say
//! little about the radar and dilute what the vehicles say. Only detections with a vehicle
//! class's label count (`crate::tracker`'s grouping stage): a pedestrian passing a slow car lies
//! in its box and moves much as the car does. An object-list radar gives one detection per object, so its multiples are the rare scans
//! in which another object's detection falls inside a track's box; a point-cloud radar gives
//! several per vehicle in most scans. The share of multiples is estimated like the detection
//! probability (`crate::sensor::estimates::DetectionEstimate`): the prior share 0 (objects, the
//! behaviour of a tracker without a front end) enters as `points_prior_scans` pseudo-scans, and
//! beyond `points_window_scans` counts and prior are scaled down together. The radar is taken to
//! deliver points once the share passes `points_share_threshold`, and objects again once it
//! falls below `points_fallback_share`, so that a share near the threshold does not switch
//! the front end from scan to scan. The share is counted in either state from the
//! raw detections, so the decision does not feed back into its own evidence.
//!
//! Before its first track scan a radar has no confirmed track to count on, and tracking a point
//! cloud one detection at a time in those scans starts several tracks per vehicle that outlive
//! the decision. So until then its scans speak for themselves: the share of its vehicle
//! detections that lie in a cluster of at least [`SCAN_CLUSTER_DETECTIONS`] vehicle
//! detections linked by the grouping's link rule (`crate::grouping::linkage`), pooled over the
//! `auto` radars with `points_scan_prior_detections` pseudo-detections outside any cluster. An
//! object list puts one detection on each object, and objects are metres apart; a radar that
//! reflects on the outline gives an object a second detection now and then; a point cloud gives
//! a vehicle three or more detections in most scans. Past `points_scan_share` the radar starts
//! as points, and its prior then weighs its `points_prior_scans` pseudo-scans at share 1 instead
//! of 0.

use crate::grouping::GroupingConfig;

/// The fewest linked vehicle detections of one scan that count as one object's point cloud
/// before a radar's first track scan: more than the pair an outline radar gives an object now
/// and then.
pub const SCAN_CLUSTER_DETECTIONS: usize = 3;

/// A radar's running share of multiple detections per confirmed track and its decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointsEstimate {
    /// Track scans within the window, the prior's pseudo-scans included (0 before the first).
    pub track_scans: f64,
    /// Multiples among them.
    pub multiples: f64,
    /// Track scans taken in all.
    pub samples: u64,
    /// Whether the radar is taken to deliver points.
    pub points: bool,
    /// Times the decision changed.
    pub switches: u64,
    /// Vehicle detections of the radar's scans before its first track scan.
    pub scan_detections: u32,
    /// Those of them in a cluster of at least [`SCAN_CLUSTER_DETECTIONS`].
    pub scan_clustered: u32,
    /// Whether the scans before the first track scan (pooled over the `auto` radars) said
    /// points: the prior's share is then 1.
    pub scan_points: bool,
}

impl Default for PointsEstimate {
    fn default() -> Self {
        Self::new()
    }
}

impl PointsEstimate {
    /// The estimate at its prior: objects, share 0.
    pub const fn new() -> Self {
        PointsEstimate {
            track_scans: 0.0,
            multiples: 0.0,
            samples: 0,
            points: false,
            switches: 0,
            scan_detections: 0,
            scan_clustered: 0,
            scan_points: false,
        }
    }

    /// The share of multiples, in [0, 1] (0 before the first track scan).
    pub fn share(&self) -> f64 {
        if self.track_scans > 0.0 {
            (self.multiples / self.track_scans).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Takes one track scan with `detections` (at least one) of the radar on the track's object.
    /// The decision follows with [`Self::decide`].
    pub fn observe(&mut self, config: &GroupingConfig, detections: usize) {
        if self.samples == 0 {
            self.track_scans = config.points_prior_scans;
            self.multiples = self.prior_multiples(config);
        }
        self.track_scans += 1.0;
        self.multiples += f64::from(u8::from(detections >= 2));
        self.samples += 1;
        let window = config.points_window_scans.max(config.points_prior_scans);
        if self.track_scans > window {
            let scale = window / self.track_scans;
            self.track_scans = window;
            self.multiples *= scale;
        }
    }

    /// The prior's multiples: its pseudo-scans at share 1 when the scans before the first track
    /// scan said points, else 0.
    fn prior_multiples(&self, config: &GroupingConfig) -> f64 {
        if self.scan_points {
            config.points_prior_scans
        } else {
            0.0
        }
    }

    /// Takes one scan's vehicle detections before the first track scan: `detections` of them,
    /// `clustered` in a cluster of at least [`SCAN_CLUSTER_DETECTIONS`]. Ignored once the radar
    /// has track scans.
    pub fn observe_scan(&mut self, detections: usize, clustered: usize) {
        if self.samples == 0 {
            let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
            self.scan_detections = self.scan_detections.saturating_add(count(detections));
            self.scan_clustered = self.scan_clustered.saturating_add(count(clustered.min(detections)));
        }
    }

    /// The share the decision compares: the radar's own counts with the share pooled over the
    /// vehicle's `auto` radars that have evidence (`pooled_share`, when any have), weighing
    /// `points_pool_scans` track scans. A radar that sees few vehicles (one looking sideways)
    /// then follows the others until its own scans outweigh them.
    pub fn decision_share(&self, config: &GroupingConfig, pooled_share: Option<f64>) -> f64 {
        let (pool_scans, pool_multiples) = match pooled_share {
            Some(share) => (config.points_pool_scans, config.points_pool_scans * share),
            None => (0.0, 0.0),
        };
        // Before the first track scan the prior alone speaks for the radar, and only when its
        // scans said points (a prior at share 0 leaves the decision to the pool, as before).
        let (own_scans, own_multiples) = match (self.samples, self.scan_points) {
            (0, true) => (config.points_prior_scans, self.prior_multiples(config)),
            (0, false) => (0.0, 0.0),
            _ => (self.track_scans, self.multiples),
        };
        let scans = own_scans + pool_scans;
        if scans > 0.0 {
            ((own_multiples + pool_multiples) / scans).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Decides, with hysteresis, from [`Self::decision_share`].
    pub fn decide(&mut self, config: &GroupingConfig, pooled_share: Option<f64>) {
        let share = self.decision_share(config, pooled_share);
        let decided = if self.points {
            share >= config.points_fallback_share
        } else {
            share > config.points_share_threshold
        };
        if decided != self.points {
            self.points = decided;
            self.switches += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One track scan, decided on the radar's own counts (no pool).
    fn observe_alone(estimate: &mut PointsEstimate, config: &GroupingConfig, detections: usize) {
        let config = GroupingConfig { points_pool_scans: 0.0, ..*config };
        estimate.observe(&config, detections);
        estimate.decide(&config, None);
    }

    #[test]
    fn a_radar_without_evidence_delivers_objects() {
        let estimate = PointsEstimate::new();
        assert!(!estimate.points);
        assert_eq!(estimate.share(), 0.0);
    }

    #[test]
    fn several_detections_per_track_scan_switch_to_points_after_the_prior_weighs_less() {
        let config = GroupingConfig {
            points_prior_scans: 10.0,
            points_share_threshold: 0.35,
            ..GroupingConfig::default()
        };
        let mut estimate = PointsEstimate::new();
        // 10 pseudo-scans at share 0: the share passes 0.35 at the 6th multiple (6 / 16).
        for scan in 1..=5 {
            observe_alone(&mut estimate, &config, 4);
            assert!(!estimate.points, "switched after {scan} scans");
        }
        observe_alone(&mut estimate, &config, 3);
        assert!(estimate.points);
        assert_eq!(estimate.switches, 1);
    }

    #[test]
    fn with_the_default_prior_of_three_track_scans_the_second_multiple_decides() {
        let config = GroupingConfig::default();
        let mut estimate = PointsEstimate::new();
        observe_alone(&mut estimate, &config, 2);
        // (0 + 1) / (3 + 1) = 0.25 stays below 0.3.
        assert!(!estimate.points, "{}", estimate.share());
        // (0 + 1 + 1) / (3 + 2) = 0.4 passes it.
        observe_alone(&mut estimate, &config, 2);
        assert!(estimate.points, "{}", estimate.share());
    }

    #[test]
    fn a_radar_that_turns_out_to_deliver_objects_falls_back_with_hysteresis() {
        let config = GroupingConfig { points_window_scans: 100.0, ..GroupingConfig::default() };
        let mut estimate = PointsEstimate::new();
        for _ in 0..200 {
            observe_alone(&mut estimate, &config, 4);
        }
        assert!(estimate.points);
        let mut scans_to_fall_back = 0;
        while estimate.points {
            observe_alone(&mut estimate, &config, 1);
            scans_to_fall_back += 1;
            assert!(scans_to_fall_back < 1000);
        }
        // It falls back below the fallback share 0.2, not at the threshold 0.3.
        let share = estimate.share();
        assert!(share < config.points_fallback_share && share > 0.15, "{share}");
        assert_eq!(estimate.switches, 2);
    }

    #[test]
    fn the_occasional_second_detection_of_an_object_list_keeps_objects() {
        let config = GroupingConfig::default();
        let mut estimate = PointsEstimate::new();
        for scan in 0..5000 {
            observe_alone(&mut estimate, &config, if scan % 5 == 4 { 2 } else { 1 });
            assert!(!estimate.points, "turned at scan {scan}: {}", estimate.share());
        }
        assert!((estimate.share() - 0.2).abs() < 0.02);
    }

    #[test]
    fn an_object_list_whose_first_track_scan_is_a_multiple_stays_grouped_above_a_low_fallback() {
        // A prior of one track scan turns a radar on its first multiple; with a fallback share of
        // 0.05 a share of 0.2 then keeps it grouped (the price of keeping point clouds grouped
        // while their vehicles are far), where the default 0.2 lets it fall back.
        let config = GroupingConfig {
            points_fallback_share: 0.05,
            points_prior_scans: 1.0,
            ..GroupingConfig::default()
        };
        let mut estimate = PointsEstimate::new();
        for scan in 0..5000 {
            observe_alone(&mut estimate, &config, if scan % 5 == 0 { 2 } else { 1 });
        }
        assert!(estimate.points);
        assert_eq!(estimate.switches, 1);
        // Only single detections from then on: it falls back once the share drops below 0.05.
        while estimate.points {
            observe_alone(&mut estimate, &config, 1);
        }
        assert!(estimate.share() < config.points_fallback_share, "{}", estimate.share());
    }

    #[test]
    fn a_radar_whose_first_scans_said_points_starts_grouped_and_its_prior_then_weighs_share_one() {
        let config = GroupingConfig::default();
        let mut estimate = PointsEstimate::new();
        estimate.observe_scan(12, 9);
        assert_eq!((estimate.scan_detections, estimate.scan_clustered), (12, 9));
        estimate.scan_points = true;
        estimate.decide(&config, None);
        assert!(estimate.points);
        // Its track scans then show single detections only: (3 + 0) / (3 + n) falls below the
        // fallback share 0.2 once n passes 12.
        let mut scans = 0;
        while estimate.points {
            observe_alone(&mut estimate, &config, 1);
            scans += 1;
            assert!(scans < 100);
        }
        assert_eq!(scans, 13);
        // Scans after the first track scan are not counted.
        estimate.observe_scan(50, 50);
        assert_eq!((estimate.scan_detections, estimate.scan_clustered), (12, 9));
    }

    #[test]
    fn a_radar_whose_first_scans_said_objects_decides_as_before() {
        let config = GroupingConfig::default();
        let (mut heeded, mut plain) = (PointsEstimate::new(), PointsEstimate::new());
        heeded.observe_scan(40, 2);
        for detections in [2, 1, 2, 2, 1] {
            for estimate in [&mut heeded, &mut plain] {
                observe_alone(estimate, &config, detections);
            }
            assert_eq!((heeded.points, heeded.share()), (plain.points, plain.share()));
        }
    }

    #[test]
    fn a_radar_that_sees_few_vehicles_follows_the_pool_until_its_own_scans_outweigh_it() {
        let config = GroupingConfig { points_pool_scans: 20.0, ..GroupingConfig::default() };
        let mut sideways = PointsEstimate::new();
        // No scans of its own: the pool's share 0.5 decides.
        sideways.decide(&config, Some(0.5));
        assert!(sideways.points);
        // Its own scans, all single detections, then outweigh the pool: (0 + 20·0.5) / (3 + n + 20)
        // falls below the fallback share 0.2 once n passes 27.
        let mut scans = 0;
        while sideways.points {
            sideways.observe(&config, 1);
            sideways.decide(&config, Some(0.5));
            scans += 1;
            assert!(scans < 100);
        }
        assert_eq!(scans, 28);
        // With an object-list pool nothing turns.
        let mut alone = PointsEstimate::new();
        alone.decide(&config, Some(0.05));
        assert!(!alone.points);
    }
}
