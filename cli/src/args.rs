//! Arguments more than one command takes, each declared once and
//! flattened into the commands' `Args` (`#[command(flatten)]`): the
//! parameter file, the temperature list, the figure, the output format
//! and units. A command offers only the ones it accepts, so its `--help`
//! lists what it really takes and clap refuses the rest by name.
//!
//! The groups that go together carry what the commands do with them:
//! [`OverTemps`] (`--params` and `--temps`) hands them to a table's
//! computation, [`PlottedTable`] (`--plot`, `--format`, `--units`) draws
//! the figure and returns the table, [`FitTable`] writes a fit's notes
//! and table, [`PaperInputs`] holds the paper's defaults; `rows_help!`
//! writes the long help of a table with a row per temperature or step.

use crate::csv::Format;
use crate::error::CliError;
use crate::plot::Figure;
use crate::units::Units;
use compensator::{Float, Params, RawParams};
use std::fmt::Debug;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

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

/// `--params FILE --sensor-data LOG.csv`: a device file and a log replayed
/// through its estimator (`estimate`, `monitor`), read together because
/// the log's second sensor's column is checked against the file's.
#[derive(clap::Args, Debug, Clone)]
pub struct ReplayInputs {
    #[command(flatten)]
    pub params: ParamsArg,
    /// Log: time_s, one of the probe's columns (t_c, t_probe_c, rtd_ohm, code) and, with the file's [monitor], the second sensor's (p_a_pa, p_b_pa, dp_ab_pa or x_m; CSV); - reads standard input.
    #[arg(long, value_name = "LOG.csv")]
    pub sensor_data: PathBuf,
}

/// A [`ReplayInputs`] read: the device file, the log, and the log's name
/// as its errors give it.
#[derive(Debug, Clone)]
pub struct Replay {
    /// The device file, validated.
    pub raw: RawParams,
    /// The log, its second sensor's column checked against the file's.
    pub log: crate::estimate::Log,
    /// The log's path, or `standard input`.
    pub shown: String,
}

impl Replay {
    /// An error of the replay: one about the log (not `--params`')
    /// prefixed with `--sensor-data` and the log's name.
    pub fn in_log(&self, e: CliError) -> CliError {
        match e {
            CliError::Input(m) if !m.starts_with("--params") => {
                CliError::Input(format!("--sensor-data: {}: {m}", self.shown))
            }
            e => e,
        }
    }
}

