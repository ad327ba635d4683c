//! Calibration from measured static data: the `calibrate` command.
//!
//! Data, long form, one row per measurement (any temperatures, any number
//! of pressure drops), read by [`crate::csv::read_columns`]:
//!
//! * pressure data `t_c,dp_pa,dp_ab_pa`: oil temperature [C], inlet-outlet
//!   drop `p_p - p_c` [Pa], chamber pressure difference `p_b - p_a` [Pa];
//! * displacement data `t_c,x_m` (optionally `dp_pa`; without it the base
//!   file's `operating.pressure_drop`): plunger displacement [m].
//!
//! What static data determine (`docs/model.md` section 4): the chamber
//! pressure difference depends on temperature only through
//! `A(t) = G nu(t) sqrt(rho(t))`, so pressure data fit the oil's Walther
//! constants `fluid.walther_a`, `fluid.walther_b` and the geometry factor
//! `G` (expressed as the capillary length `laminar_throttle.length`, the
//! other throttle dimensions kept); the displacement `x = Phi(A) - x0`
//! then fits the spring's compliance `A_p / c` and preload `x0`
//! (`plunger.spring_rate`, `plunger.preload`, the plunger diameter kept).
//! The density law, the other dimensions and everything dynamic (mass,
//! damping, volumes, bulk modulus: `identify`) are kept from the base file.
//!
//! The fit runs in two stages, as in the paper: the pressure stage alone,
//! then the displacement stage at the fitted oil. The displacement stage's
//! covariance includes the pressure stage's uncertainty propagated through
//! the oil (two-step estimator: `cov2 + M cov1 M^T`, with
//! `M = -(J2^T J2)^-1 J2^T J21` the sensitivity of the stage-2 optimum to
//! the stage-1 parameters), so the reported standard errors and
//! correlations cover all five parameters together.
//!
//! [`fit`] computes the estimates and [`calibrate`] renders them
//! (`compensator calibrate`).

use crate::csv::read_columns;
use crate::error::CliError;
use crate::lsq::{self, Fit, Uncertainty, least_squares};
use crate::params_file;
use compensator::Params;
use compensator::equilibrium::{a_parameter, equilibrium, geometry_factor, pressure_difference};
use compensator::params::{RawCore, RawParams, RawTolerances};
use nalgebra::DMatrix;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One measurement of the chamber pressure difference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressurePoint {
    /// Oil temperature [C].
    pub t_c: f64,
    /// Inlet-outlet drop `p_p - p_c` [Pa].
    pub dp_pa: f64,
    /// Chamber pressure difference `p_b - p_a` [Pa].
    pub dp_ab_pa: f64,
}

/// One measurement of the plunger displacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplacementPoint {
    /// Oil temperature [C].
    pub t_c: f64,
    /// Displacement [m].
    pub x_m: f64,
    /// Inlet-outlet drop [Pa]; `None`: the base file's pressure drop.
    pub dp_pa: Option<f64>,
}

/// The columns `names` of a data file, by position, or an error naming the
/// missing one and the columns found.
fn columns(t: &crate::csv::Numeric, names: &[&str]) -> Result<Vec<usize>, String> {
    names
        .iter()
        .map(|n| {
            t.column(n).ok_or_else(|| {
                format!(
                    "no column {n} (columns: {}; expected {})",
                    t.header.join(","),
                    names.join(",")
                )
            })
        })
        .collect()
}

/// Slack on the plunger's travel for measured displacements, as a fraction
/// of the stroke (noise or a sensor offset may put a sample just beyond a
/// stop, not a tenth of the stroke beyond).
pub const X_SLACK: f64 = 0.1;

/// A number for a message: plain when of ordinary size, else in
/// scientific notation (`{}` would print 1e308 with 309 digits).
fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `row R (line L), column C`.
fn at(t: &crate::csv::Numeric, row: usize, column: &str) -> String {
    format!("row {} (line {}), column {column}", row + 1, t.lines[row])
}

