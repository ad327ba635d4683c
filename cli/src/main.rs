//! `compensator`: the host command-line tool.
//!
//! Reads the parameter file of `docs/model.md` section 8, writes CSV with a header
//! row in SI units. Bad input exits with status 2 and one line on stderr
//! naming the field; nothing is written to stdout then.

use clap::{Parser, Subcommand, ValueEnum};
use compensator::dynamics::Scheme;
use compensator_cli::csv::Format;
use compensator_cli::error::CliError;
use compensator_cli::{calibration, paper, plot, sizing, statics};
use std::io::Write;
use std::path::{Path, PathBuf};
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
    /// Output format of a table: csv, json (one object per row) or table (aligned columns).
    #[arg(long, global = true, value_enum, default_value = "csv")]
    format: Format,
    /// Write the output to FILE instead of standard output (only once complete).
    #[arg(short = 'o', long = "output", global = true, value_name = "FILE")]
    output: Option<PathBuf>,
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

// Long help of each command: its output columns with units, an example.
const EQUILIBRIUM_HELP: &str = "\
Output: CSV, one row per temperature:
  t_c [C], a_sqrt_pa [sqrt(Pa)] (the property A), p_a_pa [Pa], p_b_pa [Pa],
  dp_ab_pa [Pa] (p_b - p_a), x_m [m] (plunger displacement),
  q_branch_m3s [m^3/s], q_throt_m3s [m^3/s], q_total_m3s [m^3/s]

Example:
  compensator equilibrium --params presets/paper.toml --temps 30:80:10";
const ASYMPTOTIC_HELP: &str = "\
Output: CSV, one row per temperature:
  t_c [C], x_qs_m [m] (quasi-static), x_asym_m [m] (the series)

Example:
  compensator asymptotic --params presets/paper.toml --order 2 --reading temperature --t0 balance";
const SENSITIVITY_HELP: &str = "\
Output: CSV, one row per temperature:
  t_c [C], dx_dt_branch_m_k [m/K], dx_dt_m_k [m/K], dq_throt_dt_m3s_k [m^3/(s K)]

Example:
  compensator sensitivity --params presets/paper.toml --temps 26:78:2";
const STEP_HELP: &str = "\
Output: CSV, one row per tick from t = 0:
  time_s [s], x_m [m], v_m_s [m/s], p_a_pa [Pa], p_b_pa [Pa]

Example:
  compensator step --params presets/paper.toml --from 40 --to 50 --t-end 0.5";
const TWIN_CONFIG_HELP: &str = "\
Output: CSV, one row:
  scheme, substeps, tick_s [s], valid_min_c [C], valid_max_c [C],
  estimated_error_pct [%], target_pct [%], goal_met (true/false)

Example:
  compensator twin-config --params presets/paper.toml --dt 0.001";
const EIGEN_HELP: &str = "\
Output: CSV, one row per temperature:
  t_c [C], re_1, im_1, ..., re_4, im_4 [1/s] (eigenvalues),
  zeta_dominant [-], omega_n_dominant [rad/s] (the dominant pair)

Example:
  compensator eigen --params presets/paper.toml --temps 30:80:10";
const INDICATORS_HELP: &str = "\
Output: CSV, one row per step:
  from_c [C], to_c [C], x_star_m [m] (final displacement),
  settling_time_s [s], overshoot_pct [%], dominant_re [1/s]

Example:
  compensator indicators --params presets/paper.toml --steps 30:40,40:50";
const COMPENSATION_HELP: &str = "\
Output: CSV, one row per temperature:
  t_c [C], losses_m3s [m^3/s], demand_m3s [m^3/s], supply_m3s [m^3/s],
  error_m3s [m^3/s] (supply - demand), required_area_m2 [m^2],
  required_x_m [m], x_m [m]
The file needs a [machine] section.

Example:
  compensator compensation --params presets/paper.toml --temps 30:80:10";
const SIZE_HELP: &str = "\
Output: TOML with the fit's provenance in comments:
  --for machine: [machine] working_flow [m^3/s], leakage_reference [m^3/s],
                 leakage_temperature [C]
  --for slot:    [slot] diameter [m], discharge_coefficient [-]

Example:
  compensator size --params presets/paper.toml --for machine --temps 30:80:1";
const CALIBRATE_HELP: &str = "\
Output: a complete parameter file (TOML, SI units as in docs/model.md
section 8) with the fit's RMS and max residuals in comments.

Without --base / --data the copies built into the binary are used, so the
command works from any directory.

Example:
  compensator calibrate > my-paper.toml";
const PAPER_HELP: &str = "\
Output: a text report: Table 1 inverted for A(t) [sqrt(Pa)], Table 1
residuals [bar], Table 2 displacements [mm], the \"asym\" column's expansion,
the Eq. (1) chamber-pressure gradient [kPa/C] and the Eq. (32) verdict.

Without --params / --data the copies built into the binary are used, so
the command works from any directory.

Example:
  compensator paper";

