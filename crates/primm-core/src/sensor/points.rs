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

use crate::grouping::GroupingConfig;

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
}

impl Default for PointsEstimate {
    fn default() -> Self {
        Self::new()
    }
}

impl PointsEstimate {
    /// The estimate at its prior: objects, share 0.
    pub const fn new() -> Self {
        PointsEstimate { track_scans: 0.0, multiples: 0.0, samples: 0, points: false, switches: 0 }
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
            self.multiples = 0.0;
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

    /// The share the decision compares: the radar's own counts with the share pooled over the
    /// vehicle's `auto` radars that have evidence (`pooled_share`, when any have), weighing
    /// `points_pool_scans` track scans. A radar that sees few vehicles (one looking sideways)
    /// then follows the others until its own scans outweigh them.
    pub fn decision_share(&self, config: &GroupingConfig, pooled_share: Option<f64>) -> f64 {
        let (pool_scans, pool_multiples) = match pooled_share {
            Some(share) => (config.points_pool_scans, config.points_pool_scans * share),
            None => (0.0, 0.0),
        };
        let scans = self.track_scans + pool_scans;
        if scans > 0.0 {
            ((self.multiples + pool_multiples) / scans).clamp(0.0, 1.0)
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
