//! What the commands read: a parameter file (a path, or `-` for standard
//! input, bounded in size) and the paper's data and presets built into the
//! binary, so that `calibrate` and `paper` work from any directory.

use crate::error::CliError;
use crate::params_file;
use compensator::{Float, Params, RawParams};
use std::io::Read;
use std::path::Path;

/// Largest parameter file read [bytes]: 1 MiB.
pub const MAX_PARAMS_BYTES: u64 = 1 << 20;

/// `presets/paper.toml`, built in.
pub const PAPER_PRESET: &str = include_str!("../../presets/paper.toml");
/// `presets/model-example.toml`, built in.
pub const MODEL_EXAMPLE: &str = include_str!("../../presets/model-example.toml");
/// `data/paper/table1.csv`, built in.
pub const TABLE1_CSV: &str = include_str!("../../data/paper/table1.csv");
/// `data/paper/table2.csv`, built in.
pub const TABLE2_CSV: &str = include_str!("../../data/paper/table2.csv");
/// `data/paper/table3.csv`, built in.
pub const TABLE3_CSV: &str = include_str!("../../data/paper/table3.csv");
/// Where [`PAPER_PRESSURE_CSV`] lives in the repository.
pub const PAPER_PRESSURE_PATH: &str = "data/calibration/paper-pressure.csv";
/// The paper's Table 1 in the long form of `calibrate --pressure-data`, built in.
pub const PAPER_PRESSURE_CSV: &str = include_str!("../../data/calibration/paper-pressure.csv");
/// Where [`PAPER_DISPLACEMENT_CSV`] lives in the repository.
pub const PAPER_DISPLACEMENT_PATH: &str = "data/calibration/paper-displacement.csv";
/// The paper's Table 2 (quasi-static column) in the long form of
/// `calibrate --displacement-data`, built in.
pub const PAPER_DISPLACEMENT_CSV: &str = include_str!("../../data/calibration/paper-displacement.csv");

/// Largest sensor log `estimate --sensor-data` reads [bytes]: 64 MiB (a
/// day of telemetry at 2 Hz is 45 MB; a log at 50 Hz of one reading per
/// line, 20 bytes a line, is 3.4 million lines, beyond
/// [`crate::estimate::MAX_ROWS`] first).
pub const MAX_LOG_BYTES: u64 = 64 << 20;

/// `limit` bytes in words: `1 MiB`, `64 MiB`, or the count.
fn bytes_in_words(limit: u64) -> String {
    if limit >= 1 << 20 && limit.is_multiple_of(1 << 20) {
        format!("{} MiB", limit >> 20)
    } else {
        format!("{limit} bytes")
    }
}

/// Reads at most `limit` bytes from `r`; more is bad input of `flag`
/// (with `advice` after the limit).
fn read_bounded(r: impl Read, flag: &str, what: &str, limit: u64, advice: &str) -> Result<String, CliError> {
    let mut buf = Vec::new();
    r.take(limit + 1)
        .read_to_end(&mut buf)
        .map_err(|e| CliError::Input(format!("{flag}: {what}: {e}")))?;
    if buf.len() as u64 > limit {
        return Err(CliError::Input(format!(
            "{flag}: {what}: larger than the limit of {}{advice}",
            bytes_in_words(limit)
        )));
    }
    String::from_utf8(buf).map_err(|_| CliError::Input(format!("{flag}: {what}: not UTF-8 text")))
}

/// The text of a parameter file given to `flag`: `-` reads standard input;
/// a path must be a regular file of at most [`MAX_PARAMS_BYTES`] (checked
/// before opening, so that `/dev/zero` or a FIFO without a writer is
/// refused rather than read without end or waited on).
pub fn params_text(path: &Path, flag: &str) -> Result<String, CliError> {
    bounded_text(path, flag, MAX_PARAMS_BYTES, "")
}

