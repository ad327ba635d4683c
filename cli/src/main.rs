//! `compensator`: the host command-line tool.
//!
//! Reads the parameter file of MODEL.md section 8, writes CSV with a header
//! row in SI units. Bad input exits with status 2 and one line on stderr
//! naming the field; nothing is written to stdout then.

use clap::{Parser, Subcommand, ValueEnum};
use compensator_cli::commands::{self, CliError};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "compensator",
    version,
    about = "Digital twin of a passive throttle-based temperature flow compensator"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Scalar type of a static computation.
#[derive(Copy, Clone, Debug, ValueEnum, PartialEq, Eq)]
enum StaticPrecision {
    F64,
    F32,
}

/// Reading of the asymptotic expansion.
#[derive(Copy, Clone, Debug, ValueEnum, PartialEq, Eq)]
enum ReadingArg {
    Temperature,
    Property,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Quasi-static equilibrium (Eqs. 2-10) per temperature.
    Equilibrium {
        /// Parameter file (TOML, MODEL.md section 8).
        #[arg(long)]
        params: PathBuf,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:10")]
        temps: String,
        /// Scalar type of the computation.
        #[arg(long, value_enum, default_value = "f64")]
        precision: StaticPrecision,
    },
    /// Asymptotic displacement (Eqs. 16-21) beside the quasi-static one.
    Asymptotic {
        #[arg(long)]
        params: PathBuf,
        /// Order of the series: 0, 1 or 2.
        #[arg(long, value_parser = clap::value_parser!(u8).range(0..=2))]
        order: u8,
        /// Expansion in temperature or in the property A itself.
        #[arg(long, value_enum)]
        reading: ReadingArg,
        /// Reference temperature [C], or `balance` (where p_a = p_b, Eq. 2).
        #[arg(long, default_value = "balance")]
        t0: String,
        #[arg(long, default_value = "30:80:10")]
        temps: String,
    },
    /// Temperature sensitivities (Eqs. 30-31) and the Eq. (32) verdict.
    Sensitivity {
        #[arg(long)]
        params: PathBuf,
        #[arg(long, default_value = "26:78:2")]
        temps: String,
    },
    /// Fit a base parameter set to the paper's Tables 1 and 2; prints TOML.
    Calibrate {
        /// Base parameter file whose geometry is kept.
        #[arg(long, default_value = "presets/model-example.toml")]
        base: PathBuf,
        /// Folder with table1.csv and table2.csv.
        #[arg(long, default_value = "data/paper")]
        data: PathBuf,
    },
    /// Reproduce the paper's tables and report the findings (text).
    Paper {
        #[arg(long, default_value = "presets/paper.toml")]
        params: PathBuf,
        #[arg(long, default_value = "data/paper")]
        data: PathBuf,
    },
}

fn run(cli: Cli) -> Result<String, CliError> {
    match cli.command {
        Command::Equilibrium {
            params,
            temps,
            precision,
        } => commands::equilibrium(&params, &temps, precision == StaticPrecision::F32),
        Command::Asymptotic {
            params,
            order,
            reading,
            t0,
            temps,
        } => {
            let reading = match reading {
                ReadingArg::Temperature => compensator::asymptotic::Reading::Temperature,
                ReadingArg::Property => compensator::asymptotic::Reading::Property,
            };
            commands::asymptotic(&params, order as usize, reading, &t0, &temps)
        }
        Command::Sensitivity { params, temps } => commands::sensitivity(&params, &temps),
        Command::Calibrate { base, data } => commands::calibrate(&base, &data),
        Command::Paper { params, data } => commands::paper(&params, &data),
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            // One line: clap's first line, without its usage block.
            let text = e.render().to_string();
            let line = text
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("invalid arguments");
            eprintln!("{}", line.trim());
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(out) => {
            print!("{out}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
