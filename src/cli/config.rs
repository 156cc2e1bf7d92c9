//! `primm config`: the configuration in effect (`show`) and the page of every key
//! (`parameters`, the text of `docs/parameters.md`).

use clap::{Args as ClapArgs, Subcommand};
use std::path::PathBuf;

/// Arguments of `primm config`.
#[derive(Debug, Clone, ClapArgs)]
#[command(about = "Print the configuration in effect, or the description of every key")]
pub struct Args {
    #[command(subcommand)]
    pub command: ConfigCommand,
}

/// The subcommands of `primm config`.
#[derive(Debug, Clone, Subcommand)]
pub enum ConfigCommand {
    /// Print the effective configuration as TOML: the file laid over the shipped defaults (or
    /// the defaults alone).
    Show(ShowArgs),
    /// Print the description of every key (type, unit, default, valid values) as Markdown: the
    /// text of docs/parameters.md.
    Parameters,
}

/// Arguments of `primm config show`.
#[derive(Debug, Clone, ClapArgs)]
pub struct ShowArgs {
    /// Configuration file (TOML), laid over the shipped defaults key by key.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print only the keys whose values differ from the shipped defaults (nothing for the
    /// defaults themselves).
    #[arg(long)]
    pub diff: bool,
}

/// Why `primm config` failed.
#[derive(Debug, thiserror::Error)]
pub enum ConfigCommandError {
    /// The configuration file could not be read, parsed or validated.
    #[error(transparent)]
    Config(#[from] primm_config::ConfigError),
    /// The configuration could not be written as TOML.
    #[error("cannot write the configuration as TOML: {0}")]
    Write(#[from] primm_config::TomlWriteError),
}

/// Runs `primm config`.
pub fn run(args: &Args) -> Result<(), ConfigCommandError> {
    match &args.command {
        ConfigCommand::Show(show) => {
            print!("{}", show_text(show)?);
            Ok(())
        }
        ConfigCommand::Parameters => {
            print!("{}", primm_config::parameters_markdown());
            Ok(())
        }
    }
}

/// What `primm config show` prints.
fn show_text(args: &ShowArgs) -> Result<String, ConfigCommandError> {
    let settings = match &args.config {
        Some(path) => primm_config::settings_from_file(path)?,
        None => primm_config::Settings::default(),
    };
    Ok(if args.diff { settings.difference_from_defaults_toml()? } else { settings.to_toml_string()? })
}