/// Reads pressure data `t_c,dp_pa,dp_ab_pa` (other columns are ignored).
///
/// Errors (naming row and column): a missing column, a cell that is not a
/// finite number, `dp_pa <= 0`, `|dp_ab_pa| >= dp_pa` (a chamber pressure
/// outside the supply and outlet pressures), no rows.
pub fn read_pressure(text: &str) -> Result<Vec<PressurePoint>, String> {
    let t = read_columns(text, &["t_c", "dp_pa", "dp_ab_pa"])?;
    let c = columns(&t, &["t_c", "dp_pa", "dp_ab_pa"])?;
    let mut out = Vec::with_capacity(t.rows.len());
    for (i, r) in t.rows.iter().enumerate() {
        let p = PressurePoint {
            t_c: r[c[0]],
            dp_pa: r[c[1]],
            dp_ab_pa: r[c[2]],
        };
        if p.dp_pa <= 0.0 {
            return Err(format!(
                "{}: {} Pa is not a positive drop",
                at(&t, i, "dp_pa"),
                num(p.dp_pa)
            ));
        }
        if p.dp_ab_pa.abs() >= p.dp_pa {
            return Err(format!(
                "{}: {} Pa is not inside (-dp_pa, dp_pa) = (-{}, {}) Pa: a chamber pressure \
                 lies between the supply and outlet pressures",
                at(&t, i, "dp_ab_pa"),
                num(p.dp_ab_pa),
                num(p.dp_pa),
                num(p.dp_pa)
            ));
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err("no data rows".into());
    }
    Ok(out)
}

/// Reads displacement data `t_c,x_m[,dp_pa]` (other columns are ignored).
///
/// Errors (naming row and column): a missing column, a cell that is not a
/// finite number, `dp_pa <= 0`, no rows.
pub fn read_displacement(text: &str) -> Result<Vec<DisplacementPoint>, String> {
    let t = read_columns(text, &["t_c", "x_m", "dp_pa"])?;
    let c = columns(&t, &["t_c", "x_m"])?;
    let dp = t.column("dp_pa");
    let mut out = Vec::with_capacity(t.rows.len());
    for (i, r) in t.rows.iter().enumerate() {
        let p = DisplacementPoint {
            t_c: r[c[0]],
            x_m: r[c[1]],
            dp_pa: dp.map(|j| r[j]),
        };
        if let Some(d) = p.dp_pa.filter(|d| *d <= 0.0) {
            return Err(format!("{}: {} Pa is not a positive drop", at(&t, i, "dp_pa"), num(d)));
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err("no data rows".into());
    }
    Ok(out)
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

/// Model residuals against pressure data [Pa]; `None` where the model
/// cannot be evaluated.
pub fn pressure_residuals(core: &RawCore, data: &[PressurePoint]) -> Option<Vec<f64>> {
    let params = params_of(core)?;
    data.iter()
        .map(|p| {
            let fluid = params.oil.state(p.t_c).ok()?;
            Some(pressure_difference(a_parameter(&params, &fluid), p.dp_pa) - p.dp_ab_pa)
        })
        .collect()
}

/// The model's displacement [m] at temperature `t_c` and drop `dp_pa`
/// (`None`: the core's own).
pub fn model_displacement(core: &RawCore, t_c: f64, dp_pa: Option<f64>) -> Option<f64> {
    let mut c = *core;
    if let Some(dp) = dp_pa {
        c.pressure_drop = dp;
    }
    equilibrium(&params_of(&c)?, t_c).ok().map(|e| e.x)
}

/// Model residuals against displacement data [m]; `None` where the model
/// cannot be evaluated.
pub fn displacement_residuals(core: &RawCore, data: &[DisplacementPoint]) -> Option<Vec<f64>> {
    data.iter()
        .map(|p| Some(model_displacement(core, p.t_c, p.dp_pa)? - p.x_m))
        .collect()
}

/// One fitted parameter with its uncertainty.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Parameter path (`fluid.walther_a`), as in the parameter file.
    pub path: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Fitted value.
    pub value: f64,
    /// Standard error (same unit).
    pub std_error: f64,
    /// Which data determined it: `pressure` or `displacement`.
    pub data: &'static str,
}

/// One stage of the fit: its least-squares result and its uncertainty in
/// the fit's own coordinates.
#[derive(Debug, Clone)]
pub struct Stage {
    /// The least-squares fit.
    pub fit: Fit,
    /// Its uncertainty (the displacement stage's conditional on the oil).
    pub uncertainty: Uncertainty,
}

/// Outcome of [`fit`].
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The calibrated parameter set (base with fitted fields; its
    /// tolerances still the base's: [`Calibration::written`] gives the
    /// calibrated file's).
    pub params: RawParams,
    /// The fitted parameters, pressure stage first.
    pub estimates: Vec<Estimate>,
    /// Covariance matrix of the estimates (same order), in the fields'
    /// units: the fit's, both stages together (module docs).
    pub covariance: DMatrix<f64>,
    /// Correlation matrix of the estimates (same order).
    pub correlation: DMatrix<f64>,
    /// Pressure stage: residuals in Pa.
    pub pressure: Stage,
    /// Displacement stage (with displacement data): residuals in m.
    pub displacement: Option<Stage>,
    /// Warnings about poorly determined parameters, one line each.
    pub warnings: Vec<String>,
}

/// Relative standard error above which a fitted parameter is reported as
/// not determined by the data (a 95 % interval would then include zero and
/// twice the value).
pub const REL_SE_LIMIT: f64 = 0.5;

/// Fit coordinates of the pressure stage: `[w_ref, walther_b, log10 G]`
/// with `w_ref = walther_a - walther_b log10(T_ref)` the Walther function
/// `log10 log10(nu + 0.7)` at the data's mean `log10 T` (centred, so that
/// the conditioning check sees the viscosity level and slope, not the
/// intercept at 0 K, which is correlated with the slope by construction).
struct Oil {
    base: RawCore,
    log_t_ref: f64,
}

impl Oil {
    fn core(&self, u: &[f64]) -> RawCore {
        let mut c = self.base;
        c.walther_b = u[1];
        c.walther_a = u[0] + u[1] * self.log_t_ref;
        c.laminar_length = capillary_length_for(&self.base, 10f64.powf(u[2]));
        c
    }
}

/// Walther's constants through the two extreme temperatures of the
/// pressure data, each inverted for `A` (`A^2 = (dp - y)^2 / (2 (dp + y))`)
/// and divided by `G sqrt(rho)`.
fn initial_walther(base: &RawCore, data: &[PressurePoint], g: f64) -> Option<[f64; 2]> {
    let params = params_of(base)?;
    let lo = data.iter().min_by(|a, b| a.t_c.total_cmp(&b.t_c))?;
    let hi = data.iter().max_by(|a, b| a.t_c.total_cmp(&b.t_c))?;
    if hi.t_c - lo.t_c < 1.0 {
        return None;
    }
    let nu_cst = |p: &PressurePoint| -> Option<f64> {
        let rho = params.oil.density(p.t_c).ok()?;
        let a = ((p.dp_pa - p.dp_ab_pa).powi(2) / (2.0 * (p.dp_pa + p.dp_ab_pa))).sqrt();
        let nu = a / (g * rho.sqrt()) * 1e6;
        (nu > 0.0).then_some(nu)
    };
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (n0, n1) = (nu_cst(lo)?, nu_cst(hi)?);
    let (l0, l1) = ((lo.t_c + 273.15).log10(), (hi.t_c + 273.15).log10());
    let b = (w(n0) - w(n1)) / (l1 - l0);
    let a = w(n0) + b * l0;
    (a.is_finite() && b.is_finite() && b > 0.0).then_some([a, b])
}

/// Central-difference steps for parameters near `x`: 1e-6 relative (about
/// the cube root of the machine epsilon, the best for central differences),
/// at least 1e-9.
fn steps(x: &[f64]) -> Vec<f64> {
    x.iter().map(|v| 1e-6 * v.abs().max(1e-3)).collect()
}

/// The data cannot determine the parameters: exit status 2 naming the data.
fn undetermined(which: &str, names: &[&str], e: lsq::Undetermined) -> CliError {
    CliError::Input(format!("{which}: cannot fit {}: {e}", names.join(", ")))
}

/// The pressure stage's outcome: the fit in its own coordinates ([`Oil`])
/// and the fitted oil in the parameter file's.
struct PressureFit {
    stage: Stage,
    /// The base core with the fitted oil and capillary.
    core: RawCore,
    /// `(walther_a, walther_b, log10 G)` at the optimum.
    theta: [f64; 3],
    /// Their covariance.
    cov: DMatrix<f64>,
}

/// Fits `fluid.walther_a`, `fluid.walther_b` and the capillary (through
/// `log10 G`) of `base` to the pressure data (module docs).
fn fit_pressure(base: &RawParams, pressure: &[PressurePoint]) -> Result<PressureFit, CliError> {
    let f = &RawCore::FIELD;
    let start = params_of(&base.core).ok_or_else(|| CliError::Input("--base: parameters are not valid".into()))?;
    let g0 = geometry_factor(&start);
    let log_t_ref = pressure.iter().map(|p| (p.t_c + 273.15).log10()).sum::<f64>() / pressure.len() as f64;
    let oil = Oil {
        base: base.core,
        log_t_ref,
    };
    let level = format!(
        "the viscosity at {:.0} C (fluid.walther_a at the fitted walther_b)",
        10f64.powf(log_t_ref) - 273.15
    );
    let names1 = [level.as_str(), f.walther_b.path, f.laminar_length.path];
    enough_points("--pressure-data", &names1, pressure.len())?;
    // Start from the oil through the data's extreme temperatures, or the
    // base file's oil where that one cannot be evaluated at every point.
    let r1 = |u: &[f64]| pressure_residuals(&oil.core(u), pressure);
    let (u0, j0) = [
        initial_walther(&base.core, pressure, g0),
        Some([base.core.walther_a, base.core.walther_b]),
    ]
    .into_iter()
    .flatten()
    .find_map(|[a0, b0]| {
        let u0 = [a0 - b0 * log_t_ref, b0, g0.log10()];
        lsq::jacobian(r1, &u0, &steps(&u0)).map(|j| (u0, j))
    })
    .ok_or_else(|| {
        // Name the first row whose temperature the base oil cannot take.
        let row = pressure
            .iter()
            .position(|p| start.oil.state(p.t_c).is_err())
            .map_or(String::new(), |i| {
                format!(": data row {}, column t_c: {} C", i + 1, num(pressure[i].t_c))
            });
        CliError::Input(format!(
            "--pressure-data: the base file's oil cannot be evaluated at every temperature of the data{row}"
        ))
    })?;
    lsq::check_design(&j0, &names1).map_err(|e| undetermined("--pressure-data", &names1, e))?;
    let fit1 = least_squares(r1, &u0, &steps(&u0)).map_err(|e| CliError::Failed(format!("--pressure-data: {e}")))?;
    let unc1 = lsq::analyse(&fit1.jacobian, &fit1.residuals, &names1)
        .map_err(|e| undetermined("--pressure-data", &names1, e))?;
    let core = oil.core(&fit1.x);
    // Covariance of (walther_a, walther_b, log10 G) from that of (w_ref, b, log10 G).
    let to_ab = DMatrix::from_row_slice(3, 3, &[1.0, log_t_ref, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let cov = &to_ab * &unc1.cov * to_ab.transpose();
    let theta = [core.walther_a, core.walther_b, fit1.x[2]];
    Ok(PressureFit {
        stage: Stage {
            fit: fit1,
            uncertainty: unc1,
        },
        core,
        theta,
        cov,
    })
}

/// Stage-2 coordinates: compliance `A_p / c` [1e-9 m/Pa], preload [1e-5 m].
struct Spring {
    /// The plunger's area [m^2].
    area: f64,
}

impl Spring {
    fn of(base: &RawCore) -> Self {
        Spring {
            area: std::f64::consts::FRAC_PI_4 * base.plunger_diameter.powi(2),
        }
    }

    /// `core` with the spring at coordinates `v`.
    fn core(&self, core: RawCore, v: &[f64]) -> RawCore {
        let mut c = core;
        c.spring_rate = self.area / (v[0] * 1e-9);
        c.preload = (v[1] * 1e-5).max(0.0);
        c
    }
}

/// Refuses a displacement beyond the travel (a record in mm read as m
/// fits nothing and was reported as "the data do not separate" the
/// spring), naming the first such row.
fn check_travel(base: &RawCore, data: &[DisplacementPoint]) -> Result<(), CliError> {
    let stroke = base.stroke;
    let (lo, hi) = (-X_SLACK * stroke, (1.0 + X_SLACK) * stroke);
    match data.iter().position(|p| !(lo..=hi).contains(&p.x_m)) {
        None => Ok(()),
        Some(i) => Err(CliError::Input(format!(
            "--displacement-data: data row {}, column x_m: {} m is outside the plunger's travel \
             [{}, {}] m (0 to plunger.stroke = {} m, with {} % slack){}",
            i + 1,
            crate::display::sig(data[i].x_m, 6),
            crate::display::sig(lo, 4),
            crate::display::sig(hi, 4),
            crate::display::sig(stroke, 6),
            X_SLACK * 100.0,
            crate::data::column("x_m").map_or(String::new(), |c| crate::data::unit_hint(c, data[i].x_m, lo, hi))
        ))),
    }
}

/// Fits `plunger.spring_rate` and `plunger.preload` to the displacement
/// data with the oil of the pressure stage `oil`; returns the stage and
/// the calibrated core.
fn fit_displacement(
    base: &RawParams,
    oil: &PressureFit,
    data: &[DisplacementPoint],
) -> Result<(Stage, RawCore), CliError> {
    let f = &RawCore::FIELD;
    let names2 = [f.spring_rate.path, f.preload.path];
    enough_points("--displacement-data", &names2, data.len())?;
    check_travel(&base.core, data)?;
    let spring = Spring::of(&base.core);
    let fluid_core = oil.core;
    let v0 = [spring.area / base.core.spring_rate * 1e9, base.core.preload * 1e5];
    let r2 = |v: &[f64]| displacement_residuals(&spring.core(fluid_core, v), data);
    let j0 = lsq::jacobian(r2, &v0, &steps(&v0)).ok_or_else(|| {
        let start = spring.core(fluid_core, &v0);
        let row = data
            .iter()
            .position(|p| model_displacement(&start, p.t_c, p.dp_pa).is_none())
            .map_or(String::new(), |i| {
                let dp = data[i]
                    .dp_pa
                    .map_or("the base file's".to_string(), |d| format!("{} Pa", num(d)));
                format!(" (first at data row {}: {} C, drop {dp})", i + 1, num(data[i].t_c))
            });
        CliError::Input(format!(
            "--displacement-data: the model cannot be evaluated at the data's temperatures and drops{row}"
        ))
    })?;
    lsq::check_design(&j0, &names2).map_err(|e| undetermined("--displacement-data", &names2, e))?;
    let fit2 =
        least_squares(r2, &v0, &steps(&v0)).map_err(|e| CliError::Failed(format!("--displacement-data: {e}")))?;
    let unc2 = lsq::analyse(&fit2.jacobian, &fit2.residuals, &names2)
        .map_err(|e| undetermined("--displacement-data", &names2, e))?;
    let core = spring.core(fluid_core, &fit2.x);
    Ok((
        Stage {
            fit: fit2,
            uncertainty: unc2,
        },
        core,
    ))
}

/// The covariance of both stages' estimates together: the displacement
/// stage's (`stage`, at `core`) propagated from the oil's (`oil`) through
/// the sensitivity of the displacement residuals to the oil (`J21`), the
/// two-step estimate's delta method. Order: the oil's three, the spring's
/// two.
fn joint_covariance(
    base: &RawCore,
    oil: &PressureFit,
    stage: &Stage,
    core: RawCore,
    data: &[DisplacementPoint],
) -> Result<DMatrix<f64>, CliError> {
    let with_oil = |t: &[f64]| {
        let mut c = core;
        c.walther_a = t[0];
        c.walther_b = t[1];
        c.laminar_length = capillary_length_for(base, 10f64.powf(t[2]));
        c
    };
    let theta1 = oil.theta;
    let h = steps(&theta1);
    let m = data.len();
    let mut j21 = DMatrix::zeros(m, 3);
    for j in 0..3 {
        let (mut tp, mut tm) = (theta1, theta1);
        tp[j] += h[j];
        tm[j] -= h[j];
        let rp = displacement_residuals(&with_oil(&tp), data);
        let rm = displacement_residuals(&with_oil(&tm), data);
        let (Some(rp), Some(rm)) = (rp, rm) else {
            return Err(CliError::Failed(
                "--displacement-data: the model cannot be evaluated next to the fitted oil".into(),
            ));
        };
        for i in 0..m {
            j21[(i, j)] = (rp[i] - rm[i]) / (2.0 * h[j]);
        }
    }
    let cov1 = &oil.cov;
    let j2 = &stage.fit.jacobian;
    let jtj = j2.transpose() * j2;
    let inv = jtj
        .try_inverse()
        .ok_or_else(|| CliError::Failed("--displacement-data: singular normal equations".into()))?;
    let sens = -(inv * j2.transpose() * &j21);
    let cov22 = &stage.uncertainty.cov + &sens * cov1 * sens.transpose();
    let cov21 = &sens * cov1;
    let mut full = DMatrix::zeros(5, 5);
    full.view_mut((0, 0), (3, 3)).copy_from(cov1);
    full.view_mut((3, 3), (2, 2)).copy_from(&cov22);
    full.view_mut((3, 0), (2, 3)).copy_from(&cov21);
    full.view_mut((0, 3), (3, 2)).copy_from(&cov21.transpose());
    Ok(full)
}

/// Refuses `points` data points for the parameters `names` (of the data
/// `which`) when they leave no degree of freedom.
fn enough_points(which: &str, names: &[&str], points: usize) -> Result<(), CliError> {
    if points <= names.len() {
        return Err(undetermined(
            which,
            names,
            lsq::Undetermined::NoDegreesOfFreedom {
                points,
                parameters: names.len(),
            },
        ));
    }
    Ok(())
}

/// Fits the base parameter set to the data (see the module docs).
///
/// Errors: [`CliError::Input`] when the data cannot determine the
/// parameters (no degree of freedom, a rank-deficient Jacobian: the message
/// names the data and the parameters) or the base file is not valid;
/// [`CliError::Failed`] when the minimiser does not converge.
pub fn fit(
    base: &RawParams,
    pressure: &[PressurePoint],
    displacement: Option<&[DisplacementPoint]>,
) -> Result<Calibration, CliError> {
    let oil = fit_pressure(base, pressure)?;
    let mut warnings: Vec<String> = (oil.stage.uncertainty.warnings().into_iter())
        .map(|w| format!("pressure data: {w}"))
        .collect();
    let mut core = oil.core;
    let mut displacement_stage = None;
    let mut cov = oil.cov.clone();
    let mut internal = oil.theta.to_vec();
    if let Some(data) = displacement {
        let (stage, spring_core) = fit_displacement(base, &oil, data)?;
        warnings.extend((stage.uncertainty.warnings().into_iter()).map(|w| format!("displacement data: {w}")));
        core = spring_core;
        cov = joint_covariance(&base.core, &oil, &stage, core, data)?;
        internal.extend_from_slice(&stage.fit.x);
        displacement_stage = Some(stage);
    }
    let mut params = *base;
    params.core = core;
    let (estimates, cov_named) = named_estimates(&params, &cov, &internal)?;
    warnings.extend(estimates.iter().filter_map(undetermined_warning));
    params
        .validate()
        .map_err(|e| CliError::Failed(format!("calibrated parameters are not valid: {e}")))?;
    Ok(Calibration {
        params,
        estimates,
        correlation: lsq::correlation(&cov_named),
        covariance: cov_named,
        pressure: oil.stage,
        displacement: displacement_stage,
        warnings,
    })
}

/// The estimates in the parameter file's fields, from the fit coordinates
/// `internal` with covariance `cov` (three with the pressure stage alone,
/// five with the displacement stage), by the delta method:
/// `L = c 10^u` (`dL/du = L ln 10`), `spring_rate = A_p / (v 1e-9)`
/// (`d/dv = -spring_rate / v`), `preload = 1e-5 v`. Returns them and
/// their covariance.
fn named_estimates(
    params: &RawParams,
    cov: &DMatrix<f64>,
    internal: &[f64],
) -> Result<(Vec<Estimate>, DMatrix<f64>), CliError> {
    let f = &RawCore::FIELD;
    let core = &params.core;
    let mut d = vec![1.0, 1.0, core.laminar_length * std::f64::consts::LN_10];
    if internal.len() > 3 {
        d.push(-core.spring_rate / internal[3]);
        d.push(1e-5);
    }
    let p = d.len();
    let cov_named = DMatrix::from_fn(p, p, |i, j| d[i] * cov[(i, j)] * d[j]);
    let fields = [f.walther_a, f.walther_b, f.laminar_length, f.spring_rate, f.preload];
    let estimates = (0..p)
        .map(|i| {
            // By name, through the schema's access by path.
            let value = params
                .get(fields[i].path)
                .map_err(|e| CliError::Failed(format!("calibrated parameters: {e}")))?;
            Ok(Estimate {
                path: fields[i].path,
                unit: fields[i].unit,
                value,
                std_error: cov_named[(i, i)].max(0.0).sqrt(),
                data: if i < 3 { "pressure" } else { "displacement" },
            })
        })
        .collect::<Result<Vec<Estimate>, CliError>>()?;
    Ok((estimates, cov_named))
}

/// The warning for an estimate the data do not determine (relative
/// standard error above [`REL_SE_LIMIT`]), if it is one.
fn undetermined_warning(e: &Estimate) -> Option<String> {
    let rel = e.std_error / e.value.abs();
    (!(rel <= REL_SE_LIMIT)).then(|| {
        format!(
            "{} = {:.4e} {} has a standard error of {:.0} % of its value (above {:.0} %): the {} data \
             do not determine it; it is kept in the preset only because the fit needs a value",
            e.path,
            e.value,
            e.unit,
            100.0 * rel,
            100.0 * REL_SE_LIMIT,
            e.data
        )
    })
}

/// Largest standard uncertainty a parameter file accepts, as a fraction of
/// the field's value (`RawTolerances::validate`: a device three standard
/// deviations away must still be a device).
pub const TOLERANCE_LIMIT: f64 = 1.0 / 3.0;

/// Correlation magnitude up to which a pair of fitted fields gets no
/// `[[correlation]]` entry. Leaving out a coefficient `r` changes a
/// propagated variance `sum_ij g_i g_j r_ij u_i u_j` by `2 r g_i u_i g_j u_j`,
/// at most `|r|` times the two fields' own contributions `(g_i u_i)^2 +
/// (g_j u_j)^2`: any standard uncertainty by at most `|r| / 2` = 0.5 %
/// (GUM 5.2.2: a correlation may be neglected where its term is small
/// beside the uncertainty's own rounding to two digits). A pair
/// is written anyway when leaving the small ones out would make the
/// correlation matrix indefinite (a nearly singular fit's).
pub const CORR_WRITE_MIN: f64 = 0.01;

/// A fitted field whose standard error exceeds what a parameter file holds
/// ([`TOLERANCE_LIMIT`] of its value): the data do not determine it. Its
/// uncertainty is the base file's tolerance instead (a drawing's, Type B),
/// at the fitted value, and the other fitted fields' covariance is the
/// fit's conditioned on it (see [`Calibration::written`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Held {
    /// Parameter path.
    pub path: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Fitted value [unit].
    pub value: f64,
    /// The fit's standard error [unit].
    pub std_error: f64,
    /// The base file's tolerance, written in its place [unit].
    pub tolerance: f64,
    /// The base file's value [unit].
    pub base_value: f64,
    /// `|value - base_value| / std_error`: how far the data place the
    /// fitted value from the base's, in the fit's standard errors. The
    /// written covariance is the fit's conditioned on the field lying
    /// within its tolerance of the fitted value, where the Gaussian update
    /// by the base's value would also move the estimate, by this fraction
    /// of the fit's standard error along the direction the data barely
    /// see: no output then moves by more than `shift` of its standard
    /// uncertainty under the fit's covariance. Above [`HELD_SHIFT_WARN`]
    /// `calibrate` warns.
    pub shift: f64,
}

/// [`Held::shift`] above which `calibrate` warns that the data place a
/// field they do not determine far from the base file's value (the
/// written band then leans on a value the base file does not support).
pub const HELD_SHIFT_WARN: f64 = 0.5;

/// What `calibrate` writes into the calibrated file's `[tolerances]` and
/// `[[correlation]]` ([`Calibration::written`]).
#[derive(Debug, Clone)]
pub struct Written {
    /// The calibrated file's tolerances: the fitted fields' from the fit,
    /// every other field's (and the correlations between two of them) from
    /// the base file.
    pub tolerances: RawTolerances,
    /// Covariance of the fitted fields as written, in the estimates' order
    /// [their units]: the fit's, conditioned on the held fields.
    pub covariance: DMatrix<f64>,
    /// The fields the data do not determine (empty for a well-posed fit).
    pub held: Vec<Held>,
    /// Pairs of fitted fields left without an entry (`|r| <=`
    /// [`CORR_WRITE_MIN`]).
    pub omitted: usize,
}

/// The covariance `c` (fields' units) with the fields `held` given the
/// variances `u2` instead of the fit's and the others conditioned on them
/// (the two-step estimator's formula, `cli/src/calibration.rs` module
/// docs): with `M = C_fh C_hh^-1` the regression of the free fields on the
/// held ones, `C_ff - M C_hf + M U M^T`, `C_fh = M U`, `C_hh = U`. `None`
/// when `C_hh` is singular.
fn hold(c: &DMatrix<f64>, held: &[usize], u2: &[f64]) -> Option<DMatrix<f64>> {
    let p = c.nrows();
    let free: Vec<usize> = (0..p).filter(|i| !held.contains(i)).collect();
    let sub = |rows: &[usize], cols: &[usize]| DMatrix::from_fn(rows.len(), cols.len(), |i, j| c[(rows[i], cols[j])]);
    let c_hh_inv = sub(held, held).try_inverse()?;
    let c_fh = sub(&free, held);
    let m = &c_fh * c_hh_inv;
    let u = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(u2));
    let c_ff = sub(&free, &free) - &m * c_fh.transpose() + &m * &u * m.transpose();
    let c_fh = &m * &u;
    let mut out = DMatrix::zeros(p, p);
    for (a, &i) in free.iter().enumerate() {
        for (b, &j) in free.iter().enumerate() {
            out[(i, j)] = c_ff[(a, b)];
        }
        for (b, &j) in held.iter().enumerate() {
            out[(i, j)] = c_fh[(a, b)];
            out[(j, i)] = c_fh[(a, b)];
        }
    }
    for (a, &i) in held.iter().enumerate() {
        out[(i, i)] = u2[a];
    }
    Some(out)
}

impl Calibration {
    /// The tolerances the calibrated file gets, `base` being the file the
    /// fit started from.
    ///
    /// Each fitted field's standard uncertainty is its standard error (the
    /// fit's covariance, both stages, [`Calibration::covariance`]) and each
    /// pair of fitted fields correlated beyond [`CORR_WRITE_MIN`] gets a
    /// `[[correlation]]`; the base's tolerances of the fitted fields and
    /// its correlations involving one are replaced, every other tolerance
    /// and correlation is kept.
    ///
    /// A fitted field whose standard error exceeds [`TOLERANCE_LIMIT`] of
    /// its value is not determined by the data, and a file cannot hold
    /// that tolerance: it is [`Held`], given the base file's tolerance (at
    /// the fitted value, which the data cannot tell from the base's), and
    /// the other fields' covariance is conditioned on it ([`hold`]),
    /// repeated until every written tolerance fits.
    ///
    /// # Errors
    ///
    /// [`CliError::Input`] naming the field when a field the data do not
    /// determine has no tolerance in the base file (the calibrated file
    /// would otherwise claim it exactly known, or hold a tolerance no file
    /// accepts); [`CliError::Failed`] when the tolerances are refused by
    /// the parameter file's checks (more correlations than a file holds).
    pub fn written(&self, base: &RawParams) -> Result<Written, CliError> {
        let p = self.estimates.len();
        let limit = |i: usize| TOLERANCE_LIMIT * self.estimates[i].value.abs();
        let mut held: Vec<usize> = Vec::new();
        let mut cov = self.covariance.clone();
        loop {
            let more: Vec<usize> = (0..p)
                .filter(|i| !held.contains(i) && !(cov[(*i, *i)].max(0.0).sqrt() <= limit(*i)))
                .collect();
            if more.is_empty() {
                break;
            }
            for &i in &more {
                let e = &self.estimates[i];
                let u = base.tolerances.get(e.path).unwrap_or(0.0);
                if !(u > 0.0) {
                    return Err(CliError::Input(format!(
                        "--write-preset: {}: the {} data do not determine it (standard error {:.3e} {}, {:.0} %                          of its value {:.4e}; a tolerance may be at most a third of the value), and the --params                          file gives it no tolerance: give its standard uncertainty in that file's [tolerances] (a                          drawing's, docs/parameters.md), or data that determine it",
                        e.path,
                        e.data,
                        self.covariance[(i, i)].max(0.0).sqrt(),
                        e.unit,
                        100.0 * self.covariance[(i, i)].max(0.0).sqrt() / e.value.abs(),
                        e.value
                    )));
                }
                held.push(i);
            }
            let u2: Vec<f64> = held
                .iter()
                .map(|&i| base.tolerances.get(self.estimates[i].path).unwrap_or(0.0).powi(2))
                .collect();
            cov = hold(&self.covariance, &held, &u2)
                .ok_or_else(|| CliError::Failed("the fit's covariance of the held fields is singular".into()))?;
        }
        let fitted: Vec<&str> = self.estimates.iter().map(|e| e.path).collect();
        let mut tol = RawTolerances {
            core: base.tolerances.core,
            machine: base.tolerances.machine,
            ..RawTolerances::NONE
        };
        for c in base.tolerances.correlations() {
            if !fitted.contains(&c.a) && !fitted.contains(&c.b) {
                tol.push_correlation(c.a, c.b, c.coefficient)
                    .map_err(|e| CliError::Failed(format!("calibrated tolerances: {e}")))?;
            }
        }
        for (i, e) in self.estimates.iter().enumerate() {
            if let Some(s) = tol.get_mut(e.path) {
                *s = cov[(i, i)].max(0.0).sqrt();
            }
        }
        let corr = lsq::correlation(&cov);
        let pairs = |min: f64| -> Vec<(usize, usize)> {
            (0..p)
                .flat_map(|i| (i + 1..p).map(move |j| (i, j)))
                .filter(|&(i, j)| corr[(i, j)].abs() > min)
                .collect()
        };
        let with = |pairs: &[(usize, usize)]| -> Result<RawTolerances, CliError> {
            let mut t = tol;
            for &(i, j) in pairs {
                t.push_correlation(fitted[i], fitted[j], corr[(i, j)])
                    .map_err(|e| CliError::Failed(format!("calibrated tolerances: {e}")))?;
            }
            Ok(t)
        };
        // The parameter file's own reader is the judge of the matrix.
        let accepted = |t: &RawTolerances| {
            let mut raw = self.params;
            raw.tolerances = *t;
            params_file::parse(&params_file::to_toml(&raw))
        };
        let some = pairs(CORR_WRITE_MIN);
        let all = pairs(0.0);
        let (tolerances, omitted) = match with(&some)? {
            t if accepted(&t).is_ok() => (t, all.len() - some.len()),
            _ => {
                let t = with(&all)?;
                accepted(&t).map_err(|e| CliError::Failed(format!("calibrated tolerances: {e}")))?;
                (t, 0)
            }
        };
        let held = held
            .iter()
            .map(|&i| {
                let e = &self.estimates[i];
                let std_error = self.covariance[(i, i)].max(0.0).sqrt();
                let base_value = base
                    .get(e.path)
                    .map_err(|e| CliError::Failed(format!("calibrated tolerances: {e}")))?;
                Ok(Held {
                    path: e.path,
                    unit: e.unit,
                    value: e.value,
                    std_error,
                    tolerance: cov[(i, i)].sqrt(),
                    base_value,
                    shift: (e.value - base_value).abs() / std_error,
                })
            })
            .collect::<Result<Vec<Held>, CliError>>()?;
        Ok(Written {
            tolerances,
            covariance: cov,
            held,
            omitted,
        })
    }
}

impl Calibration {
    /// The stage that fitted `data` (`pressure` or `displacement`).
    fn stage(&self, data: &str) -> &Stage {
        match (data, &self.displacement) {
            ("displacement", Some(s)) => s,
            _ => &self.pressure,
        }
    }

    /// The report table (CSV): one row per fitted parameter,
    /// `parameter,unit,value,std_error,rel_std_error,data,points,dof,
    /// residual_rms,residual_unit,corr_<parameter>...`, where
    /// `residual_rms = sqrt(RSS / dof)` of the data that fitted it.
    pub fn table(&self) -> String {
        let mut header = vec![
            "parameter".to_string(),
            "unit".into(),
            "value".into(),
            "std_error".into(),
            "rel_std_error".into(),
            "data".into(),
            "points".into(),
            "dof".into(),
            "residual_rms".into(),
            "residual_unit".into(),
        ];
        header.extend(self.estimates.iter().map(|e| format!("corr_{}", e.path)));
        let mut out = header.join(",");
        out.push('\n');
        for (i, e) in self.estimates.iter().enumerate() {
            let u = &self.stage(e.data).uncertainty;
            let unit = if e.data == "pressure" { "Pa" } else { "m" };
            let _ = write!(
                out,
                "{},{},{},{},{},{},{},{},{},{}",
                e.path,
                e.unit.replace(' ', "_"),
                e.value,
                e.std_error,
                e.std_error / e.value.abs(),
                e.data,
                u.points,
                u.dof,
                u.s(),
                unit
            );
            for j in 0..self.estimates.len() {
                let _ = write!(out, ",{}", self.correlation[(i, j)]);
            }
            out.push('\n');
        }
        out
    }

    /// One line per stage for standard error: points, degrees of freedom,
    /// residual RMS.
    pub fn summary(&self) -> Vec<String> {
        let mut out = Vec::new();
        let u = &self.pressure.uncertainty;
        out.push(format!(
            "pressure data: {} points, 3 parameters, {} degrees of freedom; residual RMS {:.4e} Pa \
             (sqrt(RSS/dof) = {:.4e} Pa), max {:.4e} Pa",
            u.points,
            u.dof,
            self.pressure.fit.rms(),
            u.s(),
            self.pressure.fit.max_abs()
        ));
        if let Some(s) = &self.displacement {
            let u = &s.uncertainty;
            out.push(format!(
                "displacement data: {} points, 2 parameters, {} degrees of freedom; residual RMS {:.4e} m \
                 (sqrt(RSS/dof) = {:.4e} m), max {:.4e} m",
                u.points,
                u.dof,
                s.fit.rms(),
                u.s(),
                s.fit.max_abs()
            ));
        }
        out
    }

    /// The calibrated parameter file: TOML with the fit in comments, its
    /// `[tolerances]` and `[[correlation]]` those of `written`
    /// ([`Calibration::written`]).
    pub fn preset(&self, command: &str, written: &Written) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "# Calibrated from measured static data.");
        let _ = writeln!(out, "# Generated by: {command}");
        for line in self.summary() {
            let _ = writeln!(out, "# {line}");
        }
        for e in &self.estimates {
            let _ = writeln!(
                out,
                "# {} = {} +- {:.3e} {} (standard error, {} data)",
                e.path, e.value, e.std_error, e.unit, e.data
            );
        }
        for w in &self.warnings {
            let _ = writeln!(out, "# WARNING: {w}");
        }
        let _ = writeln!(
            out,
            "# [tolerances]: the fitted fields' standard errors; [[correlation]]: their pairs beyond |r| = {CORR_WRITE_MIN} \
             (left out: {} pairs); the other fields' tolerances are the base file's.",
            written.omitted
        );
        for h in &written.held {
            let _ = writeln!(
                out,
                "# {}: not determined by the data (standard error {:.3e} {}, above a third of its value): its \
                 tolerance {:.3e} {} is the base file's (value {}, {:.2} standard errors from the fit's), the \
                 others' covariance the fit's conditioned on it.",
                h.path, h.std_error, h.unit, h.tolerance, h.unit, h.base_value, h.shift
            );
        }
        out.push('\n');
        let mut raw = self.params;
        raw.tolerances = written.tolerances;
        out.push_str(&params_file::to_toml(&raw));
        out
    }

    /// The figure of `--plot`: the data against the fitted curves, the
    /// pressure difference [bar] per drop and the displacement [mm] over
    /// temperature.
    pub fn figure(
        &self,
        pressure: &[PressurePoint],
        displacement: Option<&[DisplacementPoint]>,
    ) -> crate::plot::Figure {
        use crate::plot::{Figure, Panel, Series};
        let core = &self.params.core;
        let (lo, hi) = pressure
            .iter()
            .map(|p| p.t_c)
            .chain(displacement.unwrap_or(&[]).iter().map(|p| p.t_c))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| (l.min(t), h.max(t)));
        let grid: Vec<f64> = (0..=100).map(|k| lo + (hi - lo) * k as f64 / 100.0).collect();
        let mut drops: Vec<f64> = pressure.iter().map(|p| p.dp_pa).collect();
        drops.sort_by(f64::total_cmp);
        drops.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        let many = drops.len() > 6;
        let mut series = Vec::new();
        if !many {
            for (i, &dp) in drops.iter().enumerate() {
                let mut pts: Vec<(f64, f64)> = pressure
                    .iter()
                    .filter(|p| (p.dp_pa - dp).abs() <= 1e-9 * dp)
                    .map(|p| (p.t_c, p.dp_ab_pa * 1e-5))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                // One legend entry per drop (the circles share the line's
                // colour): six entries would push the curves into a third
                // of the panel.
                series.push(Series {
                    color: Some(i),
                    ..Series::points(String::new(), pts)
                });
                let model = grid
                    .iter()
                    .filter_map(|&t| {
                        let p = PressurePoint {
                            t_c: t,
                            dp_pa: dp,
                            dp_ab_pa: 0.0,
                        };
                        pressure_residuals(core, &[p]).map(|r| (t, r[0] * 1e-5))
                    })
                    .collect();
                series.push(Series {
                    color: Some(i),
                    ..Series::line(format!("dp = {} bar", bar(dp)), model)
                });
            }
        } else {
            // Too many drops for one curve each: residuals against temperature.
            series.push(Series::points(
                "residual (model - measured)",
                pressure
                    .iter()
                    .zip(&self.pressure.fit.residuals)
                    .map(|(p, r)| (p.t_c, r * 1e-5))
                    .collect(),
            ));
        }
        let mut panels = vec![Panel {
            y_desc: if many {
                "residual p_b - p_a [bar]".into()
            } else {
                "p_b - p_a [bar]".into()
            },
            log_y: false,
            legend: true,
            series,
        }];
        if let Some(data) = displacement {
            let mut pts: Vec<(f64, f64)> = data.iter().map(|p| (p.t_c, p.x_m * 1e3)).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let model = grid
                .iter()
                .filter_map(|&t| model_displacement(core, t, None).map(|x| (t, x * 1e3)))
                .collect();
            panels.push(Panel {
                y_desc: "x [mm]".into(),
                log_y: false,
                legend: true,
                series: vec![
                    Series {
                        color: Some(0),
                        ..Series::points("measured", pts)
                    },
                    Series {
                        color: Some(0),
                        ..Series::line(format!("fitted, dp = {} bar", bar(core.pressure_drop)), model)
                    },
                ],
            });
        }
        Figure {
            title: "Calibration: measured (circles) and fitted (lines)".into(),
            x_desc: "temperature [C]".into(),
            panels,
        }
    }
}

