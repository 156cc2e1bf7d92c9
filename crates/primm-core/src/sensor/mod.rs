//! A radar as the tracker knows it: one type that every stage asks about a sensor.
//!
//! A [`Sensor`] holds the sensor's configured mount (`[[frame.sensors]]`, its file form: pose,
//! field of view, polar noise, measurement model and existence factors) and what the tracker has
//! learned of it from its data ([`SensorEstimates`]). Radars without a configured mount (no
//! sensor id, or one not listed) share one more sensor, the *unmounted* one: it is seen from
//! the vehicle's reference point, its field of view is built from its detections of each frame
//! (`FieldOfView::spanning`), and it has no noise of its own; its measurement model is
//! `frame.unmounted_reflection`.
//!
//! The measurement model of a sensor ([`ReflectionModel`]) says where on an extended object its
//! detections lie: on the outline (the extent's expected reflection, scaled by the class's
//! `extent.offset_scale`; the default), at the centre (an object-list radar, or clustered
//! detections), or where its data says (`auto`: the running estimate of
//! [`estimates::ReflectionEstimate`]).

pub mod estimates;
pub mod platform;
pub mod points;

use crate::coordinates::CoordinatesConfig;
use crate::existence::{ExistenceConfig, FieldOfView};
use crate::extent::ExtentConfig;
use crate::grouping::DetectionModel;
use crate::limits::MAX_SENSORS;
use crate::measurement::ObjectClass;
use crate::pose::{EgoPose, SensorMount};
use crate::sensor_noise::SensorNoise;
use estimates::{ClutterEstimate, DetectionEstimate, ReflectionEstimate};
use glam::DVec2;
use points::PointsEstimate;

/// Where a sensor's detections of an extended object lie (`[[frame.sensors]] reflection`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ReflectionModel {
    /// On the outline: the extent's expected reflection, scaled by the class's
    /// `extent.offset_scale` (a detection-level radar reporting its strongest reflection, or
    /// averaging the reflections of the faces it sees). The default.
    #[default]
    Outline,
    /// At the object's centre, with the class's measurement noise (an object-list radar, or a
    /// stack that clusters detections before tracking).
    Centre,
    /// Where the sensor's data says: the scale starts at the class's `extent.offset_scale` and
    /// follows the running estimate ([`estimates::ReflectionEstimate`]).
    Auto,
}

impl ReflectionModel {
    /// The short name used in configuration and output.
    pub fn name(self) -> &'static str {
        match self {
            ReflectionModel::Outline => "outline",
            ReflectionModel::Centre => "centre",
            ReflectionModel::Auto => "auto",
        }
    }
}

/// What the tracker has learned of a sensor for one class.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClassEstimates {
    /// Where its detections lie between the centre (0) and the outline (1).
    pub reflection: ReflectionEstimate,
    /// Its detection probability.
    pub detection: DetectionEstimate,
    /// Its clutter density.
    pub clutter: ClutterEstimate,
}

/// What the tracker has learned of a sensor, per class ([`ObjectClass::index`]).
pub type SensorEstimates = [ClassEstimates; ObjectClass::COUNT];

/// A sensor: its configured mount (none for the unmounted sensor) and its estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensor {
    /// The configured mount; `None` for the radars without one.
    pub mount: Option<SensorMount>,
    /// The measurement model of extended objects.
    pub reflection: ReflectionModel,
    /// What one of its detections is: a point of a point cloud or an object.
    pub detections: DetectionModel,
    /// What its data said so far.
    pub estimates: SensorEstimates,
    /// Whether its data look like a point cloud (`detections = "auto"`).
    pub points: PointsEstimate,
}

