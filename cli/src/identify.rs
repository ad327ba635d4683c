//! Identification of the dynamic parameters from a measured transient: the
//! `identify` command.
//!
//! Static data cannot give the plunger's mass, its viscous damping, or the
//! chambers' compliance (volume over bulk modulus): they only shape how
//! the plunger gets to its equilibrium. `identify` simulates the measured
//! temperature history with the dynamic twin in `f64` (the core's SDIRK3
//! twin, `docs/dynamics.md`, at the substeps the twin-config chooser picks
//! for the data's sample interval) and fits those parameters to the
//! measured displacement (and chamber pressures when given) by least
//! squares ([`crate::lsq`]).
//!
//! Why the twin rather than the adaptive reference solver: a fit evaluates
//! the model some tens of times per parameter, and the twin follows an
//! arbitrary sampled temperature history tick by tick at microseconds per
//! tick, where the reference solver follows only a step or a ramp
//! (`compensator_reference::dynamics::Profile`) and costs milliseconds per
//! sample. Its error on the paper preset is 0.043 % of a step against the
//! reference (`cargo test -p host-tests --test dynamics`), well below any
//! displacement sensor's noise. The tests generate their data with the
//! reference solver, so the fit is checked against an independent model.
//!
//! Data: `time_s,t_c,x_m` (optionally `p_a_pa,p_b_pa`), uniformly sampled,
//! starting at rest (the twin starts in the equilibrium of the first
//! temperature). Tick `k` (from sample `k` to `k + 1`) runs at sample
//! `k + 1`'s temperature, as the firmware ticks on its newest reading, so a
//! step between the first two samples is a step at `t = 0`.
//!
//! Parameters are fitted in logarithmic coordinates (mass, bulk modulus,
//! volumes) or scaled linear ones (the damping, which may be zero:
//! [`Coord`]). Standard errors are those of [`crate::lsq::analyse`]
//! (with pressures, each channel weighted by its own residual RMS after a
//! first fit); the 95 % interval is the profile-likelihood one
//! ([`Estimate::ci95`]). At least [`MIN_DOF`] degrees of freedom are
//! required.
//!
//! Identifiability: a parameter is reported as *not identifiable* when
//! the Jacobian cannot separate it (rank-deficient, [`crate::lsq::RANK_TOL`]),
//! its relative standard error exceeds [`crate::calibration::REL_SE_LIMIT`]
//! (50 %), it runs to the edge of its plausible range, its information
//! comes from fewer than [`MIN_EFFECTIVE_SAMPLES`] samples, or its profile
//! likelihood is flat ([`PROFILE_MIN_RISE`], [`PROFILE_FAR`]). It is then
//! fixed at the base file's value and the others are fitted again without
//! it, until every remaining parameter is determined. Its value is not
//! printed (the fit's number for it would be noise).

use crate::csv::read_columns;
use crate::dynamics::chosen;
use crate::error::CliError;
use crate::lsq::{self, Undetermined};
use crate::params_file;
use compensator::Params;
use compensator::dynamics::twin::MAX_SUBSTEPS;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::params::{Field, Kind, RawCore, RawParams};
use std::fmt::Write as _;
use std::path::PathBuf;

pub mod search;

/// Fewest degrees of freedom `identify` accepts (its intervals use the
/// normal quantile 1.96; at 30 degrees of freedom Student's is 2.04).
pub const MIN_DOF: usize = 30;

/// The twin runs this many times the substeps the twin-config chooser
/// picks for the base file (at most `MAX_SUBSTEPS`): the chooser keeps the
/// error within 0.1 % of a step for that design, and the fit visits others
/// (a softer oil, a heavier plunger) whose error must stay well below the
/// measurement noise too.
pub const SUBSTEP_FACTOR: u8 = 4;

/// Profile-likelihood check: moving a parameter by two standard errors
/// (re-fitting the others) must raise the residual sum of squares by at
/// least this fraction of the `4 s^2` a linear model would give; a flatter
/// profile means the local standard error is not the data's word (Raue et
/// al., Bioinformatics 25 (2009) 1923: structural and practical
/// non-identifiability from the profile likelihood).
pub const PROFILE_MIN_RISE: f64 = 0.25;

/// Second profile check: a value this factor smaller or larger (or the
/// edge of the plausible range, if nearer) must be rejected by the data at
/// 95 % — the residual sum of squares, the others re-fitted, up by at
/// least [`CHI2_95`] `s^2`. A parameter whose profile stays under that
/// threshold up to there has a confidence region open on that side (the
/// bulk modulus in the stiff limit, where the chambers' compliance no
/// longer shows) even if its local standard error looks small.
pub const PROFILE_FAR: f64 = 10.0;

/// Fewest samples a parameter's information may come from: the
/// participation ratio `(sum J_i^2)^2 / sum J_i^4` of its Jacobian column
/// (`n` when every residual is equally sensitive, 1 when one is). A
/// parameter seen by a handful of samples (the bulk modulus, in the first
/// millisecond after a step) would be fitted to their noise, with an
/// interval the asymptotic theory does not cover. The identification
/// campaign (docs/calibration.md) sets the figure: with 10, the bulk
/// modulus of x-only records of underdamped designs, its information in
/// 14-17 samples after the step, passed in 12 of 80 designs and its
/// interval missed the truth in 5 of them (the records where noise happens
/// to look like compliance are the ones where it passes); the mass of an
/// overdamped design, the least-sampled parameter identified honestly
/// there, draws on 22-32.
pub const MIN_EFFECTIVE_SAMPLES: f64 = 20.0;

/// Bisection steps locating each end of a profile-likelihood interval
/// (the bracket, a factor [`PROFILE_FAR`] wide, shrinks to 2^-12 of it).
pub const PROFILE_BISECTIONS: usize = 12;

/// 95 % quantile of chi-square with one degree of freedom.
pub const CHI2_95: f64 = 3.841;

/// A parameter whose fitted coordinate lies within this much (of its
/// range in fit coordinates, at most 1) of a bound has run to the bound:
/// 0.1 % of the value in logarithmic coordinates.
pub const EDGE: f64 = 1e-3;

/// The fit from the base file's values alone is reported as having
/// stopped in a local minimum when its residual sum of squares exceeds the
/// best fit's by this factor (one part in a thousand is rounding and the
/// minimiser's tolerance).
pub const STALL_FACTOR: f64 = 1.001;

/// Relative spread of the sample intervals accepted as uniform.
pub const UNIFORM_TOL: f64 = 1e-6;

/// A measured transient.
#[derive(Debug, Clone, PartialEq)]
pub struct Transient {
    /// Sample times [s], uniform.
    pub time_s: Vec<f64>,
    /// Oil temperature [C] per sample.
    pub t_c: Vec<f64>,
    /// Displacement [m] per sample.
    pub x_m: Vec<f64>,
    /// Chamber pressures `(p_a, p_b)` [Pa] per sample, if measured.
    pub p_pa: Option<Vec<(f64, f64)>>,
}

impl Transient {
    /// Sample interval [s].
    pub fn tick(&self) -> f64 {
        (self.time_s[self.time_s.len() - 1] - self.time_s[0]) / (self.time_s.len() - 1) as f64
    }
}

