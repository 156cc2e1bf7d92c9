//! The `primm` command: a thin dispatcher over the library's subcommands.

use clap::{Parser, Subcommand};
use primm::cli;

#[derive(Debug, Parser)]
#[command(name = "primm", version, about = "PR-IMM multi-object tracking for automotive radar")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    Eval(cli::eval::Args),
    Generate(cli::generate::Args),
    Track(cli::track::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Eval(args) => cli::eval::run(args),
        Command::Generate(args) => cli::generate::run(args),
        Command::Track(args) => cli::track::run(args),
    };
    if let Err(error) = result {
        eprintln!("primm: {error}");
        std::process::exit(1);
    }
}