impl ReplayInputs {
    /// Reads the device file and the log (bounded: [`crate::input::MAX_LOG_BYTES`]).
    ///
    /// # Errors
    ///
    /// Both on standard input; the file as [`ParamsArg::raw`] and its
    /// `[monitor]` section as [`crate::estimate::SecondSensor::of`]; the
    /// log as [`crate::estimate::read_log`], naming `--sensor-data`, the
    /// log and its row, line and column.
    pub fn read(&self) -> Result<Replay, CliError> {
        let log_path = &self.sensor_data;
        if log_path.as_os_str() == "-" && self.params.params.as_os_str() == "-" {
            return Err(CliError::Input(
                "--sensor-data: standard input is --params' already; give one of them as a file".into(),
            ));
        }
        let raw = self.params.raw()?;
        let text = crate::input::bounded_text(
            log_path,
            "--sensor-data",
            crate::input::MAX_LOG_BYTES,
            &format!(": {}", crate::estimate::SPLIT),
        )?;
        let shown = if log_path.as_os_str() == "-" {
            "standard input".to_string()
        } else {
            log_path.display().to_string()
        };
        let sensor = crate::estimate::SecondSensor::of(&raw)?;
        let log = crate::estimate::read_log(&text, sensor.as_ref())
            .map_err(|e| CliError::Input(format!("--sensor-data: {shown}: {e}")))?;
        Ok(Replay { raw, log, shown })
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

/// The long help (`after_long_help`) of a command whose CSV has a row per
/// temperature or step: `Output: CSV, one row per <rows>:`, its `columns`
/// (lines indented by two spaces; the first line's are the macro's, as a
/// string continued after `\` starts without them), the two columns
/// every such table ends with (the envelope's mark,
/// [`crate::envelope::Envelope::mark`], and why a row could not be
/// computed), then `notes` (lines, or empty) and the example.
macro_rules! rows_help {
    ($rows:literal, $columns:literal, $notes:literal, $example:literal) => {
        concat!(
            "Output: CSV, one row per ",
            $rows,
            ":\n  ",
            $columns,
            "\n  envelope (validated | oil_model: outside the validated range, extrapolated),",
            "\n  error (why the row could not be computed; empty when it was)\n",
            $notes,
            "\nExample:\n  ",
            $example
        )
    };
}
pub(crate) use rows_help;

/// `--params` and `--temps`: a table of the file's model, one row per
/// temperature of the list.
#[derive(clap::Args, Debug, Clone)]
pub struct OverTemps<D: TempsDefault> {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub params: ParamsArg,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub temps: Temps<D>,
}

impl<D: TempsDefault> OverTemps<D> {
    /// The table `compute` makes of the file and the list (the library's
    /// per-temperature functions take them as given: the path and the
    /// list's text, and check one against the other).
    ///
    /// # Errors
    ///
    /// `compute`'s: bad input naming the file, the list or the field.
    pub fn table(&self, compute: impl FnOnce(&Path, &str) -> Result<String, CliError>) -> Result<String, CliError> {
        compute(&self.params.params, &self.temps.temps)
    }
}

/// `--plot FILE.svg|FILE.png`: the output drawn as a figure too.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PlotArg {
    /// Also draw a figure, SVG or PNG by the file's extension (docs/plots.md).
    #[arg(long, value_name = "FILE.svg|FILE.png", value_parser = crate::plot::parse_path)]
    pub plot: Option<PathBuf>,
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

/// `--plot` with `--format` and `--units`: a table the command can also
/// draw.
#[derive(clap::Args, Debug, Clone)]
pub struct PlottedTable {
    #[command(flatten)]
    #[allow(missing_docs)]
    pub plot: PlotArg,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub table: TableArgs,
}

impl PlottedTable {
    /// The command's output, the table `csv`, after drawing the figure
    /// `figure` builds from it (in the table's units) to the file of
    /// `--plot`, if one was given.
    ///
    /// # Errors
    ///
    /// The figure's or the file's error.
    pub fn output(
        &self,
        csv: String,
        figure: impl FnOnce(&str, Units) -> Result<Figure, CliError>,
    ) -> Result<Output, CliError> {
        if let Some(path) = &self.plot.plot {
            crate::plot::write(path, &figure(&csv, self.table.units.units)?)?;
        }
        Ok(Output::table(csv, &self.table))
    }
}

/// A command that fits parameters and reports them with [`FitTable`]
/// (`calibrate`, `identify`).
pub trait Fit: Clone + Debug + Send + Sync + 'static {
    /// The command's name, before each of its lines on standard error.
    const COMMAND: &'static str;
    /// The help of `--write-preset` (without the final period clap drops
    /// from a doc comment's one line).
    const WRITE_PRESET_HELP: &'static str;
}

/// `calibrate`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Calibrate;
impl Fit for Calibrate {
    const COMMAND: &'static str = "calibrate";
    const WRITE_PRESET_HELP: &'static str = "Write the calibrated parameter file (TOML, the fit in comments, its \
        standard errors and correlations in [tolerances] and [[correlation]]) to FILE";
}

/// `identify`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Identify;
impl Fit for Identify {
    const COMMAND: &'static str = "identify";
    const WRITE_PRESET_HELP: &'static str = "Write the parameter file with the identified values (TOML) to FILE";
}

/// `--write-preset`, `--plot` and `--format` of a fit `F`: the fitted
/// parameter file, a figure of the fit and the table of the parameters
/// (in their file's SI units).
#[derive(clap::Args, Debug, Clone)]
pub struct FitTable<F: Fit> {
    #[arg(long, value_name = "FILE", help = F::WRITE_PRESET_HELP)]
    #[allow(missing_docs)]
    pub write_preset: Option<PathBuf>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub plot: PlotArg,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub format: FormatArg,
    #[arg(skip)]
    fit: PhantomData<F>,
}

impl<F: Fit> FitTable<F> {
    /// The fit's output: its `notes` on standard error, each line after
    /// the command's name, and its `table`.
    pub fn output(&self, table: String, notes: &[String]) -> Output {
        for line in notes {
            eprintln!("{}: {line}", F::COMMAND);
        }
        Output::si_table(table, &self.format)
    }
}

/// Which of the paper's tables a command reads from `--data` (the
/// commands differ in it).
pub trait PaperTables: Clone + Debug + Send + Sync + 'static {
    /// The help of `--data` (without the final period clap drops from a
    /// doc comment's one line).
    const DATA_HELP: &'static str;
}

/// `paper`: Tables 1 and 2.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tables12;
impl PaperTables for Tables12 {
    const DATA_HELP: &'static str = "Folder with table1.csv and table2.csv [default: the built-in data/paper]";
}

/// `report`: Tables 1 to 3.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tables123;
impl PaperTables for Tables123 {
    const DATA_HELP: &'static str =
        "Folder with table1.csv, table2.csv and table3.csv [default: the built-in data/paper]";
}

/// `--params` and `--data` of the commands that recompute the paper, with
/// the paper's preset and tables built into the binary as defaults.
#[derive(clap::Args, Debug, Clone)]
pub struct PaperInputs<T: PaperTables> {
    /// Parameter file (TOML) [default: the built-in presets/paper.toml].
    #[arg(long, value_name = "FILE")]
    pub params: Option<PathBuf>,
    #[arg(long, value_name = "DIR", help = T::DATA_HELP)]
    #[allow(missing_docs)]
    pub data: Option<PathBuf>,
    #[arg(skip)]
    tables: PhantomData<T>,
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
