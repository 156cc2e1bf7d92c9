//! The grouping of one frame: which detection joins which group, and each group's measurement.
//! The workspace is sized once for a full frame; [`FrameGroups::form`] allocates nothing.

use super::linkage::{LinkPoint, LinkRule, Linkage, NO_OWNER};
use super::summary::summarise;
use crate::limits::MAX_MEASUREMENTS_PER_FRAME;
use crate::measurement::Measurement;
use alloc::boxed::Box;
use alloc::vec;
use glam::DVec2;

const NONE: u16 = u16::MAX;
const CAPACITY: usize = MAX_MEASUREMENTS_PER_FRAME;

/// One accepted detection handed to the grouping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// The detection, in the tracking frame.
    pub measurement: Measurement,
    /// Its index in the frame.
    pub frame_index: u16,
    /// Its radar's slot in the sensor set.
    pub sensor_slot: u8,
    /// Its radar's position in the tracking frame, m.
    pub sensor_position_m: DVec2,
    /// Whether its radar's detections are grouped; a detection that is not is a group of its
    /// own.
    pub grouped: bool,
    /// The table row of the confirmed track whose object holds it, if any.
    pub owner: Option<u16>,
}

/// `detection` as the linkage sees it: where it is, its range from its radar, its radial
/// velocity, its radar, its owner and whether it is labelled a pedestrian.
fn link_point(detection: &Detection) -> LinkPoint {
    let position_m = detection.measurement.position();
    LinkPoint {
        position_m,
        range_m: position_m.distance(detection.sensor_position_m),
        radial_velocity_mps: detection.measurement.radial_velocity_mps,
        sensor_slot: detection.sensor_slot,
        owner: detection.owner.unwrap_or(NO_OWNER),
        pedestrian: detection.measurement.class == crate::measurement::ObjectClass::Pedestrian,
    }
}

/// The groups of one frame.
#[derive(Debug, Clone)]
pub struct FrameGroups {
    detections: Box<[Detection]>,
    /// The detections' measurements, aligned with `detections`.
    measurements: Box<[Measurement]>,
    count: usize,
    group_of: Box<[u16]>,
    /// The group of each linkage label.
    label_group: Box<[u16]>,
    /// Members of each group in frame order: `members[member_start[g]..member_start[g + 1]]`.
    members: Box<[u16]>,
    member_start: Box<[u16]>,
    /// Where the next member of each group goes while the members are sorted.
    next_member: Box<[u16]>,
    points: Box<[LinkPoint]>,
    scratch: Box<[f64]>,
    linkage: Box<Linkage>,
    groups: usize,
}

impl Default for FrameGroups {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameGroups {
    /// An empty workspace.
    pub fn new() -> Self {
        const NO_MEASUREMENT: Measurement = Measurement {
            x_m: 0.0,
            y_m: 0.0,
            radial_velocity_mps: 0.0,
            rcs_dbsm: 0.0,
            class: crate::measurement::ObjectClass::Car,
            sensor_id: None,
            ground_truth_id: None,
        };
        const NO_DETECTION: Detection = Detection {
            measurement: NO_MEASUREMENT,
            frame_index: 0,
            sensor_slot: 0,
            sensor_position_m: DVec2::ZERO,
            grouped: false,
            owner: None,
        };
        const NO_POINT: LinkPoint = LinkPoint {
            position_m: DVec2::ZERO,
            range_m: 0.0,
            radial_velocity_mps: 0.0,
            sensor_slot: 0,
            owner: NO_OWNER,
            pedestrian: false,
        };
        FrameGroups {
            detections: vec![NO_DETECTION; CAPACITY].into_boxed_slice(),
            measurements: vec![NO_MEASUREMENT; CAPACITY].into_boxed_slice(),
            count: 0,
            group_of: vec![NONE; CAPACITY].into_boxed_slice(),
            label_group: vec![NONE; CAPACITY].into_boxed_slice(),
            members: vec![0; CAPACITY].into_boxed_slice(),
            member_start: vec![0; CAPACITY + 1].into_boxed_slice(),
            next_member: vec![0; CAPACITY + 1].into_boxed_slice(),
            points: vec![NO_POINT; CAPACITY].into_boxed_slice(),
            scratch: vec![0.0; CAPACITY].into_boxed_slice(),
            linkage: Box::new(Linkage::new()),
            groups: 0,
        }
    }

