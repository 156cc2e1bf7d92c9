//! Scenario configuration: every parameter of the generator, with its unit in its name.
//!
//! [`ScenarioConfig::default`] is the reference configuration; [`Preset`] names it and its
//! variants: a harder configuration for robustness checks, an often-turning ego vehicle, and
//! both scenes with false detections (clutter). All structs deserialize from TOML/JSON with
//! missing fields taken from the default, and [`ScenarioConfig::validate`] checks the physical
//! and logical consistency of a configuration before it is used.
//!
//! The module is split by role: `types` and `behaviour` declare the sections (the latter the
//! motion limits shared by the object classes and the constants of the driver and walker
//! models), `mount` the radar mounts, `defaults` the reference values, `presets` the named
//! variants and `validation` the consistency checks.

mod behaviour;
mod defaults;
mod mount;
mod presets;
mod types;
mod validation;

use serde::{Deserialize, Serialize};

pub use behaviour::{DriverConfig, MotionLimits, WalkerConfig};
pub use mount::RadarMount;
pub use presets::Preset;
pub use types::{
    CarConfig, ClutterConfig, EgoConfig, EgoPlacement, ExtendedObjectConfig, OutputConfig, PedestrianConfig,
    PointCloudConfig, RadarConfig, RadarReport, ReflectionConfig, RoadConfig, SequenceConfig, SplitConfig,
    TrafficConfig, MAX_DETECTIONS_PER_OBJECT,
};

/// A closed interval `[min, max]` from which a value is drawn uniformly.
pub type Interval = [f64; 2];

/// An invalid configuration value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid scenario configuration: `{field}` {problem}")]
pub struct ConfigError {
    /// Dotted path of the offending field, e.g. `car.max_speed_mps`.
    pub field: String,
    /// What is wrong with it.
    pub problem: String,
}

impl ConfigError {
    fn new(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Self { field: field.into(), problem: problem.into() }
    }
}

/// Why [`ScenarioConfig::from_toml_str`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScenarioTomlError {
    /// The text is not TOML, or does not describe a configuration (unknown field, wrong type).
    #[error(transparent)]
    Parse(#[from] toml::de::Error),
    /// The configuration parsed but is inconsistent.
    #[error(transparent)]
    Invalid(#[from] ConfigError),
}

/// Complete generator configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScenarioConfig {
    /// Sequence length and simulation stepping.
    pub sequence: SequenceConfig,
    /// Split sizes and seeds.
    pub splits: SplitConfig,
    /// Road grid, lanes, sidewalks and traffic signals.
    pub road: RoadConfig,
    /// Number of objects kept around the ego vehicle and where they appear.
    pub traffic: TrafficConfig,
    /// The ego vehicle.
    pub ego: EgoConfig,
    /// Cars (including large vehicles) and their driving behaviour.
    pub car: CarConfig,
    /// Pedestrians and their walking behaviour.
    pub pedestrian: PedestrianConfig,
    /// Radar sensors, scan timing and measurement noise.
    pub radar: RadarConfig,
    /// Reflection model of cars.
    pub car_reflection: ReflectionConfig,
    /// Reflection model of pedestrians.
    pub pedestrian_reflection: ReflectionConfig,
    /// False detections: clutter and multipath ghosts (off by default).
    pub clutter: ClutterConfig,
    /// Extended-object reflections of cars and two-wheelers: separate detections on the
    /// visible contour of the box instead of one averaged measurement (off by default).
    pub extended_objects: ExtendedObjectConfig,
    /// What the written frames carry besides the measurements (ego pose, sensor ids).
    pub output: OutputConfig,
    /// Detection-level output: several detections per object and scan, wheel micro-Doppler,
    /// multipath ghosts behind walls, flipped class labels (off by default).
    pub point_cloud: PointCloudConfig,
}

impl ScenarioConfig {
    /// Parses a configuration from TOML; missing fields take their default values. The result
    /// is validated.
    pub fn from_toml_str(text: &str) -> Result<Self, ScenarioTomlError> {
        let config: Self = toml::from_str(text)?;
        config.validate()?;
        Ok(config)
    }

    /// Width of one side of the carriageway (all lanes of one direction), metres.
    pub fn half_road_width_m(&self) -> f64 {
        self.road.lane_width_m * f64::from(self.road.lanes_per_direction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scenario_file_of_the_repository_reads_and_every_preset_reads_back_unchanged() {
        let directory = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../training/scenarios");
        let mut files = 0;
        for entry in std::fs::read_dir(&directory).expect("the training scenarios") {
            let path = entry.expect("a directory entry").path();
            if path.extension().is_some_and(|extension| extension == "toml") {
                let text = std::fs::read_to_string(&path).expect("a readable file");
                ScenarioConfig::from_toml_str(&text)
                    .unwrap_or_else(|error| panic!("{}: {error}", path.display()));
                files += 1;
            }
        }
        assert!(files > 0, "no scenario file in {}", directory.display());
        for preset in Preset::ALL {
            let config = preset.config();
            let text = toml::to_string(&config).expect("serialise");
            assert_eq!(ScenarioConfig::from_toml_str(&text).expect("parse"), config, "{preset}");
        }
    }
}
