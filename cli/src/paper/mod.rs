//! The paper report (`compensator paper`): the paper's tables reproduced
//! by a parameter set, and the other findings of the project's README,
//! computed and rendered as text.
//!
//! [`tables`] holds the published data; the findings computed here are
//! [`asymptotic_search`] (which expansion the "asymptotic" column of
//! Table 2 is) and [`chamber_gradient`] (the chamber-pressure gradient of
//! Eq. 1). [`report`] renders them with Table 1's inversion, both tables'
//! residuals and the Eq. (32) verdict.

pub mod tables;

use crate::error::CliError;
use crate::lsq::{max_abs, rms};
use crate::statics::find_balance;
use compensator::asymptotic::{Expansion, Reading, monotonicity};
use compensator::equilibrium::equilibrium;
use compensator::{Params, RawParams};
use std::fmt::Write as _;
use std::path::Path;
use tables::{BAR, Table1, Table2, invert_table1, load_tables, table1_residuals, table2_residuals};

/// One candidate of [`asymptotic_search`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsymptoticMatch {
    /// Reading of the expansion.
    pub reading: Reading,
    /// Order (1 or 2).
    pub order: usize,
    /// Reference temperature [C].
    pub t0: f64,
    /// RMS of (clamped series - Table 2 asym) [mm].
    pub rms_mm: f64,
    /// Largest absolute difference [mm].
    pub max_mm: f64,
}

/// Errors of one expansion against Table 2's asymptotic column [mm].
pub fn asymptotic_errors(
    params: &Params<f64>,
    t2: &Table2,
    reading: Reading,
    order: usize,
    t0: f64,
) -> Option<Vec<f64>> {
    let e = Expansion::new(params, t0, reading).ok()?;
    t2.temps
        .iter()
        .zip(&t2.x_asym_mm)
        .map(|(&t, &x)| e.at(t).ok().map(|terms| terms.x(order).0 * 1e3 - x))
        .collect()
}

/// For each reading and order 1, 2: the reference temperature on a 0.1 C
/// grid over `[t_lo, t_hi]` that best reproduces Table 2's asymptotic
/// column, plus the result at the balance temperature `balance` (if any,
/// from `statics::find_balance`) for comparison.
/// Returns (best per reading and order, balance-temperature results).
pub fn asymptotic_search(
    params: &Params<f64>,
    t2: &Table2,
    t_lo: f64,
    t_hi: f64,
    balance: Option<f64>,
) -> (Vec<AsymptoticMatch>, Vec<AsymptoticMatch>) {
    let mut best = Vec::new();
    let mut at_balance = Vec::new();
    for reading in [Reading::Temperature, Reading::Property] {
        for order in [1, 2] {
            let score = |t0: f64| {
                asymptotic_errors(params, t2, reading, order, t0).map(|e| AsymptoticMatch {
                    reading,
                    order,
                    t0,
                    rms_mm: rms(&e),
                    max_mm: max_abs(&e),
                })
            };
            let n = ((t_hi - t_lo) / 0.1).round() as usize;
            let found = (0..=n)
                .filter_map(|i| score(t_lo + 0.1 * i as f64))
                .min_by(|a, b| a.rms_mm.total_cmp(&b.rms_mm));
            best.extend(found);
            if let Some(tb) = balance {
                at_balance.extend(score(tb));
            }
        }
    }
    (best, at_balance)
}

