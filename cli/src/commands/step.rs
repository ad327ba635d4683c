//! `step`: the twin's response to a temperature step or ramp (Eqs. 33-36).

use crate::args::{Output, ParamsArg, PlotArg, TableArgs};
use crate::dynamics::{Precision, every_nth_row, sample_every, step};
use crate::error::CliError;
use crate::plot;
use clap::ValueEnum;
use compensator::dynamics::Scheme;

/// The core's one-step schemes, by name.
fn scheme_parser() -> impl clap::builder::TypedValueParser<Value = Scheme> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Scheme::ALL.map(Scheme::name))
        .try_map(|name| Scheme::from_name(&name).ok_or("unknown scheme"))
}

const HELP: &str = "\
Output: CSV, one row per tick from t = 0:
  time_s [s], t_c [C] (the temperature the tick ran at), x_m [m],
  v_m_s [m/s], p_a_pa [Pa], p_b_pa [Pa],
  envelope (validated | oil_model: outside the validated range)
The columns identify --data reads: a step can be fed to identify.

Example:
  compensator step --params presets/paper.toml --from 40 --to 50 --t-end 0.5";

/// Response to a temperature step or ramp (FSI model, Eqs. 33-36).
///
/// The twin runs what `twin-config` chooses for the file at --dt unless
/// --scheme or --substeps override it; stderr names the configuration.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
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
    precision: Precision,
    /// One-step scheme of the twin, overriding the chosen one (sdirk3).
    #[arg(long, value_parser = scheme_parser())]
    scheme: Option<Scheme>,
    /// Steps per tick, overriding the chosen number (alone: with sdirk3).
    #[arg(long)]
    substeps: Option<u8>,
    #[command(flatten)]
    plot: PlotArg,
    /// With --plot: also run the reference solver and draw it dashed over the twin.
    #[arg(long)]
    overlay_reference: bool,
    #[command(flatten)]
    table: TableArgs,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the temperatures, the times, the options that
    /// do not go together), naming it; a twin that fails.
    pub fn run(self) -> Result<Output, CliError> {
        let Args {
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
            table,
        } = self;
        let params = &params.params;
        if overlay_reference && figure.plot.is_none() {
            return Err(CliError::Input(
                "--overlay-reference: draws over a figure; give --plot FILE.svg or FILE.png".into(),
            ));
        }
        if overlay_reference && precision == Precision::Reference {
            return Err(CliError::Input(
                "--overlay-reference: the run is the reference already (--precision reference)".into(),
            ));
        }
        let every = sample_every(sample, dt)?;
        let out = step(params, from, to, ramp, dt, t_end, precision, scheme, substeps)?;
        eprintln!("{}", out.note);
        let csv = every_nth_row(&out.table, every);
        if let Some(path) = &figure.plot {
            let name = match precision {
                Precision::Reference => "reference (Radau5)".to_string(),
                Precision::Reduced => "reduced model".to_string(),
                p => format!(
                    "twin, {}",
                    p.to_possible_value().map_or("?".into(), |v| v.get_name().to_string())
                ),
            };
            let reference = if overlay_reference {
                let r = step(params, from, to, ramp, dt, t_end, Precision::Reference, None, None)?;
                Some(every_nth_row(&r.table, every))
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
                table.units.units,
            )?;
            plot::write(path, &fig)?;
        }
        Ok(Output::table(csv, &table))
    }
}
