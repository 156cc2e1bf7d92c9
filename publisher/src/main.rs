//! `primm-publisher`: replays radar measurement frames (CSV files or the built-in scenario)
//! onto `primm/measurements` over shared memory. See `primm-publisher --help`.

use clap::Parser;
use std::process::ExitCode;

/// Replay radar measurement frames onto primm/measurements over shared memory.
#[derive(Debug, Parser)]
#[command(name = "primm-publisher", version)]
struct Cli {
    #[command(flatten)]
    args: primm::cli::publish::Args,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    primm::cli::init_logging();
    match primm::cli::publish::run(cli.args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
