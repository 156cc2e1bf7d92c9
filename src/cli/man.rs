//! `primm man`: the manual page of `primm` (roff), on stdout or, with `--output DIR`, one page
//! per command into DIR.

use clap::Args as ClapArgs;
use std::io::Write as _;
use std::path::PathBuf;

/// Arguments of `primm man`.
#[derive(Debug, Clone, ClapArgs)]
#[command(
    about = "Print the manual page of primm (roff), or write one page per subcommand",
    after_help = "\
Examples:
  primm man | man -l -                      # read it now
  primm man --output ~/.local/share/man/man1   # primm.1, primm-track.1, ... for `man primm-track`"
)]
pub struct Args {
    /// Write `primm.1` and a page per subcommand (`primm-track.1`, ...) into this directory
    /// (created if missing) instead of printing `primm.1`.
    #[arg(long, value_name = "DIR")]
    pub output: Option<PathBuf>,
}

/// Why `primm man` failed.
#[derive(Debug, thiserror::Error)]
pub enum ManError {
    /// The output directory could not be created or a page not written.
    #[error("cannot write the manual pages into {}: {source}", path.display())]
    WritePages {
        /// The directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Writing the page to stdout failed.
    #[error("cannot write the manual page: {0}")]
    Write(#[from] std::io::Error),
}

/// Renders the manual page(s) of `command` (the `primm` command line).
pub fn run(args: &Args, command: clap::Command) -> Result<(), ManError> {
    match &args.output {
        Some(dir) => {
            let pages = || -> std::io::Result<()> {
                std::fs::create_dir_all(dir)?;
                clap_mangen::generate_to(command, dir)
            };
            pages().map_err(|source| ManError::WritePages { path: dir.clone(), source })
        }
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command).render(&mut page)?;
            let mut out = std::io::stdout().lock();
            out.write_all(&page)?;
            out.flush()?;
            Ok(())
        }
    }
}
