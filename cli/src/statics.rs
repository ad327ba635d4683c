//! Static-model commands: the quasi-static equilibrium (Eqs. 2-10), its
//! asymptotic expansion (Eqs. 16-21) and the temperature sensitivities
//! (Eqs. 30-32), one CSV row per temperature. A temperature the model
//! cannot evaluate (beyond the viscosity law's range, say) gives a row
//! with an `error` cell instead of failing the whole table.

use crate::csv::Table;
use crate::envelope::Envelope;
use crate::error::CliError;
use crate::input::{AtTemps, load_at_temps};
use compensator::asymptotic::{Expansion, Reading, sensitivity as sens};
use compensator::equilibrium::{self as eq, balance_temperature};
use compensator::{Params, RawParams};
use std::path::Path;

/// Formats an `f32` result as the shortest decimal that reads back as the
/// same `f32`, then as `f64` for the CSV writer.
fn widen(v: f32) -> f64 {
    format!("{v}").parse().unwrap_or(f64::NAN)
}

/// `equilibrium`: the quasi-static operating point per temperature.
pub fn equilibrium_table(path: &Path, temps_spec: &str, single: bool) -> Result<(Table, Envelope), CliError> {
    let AtTemps {
        raw,
        params: p64,
        envelope: env,
        temps,
    } = load_at_temps(path, temps_spec)?;
    let mut table = Table::new(&[
        "t_c",
        "a_sqrt_pa",
        "p_a_pa",
        "p_b_pa",
        "dp_ab_pa",
        "x_m",
        "q_branch_m3s",
        "q_throt_m3s",
        "q_total_m3s",
        "nu_m2s",
    ]);
    if single {
        let p = Params::<f32>::new(&raw).map_err(|e| CliError::Input(e.to_string()))?;
        table.rows_at(&temps, |t| {
            eq::equilibrium(&p, t as f32).map(|e| equilibrium_cells(&e, widen))
        });
    } else {
        table.rows_at(&temps, |t| {
            eq::equilibrium(&p64, t).map(|e| equilibrium_cells(&e, |v| v))
        });
    }
    Ok((table, env))
}

/// The `equilibrium` cells after `t_c` of `e`, each through `f` (to
/// `f64`).
fn equilibrium_cells<T: Copy>(e: &eq::Equilibrium<T>, f: impl Fn(T) -> f64) -> Vec<f64> {
    [
        e.a,
        e.p_a,
        e.p_b,
        e.dp_ab,
        e.x,
        e.q_branch,
        e.q_throt,
        e.q_total,
        e.fluid.kinematic_viscosity,
    ]
    .map(f)
    .to_vec()
}

/// `equilibrium` as text.
pub fn equilibrium(path: &Path, temps_spec: &str, single: bool) -> Result<String, CliError> {
    let (table, env) = equilibrium_table(path, temps_spec, single)?;
    Ok(env.mark(table.as_str(), &["t_c"]))
}

/// Balance temperature (Eq. 2) searched over the estimator's oil range:
/// a 1 C scan finds a bracket among evaluable temperatures, bisection
/// refines it.
pub fn find_balance(raw: &RawParams, p: &Params<f64>) -> Result<f64, CliError> {
    let (lo, hi) = (raw.estimator.oil_min, raw.estimator.oil_max);
    let target = (p.pressure_drop / 2.0).sqrt();
    let g = |t: f64| {
        p.oil
            .state(t)
            .ok()
            .map(|f| compensator::equilibrium::a_parameter(p, &f) - target)
    };
    let mut prev: Option<(f64, f64)> = None;
    let n = (hi - lo).ceil() as usize;
    for i in 0..=n {
        let t = (lo + i as f64).min(hi);
        if let Some(v) = g(t) {
            if let Some((tp, vp)) = prev
                && (vp > 0.0) != (v > 0.0)
            {
                return balance_temperature(p, tp, t)
                    .map_err(|e| CliError::Failed(format!("balance temperature: {e}")));
            }
            prev = Some((t, v));
        }
    }
    Err(CliError::Input(format!(
        "--t0 balance: p_a = p_b is not reached between estimator.oil_min = {lo} and estimator.oil_max = {hi} C"
    )))
}

/// `asymptotic`: quasi-static and series displacement per temperature.
pub fn asymptotic(path: &Path, order: usize, reading: Reading, t0: &str, temps_spec: &str) -> Result<String, CliError> {
    let input = load_at_temps(path, temps_spec)?;
    let (raw, p, env) = (&input.raw, &input.params, &input.envelope);
    let t0 = if t0.trim() == "balance" {
        find_balance(raw, p)?
    } else {
        let v: f64 = t0
            .trim()
            .parse()
            .map_err(|_| CliError::Input(format!("--t0: '{t0}' is neither a number nor 'balance'")))?;
        if !v.is_finite() {
            return Err(CliError::Input(format!("--t0: '{t0}' is not finite")));
        }
        env.check(v, "--t0")?;
        v
    };
    let e = Expansion::new(p, t0, reading).map_err(|e| CliError::Input(format!("--t0: {t0} C: {e}")))?;
    let mut table = Table::new(&["t_c", "x_qs_m", "x_asym_m"]);
    table.rows_at(&input.temps, |t| {
        let qs = eq::equilibrium(p, t)?;
        Ok::<_, compensator::ModelError>(vec![qs.x, e.at(t)?.x(order).0])
    });
    Ok(input.mark(table.as_str()))
}

/// `sensitivity`: Eqs. (30)-(31) per temperature, then the Eq. (32)
/// verdict over the listed range as a trailing comment line.
pub fn sensitivity(path: &Path, temps_spec: &str) -> Result<String, CliError> {
    let input = load_at_temps(path, temps_spec)?;
    let mut table = Table::new(&["t_c", "dx_dt_branch_m_k", "dx_dt_m_k", "dq_throt_dt_m3s_k"]);
    table.rows_at(&input.temps, |t| {
        sens(&input.params, t).map(|s| vec![s.dx_dt_branch, s.dx_dt, s.dq_throt_dt])
    });
    Ok(input.mark(table.as_str()))
}
