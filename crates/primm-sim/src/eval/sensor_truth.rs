//! The true properties of the simulated sensors, per sensor and class, from generated sequences
//! and their ground truth: the reference a tracker's online estimates of its sensors are
//! measured against.
//!
//! * **Reflection offset fraction** `s`: where detections lie between the object's centre (0)
//!   and the outline point the tracker's extent model expects (1). With `d` a detection minus
//!   its object's true centre and `o` the model's outline offset for that object (its true
//!   centre, its true velocity as heading, no uncertainty, the class's `classes.<class>.extent`
//!   of the tracker's configuration with `offset_scale` 1, the sensor at its mount), `s` is the
//!   least-squares coefficient of `d` on `o` over every detection of a real object:
//!   `s = Σ d·o / Σ |o|²`.
//! * **Detection probability**: the share of (object, scan) pairs, with the object's centre in
//!   the scanning sensor's field of view and range (its mount's `half_fov_rad`,
//!   `max_range_m`), in which the object yielded at least one detection. Also the same share
//!   over the pairs within the class's detection range (`car_reflection.detection_range_m`,
//!   `pedestrian_reflection.detection_range_m`; 70 m for pedestrians by default), beyond which
//!   the generator never detects the class, so a tracker never holds a track there to learn
//!   from. And the same share over those of them in clear view, *the sensor's detection
//!   probability*: the line of sight from the sensor to the object's centre crosses no other
//!   object's box ([`primm_core::occlusion`]). Hidden objects are mostly missed (the generator's
//!   `radar.occluded_point_probability`), but how often an object is hidden is the scene's, not
//!   the sensor's: in a crowd it is half the time.
//! * **Clutter density**: false detections (no ground-truth id) labelled with the class, per scan
//!   and per m² of the field of view (the sector `half_fov_rad · max_range_m²`).
//!
//! The sensor of a frame is the one the ground truth names ([`TruthFrame::sensor_id`]), also
//! where the recorded frame carries no sensor id; its mount is the generator's
//! (`radar.sensors`), which for the presets with sensor ids is the tracker's default layout.

use std::collections::BTreeMap;

use glam::DVec2;
use serde::Serialize;

use crate::scenario::{GeneratedSequence, ObjectState, ScenarioConfig, ScenarioGenerator, Split, TruthFrame};
use primm_core::config::Config;
use primm_core::extent::{ExtentConfig, ObjectPrior};
use primm_core::measurement::ObjectClass;
use primm_core::occlusion::ObjectBox;
use primm_core::pose::SensorMount;

/// The true properties of one sensor for one class.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorClassTruth {
    /// The sensor.
    pub sensor_id: u16,
    /// The class.
    pub class: ObjectClass,
    /// Whether the tracker's configuration tracks the class as an extended object (the offset
    /// model exists for every class; the fraction means most where it is used).
    pub extent_enabled: bool,
    /// Least-squares coefficient of the detections' offsets from the true centres on the
    /// outline offsets; `None` without a detection of a real object.
    pub reflection_offset_fraction: Option<f64>,
    /// Detections of real objects the fraction was fitted on.
    pub detections: u64,
    /// Share of in-view (object, scan) pairs with a detection; `None` without such a pair.
    pub detection_probability: Option<f64>,
    /// (Object, scan) pairs with the object's centre in the field of view and range.
    pub objects_in_view: u64,
    /// Of those, the pairs with at least one detection.
    pub objects_detected: u64,
    /// The detection probability over the in-view pairs within the class's detection range;
    /// `None` without such a pair.
    pub detection_probability_in_class_range: Option<f64>,
    /// In-view (object, scan) pairs within the class's detection range.
    pub objects_in_class_range: u64,
    /// Of those, the pairs with at least one detection.
    pub objects_detected_in_class_range: u64,
    /// The detection probability over the in-view pairs within the class's detection range
    /// whose object no other object hides from the sensor; `None` without such a pair.
    pub detection_probability_in_clear_view: Option<f64>,
    /// In-view pairs within the class's detection range in clear view of the sensor.
    pub objects_in_clear_view: u64,
    /// Of those, the pairs with at least one detection.
    pub objects_detected_in_clear_view: u64,
    /// False detections of the class per scan per m² of the field of view; `None` without a
    /// scan of the sensor.
    pub clutter_density_per_m2: Option<f64>,
    /// False detections labelled with the class.
    pub false_detections: u64,
    /// Scans of the sensor.
    pub scans: u64,
    /// Area of the sensor's field-of-view sector, m².
    pub field_of_view_m2: f64,
}

