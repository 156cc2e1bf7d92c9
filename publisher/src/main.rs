//! `primm-publisher`: replays radar measurement frames (CSV files or the built-in scenario)
//! onto `primm/measurements` over shared memory. See `primm-publisher --help`.

use clap::Parser;
use std::process::ExitCode;

/// Replay radar measurement frames onto primm/measurements over shared memory.
#[derive(Debug, Parser)]
#[command(name = "primm-publisher", version)]
struct Cli {
    #[command(flatten)]
    args: primm_publisher::Args,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    primm_ipc::logging::init_logging();
    match primm_publisher::run(cli.args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
