//! The detection-level front end: a radar that reports several detections per object per scan
//! (a point cloud) has each scan's detections grouped into object measurements before
//! association, so that the tracker sees one measurement per object, as from an object-list
//! radar (ARCHITECTURE.md, "Point clouds").
//!
//! Grouping runs after the prediction, in two passes over the detections of the radars that
//! deliver points ([`DetectionModel`]):
//!
//! 1. **Guided by the tracks.** A detection on the object of a confirmed track (inside its box
//!    at the prior, grown by the class's `extent.absorb_margin_m`; the nearest track's when
//!    several boxes hold it) joins that track's group of its radar. Two cars side by side stay
//!    two groups however close their faces are, and wheel returns with odd radial velocities
//!    stay with their car.
//! 2. **Clustered.** The remaining detections are grouped by single linkage ([`linkage`]) in
//!    position, with a link distance that grows with the range as the radar's azimuth noise
//!    does, and in radial velocity; these groups start tracks.
//!
//! Each group becomes one measurement ([`summary`]). Detections of radars that deliver
//! objects pass through unchanged.

pub mod contour;
pub mod frame_groups;
pub mod linkage;
pub mod summary;

/// What one detection of a radar is (`[[frame.sensors]] detections`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum DetectionModel {
    /// One point of a point cloud: an object gives several per scan, which are grouped.
    Points,
    /// One object: a detection is a measurement of its own (an object-list radar, a clustering
    /// stack, a radar that averages its echoes per object).
    Objects,
    /// Decided from the data ([`crate::sensor::points::PointsEstimate`]): points when confirmed
    /// tracks repeatedly hold several of the radar's detections in one scan. The default.
    #[default]
    Auto,
}

impl DetectionModel {
    /// The short name used in configuration and output.
    pub fn name(self) -> &'static str {
        match self {
            DetectionModel::Points => "points",
            DetectionModel::Objects => "objects",
            DetectionModel::Auto => "auto",
        }
    }
}

/// The section `frame.grouping`: how detections of point-cloud radars are grouped.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct GroupingConfig {
    /// Largest distance between two linked detections at zero range, m (absent: 2.0).
    pub link_distance_m: f64,
    /// Growth of the link distance with range, m per m of range (absent: 0.02, twice a
    /// 0.6° azimuth noise).
    pub link_distance_per_range: f64,
    /// Largest difference of radial velocity between two linked detections, m/s (absent: 2.0).
    pub link_radial_velocity_gap_mps: f64,
    /// The share of the link distance within which two detections both labelled pedestrian
    /// link, dimensionless in (0, 1] (absent: 0.25): people walking side by side, a metre
    /// apart, stay two groups, where a car's faces span metres.
    pub pedestrian_link_scale: f64,
    /// How far beyond its box (the class's extent at the track's prior) a detection still lies
    /// on a confirmed track's object and joins its group, m (absent: 3.0). Wider than the
    /// extent's `absorb_margin_m`: the prior's position error, the spread of a point cloud over
    /// the faces and a vehicle longer than the class's nominal box (a van, a lorry) all reach
    /// beyond the box, and a detection of the object left out of its group pulls the group's
    /// mean towards where the track already is.
    pub owner_margin_m: f64,
    /// With `detections = "auto"`: the share of a radar's confirmed-track scans with several
    /// detections on the track's object above which the radar delivers points, in (0, 1)
    /// (absent: 0.3). It falls back to objects below `points_fallback_share`.
    pub points_share_threshold: f64,
    /// With `detections = "auto"`: the share below which a radar that turned to points falls
    /// back to objects, in [0, `points_share_threshold`) (absent: 0.2). Lower keeps a point
    /// cloud grouped while its vehicles are far or hidden (one detection each), but an object
    /// radar that turned to points by chance then stays grouped.
    pub points_fallback_share: f64,
    /// Weight of the prior share 0 (objects), in track scans (absent: 3).
    pub points_prior_scans: f64,
    /// With `detections = "auto"`: how far beyond a confirmed vehicle track's box (the class's
    /// extent at the track's prior) a detection still counts towards the radar's share of
    /// multiples, m, in [0, 20] (absent: 1.0). While a point cloud is still tracked one
    /// detection at a time its tracks stand off their objects' centres, and a box not grown
    /// holds few of the object's points.
    pub points_evidence_margin_m: f64,
    /// With `detections = "auto"`, before a radar's first track scan: the share of the `auto`
    /// radars' vehicle detections in clusters of at least three linked ones above which a
    /// radar starts as points, in (0, 1] (absent: 0.175; 1: never; `crate::sensor::points`).
    pub points_scan_share: f64,
    /// Weight of the share 0 (no clusters) in that share, in vehicle detections, ≥ 0
    /// (absent: 20).
    pub points_scan_prior_detections: f64,
    /// Memory of the share, in track scans (absent: 2000).
    pub points_window_scans: f64,
    /// Weight of the pooled share of every `auto` radar in one radar's decision, in track scans
    /// (absent: 20; 0: each radar decides alone).
    pub points_pool_scans: f64,
    /// Factor on the existence model's detection probability (every class's, after the
    /// sensor's own factor; at most 0.999) in a scan in which a radar that groups its
    /// detections missed a track, dimensionless, > 0 (absent: 2.5): a group misses its object
    /// only when every one of the object's detections does. A detection keeps the configured
    /// probability, so that an echo seen scan after scan is confirmed no faster.
    pub detection_probability_factor: f64,
    /// Factor on the noise of a group moved to its object's centre, dimensionless, in (0, 1]
    /// (absent: 0.3): the update and the association take the group's mean with its class's
    /// R plus this share of the radar's noise and the contour's spread over the count
    /// (`contour::group_noise_m2`). 1 is the spread of the mean of independent points; a
    /// smaller factor follows far vehicles, whose few points carry the wide azimuth noise, more
    /// closely (ARCHITECTURE.md, "Point clouds").
    pub group_noise_scale: f64,
}