/// A frame names a sensor the mounts do not list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("frame {frame} of sequence seed {seed} comes from sensor {sensor_id}, which no mount lists")]
pub struct UnknownSensor {
    /// Seed of the sequence.
    pub seed: u64,
    /// Index of the frame.
    pub frame: u64,
    /// The sensor.
    pub sensor_id: u16,
}

/// Running sums of one sensor and class.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    offset_dot_outline: f64,
    outline_squared: f64,
    detections: u64,
    objects_in_view: u64,
    objects_detected: u64,
    objects_in_class_range: u64,
    objects_detected_in_class_range: u64,
    objects_in_clear_view: u64,
    objects_detected_in_clear_view: u64,
    false_detections: u64,
}

/// Collects the sums over sequences; [`SensorTruthAccumulator::finish`] gives the table.
#[derive(Debug, Clone)]
pub struct SensorTruthAccumulator {
    mounts: Vec<SensorMount>,
    extents: [ExtentConfig; ObjectClass::COUNT],
    class_ranges_m: [f64; ObjectClass::COUNT],
    sums: BTreeMap<(u16, usize), Sums>,
    scans: BTreeMap<u16, u64>,
}

impl SensorTruthAccumulator {
    /// An empty accumulator for the sensors and classes of `scenario` (its `radar.sensors` and
    /// the classes' detection ranges) and the class extents of the tracker configuration
    /// `config`.
    pub fn new(scenario: &ScenarioConfig, config: &Config) -> Self {
        Self {
            mounts: scenario.radar.sensor_layout(),
            extents: ObjectClass::ALL.map(|class| config.classes.get(class).extent),
            class_ranges_m: ObjectClass::ALL.map(|class| match class {
                ObjectClass::Pedestrian => scenario.pedestrian_reflection.detection_range_m,
                _ => scenario.car_reflection.detection_range_m,
            }),
            sums: BTreeMap::new(),
            scans: BTreeMap::new(),
        }
    }

    /// Adds every frame of a generated sequence.
    pub fn add_sequence(&mut self, generated: &GeneratedSequence) -> Result<(), UnknownSensor> {
        for (frame, truth) in generated.sequence.frames.iter().zip(&generated.truth) {
            let mount = self.mount(truth.sensor_id).ok_or(UnknownSensor {
                seed: generated.seed,
                frame: frame.index,
                sensor_id: truth.sensor_id,
            })?;
            *self.scans.entry(mount.id).or_default() += 1;
            for recorded in &frame.measurements {
                let measurement = &recorded.measurement;
                let sums = self.sums.entry((mount.id, measurement.class as usize)).or_default();
                match (measurement.ground_truth_id, recorded.true_position) {
                    (Some(_), Some(centre)) => {
                        let velocity = recorded.true_velocity.unwrap_or(DVec2::ZERO);
                        let extent = &self.extents[measurement.class as usize];
                        let outline = outline_offset(extent, centre, velocity, mount.position());
                        sums.offset_dot_outline += (measurement.position() - centre).dot(outline);
                        sums.outline_squared += outline.length_squared();
                        sums.detections += 1;
                    }
                    (None, _) => sums.false_detections += 1,
                    (Some(_), None) => {}
                }
            }
            self.add_objects_in_view(&mount, frame, truth);
        }
        Ok(())
    }

