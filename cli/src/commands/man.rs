//! `man`: the man page compensator(1), or one page per command.

use crate::args::Output;
use crate::error::CliError;
use std::path::PathBuf;

const HELP: &str = "\
Output: the man page compensator(1) in roff, on stdout; with --dir, the
files compensator.1 and compensator-<command>.1 (one per subcommand).

Example:
  compensator man > compensator.1 && man ./compensator.1";

/// The man page compensator(1) (roff), or with --dir one page per subcommand.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    /// Write compensator.1 and compensator-<command>.1 into DIR instead of printing compensator(1).
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// A folder that cannot be written (bad input naming `--dir`).
    pub fn run(self) -> Result<Output, CliError> {
        let command = super::command();
        match self.dir {
            Some(dir) => {
                std::fs::create_dir_all(&dir)
                    .and_then(|()| clap_mangen::generate_to(command.name("compensator"), &dir))
                    .map_err(|e| CliError::Input(format!("--dir: {}: {e}", dir.display())))?;
                Ok(Output::Text(String::new()))
            }
            None => {
                let mut buf = Vec::new();
                clap_mangen::Man::new(command)
                    .render(&mut buf)
                    .map_err(|e| CliError::Failed(format!("man: {e}")))?;
                String::from_utf8(buf)
                    .map(Output::Text)
                    .map_err(|e| CliError::Failed(format!("man: {e}")))
            }
        }
    }
}
