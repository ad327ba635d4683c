//! The temperature envelope of a parameter file, decided once and checked
//! by every command for every temperature it is given (`--temps`,
//! `--from`/`--to`, `--steps`, `--step`, `--t0`, a data file's `t_c`):
//!
//! * **validated**: `[estimator] valid_min ..= valid_max`, the range the
//!   device's figures are promised for; rows there are marked `validated`;
//! * **oil model**: `oil_min ..= oil_max` as far as the fluid model of the
//!   file evaluates there (Walther's law holds down to 2 cSt, so a thin
//!   oil's model may end below `oil_max`: the paper's oil at 105.4 C);
//!   rows there but outside the validated range are computed and marked
//!   `oil_model` (an extrapolation);
//! * **refused** beyond: bad input (exit status 2) naming the argument,
//!   the temperature, the limit and why it lies there.
//!
//! `docs/parameters.md` ("The temperature envelope") says the same for
//! users; this module is the one place the code decides it.

use crate::error::CliError;
use compensator::{Params, RawParams};
use std::fmt;

/// Where a temperature lies in a file's envelope (refused temperatures
/// are errors, not zones).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Zone {
    /// Inside the validated range.
    Validated,
    /// Outside the validated range, inside the oil model's: extrapolated.
    OilModel,
}

impl Zone {
    /// The word of the `envelope` column.
    pub fn word(self) -> &'static str {
        match self {
            Zone::Validated => "validated",
            Zone::OilModel => "oil_model",
        }
    }
}

/// Name of the table column that gives each row's [`Zone`].
pub const ENVELOPE_COLUMN: &str = "envelope";

/// One end of the oil model's range and why it lies there.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// The temperature [C].
    pub t_c: f64,
    /// Why: the file's field (`estimator.oil_max`), or the fluid model's
    /// reason where it ends first (`viscosity below 2 cSt`).
    pub why: String,
}

/// The envelope of one parameter file.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// `estimator.valid_min ..= valid_max` [C].
    pub validated: (f64, f64),
    /// The lower end of the oil model's range.
    pub oil_min: Limit,
    /// The upper end of the oil model's range.
    pub oil_max: Limit,
}

/// A temperature in messages: at most two decimals, no float noise.
pub fn celsius(t: f64) -> String {
    crate::display::short(t, 2)
}

/// The last temperature of `from ..` towards `to` at which `ok` holds,
/// to 1e-3 C (bisection; `ok(from)` holds, `ok(to)` does not).
fn last_ok(ok: impl Fn(f64) -> bool, from: f64, to: f64) -> f64 {
    let (mut good, mut bad) = (from, to);
    while (bad - good).abs() > 1e-3 {
        let mid = 0.5 * (good + bad);
        if ok(mid) { good = mid } else { bad = mid }
    }
    // Rounded towards the inside to 0.1 C, so the limit shown is computed.
    let shown = if to > from {
        (good * 10.0).floor() / 10.0
    } else {
        (good * 10.0).ceil() / 10.0
    };
    if ok(shown) { shown } else { good }
}

impl Envelope {
    /// The envelope of a validated parameter set and its model.
    pub fn of(raw: &RawParams, p: &Params<f64>) -> Envelope {
        let e = &raw.estimator;
        let reason = |t: f64| p.oil.state(t).err().map(|err| err.to_string());
        let inside = 0.5 * (e.valid_min + e.valid_max);
        let limit = |end: f64, field: &str| match reason(end) {
            None => Limit {
                t_c: end,
                why: format!("estimator.{field}"),
            },
            Some(_) if reason(inside).is_some() => Limit {
                t_c: end,
                why: format!("estimator.{field}"),
            },
            Some(_) => {
                let t = last_ok(|t| reason(t).is_none(), inside, end);
                let next = if end > inside { t + 0.1 } else { t - 0.1 };
                let why = reason(next).map_or_else(|| "the fluid model".to_string(), |w| fluid_reason(&w));
                Limit {
                    t_c: t,
                    why: format!("{why}; estimator.{field} = {} C", celsius(end)),
                }
            }
        };
        Envelope {
            validated: (e.valid_min, e.valid_max),
            oil_min: limit(e.oil_min, "oil_min"),
            oil_max: limit(e.oil_max, "oil_max"),
        }
    }

    /// The zone of `t` [C], or why it is refused: `what` names the
    /// argument (`--temps`, `--to`, `row 3, column t_c`).
    ///
    /// # Errors
    ///
    /// [`CliError::Input`] for a temperature outside the oil model's
    /// range, naming `what`, the limit and its reason, and the validated
    /// range.
    pub fn check(&self, t: f64, what: &str) -> Result<Zone, CliError> {
        let (lo, hi) = (&self.oil_min, &self.oil_max);
        let side = if !t.is_finite() {
            return Err(CliError::Input(format!("{what}: {t} C is not a finite temperature")));
        } else if t < lo.t_c {
            Some(("below", lo))
        } else if t > hi.t_c {
            Some(("above", hi))
        } else {
            None
        };
        if let Some((word, limit)) = side {
            return Err(CliError::Input(format!(
                "{what}: {} C is {word} the oil model's range {} ({} C: {}); validated {}",
                celsius(t),
                self.oil_range(),
                celsius(limit.t_c),
                limit.why,
                self.validated_range()
            )));
        }
        Ok(self.zone(t))
    }