    /// Counts the objects whose centre `mount` sees in this frame, and which of them it detected.
    fn add_objects_in_view(
        &mut self,
        mount: &SensorMount,
        frame: &crate::io::RecordedFrame,
        truth: &TruthFrame,
    ) {
        let sensor_m = truth.ego.pose.point_to_world(mount.position());
        for object in &truth.objects {
            let centre = truth.ego.pose.world_to_car(object.position);
            if !in_view(mount, centre) {
                continue;
            }
            let detected =
                frame.measurements.iter().any(|m| m.measurement.ground_truth_id == Some(object.id));
            let in_class_range =
                centre.distance(mount.position()) <= self.class_ranges_m[object.class as usize];
            let in_clear_view = in_class_range
                && !truth.objects.iter().any(|other| {
                    other.id != object.id && object_box(other).crossed_by(sensor_m, object.position)
                });
            let sums = self.sums.entry((mount.id, object.class as usize)).or_default();
            sums.objects_in_view += 1;
            sums.objects_detected += u64::from(detected);
            sums.objects_in_class_range += u64::from(in_class_range);
            sums.objects_detected_in_class_range += u64::from(in_class_range && detected);
            sums.objects_in_clear_view += u64::from(in_clear_view);
            sums.objects_detected_in_clear_view += u64::from(in_clear_view && detected);
        }
    }

    fn mount(&self, sensor_id: u16) -> Option<SensorMount> {
        self.mounts.iter().find(|mount| mount.id == sensor_id).copied()
    }

    /// The truth of every (sensor, class) pair seen, in sensor and class order.
    pub fn finish(&self) -> Vec<SensorClassTruth> {
        self.sums
            .iter()
            .filter_map(|(&(sensor_id, class_index), sums)| {
                let mount = self.mount(sensor_id)?;
                let class = ObjectClass::ALL[class_index];
                let scans = self.scans.get(&sensor_id).copied().unwrap_or(0);
                let field_of_view_m2 = mount.half_fov_rad * mount.max_range_m * mount.max_range_m;
                Some(SensorClassTruth {
                    sensor_id,
                    class,
                    extent_enabled: self.extents[class_index].enabled,
                    reflection_offset_fraction: (sums.outline_squared > 0.0)
                        .then(|| sums.offset_dot_outline / sums.outline_squared),
                    detections: sums.detections,
                    detection_probability: (sums.objects_in_view > 0)
                        .then(|| sums.objects_detected as f64 / sums.objects_in_view as f64),
                    objects_in_view: sums.objects_in_view,
                    objects_detected: sums.objects_detected,
                    detection_probability_in_class_range: (sums.objects_in_class_range > 0).then(|| {
                        sums.objects_detected_in_class_range as f64 / sums.objects_in_class_range as f64
                    }),
                    objects_in_class_range: sums.objects_in_class_range,
                    objects_detected_in_class_range: sums.objects_detected_in_class_range,
                    detection_probability_in_clear_view: (sums.objects_in_clear_view > 0).then(|| {
                        sums.objects_detected_in_clear_view as f64 / sums.objects_in_clear_view as f64
                    }),
                    objects_in_clear_view: sums.objects_in_clear_view,
                    objects_detected_in_clear_view: sums.objects_detected_in_clear_view,
                    clutter_density_per_m2: (scans > 0 && field_of_view_m2 > 0.0)
                        .then(|| sums.false_detections as f64 / (scans as f64 * field_of_view_m2)),
                    false_detections: sums.false_detections,
                    scans,
                    field_of_view_m2,
                })
            })
            .collect()
    }
}

/// The truth table of `sequences` sequences (all when `None`) of `split` of `generator`, with
/// the class extents of the tracker configuration `tracker`.
pub fn sensor_truth_of_split(
    generator: &ScenarioGenerator,
    split: Split,
    sequences: Option<u32>,
    tracker: &Config,
) -> Result<Vec<SensorClassTruth>, UnknownSensor> {
    let count = sequences.unwrap_or_else(|| generator.sequence_count(split));
    let mut accumulator = SensorTruthAccumulator::new(generator.config(), tracker);
    for index in 0..count {
        accumulator.add_sequence(&generator.generate(split, index))?;
    }
    Ok(accumulator.finish())
}

