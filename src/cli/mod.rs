//! Command-line subcommands of the `primm` binary: each file holds one subcommand's arguments
//! and its `run` function; `src/main.rs` only dispatches.

pub mod demo;
pub mod eval;
pub mod generate;
pub mod predictor;
pub mod publish;
pub mod score;
pub mod serve;
pub mod subscribe;
pub mod track;

/// Logs to stderr, filtered by `RUST_LOG` (default `info`).
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
}
