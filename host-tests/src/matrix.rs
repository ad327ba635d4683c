//! The bad-input matrix of the parameter file: every field of the schema
//! (its field tables, in file order) against every kind of bad value, each
//! case written into `presets/paper.toml` and read by the file reader the
//! CLI and the firmware's build script use; accepted cases go on through
//! the model ([`Params::new`] and the equilibrium at the middle of the
//! validated range, in `f64` and `f32`).
//!
//! A case is right when it is refused naming its own field (the error's
//! field is that field), or accepted with finite results. A value inside
//! the plausible range (the range's ends) may also be refused by a rule
//! between fields, if the message names the field.
//!
//! `docs/parameters.md` holds the field table and the matrix this module
//! writes (`cargo run -p host-tests --example bad_input_matrix -- --write`);
//! `host-tests/tests/bad_input_matrix.rs` checks that every case is right
//! and that the document is current.

use compensator::equilibrium::equilibrium;
use compensator::estimator::{ConfigError, Estimator, EstimatorConfig};
use compensator::params::{
    CORE_FIELDS, Compact, ESTIMATOR_FIELDS, Field, Kind, MACHINE_FIELDS, MONITOR_FIELDS, PROBE_FIELDS, Problem,
    RawParams,
};
use compensator::uncertainty::UncertaintyError;
use compensator::{Float, Params};
use compensator_cli::params_file::{self, LoadError, fmt_float};
use std::fmt::Write as _;

/// Every field of the file, in file order.
pub fn fields() -> impl Iterator<Item = &'static Field> {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .chain(PROBE_FIELDS.iter())
        .chain(MONITOR_FIELDS.iter())
}

/// The standard uncertainty of every field that can have one, as a field
/// of its own: section `tolerances.<section>`, path
/// `tolerances.<section>.<key>`, plausible up to a third of the preset's
/// value ([`compensator::params::RawTolerances::validate`]).
pub fn tolerance_fields() -> Vec<&'static Field> {
    let base = params_file::parse(&base_text()).expect("the preset");
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .map(|f| {
            let value = base
                .core
                .named()
                .into_array()
                .iter()
                .chain(
                    base.machine
                        .iter()
                        .flat_map(|m| m.named().into_array())
                        .collect::<Vec<_>>()
                        .iter(),
                )
                .find(|n| n.path == f.path)
                .map_or(0.0, |n| n.value);
            let field: &'static Field = Box::leak(Box::new(Field {
                section: Box::leak(format!("tolerances.{}", f.section).into_boxed_str()),
                path: f.tolerance_path,
                min: 0.0,
                max: value.abs() / 3.0,
                kind: Kind::Real,
                default: Some(0.0),
                doc: "Standard uncertainty (GUM, one standard deviation).",
                ..*f
            }));
            field
        })
        .collect()
}

/// One kind of input tried on every field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Case {
    /// The key left out.
    Missing,
    /// `-1`.
    Negative,
    /// `0`.
    Zero,
    /// `nan`.
    Nan,
    /// `inf`.
    Inf,
    /// A string.
    Text,
    /// An array.
    Array,
    /// `1e300`.
    Huge,
    /// `5e-324`, the smallest subnormal.
    Tiny,
    /// Just below the plausible range (by a millionth of it).
    Below,
    /// The range's lower end.
    AtMin,
    /// The range's upper end.
    AtMax,
    /// Just above the plausible range.
    Above,
}

impl Case {
    /// Every case, in the matrix's column order.
    pub const ALL: [Case; 13] = [
        Case::Missing,
        Case::Negative,
        Case::Zero,
        Case::Nan,
        Case::Inf,
        Case::Text,
        Case::Array,
        Case::Huge,
        Case::Tiny,
        Case::Below,
        Case::AtMin,
        Case::AtMax,
        Case::Above,
    ];

