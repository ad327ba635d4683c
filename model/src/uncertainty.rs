//! The uncertainty of the estimate (GUM: standard uncertainties, `k = 1`;
//! a band of +-1.96 standard deviations is the 95 % interval where the
//! estimate's error is close to normal): what the model's figure cannot
//! know about the device it describes.
//!
//! Three sources, independent of each other:
//!
//! 1. the oil-temperature observer's own variance (it falls in a hold and
//!    grows in a fast change: [`crate::estimator::OilObserver::variance`]);
//! 2. the probe: its IEC 60751 class tolerance `+-(a + b |t|)`, a
//!    systematic error that does not average down, taken as uniform within
//!    the limits (variance `(a + b |t|)^2 / 3`, GUM 4.3.7), and the
//!    converter's resolution as a uniform error of one code (`code^2 /
//!    12`);
//! 3. the device's parameters: the standard uncertainties and correlations
//!    of the file's `[tolerances]` and `[[correlation]]`
//!    ([`crate::params::RawTolerances`]).
//!
//! Each reported quantity `y` (the displacement, both chamber pressures,
//! the total flow and the compensation error) is linearised at the
//! equilibrium (GUM 5.1.2, the law of propagation of uncertainty):
//!
//! ```text
//! u^2(y) = (dy/dT)^2 (u^2_observer + u^2_probe) + g' V g,   g_i = dy/dtheta_i
//! ```
//!
//! with `V` the parameters' covariance. `g' V g` is `sum_c (g . L_c)^2`
//! over the columns of `V`'s Cholesky factor `L` (`V = L L'`), each
//! `g . L_c` a central difference across `+-L_c`: a joint displacement of
//! one standard deviation of the device population (for uncorrelated
//! fields, one field by its standard uncertainty), computed
//! in `f64` on a grid of [`GRID`] temperatures over the oil range once
//! ([`UncertaintyTable::new`]: the firmware's build script does it on the
//! host); per refresh the estimator interpolates the grid linearly (ten
//! multiply-adds, six square roots).
//!
//! Near an end stop the displacement's error is not symmetric: the
//! sensitivities are those of the free displacement (`x_free`, the force
//! balance before the stops clamp it) and of the window flow extended
//! linearly past the stops, so the band `[x - 1.96 u, x + 1.96 u]`
//! clipped to the stroke holds the true displacement at least as often as
//! away from the stops (a device whose free displacement lies beyond the
//! stop sits on it, where the estimate is).

use crate::compensation::losses;
use crate::equilibrium::equilibrium;
use crate::error::ModelError;
use crate::params::{CORE_FIELDS, Field, MACHINE_FIELDS, ParamError, Params, RawParams};

/// Temperatures of the table, evenly spaced over the oil range: 17 keep
/// the interpolated standard deviations within 3 % of the ones computed
/// at the temperature (`tests::the_interpolated_band_is_the_band_computed_
/// there`) in 0.75 KiB.
pub const GRID: usize = 17;

/// The quantities whose uncertainty is tabulated, in this order.
pub const OUTPUTS: usize = 5;

/// Names of the [`OUTPUTS`] (the table's columns).
pub const OUTPUT_NAMES: [&str; OUTPUTS] = ["x", "p_a", "p_b", "q_total", "compensation_error"];

/// Why a table cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UncertaintyError {
    /// The nominal parameters are refused.
    Params(ParamError),
    /// A parameter's tolerance takes the device outside what the model
    /// accepts on both sides (`tolerances.section.key`).
    Tolerance(&'static str),
    /// The grid's range is not a finite, increasing interval.
    Range,
}

impl core::fmt::Display for UncertaintyError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            UncertaintyError::Params(e) => write!(f, "{e}"),
            UncertaintyError::Tolerance(path) => write!(
                f,
                "{path}: one standard uncertainty either way gives a device the model refuses"
            ),
            UncertaintyError::Range => f.write_str("the uncertainty grid's range must be finite and increasing"),
        }
    }
}

impl core::error::Error for UncertaintyError {}

impl From<ParamError> for UncertaintyError {
    fn from(e: ParamError) -> Self {
        UncertaintyError::Params(e)
    }
}

