//! Reading the parameter file (`docs/model.md` section 8) into a validated
//! [`RawParams`], and writing one back.
//!
//! Every key of the file must be known (a typo is an error, not a silently
//! ignored value); numbers may be written as integers or floats; TOML's
//! `nan` and `inf` are read and then rejected by validation with the field's
//! name. Every error is one line of bounded length: echoed input is cut
//! ([`Echo`]), numbers are compact ([`crate::Compact`]).

use crate::{CORE_FIELDS, Echo, Field, MACHINE_FIELDS, ParamError, RawParams, RawTolerances, all_fields};
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
    /// A key whose value must be one of a few names (a TOML string, such
    /// as `sensor = "ntc"`) and is not.
    NotAName {
        /// `section.key` of the field.
        field: &'static str,
        /// The names it accepts.
        names: &'static [&'static str],
    },
    /// A value that breaks a physical rule (names the field).
    Param(ParamError),
    /// A `[[correlation]]` table that cannot be read (says which and why).
    Correlation(String),
}

impl LoadError {
    /// The field of the format (`section.key`) the error is about, if it is
    /// about one: a value that is not a number or breaks a rule.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            LoadError::NotANumber { field, .. } | LoadError::NotAName { field, .. } => Some(field),
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
            LoadError::UnknownKey(k) => write!(f, "{}: unknown key{}", Echo::head(k), did_you_mean(k)),
            LoadError::NotASection(k) => write!(f, "{}: expected a section [{0}], not a value", Echo::head(k)),
            LoadError::NotANumber { field, found } => write!(f, "{field}: expected a number, found a TOML {found}"),
            LoadError::NotAName { field, names } => {
                write!(f, "{field}: expected ")?;
                for (i, n) in names.iter().enumerate() {
                    match i {
                        0 => {}
                        i if i + 1 == names.len() => f.write_str(" or ")?,
                        _ => f.write_str(", ")?,
                    }
                    write!(f, "\"{n}\"")?;
                }
                Ok(())
            }
            LoadError::Param(e) => write!(f, "{e}"),
            LoadError::Correlation(msg) => write!(f, "{}", Echo::head(msg).max(240)),
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
    all_fields().find(|f| f.section == section && f.key == key)
}

fn is_section(name: &str) -> bool {
    all_fields().any(|f| f.section == name)
}

/// The field that can carry a tolerance at `section.key` (the compensator's
/// and the machine's).
fn uncertain_field(section: &str, key: &str) -> Option<&'static Field> {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .find(|f| f.section == section && f.key == key)
}

/// The section of the standard uncertainties.
const TOLERANCES: &str = "tolerances";
/// The array of tables declaring correlations.
const CORRELATION: &str = "correlation";

/// A TOML number as `f64`, else what it is.
fn number(v: &toml::Value) -> Result<f64, &'static str> {
    match v {
        toml::Value::Float(x) => Ok(*x),
        toml::Value::Integer(i) => Ok(*i as f64),
        other => Err(other.type_str()),
    }
}

/// Reads `[tolerances]` (tables keyed like the sections: `[tolerances]
/// plunger.spring_rate = 700.0` or `[tolerances.plunger] spring_rate =
/// 700.0`) into `tol`.
fn read_tolerances(value: &toml::Value, tol: &mut RawTolerances) -> Result<(), LoadError> {
    let toml::Value::Table(sections) = value else {
        return Err(LoadError::NotASection(TOLERANCES.to_string()));
    };
    for (section, inner) in sections {
        let toml::Value::Table(inner) = inner else {
            return Err(LoadError::UnknownKey(format!("{TOLERANCES}.{section}")));
        };
        for (key, v) in inner {
            let Some(field) = uncertain_field(section, key) else {
                return Err(LoadError::UnknownKey(format!("{TOLERANCES}.{section}.{key}")));
            };
            let sigma = number(v).map_err(|found| LoadError::NotANumber {
                field: field.tolerance_path,
                found,
            })?;
            if let Some(slot) = tol.get_mut(field.path) {
                *slot = sigma;
            }
        }
    }
    Ok(())
}

