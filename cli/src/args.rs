//! Arguments more than one command takes, each declared once and
//! flattened into the commands' `Args` (`#[command(flatten)]`): the
//! parameter file, the temperature list, the figure, the output format
//! and units. A command offers only the ones it accepts, so its `--help`
//! lists what it really takes and clap refuses the rest by name.

use crate::csv::Format;
use crate::error::CliError;
use crate::units::Units;
use compensator::{Float, Params, RawParams};
use std::fmt::Debug;
use std::marker::PhantomData;
use std::path::PathBuf;

/// `--params FILE`: the parameter file every computing command reads.
#[derive(clap::Args, Debug, Clone)]
pub struct ParamsArg {
    /// Parameter file (TOML; its fields: docs/parameters.md); `-` reads standard input.
    #[arg(long, value_name = "FILE")]
    pub params: PathBuf,
}

impl ParamsArg {
    /// The file, read and validated.
    ///
    /// # Errors
    ///
    /// As [`crate::input::load_raw`]: bad input naming `--params` or the field.
    pub fn raw(&self) -> Result<RawParams, CliError> {
        crate::input::load_raw(&self.params, "--params")
    }

    /// The file, read, validated and converted to `T`.
    ///
    /// # Errors
    ///
    /// As [`crate::input::load_params`].
    pub fn load<T: Float>(&self) -> Result<(RawParams, Params<T>), CliError> {
        crate::input::load_params(&self.params)
    }
}

/// The default of a command's `--temps` (the commands differ in it).
pub trait TempsDefault: Clone + Debug + Send + Sync + 'static {
    /// `start:end:step` or a comma list [C].
    const TEMPS: &'static str;
}

/// `--temps`, with the default of `D`.
#[derive(clap::Args, Debug, Clone)]
pub struct Temps<D: TempsDefault> {
    /// Temperatures [C]: start:end:step or a comma list, inside the file's oil-model range (docs/parameters.md).
    #[arg(long, value_name = "LIST", default_value = D::TEMPS, allow_hyphen_values = true)]
    pub temps: String,
    #[arg(skip)]
    default: PhantomData<D>,
}

impl<D: TempsDefault> Temps<D> {
    /// A list as given on the command line (for calling a command from code).
    pub fn new(temps: &str) -> Self {
        Temps {
            temps: temps.to_string(),
            default: PhantomData,
        }
    }
}

macro_rules! temps_default {
    ($($(#[$doc:meta])* $name:ident = $value:literal;)*) => {$(
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default)]
        pub struct $name;
        impl TempsDefault for $name {
            const TEMPS: &'static str = $value;
        }
    )*};
}

temps_default! {
    /// Every 10 C over the paper's range.
    Every10 = "30:80:10";
    /// Every 2 C over the validated range of the presets.
    Every2 = "26:78:2";
    /// Every 1 C over the paper's range (the sizing fits).
    Every1 = "30:80:1";
    /// Three temperatures (a sweep's displacement columns).
    Three = "30,50,80";
}

/// `--plot FILE.svg|FILE.png`: the output drawn as a figure too.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PlotArg {
    /// Also draw a figure, SVG or PNG by the file's extension (docs/plots.md).
    #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = crate::plot::parse_path)]
    pub plot: Option<PathBuf>,
}

impl PlotArg {
    /// Draws the figure `fig` builds from a command's CSV output `csv` to
    /// the file of `--plot`, if one was given.
    ///
    /// # Errors
    ///
    /// The figure's or the file's error.
    pub fn draw(
        &self,
        csv: &str,
        fig: impl FnOnce(&str) -> Result<crate::plot::Figure, CliError>,
    ) -> Result<(), CliError> {
        match &self.plot {
            Some(path) => crate::plot::write(path, &fig(csv)?),
            None => Ok(()),
        }
    }
}

/// `--format csv|json|table`, for the commands that print a table.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct FormatArg {
    /// Output format: csv, json (one object per row) or table (aligned, rounded columns for reading).
    #[arg(long, value_enum, default_value = "csv")]
    pub format: Format,
}

/// `--units si|eng`, for the commands whose tables or figures have units.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct UnitsArg {
    /// Units of tables and figures: si (m, Pa, m^3/s, m^2/s) or eng (mm, bar, L/min, cSt; columns renamed).
    #[arg(long, value_enum, default_value = "si")]
    pub units: Units,
}

/// `--format` and `--units`: a table of physical quantities.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct TableArgs {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub format: FormatArg,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub units: UnitsArg,
}

/// What a command writes to standard output (or `-o FILE`).
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// CSV with a header row in SI units, rendered in `format` and `units`.
    Table {
        /// The CSV text.
        csv: String,
        /// How to print it.
        format: Format,
        /// In which units.
        units: Units,
    },
    /// Text written as it is (TOML, a report, a script, a man page).
    Text(String),
    /// A sweep's CSV rows, computed and written a block at a time
    /// ([`crate::sweep::stream`]).
    Rows(Box<crate::sweep::stream::Rows>),
}

impl Output {
    /// A table in the format and units of `args`.
    pub fn table(csv: String, args: &TableArgs) -> Self {
        Output::Table {
            csv,
            format: args.format.format,
            units: args.units.units,
        }
    }

    /// A table of parameter values (their file's SI units) in `format`.
    pub fn si_table(csv: String, format: &FormatArg) -> Self {
        Output::Table {
            csv,
            format: format.format,
            units: Units::Si,
        }
    }
}