/// The standard uncertainties of one estimate (`k = 1`, SI units): the
/// band of 95 % is +-1.96 of each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uncertainty {
    /// Of the oil temperature \[C\].
    pub t_oil: f32,
    /// Of the displacement \[m\] (of the free displacement: see the module
    /// docs for the band at a stop).
    pub x: f32,
    /// Of the chamber (a) pressure \[Pa\].
    pub p_a: f32,
    /// Of the chamber (b) pressure \[Pa\].
    pub p_b: f32,
    /// Of the total flow [m^3/s].
    pub q_total: f32,
    /// Of the compensation error [m^3/s] (NaN without a `[machine]`).
    pub compensation_error: f32,
}

impl Uncertainty {
    /// No estimate yet: every entry infinite (unbounded), the compensation
    /// error's NaN.
    pub const UNKNOWN: Uncertainty = Uncertainty {
        t_oil: f32::INFINITY,
        x: f32::INFINITY,
        p_a: f32::INFINITY,
        p_b: f32::INFINITY,
        q_total: f32::INFINITY,
        compensation_error: f32::NAN,
    };
}

/// Sensitivities and parameter variances on a temperature grid
/// ([`UncertaintyTable::new`]); [`UncertaintyTable::at`] combines them
/// with the temperature's variance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UncertaintyTable {
    /// First grid temperature \[C\].
    pub t0: f32,
    /// Grid spacing \[C\].
    pub step: f32,
    /// `dy/dT` of each output at each grid temperature [unit/K] (NaN where
    /// the model refuses the temperature).
    pub slope: [[f32; OUTPUTS]; GRID],
    /// `sqrt(g' V g)`, each output's standard deviation from the
    /// parameters [unit] (interpolated as a deviation, not a variance: it
    /// is the nearer to linear in temperature).
    pub sd_params: [[f32; OUTPUTS]; GRID],
    /// The probe's standard deviation: class tolerance and resolution \[C\].
    pub sd_probe: [f32; GRID],
    /// The device has a `[machine]` (else the compensation error and its
    /// uncertainty are NaN).
    pub machine: bool,
}

/// The reported quantities at `t` for `p`: `x_free`, `p_a`, `p_b`, the
/// total flow with the window extended linearly past the stops, the
/// compensation error (NaN without a machine): [`OUTPUT_NAMES`], what the
/// table propagates.
///
/// # Errors
///
/// The equilibrium's, where the model refuses `t`.
pub fn outputs(p: &Params<f64>, t: f64) -> Result<[f64; OUTPUTS], ModelError> {
    let eq = equilibrium(p, t)?;
    let velocity = libm::sqrt(2.0 * p.pressure_drop / eq.fluid.density);
    let per_x = p.slot.discharge_coefficient * core::f64::consts::PI * p.slot.diameter * velocity;
    let q = eq.q_total + per_x * (eq.x_free - eq.x);
    // The machine's losses may be refused (its reference temperature
    // where the oil model is not used): the error alone is then unknown.
    let error = match &p.machine {
        Some(m) => losses(p, m, t).map_or(f64::NAN, |l| q - (m.working_flow + l)),
        None => f64::NAN,
    };
    Ok([eq.x_free, eq.p_a, eq.p_b, q, error])
}

/// `raw` with the field at `path` moved by `delta`.
fn moved(raw: &RawParams, path: &str, delta: f64) -> RawParams {
    let mut r = *raw;
    r.core = r.core.map(|n| if n.path == path { n.value + delta } else { n.value });
    if let Some(m) = &mut r.machine {
        *m = m.map(|n| if n.path == path { n.value + delta } else { n.value });
    }
    r
}

/// The outputs at `t` for `raw`, `None` where the parameters or the model
/// refuse.
fn outputs_of(raw: &RawParams, t: f64) -> Option<[f64; OUTPUTS]> {
    let p = Params::<f64>::new(raw).ok()?;
    outputs(&p, t).ok()
}

