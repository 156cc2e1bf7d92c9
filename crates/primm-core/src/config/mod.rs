//! All tracker parameters in one validated structure.
//!
//! Units are part of every key's name. [`Config::default`] holds the values of the documented
//! file `config/primm.toml`; `primm-config` reads TOML files into a [`Config`] and a test there
//! checks that the file and the defaults here are equal. [`Config::validate`] checks every
//! value and names the offending key.

mod classes;
mod defaults;
mod predictor;
mod sections;
#[cfg(test)]
mod tests;
mod validation;

pub use classes::*;
pub use predictor::*;
pub use sections::*;
use validation::*;

pub use crate::coordinates::{CoordinateFrame, CoordinatesConfig};
pub use crate::existence::{ExistenceConfig, Lifecycle};
pub use crate::extent::ExtentConfig;
use crate::measurement::{ClassSet, ObjectClass};
use crate::mode::{ModeSet, MODE_COUNT};
use alloc::string::String;
use nalgebra::Matrix2;

/// A 2×2 covariance as written in TOML (`[[xx, xy], [yx, yy]]`), m².
pub type Covariance2 = [[f64; 2]; 2];

/// Complete tracker configuration.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Config {
    /// Mode set, transition matrix and mode-probability settings.
    pub imm: ImmConfig,
    /// Association cost settings (`eq:association_cost`).
    pub association: AssociationConfig,
    /// Frame validation and track lifecycle.
    pub tracker: TrackerConfig,
    /// Per-class parameters.
    pub classes: ClassTable,
    /// The tracker's use of the learned predictor (absent: the defaults).
    #[cfg_attr(feature = "serde", serde(default))]
    pub predictor: PredictorConfig,
    /// The tracking frame and the sensors' mounting poses (absent: the defaults).
    #[cfg_attr(feature = "serde", serde(default))]
    pub frame: CoordinatesConfig,
}

/// An invalid configuration value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    /// A value is out of its valid range.
    #[error("configuration key `{key}` is invalid: {reason}")]
    Invalid {
        /// Dotted path of the key, e.g. `classes.car.paper_gate_m`.
        key: String,
        /// What is wrong with it.
        reason: String,
    },
}

/// A TOML covariance as a nalgebra matrix.
pub fn to_matrix(value: &Covariance2) -> Matrix2<f64> {
    Matrix2::new(value[0][0], value[0][1], value[1][0], value[1][1])
}

impl Config {
    /// This configuration with another set of active modes.
    pub fn with_modes(mut self, modes: ModeSet) -> Self {
        self.imm.modes = modes;
        self
    }

    /// This configuration with every class tracked as a point (`classes.<class>.extent` off):
    /// for detections that are already object centres (or a scene built of points).
    pub fn with_point_objects(mut self) -> Self {
        for class in ObjectClass::ALL {
            self.classes.get_mut(class).extent.enabled = false;
        }
        self
    }

    /// The IMM settings of `class`: the `imm` section with `classes.<class>.imm` applied.
    pub fn imm_for(&self, class: ObjectClass) -> ImmConfig {
        self.imm.with_overrides(&self.classes.get(class).imm)
    }

    /// The IMM settings of `class` in steps whose ego motion is compensated (a frame with an ego
    /// pose, tracked in the world frame): [`imm_for`](Self::imm_for) with the class's
    /// `compensated_*` keys applied.
    pub fn compensated_imm_for(&self, class: ObjectClass) -> ImmConfig {
        self.imm.with_compensated_overrides(&self.classes.get(class).imm)
    }

    /// Checks every value; the error names the first offending key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        validate_imm(&self.imm)?;
        validate_association(&self.association)?;
        validate_tracker_and_predictor(&self.tracker, &self.predictor)?;
        if let Some((key, reason)) = self.frame.problem() {
            return Err(invalid(key, reason));
        }
        for class in ObjectClass::ALL {
            validate_class(class, self.classes.get(class))?;
            validate_class_imm(class, &self.imm, &self.classes.get(class).imm)?;
        }
        Ok(())
    }
}