/// Reads the `[[correlation]]` tables (`fields = ["fluid.walther_a",
/// "fluid.walther_b"]`, `coefficient = -0.99`) into `tol`.
fn read_correlations(value: &toml::Value, tol: &mut RawTolerances) -> Result<(), LoadError> {
    let toml::Value::Array(tables) = value else {
        return Err(LoadError::Correlation(
            "correlation: expected [[correlation]] tables with fields = [\"a\", \"b\"] and coefficient = r".into(),
        ));
    };
    for (i, t) in tables.iter().enumerate() {
        let n = i + 1;
        let toml::Value::Table(t) = t else {
            return Err(LoadError::Correlation(format!("correlation {n}: expected a table")));
        };
        if let Some(k) = t.keys().find(|k| *k != "fields" && *k != "coefficient") {
            return Err(LoadError::UnknownKey(format!("{CORRELATION}.{}", Echo::head(k))));
        }
        let names: Vec<&str> = match t.get("fields") {
            Some(toml::Value::Array(a)) => a.iter().filter_map(|v| v.as_str()).collect(),
            _ => Vec::new(),
        };
        let [a, b] = names[..] else {
            return Err(LoadError::Correlation(format!(
                "correlation {n}: fields must name two fields, fields = [\"section.key\", \"section.key\"]"
            )));
        };
        let known = |name: &str| {
            name.split_once('.')
                .and_then(|(s, k)| uncertain_field(s, k))
                .ok_or_else(|| {
                    LoadError::Correlation(format!(
                        "correlation {n}: {}: not a field with a tolerance",
                        Echo::head(name)
                    ))
                })
        };
        let (fa, fb) = (known(a)?, known(b)?);
        let r = match t.get("coefficient") {
            Some(v) => number(v).map_err(|found| {
                LoadError::Correlation(format!(
                    "correlation {n}: coefficient: expected a number, found a TOML {found}"
                ))
            })?,
            None => return Err(LoadError::Correlation(format!("correlation {n}: coefficient: missing"))),
        };
        tol.push_correlation(fa.path, fb.path, r)?;
    }
    Ok(())
}

/// The declared correlations must form a positive semi-definite matrix (a
/// covariance some device population can have): a Cholesky factorisation
/// of the correlation matrix over the fields they name, with a pivot
/// tolerance of 1e-9.
fn check_correlation_matrix(tol: &RawTolerances) -> Result<(), LoadError> {
    let mut names: Vec<&'static str> = Vec::new();
    for c in tol.correlations() {
        for name in [c.a, c.b] {
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    let n = names.len();
    let mut l = vec![0.0f64; n * n];
    for j in 0..n {
        let mut d = 1.0 - (0..j).map(|k| l[j * n + k] * l[j * n + k]).sum::<f64>();
        if d < -1e-9 {
            return Err(LoadError::Correlation(format!(
                "the correlations involving {} are not a valid correlation matrix (not positive semi-definite)",
                names[j]
            )));
        }
        d = d.max(0.0).sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let r = tol.correlation(names[i], names[j]);
            let s = r - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            l[i * n + j] = if d > 1e-12 { s / d } else { 0.0 };
        }
    }
    Ok(())
}

/// The candidate nearest to `input` by edit distance (Damerau-Levenshtein,
/// `strsim`), if it is near enough to be a misspelling: at most a third of
/// the longer name's characters differ (at least one edit allowed); none
/// for an input longer than [`crate::ECHO_MAX`].
fn nearest<'c>(input: &str, candidates: impl Iterator<Item = &'c str>) -> Option<&'c str> {
    // No name of the format is near a long input (and the distance costs
    // the product of the lengths).
    if input.len() > crate::ECHO_MAX {
        return None;
    }
    candidates
        .map(|c| (strsim::damerau_levenshtein(input, c), c))
        .filter(|&(d, c)| d > 0 && d <= (input.chars().count().max(c.chars().count()) / 3).max(1))
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// The valid `section.key` nearest to a misspelt one (`plunger.sping_rate`
/// -> `plunger.spring_rate`, `plungr.mass` -> `plunger.mass`, and a key in
/// the wrong section: `plunger.bulk_modulus` -> `fluid.bulk_modulus`), if
/// one is near enough to be meant.
pub fn nearest_path(path: &str) -> Option<&'static str> {
    let Some((section, key)) = path.split_once('.') else {
        return nearest(path, all_fields().map(|f| f.path));
    };
    // A key only one section has, in the wrong or a misspelt section.
    let mut with_key = all_fields().filter(|f| f.key == key);
    if let (Some(f), None) = (with_key.next(), with_key.next()) {
        return Some(f.path);
    }
    let in_section = |s: &'static str| all_fields().filter(move |f| f.section == s);
    let section = if is_section(section) {
        all_fields().find(|f| f.section == section).map(|f| f.section)?
    } else {
        nearest(section, all_fields().map(|f| f.section))?
    };
    // The key as given, or the nearest one, in the (nearest) section.
    let keys = in_section(section).map(|f| f.key);
    let key = in_section(section)
        .find(|f| f.key == key)
        .map(|f| f.key)
        .or_else(|| nearest(key, keys))?;
    field(section, key).map(|f| f.path)
}

