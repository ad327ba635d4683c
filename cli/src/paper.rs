//! The paper's tables, and the calibration that reproduces them.
//!
//! * [`Table1`]: `p_b - p_a` [bar] at 30-80 C for dp = 4, 5, 6 bar.
//! * [`Table2`]: quasi-static and "asymptotic" displacement [mm] at 30-80 C.
//!
//! [`calibrate`] keeps a base parameter set's geometry and fits
//! 1. the oil (Walther `a`, `b`) and the geometry factor `G` of
//!    `A = G nu sqrt(rho)` to all 18 points of Table 1 (`G` becomes the
//!    capillary length), then
//! 2. the spring rate and preload (`A_p / c` and `x0`) to Table 2's
//!    quasi-static column at 4 bar.
//!
//! [`invert_table1`], [`asymptotic_search`] and [`chamber_gradient`] are the
//! other findings of the project's README.

use crate::csv;
use crate::lsq::{Fit, levenberg_marquardt, rms};
use compensator::Params;
use compensator::asymptotic::{Expansion, Reading};
use compensator::equilibrium::{equilibrium, pressure_difference};
use compensator::params::{RawCore, RawParams};
use std::path::Path;

/// One bar in pascals.
pub const BAR: f64 = 1.0e5;

/// Table 1: `p_b - p_a` [bar] by temperature and pressure drop.
#[derive(Debug, Clone, PartialEq)]
pub struct Table1 {
    /// Temperatures [C].
    pub temps: Vec<f64>,
    /// Pressure drops [bar] of the columns.
    pub drops_bar: Vec<f64>,
    /// `values[i][j]`: at `temps[i]`, drop `drops_bar[j]` [bar].
    pub values: Vec<Vec<f64>>,
}

/// Table 2: displacements [mm].
#[derive(Debug, Clone, PartialEq)]
pub struct Table2 {
    /// Temperatures [C].
    pub temps: Vec<f64>,
    /// Quasi-static column [mm].
    pub x_qs_mm: Vec<f64>,
    /// "Asymptotic" column [mm].
    pub x_asym_mm: Vec<f64>,
}

/// A table of finite numbers whose first column is `t_c`, with at least two
/// rows (the fits and the Walther start need two temperatures).
fn read(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (header, rows) = csv::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if header.first().map(String::as_str) != Some("t_c") {
        return Err(format!("{}: the first column must be t_c", path.display()));
    }
    if rows.len() < 2 {
        return Err(format!(
            "{}: at least two rows needed, found {}",
            path.display(),
            rows.len()
        ));
    }
    if let Some(i) = rows.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
        return Err(format!("{}: row {}: not a finite number", path.display(), i + 1));
    }
    Ok((header, rows))
}