impl Default for GroupingConfig {
    fn default() -> Self {
        GroupingConfig {
            link_distance_m: 2.0,
            link_distance_per_range: 0.02,
            link_radial_velocity_gap_mps: 2.0,
            pedestrian_link_scale: 0.25,
            owner_margin_m: 3.0,
            points_share_threshold: 0.3,
            points_fallback_share: 0.2,
            points_prior_scans: 3.0,
            points_evidence_margin_m: 1.0,
            points_scan_share: 0.175,
            points_scan_prior_detections: 20.0,
            points_window_scans: 2000.0,
            points_pool_scans: 20.0,
            detection_probability_factor: 2.5,
            group_noise_scale: 0.3,
        }
    }
}

impl GroupingConfig {
    /// The rule two detections link by.
    pub fn link_rule(&self) -> linkage::LinkRule {
        linkage::LinkRule {
            distance_m: self.link_distance_m,
            distance_per_range: self.link_distance_per_range,
            radial_velocity_gap_mps: self.link_radial_velocity_gap_mps,
            pedestrian_distance_scale: self.pedestrian_link_scale,
        }
    }

    /// The first problem of the section, as (key, reason).
    pub(crate) fn problem(&self) -> Option<(&'static str, &'static str)> {
        let within = |value: f64, low: f64, high: f64| value >= low && value <= high;
        if !within(self.link_distance_m, 0.0, 20.0) {
            return Some(("frame.grouping.link_distance_m", "must lie in [0, 20] m"));
        }
        if !within(self.link_distance_per_range, 0.0, 1.0) {
            return Some(("frame.grouping.link_distance_per_range", "must lie in [0, 1]"));
        }
        if !within(self.link_radial_velocity_gap_mps, 0.0, 100.0) {
            return Some(("frame.grouping.link_radial_velocity_gap_mps", "must lie in [0, 100] m/s"));
        }
        if !(self.pedestrian_link_scale > 0.0 && self.pedestrian_link_scale <= 1.0) {
            return Some(("frame.grouping.pedestrian_link_scale", "must lie in (0, 1]"));
        }
        if !within(self.owner_margin_m, 0.0, 20.0) {
            return Some(("frame.grouping.owner_margin_m", "must lie in [0, 20] m"));
        }
        if !(self.points_share_threshold > 0.0 && self.points_share_threshold < 1.0) {
            return Some(("frame.grouping.points_share_threshold", "must lie in (0, 1)"));
        }
        if !(self.points_fallback_share >= 0.0 && self.points_fallback_share < self.points_share_threshold) {
            return Some(("frame.grouping.points_fallback_share", "must lie in [0, points_share_threshold)"));
        }
        if !(self.detection_probability_factor > 0.0 && self.detection_probability_factor <= 1e3) {
            return Some(("frame.grouping.detection_probability_factor", "must lie in (0, 1000]"));
        }
        if !(self.group_noise_scale > 0.0 && self.group_noise_scale <= 1.0) {
            return Some(("frame.grouping.group_noise_scale", "must lie in (0, 1]"));
        }
        if !within(self.points_evidence_margin_m, 0.0, 20.0) {
            return Some(("frame.grouping.points_evidence_margin_m", "must lie in [0, 20] m"));
        }
        if !(self.points_scan_share > 0.0 && self.points_scan_share <= 1.0) {
            return Some(("frame.grouping.points_scan_share", "must lie in (0, 1]"));
        }
        if !within(self.points_scan_prior_detections, 0.0, 1e9) {
            return Some(("frame.grouping.points_scan_prior_detections", "must lie in [0, 1e9]"));
        }
        if !within(self.points_pool_scans, 0.0, 1e9) {
            return Some(("frame.grouping.points_pool_scans", "must lie in [0, 1e9]"));
        }
        if !(within(self.points_prior_scans, 1e-9, 1e9) && within(self.points_window_scans, 1e-9, 1e9)) {
            return Some((
                "frame.grouping",
                "points_prior_scans and points_window_scans must lie in (0, 1e9]",
            ));
        }
        None
    }
}