    /// The zone of a temperature inside the oil model's range.
    pub fn zone(&self, t: f64) -> Zone {
        if t >= self.validated.0 && t <= self.validated.1 {
            Zone::Validated
        } else {
            Zone::OilModel
        }
    }

    /// `26-78 C`.
    pub fn validated_range(&self) -> String {
        format!("{} to {} C", celsius(self.validated.0), celsius(self.validated.1))
    }

    /// `-20 to 105.4 C`.
    pub fn oil_range(&self) -> String {
        format!("{} to {} C", celsius(self.oil_min.t_c), celsius(self.oil_max.t_c))
    }

    /// Checks every temperature of `list` (`what` names the argument).
    ///
    /// # Errors
    ///
    /// The first refused temperature ([`Envelope::check`]).
    pub fn check_all(&self, list: &[f64], what: &str) -> Result<Vec<Zone>, CliError> {
        list.iter().map(|&t| self.check(t, what)).collect()
    }

    /// Parses a `--temps` list and checks it.
    ///
    /// # Errors
    ///
    /// A list that is not one ([`crate::temps::parse`]), a refused temperature.
    pub fn temps(&self, spec: &str) -> Result<Vec<(f64, Zone)>, CliError> {
        let temps = crate::temps::parse(spec)?;
        let zones = self.check_all(&temps, "--temps")?;
        Ok(temps.into_iter().zip(zones).collect())
    }
}

impl Envelope {
    /// `csv` (a command's table) with an [`ENVELOPE_COLUMN`] giving each
    /// row's zone by the temperatures in `columns` (the farther out of
    /// them), placed before the `error` column. A row without those
    /// temperatures (one that failed) gets an empty cell.
    pub fn mark(&self, csv: &str, columns: &[&str]) -> String {
        let mut lines = csv.lines();
        let Some(header) = lines.next() else {
            return String::new();
        };
        let names: Vec<&str> = header.split(',').collect();
        let at = if names.last() == Some(&crate::csv::ERROR_COLUMN) {
            names.len() - 1
        } else {
            names.len()
        };
        let wanted: Vec<usize> = columns
            .iter()
            .filter_map(|c| names.iter().position(|n| n == c))
            .collect();
        let insert = |line: &str, cell: &str| {
            let mut cells: Vec<&str> = line.split(',').collect();
            cells.insert(at.min(cells.len()), cell);
            cells.join(",")
        };
        let mut out = insert(header, ENVELOPE_COLUMN);
        out.push('\n');
        for line in lines {
            let cells: Vec<&str> = line.split(',').collect();
            let zones: Option<Vec<Zone>> = wanted
                .iter()
                .map(|&i| cells.get(i).and_then(|c| c.parse::<f64>().ok()).map(|t| self.zone(t)))
                .collect();
            let word = match zones {
                Some(z) if !z.is_empty() && z.iter().all(|z| *z == Zone::Validated) => Zone::Validated.word(),
                Some(z) if !z.is_empty() => Zone::OilModel.word(),
                _ => "",
            };
            out.push_str(&insert(line, word));
            out.push('\n');
        }
        out
    }
}

impl fmt::Display for Envelope {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "validated {}; oil model {} (low end: {}, high end: {}); refused outside",
            self.validated_range(),
            self.oil_range(),
            self.oil_min.why,
            self.oil_max.why
        )
    }
}

/// The fluid model's reason as a phrase: `temperature (viscosity below 2
/// cSt)` -> `viscosity below 2 cSt`.
fn fluid_reason(message: &str) -> String {
    match (message.find('('), message.rfind(')')) {
        (Some(a), Some(b)) if b > a => message[a + 1..b].to_string(),
        _ => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> (RawParams, Params<f64>) {
        let raw = crate::params_file::parse(crate::input::PAPER_PRESET).unwrap();
        let p = Params::<f64>::new(&raw).unwrap();
        (raw, p)
    }

    #[test]
    fn the_paper_oil_ends_where_its_viscosity_reaches_2_cst() {
        let (raw, p) = paper();
        let env = Envelope::of(&raw, &p);
        assert_eq!(env.validated, (26.0, 78.0));
        assert_eq!(env.oil_min.t_c, raw.estimator.oil_min);
        assert_eq!(env.oil_min.why, "estimator.oil_min");
        // The fluid model evaluates at the limit and not 0.1 C beyond.
        let hi = env.oil_max.t_c;
        assert!(p.oil.state(hi).is_ok() && p.oil.state(hi + 0.1).is_err(), "{hi}");
        assert!(hi < raw.estimator.oil_max);
        assert!(
            env.oil_max.why.starts_with("viscosity below 2 cSt"),
            "{}",
            env.oil_max.why
        );
        assert_eq!(env.check(50.0, "--temps").unwrap(), Zone::Validated);
        assert_eq!(env.check(90.0, "--temps").unwrap(), Zone::OilModel);
        assert_eq!(env.check(-20.0, "--temps").unwrap(), Zone::OilModel);
        let e = env.check(-30.0, "--temps").unwrap_err().to_string();
        assert!(
            e.starts_with("--temps: -30 C is below the oil model's range -20 to"),
            "{e}"
        );
        let e = env.check(106.0, "--to").unwrap_err().to_string();
        assert!(
            e.contains("106 C is above the oil model's range") && e.contains("viscosity below 2 cSt"),
            "{e}"
        );
        assert!(e.contains("validated 26 to 78 C"), "{e}");
    }
}
