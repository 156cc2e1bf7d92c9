//! Logging for primm's programs.

use std::io::IsTerminal;

/// Logs to stderr, filtered by `RUST_LOG` (default `info`). Colours (ANSI escape sequences) only
/// when stderr is a terminal, so that logs piped into a file or another program stay plain
/// text. Calling it twice is harmless.
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .try_init();
}