/// Reads `time_s,t_c,x_m[,p_a_pa,p_b_pa]` (other columns are ignored).
///
/// Errors (naming row and column): a missing column, a cell that is not a
/// finite number, fewer than 3 rows, sample times not increasing or not
/// uniform (within [`UNIFORM_TOL`] of the first interval), only one of the
/// two pressure columns.
pub fn read_transient(text: &str) -> Result<Transient, String> {
    let t = read_columns(text, &["time_s", "t_c", "x_m", "p_a_pa", "p_b_pa"])?;
    let col = |n: &str| {
        t.column(n).ok_or_else(|| {
            format!(
                "no column {n} (columns: {}; expected time_s,t_c,x_m[,p_a_pa,p_b_pa])",
                t.header.join(",")
            )
        })
    };
    let (ct, cc, cx) = (col("time_s")?, col("t_c")?, col("x_m")?);
    let pressures = match (t.column("p_a_pa"), t.column("p_b_pa")) {
        (Some(a), Some(b)) => Some((a, b)),
        (None, None) => None,
        (Some(_), None) => return Err("column p_a_pa without p_b_pa: give both chamber pressures or neither".into()),
        (None, Some(_)) => return Err("column p_b_pa without p_a_pa: give both chamber pressures or neither".into()),
    };
    if t.rows.len() < 3 {
        return Err(format!("{} data rows: a transient needs at least 3", t.rows.len()));
    }
    let time: Vec<f64> = t.rows.iter().map(|r| r[ct]).collect();
    let first = time[1] - time[0];
    for i in 1..time.len() {
        let dt = time[i] - time[i - 1];
        if !(dt > 0.0) || (dt - first).abs() > UNIFORM_TOL * first.abs() {
            return Err(format!(
                "row {} (line {}), column time_s: interval {dt} s after the previous sample; the samples \
                 must be uniform (the first interval is {first} s, tolerance {UNIFORM_TOL} relative)",
                i + 1,
                t.lines[i]
            ));
        }
    }
    Ok(Transient {
        time_s: time,
        t_c: t.rows.iter().map(|r| r[cc]).collect(),
        x_m: t.rows.iter().map(|r| r[cx]).collect(),
        p_pa: pressures.map(|(a, b)| t.rows.iter().map(|r| (r[a], r[b])).collect()),
    })
}

/// The dynamic parameters `identify` can fit, by their path in the
/// parameter file.
pub const CANDIDATES: [&str; 5] = [
    "plunger.mass",
    "plunger.damping",
    "fluid.bulk_modulus",
    "chambers.volume_a",
    "chambers.volume_b",
];

/// Fitted by default: the chambers' volumes and the bulk modulus enter
/// only as the compliances `V / beta`, so the bulk modulus stands for both.
pub const DEFAULT_FIT: [&str; 3] = ["plunger.mass", "plunger.damping", "fluid.bulk_modulus"];

/// Checks that every path of `fit` names a field of `base`
/// ([`RawParams::get`]): an unknown name, or a `[machine]` field of a set
/// without that section, is bad input naming it. The fit then reads and
/// writes those fields ([`get`], [`set`], [`field`]) in copies of `base`,
/// which have its sections, so that by name cannot fail.
fn check_fit(base: &RawParams, fit: &[&'static str]) -> Result<(), CliError> {
    for path in fit {
        base.get(path).map_err(|e| CliError::Input(format!("--fit: {e}")))?;
    }
    Ok(())
}

/// The schema's field of a path [`check_fit`] accepted (`plunger.mass`).
fn field(path: &str) -> &'static Field {
    compensator_params::field_by_path(path).expect("check_fit accepted the fit's paths")
}

/// Sets the field `path` of `raw` ([`RawParams::set`], the schema's access
/// by name) to `v`; `path` is one [`check_fit`] accepted.
fn set(raw: &mut RawParams, path: &str, v: f64) {
    raw.set(path, v)
        .unwrap_or_else(|e| panic!("{e}: check_fit accepted the fit's paths"));
}

/// The field `path` of `raw` ([`RawParams::get`]); `path` is one
/// [`check_fit`] accepted.
fn get(raw: &RawParams, path: &str) -> f64 {
    raw.get(path)
        .unwrap_or_else(|e| panic!("{e}: check_fit accepted the fit's paths"))
}

/// Parses `--fit`: a comma list of [`CANDIDATES`] (the part after the dot
/// is enough: `mass,damping`).
pub fn parse_fit(list: &str) -> Result<Vec<&'static str>, String> {
    let mut out: Vec<&'static str> = Vec::new();
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let path = CANDIDATES
            .iter()
            .find(|c| **c == item || c.split('.').nth(1) == Some(item))
            .ok_or_else(|| format!("'{item}' is not one of {}", CANDIDATES.join(", ")))?;
        if !out.contains(path) {
            out.push(path);
        }
    }
    if out.is_empty() {
        return Err("no parameter to fit".into());
    }
    Ok(out)
}

/// Simulated `(x, p_a, p_b)` at every sample of `data` with the twin in
/// `f64`; `None` where the model cannot run (parameters refused, a
/// temperature outside the oil model, a failed tick).
pub fn simulate(core: &RawCore, config: TwinConfig, data: &Transient) -> Option<Vec<[f64; 3]>> {
    let params = Params::<f64>::from_core(core, None).ok()?;
    let mut twin = Twin::<f64, f64>::new(&params, config, data.t_c[0]).ok()?;
    let mut out = Vec::with_capacity(data.t_c.len());
    let s = twin.state();
    out.push([s.x, s.p_a, s.p_b]);
    for &t in &data.t_c[1..] {
        twin.set_temperature(t).ok()?;
        twin.tick().ok()?;
        let s = twin.state();
        out.push([s.x, s.p_a, s.p_b]);
    }
    Some(out)
}

/// Coordinates a parameter is fitted in: the logarithm (positive
/// parameters: mass, bulk modulus, volumes), or the value over a scale
/// (the damping, which may be zero: in `ln b` the fit would lose its
/// gradient as `b -> 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coord {
    /// `u = ln v`.
    Log,
    /// `u = v / scale`.
    Linear(f64),
}

impl Coord {
    /// The coordinates of field `f` for a fit starting from the value
    /// `base` (linear for a field that may be zero: the damping).
    pub fn of(f: &Field, base: f64) -> Coord {
        if f.kind == Kind::OrZero {
            Coord::Linear(base.max(1e-2))
        } else {
            Coord::Log
        }
    }
    /// Value from coordinate.
    pub fn value(self, u: f64) -> f64 {
        match self {
            Coord::Log => u.exp(),
            Coord::Linear(s) => u * s,
        }
    }
    /// Coordinate from value (a non-positive value in log coordinates
    /// becomes the field's smallest plausible one).
    pub fn coord(self, v: f64, min: f64) -> f64 {
        match self {
            Coord::Log => v.max(min).max(1e-300).ln(),
            Coord::Linear(s) => v / s,
        }
    }
    /// The plausible range of field `f` in these coordinates (a field
    /// that may be zero starts at zero: `Linear` only).
    pub fn range(self, f: &Field) -> (f64, f64) {
        let lo = if f.kind == Kind::OrZero { 0.0 } else { f.min };
        match self {
            Coord::Log => (f.min.ln(), f.max.ln()),
            Coord::Linear(s) => (lo / s, f.max / s),
        }
    }
    /// Standard error of the value from that of the coordinate at `u`.
    pub fn std_error(self, u: f64, se: f64) -> f64 {
        match self {
            Coord::Log => u.exp() * se,
            Coord::Linear(s) => s * se,
        }
    }
    /// 95 % interval of the value: `exp(u +- 1.96 se)` or
    /// `(u +- 1.96 se) scale` (not below zero).
    pub fn interval(self, u: f64, se: f64) -> (f64, f64) {
        match self {
            Coord::Log => ((u - 1.96 * se).exp(), (u + 1.96 * se).exp()),
            Coord::Linear(s) => (((u - 1.96 * se) * s).max(0.0), (u + 1.96 * se) * s),
        }
    }
}