/// A drop [Pa] in bar for a legend, without representation noise (`6`, not
/// `6.000000000000001`).
fn bar(dp: f64) -> String {
    let s = format!("{:.4}", dp * 1e-5);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Reads a data file given to `flag` (bounded like a parameter file), or
/// the built-in text `builtin` without a path.
fn data_text(path: Option<&Path>, flag: &str, builtin: &str) -> Result<String, CliError> {
    match path {
        Some(p) => crate::input::params_text(p, flag),
        None => Ok(builtin.to_string()),
    }
}

/// Options of `calibrate`.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Base parameter file whose geometry and dynamics are kept (`None`:
    /// the built-in `presets/model-example.toml`).
    pub base: Option<PathBuf>,
    /// Pressure data (`None`: the built-in paper Table 1, and its Table 2
    /// as displacement data unless `displacement` is given).
    pub pressure: Option<PathBuf>,
    /// Displacement data.
    pub displacement: Option<PathBuf>,
    /// Where to write the calibrated parameter file.
    pub write_preset: Option<PathBuf>,
    /// Where to draw the data against the fitted curves (SVG).
    pub plot: Option<PathBuf>,
}

/// What `calibrate` prints: the report table (standard output) and the
/// summary and warnings (standard error).
#[derive(Debug, Clone)]
pub struct Output {
    /// The report table, CSV.
    pub table: String,
    /// Lines for standard error.
    pub notes: Vec<String>,
}

