//! Command-line subcommands of the `primm` binary, one file each.

pub mod eval;
pub mod generate;
pub mod predictor;
pub mod track;
