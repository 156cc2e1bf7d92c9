//! The tracker's options shared by every subcommand that builds a tracker (`track`, `eval`,
//! `serve`, `soak`, and `bench-service`, which hands them on to `primm serve`): the
//! configuration file, the learned model, its engine and the tracking frame.

use clap::Args;
use primm_config::{InferenceEngine, Settings};
use primm_core::config::CoordinateFrame;
use std::ffi::OsString;
use std::path::PathBuf;

/// `--config`, `--model`, `--engine` and `--tracking-frame`.
#[derive(Debug, Clone, Default, Args)]
pub struct TrackerArgs {
    /// Tracker configuration (TOML); the built-in defaults otherwise.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// ONNX model of the learned predictor for the methods pr and pr-imm (default: the model
    /// built into primm, models/pr.onnx).
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// What runs the PR model: `native` (primm's forward pass where the model allows it) or
    /// `tract`; overrides the configuration's `predictor.engine`.
    #[arg(long, value_name = "ENGINE")]
    pub engine: Option<InferenceEngine>,
    /// Overrides the configuration's `frame.tracking_frame`: `world` (tracks in the world
    /// frame when frames carry an ego pose) or `vehicle` (always the vehicle frame).
    #[arg(long, value_name = "FRAME", value_parser = parse_tracking_frame)]
    pub tracking_frame: Option<CoordinateFrame>,
}

impl TrackerArgs {
    /// The configuration file (validated as it is read) or the defaults, with `--engine` and
    /// `--tracking-frame` applied.
    pub fn load_settings(&self) -> Result<Settings, primm_config::ConfigError> {
        let mut settings = match &self.config {
            Some(path) => primm_config::settings_from_file(path)?,
            None => Settings::default(),
        };
        if let Some(frame) = self.tracking_frame {
            settings.tracker.frame.tracking_frame = frame;
        }
        if let Some(engine) = self.engine {
            settings.inference.engine = engine;
        }
        Ok(settings)
    }

    /// These options as command-line arguments, to hand on to another `primm` process.
    pub fn to_arguments(&self) -> Vec<OsString> {
        let mut arguments = Vec::new();
        if let Some(config) = &self.config {
            arguments.extend(["--config".into(), config.into()]);
        }
        if let Some(model) = &self.model {
            arguments.extend(["--model".into(), model.into()]);
        }
        if let Some(engine) = self.engine {
            arguments.extend(["--engine".into(), engine.name().into()]);
        }
        if let Some(frame) = self.tracking_frame {
            arguments.extend(["--tracking-frame".into(), frame.name().into()]);
        }
        arguments
    }
}

/// Parses `--tracking-frame`.
fn parse_tracking_frame(text: &str) -> Result<CoordinateFrame, String> {
    CoordinateFrame::from_name(text).ok_or_else(|| format!("`{text}` is neither `world` nor `vehicle`"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Command {
        #[command(flatten)]
        tracker: TrackerArgs,
    }

    #[test]
    fn the_options_handed_on_parse_back_to_the_same_options() {
        let parsed = Command::try_parse_from([
            "primm",
            "--config",
            "a.toml",
            "--model",
            "m.onnx",
            "--engine",
            "tract",
            "--tracking-frame",
            "vehicle",
        ])
        .unwrap()
        .tracker;
        let again =
            Command::try_parse_from(std::iter::once(OsString::from("primm")).chain(parsed.to_arguments()))
                .unwrap()
                .tracker;
        assert_eq!(format!("{parsed:?}"), format!("{again:?}"));
        assert_eq!(again.engine, Some(InferenceEngine::Tract));
        assert_eq!(again.tracking_frame, Some(CoordinateFrame::Vehicle));
    }

    #[test]
    fn engine_and_tracking_frame_override_the_defaults() {
        let args = TrackerArgs {
            engine: Some(InferenceEngine::Tract),
            tracking_frame: Some(CoordinateFrame::Vehicle),
            ..TrackerArgs::default()
        };
        let settings = args.load_settings().unwrap();
        assert_eq!(settings.inference.engine, InferenceEngine::Tract);
        assert_eq!(settings.tracker.frame.tracking_frame, CoordinateFrame::Vehicle);
        assert_eq!(TrackerArgs::default().load_settings().unwrap(), Settings::default());
    }

    #[test]
    fn an_unknown_tracking_frame_is_refused_with_its_name() {
        let error = Command::try_parse_from(["primm", "--tracking-frame", "road"]).err().unwrap();
        assert!(error.to_string().contains("`road` is neither"));
    }
}
