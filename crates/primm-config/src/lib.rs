//! # primm-config: the tracker configuration as a TOML file
//!
//! `primm-core` keeps its [`Config`] a plain, validated value so that it needs no parser. This
//! crate reads the TOML form of it: [`settings_from_toml_str`] and [`settings_from_file`] lay
//! the file over the shipped defaults key by key (a file of one key is the shipped
//! configuration with that key changed), reject unknown keys, renamed keys and values of the
//! wrong type with the line of the file, then validate, with an error that names the offending
//! key. [`Settings::difference_from_defaults`] is what a configuration changes, as TOML;
//! [`parameters_markdown`] documents every key (`docs/parameters.md`). A file also says how the learned model runs ([`InferenceConfig`]: engine,
//! inference threads, deadline), which the tracker never reads; [`Settings`] holds both, and
//! [`from_toml_str`] and [`from_file`] return the tracker's part alone.
//! [`DEFAULT_CONFIG_TOML`] is the documented default file, `config/primm.toml`, embedded; a
//! test checks that it parses to exactly [`Settings::default`].
//!
//! ```
//! let config = primm_config::from_toml_str("[classes.car]\npaper_gate_m = 4.5\n")?;
//! let mut expected = primm_core::config::Config::default();
//! expected.classes.car.paper_gate_m = 4.5;
//! assert_eq!(config, expected);
//!
//! let error = primm_config::from_toml_str("[classes.car]\npaper_gate_m = -1.0\n");
//! assert!(error.unwrap_err().to_string().contains("classes.car.paper_gate_m"));
//! # Ok::<(), primm_config::ConfigError>(())
//! ```

mod difference;
mod file;
mod inference;
mod layers;
mod parameters;
mod renamed;

pub use inference::{InferenceConfig, InferenceEngine, UnknownEngine, MAX_INFERENCE_THREADS};
pub use parameters::parameters_markdown;
use primm_core::config::Config;
pub use renamed::RenamedKey;
use std::path::Path;
/// Why a configuration could not be written as TOML.
pub use toml::ser::Error as TomlWriteError;

/// The default configuration file (`config/primm.toml`), embedded.
pub const DEFAULT_CONFIG_TOML: &str = include_str!("../../../config/primm.toml");

/// Everything a configuration file sets: the tracker's configuration and how the learned model
/// runs (which the tracker never reads).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Settings {
    /// The tracker's configuration.
    pub tracker: Config,
    /// The learned model's engine, inference threads and deadline.
    pub inference: InferenceConfig,
}

impl Settings {
    /// Checks every value; the error names the first offending key.
    pub fn validate(&self) -> Result<(), primm_core::config::ConfigError> {
        self.tracker.validate()?;
        self.inference.validate()
    }

    /// This configuration as a TOML document that [`settings_from_toml_str`] reads back
    /// unchanged.
    pub fn to_toml_string(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(&file::FileLayout::from(self))
    }
}

/// A configuration that could not be read, parsed or validated.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The configuration file could not be read.
    #[error("cannot read configuration file {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The TOML is malformed, a key is unknown or a value has the wrong type (the message
    /// shows the line).
    #[error("configuration is not valid TOML for primm: {0}")]
    Parse(#[from] toml::de::Error),
    /// A key was renamed; the error names the new key and the line.
    #[error(transparent)]
    RenamedKey(#[from] RenamedKey),
    /// A value is out of its valid range; the error names the key.
    #[error(transparent)]
    Invalid(#[from] primm_core::config::ConfigError),
}

/// Parses a TOML document laid over the shipped defaults (every key it leaves out keeps the
/// value of `config/primm.toml`) and validates the result.
pub fn settings_from_toml_str(text: &str) -> Result<Settings, ConfigError> {
    let settings = Settings::from(layers::layered_file(text)?);
    settings.validate()?;
    Ok(settings)
}

/// Reads a TOML file, lays it over the shipped defaults and validates the result.
pub fn settings_from_file(path: &Path) -> Result<Settings, ConfigError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| ConfigError::Io { path: path.display().to_string(), source })?;
    settings_from_toml_str(&text)
}