impl Table1 {
    /// Reads `t_c,dp_ab_<N>bar,...`.
    pub fn load(path: &Path) -> Result<Self, String> {
        let (header, rows) = read(path)?;
        if header.len() < 2 {
            return Err(format!("{}: no dp_ab_<N>bar column", path.display()));
        }
        let drops_bar = header[1..]
            .iter()
            .map(|h| {
                h.strip_prefix("dp_ab_")
                    .and_then(|s| s.strip_suffix("bar"))
                    .and_then(|s| s.parse::<f64>().ok())
                    .ok_or_else(|| format!("{}: column '{h}' is not dp_ab_<N>bar", path.display()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Table1 {
            temps: rows.iter().map(|r| r[0]).collect(),
            drops_bar,
            values: rows.iter().map(|r| r[1..].to_vec()).collect(),
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.temps.len() * self.drops_bar.len()
    }

    /// `true` without points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Table2 {
    /// Reads `t_c,x_qs_mm,x_asym_mm,...`.
    pub fn load(path: &Path) -> Result<Self, String> {
        let (header, rows) = read(path)?;
        let col = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| format!("{}: no column {name}", path.display()))
        };
        let (qs, asym) = (col("x_qs_mm")?, col("x_asym_mm")?);
        Ok(Table2 {
            temps: rows.iter().map(|r| r[0]).collect(),
            x_qs_mm: rows.iter().map(|r| r[qs]).collect(),
            x_asym_mm: rows.iter().map(|r| r[asym]).collect(),
        })
    }
}

/// The tables shipped in `data/paper/`, found from the workspace root.
pub fn paper_tables(root: &Path) -> Result<(Table1, Table2), String> {
    let dir = root.join("data").join("paper");
    Ok((
        Table1::load(&dir.join("table1.csv"))?,
        Table2::load(&dir.join("table2.csv"))?,
    ))
}

/// Model residuals against Table 1 [bar], row by row (temperature-major).
/// A point the model cannot evaluate gives an infinite residual.
pub fn table1_residuals(params: &Params<f64>, t1: &Table1) -> Vec<f64> {
    let mut r = Vec::with_capacity(t1.len());
    for (i, &t) in t1.temps.iter().enumerate() {
        let fluid = params.oil.state(t);
        for (j, &dp) in t1.drops_bar.iter().enumerate() {
            let model = match fluid {
                Ok(f) => pressure_difference(compensator::equilibrium::a_parameter(params, &f), dp * BAR) / BAR,
                Err(_) => f64::INFINITY,
            };
            r.push(model - t1.values[i][j]);
        }
    }
    r
}

/// Model residuals against Table 2's quasi-static column [mm] at the
/// parameter set's own pressure drop.
pub fn table2_residuals(params: &Params<f64>, t2: &Table2) -> Vec<f64> {
    t2.temps
        .iter()
        .zip(&t2.x_qs_mm)
        .map(|(&t, &x)| match equilibrium(params, t) {
            Ok(e) => e.x * 1e3 - x,
            Err(_) => f64::INFINITY,
        })
        .collect()
}

/// Capillary length that gives geometry factor `g` with the base's other
/// throttle dimensions: `L = G pi d_l^4 / (128 sqrt(2) C_d f)`.
fn capillary_length_for(base: &RawCore, g: f64) -> f64 {
    let f = std::f64::consts::FRAC_PI_4 * base.turbulent_diameter.powi(2);
    g * std::f64::consts::PI * base.laminar_diameter.powi(4)
        / (128.0 * std::f64::consts::SQRT_2 * base.turbulent_discharge * f)
}

fn params_of(core: &RawCore) -> Option<Params<f64>> {
    Params::<f64>::from_core(core, None).ok()
}

/// Outcome of [`calibrate`].
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The calibrated parameter set (base with fitted fields).
    pub params: RawParams,
    /// Table 1 fit (Walther a, b, log10 G) and its residuals [bar].
    pub table1: Fit,
    /// Table 2 fit (A_p / c in 1e-9 m/Pa, x0 in 1e-5 m) and its residuals [mm].
    pub table2: Fit,
}

/// Fits the base parameter set to Tables 1 and 2 (see the module docs).
pub fn calibrate(base: &RawParams, t1: &Table1, t2: &Table2) -> Result<Calibration, String> {
    let start = params_of(&base.core).ok_or("base parameters are not valid")?;
    let g0 = compensator::equilibrium::geometry_factor(&start);
    let with_fluid = |p: &[f64]| {
        let mut c = base.core;
        c.walther_a = p[0];
        c.walther_b = p[1];
        c.laminar_length = capillary_length_for(&base.core, 10f64.powf(p[2]));
        c
    };
    // Start from an oil whose A(t) crosses the data: invert the 4 bar
    // column's end points for nu and solve Walther's two constants.
    let x0 = initial_walther(base, t1, g0).unwrap_or([base.core.walther_a, base.core.walther_b]);
    let fit1 = levenberg_marquardt(
        |p| match params_of(&with_fluid(p)) {
            Some(params) => table1_residuals(&params, t1),
            None => vec![f64::INFINITY; t1.len()],
        },
        &[x0[0], x0[1], g0.log10()],
        &[1e-7, 1e-7, 1e-7],
        500,
    );
    if !fit1.rms().is_finite() {
        return Err("Table 1 fit failed: the model cannot be evaluated at the table's temperatures".into());
    }
    let fluid_core = with_fluid(&fit1.x);
    let area = std::f64::consts::FRAC_PI_4 * base.core.plunger_diameter.powi(2);
    let with_spring = |p: &[f64]| {
        let mut c = fluid_core;
        c.spring_rate = area / (p[0] * 1e-9);
        c.preload = (p[1] * 1e-5).max(0.0);
        c
    };
    let k0 = area / base.core.spring_rate * 1e9;
    let fit2 = levenberg_marquardt(
        |p| match params_of(&with_spring(p)) {
            Some(params) => table2_residuals(&params, t2),
            None => vec![f64::INFINITY; t2.temps.len()],
        },
        &[k0, base.core.preload * 1e5],
        &[1e-7, 1e-7],
        500,
    );
    if !fit2.rms().is_finite() {
        return Err("Table 2 fit failed".into());
    }
    let mut params = *base;
    params.core = with_spring(&fit2.x);
    params
        .validate()
        .map_err(|e| format!("calibrated parameters are not valid: {e}"))?;
    Ok(Calibration {
        params,
        table1: fit1,
        table2: fit2,
    })
}

/// Walther constants through two points of Table 1's first column,
/// inverted for `A` and divided by `G sqrt(rho)`.
fn initial_walther(base: &RawParams, t1: &Table1, g: f64) -> Option<[f64; 2]> {
    let params = params_of(&base.core)?;
    let inv = invert_table1(t1);
    let (i0, i1) = (0, t1.temps.len().checked_sub(1)?);
    let nu_cst = |i: usize| -> Option<f64> {
        let rho = params.oil.density(t1.temps[i]).ok()?;
        let nu = inv.a[i][0] / (g * rho.sqrt()) * 1e6;
        (nu > 0.0).then_some(nu)
    };
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (n0, n1) = (nu_cst(i0)?, nu_cst(i1)?);
    let (l0, l1) = ((t1.temps[i0] + 273.15).log10(), (t1.temps[i1] + 273.15).log10());
    let b = (w(n0) - w(n1)) / (l1 - l0);
    let a = w(n0) + b * l0;
    (a.is_finite() && b.is_finite() && b > 0.0).then_some([a, b])
}

/// Table 1 inverted for `A`: `A^2 = (dp - y)^2 / (2 (dp + y))` [Pa], per column.
#[derive(Debug, Clone)]
pub struct Inversion {
    /// `a[i][j]`: `A` at `temps[i]` from column `j` [sqrt(Pa)].
    pub a: Vec<Vec<f64>>,
    /// Per temperature: (max - min) / mean of the columns' `A`.
    pub spread: Vec<f64>,
}

/// Inverts each column of Table 1 for `A(t)` (`docs/model.md` section 4).
pub fn invert_table1(t1: &Table1) -> Inversion {
    let a: Vec<Vec<f64>> = t1
        .values
        .iter()
        .map(|row| {
            row.iter()
                .zip(&t1.drops_bar)
                .map(|(&y, &dp)| ((dp - y).powi(2) / (2.0 * (dp + y)) * BAR).sqrt())
                .collect()
        })
        .collect();
    let spread = a
        .iter()
        .map(|row| {
            let (lo, hi) = row
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
            let mean = row.iter().sum::<f64>() / row.len() as f64;
            (hi - lo) / mean
        })
        .collect();
    Inversion { a, spread }
}

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
/// from `commands::find_balance`) for comparison.
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
                    max_mm: crate::lsq::max_abs(&e),
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