/// A parameter the data determine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Value.
    pub value: f64,
    /// Standard error (same unit).
    pub std_error: f64,
    /// 95 % profile-likelihood interval: the values where the residual sum
    /// of squares, the other parameters re-fitted, exceeds its minimum by
    /// [`CHI2_95`] `s^2` (Venzon and Moolgavkar, Appl. Statist. 37 (1988)
    /// 87). Unlike the Wald interval it follows the model's nonlinearity.
    pub ci95: (f64, f64),
    /// 95 % Wald interval from the standard error ([`Coord::interval`]).
    pub wald95: (f64, f64),
}

/// One dynamic parameter's outcome.
#[derive(Debug, Clone)]
pub struct Identified {
    /// Parameter path (`plunger.mass`).
    pub path: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// The estimate when the data determine it; `None` when they do not
    /// (see `reason`).
    pub estimate: Option<Estimate>,
    /// Why it is not identifiable (empty when it is).
    pub reason: String,
    /// The value in [`Identification::params`]: the estimate, or for a
    /// parameter not identified the base file's value or the bound its
    /// best fit ran to.
    pub held: f64,
}

/// The fit of the parameters `free` from `start`: their coordinates
/// ([`Coord::of`], from the base file's values), plausible ranges in those
/// coordinates, starting point and difference steps, and the residuals
/// the minimiser sees.
struct Problem<'a> {
    /// The base parameter set (the weights' floors, the coordinates).
    base: &'a RawParams,
    /// The set the free parameters are written into.
    start: RawParams,
    free: Vec<&'static str>,
    coords: Vec<Coord>,
    ranges: Vec<(f64, f64)>,
    u0: Vec<f64>,
    step: Vec<f64>,
    config: TwinConfig,
    data: &'a Transient,
    scales: Scales,
}

impl<'a> Problem<'a> {
    fn new(
        base: &'a RawParams,
        start: RawParams,
        free: Vec<&'static str>,
        config: TwinConfig,
        data: &'a Transient,
        scales: Scales,
    ) -> Self {
        let coords: Vec<Coord> = free.iter().map(|p| Coord::of(field(p), get(base, p))).collect();
        let ranges = free.iter().zip(&coords).map(|(p, k)| k.range(field(p))).collect();
        let u0: Vec<f64> = free
            .iter()
            .zip(&coords)
            .map(|(p, k)| k.coord(get(&start, p), field(p).min))
            .collect();
        let step = vec![1e-5; u0.len()];
        Problem {
            base,
            start,
            free,
            coords,
            ranges,
            u0,
            step,
            config,
            data,
            scales,
        }
    }

    fn bounds(&self) -> search::Bounds {
        search::Bounds {
            lo: self.ranges.iter().map(|r| r.0).collect(),
            hi: self.ranges.iter().map(|r| r.1).collect(),
        }
    }

    /// The parameter set at fit coordinates `u` ([`with_values`]).
    fn with(&self, u: &[f64]) -> RawParams {
        with_values(&self.start, &self.free, &self.coords, u)
    }

    /// The weighted residuals at fit coordinates `u` (`None` where the
    /// twin cannot run).
    fn residuals(&self, u: &[f64]) -> Option<Vec<f64>> {
        residuals(&self.with(u), self.config, self.data, self.scales)
    }

    /// The estimate of free parameter `i` at the optimum `x` with
    /// standard errors `se` and profile-likelihood interval `ci95`.
    fn estimate(&self, i: usize, x: &[f64], se: &[f64], ci95: (f64, f64)) -> Estimate {
        let k = self.coords[i];
        Estimate {
            value: k.value(x[i]),
            std_error: k.std_error(x[i], se[i]),
            ci95,
            wald95: k.interval(x[i], se[i]),
        }
    }

    /// The parameter along a direction the Jacobian does not see
    /// (`confounded`, [`Undetermined::RankDeficient`]; `when`: where the
    /// Jacobian was taken), dropped for good.
    fn unseen(&self, confounded: &[String], when: &str) -> Step {
        let worst = confounded.first().map(String::as_str).unwrap_or(self.free[0]);
        let path = *self.free.iter().find(|p| **p == worst).unwrap_or(&self.free[0]);
        Step::Drop {
            path,
            reason: unseen_reason(path, confounded, when),
            structural: true,
        }
    }

    /// One round of the fit: the parameters the Jacobian cannot see at the
    /// start dropped first, then the best fit ([`search::best_fit`]), the
    /// pressures' and the displacement's weights set once from their own
    /// misfit, a parameter run to a bound pinned there ([`Self::at_edge`])
    /// and the optimum judged ([`Self::judge`]). A remark on a fit from the
    /// base values that stopped in a local minimum goes to `notes`.
    fn round(&self, reweighted: &mut bool, notes: &mut Vec<String>) -> Result<Step, CliError> {
        let names: Vec<&str> = self.free.to_vec();
        let f = |u: &[f64]| self.residuals(u);
        // Directions the data do not see at the start are dropped first.
        if let Some(j0) = lsq::jacobian(f, &self.u0, &self.step)
            && let Err(Undetermined::RankDeficient { confounded, .. }) = lsq::check_design(&j0, &names)
        {
            return Ok(self.unseen(&confounded, "at the start"));
        }
        let found = search::best_fit(&f, &self.u0, &self.step, &self.bounds())
            .map_err(|e| CliError::Failed(format!("--data: {e}")))?;
        if found.rss_from_start > STALL_FACTOR * found.rss() {
            notes.push(format!(
                "the fit of {} from the base file's values stopped in a local minimum, at {:.1} times the \
                 residual sum of squares of the best of {} fits started from sub-fits' optima (reported)",
                self.free.join(", "),
                found.rss_from_start / found.rss(),
                found.minimisations
            ));
        }
        let fit = found.fit;
        // Second pass on the channels' own misfit (pressures and
        // displacement weighted by their residual RMS at the optimum).
        if !*reweighted {
            *reweighted = true;
            if let Some((rx, Some(rp))) = channel_rms(&self.with(&fit.x), self.config, self.data) {
                return Ok(Step::Reweighted(Scales {
                    x: rx.max(1e-9 * self.base.core.stroke),
                    p: rp.max(1e-9 * self.base.core.pressure_drop),
                }));
            }
        }
        // Which parameter goes first when several fail a check: the
        // chambers' compliance before the plunger's (NUISANCE).
        let order = priority(&self.free);
        if let Some(pin) = self.at_edge(&order, &fit.x) {
            return Ok(pin);
        }
        match lsq::analyse(&fit.jacobian, &fit.residuals, &names) {
            Err(Undetermined::RankDeficient { confounded, .. }) => Ok(self.unseen(&confounded, "at the optimum")),
            Err(e) => Err(CliError::Input(format!("--data: {e}"))),
            Ok(u) => Ok(self.judge(&order, fit, u)),
        }
    }