impl Sensor {
    /// A sensor of `mount` (or the unmounted one with `reflection`) at its priors: each class's
    /// configured offset scale, detection probability and clutter density (with the mount's
    /// factors).
    fn new(
        mount: Option<SensorMount>,
        (reflection, detections): (ReflectionModel, DetectionModel),
        classes: &[(&ExtentConfig, &ExistenceConfig); ObjectClass::COUNT],
    ) -> Self {
        let (detection_factor, clutter_factor) = mount
            .map_or((1.0, 1.0), |mount| (mount.detection_probability_factor, mount.clutter_density_factor));
        let estimates = core::array::from_fn(|index| {
            let (extent, existence) = classes[index];
            ClassEstimates {
                reflection: ReflectionEstimate::new(extent.offset_scale),
                detection: DetectionEstimate::new(
                    (existence.detection_probability * detection_factor).min(MAX_DETECTION_PROBABILITY),
                ),
                clutter: ClutterEstimate::new(existence.clutter_density_per_m2 * clutter_factor),
            }
        });
        Sensor { mount, reflection, detections, estimates, points: PointsEstimate::new() }
    }

    /// The sensor id of its mount (`None`: the unmounted sensor).
    pub fn id(&self) -> Option<u16> {
        self.mount.map(|mount| mount.id)
    }

    /// Where the sensor is in the tracking frame: its mount, mapped into the world with the
    /// step's `pose` in a world-frame step; the vehicle's reference point for the unmounted
    /// sensor.
    pub fn position_m(&self, pose: Option<EgoPose>) -> DVec2 {
        let in_vehicle = self.mount.map_or(DVec2::ZERO, |mount| mount.position());
        match pose {
            Some(pose) => pose.point_to_world(in_vehicle),
            None => in_vehicle,
        }
    }

    /// Its configured field of view in the tracking frame (`None` for the unmounted sensor,
    /// whose view its detections give).
    pub fn field_of_view(&self, pose: Option<EgoPose>) -> Option<FieldOfView> {
        self.mount.map(|mount| FieldOfView::of(&mount, pose))
    }

    /// Its polar noise in the tracking frame. The noise enters world-frame steps only (in the
    /// vehicle frame a turning ego sweeps far objects across the line of sight at ω·r, which no
    /// motion model predicts; trusting far detections less there makes their tracks lag:
    /// ARCHITECTURE.md, "The radar's own noise").
    pub fn noise(&self, pose: Option<EgoPose>) -> SensorNoise {
        match (self.mount, pose) {
            (Some(mount), Some(pose)) => SensorNoise::of(&mount, Some(pose)),
            _ => SensorNoise::NONE,
        }
    }

    /// The scale of the outline offset for its detections of `class`: the class's
    /// `extent.offset_scale` (outline), 0 (centre), or the running estimate (auto).
    pub fn reflection_scale(&self, class: ObjectClass, extent: &ExtentConfig) -> f64 {
        match self.reflection {
            ReflectionModel::Outline => extent.offset_scale,
            ReflectionModel::Centre => 0.0,
            ReflectionModel::Auto => self.estimates[class.index()].reflection.value,
        }
    }

    /// Whether its detections are grouped into objects before association: `points`, or
    /// `auto` once its data showed a point cloud.
    pub fn groups_detections(&self) -> bool {
        match self.detections {
            DetectionModel::Points => true,
            DetectionModel::Objects => false,
            DetectionModel::Auto => self.points.points,
        }
    }

    /// The detection probability and clutter density of `class` the existence model uses: the
    /// configured ones (with the mount's factors).
    pub fn detection_and_clutter(&self, class: ObjectClass) -> (f64, f64) {
        let estimates = &self.estimates[class.index()];
        (estimates.detection.prior, estimates.clutter.prior_per_m2)
    }
}

/// The detection probabilities are kept below 1, so that a miss never makes existence 0.
pub const MAX_DETECTION_PROBABILITY: f64 = 0.999;

/// The index of the unmounted sensor in a [`SensorSet`].
pub const UNMOUNTED: usize = MAX_SENSORS;

/// Every sensor of a configuration, the unmounted one last (at [`UNMOUNTED`]); fixed capacity,
/// `Copy`, so that the replay snapshots hold it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorSet {
    sensors: [Sensor; MAX_SENSORS + 1],
    mounted: usize,
    platform: platform::PlatformEstimate,
}