/// `calibrate`: fits, writes the preset and the figure if asked, and
/// returns the report (see [`Calibration::table`]).
///
/// Errors: bad data or base file (exit 2, naming the file, row and
/// column), data that cannot determine the parameters (exit 2, naming
/// them), a fit that does not converge (exit 1).
pub fn calibrate(opts: &Options) -> Result<Output, CliError> {
    if opts.pressure.is_none() && opts.displacement.is_some() {
        return Err(CliError::Input(
            "--displacement-data: needs --pressure-data (the displacement fit runs at the oil the pressure data \
             give; without --pressure-data the paper's two tables are used together)"
                .into(),
        ));
    }
    let base = match &opts.base {
        Some(path) => crate::input::load_raw(path, "--params")?,
        None => params_file::parse(crate::input::MODEL_EXAMPLE)?,
    };
    let shown = |p: &Option<PathBuf>, d: &str| p.as_ref().map_or(d.to_string(), |p| p.display().to_string());
    let p_name = shown(&opts.pressure, crate::input::PAPER_PRESSURE_PATH);
    let pressure = read_pressure(&data_text(
        opts.pressure.as_deref(),
        "--pressure-data",
        crate::input::PAPER_PRESSURE_CSV,
    )?)
    .map_err(|e| CliError::Input(format!("--pressure-data: {p_name}: {e}")))?;
    let displacement_path = match (&opts.pressure, &opts.displacement) {
        (Some(_), Some(p)) => Some(Some(p.clone())),
        (None, _) => Some(None),
        (Some(_), None) => None,
    };
    let displacement = match &displacement_path {
        Some(path) => {
            let name = shown(path, crate::input::PAPER_DISPLACEMENT_PATH);
            let text = data_text(
                path.as_deref(),
                "--displacement-data",
                crate::input::PAPER_DISPLACEMENT_CSV,
            )?;
            Some(read_displacement(&text).map_err(|e| CliError::Input(format!("--displacement-data: {name}: {e}")))?)
        }
        None => None,
    };
    let params = compensator::Params::<f64>::new(&base).map_err(|e| CliError::Input(format!("--params: {e}")))?;
    let env = crate::envelope::Envelope::of(&base, &params);
    let outside = outside_validated(&env, &pressure, displacement.as_deref())?;
    let cal = fit(&base, &pressure, displacement.as_deref())?;
    let mut held = Vec::new();
    let mut command = format!(
        "compensator calibrate --base {} --pressure-data {p_name}",
        shown(&opts.base, "presets/model-example.toml")
    );
    if let Some(path) = &displacement_path {
        let _ = write!(
            command,
            " --displacement-data {}",
            shown(path, crate::input::PAPER_DISPLACEMENT_PATH)
        );
    }
    if let Some(path) = &opts.write_preset {
        let written = cal.written(&base)?;
        std::fs::write(path, cal.preset(&command, &written))
            .map_err(|e| CliError::Input(format!("--write-preset: {}: {e}", path.display())))?;
        held = written.held;
    }
    if let Some(path) = &opts.plot {
        crate::plot::write(path, &cal.figure(&pressure, displacement.as_deref()))?;
    }
    let mut notes = cal.summary();
    if outside > 0 {
        notes.push(format!(
            "WARNING: {outside} data rows lie outside the validated range {} (the fit extrapolates there)",
            env.validated_range()
        ));
    }
    notes.extend(cal.warnings.iter().map(|w| format!("WARNING: {w}")));
    notes.extend(held.iter().flat_map(held_notes));
    Ok(Output {
        table: cal.table(),
        notes,
    })
}

