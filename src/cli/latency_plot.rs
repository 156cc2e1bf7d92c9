//! `primm latency-plot`: compares runs by plotting HdrHistogram interval logs (`.hlog`, as
//! `--latency-out` writes them, or from any HdrHistogram tool recording nanoseconds) into one
//! latency-by-percentile SVG, one line per file, and prints their percentiles.

use primm_service::latency::{format_named_table, summarise};
use primm_service::latency_files::{read_interval_log, ReadLogError};
use primm_service::latency_plot::{plot_by_percentile_with, LatencyAxis, PlotError, PlotSeries};
use std::path::{Path, PathBuf};

/// Arguments of `primm latency-plot`.
#[derive(Debug, Clone, clap::Args)]
#[command(about = "Plot HdrHistogram interval logs (.hlog) by percentile into one SVG, one line per file")]
pub struct Args {
    /// Interval logs to compare (each one line: the sum of its intervals).
    #[arg(required = true, value_name = "FILE.hlog")]
    pub logs: Vec<PathBuf>,
    /// The SVG file to write.
    #[arg(long, short, value_name = "FILE.svg")]
    pub output: PathBuf,
    /// Legend entry of each file, in order (default: the file name, with its directory when
    /// two files share a name).
    #[arg(long = "label", value_name = "TEXT")]
    pub labels: Vec<String>,
    /// Title of the plot.
    #[arg(long, default_value = "latency by percentile")]
    pub title: String,
    /// A linear latency axis from zero instead of a logarithmic one.
    #[arg(long)]
    pub linear: bool,
}

/// Why `primm latency-plot` failed.
#[derive(Debug, thiserror::Error)]
pub enum LatencyPlotError {
    /// More labels than files.
    #[error("{labels} labels for {files} files: give at most one --label per file")]
    Labels {
        /// Labels given.
        labels: usize,
        /// Files given.
        files: usize,
    },
    /// A log could not be read.
    #[error(transparent)]
    Read(#[from] ReadLogError),
    /// The plot could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// Reads the logs, plots them and prints their percentiles.
pub fn run(args: &Args) -> Result<(), LatencyPlotError> {
    if args.labels.len() > args.logs.len() {
        return Err(LatencyPlotError::Labels { labels: args.labels.len(), files: args.logs.len() });
    }
    let mut series = Vec::with_capacity(args.logs.len());
    for (index, path) in args.logs.iter().enumerate() {
        let histogram = read_interval_log(path)?;
        let label = args.labels.get(index).cloned().unwrap_or_else(|| default_label(path, &args.logs));
        series.push(PlotSeries { label, histogram });
    }
    let axis = if args.linear { LatencyAxis::Linear } else { LatencyAxis::Logarithmic };
    plot_by_percentile_with(&args.output, &args.title, &series, axis)?;
    let rows: Vec<_> = series.iter().map(|line| summarise(&line.label, &line.histogram)).collect();
    print!("{}", format_named_table(series.iter().map(|line| line.label.as_str()).zip(&rows)));
    println!("wrote {}", args.output.display());
    Ok(())
}

/// The file name without `.hlog`; with the parent directory's name in front when another file
/// has the same name.
fn default_label(path: &Path, all: &[PathBuf]) -> String {
    let stem =
        |path: &Path| path.file_stem().map(|stem| stem.to_string_lossy().into_owned()).unwrap_or_default();
    let name = stem(path);
    let shared = all.iter().filter(|other| stem(other) == name).count() > 1;
    match path.parent().and_then(Path::file_name) {
        Some(parent) if shared => format!("{}/{name}", parent.to_string_lossy()),
        _ => name,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_the_directory_only_when_file_names_repeat() {
        let files = [PathBuf::from("runs/imm/end_to_end.hlog"), PathBuf::from("runs/pr-imm/end_to_end.hlog")];
        assert_eq!(default_label(&files[0], &files), "imm/end_to_end");
        let single = [PathBuf::from("runs/imm/end_to_end.hlog"), PathBuf::from("runs/imm/publish.hlog")];
        assert_eq!(default_label(&single[1], &single), "publish");
    }
}