/// Chamber-pressure gradient of Eq. (1) over `[lo, hi]` at drop `dp` [Pa]:
/// (mean |dp_a/dt|, max |dp_a/dt|, mean |dp_b/dt|) [Pa/K], from the
/// equilibrium's closed form at 0.5 C spacing (central differences).
pub fn chamber_gradient(params: &Params<f64>, dp: f64, lo: f64, hi: f64) -> Result<(f64, f64, f64), String> {
    let p = params.with_pressure_drop(dp).map_err(|e| e.to_string())?;
    let h = 0.5;
    let n = ((hi - lo) / h).round() as usize;
    let (mut sum_a, mut max_a, mut sum_b) = (0.0, 0.0f64, 0.0);
    for i in 0..n {
        let (t, tn) = (lo + h * i as f64, lo + h * (i + 1) as f64);
        let (e0, e1) = (
            equilibrium(&p, t).map_err(|e| e.to_string())?,
            equilibrium(&p, tn).map_err(|e| e.to_string())?,
        );
        let ga = ((e1.p_a - e0.p_a) / h).abs();
        sum_a += ga;
        max_a = max_a.max(ga);
        sum_b += ((e1.p_b - e0.p_b) / h).abs();
    }
    Ok((sum_a / n as f64, max_a, sum_b / n as f64))
}

/// `paper`: the findings of the README, recomputed, with the parameter
/// file `path` and the tables in `data` (without them: the built-in
/// `presets/paper.toml` and `data/paper/`).
pub fn report(path: Option<&Path>, data: Option<&Path>) -> Result<String, CliError> {
    let (raw, p) = crate::input::load_or_paper(path)?;
    let (t1, t2) = load_tables(data).map_err(CliError::Input)?;
    let mut o = String::new();
    let shown = path.map_or("presets/paper.toml".into(), |p| p.display().to_string());
    let _ = writeln!(o, "# Paper reproduction with {shown}");
    table1_inverted(&mut o, &t1);
    table1_section(&mut o, &p, &t1);
    table2_section(&mut o, &p, &t2);
    asym_section(&mut o, &raw, &p, &t2);
    gradient_section(&mut o, &p)?;
    monotonicity_section(&mut o, &p)?;
    Ok(o)
}

/// Table 1 inverted for `A(t)`, column by column, with the spread between the drops.
fn table1_inverted(o: &mut String, t1: &Table1) {
    let inv = invert_table1(t1);
    let _ = writeln!(o, "\n## Table 1 inverted for A(t) [sqrt(Pa)], column by column");
    let _ = writeln!(
        o,
        "t_c  {}  spread",
        t1.drops_bar
            .iter()
            .map(|d| format!("A({d} bar)"))
            .collect::<Vec<_>>()
            .join("  ")
    );
    for (i, t) in t1.temps.iter().enumerate() {
        let cols: Vec<String> = inv.a[i].iter().map(|a| format!("{a:9.1}")).collect();
        let _ = writeln!(o, "{t:4}  {}  {:5.1} %", cols.join("  "), inv.spread[i] * 100.0);
    }
    let max_spread = inv.spread.iter().fold(0.0f64, |m, v| m.max(*v));
    let _ = writeln!(o, "largest spread between the three drops: {:.1} %", max_spread * 100.0);
}

