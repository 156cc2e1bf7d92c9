//! `primm-subscriber`: shows or records the tracks the primm tracker publishes on
//! `primm/tracks`, with accuracy and latency. See `primm-subscriber --help`.

use clap::Parser;
use std::process::ExitCode;

/// Show or record the tracks published on primm/tracks, with accuracy and latency.
#[derive(Debug, Parser)]
#[command(name = "primm-subscriber", version)]
struct Cli {
    #[command(flatten)]
    args: primm_subscriber::Args,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    primm_ipc::logging::init_logging();
    match primm_subscriber::run(cli.args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
