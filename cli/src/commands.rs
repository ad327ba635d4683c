//! The subcommands, as functions returning their complete standard output.

use crate::csv::Table;
use crate::paper::{self, BAR, Table1, Table2};
use crate::params_file::{self, LoadError};
use crate::temps;
use compensator::asymptotic::{Expansion, Reading, monotonicity, sensitivity as sens};
use compensator::equilibrium::{self as eq, balance_temperature};
use compensator::{Float, ModelError, Params, RawParams};
use std::fmt;
use std::fmt::Write as _;
use std::path::Path;

/// A command's failure: bad input (exit status 2) or a computation that
/// could not be completed (exit status 1). `Display` is one line.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: the message names the field or argument.
    Input(String),
    /// A computation failed.
    Failed(String),
}

impl CliError {
    /// Process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Failed(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(s) | CliError::Failed(s) => f.write_str(s),
        }
    }
}

impl From<LoadError> for CliError {
    fn from(e: LoadError) -> Self {
        CliError::Input(e.to_string())
    }
}

impl From<temps::TempsError> for CliError {
    fn from(e: temps::TempsError) -> Self {
        CliError::Input(e.to_string())
    }
}

/// Loads a parameter file and converts it to `T`.
pub fn load_params<T: Float>(path: &Path) -> Result<(RawParams, Params<T>), CliError> {
    let raw = params_file::load(path)?;
    let params = Params::<T>::new(&raw).map_err(|e| CliError::Input(e.to_string()))?;
    Ok((raw, params))
}

/// A model error at a given temperature is bad input (the temperature).
pub fn at_temperature(t: f64, e: ModelError) -> CliError {
    CliError::Input(format!("--temps: {t} C: {e}"))
}

/// Formats an `f32` result as the shortest decimal that reads back as the
/// same `f32`, then as `f64` for the CSV writer.
fn widen(v: f32) -> f64 {
    format!("{v}").parse().unwrap_or(f64::NAN)
}

/// `equilibrium`: the quasi-static operating point per temperature.
pub fn equilibrium_table(path: &Path, temps_spec: &str, single: bool) -> Result<Table, CliError> {
    let temps = temps::parse(temps_spec)?;
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
    ]);
    if single {
        let (_, p) = load_params::<f32>(path)?;
        for &t in &temps {
            let e = eq::equilibrium(&p, t as f32).map_err(|e| at_temperature(t, e))?;
            table.row(&[
                t,
                widen(e.a),
                widen(e.p_a),
                widen(e.p_b),
                widen(e.dp_ab),
                widen(e.x),
                widen(e.q_branch),
                widen(e.q_throt),
                widen(e.q_total),
            ]);
        }
    } else {
        let (_, p) = load_params::<f64>(path)?;
        for &t in &temps {
            let e = eq::equilibrium(&p, t).map_err(|e| at_temperature(t, e))?;
            table.row(&[t, e.a, e.p_a, e.p_b, e.dp_ab, e.x, e.q_branch, e.q_throt, e.q_total]);
        }
    }
    Ok(table)
}

/// `equilibrium` as text.
pub fn equilibrium(path: &Path, temps_spec: &str, single: bool) -> Result<String, CliError> {
    Ok(equilibrium_table(path, temps_spec, single)?.as_str().to_string())
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
    let temps = temps::parse(temps_spec)?;
    let (raw, p) = load_params::<f64>(path)?;
    let t0 = if t0.trim() == "balance" {
        find_balance(&raw, &p)?
    } else {
        let v: f64 = t0
            .trim()
            .parse()
            .map_err(|_| CliError::Input(format!("--t0: '{t0}' is neither a number nor 'balance'")))?;
        if !v.is_finite() {
            return Err(CliError::Input(format!("--t0: '{t0}' is not finite")));
        }
        v
    };
    let e = Expansion::new(&p, t0, reading).map_err(|e| CliError::Input(format!("--t0: {t0} C: {e}")))?;
    let mut table = Table::new(&["t_c", "x_qs_m", "x_asym_m"]);
    for &t in &temps {
        let qs = eq::equilibrium(&p, t).map_err(|e| at_temperature(t, e))?;
        let terms = e.at(t).map_err(|e| at_temperature(t, e))?;
        table.row(&[t, qs.x, terms.x(order).0]);
    }
    Ok(table.as_str().to_string())
}