impl SensorSet {
    /// The sensors of `frame` at their priors for `classes`' extents and existence settings.
    pub fn new(
        frame: &CoordinatesConfig,
        classes: &[(&ExtentConfig, &ExistenceConfig); ObjectClass::COUNT],
    ) -> Self {
        let unmounted = Sensor::new(None, (frame.unmounted_reflection, frame.unmounted_detections), classes);
        let mut sensors = [unmounted; MAX_SENSORS + 1];
        for (slot, mount) in frame.sensors.iter().enumerate() {
            sensors[slot] = Sensor::new(Some(*mount), (mount.reflection, mount.detections), classes);
        }
        SensorSet { sensors, mounted: frame.sensors.len(), platform: platform::PlatformEstimate::new() }
    }

    /// The slot of the sensor that measured with `sensor_id`: its mount's, or [`UNMOUNTED`].
    pub fn slot(&self, sensor_id: Option<u16>) -> usize {
        sensor_id
            .and_then(|id| self.sensors[..self.mounted].iter().position(|sensor| sensor.id() == Some(id)))
            .unwrap_or(UNMOUNTED)
    }

    /// The sensor in `slot`.
    pub fn get(&self, slot: usize) -> &Sensor {
        &self.sensors[slot.min(UNMOUNTED)]
    }

    /// The sensor in `slot`, to update its estimates.
    pub fn get_mut(&mut self, slot: usize) -> &mut Sensor {
        &mut self.sensors[slot.min(UNMOUNTED)]
    }

    /// The sensor that measured with `sensor_id`.
    pub fn of(&self, sensor_id: Option<u16>) -> &Sensor {
        self.get(self.slot(sensor_id))
    }

    /// Whether the sensors stand still, as the frames without a pose say (`frame.platform =
    /// "auto"`).
    pub fn platform(&self) -> &platform::PlatformEstimate {
        &self.platform
    }

    /// The platform estimate, to update it.
    pub fn platform_mut(&mut self) -> &mut platform::PlatformEstimate {
        &mut self.platform
    }

    /// Decides for every radar with `detections = "auto"` whether it delivers points, from its
    /// own share and the share pooled over the radars with at least `points_pool_scans` track
    /// scans of their own ([`PointsEstimate::decide`]); before any has, each radar decides
    /// alone. A radar's first few scans, whose share swings, never move the others. Before its
    /// first track scan a radar's prior follows the clusters of the scans of every `auto`
    /// radar before theirs ([`PointsEstimate::observe_scan`]; its own alone when
    /// `points_pool_scans` is 0).
    pub fn decide_points(&mut self, config: &crate::grouping::GroupingConfig) {
        let slots = || (0..self.mounted).chain(core::iter::once(UNMOUNTED));
        let auto = |sensor: &Sensor| sensor.detections == DetectionModel::Auto;
        // The track scans of the radars with enough of their own, and the scans before each
        // radar's first track scan, pooled over the `auto` radars (the latter each radar's own
        // when they decide alone).
        let (mut multiples, mut scans) = (0.0, 0.0);
        let (mut detections, mut clustered) = (0.0, 0.0);
        for sensor in slots().map(|slot| &self.sensors[slot]).filter(|sensor| auto(sensor)) {
            if sensor.points.samples as f64 >= config.points_pool_scans {
                multiples += sensor.points.multiples;
                scans += sensor.points.track_scans;
            }
            detections += f64::from(sensor.points.scan_detections);
            clustered += f64::from(sensor.points.scan_clustered);
        }
        let pooled_share = (scans > 0.0).then(|| multiples / scans);
        let alone = config.points_pool_scans == 0.0;
        let scan_points = |(detections, clustered): (f64, f64)| {
            clustered / (detections + config.points_scan_prior_detections) > config.points_scan_share
        };
        for slot in slots() {
            let sensor = &mut self.sensors[slot];
            if auto(sensor) {
                if sensor.points.samples == 0 {
                    let own =
                        (f64::from(sensor.points.scan_detections), f64::from(sensor.points.scan_clustered));
                    sensor.points.scan_points =
                        scan_points(if alone { own } else { (detections, clustered) });
                }
                sensor.points.decide(config, pooled_share);
            }
        }
    }

