//! Command-line subcommands of the `primm` binary: each file holds one subcommand's arguments
//! and its `run` function; `src/main.rs` only dispatches. `primm publish` and
//! `primm subscribe` run the loops of the `primm-publisher` and `primm-subscriber` packages.

pub mod bench_service;
pub mod demo;
pub mod eval;
pub mod generate;
pub mod latency_out;
pub mod latency_plot;
pub mod score;
pub mod serve;
pub mod soak;
pub mod track;
#[cfg(feature = "tunnel")]
pub mod tunnel;

use primm_core::config::{Config, TrackingFrame};

/// Parses `--tracking-frame`.
fn parse_tracking_frame(text: &str) -> Result<TrackingFrame, String> {
    TrackingFrame::from_name(text).ok_or_else(|| format!("`{text}` is neither `world` nor `vehicle`"))
}

/// `config` with `--tracking-frame` applied, if given.
fn with_tracking_frame(mut config: Config, tracking_frame: Option<TrackingFrame>) -> Config {
    if let Some(frame) = tracking_frame {
        config.frame.tracking_frame = frame;
    }
    config
}