#[derive(Subcommand, Debug)]
enum Command {
    /// Quasi-static equilibrium (Eqs. 2-10) per temperature.
    #[command(after_long_help = EQUILIBRIUM_HELP)]
    Equilibrium {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
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
    #[command(after_long_help = ASYMPTOTIC_HELP)]
    Asymptotic {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
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
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Temperature sensitivities (Eqs. 30-31) and the Eq. (32) verdict.
    #[command(after_long_help = SENSITIVITY_HELP)]
    Sensitivity {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "26:78:2", allow_hyphen_values = true)]
        temps: String,
    },
    /// Response to a temperature step or ramp (FSI model, Eqs. 33-36).
    ///
    /// The twin runs what `twin-config` chooses for the file at --dt unless
    /// --scheme or --substeps override it; stderr names the configuration.
    #[command(after_long_help = STEP_HELP)]
    Step {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
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
        /// Tick [s]: the twin's integration step (and output interval without --sample).
        #[arg(long, default_value = "0.001", allow_hyphen_values = true)]
        dt: f64,
        /// Output interval [s]: a row every round(S / dt) ticks (default: every tick).
        #[arg(long, value_name = "S", allow_hyphen_values = true)]
        sample: Option<f64>,
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
    #[command(after_long_help = TWIN_CONFIG_HELP)]
    TwinConfig {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Tick [s].
        #[arg(long, default_value = "0.001", allow_hyphen_values = true)]
        dt: f64,
    },
    /// Eigenvalues of the linearisation at the equilibrium (Eq. 37).
    #[command(after_long_help = EIGEN_HELP)]
    Eigen {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Step-response indicators of Table 3 (reference solver).
    #[command(after_long_help = INDICATORS_HELP)]
    Indicators {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
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
    #[command(after_long_help = COMPENSATION_HELP)]
    Compensation {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:10", allow_hyphen_values = true)]
        temps: String,
        /// Also draw the output as a figure (SVG; docs/plots.md).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Design sizing: the machine a compensator serves best (`machine`), or
    /// the window diameter a machine needs (`slot`); prints TOML.
    #[command(after_long_help = SIZE_HELP)]
    Size {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// What to size: machine or slot.
        #[arg(long = "for")]
        what: String,
        /// Temperatures [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30:80:1", allow_hyphen_values = true)]
        temps: String,
        /// Reference temperature of the fitted leakage [C].
        #[arg(long, default_value = "40", allow_hyphen_values = true)]
        reference: f64,
    },
    /// Fit a base parameter set to the paper's Tables 1 and 2; prints TOML.
    #[command(after_long_help = CALIBRATE_HELP)]
    Calibrate {
        /// Base parameter file whose geometry is kept [default: the built-in presets/model-example.toml].
        #[arg(long)]
        base: Option<PathBuf>,
        /// Folder with table1.csv and table2.csv [default: the built-in data/paper].
        #[arg(long)]
        data: Option<PathBuf>,
    },
    /// Reproduce the paper's tables and report the findings (text).
    #[command(after_long_help = PAPER_HELP)]
    Paper {
        /// Parameter file (TOML) [default: the built-in presets/paper.toml].
        #[arg(long)]
        params: Option<PathBuf>,
        /// Folder with table1.csv and table2.csv [default: the built-in data/paper].
        #[arg(long)]
        data: Option<PathBuf>,
    },
}

/// The command's output in the chosen format: the commands that write
/// TOML or text (`size`, `calibrate`, `paper`) have only that.
fn run(cli: Cli) -> Result<String, CliError> {
    let tabular = !matches!(
        cli.command,
        Command::Size { .. } | Command::Calibrate { .. } | Command::Paper { .. }
    );
    if !tabular && cli.format != Format::Csv {
        return Err(CliError::Input(
            "--format: size, calibrate and paper write TOML or text; json and table apply to the CSV commands".into(),
        ));
    }
    let format = cli.format;
    let out = run_command(cli.command)?;
    Ok(if tabular {
        compensator_cli::csv::render(&out, format)
    } else {
        out
    })
}

/// Writes the output to `path` or standard output. A closed pipe on
/// standard output (`| head`) ends quietly: `Ok(())`.
fn write_output(out: &str, path: Option<&Path>) -> Result<(), CliError> {
    match path {
        Some(path) => {
            std::fs::write(path, out).map_err(|e| CliError::Input(format!("--output: {}: {e}", path.display())))
        }
        None => {
            let mut stdout = std::io::stdout().lock();
            match stdout.write_all(out.as_bytes()).and_then(|()| stdout.flush()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                    Err(CliError::Failed(format!("standard output: {e}")))
                }
                _ => Ok(()),
            }
        }
    }
}

/// Draws `fig` (built from a command's CSV output `out`) to `path` if
/// given, and passes `out` on.
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

fn run_command(command: Command) -> Result<String, CliError> {
    match command {
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
            sample,
            t_end,
            precision,
            scheme,
            substeps,
            plot: figure,
            overlay_reference,
        } => {
            use compensator_cli::dynamics::{Precision, every_nth_row, step};
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
            let every = compensator_cli::dynamics::sample_every(sample, dt)?;
            let out = step(&params, from, to, ramp, dt, t_end, precision, scheme, substeps)?;
            let _ = writeln!(std::io::stderr(), "{}", out.note);
            let csv = every_nth_row(&out.csv, every);
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
                    let r = step(&params, from, to, ramp, dt, t_end, Precision::Reference, None, None)?;
                    Some(every_nth_row(&r.csv, every))
                } else {
                    None
                };
                let title = match ramp {
                    None => format!("Step {from} C to {to} C"),
                    Some(r) => format!("Ramp {from} C to {to} C at {r} C/s"),
                };
                let fig = plot::step(
                    &csv,
                    &name,
                    reference.as_deref().map(|r| (r, "reference (Radau5)")),
                    &title,
                )?;
                plot::write(&path, &fig)?;
            }
            Ok(csv)
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
        Command::Calibrate { base, data } => calibration::calibrate(base.as_deref(), data.as_deref()),
        Command::Paper { params, data } => paper::report(params.as_deref(), data.as_deref()),
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
            let _ = writeln!(std::io::stderr(), "{}", line.trim());
            return ExitCode::from(2);
        }
    };
    let output = cli.output.clone();
    match run(cli).and_then(|out| write_output(&out, output.as_deref())) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