/// Parses and validates a TOML document; the tracker's part of it (the inference keys are
/// checked too).
pub fn from_toml_str(text: &str) -> Result<Config, ConfigError> {
    settings_from_toml_str(text).map(|settings| settings.tracker)
}

/// Reads, parses and validates a TOML file; the tracker's part of it.
pub fn from_file(path: &Path) -> Result<Config, ConfigError> {
    settings_from_file(path).map(|settings| settings.tracker)
}

/// Writes a tracker configuration, with the default inference keys, as a TOML document that
/// [`from_toml_str`] reads back unchanged.
pub fn to_toml_string(config: &Config) -> Result<String, toml::ser::Error> {
    Settings { tracker: config.clone(), inference: InferenceConfig::default() }.to_toml_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use primm_core::config::PredictorConfig;

    fn invalid_key(text: &str) -> String {
        match from_toml_str(text) {
            Err(ConfigError::Invalid(primm_core::config::ConfigError::Invalid { key, .. })) => key,
            other => panic!("expected an invalid-key error, got {other:?}"),
        }
    }

    #[test]
    fn the_embedded_file_parses_to_exactly_the_core_defaults() {
        assert_eq!(settings_from_toml_str(DEFAULT_CONFIG_TOML).unwrap(), Settings::default());
        assert_eq!(from_toml_str(DEFAULT_CONFIG_TOML).unwrap(), Config::default());
    }

    #[test]
    fn a_configuration_survives_a_round_trip_through_toml() {
        let mut config = Config::default();
        config.classes.pedestrian.paper_gate_m = 2.25;
        let text = to_toml_string(&config).unwrap();
        assert_eq!(from_toml_str(&text).unwrap(), config);
    }

    #[test]
    fn a_transition_row_that_does_not_sum_to_one_is_named() {
        let text = DEFAULT_CONFIG_TOML.replace("[0.01, 0.97, 0.01, 0.01]", "[0.01, 0.96, 0.01, 0.01]");
        assert_eq!(invalid_key(&text), "imm.transition[1]");
    }

    #[test]
    fn an_asymmetric_covariance_is_named() {
        let text = DEFAULT_CONFIG_TOML.replacen(
            "measurement_noise_covariance_m2 = [[0.05, 0.0], [0.0, 0.05]]",
            "measurement_noise_covariance_m2 = [[0.05, 0.01], [0.0, 0.05]]",
            1,
        );
        assert_eq!(invalid_key(&text), "classes.pedestrian.measurement_noise_covariance_m2");
    }

    #[test]
    fn an_unknown_key_is_a_parse_error_that_names_it() {
        let text = DEFAULT_CONFIG_TOML.replace("paper_gate_m = 8.4", "paper_gate_m = 8.4\ngate_meters = 1.0");
        let error = from_toml_str(&text).unwrap_err();
        assert!(matches!(error, ConfigError::Parse(_)), "{error:?}");
        assert!(error.to_string().contains("gate_meters"), "{error}");
    }

    #[test]
    fn an_empty_mode_set_is_rejected() {
        let text = DEFAULT_CONFIG_TOML.replace(r#"modes = ["pr", "cv", "ca", "ct"]"#, "modes = []");
        assert_eq!(invalid_key(&text), "imm.modes");
    }

    #[test]
    fn a_missing_predictor_section_takes_the_default_and_a_bad_deadline_is_named() {
        let start = DEFAULT_CONFIG_TOML.find("[predictor]").unwrap();
        let end = DEFAULT_CONFIG_TOML.find("[classes.car]").unwrap();
        let without = format!("{}{}", &DEFAULT_CONFIG_TOML[..start], &DEFAULT_CONFIG_TOML[end..]);
        assert_eq!(settings_from_toml_str(&without).unwrap(), Settings::default());
        for bad in ["0.0", "-1.0", "nan", "5000.0"] {
            let text = DEFAULT_CONFIG_TOML.replace("deadline_ms = 5.0", &format!("deadline_ms = {bad}"));
            assert_eq!(invalid_key(&text), "predictor.deadline_ms", "deadline {bad}");
        }
    }

    #[test]
    fn the_inference_keys_are_read_beside_the_tracker_s_and_survive_a_round_trip() {
        let text = DEFAULT_CONFIG_TOML
            .replace("engine = \"native\"", "engine = \"tract\"")
            .replace("inference_threads = 2", "inference_threads = 3");
        let settings = settings_from_toml_str(&text).unwrap();
        assert_eq!(settings.inference.engine, InferenceEngine::Tract);
        assert_eq!(settings.inference.inference_threads, 3);
        assert_eq!(settings.tracker, Config::default());
        let again = settings_from_toml_str(&settings.to_toml_string().unwrap()).unwrap();
        assert_eq!(again, settings);
        let bad = DEFAULT_CONFIG_TOML.replace("inference_threads = 2", "inference_threads = 0");
        assert_eq!(invalid_key(&bad), "predictor.inference_threads");
    }

    #[test]
    fn an_error_in_the_file_names_its_line() {
        let text = DEFAULT_CONFIG_TOML.replace("engine = \"native\"", "engine = \"onnxruntime\"");
        let line = DEFAULT_CONFIG_TOML.lines().position(|line| line.starts_with("engine = ")).unwrap() + 1;
        let error = from_toml_str(&text).unwrap_err().to_string();
        assert!(error.contains(&format!("line {line}")), "{error}");
    }

    #[test]
    fn a_predictor_section_without_the_speed_bound_takes_its_default_and_a_bad_bound_is_named() {
        let without = DEFAULT_CONFIG_TOML.replace("max_displacement_speed_mps = 100.0", "");
        assert_eq!(from_toml_str(&without).unwrap().predictor, PredictorConfig::default());
        let text = DEFAULT_CONFIG_TOML
            .replace("max_displacement_speed_mps = 100.0", "max_displacement_speed_mps = -3.0");
        assert_eq!(invalid_key(&text), "predictor.max_displacement_speed_mps");
    }

    #[test]
    fn predictor_classes_are_read_by_name_and_an_unknown_name_is_a_parse_error_that_names_it() {
        use primm_core::measurement::{ClassSet, ObjectClass};
        let line = DEFAULT_CONFIG_TOML.lines().find(|line| line.starts_with("classes = [")).unwrap();
        let text = DEFAULT_CONFIG_TOML.replace(line, r#"classes = ["pedestrian", "car"]"#);
        let expected = ClassSet::of(&[ObjectClass::Car, ObjectClass::Pedestrian]);
        assert_eq!(from_toml_str(&text).unwrap().predictor.classes, expected);
        let text = DEFAULT_CONFIG_TOML.replace(line, "classes = []");
        assert!(from_toml_str(&text).unwrap().predictor.classes.is_empty());
        let text = DEFAULT_CONFIG_TOML.replace(line, r#"classes = ["truck"]"#);
        let error = from_toml_str(&text).unwrap_err();
        assert!(matches!(error, ConfigError::Parse(_)), "{error:?}");
        assert!(error.to_string().contains("truck"), "{error}");
        // Written back, the set reads the same.
        let config =
            from_toml_str(&DEFAULT_CONFIG_TOML.replace(line, r#"classes = ["two_wheeler"]"#)).unwrap();
        assert_eq!(from_toml_str(&to_toml_string(&config).unwrap()).unwrap(), config);
    }

    #[test]
    fn a_missing_file_names_the_file() {
        let error = from_file(Path::new("/nonexistent/primm.toml")).unwrap_err();
        assert!(error.to_string().contains("/nonexistent/primm.toml"), "{error}");
    }
}
