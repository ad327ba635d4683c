//! One module per command: its clap `Args` (the options it accepts, with
//! the shared ones of [`crate::args`] flattened in) and its `run`, which
//! returns what the command writes ([`crate::args::Output`]). The
//! computations live in the library modules they call ([`crate::statics`],
//! [`crate::dynamics`], ...), so that tests call the same code.
//!
//! Adding a command: a module here with `Args` (the shared options as the
//! groups of [`crate::args`], flattened: [`crate::args::OverTemps`],
//! [`crate::args::PlottedTable`], ...) and `run`, a variant of [`Command`]
//! and its arm in [`Command::run`]; it then has the error path, the
//! envelope check of its temperatures, the output formats and the
//! doc-example tests of every other command (ARCHITECTURE.md, "Add a CLI
//! command").

use crate::args::Output;
use crate::error::CliError;
use std::path::PathBuf;

pub mod asymptotic;
pub mod calibrate;
pub mod compensation;
pub mod completions;
pub mod eigen;
pub mod equilibrium;
pub mod estimate;
pub mod identify;
pub mod indicators;
pub mod man;
pub mod monitor;
pub mod paper;
pub mod report;
pub mod sensitivity;
pub mod size;
pub mod step;
pub mod sweep;
pub mod twin_config;

/// The command line.
#[derive(clap::Parser, Debug)]
#[command(
    name = "compensator",
    version,
    about = "Digital twin of a passive throttle-based temperature flow compensator"
)]
pub struct Cli {
    /// The subcommand and its arguments.
    #[command(subcommand)]
    pub command: Command,
    /// Write the output to FILE instead of standard output (only once complete).
    #[arg(short = 'o', long = "output", global = true, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// The command-line definition (for completions and man pages).
pub fn command() -> clap::Command {
    <Cli as clap::CommandFactory>::command()
}

/// The subcommands, in the order `--help` lists them.
#[derive(clap::Subcommand, Debug, Clone)]
#[allow(missing_docs, reason = "each Args struct's doc comment is its description")]
pub enum Command {
    Equilibrium(equilibrium::Args),
    Asymptotic(asymptotic::Args),
    Sensitivity(sensitivity::Args),
    Step(step::Args),
    TwinConfig(twin_config::Args),
    Eigen(eigen::Args),
    Indicators(indicators::Args),
    Compensation(compensation::Args),
    Size(size::Args),
    Calibrate(calibrate::Args),
    Identify(identify::Args),
    Estimate(estimate::Args),
    Monitor(monitor::Args),
    Paper(paper::Args),
    Report(report::Args),
    Sweep(sweep::Args),
    Completions(completions::Args),
    Man(man::Args),
}

impl Command {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// The command's [`CliError`]: bad input (exit 2) or a failed
    /// computation (exit 1).
    pub fn run(self) -> Result<Output, CliError> {
        match self {
            Command::Equilibrium(a) => a.run(),
            Command::Asymptotic(a) => a.run(),
            Command::Sensitivity(a) => a.run(),
            Command::Step(a) => a.run(),
            Command::TwinConfig(a) => a.run(),
            Command::Eigen(a) => a.run(),
            Command::Indicators(a) => a.run(),
            Command::Compensation(a) => a.run(),
            Command::Size(a) => a.run(),
            Command::Calibrate(a) => a.run(),
            Command::Identify(a) => a.run(),
            Command::Estimate(a) => a.run(),
            Command::Monitor(a) => a.run(),
            Command::Paper(a) => a.run(),
            Command::Report(a) => a.run(),
            Command::Sweep(a) => a.run(),
            Command::Completions(a) => a.run(),
            Command::Man(a) => a.run(),
        }
    }
}