    /// A parameter whose best fit `x` lies on the edge of its plausible
    /// range is bounded by the data from one side only: pinned there, the
    /// others refitted without it (the profile along it, whose minimum is
    /// then interior). The first of `order` that is.
    fn at_edge(&self, order: &[usize], x: &[f64]) -> Option<Step> {
        let i = order.iter().copied().find(|&i| {
            let (lo, hi) = self.ranges[i];
            x[i] >= hi - EDGE * (hi - lo).min(1.0) || x[i] <= lo + EDGE * (hi - lo).min(1.0)
        })?;
        let f = field(self.free[i]);
        let (lo, hi) = self.ranges[i];
        let upper = x[i] > 0.5 * (lo + hi);
        let value = if upper {
            f.max
        } else {
            self.coords[i]
                .value(lo)
                .max(if f.kind == Kind::OrZero { 0.0 } else { f.min })
        };
        Some(Step::Pin {
            path: self.free[i],
            value,
            reason: format!(
                "its best fit lies at the {} edge of its plausible range (docs/parameters.md), {value:e} {}: the \
                 data bound it from one side only",
                if upper { "upper" } else { "lower" },
                f.unit
            ),
        })
    }

    /// The optimum `fit` with uncertainty `u` judged, the parameters in
    /// `order`: the first (by [`rank`]) with a relative standard error
    /// above [`crate::calibration::REL_SE_LIMIT`], then the first whose
    /// information comes from fewer than [`MIN_EFFECTIVE_SAMPLES`]
    /// samples, then the first whose profile is flat or open on a side,
    /// is dropped; with none, the fit is accepted.
    fn judge(&self, order: &[usize], fit: lsq::Fit, u: lsq::Uncertainty) -> Step {
        let free = &self.free;
        let drop = |i: usize, reason: String| Step::Drop {
            path: free[i],
            reason,
            structural: false,
        };
        let se = u.std_errors();
        let rel_se = |i: usize| {
            let v = self.coords[i].value(fit.x[i]);
            self.coords[i].std_error(fit.x[i], se[i]) / v.abs()
        };
        if let Some((worst, rel)) = order
            .iter()
            .map(|&i| (i, rel_se(i)))
            .filter(|(_, rel)| !(*rel <= crate::calibration::REL_SE_LIMIT))
            .min_by(|a, b| rank(free, a.0).cmp(&rank(free, b.0)).then(b.1.total_cmp(&a.1)))
        {
            return drop(
                worst,
                format!(
                    "relative standard error {:.0} % (above {:.0} %): the data do not determine it",
                    100.0 * rel,
                    100.0 * crate::calibration::REL_SE_LIMIT
                ),
            );
        }
        // Where the information comes from: the participation ratio of
        // each Jacobian column (MIN_EFFECTIVE_SAMPLES).
        let effective = |j: usize| {
            let col = fit.jacobian.column(j);
            let s2: f64 = col.iter().map(|v| v * v).sum();
            let s4: f64 = col.iter().map(|v| v.powi(4)).sum();
            if s4 > 0.0 { s2 * s2 / s4 } else { 0.0 }
        };
        if let Some((i, n_eff)) = order
            .iter()
            .map(|&i| (i, effective(i)))
            .filter(|(_, n)| !(*n >= MIN_EFFECTIVE_SAMPLES))
            .min_by(|a, b| rank(free, a.0).cmp(&rank(free, b.0)).then(a.1.total_cmp(&b.1)))
        {
            return drop(
                i,
                format!(
                    "its effect is concentrated in about {n_eff:.1} samples (fewer than {MIN_EFFECTIVE_SAMPLES}): a \
                     fit to so few points adapts to their noise, and no interval from them can be trusted"
                ),
            );
        }
        match self.profiles(order, &fit, &u) {
            Err((i, reason)) => drop(i, reason),
            Ok(ci) => Step::Accept(Box::new(self.with(&fit.x)), (u, fit.x, self.coords.clone(), ci)),
        }
    }

    /// The profile checks ([`PROFILE_MIN_RISE`], [`PROFILE_FAR`]) of the
    /// optimum `fit` with uncertainty `u`, in `order`: every parameter's
    /// 95 % profile-likelihood interval, or the first parameter that fails
    /// and why.
    fn profiles(
        &self,
        order: &[usize],
        fit: &lsq::Fit,
        u: &lsq::Uncertainty,
    ) -> Result<Vec<(f64, f64)>, (usize, String)> {
        let f = |v: &[f64]| self.residuals(v);
        let se = u.std_errors();
        let rss0: f64 = fit.residuals.iter().map(|r| r * r).sum();
        let mut ci = vec![(0.0, 0.0); self.free.len()];
        for &i in order {
            let near = (profile(&f, &fit.x, i, 2.0 * se[i], &self.step) - rss0) / (4.0 * u.s2);
            if !(near >= PROFILE_MIN_RISE) {
                return Err((
                    i,
                    format!(
                        "moving it by two standard errors raises the misfit by {:.0} % of what its standard error \
                         implies (flat profile likelihood): the data do not determine it",
                        100.0 * near.max(0.0)
                    ),
                ));
            }
            ci[i] = profile_interval(
                &f,
                &fit.x,
                i,
                self.coords[i],
                field(self.free[i]),
                rss0,
                u.s2,
                &self.step,
            )
            .map_err(|reason| (i, reason))?;
        }
        Ok(ci)
    }
}

/// What one round of the fit ([`Problem::round`]) decided.
enum Step {
    /// Fit again with the channels weighted by these scales.
    Reweighted(Scales),
    /// `path` is not identifiable (`structural`: the response does not
    /// separate it, [`Held::structural`]).
    Drop {
        path: &'static str,
        reason: String,
        structural: bool,
    },
    /// `path`'s best fit lies on a bound, `value`: held there.
    Pin {
        path: &'static str,
        value: f64,
        reason: String,
    },
    /// Every free parameter determined: the fitted set and the fit.
    Accept(Box<RawParams>, Accepted),
}