/// The data rows outside the validated range of `env`; every temperature
/// must be inside its oil model (refused naming the data and the row
/// otherwise).
fn outside_validated(
    env: &crate::envelope::Envelope,
    pressure: &[PressurePoint],
    displacement: Option<&[DisplacementPoint]>,
) -> Result<usize, CliError> {
    let mut outside = 0;
    for (flag, temps) in [
        ("--pressure-data", pressure.iter().map(|p| p.t_c).collect::<Vec<_>>()),
        (
            "--displacement-data",
            displacement
                .iter()
                .copied()
                .flatten()
                .map(|p| p.t_c)
                .collect::<Vec<_>>(),
        ),
    ] {
        for (i, &t) in temps.iter().enumerate() {
            let at = format!("{flag}: data row {}, column t_c", i + 1);
            if env.check(t, &at)? == crate::envelope::Zone::OilModel {
                outside += 1;
            }
        }
    }
    Ok(outside)
}

/// The notes on a field written with the base file's tolerance
/// ([`Written::held`]): that it is, and a warning when the fit lies far
/// from the base file's value.
fn held_notes(h: &Held) -> Vec<String> {
    let mut notes = vec![format!(
        "--write-preset: {}: its tolerance is the base file's, {:.3e} {} (the fit's standard error, {:.3e} {}, \
         is above a third of the value); the other fitted fields' covariance is conditioned on it",
        h.path, h.tolerance, h.unit, h.std_error, h.unit
    )];
    if h.shift > HELD_SHIFT_WARN {
        notes.push(format!(
            "WARNING: {}: the fitted value {} lies {:.2} standard errors from the base file's {}: the written \
             band assumes a value the base file does not support",
            h.path, h.value, h.shift, h.base_value
        ));
    }
    notes
}
