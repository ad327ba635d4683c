//! `compensator`: the host command-line tool.
//!
//! Reads the parameter file of `docs/model.md` section 8, writes CSV with a header
//! row in SI units. Bad input exits with status 2 and one line on stderr
//! naming the field; nothing is written to stdout then.

use clap::{Parser, Subcommand, ValueEnum};
use compensator::dynamics::Scheme;
use compensator_cli::error::CliError;
use compensator_cli::{calibration, paper, plot, sizing, statics};
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

/// The core's one-step schemes, by name.
fn scheme_parser() -> impl clap::builder::TypedValueParser<Value = Scheme> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Scheme::ALL.map(Scheme::name))
        .try_map(|name| Scheme::from_name(&name).ok_or("unknown scheme"))
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
        /// Parameter file (TOML, docs/model.md section 8).
        #[arg(long)]
        params: PathBuf,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Scalar type of the computation.
        #[arg(long, value_enum, default_value = "f64")]
        precision: StaticPrecision,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
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
        #[arg(long, default_value = "balance", allow_hyphen_values = true)]
        t0: String,
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Temperature sensitivities (Eqs. 30-31) and the Eq. (32) verdict.
    Sensitivity {
        #[arg(long)]
        params: PathBuf,
        #[arg(long, default_value = "26:78:2", allow_hyphen_values = true)]
        temps: String,
    },
    /// Response to a temperature step or ramp (FSI model, Eqs. 33-36).
    ///
    /// The twin runs what `twin-config` chooses for the file at --dt unless
    /// --scheme or --substeps override it; stderr names the configuration.
    Step {
        #[arg(long)]
        params: PathBuf,
        /// Initial temperature [C] (the twin starts at its equilibrium).
        #[arg(long, allow_hyphen_values = true)]
        from: f64,
        /// Final temperature [C].
        #[arg(long, allow_hyphen_values = true)]
        to: f64,
        /// Ramp rate [C/s]; without it, a step at t = 0.
        #[arg(long, allow_hyphen_values = true)]
        ramp: Option<f64>,
        /// Tick [s]: output interval and integration step.
        #[arg(long, default_value = "0.001", allow_hyphen_values = true)]
        dt: f64,
        /// Simulated time [s] (default: ramp duration + 0.5 s).
        #[arg(long, allow_hyphen_values = true)]
        t_end: Option<f64>,
        /// Scalar type, the reduced model, or the adaptive reference solver.
        #[arg(long, value_enum, default_value = "f64")]
        precision: compensator_cli::dynamics::Precision,
        /// One-step scheme of the twin, overriding the chosen one (sdirk3).
        #[arg(long, value_parser = scheme_parser())]
        scheme: Option<Scheme>,
        /// Steps per tick, overriding the chosen number (alone: with sdirk3).
        #[arg(long)]
        substeps: Option<u8>,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
        /// With --plot: also run the reference solver and draw it dashed over the twin.
        #[arg(long)]
        overlay_reference: bool,
    },
    /// The twin's scheme and substeps per tick chosen for a file (CSV).
    ///
    /// Chosen from the design's own dynamics over the file's validated
    /// range ([estimator] valid_min, valid_max): the cheapest substep count
    /// whose estimated error stays within the target (% of a step).
    TwinConfig {
        #[arg(long)]
        params: PathBuf,
        /// Tick [s].
        #[arg(long, default_value = "0.001", allow_hyphen_values = true)]
        dt: f64,
    },
    /// Eigenvalues of the linearisation at the equilibrium (Eq. 37).
    Eigen {
        #[arg(long)]
        params: PathBuf,
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Step-response indicators of Table 3 (reference solver).
    Indicators {
        #[arg(long)]
        params: PathBuf,
        /// Steps as from:to pairs.
        #[arg(long, default_value = "30:40,40:50,50:60,60:70,70:80", allow_hyphen_values = true)]
        steps: String,
        /// Sampling interval [s].
        #[arg(long, default_value = "0.0001", allow_hyphen_values = true)]
        dt: f64,
        /// Simulated time per step [s].
        #[arg(long, default_value = "1.0", allow_hyphen_values = true)]
        t_end: f64,
    },
    /// Demand, supply, compensation error and the Eq. (9) window per temperature.
    Compensation {
        #[arg(long)]
        params: PathBuf,
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Design sizing: the machine a compensator serves best (`machine`), or
    /// the window diameter a machine needs (`slot`); prints TOML.
    Size {
        #[arg(long)]
        params: PathBuf,
        /// What to size: machine or slot.
        #[arg(long = "for")]
        what: String,
        #[arg(long, default_value = "30:80:1", allow_hyphen_values = true)]
        temps: String,
        /// Reference temperature of the fitted leakage [C].
        #[arg(long, default_value = "40", allow_hyphen_values = true)]
        reference: f64,
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

/// Draws `fig` (built from a command's output `out`) to `path` if given,
/// and passes `out` on.
fn plotted(
    out: String,
    path: Option<PathBuf>,
    fig: impl FnOnce(&str) -> Result<plot::Figure, CliError>,
) -> Result<String, CliError> {
    if let Some(path) = path {
        plot::write(&path, &fig(&out)?)?;
    }
    Ok(out)
}

fn run(cli: Cli) -> Result<String, CliError> {
    match cli.command {
        Command::Equilibrium {
            params,
            temps,
            precision,
            plot: figure,
        } => plotted(
            statics::equilibrium(&params, &temps, precision == StaticPrecision::F32)?,
            figure,
            plot::equilibrium,
        ),
        Command::Asymptotic {
            params,
            order,
            reading,
            t0,
            temps,
            plot: figure,
        } => {
            let reading = match reading {
                ReadingArg::Temperature => compensator::asymptotic::Reading::Temperature,
                ReadingArg::Property => compensator::asymptotic::Reading::Property,
            };
            plotted(
                statics::asymptotic(&params, order as usize, reading, &t0, &temps)?,
                figure,
                |csv| plot::asymptotic(csv, order as usize),
            )
        }
        Command::Sensitivity { params, temps } => statics::sensitivity(&params, &temps),
        Command::Step {
            params,
            from,
            to,
            ramp,
            dt,
            t_end,
            precision,
            scheme,
            substeps,
            plot: figure,
            overlay_reference,
        } => {
            use compensator_cli::dynamics::{Precision, step};
            if overlay_reference && figure.is_none() {
                return Err(CliError::Input(
                    "--overlay-reference: draws over a figure; give --plot FILE.svg".into(),
                ));
            }
            if overlay_reference && precision == Precision::Reference {
                return Err(CliError::Input(
                    "--overlay-reference: the run is the reference already (--precision reference)".into(),
                ));
            }
            let out = step(&params, from, to, ramp, dt, t_end, precision, scheme, substeps)?;
            eprintln!("{}", out.note);
            if let Some(path) = figure {
                let name = match precision {
                    Precision::Reference => "reference (Radau5)".to_string(),
                    Precision::Reduced => "reduced model".to_string(),
                    p => format!(
                        "twin, {}",
                        p.to_possible_value().map_or("?".into(), |v| v.get_name().to_string())
                    ),
                };
                let reference = if overlay_reference {
                    Some(step(&params, from, to, ramp, dt, t_end, Precision::Reference, None, None)?.csv)
                } else {
                    None
                };
                let title = match ramp {
                    None => format!("Step {from} C to {to} C"),
                    Some(r) => format!("Ramp {from} C to {to} C at {r} C/s"),
                };
                let fig = plot::step(
                    &out.csv,
                    &name,
                    reference.as_deref().map(|r| (r, "reference (Radau5)")),
                    &title,
                )?;
                plot::write(&path, &fig)?;
            }
            Ok(out.csv)
        }
        Command::TwinConfig { params, dt } => compensator_cli::dynamics::twin_config(&params, dt),
        Command::Eigen {
            params,
            temps,
            plot: figure,
        } => plotted(compensator_cli::dynamics::eigen(&params, &temps)?, figure, plot::eigen),
        Command::Indicators {
            params,
            steps,
            dt,
            t_end,
        } => compensator_cli::dynamics::indicators(&params, &steps, dt, t_end),
        Command::Compensation {
            params,
            temps,
            plot: figure,
        } => plotted(sizing::compensation_table(&params, &temps)?, figure, plot::compensation),
        Command::Size {
            params,
            what,
            temps,
            reference,
        } => sizing::size(&params, &what, &temps, reference),
        Command::Calibrate { base, data } => calibration::calibrate(&base, &data),
        Command::Paper { params, data } => paper::report(&params, &data),
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