/// The joint fit: the identified parameters of `results` and the
/// `nuisance` ones (not identifiable, but not structurally so) all free,
/// from `start` (the identified values, the nuisance ones where they were
/// held), with the sub-fit search ([`search::best_fit`]). Each identified
/// parameter's value, standard error and profile-likelihood interval are
/// replaced by the joint fit's (the interval maximised over the nuisance
/// parameters too: a profile in the statistical sense); one whose relative
/// standard error then exceeds [`crate::calibration::REL_SE_LIMIT`] or
/// whose profile stays open on one side is reported not identifiable. The
/// nuisance parameters are held at their joint best fit. Returns the
/// joint fit's parameter set and uncertainty.
///
/// Errors: the joint fit fails or its Jacobian is rank-deficient (the
/// caller keeps the results it had).
#[allow(clippy::too_many_arguments)]
fn joint(
    base: &RawParams,
    start: &RawParams,
    fit: &[&'static str],
    nuisance: &[&'static str],
    results: &mut [Identified],
    config: TwinConfig,
    data: &Transient,
    scales: Scales,
) -> Result<(RawParams, lsq::Uncertainty), String> {
    let free: Vec<&'static str> = fit
        .iter()
        .copied()
        .filter(|p| nuisance.contains(p) || results.iter().any(|r| r.path == *p && r.estimate.is_some()))
        .collect();
    let problem = Problem::new(base, *start, free, config, data, scales);
    let (free, coords, step) = (&problem.free, &problem.coords, &problem.step);
    let f = |u: &[f64]| problem.residuals(u);
    let found = search::best_fit(&f, &problem.u0, step, &problem.bounds())?;
    let x = found.fit.x.clone();
    let names: Vec<&str> = free.to_vec();
    let u = lsq::analyse(&found.fit.jacobian, &found.fit.residuals, &names).map_err(|e| e.to_string())?;
    let se = u.std_errors();
    let rss0 = found.rss();
    for r in results.iter_mut() {
        let Some(i) = free.iter().position(|p| *p == r.path) else {
            continue;
        };
        if nuisance.contains(&r.path) {
            continue;
        }
        let estimate = problem.estimate(i, &x, &se, (0.0, 0.0));
        let rel = estimate.std_error / estimate.value.abs();
        let verdict = if !(rel <= crate::calibration::REL_SE_LIMIT) {
            Err(format!(
                "relative standard error {:.0} % (above {:.0} %) with {} fitted too: the data determine it \
                 only together with them",
                100.0 * rel,
                100.0 * crate::calibration::REL_SE_LIMIT,
                nuisance.join(", ")
            ))
        } else {
            profile_interval(&f, &x, i, coords[i], field(r.path), rss0, u.s2, step)
                .map_err(|e| format!("with {} fitted too, {e}", nuisance.join(", ")))
        };
        match verdict {
            Ok(ci95) => r.estimate = Some(Estimate { ci95, ..estimate }),
            Err(reason) => {
                r.estimate = None;
                r.reason = reason;
            }
        }
    }
    let raw = problem.with(&x);
    for r in results.iter_mut() {
        r.held = get(&raw, r.path);
    }
    Ok((raw, u))
}

/// `start` with the parameters `free` set from fit coordinates `u`,
/// clamped into their plausible ranges (a value between zero and the
/// smallest plausible one of a field that may be zero is zero: the gap is
/// refused).
fn with_values(start: &RawParams, free: &[&'static str], coords: &[Coord], u: &[f64]) -> RawParams {
    let mut c = *start;
    for ((p, v), k) in free.iter().zip(u).zip(coords) {
        let f = field(p);
        // exp(ln max) may round above max.
        let v = k.value(*v).min(f.max);
        set(
            &mut c,
            p,
            if f.kind == Kind::OrZero && v < f.min {
                0.0
            } else {
                v.max(f.min)
            },
        );
    }
    c
}

/// The parameters not fitted, and where they are held.
struct Held {
    /// The base file's values.
    base: RawParams,
    /// The base file's values, with the pinned parameters at their bound.
    fixed: RawParams,
    /// Not identifiable: held at the base file's value.
    dropped: Vec<(&'static str, String)>,
    /// Best fit on a bound: held there.
    pinned: Vec<(&'static str, String)>,
    /// Of `dropped`, those the response does not depend on or depends on
    /// only in combination (rank-deficient): never freed again.
    structural: Vec<&'static str>,
}

impl Held {
    /// The parameters of `fit` still free, in its order.
    fn free(&self, fit: &[&'static str]) -> Vec<&'static str> {
        fit.iter()
            .copied()
            .filter(|p| !self.dropped.iter().chain(&self.pinned).any(|(d, _)| d == p))
            .collect()
    }

    /// `path` is not identifiable: held at the base file's value. The
    /// misfit the others are fitted in changes with it, so a bound another
    /// parameter ran to is no longer known to be its best fit: the pinned
    /// parameters are freed again (each drop frees them once, so the fit
    /// still ends).
    fn drop(&mut self, path: &'static str, reason: String) {
        self.dropped.push((path, reason));
        for (p, _) in self.pinned.drain(..) {
            set(&mut self.fixed, p, get(&self.base, p));
        }
    }

    /// `path`'s best fit lies on a bound, `value`: held there.
    fn pin(&mut self, path: &'static str, value: f64, reason: String) {
        set(&mut self.fixed, path, value);
        self.pinned.push((path, reason));
    }
}

/// The chambers' compliance: the parameters dropped first when several
/// fail an identifiability check. A flat direction of the misfit along
/// which the bulk modulus and the friction trade (an overdamped creep is
/// slowed alike by soft chambers and by friction) leaves either one's
/// profile flat; holding the friction at the base file's value would let
/// the bulk modulus absorb its error, with an interval conditional on a
/// wrong friction. The bulk modulus of a mineral oil is known within tens
/// of percent from its datasheet, a plunger's friction is not known at
/// all: the compliance goes first.
pub const NUISANCE: [&str; 3] = ["fluid.bulk_modulus", "chambers.volume_a", "chambers.volume_b"];

/// 0 for a [`NUISANCE`] parameter, 1 for the others.
fn rank(free: &[&str], i: usize) -> u8 {
    u8::from(!NUISANCE.contains(&free[i]))
}

/// The indices of `free` in the order the checks visit them: the
/// [`NUISANCE`] parameters first, each group in the `--fit` order.
fn priority(free: &[&str]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..free.len()).collect();
    order.sort_by_key(|&i| rank(free, i));
    order
}

/// Why a parameter the Jacobian cannot separate is dropped: `confounded`
/// are the parameters along the unseen direction (it among them), `when`
/// says where the Jacobian was taken. A parameter alone along it is one the
/// response does not depend on; never "confounded with" itself.
fn unseen_reason(path: &str, confounded: &[String], when: &str) -> String {
    let others: Vec<&str> = confounded.iter().map(String::as_str).filter(|c| *c != path).collect();
    if others.is_empty() {
        format!("the response does not depend on it {when} (its column of the Jacobian is below the rank tolerance)")
    } else {
        format!(
            "the data do not separate it from {} {when}: only a combination of them is determined",
            others.join(", ")
        )
    }
}

/// Outcome of [`identify_params`].
#[derive(Debug, Clone)]
pub struct Identification {
    /// The base parameters with the identified fields replaced.
    pub params: RawParams,
    /// The base parameters as given.
    pub base: RawParams,
    /// Every requested parameter, identified or not, in the requested order.
    pub results: Vec<Identified>,
    /// The twin's configuration used.
    pub config: TwinConfig,
    /// Residual RMS of the displacement [m] at the optimum.
    pub rms_x: f64,
    /// Residual RMS of the pressures [Pa], if measured.
    pub rms_p: Option<f64>,
    /// Residuals (all channels), degrees of freedom.
    pub points: usize,
    /// Degrees of freedom of the final fit.
    pub dof: usize,
    /// Condition number of the final fit's scaled Jacobian.
    pub condition: f64,
    /// Warnings, one line each.
    pub warnings: Vec<String>,
    /// What the fit strategy found besides (a fit from the base values
    /// that stopped in a local minimum), one line each.
    pub remarks: Vec<String>,
}

/// The residual sum of squares of the profile at `x[i] + d`: parameter
/// `i` held there, the others re-fitted from `x` (infinite when the model
/// cannot run there).
fn profile_at(f: &dyn Fn(&[f64]) -> Option<Vec<f64>>, x: &[f64], i: usize, d: f64, step: &[f64]) -> f64 {
    let rss = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let xi = x[i] + d;
    let others: Vec<f64> = x.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, v)| *v).collect();
    let full = |o: &[f64]| -> Vec<f64> {
        let mut v = o.to_vec();
        v.insert(i, xi);
        v
    };
    if others.is_empty() {
        return f(&full(&[])).map_or(f64::INFINITY, |r| rss(&r));
    }
    let st: Vec<f64> = step
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != i)
        .map(|(_, v)| *v)
        .collect();
    match lsq::least_squares(|o| f(&full(o)), &others, &st) {
        Ok(fit) => rss(&fit.residuals),
        Err(_) => f(&full(&others)).map_or(f64::INFINITY, |r| rss(&r)),
    }
}

/// The 95 % profile-likelihood interval of parameter `i` (coordinates
/// `coord`, field `fd`) of the fit at `x` with residual sum of squares
/// `rss0` and residual variance `s2`: on each side, where the profile
/// crosses [`CHI2_95`] `s2` above `rss0` (bisection, [`PROFILE_BISECTIONS`]
/// steps) within a value [`PROFILE_FAR`] times smaller or larger (or the
/// range's edge).
///
/// Errors: the reason the data bound it from one side at most (the
/// profile under the threshold at the bracket's end).
#[allow(clippy::too_many_arguments)]
fn profile_interval(
    f: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    x: &[f64],
    i: usize,
    coord: Coord,
    fd: &Field,
    rss0: f64,
    s2: f64,
    step: &[f64],
) -> Result<(f64, f64), String> {
    let xi = x[i];
    let v = coord.value(xi);
    let lower = coord.coord((v / PROFILE_FAR).max(fd.min * 1.001), fd.min);
    let upper = coord.coord((v * PROFILE_FAR).min(fd.max * 0.999), fd.min);
    let mut ci = (0.0, 0.0);
    for (side, (d, word)) in [(lower - xi, "smaller"), (upper - xi, "larger")]
        .into_iter()
        .enumerate()
    {
        let rise_at = |d: f64| (profile_at(f, x, i, d, step) - rss0) / s2;
        let rise = rise_at(d);
        if !(rise >= CHI2_95) {
            return Err(format!(
                "a value {:.3} times {word} fits the data as well (misfit up by {:.2} s^2, less than the 95 % \
                 threshold {CHI2_95}): the data bound it from one side at most",
                (coord.value(xi + d) / v).max(v / coord.value(xi + d)),
                rise.max(0.0)
            ));
        }
        // The 95 % profile-likelihood bound on this side: where the profile
        // crosses CHI2_95 (bisection).
        let (mut inside, mut outside) = (0.0, d);
        for _ in 0..PROFILE_BISECTIONS {
            let mid = 0.5 * (inside + outside);
            if rise_at(mid) < CHI2_95 {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        let bound = coord.value(xi + 0.5 * (inside + outside));
        if side == 0 {
            ci.0 = bound;
        } else {
            ci.1 = bound;
        }
    }
    Ok(ci)
}

/// The smaller of the profile's residual sums of squares at `x[i] +- delta`.
fn profile(f: &dyn Fn(&[f64]) -> Option<Vec<f64>>, x: &[f64], i: usize, delta: f64, step: &[f64]) -> f64 {
    profile_at(f, x, i, -delta, step).min(profile_at(f, x, i, delta, step))
}

/// The accepted fit: its uncertainty, optimum (fit coordinates), the
/// coordinates and the profile-likelihood intervals of its parameters.
type Accepted = (lsq::Uncertainty, Vec<f64>, Vec<Coord>, Vec<(f64, f64)>);

/// Residual scales of the channels: displacement [m], pressures [Pa].
#[derive(Clone, Copy, Debug)]
struct Scales {
    x: f64,
    p: f64,
}

/// Weighted residuals of `raw` against `data`: `(x_sim - x) / s.x`, then
/// `(p_sim - p) / s.p` for both chambers when measured.
fn residuals(raw: &RawParams, config: TwinConfig, data: &Transient, s: Scales) -> Option<Vec<f64>> {
    let sim = simulate(&raw.core, config, data)?;
    let mut r: Vec<f64> = sim.iter().zip(&data.x_m).map(|(y, x)| (y[0] - x) / s.x).collect();
    if let Some(p) = &data.p_pa {
        for (y, (pa, pb)) in sim.iter().zip(p) {
            r.push((y[1] - pa) / s.p);
            r.push((y[2] - pb) / s.p);
        }
    }
    Some(r)
}

/// RMS of the displacement and pressure parts of unweighted residuals.
fn channel_rms(raw: &RawParams, config: TwinConfig, data: &Transient) -> Option<(f64, Option<f64>)> {
    let r = residuals(raw, config, data, Scales { x: 1.0, p: 1.0 })?;
    let n = data.x_m.len();
    Some((lsq::rms(&r[..n]), data.p_pa.as_ref().map(|_| lsq::rms(&r[n..]))))
}

/// Fits `fit` (paths of [`CANDIDATES`]) of `base` to `data` (module docs).
///
/// Errors: [`CliError::Input`] for a path no field of `base` has (naming
/// it), a base file the twin refuses, data the twin cannot follow from the
/// base file (a temperature outside the oil model), too few degrees of
/// freedom ([`MIN_DOF`]); [`CliError::Failed`] when the minimiser does not
/// converge or the twin fails mid-fit.
pub fn identify_params(base: &RawParams, data: &Transient, fit: &[&'static str]) -> Result<Identification, CliError> {
    check_fit(base, fit)?;
    let tick = data.tick();
    let choice = chosen(base, tick)?;
    let config = TwinConfig {
        substeps: (choice.config.substeps.saturating_mul(SUBSTEP_FACTOR)).min(MAX_SUBSTEPS),
        ..choice.config
    };
    let n_res = data.x_m.len() * if data.p_pa.is_some() { 3 } else { 1 };
    let mut scales = first_scales(base, config, data)?;
    let mut held = Held {
        base: *base,
        fixed: *base,
        dropped: Vec::new(),
        pinned: Vec::new(),
        structural: Vec::new(),
    };
    let mut warnings = Vec::new();
    let mut notes = Vec::new();
    let mut reweighted = data.p_pa.is_none();
    let (mut raw, last) = loop {
        let free = held.free(fit);
        if free.is_empty() {
            break (held.fixed, None);
        }
        if n_res < free.len() + MIN_DOF {
            return Err(CliError::Input(format!(
                "--data: {n_res} residuals for {} parameters: at least {MIN_DOF} degrees of freedom are needed \
                 (the intervals use the normal quantile); give a longer or finer record",
                free.len()
            )));
        }
        let problem = Problem::new(base, held.fixed, free, config, data, scales);
        match problem.round(&mut reweighted, &mut notes)? {
            Step::Reweighted(s) => scales = s,
            Step::Drop {
                path,
                reason,
                structural,
            } => {
                held.drop(path, reason);
                if structural {
                    held.structural.push(path);
                }
            }
            Step::Pin { path, value, reason } => held.pin(path, value, reason),
            Step::Accept(raw, accepted) => {
                warnings.extend(accepted.0.warnings());
                break (*raw, Some(accepted));
            }
        }
    };
    let free = held.free(fit);
    let (mut dof, mut condition) = last.as_ref().map_or((n_res, 1.0), |(u, ..)| (u.dof, u.condition));
    let mut results = outcomes(fit, &held, &free, &raw, last.as_ref());
    // The parameters the data do not determine on their own, fitted again
    // with the identified ones: their values are not known, so the others'
    // estimates and intervals must not depend on where they were held.
    let nuisance: Vec<&'static str> = fit
        .iter()
        .copied()
        .filter(|p| !free.contains(p) && !held.structural.contains(p))
        .collect();
    if !free.is_empty() && !nuisance.is_empty() {
        match joint(base, &raw, fit, &nuisance, &mut results, config, data, scales) {
            Ok((joint_raw, u)) => {
                raw = joint_raw;
                dof = u.dof;
                condition = u.condition;
            }
            Err(e) => warnings.push(format!(
                "the identified parameters could not be fitted again with {} free ({e}): their intervals \
                 assume those held where the preset has them",
                nuisance.join(", ")
            )),
        }
    }
    let params = checked(raw, tick, config, &mut warnings)?;
    let (rms_x, rms_p) = channel_rms(&params, config, data)
        .ok_or_else(|| CliError::Failed("the twin fails at the identified parameters".into()))?;
    Ok(Identification {
        params,
        base: *base,
        results,
        config,
        rms_x,
        rms_p,
        points: n_res,
        dof,
        condition,
        warnings,
        remarks: notes,
    })
}

/// The first pass's weights: the base file's misfit per channel, floored
/// at 1e-6 of the stroke and of the drop (noise-free data).
///
/// Errors: data the twin cannot follow with the base parameters.
fn first_scales(base: &RawParams, config: TwinConfig, data: &Transient) -> Result<Scales, CliError> {
    let (rx0, rp0) = channel_rms(base, config, data).ok_or_else(|| {
        CliError::Input(
            "--data: the twin cannot follow the data with the base parameters (a temperature outside the oil model?)"
                .into(),
        )
    })?;
    Ok(Scales {
        x: rx0.max(1e-6 * base.core.stroke),
        p: rp0.unwrap_or(1.0).max(1e-6 * base.core.pressure_drop),
    })
}

/// Every parameter of `fit`, in its order: not identifiable (dropped or
/// pinned by `held`, with the reason), or estimated by the accepted fit
/// `last` of the parameters `free`; each with its value in `raw`.
fn outcomes(
    fit: &[&'static str],
    held: &Held,
    free: &[&'static str],
    raw: &RawParams,
    last: Option<&Accepted>,
) -> Vec<Identified> {
    fit.iter()
        .map(|p| {
            let f = field(p);
            if let Some((_, reason)) = held.dropped.iter().chain(&held.pinned).find(|(d, _)| d == p) {
                return Identified {
                    path: f.path,
                    unit: f.unit,
                    estimate: None,
                    reason: reason.clone(),
                    held: get(raw, p),
                };
            }
            let (u, x, coords, ci) = last.expect("a parameter left free was fitted");
            let i = free.iter().position(|q| q == p).expect("free parameter");
            let se = u.std_errors()[i];
            Identified {
                path: f.path,
                unit: f.unit,
                estimate: Some(Estimate {
                    value: coords[i].value(x[i]),
                    std_error: coords[i].std_error(x[i], se),
                    ci95: ci[i],
                    wald95: coords[i].interval(x[i], se),
                }),
                reason: String::new(),
                held: get(raw, p),
            }
        })
        .collect()
}

/// The identified set `raw`, validated; a warning in `warnings` when the
/// chooser wants more substeps for it at `tick` than the fit ran
/// (`config`).
///
/// Errors: a set the validation refuses.
fn checked(raw: RawParams, tick: f64, config: TwinConfig, warnings: &mut Vec<String>) -> Result<RawParams, CliError> {
    raw.validate()
        .map_err(|e| CliError::Failed(format!("identified parameters are not valid: {e}")))?;
    if let Ok(after) = chosen(&raw, tick)
        && after.config.substeps > config.substeps
    {
        warnings.push(format!(
            "the identified design needs {} substeps per tick where the fit ran {}: rerun with the \
             written preset as --params to refine",
            after.config.substeps, config.substeps
        ));
    }
    Ok(raw)
}

impl Identification {
    /// The report table (CSV), one row per requested parameter:
    /// `parameter,unit,identifiable,value,std_error,rel_std_error,ci95_low,ci95_high`
    /// (the numbers empty for a parameter the data do not determine).
    pub fn table(&self) -> String {
        let mut out = String::from("parameter,unit,identifiable,value,std_error,rel_std_error,ci95_low,ci95_high\n");
        for r in &self.results {
            let unit = r.unit.replace(' ', "_");
            match r.estimate {
                Some(Estimate {
                    value,
                    std_error,
                    ci95: (lo, hi),
                    ..
                }) => {
                    let _ = writeln!(
                        out,
                        "{},{unit},true,{value},{std_error},{},{lo},{hi}",
                        r.path,
                        std_error / value.abs()
                    );
                }
                None => {
                    let _ = writeln!(out, "{},{unit},false,,,,,", r.path);
                }
            }
        }
        out
    }

    /// Lines for standard error: the fit, and each parameter not identified.
    pub fn notes(&self) -> Vec<String> {
        let mut out = vec![format!(
            "twin {} ({} substeps per {} s sample); {} residuals, {} degrees of freedom; residual RMS {:.4e} m{}; \
             condition number {:.1e}",
            self.config.scheme.name(),
            self.config.substeps,
            self.config.tick,
            self.points,
            self.dof,
            self.rms_x,
            self.rms_p.map_or(String::new(), |p| format!(", pressures {p:.4e} Pa")),
            self.condition
        )];
        out.extend(self.remarks.iter().cloned());
        for r in &self.results {
            if r.estimate.is_none() {
                out.push(format!(
                    "NOT IDENTIFIABLE: {}: {}; {} in the preset",
                    r.path,
                    r.reason,
                    if r.held == get(&self.base, r.path) {
                        "kept at the base file's value".to_string()
                    } else {
                        format!("{:e} {} (its best fit with the others)", r.held, r.unit)
                    }
                ));
            }
        }
        out.extend(self.warnings.iter().map(|w| format!("WARNING: {w}")));
        out
    }

    /// The identified parameter file: TOML with the fit in comments.
    pub fn preset(&self, command: &str) -> String {
        let mut out = String::from("# Dynamic parameters identified from a measured transient.\n");
        let _ = writeln!(out, "# Generated by: {command}");
        for line in self.notes() {
            let _ = writeln!(out, "# {line}");
        }
        for r in &self.results {
            if let Some(e) = r.estimate {
                let _ = writeln!(
                    out,
                    "# {} = {} {} (standard error {:.3e}, 95 % interval {:.4e} .. {:.4e})",
                    r.path, e.value, r.unit, e.std_error, e.ci95.0, e.ci95.1
                );
            }
        }
        out.push('\n');
        out.push_str(&params_file::to_toml(&self.params));
        out
    }

    /// The figure of `--plot`: measured and simulated displacement (and
    /// pressures) over time.
    pub fn figure(&self, data: &Transient) -> crate::plot::Figure {
        use crate::plot::{Figure, Panel, Series};
        let sim = simulate(&self.params.core, self.config, data).unwrap_or_default();
        let series = |label: &str, pts: Vec<(f64, f64)>, dashed: bool| Series {
            label: label.into(),
            points: pts,
            dashed,
            ..Series::line(label, Vec::new())
        };
        let t = &data.time_s;
        let mut panels = vec![Panel {
            y_desc: "x [mm]".into(),
            log_y: false,
            legend: true,
            series: vec![
                series(
                    "measured",
                    t.iter().zip(&data.x_m).map(|(t, x)| (*t, x * 1e3)).collect(),
                    true,
                ),
                series(
                    "identified twin",
                    t.iter().zip(&sim).map(|(t, y)| (*t, y[0] * 1e3)).collect(),
                    false,
                ),
            ],
        }];
        if let Some(p) = &data.p_pa {
            panels.push(Panel {
                y_desc: "p [bar]".into(),
                log_y: false,
                legend: true,
                series: vec![
                    series(
                        "p_a measured",
                        t.iter().zip(p).map(|(t, p)| (*t, p.0 * 1e-5)).collect(),
                        true,
                    ),
                    series(
                        "p_b measured",
                        t.iter().zip(p).map(|(t, p)| (*t, p.1 * 1e-5)).collect(),
                        true,
                    ),
                    series(
                        "p_a twin",
                        t.iter().zip(&sim).map(|(t, y)| (*t, y[1] * 1e-5)).collect(),
                        false,
                    ),
                    series(
                        "p_b twin",
                        t.iter().zip(&sim).map(|(t, y)| (*t, y[2] * 1e-5)).collect(),
                        false,
                    ),
                ],
            });
        }
        panels.push(Panel {
            y_desc: "temperature [C]".into(),
            log_y: false,
            legend: false,
            series: vec![series(
                "t_c",
                t.iter().zip(&data.t_c).map(|(t, c)| (*t, *c)).collect(),
                false,
            )],
        });
        Figure {
            title: "Identification: measured transient and the identified twin".into(),
            x_desc: "time [s]".into(),
            panels,
        }
    }
}

/// Options of `identify`.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Base parameter file (static parameters already calibrated).
    pub params: PathBuf,
    /// The transient (CSV).
    pub data: PathBuf,
    /// `--fit` list ([`parse_fit`]); `None`: [`DEFAULT_FIT`].
    pub fit: Option<String>,
    /// Where to write the identified parameter file.
    pub write_preset: Option<PathBuf>,
    /// Where to draw the fit (SVG).
    pub plot: Option<PathBuf>,
}

/// Slack on the plunger's travel for measured displacements: noise and a
/// sensor's offset may put a sample slightly beyond a stop, but not by a
/// tenth of the stroke.
pub const STROKE_SLACK: f64 = 0.1;

/// Checks a record against the base file before fitting: every
/// temperature within the oil model's range, every displacement within
/// `[-STROKE_SLACK, 1 + STROKE_SLACK]` strokes (a record in mm or um read as
/// m, or from another device, would otherwise be fitted through the
/// pressures alone and reported as identified).
///
/// Errors: the first offending data row (1-based) and column, with the
/// allowed range.
pub fn check_plausible(base: &RawParams, data: &Transient) -> Result<(), String> {
    let stroke = base.core.stroke;
    let (lo, hi) = (-STROKE_SLACK * stroke, (1.0 + STROKE_SLACK) * stroke);
    if let Some(i) = data.x_m.iter().position(|x| !(lo..=hi).contains(x)) {
        return Err(format!(
            "row {}, column x_m: {} m is outside the plunger's travel [{}, {}] m \
             (0 to plunger.stroke = {} m, with {} % slack){}",
            i + 1,
            crate::display::sig(data.x_m[i], 6),
            crate::display::sig(lo, 4),
            crate::display::sig(hi, 4),
            crate::display::sig(stroke, 6),
            STROKE_SLACK * 100.0,
            crate::data::column("x_m").map_or(String::new(), |c| crate::data::unit_hint(c, data.x_m[i], lo, hi))
        ));
    }
    if let Ok(p) = Params::<f64>::new(base) {
        let env = crate::envelope::Envelope::of(base, &p);
        for (i, &t) in data.t_c.iter().enumerate() {
            env.check(t, &format!("row {}, column t_c", i + 1))
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// `identify`: the report table (CSV) and the lines for standard error.
///
/// Errors: bad parameter file or data (exit 2, naming the field, row and
/// column), too few degrees of freedom (exit 2), a fit that fails (exit 1).
pub fn identify(opts: &Options) -> Result<(String, Vec<String>), CliError> {
    let fit = match &opts.fit {
        Some(list) => parse_fit(list).map_err(|e| CliError::Input(format!("--fit: {e}")))?,
        None => DEFAULT_FIT.to_vec(),
    };
    let base = crate::input::load_raw(&opts.params, "--params")?;
    let shown = opts.data.display().to_string();
    let text = crate::input::params_text(&opts.data, "--data")?;
    let data = read_transient(&text).map_err(|e| CliError::Input(format!("--data: {shown}: {e}")))?;
    check_plausible(&base, &data).map_err(|e| CliError::Input(format!("--data: {shown}: {e}")))?;
    let id = identify_params(&base, &data, &fit)?;
    if let Some(path) = &opts.write_preset {
        let command = format!(
            "compensator identify --params {} --data {shown} --fit {}",
            opts.params.display(),
            fit.join(",")
        );
        std::fs::write(path, id.preset(&command))
            .map_err(|e| CliError::Input(format!("--write-preset: {}: {e}", path.display())))?;
    }
    if let Some(path) = &opts.plot {
        crate::plot::write(path, &id.figure(&data))?;
    }
    Ok((id.table(), id.notes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_no_field_has_is_bad_input_naming_it() {
        // The example has no [machine] section.
        let base = crate::params_file::parse(crate::input::MODEL_EXAMPLE).unwrap();
        let data = Transient {
            time_s: vec![0.0, 0.001],
            t_c: vec![40.0; 2],
            x_m: vec![0.0; 2],
            p_pa: None,
        };
        for (path, says) in [
            ("plunger.bogus", "unknown parameter 'plunger.bogus'"),
            (
                "machine.working_flow",
                "machine.working_flow: the parameter file has no [machine] section",
            ),
        ] {
            let e = identify_params(&base, &data, &["plunger.mass", path]).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{e}");
            assert!(
                e.to_string().starts_with("--fit: ") && e.to_string().contains(says),
                "{e}"
            );
        }
    }

    #[test]
    fn an_unseen_direction_names_the_others_never_the_parameter_itself() {
        let alone = unseen_reason("fluid.bulk_modulus", &["fluid.bulk_modulus".into()], "at the start");
        assert!(
            alone.starts_with("the response does not depend on it at the start"),
            "{alone}"
        );
        assert!(!alone.contains("fluid.bulk_modulus"), "{alone}");
        let two = unseen_reason(
            "chambers.volume_a",
            &["fluid.bulk_modulus".into(), "chambers.volume_a".into()],
            "at the optimum",
        );
        assert!(
            two.contains("separate it from fluid.bulk_modulus at the optimum"),
            "{two}"
        );
        assert!(!two.contains("chambers.volume_a"), "{two}");
    }
}
