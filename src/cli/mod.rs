//! Command-line subcommands of the `primm` binary.

pub mod generate;
