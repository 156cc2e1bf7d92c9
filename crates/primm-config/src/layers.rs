//! A configuration file laid over the shipped defaults.
//!
//! The file's TOML is merged key by key into the TOML of `config/primm.toml`
//! ([`DEFAULT_CONFIG_TOML`](crate::DEFAULT_CONFIG_TOML)): a table in both is merged, anything
//! else the file sets (a value, an array, an array of tables such as `[[frame.sensors]]`)
//! replaces the default whole. The merged document is then read as a complete file, so a file
//! of one key gives the shipped configuration with that key changed, and no key ever falls back
//! to a value other than the shipped one.
//!
//! Both documents are parsed with their spans, and the file's keys and values keep theirs in the
//! merged document: an unknown key or a value of the wrong type is reported at its line in the
//! file (the defaults hold no such error; a test checks that they read alone).

use crate::file::FileLayout;
use crate::renamed::renamed_key_in;
use crate::ConfigError;
use serde::Deserialize;
use toml::de::{DeTable, DeValue, Deserializer};
use toml::Spanned;

/// Reads `text` laid over the shipped defaults.
pub(crate) fn layered_file(text: &str) -> Result<FileLayout, ConfigError> {
    let file = DeTable::parse(text)?;
    if let Some(renamed) = renamed_key_in(file.get_ref(), text) {
        return Err(ConfigError::RenamedKey(renamed));
    }
    let mut defaults = DeTable::parse(crate::DEFAULT_CONFIG_TOML)
        .expect("the shipped configuration is valid TOML (checked by a test)")
        .into_inner();
    let span = file.span();
    merge(&mut defaults, file.into_inner());
    let merged = Spanned::new(span, defaults);
    FileLayout::deserialize(Deserializer::from(merged)).map_err(|mut error| {
        error.set_input(Some(text));
        ConfigError::Parse(error)
    })
}

/// Lays `file` over `base`: tables in both are merged, every other key of `file` replaces
/// `base`'s (with the file's spans).
fn merge<'i>(base: &mut DeTable<'i>, file: DeTable<'i>) {
    for (key, value) in file {
        let existing = base.remove(key.get_ref().as_ref()).map(Spanned::into_inner);
        let span = value.span();
        let merged = match (existing, value.into_inner()) {
            (Some(DeValue::Table(mut inner)), DeValue::Table(file_inner)) => {
                merge(&mut inner, file_inner);
                DeValue::Table(inner)
            }
            (_, value) => value,
        };
        base.insert(key, Spanned::new(span, merged));
    }
}

#[cfg(test)]
mod tests {
    use crate::{settings_from_toml_str, ConfigError, Settings, DEFAULT_CONFIG_TOML};
    use primm_core::config::{AssociationCost, Lifecycle};

    #[test]
    fn an_empty_file_is_the_shipped_configuration() {
        assert_eq!(settings_from_toml_str("").unwrap(), Settings::default());
        assert_eq!(settings_from_toml_str("# nothing\n[tracker]\n").unwrap(), Settings::default());
    }

    #[test]
    fn a_file_of_one_key_is_the_shipped_configuration_with_that_key_changed() {
        let settings = settings_from_toml_str("[tracker]\nmax_frame_interval_s = 0.5\n").unwrap();
        let mut expected = Settings::default();
        expected.tracker.tracker.max_frame_interval_s = 0.5;
        assert_eq!(settings, expected);
        // The keys that once fell back to older behaviours keep the shipped values.
        assert_eq!(settings.tracker.tracker.lifecycle, Lifecycle::Existence);
        assert_eq!(settings.tracker.association.cost, AssociationCost::Likelihood);
        assert_eq!(settings.tracker.tracker.replay_frames, 16);

        let settings =
            settings_from_toml_str("classes.pedestrian.existence.detection_probability = 0.3").unwrap();
        let mut expected = Settings::default();
        expected.tracker.classes.pedestrian.existence.detection_probability = 0.3;
        assert_eq!(settings, expected);

        let settings = settings_from_toml_str("[predictor]\nengine = \"tract\"\n").unwrap();
        let mut expected = Settings::default();
        expected.inference.engine = crate::InferenceEngine::Tract;
        assert_eq!(settings, expected);
    }

