//! `compensator`: the host command-line tool.
//!
//! Reads the parameter file of `docs/model.md` section 8, writes CSV with a header
//! row in SI units (`--units eng`: mm, bar, L/min). Bad input exits with status 2
//! and one line on stderr naming the field; nothing is written to stdout then.
//! A table some of whose rows could not be computed is written with an
//! `error` column, then the status is 1.

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use compensator::dynamics::Scheme;
use compensator_cli::csv::Format;
use compensator_cli::error::CliError;
use compensator_cli::units::Units;
use compensator_cli::{calibration, paper, plot, report, sizing, statics, sweep};
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
    /// Units of tables and figures: si (m, Pa, m^3/s) or eng (mm, bar, L/min, cSt; columns renamed).
    #[arg(long, global = true, value_enum, default_value = "si")]
    units: Units,
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
Fits fluid.walther_a, fluid.walther_b and laminar_throttle.length (through
the geometry factor G of A = G nu sqrt(rho)) to the pressure data, then
plunger.spring_rate and plunger.preload to the displacement data; the
other fields are the base file's. Refuses (exit 2, naming why) data that
cannot determine them: no more points than parameters, or parameters the
data do not separate; warns on stderr when they are barely separated.

Data (long form, one row per measurement; ',' ';' or tab separated, a BOM
and quoted cells accepted, '#' lines are comments):
  pressure:     t_c [C], dp_pa [Pa] (p_p - p_c), dp_ab_pa [Pa] (p_b - p_a)
  displacement: t_c [C], x_m [m] (optional dp_pa [Pa]; default: the base
                file's operating.pressure_drop)

Output: CSV, one row per fitted parameter:
  parameter, unit, value, std_error [unit], rel_std_error [-],
  data (pressure|displacement), points, dof (points - parameters of that
  data), residual_rms [residual_unit] (sqrt(RSS/dof)), residual_unit (Pa|m),
  corr_<parameter> [-] (the correlation matrix, one column per parameter)
stderr: points, dof and residual RMS per data set, and any warning.

Without --pressure-data the paper's Tables 1 and 2 built into the binary
are used (data/calibration/), so the command works from any directory.

Example:
  compensator calibrate --base presets/model-example.toml \\
    --pressure-data data/calibration/paper-pressure.csv \\
    --displacement-data data/calibration/paper-displacement.csv \\
    --write-preset my-paper.toml --plot fit.svg --format table";
const IDENTIFY_HELP: &str = "\
Simulates the measured temperature history with the dynamic twin in f64
(four times the substeps twin-config chooses for the sample interval) and
fits the dynamic parameters by least squares. 95 % intervals are profile
likelihood ones. A parameter is reported as not identifiable (no value
printed; kept at the --params value, the others fitted again without it)
when its relative standard error exceeds 50 %, the data cannot separate it
from another, it runs to the edge of its plausible range, fewer than 10
samples carry its information, or its profile likelihood is flat
(docs/calibration.md).

Data: time_s [s] (uniform samples), t_c [C], x_m [m], optionally
p_a_pa, p_b_pa [Pa]; the record starts at rest at the first temperature.

Output: CSV, one row per parameter of --fit:
  parameter, unit, identifiable (true|false), value [unit],
  std_error [unit], rel_std_error [-], ci95_low [unit], ci95_high [unit]
  (the numbers are empty when identifiable is false)
stderr: the twin used, residuals, degrees of freedom, residual RMS [m]
(and [Pa]), and why each parameter is not identifiable.

Example:
  compensator identify --params my-device.toml --data step.csv \\
    --fit mass,damping --write-preset my-device-dynamic.toml --format table";
const PAPER_HELP: &str = "\
Output: a text report: Table 1 inverted for A(t) [sqrt(Pa)], Table 1
residuals [bar], Table 2 displacements [mm], the \"asym\" column's expansion,
the Eq. (1) chamber-pressure gradient [kPa/C] and the Eq. (32) verdict.

Without --params / --data the copies built into the binary are used, so
the command works from any directory.

Example:
  compensator paper";
const SWEEP_HELP: &str = "\
Output: CSV, one row per variant (grid points, each with --samples draws):
  variant [-] (0-based), one column per --set/--vary parameter [its unit in
  the file, SI], x_<T>c_m [m] (quasi-static displacement at each --temps T),
  monotonic (true/false: the Eq. 32 verdict over the validated range),
  min_dx_dt_m_k [m/K] (the smallest dx/dt found), dominant_re [1/s]
  (dominant eigenvalue at the step's final temperature), settling_time_s [s]
  (2 % settling of the --step response, reference solver),
  comp_error_rms_m3s [m^3/s] (compensation error RMS over the validated
  range; only with a [machine] section), error (why a variant failed).
A variant outside its field's plausible range keeps its row, with the reason
in the error column; the exit status is then 1. Rows do not depend on the
number of threads (RAYON_NUM_THREADS).

Example:
  compensator sweep --params presets/paper.toml --set plunger.spring_rate=20e3:30e3:5
  compensator sweep --params presets/paper.toml --vary plunger.diameter=1% --samples 200 --seed 7";
const REPORT_HELP: &str = "\
Output: files in --out (their names listed on stdout):
  report.md   Tables 1-3, each model value beside the paper's, the figures
              linked, and the findings of `compensator paper`
  table1.csv  t_c [C], dp_pa, paper_dp_ab_pa, model_dp_ab_pa, residual_pa [Pa]
  table2.csv  t_c [C], paper/model x_qs_m and x_asym_m, residuals [m]
  table3.csv  from_c, to_c [C], paper/model x_star_m [m], paper_settling_rel [-],
              model_settling_time_s [s], overshoot_pct [%], dominant_re [1/s]
  fig2_pressure_difference, fig3_displacement, fig4_step_responses,
  fig5_normalised_responses, eigenvalues, compensation: .svg (and .png
  with --png)
--units eng writes bar, mm, L/min (columns renamed). Without --params /
--data the copies built into the binary are used, so the command works
from any directory.

Example:
  compensator report --out paper-report --units eng --png";
const COMPLETIONS_HELP: &str = "\
Output: the completion script for the shell, on stdout.

Example:
  compensator completions bash > /etc/bash_completion.d/compensator";
const MAN_HELP: &str = "\
Output: the man page compensator(1) in roff, on stdout; with --dir, the
files compensator.1 and compensator-<command>.1 (one per subcommand).

Example:
  compensator man > compensator.1 && man ./compensator.1";

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
        /// Also draw the output as a figure (SVG or PNG by the name; docs/plots.md).
        #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = plot::parse_path)]
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
        /// Also draw the output as a figure (SVG or PNG by the name; docs/plots.md).
        #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = plot::parse_path)]
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
        /// Also draw the output as a figure (SVG or PNG by the name; docs/plots.md).
        #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = plot::parse_path)]
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
        /// Also draw the output as a figure (SVG or PNG by the name; docs/plots.md).
        #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = plot::parse_path)]
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
        /// Also draw the output as a figure (SVG or PNG by the name; docs/plots.md).
        #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = plot::parse_path)]
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
    /// Fit the static parameters to measured pressures and displacements, with standard errors.
    #[command(after_long_help = CALIBRATE_HELP)]
    Calibrate {
        /// Base parameter file whose other fields are kept [default: the built-in presets/model-example.toml].
        #[arg(long)]
        base: Option<PathBuf>,
        /// Pressure data t_c,dp_pa,dp_ab_pa (CSV) [default: the paper's Table 1, built in].
        #[arg(long, value_name = "P.csv")]
        pressure_data: Option<PathBuf>,
        /// Displacement data t_c,x_m[,dp_pa] (CSV) [default: the paper's Table 2 without --pressure-data].
        #[arg(long, value_name = "X.csv")]
        displacement_data: Option<PathBuf>,
        /// Write the calibrated parameter file (TOML, the fit in comments) to FILE.
        #[arg(long, value_name = "FILE")]
        write_preset: Option<PathBuf>,
        /// Draw the data against the fitted curves (SVG).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
    },
    /// Fit the dynamic parameters (mass, damping, compliance) to a measured transient, with intervals.
    #[command(after_long_help = IDENTIFY_HELP)]
    Identify {
        /// Parameter file (TOML) with the static parameters calibrated; `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Transient time_s,t_c,x_m[,p_a_pa,p_b_pa] (CSV).
        #[arg(long, value_name = "STEP.csv")]
        data: PathBuf,
        /// Parameters to fit, comma list of mass, damping, bulk_modulus, volume_a, volume_b.
        #[arg(long, default_value = "mass,damping,bulk_modulus")]
        fit: String,
        /// Write the parameter file with the identified values (TOML) to FILE.
        #[arg(long, value_name = "FILE")]
        write_preset: Option<PathBuf>,
        /// Draw the measured and simulated transient (SVG).
        #[arg(long, value_name = "FILE.svg", value_parser = plot::parse_path)]
        plot: Option<PathBuf>,
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
    /// The paper's Tables 1-3 and Figures 2-5 recomputed, as files in a folder.
    #[command(after_long_help = REPORT_HELP)]
    Report {
        /// Parameter file (TOML) [default: the built-in presets/paper.toml].
        #[arg(long)]
        params: Option<PathBuf>,
        /// Folder with table1.csv, table2.csv and table3.csv [default: the built-in data/paper].
        #[arg(long)]
        data: Option<PathBuf>,
        /// Folder to write into (created if absent; files in it are replaced).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Also write each figure as PNG.
        #[arg(long)]
        png: bool,
    },
    /// Design variants on a grid of named parameters or drawn within tolerances.
    #[command(after_long_help = SWEEP_HELP)]
    Sweep {
        /// Parameter file (TOML, docs/model.md section 8); `-` reads standard input.
        #[arg(long)]
        params: PathBuf,
        /// Grid axis section.key=START:END:COUNT (COUNT values, ends included) or =V1,V2; repeatable.
        #[arg(long = "set", value_name = "NAME=SPEC", allow_hyphen_values = true)]
        set: Vec<String>,
        /// Tolerance section.key=P% or =A (uniform within +-P % or +-A of the value); repeatable.
        #[arg(long, value_name = "NAME=TOL", allow_hyphen_values = true)]
        vary: Vec<String>,
        /// Draws per grid point with --vary [default: 100].
        #[arg(long, value_name = "N")]
        samples: Option<usize>,
        /// Seed of the draws (same seed, same variants).
        #[arg(long, default_value = "1")]
        seed: u64,
        /// Temperatures of the displacement columns [C]: start:end:step or a comma list.
        #[arg(long, default_value = "30,50,80", allow_hyphen_values = true)]
        temps: String,
        /// Step of the settling time and dominant eigenvalue, from:to [C].
        #[arg(long, default_value = "40:50", allow_hyphen_values = true)]
        step: String,
        /// Sampling interval of the step response [s].
        #[arg(long, default_value = "0.0001", allow_hyphen_values = true)]
        dt: f64,
        /// Simulated time of the step [s].
        #[arg(long, default_value = "0.2", allow_hyphen_values = true)]
        t_end: f64,
    },
    /// Shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_long_help = COMPLETIONS_HELP)]
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// The man page compensator(1) (roff), or with --dir one page per subcommand.
    #[command(after_long_help = MAN_HELP)]
    Man {
        /// Write compensator.1 and compensator-<command>.1 into DIR instead of printing compensator(1).
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
}

/// A command's output in the chosen format and units, and its rows that
/// could not be computed (failed, total): the commands that write TOML or
/// text (`size`, `paper`, `report`, `completions`, `man`) have only that.
fn run(cli: Cli) -> Result<(String, (usize, usize)), CliError> {
    let tabular = !matches!(
        cli.command,
        Command::Size { .. }
            | Command::Paper { .. }
            | Command::Report { .. }
            | Command::Completions { .. }
            | Command::Man { .. }
    );
    if !tabular && cli.format != Format::Csv {
        return Err(CliError::Input(
            "--format: size, paper, report, completions and man write files, TOML or text; \
             json and table apply to the CSV commands"
                .into(),
        ));
    }
    if cli.units != Units::Si
        && matches!(
            cli.command,
            Command::Size { .. } | Command::Calibrate { .. } | Command::Identify { .. } | Command::Paper { .. }
        )
    {
        return Err(CliError::Input(
            "--units: size, calibrate and identify write parameter values and paper its report in the file's SI units; \
             eng applies to the tables, figures and report"
                .into(),
        ));
    }
    let (format, units) = (cli.format, cli.units);
    let out = run_command(cli.command, units)?;
    Ok(if tabular {
        let failed = compensator_cli::csv::failed_rows(&out);
        (compensator_cli::csv::render(&units.convert_csv(&out), format), failed)
    } else {
        (out, (0, 0))
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

fn run_command(command: Command, units: Units) -> Result<String, CliError> {
    match command {
        Command::Equilibrium {
            params,
            temps,
            precision,
            plot: figure,
        } => plotted(
            statics::equilibrium(&params, &temps, precision == StaticPrecision::F32)?,
            figure,
            |csv| plot::equilibrium(csv, units),
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
                |csv| plot::asymptotic(csv, order as usize, units),
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
                    "--overlay-reference: draws over a figure; give --plot FILE.svg or FILE.png".into(),
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
                    units,
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
        } => plotted(sizing::compensation_table(&params, &temps)?, figure, |csv| {
            plot::compensation(csv, units)
        }),
        Command::Size {
            params,
            what,
            temps,
            reference,
        } => sizing::size(&params, &what, &temps, reference),
        Command::Calibrate {
            base,
            pressure_data,
            displacement_data,
            write_preset,
            plot: figure,
        } => {
            let out = calibration::calibrate(&calibration::Options {
                base,
                pressure: pressure_data,
                displacement: displacement_data,
                write_preset,
                plot: figure,
            })?;
            let mut stderr = std::io::stderr().lock();
            for line in &out.notes {
                let _ = writeln!(stderr, "calibrate: {line}");
            }
            Ok(out.table)
        }
        Command::Identify {
            params,
            data,
            fit,
            write_preset,
            plot: figure,
        } => {
            let (table, notes) = compensator_cli::identify::identify(&compensator_cli::identify::Options {
                params,
                data,
                fit: Some(fit),
                write_preset,
                plot: figure,
            })?;
            let mut stderr = std::io::stderr().lock();
            for line in &notes {
                let _ = writeln!(stderr, "identify: {line}");
            }
            Ok(table)
        }
        Command::Paper { params, data } => paper::report(params.as_deref(), data.as_deref()),
        Command::Report { params, data, out, png } => report::report(&report::Options {
            params: params.as_deref(),
            data: data.as_deref(),
            out: &out,
            png,
            units,
        }),
        Command::Sweep {
            params,
            set,
            vary,
            samples,
            seed,
            temps,
            step,
            dt,
            t_end,
        } => {
            let raw = compensator_cli::input::load_raw(&params, "--params")?;
            let s = sweep::build(raw, &set, &vary, samples, seed, &temps, &step, dt, t_end)?;
            sweep::run(&s)
        }
        Command::Completions { shell } => {
            let mut buf = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "compensator", &mut buf);
            String::from_utf8(buf).map_err(|e| CliError::Failed(format!("completions: {e}")))
        }
        Command::Man { dir: Some(dir) } => {
            std::fs::create_dir_all(&dir)
                .and_then(|()| clap_mangen::generate_to(Cli::command().name("compensator"), &dir))
                .map_err(|e| CliError::Input(format!("--dir: {}: {e}", dir.display())))?;
            Ok(String::new())
        }
        Command::Man { dir: None } => {
            let mut buf = Vec::new();
            clap_mangen::Man::new(Cli::command())
                .render(&mut buf)
                .map_err(|e| CliError::Failed(format!("man: {e}")))?;
            String::from_utf8(buf).map_err(|e| CliError::Failed(format!("man: {e}")))
        }
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
    match run(cli).and_then(|(out, failed)| write_output(&out, output.as_deref()).map(|()| failed)) {
        Ok((0, _)) => ExitCode::SUCCESS,
        Ok((failed, total)) => {
            let _ = writeln!(
                std::io::stderr(),
                "error: {failed} of {total} rows could not be computed (their error column says why)"
            );
            ExitCode::from(1)
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