    /// Forgets the previous frame.
    pub fn clear(&mut self) {
        self.count = 0;
        self.groups = 0;
    }

    /// Adds a detection; `false` (and nothing added) when the workspace is full.
    pub fn push(&mut self, detection: Detection) -> bool {
        if self.count == CAPACITY {
            return false;
        }
        self.detections[self.count] = detection;
        self.measurements[self.count] = detection.measurement;
        self.count += 1;
        true
    }

    /// The detections added since [`clear`](Self::clear).
    pub fn detections(&self) -> impl Iterator<Item = &Detection> {
        self.detections[..self.count].iter()
    }

    /// Groups the detections: the grouped ones by [`Linkage::cluster`] with their owners (the
    /// detections of one owner and radar are one group, and groups of two owners never join),
    /// and each detection that is not grouped is a group of its own. Groups are numbered in the
    /// order of their first detection. Returns the number of groups.
    pub fn form(&mut self, rule: &LinkRule) -> usize {
        self.link(rule);
        self.groups = 0;
        for index in 0..self.count {
            let detection = self.detections[index];
            let group = if detection.grouped {
                let label = self.linkage.label_of(self.group_of[index] as usize);
                if self.label_group[label] == NONE {
                    self.label_group[label] = self.open_group();
                }
                self.label_group[label]
            } else {
                self.open_group()
            };
            self.group_of[index] = group;
        }
        self.sort_members();
        self.groups
    }

    /// Links the grouped detections; `group_of` holds each one's linkage point until
    /// [`form`](Self::form) overwrites it with its group.
    fn link(&mut self, rule: &LinkRule) {
        let mut points = 0;
        for index in 0..self.count {
            let detection = self.detections[index];
            if detection.grouped {
                self.points[points] = link_point(&detection);
                self.group_of[index] = points as u16;
                points += 1;
            }
        }
        let labels = self.linkage.cluster(&self.points[..points], rule);
        self.label_group[..labels].fill(NONE);
    }

    fn open_group(&mut self) -> u16 {
        self.groups += 1;
        (self.groups - 1) as u16
    }

    /// Lists each group's members in frame order (a counting sort by group).
    fn sort_members(&mut self) {
        self.member_start[..=self.groups].fill(0);
        for index in 0..self.count {
            self.member_start[self.group_of[index] as usize + 1] += 1;
        }
        for group in 0..self.groups {
            self.member_start[group + 1] += self.member_start[group];
        }
        self.next_member[..=self.groups].copy_from_slice(&self.member_start[..=self.groups]);
        for index in 0..self.count {
            let group = self.group_of[index] as usize;
            self.members[self.next_member[group] as usize] = index as u16;
            self.next_member[group] += 1;
        }
    }

    /// Links the first `limit` detections that `keep` takes by `rule`, as their own groups
    /// (owners left aside), and returns how many were taken and how many of those lie in a
    /// group of at least `min_size`. Leaves the frame's groups to [`form`](Self::form).
    pub fn clustered(
        &mut self,
        rule: &LinkRule,
        keep: impl Fn(&Detection) -> bool,
        limit: usize,
        min_size: usize,
    ) -> (usize, usize) {
        let mut taken = 0;
        for detection in self.detections[..self.count].iter().filter(|detection| keep(detection)).take(limit)
        {
            self.points[taken] = LinkPoint { owner: NO_OWNER, pedestrian: false, ..link_point(detection) };
            taken += 1;
        }
        let labels = self.linkage.cluster(&self.points[..taken], rule);
        let sizes = &mut self.label_group[..labels];
        sizes.fill(0);
        for index in 0..taken {
            sizes[self.linkage.label_of(index)] += 1;
        }
        let clustered =
            (0..taken).filter(|&index| usize::from(sizes[self.linkage.label_of(index)]) >= min_size).count();
        (taken, clustered)
    }

