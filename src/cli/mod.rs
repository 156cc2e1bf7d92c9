//! Command-line subcommands of the `primm` binary: each file holds one subcommand's arguments
//! and its `run` function; `src/main.rs` only dispatches. `primm publish` and
//! `primm subscribe` run the loops of the `primm-publisher` and `primm-subscriber` packages.

pub mod bench_service;
pub mod completions;
pub mod config;
pub mod demo;
pub mod eval;
pub mod generate;
pub mod latency_out;
pub mod latency_plot;
pub mod man;
pub mod record;
pub mod replay;
pub mod score;
pub mod sensor_truth;
pub mod serve;
pub mod soak;
pub mod track;
pub mod track_mcap;
pub mod tracker_args;
#[cfg(feature = "tunnel")]
pub mod tunnel;

pub use tracker_args::TrackerArgs;