/// The outline offset the extent model expects for an object at `centre_m` moving at
/// `velocity_mps`, seen from `sensor_m`: its expected reflection with `offset_scale` 1 and no
/// uncertainty.
pub fn outline_offset(extent: &ExtentConfig, centre_m: DVec2, velocity_mps: DVec2, sensor_m: DVec2) -> DVec2 {
    let object = ObjectPrior { centre_m, velocity_mps, ..ObjectPrior::default() };
    primm_core::extent::outline_reflection(extent, &object, sensor_m).offset_m
}

/// The true box of `object` (world frame).
fn object_box(object: &ObjectState) -> ObjectBox {
    ObjectBox {
        centre_m: object.position,
        heading: DVec2::from_angle(object.heading_rad),
        half_extent_m: DVec2::new(0.5 * object.length_m, 0.5 * object.width_m),
    }
}

/// Whether `point` (car frame) lies within `mount`'s range and field of view.
fn in_view(mount: &SensorMount, point: DVec2) -> bool {
    let relative = point - mount.position();
    let range = relative.length();
    let along_boresight = DVec2::from_angle(-mount.yaw_rad).rotate(relative);
    let azimuth = along_boresight.y.atan2(along_boresight.x);
    range <= mount.max_range_m && azimuth.abs() <= mount.half_fov_rad
}

