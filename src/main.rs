//! `primm`: command-line host of the PR-IMM tracker. Each subcommand lives in `src/cli/`.

use clap::{Parser, Subcommand};
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
    /// Generate simulated radar sequences as measurement CSV files.
    Generate(cli::generate::Args),
    /// Track a measurement CSV file offline into a track CSV file.
    Track(cli::track::Args),
    /// Evaluate methods on a data set and print the paper's tables.
    Eval(cli::eval::Args),
    /// Score association CSV files written by any tracker with the metrics of `eval`.
    Score(cli::score::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    primm_service::logging::init_logging();
    let result: Result<(), Box<dyn std::error::Error>> = match cli.command {
        Command::Demo(args) => cli::demo::run(args).map_err(Into::into),
        Command::Serve(args) => cli::serve::run(args).map_err(Into::into),
        Command::Publish(args) => primm_publisher::run(args).map_err(Into::into),
        Command::Subscribe(args) => primm_subscriber::run(args).map_err(Into::into),
        Command::Generate(args) => cli::generate::run(&args),
        Command::Track(args) => cli::track::run(&args),
        Command::Eval(args) => cli::eval::run(&args),
        Command::Score(args) => cli::score::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