    /// The number of groups of the latest [`form`](Self::form).
    pub fn groups(&self) -> usize {
        self.groups
    }

    /// Group `group`'s members: indices of [`detections`](Self::detections) in frame order.
    pub fn members(&self, group: usize) -> &[u16] {
        &self.members[self.member_start[group] as usize..self.member_start[group + 1] as usize]
    }

    /// The owner of group `group` (the confirmed track whose object holds one of its
    /// detections; a group has at most one), if any.
    pub fn owner(&self, group: usize) -> Option<u16> {
        self.members(group).iter().find_map(|&member| self.detections[member as usize].owner)
    }

    /// The frame index of group `group`'s representative: its detection nearest to the mean
    /// of its detections (the first of them on a tie), which the outputs name.
    pub fn representative_frame_index(&self, group: usize) -> u16 {
        let members = self.members(group);
        let mean_m = members
            .iter()
            .map(|&member| self.measurements[member as usize].position())
            .fold(DVec2::ZERO, |sum, position| sum + position)
            / members.len() as f64;
        let mut best = (members[0], f64::INFINITY);
        for &member in members {
            let distance_m2 = self.measurements[member as usize].position().distance_squared(mean_m);
            if distance_m2 < best.1 {
                best = (member, distance_m2);
            }
        }
        self.detections[best.0 as usize].frame_index
    }

    /// Group `group`'s measurement ([`summarise`]).
    pub fn measurement(&mut self, group: usize) -> Measurement {
        let (start, end) = (self.member_start[group] as usize, self.member_start[group + 1] as usize);
        summarise(&self.measurements[..self.count], &self.members[start..end], &mut self.scratch)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measurement::ObjectClass;

    fn detection(x_m: f64, y_m: f64, sensor_slot: u8, class: ObjectClass) -> Detection {
        Detection {
            measurement: Measurement {
                x_m,
                y_m,
                radial_velocity_mps: 1.0,
                rcs_dbsm: 0.0,
                class,
                sensor_id: None,
                ground_truth_id: None,
            },
            frame_index: 0,
            sensor_slot,
            sensor_position_m: DVec2::ZERO,
            grouped: false,
            owner: None,
        }
    }

    #[test]
    fn clustered_counts_the_kept_detections_in_groups_of_at_least_the_size_asked() {
        let rule = LinkRule {
            distance_m: 2.0,
            distance_per_range: 0.0,
            radial_velocity_gap_mps: 2.0,
            pedestrian_distance_scale: 1.0,
        };
        let mut groups = FrameGroups::new();
        // Radar 0: a chain of three 1.5 m apart, a pair, a single; radar 1 and a pedestrian
        // beside the chain are not kept.
        for (x_m, y_m) in [(10.0, 0.0), (11.5, 0.0), (13.0, 0.0), (30.0, 0.0), (31.0, 0.0), (50.0, 0.0)] {
            groups.push(detection(x_m, y_m, 0, ObjectClass::Car));
        }
        groups.push(detection(12.0, 1.0, 1, ObjectClass::Car));
        groups.push(detection(14.0, 0.0, 0, ObjectClass::Pedestrian));
        let keep = |d: &Detection| d.sensor_slot == 0 && d.measurement.class == ObjectClass::Car;
        assert_eq!(groups.clustered(&rule, keep, 128, 3), (6, 3));
        assert_eq!(groups.clustered(&rule, keep, 128, 2), (6, 5));
        // Only the first four kept detections: the chain and one of the pair.
        assert_eq!(groups.clustered(&rule, keep, 4, 2), (4, 3));
        // The frame's groups are formed afterwards as before.
        assert_eq!(groups.form(&rule), 8);
    }
}
