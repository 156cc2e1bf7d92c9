//! `--latency-out DIR`: the options that ask a subcommand for HdrHistogram latency files
//! (`STAGE.hlog`, `STAGE.hgrm`, `PROCESS.svg`; see `primm_service::latency_files`).

use std::path::{Path, PathBuf};
use std::time::Duration;

/// Where and how often latency files are written.
#[derive(Debug, Clone, clap::Args)]
pub struct LatencyOutArgs {
    /// Write per-stage latency files into this directory: an HdrHistogram interval log
    /// (`STAGE.hlog`), a percentile distribution (`STAGE.hgrm`) and a latency-by-percentile
    /// plot (`PROCESS.svg`).
    #[arg(long, value_name = "DIR")]
    pub latency_out: Option<PathBuf>,
    /// Length of one interval of the `.hlog` files, s.
    #[arg(long, default_value_t = 1.0, value_name = "S", value_parser = parse_positive_seconds)]
    pub latency_interval_s: f64,
}

impl LatencyOutArgs {
    /// The directory, if files were asked for.
    pub fn directory(&self) -> Option<&Path> {
        self.latency_out.as_deref()
    }

    /// The interval of the logs.
    pub fn interval(&self) -> Duration {
        Duration::from_secs_f64(self.latency_interval_s)
    }
}

/// Parses a positive, finite number of seconds (at most a day).
pub fn parse_positive_seconds(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.parse().map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0 {
        Ok(seconds)
    } else {
        Err(format!("`{text}`: the interval must be more than 0 and at most 86400 s"))
    }
}

/// Prints the files written, one per line, under a heading.
pub fn print_files(heading: &str, files: &[PathBuf]) {
    if files.is_empty() {
        return;
    }
    println!("{heading}:");
    for file in files {
        println!("  {}", file.display());
    }
}
