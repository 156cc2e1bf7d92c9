//! Seeded generator of realistic radar scenarios in the style of RadarScenes.
//!
//! The paper (Section IV, "Dataset") trains and evaluates on RadarScenes, which is not
//! redistributable. This module emulates what such a recording contains, so that the predictor
//! can be trained and the tracker evaluated on data with the same structure:
//!
//! * an ego vehicle driving an urban road grid (cruising, turning at junctions, stopping at
//!   signals) whose pose is known per frame;
//! * four radars on the front bumper, each scanning every ~60 ms; one frame is one scan of one
//!   sensor, so frames alternate between sensors and arrive every ~15 ms on average with
//!   irregular spacing;
//! * cars and pedestrians with bounded speed, acceleration, jerk and yaw rate, which enter and
//!   leave the fields of view, meet closely and cross each other's paths;
//! * object-level measurements formed like the paper's (Section III-A, `eq:measurement_full`):
//!   the average of reflection points drawn on the visible outline of the object, with
//!   ego-motion compensated radial velocity and RCS, plus occlusion and random misses;
//! * optionally, false detections: clutter over the field of view and multipath ghosts behind
//!   objects (see [`ClutterConfig`]);
//! * optionally, vehicles measured as extended objects: separate detections from the visible
//!   contour and corners of each vehicle's box, sometimes several per scan (see
//!   [`ExtendedObjectConfig`]);
//! * optionally, detection-level output: several detections per object and scan, wheel
//!   micro-Doppler, multipath ghosts mirrored in the walls along the roads and wrong class labels
//!   (see [`PointCloudConfig`]).
//!
//! Everything is deterministic given the configuration and a seed. See `docs/scenario.md` for
//! the full model description, its limits, and every parameter.
//!
//! ```
//! use primm_sim::scenario::{ScenarioGenerator, Split, Preset};
//!
//! let mut config = Preset::Default.config();
//! config.sequence.duration_s = 1.0;
//! let generator = ScenarioGenerator::new(config).unwrap();
//! let generated = generator.generate(Split::Evaluation, 0);
//! assert_eq!(generated.sequence.frames.len(), generated.truth.len());
//! ```

mod clutter;
mod config;
mod events;
#[cfg(test)]
mod extended_tests;
mod kinematics;
mod path;
mod point_cloud;
#[cfg(test)]
mod point_cloud_tests;
mod radar;
mod road;
#[cfg(test)]
mod sensor_presets_tests;
mod split;
mod world;

use glam::DVec2;
use rand::SeedableRng;
use rand_chacha::ChaCha12Rng;
use serde::{Deserialize, Serialize};

pub use config::{
    CarConfig, ClutterConfig, ConfigError, DriverConfig, EgoConfig, EgoPlacement, ExtendedObjectConfig,
    Interval, MotionLimits, OutputConfig, PedestrianConfig, PointCloudConfig, Preset, RadarConfig,
    RadarMount, RadarReport, ReflectionConfig, RoadConfig, ScenarioConfig, ScenarioTomlError, SequenceConfig,
    SplitConfig, TrafficConfig, WalkerConfig, MAX_DETECTIONS_PER_OBJECT,
};
pub use events::{
    count_events, EventCounts, CLOSE_PROXIMITY_DISTANCE_M, CROSSING_DISTANCE_M,
    CROSSING_MAX_HEADING_DIFF_DEG, CROSSING_MIN_HEADING_DIFF_DEG, MOVING_SPEED_MPS,
};
pub use split::{format_table, Split, SplitSummary};

use crate::io::{EgoPose, RecordedFrame, Sequence};
use primm_core::measurement::ObjectClass;