    /// Column header.
    pub fn header(self) -> &'static str {
        match self {
            Case::Missing => "missing",
            Case::Negative => "-1",
            Case::Zero => "0",
            Case::Nan => "nan",
            Case::Inf => "inf",
            Case::Text => "\"x\"",
            Case::Array => "[1.0]",
            Case::Huge => "1e300",
            Case::Tiny => "5e-324",
            Case::Below => "below",
            Case::AtMin => "min",
            Case::AtMax => "max",
            Case::Above => "above",
        }
    }

    /// Inside the plausible range of `field`: a rule between fields may
    /// refuse it (the range's ends; the text `"x"` for a field that has
    /// the name, `monitor.sensor`'s displacement).
    fn in_range(self, field: &Field) -> bool {
        match self {
            Case::AtMin | Case::AtMax => true,
            Case::Text => matches!(field.kind, Kind::Named(names) if names.contains(&"x")),
            _ => false,
        }
    }

    /// The TOML value written for `field` (`None`: the key left out).
    pub fn value(self, field: &Field) -> Option<String> {
        let below = if field.min == 0.0 && field.max > 0.0 {
            -1e-6 * field.max
        } else if field.min == 0.0 {
            // A range of zero alone (the tolerance of a field whose value
            // is 0): a millionth below it.
            -1e-6
        } else {
            field.min - 1e-6 * field.min.abs()
        };
        if let Kind::Named(names) = field.kind {
            // A named field's range is its names: the first and the last.
            match self {
                Case::AtMin => return names.first().map(|n| format!("\"{n}\"")),
                Case::AtMax => return names.last().map(|n| format!("\"{n}\"")),
                _ => {}
            }
        }
        Some(match self {
            Case::Missing => return None,
            Case::Negative => "-1.0".into(),
            Case::Zero => "0.0".into(),
            Case::Nan => "nan".into(),
            Case::Inf => "inf".into(),
            Case::Text => "\"x\"".into(),
            Case::Array => "[1.0]".into(),
            Case::Huge => "1e300".into(),
            Case::Tiny => "5e-324".into(),
            Case::Below => fmt_float(below),
            Case::AtMin => fmt_float(field.min),
            Case::AtMax => fmt_float(field.max),
            Case::Above if field.max == 0.0 => fmt_float(1e-6),
            Case::Above => fmt_float(field.max + 1e-6 * field.max.abs()),
        })
    }
}

/// The preset every case edits: `presets/paper.toml` (it has a `[machine]`
/// section; `[estimator]` keys are appended).
pub fn base_text() -> String {
    std::fs::read_to_string(crate::repo_root().join("presets/paper.toml")).expect("presets/paper.toml")
}

/// The preset the cases of a `[monitor]` field edit:
/// `presets/paper-monitor.toml` (the paper preset with a chamber pressure
/// transducer), so that the monitor's rules are in force.
pub fn monitor_base_text() -> String {
    std::fs::read_to_string(crate::repo_root().join("presets/paper-monitor.toml")).expect("presets/paper-monitor.toml")
}

/// `text` with `field` set to `value` (its line replaced, added under its
/// section's header, or appended in a section of its own), or left out
/// when `value` is `None`.
pub fn edited(text: &str, field: &Field, value: Option<&str>) -> String {
    let mut out = String::new();
    let mut current = String::new();
    let mut hit = false;
    for line in text.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            current = trimmed.trim_matches(|c| c == '[' || c == ']').to_string();
        }
        let key = trimmed.split('=').next().map(str::trim);
        if current == field.section && key == Some(field.key) && !trimmed.starts_with('#') {
            hit = true;
            if let Some(v) = value {
                let _ = writeln!(out, "{} = {v}", field.key);
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
        if trimmed == format!("[{}]", field.section) && !text_has_key(text, field) {
            if let Some(v) = value {
                let _ = writeln!(out, "{} = {v}", field.key);
            }
            hit = true;
        }
    }
    if !hit && let Some(v) = value {
        let _ = write!(out, "\n[{}]\n{} = {v}\n", field.section, field.key);
    }
    out
}

