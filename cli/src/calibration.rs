//! Calibration against the paper's Tables 1 and 2: the `calibrate` command.
//!
//! [`fit`] keeps a base parameter set's geometry and fits
//! 1. the oil (Walther `a`, `b`) and the geometry factor `G` of
//!    `A = G nu sqrt(rho)` to all 18 points of Table 1 (`G` becomes the
//!    capillary length), then
//! 2. the spring rate and preload (`A_p / c` and `x0`) to Table 2's
//!    quasi-static column at 4 bar.
//!
//! [`calibrate`] writes the fitted set as TOML with its provenance.

use crate::error::CliError;
use crate::lsq::{Fit, levenberg_marquardt};
use crate::paper::tables::{Table1, Table2, invert_table1, load_tables, table1_residuals, table2_residuals};
use crate::params_file;
use compensator::Params;
use compensator::params::{RawCore, RawParams};
use std::fmt::Write as _;
use std::path::Path;

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

/// Outcome of [`fit`].
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
pub fn fit(base: &RawParams, t1: &Table1, t2: &Table2) -> Result<Calibration, String> {
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

/// `calibrate`: fitted preset as TOML with its provenance in comments,
/// from the base file `base_path` and the tables in `data` (without them:
/// the built-in `presets/model-example.toml` and `data/paper/`).
pub fn calibrate(base_path: Option<&Path>, data: Option<&Path>) -> Result<String, CliError> {
    let base = match base_path {
        Some(path) => crate::input::load_raw(path, "--base")?,
        None => params_file::parse(crate::input::MODEL_EXAMPLE)?,
    };
    let (t1, t2) = load_tables(data).map_err(CliError::Input)?;
    let cal = fit(&base, &t1, &t2).map_err(CliError::Failed)?;
    let base_path = base_path.unwrap_or(Path::new("presets/model-example.toml"));
    let data = data.unwrap_or(Path::new("data/paper"));
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Paper preset: {} with the oil, capillary length, spring rate and",
        base_path.display()
    );
    let _ = writeln!(
        out,
        "# preload fitted to the paper's Tables 1 and 2 ({}).",
        data.display()
    );
    let _ = writeln!(
        out,
        "# Generated by: compensator calibrate --base {} --data {}",
        base_path.display(),
        data.display()
    );
    let _ = writeln!(
        out,
        "# Table 1: RMS {:.4} bar, max {:.4} bar over {} points. Table 2 (x_QS): RMS {:.4} mm, max {:.4} mm.",
        cal.table1.rms(),
        cal.table1.max_abs(),
        cal.table1.residuals.len(),
        cal.table2.rms(),
        cal.table2.max_abs()
    );
    out.push('\n');
    out.push_str(&params_file::to_toml(&cal.params));
    Ok(out)
}