    #[test]
    fn a_file_that_lists_sensors_replaces_the_whole_list() {
        let text = "[[frame.sensors]]\nid = 7\nx_m = 1.0\ny_m = 0.0\nyaw_rad = 0.0\n";
        let settings = settings_from_toml_str(text).unwrap();
        let sensors = &settings.tracker.frame.sensors;
        assert_eq!(sensors.iter().map(|sensor| sensor.id).collect::<Vec<_>>(), [7]);
        assert_eq!(settings.tracker.frame.tracking_frame, Settings::default().tracker.frame.tracking_frame);
        let none = settings_from_toml_str("[frame]\nsensors = []\n").unwrap();
        assert!(none.tracker.frame.sensors.is_empty());
    }

    fn parse_error(text: &str) -> String {
        match settings_from_toml_str(text) {
            Err(error @ ConfigError::Parse(_)) => error.to_string(),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    #[test]
    fn an_unknown_key_in_a_partial_file_is_reported_at_its_line_in_that_file() {
        let error = parse_error("# a comment\n[tracker]\nmax_coast_s = 2.0\nmax_coast_seconds = 2.0\n");
        assert!(error.contains("max_coast_seconds"), "{error}");
        assert!(error.contains("line 4"), "{error}");
        let error = parse_error("\n\n[classes.car.extent]\nlenght_m = 5.0\n");
        assert!(error.contains("lenght_m") && error.contains("line 4"), "{error}");
        let error = parse_error("[trackers]\nmax_coast_s = 2.0\n");
        assert!(error.contains("trackers") && error.contains("line 1"), "{error}");
    }

    #[test]
    fn a_value_of_the_wrong_type_is_reported_at_its_line_in_the_file() {
        let error = parse_error("\n[tracker]\nreplay_frames = \"many\"\n");
        assert!(error.contains("line 3"), "{error}");
        let error = parse_error("[association]\n\ncost = \"nearest\"\n");
        assert!(error.contains("line 3") && error.contains("nearest"), "{error}");
    }

    #[test]
    fn a_renamed_key_is_refused_with_its_new_name_and_its_line() {
        for (old, new) in [
            ("gate_m", "paper_gate_m"),
            ("radial_velocity_std_mps", "initial_radial_speed_std_mps"),
            ("radial_velocity_residual_std_mps", "likelihood_radial_velocity_std_mps"),
        ] {
            let text = format!("[tracker]\nmax_coast_s = 2.0\n\n[classes.pedestrian]\n{old} = 1.0\n");
            match settings_from_toml_str(&text) {
                Err(ConfigError::RenamedKey(renamed)) => {
                    assert_eq!(renamed.old_key, format!("classes.pedestrian.{old}"));
                    assert_eq!(renamed.new_key, format!("classes.pedestrian.{new}"));
                    assert_eq!(renamed.line, 5);
                    let message = ConfigError::RenamedKey(renamed).to_string();
                    assert!(message.contains(new) && message.contains("line 5"), "{message}");
                }
                other => panic!("{old}: expected a renamed-key error, got {other:?}"),
            }
        }
        // The new name is read.
        let settings = settings_from_toml_str("[classes.car]\npaper_gate_m = 5.0\n").unwrap();
        assert_eq!(settings.tracker.classes.car.paper_gate_m, 5.0);
    }

    #[test]
    fn the_shipped_file_sets_every_key_of_the_configuration() {
        fn keys(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
            for (name, value) in table {
                let path = format!("{prefix}{name}");
                if let toml::Value::Table(inner) = value {
                    keys(inner, &format!("{path}."), out);
                }
                out.push(path);
            }
        }
        let file: toml::Table = toml::from_str(DEFAULT_CONFIG_TOML).unwrap();
        let written: toml::Table = toml::from_str(&Settings::default().to_toml_string().unwrap()).unwrap();
        let (mut in_file, mut in_code) = (Vec::new(), Vec::new());
        keys(&file, "", &mut in_file);
        keys(&written, "", &mut in_code);
        in_file.sort();
        in_code.sort();
        assert_eq!(in_file, in_code);
    }
}