/// Table 1: the model's `p_b - p_a` beside the paper's, with the residuals.
fn table1_section(o: &mut String, p: &Params<f64>, t1: &Table1) {
    let r1 = table1_residuals(p, t1);
    let _ = writeln!(o, "\n## Table 1: model p_b - p_a against the paper [bar]");
    let _ = writeln!(
        o,
        "t_c  {}",
        t1.drops_bar
            .iter()
            .map(|d| format!("{d} bar: paper model"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let nd = t1.drops_bar.len();
    for (i, t) in t1.temps.iter().enumerate() {
        let cols: Vec<String> = (0..nd)
            .map(|j| format!("{:5.2} {:6.3}", t1.values[i][j], t1.values[i][j] + r1[i * nd + j]))
            .collect();
        let _ = writeln!(o, "{t:4}  {}", cols.join(" | "));
    }
    let _ = writeln!(
        o,
        "RMS {:.4} bar, max {:.4} bar over {} points",
        rms(&r1),
        max_abs(&r1),
        r1.len()
    );
}

/// Table 2: the model's quasi-static displacement beside the paper's.
fn table2_section(o: &mut String, p: &Params<f64>, t2: &Table2) {
    let r2 = table2_residuals(p, t2);
    let _ = writeln!(
        o,
        "\n## Table 2: quasi-static displacement at {} bar [mm]",
        p.pressure_drop / BAR
    );
    for (i, t) in t2.temps.iter().enumerate() {
        let _ = writeln!(
            o,
            "{t:4}  paper {:5.2}  model {:7.4}",
            t2.x_qs_mm[i],
            t2.x_qs_mm[i] + r2[i]
        );
    }
    let _ = writeln!(o, "RMS {:.4} mm, max {:.4} mm", rms(&r2), max_abs(&r2));
}

/// Table 2's "asym" column: which expansion (reading, order, `t0`) reproduces it best, and each at the balance temperature.
fn asym_section(o: &mut String, raw: &RawParams, p: &Params<f64>, t2: &Table2) {
    let balance = find_balance(raw, p).ok();
    let (best, at_balance) = asymptotic_search(p, t2, 26.0, 80.0, balance);
    let _ = writeln!(o, "\n## Table 2 \"asym\" column: which expansion reproduces it");
    if let Some(tb) = balance {
        let _ = writeln!(o, "balance temperature (p_a = p_b, Eq. 2): {tb:.2} C");
    }
    let name = |r: Reading| match r {
        Reading::Temperature => "temperature",
        Reading::Property => "property",
    };
    for m in &best {
        let _ = writeln!(
            o,
            "best t0 for {:11} reading, order {}: t0 = {:5.1} C, RMS {:.4} mm, max {:.4} mm",
            name(m.reading),
            m.order,
            m.t0,
            m.rms_mm,
            m.max_mm
        );
    }
    for m in &at_balance {
        let _ = writeln!(
            o,
            "at the balance temperature, {:11} reading, order {}: RMS {:.4} mm, max {:.4} mm",
            name(m.reading),
            m.order,
            m.rms_mm,
            m.max_mm
        );
    }
    if let Some(b) = best.iter().min_by(|a, b| a.rms_mm.total_cmp(&b.rms_mm)) {
        let _ = writeln!(
            o,
            "=> closest: {} reading, order {}, t0 = {:.1} C (RMS {:.4} mm)",
            name(b.reading),
            b.order,
            b.t0,
            b.rms_mm
        );
    }
}

/// Eq. (1): the chamber-pressure gradient at 0.2 MPa against the paper's, and its bound.
fn gradient_section(o: &mut String, p: &Params<f64>) -> Result<(), CliError> {
    let _ = writeln!(
        o,
        "\n## Eq. (1): chamber-pressure gradient at dp = 0.2 MPa over 26-78 C"
    );
    let (mean_a, max_a, mean_b) = chamber_gradient(p, 2.0e5, 26.0, 78.0).map_err(CliError::Failed)?;
    let _ = writeln!(
        o,
        "model: mean |dp_a/dt| {:.2} kPa/C (max {:.2}), mean |dp_b/dt| {:.2} kPa/C; paper: 8.3 kPa/C",
        mean_a / 1e3,
        max_a / 1e3,
        mean_b / 1e3
    );
    let _ = writeln!(
        o,
        "bound: a chamber pressure stays within [p_c, p_p], so over 52 C its mean gradient cannot exceed {:.2} kPa/C at 0.2 MPa",
        2.0e5 / 52.0 / 1e3
    );
    Ok(())
}

/// Eq. (32) over 26-78 C.
fn monotonicity_section(o: &mut String, p: &Params<f64>) -> Result<(), CliError> {
    let mono = monotonicity(p, 26.0, 78.0, 521).map_err(|e| CliError::Failed(e.to_string()))?;
    let _ = writeln!(
        o,
        "\n## Eq. (32) over 26-78 C: monotonic = {}, smallest |dx/dt| = {:.3e} m/K at {:.1} C",
        mono.monotonic, mono.worst_dx_dt, mono.worst_temperature
    );
    Ok(())
}
