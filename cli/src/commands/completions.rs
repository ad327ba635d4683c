//! `completions`: the shell completion script.

use crate::args::Output;
use crate::error::CliError;

const HELP: &str = "\
Output: the completion script for the shell, on stdout.

Example:
  compensator completions bash > /etc/bash_completion.d/compensator";

/// Shell completion script (bash, zsh, fish, elvish, powershell).
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    /// The shell.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// A script that is not text (never expected).
    pub fn run(self) -> Result<Output, CliError> {
        let mut buf = Vec::new();
        clap_complete::generate(self.shell, &mut super::command(), "compensator", &mut buf);
        String::from_utf8(buf)
            .map(Output::Text)
            .map_err(|e| CliError::Failed(format!("completions: {e}")))
    }
}