    /// The mounted sensors, in configuration order, then the unmounted one.
    pub fn iter(&self) -> impl Iterator<Item = &Sensor> {
        self.sensors[..self.mounted].iter().chain(core::iter::once(&self.sensors[UNMOUNTED]))
    }
}

/// The estimates of every sensor that took a sample, one line per sensor and class, as the
/// service's summary and `primm track` print them ([`SensorSet::report`]).
#[derive(Debug, Clone, Copy)]
pub struct SensorReport<'a> {
    sensors: &'a SensorSet,
    config: &'a crate::config::Config,
}

impl SensorSet {
    /// The estimates of every sensor and class that took a sample, for display.
    pub fn report<'a>(&'a self, config: &'a crate::config::Config) -> SensorReport<'a> {
        SensorReport { sensors: self, config }
    }
}

impl core::fmt::Display for SensorReport<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let mut first = true;
        for sensor in self.sensors.iter() {
            for class in ObjectClass::ALL {
                let estimates = &sensor.estimates[class.index()];
                if estimates.reflection.samples == 0
                    && estimates.detection.samples == 0
                    && estimates.clutter.scans == 0
                {
                    continue;
                }
                start_line(f, sensor, &mut first)?;
                let extent = &self.config.classes.get(class).extent;
                write!(f, " {}: ", class.name())?;
                if extent.enabled {
                    write!(
                        f,
                        "reflection {} (used {:.3}, estimate {:.3}, {} samples), ",
                        sensor.reflection.name(),
                        sensor.reflection_scale(class, extent),
                        estimates.reflection.value,
                        estimates.reflection.samples,
                    )?;
                }
                write!(
                    f,
                    "detection probability {:.3} ({} opportunities), clutter {:.2e} /m² ({} scans), held at bounds {}",
                    estimates.detection.value(),
                    estimates.detection.samples,
                    estimates.clutter.value_per_m2(),
                    estimates.clutter.scans,
                    estimates.reflection.bounded + estimates.detection.bounded + estimates.clutter.bounded,
                )?;
            }
            if sensor.points.samples > 0 || sensor.points.scan_detections > 0 {
                start_line(f, sensor, &mut first)?;
                write!(
                    f,
                    " detections: {} ({}; several per track in {:.3} of {} vehicle track scans; first scans: {} of {} vehicle detections in clusters; decision changed {} times)",
                    sensor.detections.name(),
                    if sensor.groups_detections() { "grouped as points" } else { "objects" },
                    sensor.points.share(),
                    sensor.points.samples,
                    sensor.points.scan_clustered,
                    sensor.points.scan_detections,
                    sensor.points.switches,
                )?;
            }
        }
        let platform = &self.sensors.platform;
        if platform.samples > 0 {
            if !first {
                f.write_str("\n")?;
            }
            write!(
                f,
                "platform: {} ({}; velocity estimate {} from {} updates without a pose; decision changed {} times)",
                self.config.frame.platform.name(),
                if platform.stationary { "stationary" } else { "moving" },
                PlatformVelocity(platform.velocity_mps()),
                platform.samples,
                platform.switches,
            )?;
        }
        Ok(())
    }
}

/// The platform's velocity estimate for the report: `(x, y) m/s`, or that it lacks information.
struct PlatformVelocity(Option<DVec2>);

impl core::fmt::Display for PlatformVelocity {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.0 {
            Some(velocity) => write!(f, "({:.2}, {:.2}) m/s", velocity.x, velocity.y),
            None => f.write_str("not yet determined"),
        }
    }
}

/// Starts a line of the report for `sensor`: a line break unless it is the `first`, then the
/// sensor's name.
fn start_line(f: &mut core::fmt::Formatter<'_>, sensor: &Sensor, first: &mut bool) -> core::fmt::Result {
    if !*first {
        f.write_str("\n")?;
    }
    *first = false;
    match sensor.id() {
        Some(id) => write!(f, "sensor {id}"),
        None => f.write_str("sensor without mount"),
    }
}