/// `sensitivity`: Eqs. (30)-(31) per temperature, then the Eq. (32)
/// verdict over the listed range as a trailing comment line.
pub fn sensitivity(path: &Path, temps_spec: &str) -> Result<String, CliError> {
    let temps = temps::parse(temps_spec)?;
    let (_, p) = load_params::<f64>(path)?;
    let mut table = Table::new(&["t_c", "dx_dt_branch_m_k", "dx_dt_m_k", "dq_throt_dt_m3s_k"]);
    for &t in &temps {
        let s = sens(&p, t).map_err(|e| at_temperature(t, e))?;
        table.row(&[t, s.dx_dt_branch, s.dx_dt, s.dq_throt_dt]);
    }
    Ok(table.as_str().to_string())
}

/// `calibrate`: fitted preset as TOML with its provenance in comments.
pub fn calibrate(base_path: &Path, data: &Path) -> Result<String, CliError> {
    let base = params_file::load(base_path)?;
    let t1 = Table1::load(&data.join("table1.csv")).map_err(CliError::Input)?;
    let t2 = Table2::load(&data.join("table2.csv")).map_err(CliError::Input)?;
    let cal = paper::calibrate(&base, &t1, &t2).map_err(CliError::Failed)?;
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

/// `paper`: the findings of the README, recomputed.
pub fn paper(path: &Path, data: &Path) -> Result<String, CliError> {
    let (raw, p) = load_params::<f64>(path)?;
    let t1 = Table1::load(&data.join("table1.csv")).map_err(CliError::Input)?;
    let t2 = Table2::load(&data.join("table2.csv")).map_err(CliError::Input)?;
    let mut o = String::new();
    let _ = writeln!(o, "# Paper reproduction with {}", path.display());

    let inv = paper::invert_table1(&t1);
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

    let r1 = paper::table1_residuals(&p, &t1);
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
        crate::lsq::rms(&r1),
        crate::lsq::max_abs(&r1),
        r1.len()
    );

    let r2 = paper::table2_residuals(&p, &t2);
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
    let _ = writeln!(
        o,
        "RMS {:.4} mm, max {:.4} mm",
        crate::lsq::rms(&r2),
        crate::lsq::max_abs(&r2)
    );

    let balance = find_balance(&raw, &p).ok();
    let (best, at_balance) = paper::asymptotic_search(&p, &t2, 26.0, 80.0, balance);
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

    let _ = writeln!(
        o,
        "\n## Eq. (1): chamber-pressure gradient at dp = 0.2 MPa over 26-78 C"
    );
    let (mean_a, max_a, mean_b) = paper::chamber_gradient(&p, 2.0e5, 26.0, 78.0).map_err(CliError::Failed)?;
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

    let mono = monotonicity(&p, 26.0, 78.0, 521).map_err(|e| CliError::Failed(e.to_string()))?;
    let _ = writeln!(
        o,
        "\n## Eq. (32) over 26-78 C: monotonic = {}, smallest |dx/dt| = {:.3e} m/K at {:.1} C",
        mono.monotonic, mono.worst_dx_dt, mono.worst_temperature
    );
    Ok(o)
}

/// `compensation`: demand, supply, error and the Eq. (9) window per temperature.
pub fn compensation_table(path: &Path, temps_spec: &str) -> Result<String, CliError> {
    let temps = temps::parse(temps_spec)?;
    let (_, p) = load_params::<f64>(path)?;
    if p.machine.is_none() {
        return Err(CliError::Input(format!(
            "{}: no [machine] section (see `compensator size --for machine`)",
            path.display()
        )));
    }
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
    for &t in &temps {
        let c = compensator::compensation::compensation(&p, t).map_err(|e| at_temperature(t, e))?;
        table.row(&[
            t,
            c.losses,
            c.demand,
            c.equilibrium.q_total,
            c.error,
            c.required_area,
            c.required_x,
            c.equilibrium.x,
        ]);
    }
    Ok(table.as_str().to_string())
}

/// `size`: the machine a compensator serves best, or the window a machine needs.
pub fn size(path: &Path, what: &str, temps_spec: &str, reference: f64) -> Result<String, CliError> {
    let temps = temps::parse(temps_spec)?;
    let (_, p) = load_params::<f64>(path)?;
    let mut o = String::new();
    match what {
        "machine" => {
            let f = crate::sizing::fit_machine(&p, &temps, reference).map_err(CliError::Input)?;
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
                crate::params_file::fmt_float(f.leakage_temperature)
            );
        }
        "slot" => {
            let f = crate::sizing::fit_slot(&p, &temps).map_err(CliError::Input)?;
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
                crate::params_file::fmt_float(p.slot.discharge_coefficient)
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