/// Whether `text` sets `field` in its section.
fn text_has_key(text: &str, field: &Field) -> bool {
    let mut current = "";
    text.lines().map(str::trim).any(|l| {
        if l.starts_with('[') {
            current = l.trim_matches(|c| c == '[' || c == ']');
        }
        current == field.section && !l.starts_with('#') && l.split('=').next().map(str::trim) == Some(field.key)
    })
}

/// What became of one case.
#[derive(Debug)]
pub enum Outcome {
    /// Read, validated and converted; the equilibrium at `t` [C] is finite
    /// in `f64` and `f32`, or not.
    Accepted {
        /// The temperature evaluated (middle of the validated range).
        t: f64,
        /// Whether every result was finite in both types.
        finite: bool,
        /// What failed, if anything did.
        failure: Option<String>,
    },
    /// Refused by the reader, the validation or the conversion.
    Refused(Refusal),
}

/// A refusal: the field the error names (if any), what kind of rule, and
/// the message.
#[derive(Debug)]
pub struct Refusal {
    /// The field the error is about.
    pub field: Option<&'static str>,
    /// Short name of the rule (`range`, `NaN`, `type`, `rule`, ...).
    pub rule: &'static str,
    /// The one-line message.
    pub message: String,
}

impl Refusal {
    fn of_load(e: &LoadError) -> Self {
        let rule = match e {
            LoadError::NotANumber { .. } => "type",
            LoadError::NotAName { .. } => "name",
            LoadError::Param(p) => rule_of(p.problem),
            LoadError::Syntax(_) => "syntax",
            _ => "other",
        };
        Refusal {
            field: e.field(),
            rule,
            message: e.to_string(),
        }
    }
}

fn rule_of(problem: Problem) -> &'static str {
    match problem {
        Problem::Missing => "missing",
        Problem::NotANumber => "NaN",
        Problem::Infinite => "inf",
        Problem::Implausible(_) => "range",
        Problem::NotWhole => "whole",
        Problem::NotOneOf(_) | Problem::NotNamed(_) => "choice",
        Problem::NotRepresentable(_) => "type",
        _ => "rule",
    }
}

/// Runs one case of `field`.
pub fn run(base: &str, field: &Field, case: Case) -> Outcome {
    let text = edited(base, field, case.value(field).as_deref());
    let raw = match params_file::parse(&text) {
        Ok(raw) => raw,
        Err(e) => return Outcome::Refused(Refusal::of_load(&e)),
    };
    if let Err(e) = Params::<f64>::new(&raw) {
        // Refused by the conversion (not expected: the reader validates).
        return Outcome::Refused(Refusal {
            field: Some(e.field),
            rule: rule_of(e.problem),
            message: e.to_string(),
        });
    }
    // A tolerance whose device the model refuses either way: refused by
    // the estimator's construction, naming it (what the CLI, the FMU and
    // the firmware's build script report).
    if let Err(ConfigError::Uncertainty(e @ UncertaintyError::Tolerance(path))) = EstimatorConfig::new(&raw) {
        return Outcome::Refused(Refusal {
            field: Some(path),
            rule: "model",
            message: e.to_string(),
        });
    }
    let t = 0.5 * (raw.estimator.valid_min + raw.estimator.valid_max);
    let failure = evaluate::<f64>(&raw, t)
        .err()
        .or_else(|| evaluate::<f32>(&raw, t).err());
    Outcome::Accepted {
        t,
        finite: failure.is_none(),
        failure,
    }
}