/// The text of a file given to `flag`, as [`params_text`] with the limit
/// `limit` [bytes]; a larger file's message ends with `advice` (`: split
/// the log`).
pub fn bounded_text(path: &Path, flag: &str, limit: u64, advice: &str) -> Result<String, CliError> {
    if path.as_os_str() == "-" {
        return read_bounded(std::io::stdin().lock(), flag, "standard input", limit, advice);
    }
    let shown = path.display();
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        // The loader's own message for a file that cannot be read.
        Err(e) => {
            return Err(CliError::Input(format!(
                "{flag}: {}",
                params_file::LoadError::Io(shown.to_string(), e)
            )));
        }
    };
    if !meta.is_file() {
        return Err(CliError::Input(format!("{flag}: {shown}: not a regular file")));
    }
    if meta.len() > limit {
        return Err(CliError::Input(format!(
            "{flag}: {shown}: {} bytes, larger than the limit of {}{advice}",
            meta.len(),
            bytes_in_words(limit)
        )));
    }
    let file = std::fs::File::open(path).map_err(|e| params_file::LoadError::Io(shown.to_string(), e))?;
    read_bounded(file, flag, &shown.to_string(), limit, advice)
}

/// Reads and validates the parameter file given to `flag` (see [`params_text`]).
pub fn load_raw(path: &Path, flag: &str) -> Result<RawParams, CliError> {
    Ok(params_file::parse(&params_text(path, flag)?)?)
}

/// Loads a parameter file given to `--params` (`-`: standard input) and
/// converts it to `T`.
///
/// # Errors
///
/// As [`load_raw`]; a set the model refuses in `T` (naming the field).
pub fn load_params<T: Float>(path: &Path) -> Result<(RawParams, Params<T>), CliError> {
    let raw = load_raw(path, "--params")?;
    let params = Params::<T>::new(&raw).map_err(|e| CliError::Input(e.to_string()))?;
    Ok((raw, params))
}

/// [`load_params`] in `f64` of the file `path`, or without one of the
/// built-in [`PAPER_PRESET`] (`paper` and `report`).
///
/// # Errors
///
/// As [`load_params`].
pub fn load_or_paper(path: Option<&Path>) -> Result<(RawParams, Params<f64>), CliError> {
    match path {
        Some(path) => load_params::<f64>(path),
        None => {
            let raw = params_file::parse(PAPER_PRESET)?;
            let p = Params::<f64>::new(&raw).map_err(|e| CliError::Input(e.to_string()))?;
            Ok((raw, p))
        }
    }
}

/// What a table with a row per temperature is computed from: the file in
/// `f64` with its envelope, and the temperature list checked against it.
pub struct AtTemps {
    /// The file as read.
    pub raw: RawParams,
    /// The file in `f64`.
    pub params: Params<f64>,
    /// Its temperature envelope.
    pub envelope: crate::envelope::Envelope,
    /// The list's temperatures [C], each within the envelope.
    pub temps: Vec<f64>,
}

impl AtTemps {
    /// `csv`, a table whose rows start with `t_c`, with the envelope's
    /// column.
    pub fn mark(&self, csv: &str) -> String {
        self.envelope.mark(csv, &["t_c"])
    }
}

/// Loads the file `path` ([`load_with_envelope`]) and the list
/// `temps_spec` (`--temps`), each temperature checked against the file's
/// envelope.
///
/// # Errors
///
/// As [`load_with_envelope`]; a list that does not parse or a temperature
/// outside the oil model (naming `--temps`).
pub fn load_at_temps(path: &Path, temps_spec: &str) -> Result<AtTemps, CliError> {
    let (raw, params, envelope) = load_with_envelope(path)?;
    let temps = envelope.temps(temps_spec)?.into_iter().map(|(t, _)| t).collect();
    Ok(AtTemps {
        raw,
        params,
        envelope,
        temps,
    })
}

/// [`load_params`] in `f64` with the file's temperature envelope.
///
/// # Errors
///
/// As [`load_params`].
pub fn load_with_envelope(path: &Path) -> Result<(RawParams, Params<f64>, crate::envelope::Envelope), CliError> {
    let (raw, p) = load_params::<f64>(path)?;
    let env = crate::envelope::Envelope::of(&raw, &p);
    Ok((raw, p, env))
}
