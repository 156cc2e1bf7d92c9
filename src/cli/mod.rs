//! Command-line subcommands of the `primm` binary: each file holds one subcommand's arguments
//! and its `run` function; `src/main.rs` only dispatches. `primm publish` and
//! `primm subscribe` run the loops of the `primm-publisher` and `primm-subscriber` packages.

pub mod demo;
pub mod eval;
pub mod generate;
pub mod score;
pub mod serve;
pub mod soak;
pub mod track;