/// The model on an accepted set: conversion, then the equilibrium at `t`,
/// every result finite; and the estimator (its observer designed, its
/// uncertainty table built) through a second of readings at `t`, its
/// estimate and uncertainty finite.
fn evaluate<T: Float>(raw: &RawParams, t: f64) -> Result<(), String> {
    let p = Params::<T>::new(raw).map_err(|e| format!("{}: {e}", T::NAME))?;
    let e = equilibrium(&p, T::from_f64(t)).map_err(|e| format!("{} at {t} C: {e}", T::NAME))?;
    let all = [e.a, e.p_a, e.p_b, e.dp_ab, e.x, e.q_branch, e.q_throt, e.q_total];
    if !all.iter().all(|v| v.is_finite()) {
        return Err(format!("{} at {t} C: not finite: {e:?}", T::NAME));
    }
    let config = EstimatorConfig::new(raw).map_err(|e| format!("estimator: {e}"))?;
    let p32 = Params::<f32>::new(raw).map_err(|e| format!("f32: {e}"))?;
    let mut est = Estimator::new(&p32, config, t as f32).map_err(|e| format!("estimator at {t} C: {e}"))?;
    let every = config.ticks_per(0.02);
    let ticks = config.ticks_per(1.0).min(5_000);
    let mut last = None;
    for k in 0..ticks {
        let reading = if k % every == 0 { Ok(Some(t as f32)) } else { Ok(None) };
        last = Some(est.tick(reading));
    }
    let e = last.ok_or("no tick")?;
    let u = e.uncertainty;
    let bands = [u.t_oil, u.x, u.p_a, u.p_b, u.q_total];
    if e.is_finite() && bands.iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(())
    } else {
        Err(format!("estimator at {t} C: not finite: {e:?}"))
    }
}

/// One cell of the matrix.
#[derive(Debug)]
pub struct Cell {
    /// The field.
    pub field: &'static Field,
    /// The case.
    pub case: Case,
    /// What became of it.
    pub outcome: Outcome,
}

impl Cell {
    /// Whether the outcome is right: refused naming the field (a value
    /// inside the range may be refused by a rule that names it in its
    /// message), or accepted with finite results.
    pub fn is_right(&self) -> bool {
        match &self.outcome {
            Outcome::Accepted { finite, .. } => *finite,
            Outcome::Refused(r) => {
                r.field == Some(self.field.path)
                    || (self.case.in_range(self.field) && r.message.contains(self.field.path))
            }
        }
    }

    /// The cell's text in the table.
    pub fn label(&self) -> String {
        let text = match &self.outcome {
            Outcome::Accepted { .. } if self.case == Case::Missing => "default".to_string(),
            Outcome::Accepted { .. } => "ok".to_string(),
            Outcome::Refused(r) if r.field == Some(self.field.path) => r.rule.to_string(),
            Outcome::Refused(r) => format!("{}: {}", r.rule, r.field.unwrap_or("-")),
        };
        if self.is_right() {
            text
        } else {
            format!("**WRONG** {text}")
        }
    }
}

/// Every field against every case.
pub fn matrix() -> Vec<Cell> {
    cells(fields().collect())
}

/// Every tolerance against every case.
pub fn tolerance_matrix() -> Vec<Cell> {
    cells(tolerance_fields())
}

fn cells(fields: Vec<&'static Field>) -> Vec<Cell> {
    let (paper, monitor) = (base_text(), monitor_base_text());
    fields
        .into_iter()
        .flat_map(|field| {
            let base = if field.section == "monitor" { &monitor } else { &paper };
            Case::ALL.iter().map(move |&case| Cell {
                field,
                case,
                outcome: run(base, field, case),
            })
        })
        .collect()
}

