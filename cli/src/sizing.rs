//! Design sizing: matching a compensator and the machine whose losses it
//! covers (paper Eqs. 8-9).
//!
//! The machine's losses are laminar leakage, `dQ_lost(t) = L mu(t_ref) / mu(t)`,
//! and it needs `Q_work + dQ_lost(t)`; the compensator supplies
//! `Q0(t) = 2 Q_a(t) + eta pi d x(t) sqrt(2 dp / rho(t))`. Both fits below
//! are linear least squares in closed form over a temperature list:
//!
//! * [`fit_machine`]: the `(Q_work, L)` a given compensator serves best;
//! * [`fit_slot`]: the window diameter `d` that serves a given machine best
//!   (`x(t)` does not depend on `d`, so `Q0` is linear in it).
//!
//! The commands: [`compensation_table`] (`compensation`: demand, supply and
//! error per temperature) and [`size`] (`size`: either fit, as TOML).

use crate::csv::Table;
use crate::error::CliError;
use crate::params_file;
use compensator::Params;
use compensator::compensation::compensation;
use compensator::equilibrium::equilibrium;
use compensator::params::Machine;
use std::fmt::Write as _;
use std::path::Path;

/// A fitted design and how well it compensates.
#[derive(Debug, Clone, Copy)]
pub struct Fit {
    /// Working flow `Q_work` [m^3/s] (machine fit) or unchanged.
    pub working_flow: f64,
    /// Leakage at the reference temperature [m^3/s] (machine fit) or unchanged.
    pub leakage_reference: f64,
    /// Reference temperature of the leakage [C].
    pub leakage_temperature: f64,
    /// Window diameter [m] (slot fit) or unchanged.
    pub slot_diameter: f64,
    /// RMS of `Q0 - demand` over the temperatures [m^3/s].
    pub rms_error: f64,
    /// Largest `|Q0 - demand|` [m^3/s].
    pub max_error: f64,
}

fn errors(p: &Params<f64>, temps: &[f64]) -> Result<(f64, f64), String> {
    let mut sum = 0.0;
    let mut max = 0.0f64;
    for &t in temps {
        let c = compensation(p, t).map_err(|e| format!("{t} C: {e}"))?;
        sum += c.error * c.error;
        max = max.max(c.error.abs());
    }
    Ok(((sum / temps.len() as f64).sqrt(), max))
}

/// The machine (working flow and laminar leakage at `t_ref` [C]) that the
/// compensator `p` serves best over `temps` [C], with both coefficients
/// kept non-negative.
pub fn fit_machine(p: &Params<f64>, temps: &[f64], t_ref: f64) -> Result<Fit, String> {
    if temps.len() < 2 {
        return Err("--temps: at least two temperatures are needed".into());
    }
    let mu_ref = p
        .oil
        .state(t_ref)
        .map_err(|e| format!("--reference {t_ref} C: {e}"))?
        .dynamic_viscosity;
    // Rows (1, r(t)) against Q0(t), r = mu_ref / mu(t).
    let (mut s11, mut s1r, mut srr, mut s1q, mut srq) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &t in temps {
        let e = equilibrium(p, t).map_err(|e| format!("{t} C: {e}"))?;
        let r = mu_ref / e.fluid.dynamic_viscosity;
        s11 += 1.0;
        s1r += r;
        srr += r * r;
        s1q += e.q_total;
        srq += r * e.q_total;
    }
    let det = s11 * srr - s1r * s1r;
    let (mut qw, mut leak) = ((srr * s1q - s1r * srq) / det, (s11 * srq - s1r * s1q) / det);
    if leak < 0.0 {
        leak = 0.0;
        qw = s1q / s11;
    }
    if qw < 0.0 {
        qw = 0.0;
        leak = srq / srr;
    }
    let machine = Machine {
        working_flow: qw,
        leakage_reference: leak,
        leakage_temperature: t_ref,
    };
    let fitted = Params {
        machine: Some(machine),
        ..*p
    };
    let (rms_error, max_error) = errors(&fitted, temps)?;
    Ok(Fit {
        working_flow: qw,
        leakage_reference: leak,
        leakage_temperature: t_ref,
        slot_diameter: p.slot.diameter,
        rms_error,
        max_error,
    })
}

/// The window diameter that serves the parameter set's `[machine]` best
/// over `temps` [C].
pub fn fit_slot(p: &Params<f64>, temps: &[f64]) -> Result<Fit, String> {
    let m = p
        .machine
        .ok_or("the parameter file has no [machine] section to size the slot for")?;
    let (mut sgg, mut sgb) = (0.0, 0.0);
    for &t in temps {
        let c = compensation(p, t).map_err(|e| format!("{t} C: {e}"))?;
        // Q_throt = d g(t): the window flow per metre of diameter.
        let g = c.equilibrium.q_throt / p.slot.diameter;
        let need = c.demand - 2.0 * c.equilibrium.q_branch;
        sgg += g * g;
        sgb += g * need;
    }
    if !(sgg > 0.0) {
        return Err("the window never opens over --temps: no diameter changes the supply".into());
    }
    let d = sgb / sgg;
    if !(d > 0.0) {
        return Err(format!(
            "the best diameter would be {d} m: the branches alone oversupply this machine"
        ));
    }
    let mut fitted = *p;
    fitted.slot.diameter = d;
    let (rms_error, max_error) = errors(&fitted, temps)?;
    Ok(Fit {
        working_flow: m.working_flow,
        leakage_reference: m.leakage_reference,
        leakage_temperature: m.leakage_temperature,
        slot_diameter: d,
        rms_error,
        max_error,
    })
}

