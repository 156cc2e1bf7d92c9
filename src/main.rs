//! `primm`: command-line host of the PR-IMM tracker. Each subcommand lives in `src/cli/`.

use clap::{CommandFactory, Parser, Subcommand};
mod cli;

use std::process::ExitCode;

/// PR-IMM multi-object tracking for automotive radar.
#[derive(Debug, Parser)]
#[command(name = "primm", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run tracker, publisher and subscriber on a built-in scenario and print accuracy and latency.
    Demo(cli::demo::Args),
    /// Run the tracker as a shared-memory service (iceoryx2).
    Serve(cli::serve::Args),
    /// Replay measurement frames onto the service (same as `primm-publisher`).
    Publish(primm_publisher::Args),
    /// Show or record the tracks of the service (same as `primm-subscriber`).
    Subscribe(primm_subscriber::Args),
    /// Record the service's streams into an MCAP file (Foxglove's format).
    Record(cli::record::Args),
    /// Publish the measurement frames of an MCAP recording onto the service.
    Replay(cli::replay::Args),
    /// Generate simulated radar sequences as measurement CSV files.
    Generate(cli::generate::Args),
    /// The true reflection offset, detection probability and clutter density of simulated sensors.
    SensorTruth(cli::sensor_truth::Args),
    /// Track a measurement CSV file offline into a track CSV file.
    Track(cli::track::Args),
    /// Evaluate methods on a data set and print the paper's tables.
    Eval(cli::eval::Args),
    /// Score association CSV files written by any tracker with the metrics of `eval`.
    Score(cli::score::Args),
    /// Run the tracker over a long synthetic scene, checking it after every frame.
    Soak(cli::soak::Args),
    /// Benchmark the tracking service: latency files, plots, a summary, the highest lossless rate.
    BenchService(cli::bench_service::Args),
    /// Print the configuration in effect (`show`) or the description of every key (`parameters`).
    Config(cli::config::Args),
    /// Plot HdrHistogram interval logs (.hlog) by percentile into one SVG to compare runs.
    LatencyPlot(cli::latency_plot::Args),
    /// Relay the service's streams to other hosts through the iceoryx2 link tunnel over zenoh.
    #[cfg(feature = "tunnel")]
    Tunnel(cli::tunnel::Args),
    /// Print the shell completion script (bash, elvish, fish, powershell, zsh).
    Completions(cli::completions::Args),
    /// Print the manual page, or write one page per subcommand into a directory.
    Man(cli::man::Args),
}

/// Why a subcommand failed: its own error.
#[derive(Debug, thiserror::Error)]
enum CommandError {
    /// `primm demo` failed.
    #[error(transparent)]
    Demo(#[from] cli::demo::DemoError),
    /// `primm serve` failed.
    #[error(transparent)]
    Serve(#[from] cli::serve::ServeError),
    /// `primm publish` failed.
    #[error(transparent)]
    Publish(#[from] primm_publisher::PublishError),
    /// `primm subscribe` failed.
    #[error(transparent)]
    Subscribe(#[from] primm_subscriber::SubscribeError),
    /// `primm record` failed.
    #[error(transparent)]
    Record(#[from] cli::record::RecordCommandError),
    /// `primm replay` failed.
    #[error(transparent)]
    Replay(#[from] cli::replay::ReplayCommandError),
    /// `primm generate` failed.
    #[error(transparent)]
    Generate(#[from] cli::generate::GenerateError),
    /// `primm sensor-truth` failed.
    #[error(transparent)]
    SensorTruth(#[from] cli::sensor_truth::SensorTruthError),
    /// `primm track` failed.
    #[error(transparent)]
    Track(#[from] cli::track::TrackError),
    /// `primm eval` failed.
    #[error(transparent)]
    Eval(#[from] cli::eval::EvaluateError),
    /// `primm score` failed.
    #[error(transparent)]
    Score(#[from] cli::score::ScoreError),
    /// `primm soak` failed.
    #[error(transparent)]
    Soak(#[from] cli::soak::SoakError),
    /// `primm bench-service` failed.
    #[error(transparent)]
    BenchService(#[from] cli::bench_service::BenchServiceError),
    /// `primm config` failed.
    #[error(transparent)]
    Config(#[from] cli::config::ConfigCommandError),
    /// `primm latency-plot` failed.
    #[error(transparent)]
    LatencyPlot(#[from] cli::latency_plot::LatencyPlotError),
    /// `primm tunnel` failed.
    #[cfg(feature = "tunnel")]
    #[error(transparent)]
    Tunnel(#[from] cli::tunnel::TunnelError),
    /// `primm completions` failed.
    #[error(transparent)]
    Completions(#[from] cli::completions::CompletionsError),
    /// `primm man` failed.
    #[error(transparent)]
    Man(#[from] cli::man::ManError),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    primm_service::logging::init_logging();
    let result: Result<(), CommandError> = match cli.command {
        Command::Demo(args) => cli::demo::run(args).map_err(Into::into),
        Command::Serve(args) => cli::serve::run(args).map_err(Into::into),
        Command::Publish(args) => primm_publisher::run(args).map_err(Into::into),
        Command::Subscribe(args) => primm_subscriber::run(args).map_err(Into::into),
        Command::Record(args) => cli::record::run(&args).map_err(Into::into),
        Command::Replay(args) => cli::replay::run(&args).map_err(Into::into),
        Command::Generate(args) => cli::generate::run(&args).map_err(Into::into),
        Command::SensorTruth(args) => cli::sensor_truth::run(&args).map_err(Into::into),
        Command::Track(args) => cli::track::run(&args).map_err(Into::into),
        Command::Eval(args) => cli::eval::run(&args).map_err(Into::into),
        Command::Score(args) => cli::score::run(&args).map_err(Into::into),
        Command::Soak(args) => cli::soak::run(&args).map_err(Into::into),
        Command::BenchService(args) => cli::bench_service::run(&args).map_err(Into::into),
        Command::Config(args) => cli::config::run(&args).map_err(Into::into),
        Command::LatencyPlot(args) => cli::latency_plot::run(&args).map_err(Into::into),
        #[cfg(feature = "tunnel")]
        Command::Tunnel(args) => cli::tunnel::run(&args).map_err(Into::into),
        Command::Completions(args) => cli::completions::run(&args, Cli::command()).map_err(Into::into),
        Command::Man(args) => cli::man::run(&args, Cli::command()).map_err(Into::into),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
