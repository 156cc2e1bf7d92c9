//! What a configuration changes from the shipped defaults, as TOML (`primm config show --diff`).

use crate::file::FileLayout;
use crate::Settings;
use toml::{Table, Value};

impl Settings {
    /// The keys whose values differ from the shipped defaults', as a TOML table: a table where
    /// it holds a difference, any other value whole (an array, such as `frame.sensors`, whole).
    /// Empty for the defaults. Laid over the defaults (as every file is), the table gives this
    /// configuration back, except where this configuration leaves out a key the defaults set
    /// (a class's `imm` override or `max_speed_mps`), which no file can do.
    pub fn difference_from_defaults(&self) -> Result<Table, toml::ser::Error> {
        let mine = Table::try_from(FileLayout::from(self))?;
        let defaults = Table::try_from(FileLayout::from(&Settings::default()))?;
        Ok(difference(&mine, &defaults))
    }

    /// [`difference_from_defaults`](Self::difference_from_defaults) as a TOML document (empty
    /// for the defaults).
    pub fn difference_from_defaults_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(&self.difference_from_defaults()?)
    }
}

/// The entries of `mine` that `base` does not have with the same value.
fn difference(mine: &Table, base: &Table) -> Table {
    let mut out = Table::new();
    for (key, value) in mine {
        match (value, base.get(key)) {
            (Value::Table(inner), Some(Value::Table(base_inner))) => {
                let inner = difference(inner, base_inner);
                if !inner.is_empty() {
                    out.insert(key.clone(), Value::Table(inner));
                }
            }
            (value, Some(base_value)) if value == base_value => {}
            (value, _) => {
                out.insert(key.clone(), value.clone());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::{settings_from_toml_str, Settings, DEFAULT_CONFIG_TOML};

    #[test]
    fn the_shipped_file_differs_from_the_defaults_in_nothing() {
        let settings = settings_from_toml_str(DEFAULT_CONFIG_TOML).unwrap();
        assert_eq!(settings.difference_from_defaults_toml().unwrap(), "");
    }

    #[test]
    fn a_difference_names_only_the_changed_keys_and_reads_back_to_the_same_settings() {
        let text =
            "[classes.pedestrian.extent]\nlength_m = 0.9\nwidth_m = 0.5\n\n[tracker]\nreplay_frames = 8\n";
        let settings = settings_from_toml_str(text).unwrap();
        let difference = settings.difference_from_defaults().unwrap();
        assert_eq!(difference, toml::from_str::<toml::Table>(text).unwrap());
        let again = settings_from_toml_str(&settings.difference_from_defaults_toml().unwrap()).unwrap();
        assert_eq!(again, settings);
        assert_ne!(settings, Settings::default());
    }
}
