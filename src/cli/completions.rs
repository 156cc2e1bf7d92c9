//! `primm completions SHELL`: the shell completion script for `primm`, on stdout.

use clap::Args as ClapArgs;
use clap_complete::Shell;
use std::io::Write as _;

/// Arguments of `primm completions`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Print the shell completion script for primm",
    after_help = "\
Examples:
  primm completions bash > ~/.local/share/bash-completion/completions/primm
  primm completions zsh > ~/.zfunc/_primm          # with fpath+=~/.zfunc before compinit
  primm completions fish > ~/.config/fish/completions/primm.fish"
)]
pub struct Args {
    /// The shell: bash, elvish, fish, powershell or zsh.
    #[arg(value_name = "SHELL")]
    pub shell: Shell,
}

/// Why `primm completions` failed.
#[derive(Debug, thiserror::Error)]
pub enum CompletionsError {
    /// Writing the script to stdout failed.
    #[error("cannot write the completion script: {0}")]
    Write(#[from] std::io::Error),
}

/// Writes the completion script of `command` (the `primm` command line) for `args.shell`.
pub fn run(args: &Args, mut command: clap::Command) -> Result<(), CompletionsError> {
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "primm", &mut script);
    let mut out = std::io::stdout().lock();
    out.write_all(&script)?;
    out.flush()?;
    Ok(())
}