/// `compensation`: demand, supply, error and the Eq. (9) window per temperature.
pub fn compensation_table(path: &Path, temps_spec: &str) -> Result<String, CliError> {
    let input = crate::input::load_at_temps(path, temps_spec)?;
    if input.params.machine.is_none() {
        return Err(CliError::Input(format!(
            "{}: no [machine] section (see `compensator size --for machine`)",
            path.display()
        )));
    }
    Ok(input.mark(compensation_of(&input.params, &input.temps).as_str()))
}

/// The `compensation` table of a parameter set with a `[machine]` at
/// `temps` [C]; a temperature the model cannot evaluate gets an `error`
/// cell.
pub fn compensation_of(p: &Params<f64>, temps: &[f64]) -> Table {
    let mut table = Table::new(&[
        "t_c",
        "losses_m3s",
        "demand_m3s",
        "supply_m3s",
        "error_m3s",
        "required_area_m2",
        "required_x_m",
        "x_m",
    ]);
    table.rows_at(temps, |t| {
        compensation(p, t).map(|c| {
            vec![
                c.losses,
                c.demand,
                c.equilibrium.q_total,
                c.error,
                c.required_area,
                c.required_x,
                c.equilibrium.x,
            ]
        })
    });
    table
}

/// A fit whose result is not a finite number failed (exit status 1),
/// naming the first such quantity.
fn finite(quantities: &[(&str, f64)]) -> Result<(), CliError> {
    match quantities.iter().find(|(_, v)| !v.is_finite()) {
        Some((name, v)) => Err(CliError::Failed(format!(
            "{name} is {v}: the fit has no finite result for these parameters"
        ))),
        None => Ok(()),
    }
}

/// `size`: the machine a compensator serves best, or the window a machine needs.
pub fn size(path: &Path, what: &str, temps_spec: &str, reference: f64) -> Result<String, CliError> {
    let crate::input::AtTemps {
        params: p,
        envelope: env,
        temps,
        ..
    } = crate::input::load_at_temps(path, temps_spec)?;
    env.check(reference, "--reference")?;
    let mut o = String::new();
    match what {
        "machine" => {
            let f = fit_machine(&p, &temps, reference).map_err(CliError::Input)?;
            finite(&[
                ("working_flow", f.working_flow),
                ("leakage_reference", f.leakage_reference),
                ("leakage_temperature", f.leakage_temperature),
                ("compensation error RMS", f.rms_error),
                ("compensation error max", f.max_error),
            ])?;
            let _ = writeln!(o, "# The machine {} serves best over {temps_spec} C", path.display());
            let _ = writeln!(
                o,
                "# (laminar leakage, least squares): compensation error RMS {:.3e} m^3/s, max {:.3e} m^3/s.",
                f.rms_error, f.max_error
            );
            let _ = writeln!(
                o,
                "# Generated by: compensator size --params {} --for machine --temps {temps_spec} --reference {reference}",
                path.display()
            );
            let _ = writeln!(o, "[machine]");
            let _ = writeln!(o, "working_flow = {:e}    # m^3/s", f.working_flow);
            let _ = writeln!(
                o,
                "leakage_reference = {:e}    # m^3/s at leakage_temperature",
                f.leakage_reference
            );
            let _ = writeln!(
                o,
                "leakage_temperature = {}    # C",
                params_file::fmt_float(f.leakage_temperature)
            );
        }
        "slot" => {
            let f = fit_slot(&p, &temps).map_err(CliError::Input)?;
            finite(&[
                ("slot diameter", f.slot_diameter),
                ("compensation error RMS", f.rms_error),
                ("compensation error max", f.max_error),
            ])?;
            let _ = writeln!(
                o,
                "# The window diameter that serves the [machine] of {} best over {temps_spec} C",
                path.display()
            );
            let _ = writeln!(
                o,
                "# (least squares): compensation error RMS {:.3e} m^3/s, max {:.3e} m^3/s.",
                f.rms_error, f.max_error
            );
            let _ = writeln!(o, "[slot]");
            let _ = writeln!(o, "diameter = {:e}    # m", f.slot_diameter);
            let _ = writeln!(
                o,
                "discharge_coefficient = {}",
                params_file::fmt_float(p.slot.discharge_coefficient)
            );
        }
        other => {
            return Err(CliError::Input(format!(
                "--for: '{other}' is neither 'machine' nor 'slot'"
            )));
        }
    }
    Ok(o)
}

#[cfg(test)]
mod finite_tests {
    use super::finite;

    #[test]
    fn a_non_finite_result_is_a_failure_naming_the_quantity() {
        assert!(finite(&[("slot diameter", 1e-3), ("compensation error RMS", 1e-6)]).is_ok());
        for bad in [f64::INFINITY, f64::NAN, f64::NEG_INFINITY] {
            let e = finite(&[("slot diameter", 1e-3), ("compensation error RMS", bad)]).unwrap_err();
            assert_eq!(e.exit_code(), 1);
            assert!(e.to_string().starts_with("compensation error RMS is"), "{e}");
        }
    }
}