/// What a key the format does not have most likely means: a section name
/// (`[plungr]`: `[plunger]`) or a field (`nearest_path`), as the end of a
/// message (`; did you mean [plunger]?`), or nothing.
fn did_you_mean(path: &str) -> String {
    // A tolerance is keyed like the field it belongs to.
    if let Some(rest) = path.strip_prefix("tolerances.") {
        return nearest_path(rest)
            .filter(|p| p.split_once('.').is_some_and(|(s, k)| uncertain_field(s, k).is_some()))
            .map_or(String::new(), |p| format!("; did you mean tolerances.{p}?"));
    }
    let (section, key) = path.split_once('.').unwrap_or((path, ""));
    if !is_section(section) {
        let sections = all_fields().map(|f| f.section);
        if let Some(s) = nearest(section, sections) {
            return format!("; did you mean [{s}]?");
        }
    }
    if key.is_empty() {
        return String::new();
    }
    nearest_path(path).map_or(String::new(), |p| format!("; did you mean {p}?"))
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
/// [`LoadError::NotANumber`] for a field whose value is not a number,
/// [`LoadError::NotAName`] for one whose value is not one of its names, and
/// [`LoadError::Param`] for the first field that is missing or breaks its
/// rule ([`RawParams::validate`]).
pub fn parse(text: &str) -> Result<RawParams, LoadError> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| syntax_error(text, &e))?;
    let mut numbers: Vec<(&'static Field, f64)> = Vec::new();
    let mut tolerances = RawTolerances::NONE;
    for (section, value) in &table {
        if section == TOLERANCES {
            read_tolerances(value, &mut tolerances)?;
            continue;
        }
        if section == CORRELATION {
            read_correlations(value, &mut tolerances)?;
            continue;
        }
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
            if let crate::Kind::Named(names) = field.kind {
                // A name: its place in the list.
                let place = v.as_str().and_then(|name| names.iter().position(|n| *n == name));
                let Some(i) = place else {
                    return Err(LoadError::NotAName {
                        field: field.path,
                        names,
                    });
                };
                numbers.push((field, i as f64));
                continue;
            }
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
    let mut raw = RawParams::from_lookup(|s, k| {
        numbers
            .iter()
            .find(|(f, _)| f.section == s && f.key == k)
            .map(|(_, v)| *v)
    })?;
    raw.tolerances = tolerances;
    raw.tolerances.validate(&raw.core, raw.machine.as_ref())?;
    check_correlation_matrix(&raw.tolerances)?;
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
/// present, then the `[estimator]`, `[probe]` and `[monitor]` keys that
/// differ from their defaults).
pub fn to_toml(raw: &RawParams) -> String {
    use crate::{RawCore, RawEstimator, RawMachine, RawMonitor, RawProbe};
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
        match field.kind {
            crate::Kind::Named(names) => {
                let name = names.get(v as usize).copied().unwrap_or("?");
                out.push_str(&format!("{} = \"{name}\"\n", field.key));
            }
            _ => out.push_str(&format!("{} = {}    # {}\n", field.key, fmt_float(v), field.unit)),
        }
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
    for (f, n) in RawProbe::FIELD.zip(raw.probe.named()).into_array() {
        if Some(n.value) != f.default {
            emit(&mut out, &f, n.value);
        }
    }
    // The monitor's required keys read as 0 without a sensor.
    let sensor = raw.monitor.has_sensor();
    for (f, n) in RawMonitor::FIELD.zip(raw.monitor.named()).into_array() {
        let default = f.default.or(if sensor { None } else { Some(0.0) });
        if Some(n.value) != default {
            emit(&mut out, &f, n.value);
        }
    }
    let tol = &raw.tolerances;
    let sigmas = CORE_FIELDS
        .iter()
        .zip(tol.core.into_array())
        .chain(MACHINE_FIELDS.iter().zip(tol.machine.into_array()));
    let mut first = true;
    for (f, sigma) in sigmas.filter(|(_, s)| *s != 0.0) {
        if first {
            out.push_str("\n[tolerances]    # standard uncertainties (GUM, one standard deviation)\n");
            first = false;
        }
        out.push_str(&format!("{} = {}    # {}\n", f.path, fmt_float(sigma), f.unit));
    }
    for c in tol.correlations() {
        out.push_str(&format!(
            "\n[[correlation]]\nfields = [\"{}\", \"{}\"]\ncoefficient = {}\n",
            c.a,
            c.b,
            fmt_float(c.coefficient)
        ));
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