/// Random stream of the traffic simulation.
const STREAM_WORLD: u64 = 1;
/// Random stream of the scan schedule.
const STREAM_SCHEDULE: u64 = 2;
/// Random stream of the measurement model.
const STREAM_SENSOR: u64 = 3;
/// Random stream of the false detections, so that clutter leaves every real measurement as it
/// is without clutter.
const STREAM_CLUTTER: u64 = 4;
/// Random stream of the extended-object detections of vehicles, so that the point model's
/// stream, and with it every preset without extended objects, stays as it was.
const STREAM_EXTENDED: u64 = 5;
/// Random stream of the point-cloud detections, so that every preset without them stays as it
/// was.
const STREAM_POINT_CLOUD: u64 = 6;

/// True state of one object at one frame (world frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObjectState {
    /// Ground-truth id, as in the measurements.
    pub id: u64,
    /// Object class.
    pub class: ObjectClass,
    /// Centre of the object's box, world frame, metres.
    pub position: DVec2,
    /// Heading, radians, counter-clockwise from the world x axis.
    pub heading_rad: f64,
    /// Speed along the heading, m/s (never negative).
    pub speed_mps: f64,
    /// Longitudinal acceleration, m/s².
    pub acceleration_mps2: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_radps: f64,
    /// Box length, metres.
    pub length_m: f64,
    /// Box width, metres.
    pub width_m: f64,
}

impl ObjectState {
    /// World velocity, m/s.
    pub fn velocity(&self) -> DVec2 {
        DVec2::from_angle(self.heading_rad) * self.speed_mps
    }
}

/// True state of the ego vehicle at one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EgoState {
    /// Pose of the rear-axle reference point.
    pub pose: EgoPose,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Longitudinal acceleration, m/s².
    pub acceleration_mps2: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_radps: f64,
}

/// Ground truth of one frame: every simulated object, visible or not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthFrame {
    /// Frame time, seconds (same as the recorded frame's).
    pub timestamp_s: f64,
    /// The sensor that scanned, also where the recorded frame leaves it out
    /// (`output.sensor_id = false`).
    pub sensor_id: u16,
    /// The ego vehicle.
    pub ego: EgoState,
    /// All objects that exist at this time.
    pub objects: Vec<ObjectState>,
}

impl TruthFrame {
    /// The state of object `id`, if it exists at this frame.
    pub fn object(&self, id: u64) -> Option<&ObjectState> {
        self.objects.iter().find(|o| o.id == id)
    }
}

/// A generated sequence: the recording and its ground truth, frame by frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedSequence {
    /// Split the sequence belongs to, if generated for one.
    pub split: Option<Split>,
    /// Seed the sequence was generated from.
    pub seed: u64,
    /// What the sensors recorded.
    pub sequence: Sequence,
    /// Ground truth; `truth[i]` belongs to `sequence.frames[i]`.
    pub truth: Vec<TruthFrame>,
}

/// Generates sequences from a validated configuration.
#[derive(Debug, Clone)]
pub struct ScenarioGenerator {
    config: ScenarioConfig,
}

/// Offset between the seed ranges of the splits (see [`SplitConfig`]).
pub const SPLIT_SEED_STRIDE: u64 = 1 << 40;