/// Every field that can carry a tolerance, with its standard uncertainty
/// in `raw` (zero ones included).
fn uncertain_fields(raw: &RawParams) -> impl Iterator<Item = (&'static Field, f64)> + '_ {
    CORE_FIELDS
        .iter()
        .zip(raw.tolerances.core.into_array())
        .chain(MACHINE_FIELDS.iter().zip(raw.tolerances.machine.into_array()))
}

/// The most fields with a tolerance (every compensator and machine field).
const MAX_FIELDS: usize = CORE_FIELDS.len() + MACHINE_FIELDS.len();

impl UncertaintyTable {
    /// The table for the device `raw` (its `[probe]` and `[tolerances]`)
    /// over `t_min..=t_max` \[C\], with the converter's resolution
    /// `resolution(t)` [C per code] at each grid temperature.
    ///
    /// # Errors
    ///
    /// [`UncertaintyError::Params`] for refused parameters,
    /// [`UncertaintyError::Tolerance`] naming a tolerance whose device is
    /// refused both one standard uncertainty up and down,
    /// [`UncertaintyError::Range`] for a range that is not finite and
    /// increasing. A temperature the model refuses is not an error: its
    /// row is NaN, and [`UncertaintyTable::at`] reports unbounded
    /// uncertainties there.
    pub fn new(
        raw: &RawParams,
        t_min: f64,
        t_max: f64,
        resolution: impl Fn(f64) -> f64,
    ) -> Result<Self, UncertaintyError> {
        if !(t_min.is_finite() && t_max.is_finite() && t_max > t_min) {
            return Err(UncertaintyError::Range);
        }
        let nominal = Params::<f64>::new(raw)?;
        raw.tolerances.validate(&raw.core, raw.machine.as_ref())?;
        let step = (t_max - t_min) / (GRID - 1) as f64;
        let mut table = UncertaintyTable {
            t0: t_min as f32,
            step: step as f32,
            slope: [[f32::NAN; OUTPUTS]; GRID],
            sd_params: [[f32::NAN; OUTPUTS]; GRID],
            sd_probe: [f32::NAN; GRID],
            machine: raw.machine.is_some(),
        };
        // The uncertain fields (nonzero tolerance), their sigmas and paths.
        let mut paths: [&str; MAX_FIELDS] = [""; MAX_FIELDS];
        let mut sigmas = [0.0f64; MAX_FIELDS];
        let mut n = 0;
        for (field, sigma) in uncertain_fields(raw) {
            if sigma > 0.0 && n < MAX_FIELDS {
                paths[n] = field.path;
                sigmas[n] = sigma;
                n += 1;
            }
        }
        // The covariance's square root: V = L L' (Cholesky, lower
        // triangular, fields in schema order). Column c of L is a joint
        // displacement of one standard deviation: the c-th field by its
        // conditional standard uncertainty, the later ones by what their
        // correlation with it carries along. g' V g = sum_c (g . L_c)^2,
        // and g . L_c is the difference across +-L_c: each difference
        // moves the device along the population's own spread, so a nearly
        // perfectly correlated pair (a calibrated Walther law, +0.99998)
        // is moved along its ridge and not across it by the full marginal
        // uncertainty of one member, whose curvature would not cancel.
        // Uncorrelated fields give L = diag(sigma): one field at a time.
        let mut chol = [[0.0f64; MAX_FIELDS]; MAX_FIELDS];
        for j in 0..n {
            let cov = |a: usize, b: usize| raw.tolerances.correlation(paths[a], paths[b]) * sigmas[a] * sigmas[b];
            let d = cov(j, j) - (0..j).map(|k| chol[j][k] * chol[j][k]).sum::<f64>();
            // Semi-definite (a field fully determined by earlier ones):
            // no displacement of its own. Parsed files are checked to be
            // semi-definite (`compensator_params::file`); a pivot below
            // rounding is taken as zero.
            let d = if d > 1e-18 * cov(j, j) { libm::sqrt(d) } else { 0.0 };
            chol[j][j] = d;
            for i in j + 1..n {
                let s = cov(i, j) - (0..j).map(|k| chol[i][k] * chol[j][k]).sum::<f64>();
                chol[i][j] = if d > 0.0 { s / d } else { 0.0 };
            }
        }
        // `raw` moved by `sign` times column `c`.
        let along = |c: usize, sign: f64| {
            let mut r = *raw;
            for (i, path) in paths.iter().enumerate().take(n).skip(c) {
                if chol[i][c] != 0.0 {
                    r = moved(&r, path, sign * chol[i][c]);
                }
            }
            r
        };
        // Which of the displaced parameter sets are valid devices.
        let mut up = [false; MAX_FIELDS];
        let mut down = [false; MAX_FIELDS];
        for c in 0..n {
            if chol[c][c] == 0.0 {
                continue;
            }
            up[c] = Params::<f64>::new(&along(c, 1.0)).is_ok();
            down[c] = Params::<f64>::new(&along(c, -1.0)).is_ok();
            if !up[c] && !down[c] {
                let tol = uncertain_fields(raw)
                    .find(|(f, _)| f.path == paths[c])
                    .map_or("tolerances", |(f, _)| f.tolerance_path);
                return Err(UncertaintyError::Tolerance(tol));
            }
        }
        for k in 0..GRID {
            let t = t_min + step * k as f64;
            let tol = raw.probe.tolerance_at(t);
            let res = resolution(t);
            table.sd_probe[k] = libm::sqrt(tol * tol / 3.0 + res * res / 12.0) as f32;
            let Ok(y0) = outputs(&nominal, t) else { continue };
            // dy/dT by a central difference of 0.05 K (the closed form is
            // smooth in T; the stops do not enter x_free).
            let h = 0.05;
            let (Ok(hi), Ok(lo)) = (outputs(&nominal, t + h), outputs(&nominal, t - h)) else {
                continue;
            };
            let mut var = [0.0f64; OUTPUTS];
            let mut ok = true;
            for c in 0..n {
                if chol[c][c] == 0.0 {
                    continue;
                }
                let yu = if up[c] { outputs_of(&along(c, 1.0), t) } else { None };
                let yd = if down[c] { outputs_of(&along(c, -1.0), t) } else { None };
                // g . L_c: the output's change over one standard
                // deviation along the column.
                let g: [f64; OUTPUTS] = match (yu, yd) {
                    (Some(u), Some(d)) => core::array::from_fn(|o| (u[o] - d[o]) / 2.0),
                    (Some(u), None) => core::array::from_fn(|o| u[o] - y0[o]),
                    (None, Some(d)) => core::array::from_fn(|o| y0[o] - d[o]),
                    (None, None) => {
                        ok = false;
                        break;
                    }
                };
                for o in 0..OUTPUTS {
                    var[o] += g[o] * g[o];
                }
            }
            if !ok {
                continue;
            }
            for o in 0..OUTPUTS {
                table.slope[k][o] = ((hi[o] - lo[o]) / (2.0 * h)) as f32;
                table.sd_params[k][o] = libm::sqrt(var[o]) as f32;
            }
        }
        Ok(table)
    }

    /// The standard uncertainties at the estimated oil temperature `t` \[C\]
    /// whose observer variance is `var_observer` [C^2]: the grid
    /// interpolated linearly (clamped to its ends), infinite where a
    /// neighbouring grid point is one the model refuses. The same as
    /// [`UncertaintyTable::lookup`], each [`UncertaintyTable::output`] and
    /// [`UncertaintyTable::assemble`] (what a caller that spreads the cost
    /// over several calls runs).
    pub fn at(&self, t: f32, var_observer: f32) -> Uncertainty {
        let lookup = self.lookup(t, var_observer);
        let mut sd = [0.0f32; OUTPUTS];
        for (o, s) in sd.iter_mut().enumerate() {
            *s = self.output(&lookup, o);
        }
        self.assemble(&lookup, sd)
    }

    /// Where `t` \[C\] falls on the grid and the oil temperature's
    /// variance there [C^2] (the observer's `var_observer` and the probe's
    /// tolerance): what [`UncertaintyTable::at`]'s outputs share.
    pub fn lookup(&self, t: f32, var_observer: f32) -> Lookup {
        let pos = (t - self.t0) / self.step;
        // NaN and beyond the ends: the end rows.
        let pos = if pos > 0.0 { pos } else { 0.0 };
        let last = (GRID - 1) as f32;
        let pos = if pos < last { pos } else { last };
        let k = (pos as usize).min(GRID - 2);
        let w = pos - k as f32;
        let sd_probe = lerp(w, self.sd_probe[k], self.sd_probe[k + 1]);
        Lookup {
            k,
            w,
            var_t: var_observer + sd_probe * sd_probe,
        }
    }

    /// The standard uncertainty of output `o` ([`OUTPUT_NAMES`]) at
    /// `lookup`; infinite where the model refuses a neighbouring grid
    /// point, and for an `o` beyond [`OUTPUTS`].
    pub fn output(&self, lookup: &Lookup, o: usize) -> f32 {
        let k = lookup.k.min(GRID - 2);
        let (Some(slope), Some(sd_params)) = (
            self.slope[k].get(o).zip(self.slope[k + 1].get(o)),
            self.sd_params[k].get(o).zip(self.sd_params[k + 1].get(o)),
        ) else {
            return f32::INFINITY;
        };
        let slope = lerp(lookup.w, *slope.0, *slope.1);
        let sd_params = lerp(lookup.w, *sd_params.0, *sd_params.1);
        let var = slope * slope * lookup.var_t + sd_params * sd_params;
        if var.is_nan() {
            f32::INFINITY
        } else {
            crate::scalar::Real::sqrt(var)
        }
    }

    /// The uncertainty from the outputs' standard uncertainties `sd` (in
    /// [`OUTPUT_NAMES`]' order) at `lookup`.
    pub fn assemble(&self, lookup: &Lookup, sd: [f32; OUTPUTS]) -> Uncertainty {
        let t_oil = crate::scalar::Real::sqrt(lookup.var_t);
        let [x, p_a, p_b, q_total, compensation_error] = sd;
        Uncertainty {
            t_oil,
            x,
            p_a,
            p_b,
            q_total,
            compensation_error: if self.machine { compensation_error } else { f32::NAN },
        }
    }
}

/// `a + w (b - a)`.
#[inline(always)]
fn lerp(w: f32, a: f32, b: f32) -> f32 {
    a + w * (b - a)
}

/// Where a temperature falls on an [`UncertaintyTable`]'s grid
/// ([`UncertaintyTable::lookup`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lookup {
    /// The grid row below.
    k: usize,
    /// The weight of the row above, in `[0, 1]`.
    w: f32,
    /// The oil temperature's variance [C^2].
    var_t: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper preset's design with a design office's tolerances.
    fn device() -> RawParams {
        let text = include_str!("../presets/model-example.toml");
        let raw = compensator_params::file::parse(text).unwrap();
        assert!(raw.tolerances.any());
        raw
    }

    /// The grid's linear interpolation against the table computed at the
    /// midpoints themselves (a grid shifted by half a step): within 4 % of
    /// the standard deviation over the validated range (measured 3.0 % at
    /// 17 points over -20..150 C; 33 points would give 0.9 %).
    #[test]
    fn the_interpolated_band_is_the_band_computed_there() {
        let raw = device();
        let e = &raw.estimator;
        let res = |t: f64| e.resolution(t);
        let a = UncertaintyTable::new(&raw, e.oil_min, e.oil_max, res).unwrap();
        let half = f64::from(a.step) / 2.0;
        let b = UncertaintyTable::new(&raw, e.oil_min + half, e.oil_max + half, res).unwrap();
        let mut worst = 0.0f32;
        for k in 0..GRID - 1 {
            let t = b.t0 + b.step * k as f32;
            if !(f64::from(t) >= e.valid_min - 5.0 && f64::from(t) <= e.valid_max + 5.0) {
                continue;
            }
            let (ua, ub) = (a.at(t, 1e-4), b.at(t, 1e-4));
            for (x, y) in [
                (ua.x, ub.x),
                (ua.p_a, ub.p_a),
                (ua.q_total, ub.q_total),
                (ua.t_oil, ub.t_oil),
            ] {
                worst = worst.max((x / y - 1.0).abs());
            }
        }
        eprintln!("worst interpolation error {worst}");
        assert!(worst < 0.04, "{worst}");
    }
}