fn escape(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The field table of `docs/parameters.md`: every field with its unit,
/// plausible range, default and description, from the schema.
pub fn field_table() -> String {
    let mut s = String::new();
    s += "| field | unit | plausible range | default | also | description |\n";
    s += "|---|---|---|---|---|---|\n";
    for f in fields() {
        let default = match (f.default, f.kind) {
            (Some(d), Kind::Named(names)) => format!("`\"{}\"`", names.get(d as usize).copied().unwrap_or("?")),
            (Some(d), _) => Compact(d).to_string(),
            (None, _) if f.section == "machine" => "required in `[machine]`".into(),
            (None, _) if f.section == "monitor" => "required with a `sensor`".into(),
            (None, _) => "required".into(),
        };
        let also = match f.kind {
            Kind::Real | Kind::OrZero => String::new(),
            Kind::Whole => "whole number".into(),
            Kind::OneOf(values) => {
                let v: Vec<String> = values.iter().map(|x| Compact(*x).to_string()).collect();
                format!("one of {}", v.join(", "))
            }
            Kind::Named(names) => {
                let v: Vec<String> = names.iter().map(|n| format!("`\"{n}\"`")).collect();
                format!("a name: {}", v.join(", "))
            }
        };
        let range = match f.kind {
            Kind::Named(names) => names
                .iter()
                .map(|n| format!("`\"{n}\"`"))
                .collect::<Vec<_>>()
                .join(", "),
            _ => format!("[{}, {}]", Compact(f.min), Compact(f.max)),
        };
        let range = if f.kind == Kind::OrZero {
            format!("0 or {range}")
        } else {
            range
        };
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {} | {} |",
            f.path,
            escape(f.unit),
            range,
            default,
            also,
            escape(f.doc)
        );
    }
    s
}

/// The matrix of `docs/parameters.md`: one row per field, one column per
/// case, and a summary line.
pub fn matrix_table(cells: &[Cell]) -> String {
    let mut s = String::new();
    s += "| field | range |";
    for case in Case::ALL {
        let _ = write!(s, " {} |", escape(case.header()));
    }
    s += "\n|---|---|";
    s += &"---|".repeat(Case::ALL.len());
    s += "\n";
    for row in cells.chunks(Case::ALL.len()) {
        let f = row[0].field;
        let _ = write!(s, "| `{}` | {} |", f.path, escape(&f.range().to_string()));
        for cell in row {
            let _ = write!(s, " {} |", escape(&cell.label()));
        }
        s += "\n";
    }
    s += "\n";
    s += &summary(cells);
    s += "\n";
    s
}

/// Counts of the matrix: cases, accepted, refused naming the field,
/// in-range values refused by a rule naming the field, wrong.
pub fn summary(cells: &[Cell]) -> String {
    let accepted = cells
        .iter()
        .filter(|c| matches!(c.outcome, Outcome::Accepted { .. }) && c.is_right())
        .count();
    let own = cells
        .iter()
        .filter(|c| matches!(&c.outcome, Outcome::Refused(r) if r.field == Some(c.field.path)))
        .count();
    let by_rule = cells
        .iter()
        .filter(|c| matches!(&c.outcome, Outcome::Refused(r) if r.field != Some(c.field.path)) && c.is_right())
        .count();
    let wrong = cells.iter().filter(|c| !c.is_right()).count();
    format!(
        "{} cases ({} fields x {} inputs): {accepted} accepted with finite results (f64 and f32), \
         {own} refused naming their field, {by_rule} in-range values refused by a rule that names \
         the field in its message, {wrong} wrong.",
        cells.len(),
        cells.len() / Case::ALL.len(),
        Case::ALL.len()
    )
}

/// The generated blocks of `docs/parameters.md`: `(marker, content)`.
pub fn generated_blocks() -> [(&'static str, String); 3] {
    [
        ("fields", field_table()),
        ("matrix", matrix_table(&matrix())),
        ("tolerances", matrix_table(&tolerance_matrix())),
    ]
}

/// `doc` with the content between `<!-- BEGIN GENERATED: name -->` and
/// `<!-- END GENERATED: name -->` replaced for every block, or `None` if a
/// marker is missing.
pub fn with_blocks(doc: &str, blocks: &[(&str, String)]) -> Option<String> {
    let mut out = doc.to_string();
    for (name, content) in blocks {
        let begin = format!("<!-- BEGIN GENERATED: {name} -->\n");
        let end = format!("<!-- END GENERATED: {name} -->");
        let a = out.find(&begin)? + begin.len();
        let b = a + out[a..].find(&end)?;
        out.replace_range(a..b, content);
    }
    Some(out)
}
