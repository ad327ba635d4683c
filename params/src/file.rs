//! Reading the parameter file (`docs/model.md` section 8) into a validated
//! [`RawParams`], and writing one back.
//!
//! Every key of the file must be known (a typo is an error, not a silently
//! ignored value); numbers may be written as integers or floats; TOML's
//! `nan` and `inf` are read and then rejected by validation with the field's
//! name.

use crate::{CORE_FIELDS, ESTIMATOR_FIELDS, Field, MACHINE_FIELDS, ParamError, RawParams};
use std::fmt;
use std::path::Path;

/// Why a parameter file could not be used. `Display` is one line.
#[derive(Debug)]
pub enum LoadError {
    /// The file could not be read.
    Io(String, std::io::Error),
    /// Not valid TOML.
    Syntax(String),
    /// A key that is not part of the format.
    UnknownKey(String),
    /// A key whose value is not a number.
    NotANumber(String),
    /// A value that breaks a physical rule (names the field).
    Param(ParamError),
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Io(path, e) => write!(f, "{path}: {e}"),
            LoadError::Syntax(msg) => write!(f, "{msg}"),
            LoadError::UnknownKey(k) => write!(f, "{k}: unknown key"),
            LoadError::NotANumber(k) => write!(f, "{k}: expected a number"),
            LoadError::Param(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for LoadError {}

impl From<ParamError> for LoadError {
    fn from(e: ParamError) -> Self {
        LoadError::Param(e)
    }
}

fn known(section: &str, key: &str) -> bool {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .any(|f| f.section == section && f.key == key)
}

/// Parses parameter-file text.
pub fn parse(text: &str) -> Result<RawParams, LoadError> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let msg = e.message().lines().next().unwrap_or("invalid TOML").to_string();
        match e.span() {
            Some(span) => {
                let before = &text.as_bytes()[..span.start.min(text.len())];
                let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
                LoadError::Syntax(format!("line {line}: {msg}"))
            }
            None => LoadError::Syntax(msg),
        }
    })?;
    let mut numbers: Vec<(String, String, f64)> = Vec::new();
    for (section, value) in &table {
        let toml::Value::Table(inner) = value else {
            return Err(LoadError::UnknownKey(section.clone()));
        };
        for (key, v) in inner {
            let path = format!("{section}.{key}");
            if !known(section, key) {
                return Err(LoadError::UnknownKey(path));
            }
            let x = match v {
                toml::Value::Float(x) => *x,
                toml::Value::Integer(i) => *i as f64,
                _ => return Err(LoadError::NotANumber(path)),
            };
            numbers.push((section.clone(), key.clone(), x));
        }
    }
    let raw = RawParams::from_lookup(|s, k| {
        numbers
            .iter()
            .find(|(ns, nk, _)| ns == s && nk == k)
            .map(|(_, _, v)| *v)
    })?;
    Ok(raw)
}

/// Reads and validates a parameter file.
pub fn load(path: &Path) -> Result<RawParams, LoadError> {
    let text = std::fs::read_to_string(path).map_err(|e| LoadError::Io(path.display().to_string(), e))?;
    parse(&text)
}

/// Writes a parameter set back as TOML (core sections, then `[machine]` if
/// present, then the `[estimator]` keys that differ from their defaults).
pub fn to_toml(raw: &RawParams) -> String {
    use crate::{RawCore, RawEstimator, RawMachine};
    let mut out = String::new();
    let mut section = "";
    let mut emit = |out: &mut String, field: &Field, v: f64| {
        if field.section != section {
            if !out.is_empty() {
                out.push('\n');
            }
            out.push_str(&format!("[{}]\n", field.section));
            section = field.section;
        }
        out.push_str(&format!("{} = {}    # {}\n", field.key, fmt_float(v), field.unit));
    };
    // Each field's description paired with its value by name, in file order.
    for (f, n) in RawCore::FIELD.zip(raw.core.named()).into_array() {
        emit(&mut out, &f, n.value);
    }
    if let Some(m) = &raw.machine {
        for (f, n) in RawMachine::FIELD.zip(m.named()).into_array() {
            emit(&mut out, &f, n.value);
        }
    }
    for (f, n) in RawEstimator::FIELD.zip(raw.estimator.named()).into_array() {
        if Some(n.value) != f.default {
            emit(&mut out, &f, n.value);
        }
    }
    out
}

/// Shortest text that reads back as the same `f64`, always with a decimal
/// point or exponent so that TOML keeps it a float.
pub fn fmt_float(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}