impl ScenarioGenerator {
    /// A generator for `config`, which is validated first.
    pub fn new(config: ScenarioConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self { config })
    }

    /// A generator for a named preset.
    pub fn from_preset(preset: Preset) -> Self {
        Self::new(preset.config()).expect("presets are valid")
    }

    /// The configuration in use.
    pub fn config(&self) -> &ScenarioConfig {
        &self.config
    }

    /// Number of sequences of `split`.
    pub fn sequence_count(&self, split: Split) -> u32 {
        let s = &self.config.splits;
        match split {
            Split::Train => s.train_sequences,
            Split::Validation => s.validation_sequences,
            Split::Evaluation => s.evaluation_sequences,
        }
    }

    /// Seed of sequence `index` of `split`: `seed_base + split_index · 2^40 + index`.
    pub fn seed(&self, split: Split, index: u32) -> u64 {
        let offset = match split {
            Split::Train => 0,
            Split::Validation => SPLIT_SEED_STRIDE,
            Split::Evaluation => 2 * SPLIT_SEED_STRIDE,
        };
        self.config.splits.seed_base.wrapping_add(offset).wrapping_add(u64::from(index))
    }

    /// Generates sequence `index` of `split`, named `<split>_<index:04>`.
    pub fn generate(&self, split: Split, index: u32) -> GeneratedSequence {
        let name = format!("{}_{index:04}", split.name());
        let mut generated = self.generate_seeded(self.seed(split, index), &name);
        generated.split = Some(split);
        generated
    }

    /// All sequences of `split`, generated lazily in index order.
    pub fn split_sequences(&self, split: Split) -> impl Iterator<Item = GeneratedSequence> + '_ {
        (0..self.sequence_count(split)).map(move |index| self.generate(split, index))
    }

    /// Generates one sequence from an explicit seed.
    pub fn generate_seeded(&self, seed: u64, name: &str) -> GeneratedSequence {
        let cfg = &self.config;
        let rng_for = |stream| {
            let mut rng = ChaCha12Rng::seed_from_u64(seed);
            rng.set_stream(stream);
            rng
        };
        let mut world = world::World::new(cfg, rng_for(STREAM_WORLD));
        let scans = radar::schedule(&cfg.radar, cfg.sequence.duration_s, &mut rng_for(STREAM_SCHEDULE));
        let mut random = radar::ScanRandom {
            sensor: rng_for(STREAM_SENSOR),
            extended: rng_for(STREAM_EXTENDED),
            point_cloud: rng_for(STREAM_POINT_CLOUD),
        };
        let mut clutter_rng = rng_for(STREAM_CLUTTER);
        let warmup = cfg.sequence.warmup_s;
        let mut sequence = Sequence::new(name);
        let mut truth = Vec::with_capacity(scans.len());
        for (index, scan) in scans.iter().enumerate() {
            world.advance_to(warmup + scan.t);
            let mut scanned = radar::scan(&world, cfg, scan.sensor, &mut random);
            clutter::add_false_detections(
                &cfg.clutter,
                &cfg.radar,
                scan.sensor,
                scanned.doppler_bias_mps,
                &mut scanned.measurements,
                &mut clutter_rng,
            );
            let ego_pose = world.ego_pose();
            let sensor_id = cfg.radar.sensors[scan.sensor].layout.id;
            let mut frame = RecordedFrame::new(index as u64, scan.t);
            frame.sensor_id = Some(sensor_id);
            frame.ego_pose = Some(ego_pose);
            frame.measurements = scanned.measurements;
            apply_output(&cfg.output, &mut frame);
            sequence.frames.push(frame);
            let ego = world.ego();
            truth.push(TruthFrame {
                timestamp_s: scan.t,
                sensor_id,
                ego: EgoState {
                    pose: ego_pose,
                    speed_mps: ego.kin.speed,
                    acceleration_mps2: ego.kin.accel,
                    yaw_rate_radps: ego.kin.yaw_rate,
                },
                objects: world
                    .agents
                    .iter()
                    .filter(|a| !a.is_ego)
                    .map(|a| ObjectState {
                        id: a.id,
                        class: a.class,
                        position: a.kin.position,
                        heading_rad: a.kin.heading,
                        speed_mps: a.kin.speed,
                        acceleration_mps2: a.kin.accel,
                        yaw_rate_radps: a.kin.yaw_rate,
                        length_m: a.length,
                        width_m: a.width,
                    })
                    .collect(),
            });
        }
        GeneratedSequence { split: None, seed, sequence, truth }
    }
}

/// Leaves out of a recorded frame what `output` does not write: the ego pose, the sensor id of
/// the frame and of each of its measurements.
fn apply_output(output: &OutputConfig, frame: &mut RecordedFrame) {
    if !output.ego_pose {
        frame.ego_pose = None;
    }
    if !output.sensor_id {
        frame.sensor_id = None;
        for measurement in &mut frame.measurements {
            measurement.measurement.sensor_id = None;
        }
    }
}