/// The table as plain text: one row per sensor and class (`P_D ranged`: the detection
/// probability within the class's detection range; `P_D clear`: of those, in clear view).
pub fn format_sensor_truth(rows: &[SensorClassTruth]) -> String {
    let mut text = format!(
        "{:>6} {:<11} {:>10} {:>10} {:>9} {:>10} {:>11} {:>10} {:>12} {:>8}\n",
        "sensor",
        "class",
        "reflection",
        "detections",
        "P_D",
        "in view",
        "P_D ranged",
        "P_D clear",
        "clutter/m2",
        "false"
    );
    let number = |value: Option<f64>, digits: usize| match value {
        Some(value) => format!("{value:.digits$}"),
        None => "-".to_owned(),
    };
    for row in rows {
        text.push_str(&format!(
            "{:>6} {:<11} {:>10} {:>10} {:>9} {:>10} {:>11} {:>10} {:>12} {:>8}\n",
            row.sensor_id,
            row.class.name(),
            number(row.reflection_offset_fraction, 3),
            row.detections,
            number(row.detection_probability, 3),
            row.objects_in_view,
            number(row.detection_probability_in_class_range, 3),
            number(row.detection_probability_in_clear_view, 3),
            row.clutter_density_per_m2.map_or_else(|| "-".to_owned(), |v| format!("{v:.3e}")),
            row.false_detections,
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Preset;

    /// The truth of `count` short validation sequences of `preset`, with the shipped tracker
    /// configuration.
    fn truth_of(preset: Preset, count: u32) -> Vec<SensorClassTruth> {
        let mut scenario = preset.config();
        scenario.sequence.duration_s = 3.0;
        let generator = ScenarioGenerator::new(scenario).expect("a valid preset");
        sensor_truth_of_split(&generator, Split::Validation, Some(count), &Config::default())
            .expect("the truth of a preset")
    }

    /// The detection-weighted mean reflection offset fraction of the cars over every sensor.
    fn car_reflection_fraction(rows: &[SensorClassTruth]) -> f64 {
        let cars: Vec<&SensorClassTruth> = rows.iter().filter(|row| row.class == ObjectClass::Car).collect();
        let detections: u64 = cars.iter().map(|row| row.detections).sum();
        assert!(detections > 100, "{detections} car detections");
        cars.iter().map(|row| row.reflection_offset_fraction.unwrap() * row.detections as f64).sum::<f64>()
            / detections as f64
    }

    #[test]
    fn centre_reports_lie_at_no_fraction_of_the_outline_and_extended_reflections_further_out_than_echoes() {
        let centroid = car_reflection_fraction(&truth_of(Preset::Centroid, 2));
        let default = car_reflection_fraction(&truth_of(Preset::Default, 2));
        let extended = car_reflection_fraction(&truth_of(Preset::Extended, 2));
        assert!(centroid.abs() < 0.05, "centroid {centroid}");
        assert!(default > centroid + 0.2, "default {default}, centroid {centroid}");
        assert!(extended > default + 0.1, "extended {extended}, default {default}");
    }

    #[test]
    fn detection_probability_and_clutter_follow_the_preset() {
        let default = truth_of(Preset::Default, 1);
        let clutter = truth_of(Preset::Clutter, 1);
        for row in &default {
            assert_eq!(row.false_detections, 0, "{row:?}");
            assert_eq!(row.clutter_density_per_m2, Some(0.0), "{row:?}");
            let probability = row.detection_probability.expect("objects in view");
            assert!(probability > 0.2 && probability <= 1.0, "{row:?}");
            assert!(row.objects_detected <= row.objects_in_view);
            // Next to nothing is detected beyond the class's detection range.
            let in_range = row.detection_probability_in_class_range.expect("objects in range");
            assert!(in_range >= probability, "{row:?}");
            // (A box may reach into range with its centre still outside.)
            let beyond = row.objects_detected - row.objects_detected_in_class_range;
            assert!(beyond <= row.objects_detected / 100 + 1, "{row:?}");
        }
        // About 1.5 false detections per scan over the sector up to 80 m of a 100 m sensor.
        let false_detections: u64 = clutter.iter().map(|row| row.false_detections).sum();
        let scans: u64 =
            clutter.iter().filter(|row| row.class == ObjectClass::Car).map(|row| row.scans).sum();
        let per_scan = false_detections as f64 / scans as f64;
        assert!((1.2..2.0).contains(&per_scan), "{per_scan} false detections per scan");
        assert!(clutter.iter().all(|row| row.clutter_density_per_m2.unwrap() > 0.0));
    }

    #[test]
    fn objects_in_clear_view_are_detected_more_often_and_in_a_crowd_much_more_often() {
        let share = |rows: &[SensorClassTruth], class: ObjectClass| {
            let rows: Vec<_> = rows.iter().filter(|row| row.class == class).collect();
            let ranged = rows.iter().map(|row| row.objects_detected_in_class_range).sum::<u64>() as f64
                / rows.iter().map(|row| row.objects_in_class_range).sum::<u64>() as f64;
            let clear = rows.iter().map(|row| row.objects_detected_in_clear_view).sum::<u64>() as f64
                / rows.iter().map(|row| row.objects_in_clear_view).sum::<u64>() as f64;
            for row in rows {
                assert!(row.objects_in_clear_view <= row.objects_in_class_range, "{row:?}");
                assert!(row.objects_detected_in_clear_view <= row.objects_in_clear_view, "{row:?}");
            }
            (ranged, clear)
        };
        // A roadside sensor in a crowd: about half of the cars in range are hidden at any time,
        // and a hidden car is mostly missed.
        let (ranged, clear) = share(&truth_of(Preset::DenseStatic, 1), ObjectClass::Car);
        assert!(clear > ranged + 0.15, "crowd: in range {ranged}, in clear view {clear}");
        let (ranged, clear) = share(&truth_of(Preset::Default, 1), ObjectClass::Car);
        assert!(
            clear >= ranged && clear < ranged + 0.15,
            "default: in range {ranged}, in clear view {clear}"
        );
    }

    #[test]
    fn a_frame_of_a_sensor_without_a_mount_is_refused() {
        let mut scenario = Preset::Default.config();
        scenario.sequence.duration_s = 0.5;
        let generated = ScenarioGenerator::new(scenario.clone()).unwrap().generate(Split::Validation, 0);
        scenario.radar.sensors.truncate(1);
        let mut accumulator = SensorTruthAccumulator::new(&scenario, &Config::default());
        let error = accumulator.add_sequence(&generated).unwrap_err();
        assert_ne!(error.sensor_id, scenario.radar.sensors[0].layout.id);
    }
}
