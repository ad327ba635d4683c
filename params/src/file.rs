//! Reading the parameter file (`docs/model.md` section 8) into a validated
//! [`RawParams`], and writing one back.
//!
//! Every key of the file must be known (a typo is an error, not a silently
//! ignored value); numbers may be written as integers or floats; TOML's
//! `nan` and `inf` are read and then rejected by validation with the field's
//! name. Every error is one line of bounded length: echoed input is cut
//! ([`Echo`]), numbers are compact ([`crate::Compact`]).

use crate::{CORE_FIELDS, ESTIMATOR_FIELDS, Echo, Field, MACHINE_FIELDS, ParamError, RawParams};
use std::fmt;
use std::path::Path;

/// Why a parameter file could not be used. `Display` is one line.
#[derive(Debug)]
pub enum LoadError {
    /// The file could not be read.
    Io(String, std::io::Error),
    /// Not valid TOML (`line N: what`; a duplicate key is named).
    Syntax(String),
    /// A key that is not part of the format (`section.key`).
    UnknownKey(String),
    /// A section of the format given as a value (`plunger = 1`), not a table.
    NotASection(String),
    /// A key whose value is not a number.
    NotANumber {
        /// `section.key` of the field.
        field: &'static str,
        /// The TOML type found instead (`"string"`, `"array"`, ...).
        found: &'static str,
    },
    /// A value that breaks a physical rule (names the field).
    Param(ParamError),
}

impl LoadError {
    /// The field of the format (`section.key`) the error is about, if it is
    /// about one: a value that is not a number or breaks a rule.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            LoadError::NotANumber { field, .. } => Some(field),
            LoadError::Param(e) => Some(e.field),
            _ => None,
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Io(path, e) => write!(f, "{}: {}", Echo::tail(path), Echo::head(&e.to_string()).max(160)),
            LoadError::Syntax(msg) => write!(f, "{}", Echo::head(msg).max(200)),
            LoadError::UnknownKey(k) => write!(f, "{}: unknown key", Echo::head(k)),
            LoadError::NotASection(k) => write!(f, "{}: expected a section [{0}], not a value", Echo::head(k)),
            LoadError::NotANumber { field, found } => write!(f, "{field}: expected a number, found a TOML {found}"),
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

/// The field of the format at `section.key`.
fn field(section: &str, key: &str) -> Option<&'static Field> {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .find(|f| f.section == section && f.key == key)
}

fn is_section(name: &str) -> bool {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .any(|f| f.section == name)
}

/// The one-line message of a TOML error: `line N: what`, a duplicate key
/// named (`duplicate key plunger.mass`), echoed input cut.
fn syntax_error(text: &str, e: &toml::de::Error) -> LoadError {
    let msg = e.message().lines().next().unwrap_or("invalid TOML");
    let Some(span) = e.span() else {
        return LoadError::Syntax(Echo::head(msg).max(160).to_string());
    };
    let start = span.start.min(text.len());
    let before = &text.as_bytes()[..start];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    if msg == "duplicate key" {
        let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let this_line = text[line_start..].lines().next().unwrap_or("").trim();
        let key = text.get(span).unwrap_or("").trim();
        if this_line.starts_with('[') {
            return LoadError::Syntax(format!("line {line}: duplicate table {}", Echo::head(this_line)));
        }
        // The table the key is in: the last header above it.
        let table = text[..line_start]
            .lines()
            .rev()
            .map(str::trim)
            .find(|l| l.starts_with('['))
            .map(|h| h.trim_matches(|c| c == '[' || c == ']').trim());
        let path = match table {
            Some(t) => format!("{t}.{key}"),
            None => key.to_string(),
        };
        return LoadError::Syntax(format!("line {line}: duplicate key {}", Echo::head(&path)));
    }
    LoadError::Syntax(format!("line {line}: {}", Echo::head(msg).max(160)))
}

/// Parses parameter-file text.
///
/// # Errors
///
/// [`LoadError::Syntax`] for text that is not TOML, [`LoadError::UnknownKey`]
/// or [`LoadError::NotASection`] for what the format does not have,
/// [`LoadError::NotANumber`] for a field whose value is not a number, and
/// [`LoadError::Param`] for the first field that is missing or breaks its
/// rule ([`RawParams::validate`]).
pub fn parse(text: &str) -> Result<RawParams, LoadError> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| syntax_error(text, &e))?;
    let mut numbers: Vec<(&'static Field, f64)> = Vec::new();
    for (section, value) in &table {
        let toml::Value::Table(inner) = value else {
            return Err(if is_section(section) {
                LoadError::NotASection(section.clone())
            } else {
                LoadError::UnknownKey(section.clone())
            });
        };
        for (key, v) in inner {
            let Some(field) = field(section, key) else {
                return Err(LoadError::UnknownKey(format!("{section}.{key}")));
            };
            let x = match v {
                toml::Value::Float(x) => *x,
                toml::Value::Integer(i) => *i as f64,
                other => {
                    return Err(LoadError::NotANumber {
                        field: field.path,
                        found: other.type_str(),
                    });
                }
            };
            numbers.push((field, x));
        }
    }
    let raw = RawParams::from_lookup(|s, k| {
        numbers
            .iter()
            .find(|(f, _)| f.section == s && f.key == k)
            .map(|(_, v)| *v)
    })?;
    Ok(raw)
}

/// Reads and validates a parameter file.
///
/// # Errors
///
/// [`LoadError::Io`] if the file cannot be read, else as [`parse`].
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
