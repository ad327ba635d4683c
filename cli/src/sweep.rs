//! `sweep`: design variants of a parameter file, on a grid of named
//! parameters (`--set plunger.spring_rate=20e3:30e3:5`) and/or drawn
//! within tolerances (`--vary plunger.diameter=1% --samples N --seed S`),
//! each evaluated by the library functions the single commands use:
//!
//! * `x_<T>c_m`: quasi-static displacement at each `--temps` temperature
//!   (`equilibrium`, Eqs. 2-10);
//! * `monotonic`, `min_dx_dt_m_k`: the Eq. (32) verdict over the file's
//!   validated range at 0.1 C spacing, and the smallest `|dx/dt|` found
//!   (`compensator::asymptotic::monotonicity`, as `paper`);
//! * `dominant_re`, `settling_time_s`: the dominant eigenvalue's real part
//!   [1/s] at the step's final temperature and the 2 % settling time of the
//!   step `--step FROM:TO` (reference solver, as `indicators`:
//!   [`crate::dynamics::step_indicators`]);
//! * `comp_error_rms_m3s`: the RMS compensation error over the validated
//!   range at 1 C spacing (`compensation`; only when the file has a
//!   `[machine]` section).
//!
//! Variants run on all cores (rayon); each variant's draws come from one
//! seeded generator advanced in variant order before anything runs, and
//! the rows are collected in variant order, so the output does not depend
//! on the number of threads. A variant that cannot be evaluated (a varied
//! value outside its field's plausible range, a design whose equilibrium
//! fails) keeps its parameter values and says why in the `error` column.

use crate::dynamics::{parse_steps, step_indicators, tick_count};
use crate::error::CliError;
use crate::temps;
use compensator::compensation::compensation;
use compensator::dynamics::linear::linearise;
use compensator::equilibrium::equilibrium;
use compensator::params::Field;
use compensator::{Params, RawParams};
use compensator_params::{PathError, PathProblem};
use rand::{RngExt, SeedableRng, rngs::Xoshiro256PlusPlus};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

pub mod cache;
pub mod step_response;
pub mod stream;

/// Most variants of one sweep: rows stream out as they are computed, so
/// memory does not grow with the count; at 5,000 variants per second per
/// core 1e10 is a cluster's week.
pub const MAX_VARIANTS: usize = 10_000_000_000;

/// Most values of one `--set` axis (each is held in memory).
pub const MAX_AXIS_VALUES: usize = 1_000_000;

/// A parameter file's field by its `section.key` name.
pub fn field(name: &str) -> Option<&'static Field> {
    compensator_params::field_by_path(name)
}

/// `raw` with the field `path` set to `value` (not validated), by the
/// schema's access by name ([`RawParams::set`]).
///
/// # Errors
///
/// An unknown name (with the nearest valid one), a `[machine]` field when
/// `raw` has no `[machine]` section.
pub fn with_value<'a>(raw: &RawParams, path: &'a str, value: f64) -> Result<RawParams, PathError<'a>> {
    let mut out = *raw;
    out.set(path, value)?;
    Ok(out)
}

/// One `--set NAME=SPEC`: a field and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct GridAxis {
    /// The field's `section.key`.
    pub name: &'static str,
    /// Its values [the field's unit].
    pub values: Vec<f64>,
}

/// One `--vary NAME=TOL`: a field drawn uniformly within a tolerance
/// around its (grid or file) value.
#[derive(Clone, Debug, PartialEq)]
pub struct Tolerance {
    /// The field's `section.key`.
    pub name: &'static str,
    /// Half-width of the band: a fraction of the value (`1%` -> 0.01) or,
    /// if `relative` is false, an absolute amount [the field's unit].
    pub half_width: f64,
    /// Whether `half_width` is a fraction of the value.
    pub relative: bool,
}

/// Splits `NAME=SPEC` and finds the field (unknown name: bad input naming it).
fn name_and_spec<'a>(flag: &str, arg: &'a str) -> Result<(&'static Field, &'a str), CliError> {
    let (name, spec) = arg
        .split_once('=')
        .ok_or_else(|| CliError::Input(format!("{flag}: '{arg}' is not of the form section.key=...")))?;
    let name = name.trim();
    let f = field(name).ok_or_else(|| {
        let e = PathError {
            path: name,
            problem: PathProblem::Unknown,
        };
        CliError::Input(format!("{flag}: {e}"))
    })?;
    Ok((f, spec.trim()))
}

fn number(flag: &str, name: &str, s: &str) -> Result<f64, CliError> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(CliError::Input(format!("{flag}: {name}: '{s}' is not a finite number"))),
    }
}

/// Parses `--set NAME=START:END:N` (N evenly spaced values, both ends
/// included) or `NAME=V1,V2,...`.
pub fn parse_set(arg: &str) -> Result<GridAxis, CliError> {
    let (f, spec) = name_and_spec("--set", arg)?;
    let values = if spec.contains(':') {
        let parts: Vec<&str> = spec.split(':').collect();
        if parts.len() != 3 {
            return Err(CliError::Input(format!(
                "--set: {}: '{spec}' is not of the form start:end:count",
                f.path
            )));
        }
        let (a, b) = (number("--set", f.path, parts[0])?, number("--set", f.path, parts[1])?);
        let n: usize = parts[2]
            .trim()
            .parse()
            .ok()
            .filter(|n| (1..=MAX_AXIS_VALUES).contains(n))
            .ok_or_else(|| {
                CliError::Input(format!(
                    "--set: {}: count '{}' is not a whole number in 1..={MAX_AXIS_VALUES}",
                    f.path, parts[2]
                ))
            })?;
        if n == 1 {
            vec![a]
        } else {
            (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect()
        }
    } else {
        spec.split(',')
            .map(|s| number("--set", f.path, s))
            .collect::<Result<Vec<_>, _>>()?
    };
    Ok(GridAxis { name: f.path, values })
}

/// Parses `--vary NAME=P%` (relative) or `NAME=A` (absolute, the field's unit).
pub fn parse_vary(arg: &str) -> Result<Tolerance, CliError> {
    let (f, spec) = name_and_spec("--vary", arg)?;
    let (text, relative) = match spec.strip_suffix('%') {
        Some(p) => (p, true),
        None => (spec, false),
    };
    let v = number("--vary", f.path, text)?;
    if v < 0.0 {
        return Err(CliError::Input(format!("--vary: {}: '{spec}' is negative", f.path)));
    }
    Ok(Tolerance {
        name: f.path,
        half_width: if relative { v / 100.0 } else { v },
        relative,
    })
}

/// What a sweep computes for each variant.
#[derive(Clone, Debug, PartialEq)]
pub struct Metrics {
    /// Temperatures of the displacement columns [C].
    pub temps: Vec<f64>,
    /// The step of the settling time and dominant eigenvalue [C].
    pub step: (f64, f64),
    /// Output interval of the reference solver for the settling time [s].
    pub dt: f64,
    /// Simulated time of the step [s].
    pub t_end: f64,
    /// The settling time from the reference solver (Radau5, sampled every
    /// `dt`) instead of the `f64` twin ([`step_response`]): for checking,
    /// at about 7 ms a variant.
    pub reference: bool,
}

/// A sweep: the base file, the grid, the tolerances.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The base parameter set.
    pub base: RawParams,
    /// `--set` axes (their cartesian product; the first varies slowest).
    pub grid: Vec<GridAxis>,
    /// `--vary` tolerances.
    pub vary: Vec<Tolerance>,
    /// Draws per grid point (1 without `vary`).
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// What to compute.
    pub metrics: Metrics,
}

impl Sweep {
    /// The parameter columns: the grid's fields, then the varied ones not
    /// already on the grid.
    pub fn parameter_names(&self) -> Vec<&'static str> {
        let mut names: Vec<&'static str> = self.grid.iter().map(|a| a.name).collect();
        for t in &self.vary {
            if !names.contains(&t.name) {
                names.push(t.name);
            }
        }
        names
    }

    /// Number of variants: the grid's points times the samples.
    ///
    /// # Errors
    ///
    /// More than [`MAX_VARIANTS`] (bad input naming `--set/--samples`).
    pub fn variant_count(&self) -> Result<usize, CliError> {
        let too_many = || CliError::Input(format!("--set/--samples: more than {MAX_VARIANTS} variants"));
        let mut n = Some(self.samples.max(1))
            .filter(|&n| n <= MAX_VARIANTS)
            .ok_or_else(too_many)?;
        for a in &self.grid {
            n = n
                .checked_mul(a.values.len())
                .filter(|&n| n <= MAX_VARIANTS)
                .ok_or_else(too_many)?;
        }
        Ok(n)
    }

    /// Every variant's parameter values (in [`Self::parameter_names`]
    /// order), in variant order: grid points, and for each `samples`
    /// draws from one generator seeded with `seed` (Xoshiro256++).
    pub fn variants(&self) -> Result<Vec<Vec<f64>>, CliError> {
        Ok(self.variants_in(0, self.variant_count()?)?.map(|(_, v)| v).collect())
    }

    /// Variants `start..end` (`end` at most [`Self::variant_count`]) with
    /// their index, as [`Self::variants`] numbers and draws them: the draws
    /// of the variants before `start` are replayed (drawn and discarded),
    /// so a shard's variants are the single run's.
    ///
    /// # Errors
    ///
    /// A parameter the base set does not have (bad input naming it, as
    /// [`RawParams::get`]; [`build`] refuses it before).
    pub fn variants_in(&self, start: usize, end: usize) -> Result<Variants<'_>, CliError> {
        let names = self.parameter_names();
        let base = names
            .iter()
            .map(|name| self.base.get(name).map_err(|e| CliError::Input(e.to_string())))
            .collect::<Result<Vec<f64>, _>>()?;
        let slots = self
            .vary
            .iter()
            .map(|t| {
                names
                    .iter()
                    .position(|n| *n == t.name)
                    .expect("parameter_names lists every varied field")
            })
            .collect();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(self.seed);
        for _ in 0..start {
            for _ in &self.vary {
                let _: f64 = rng.random_range(-1.0..=1.0);
            }
        }
        Ok(Variants {
            sweep: self,
            base,
            slots,
            rng,
            next: start,
            end,
        })
    }
}

/// An iterator over a sweep's variants ([`Sweep::variants_in`]):
/// `(index, parameter values)`.
pub struct Variants<'a> {
    sweep: &'a Sweep,
    base: Vec<f64>,
    slots: Vec<usize>,
    rng: Xoshiro256PlusPlus,
    next: usize,
    end: usize,
}

impl Iterator for Variants<'_> {
    type Item = (usize, Vec<f64>);

    fn next(&mut self) -> Option<Self::Item> {
        if self.next >= self.end {
            return None;
        }
        let i = self.next;
        self.next += 1;
        let mut point = i / self.sweep.samples.max(1);
        let mut values = self.base.clone();
        // Grid index: the last axis varies fastest.
        for (k, axis) in self.sweep.grid.iter().enumerate().rev() {
            values[k] = axis.values[point % axis.values.len()];
            point /= axis.values.len();
        }
        for (t, &k) in self.sweep.vary.iter().zip(&self.slots) {
            let u: f64 = self.rng.random_range(-1.0..=1.0);
            values[k] += if t.relative {
                values[k] * t.half_width * u
            } else {
                t.half_width * u
            };
        }
        Some((i, values))
    }
}

/// The column names of the metrics.
pub fn metric_columns(metrics: &Metrics, with_machine: bool) -> Vec<String> {
    let mut cols: Vec<String> = metrics.temps.iter().map(|t| format!("x_{t}c_m")).collect();
    cols.extend(
        ["monotonic", "min_dx_dt_m_k", "dominant_re", "settling_time_s"]
            .iter()
            .map(|s| s.to_string()),
    );
    if with_machine {
        cols.push("comp_error_rms_m3s".into());
    }
    cols
}

/// Samples of the Eq. (32) check: every 0.1 C of the validated range.
pub fn monotonicity_samples(raw: &RawParams) -> u32 {
    let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
    (((hi - lo) / 0.1).round() as u32).saturating_add(1)
}

/// One variant's metrics as CSV cells, or why it could not be evaluated.
pub fn evaluate(raw: &RawParams, metrics: &Metrics) -> Result<Vec<String>, String> {
    evaluate_with(raw, metrics, &cache::Shared::none())
}

/// [`evaluate`] with the work the sweep's variants share ([`cache`]).
pub fn evaluate_with(raw: &RawParams, metrics: &Metrics, shared: &cache::Shared) -> Result<Vec<String>, String> {
    raw.validate().map_err(|e| e.to_string())?;
    let p = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let mut cells = Vec::new();
    for &t in &metrics.temps {
        let e = equilibrium(&p, t).map_err(|e| format!("{t} C: {e}"))?;
        cells.push(format!("{}", e.x));
    }
    let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
    let samples = monotonicity_samples(raw);
    let m = shared
        .monotonicity(&p, lo, hi, samples)
        .map_err(|e| format!("Eq. (32) over {lo}-{hi} C: {e}"))?;
    cells.push(m.monotonic.to_string());
    cells.push(format!("{}", m.worst_dx_dt));
    let (from, to) = metrics.step;
    if metrics.reference {
        let ind = step_indicators(raw, &p, from, to, metrics.dt, metrics.t_end).map_err(|e| e.to_string())?;
        cells.push(format!("{}", ind.dominant_re));
        cells.push(format!("{}", ind.settling_time));
    } else {
        // As `step_indicators`, the response from the twin.
        let x_star = equilibrium(&p, to).map_err(|e| format!("--steps: {to} C: {e}"))?.x;
        equilibrium(&p, from).map_err(|e| format!("--steps: {from} C: {e}"))?;
        let lin = linearise(&p, to).map_err(|e| format!("linearisation at {to} C: {e}"))?;
        let s = step_response::settling_time(&p, &lin, from, to, metrics.dt, metrics.t_end, x_star)?;
        cells.push(format!("{}", lin.dominant.re));
        cells.push(format!("{}", s.time));
    }
    if p.machine.is_some() {
        let n = (hi - lo).floor() as usize;
        let mut sum = 0.0;
        for i in 0..=n {
            let t = lo + i as f64;
            let c = compensation(&p, t).map_err(|e| format!("compensation at {t} C: {e}"))?;
            sum += c.error * c.error;
        }
        cells.push(format!("{}", (sum / (n + 1) as f64).sqrt()));
    }
    Ok(cells)
}

/// The one-line progress note of a sweep whose standard error is not a
/// terminal: `done` of `total` variants after `elapsed` s, `left` s to go.
fn note(done: u64, total: u64, elapsed: f64, left: f64) -> String {
    format!(
        "sweep: {done} of {total} variants after {elapsed:.1} s; about {} to go at this rate",
        if left < 120.0 {
            format!("{left:.0} s")
        } else if left < 7200.0 {
            format!("{:.0} min", left / 60.0)
        } else {
            format!("{:.1} h", left / 3600.0)
        }
    )
}

/// Progress on standard error: drawn only when it is a terminal, and only
/// once the run has lasted a second (a short sweep prints nothing); when
/// it is not a terminal, one line ([`note`]) with the estimated time left.
struct Progress {
    bar: indicatif::ProgressBar,
    start: Instant,
    terminal: bool,
    shown: AtomicBool,
}

impl Progress {
    fn new(n: usize) -> Self {
        let bar = indicatif::ProgressBar::with_draw_target(Some(n as u64), indicatif::ProgressDrawTarget::hidden());
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} variants, {rate} variants/s, eta {eta}")
        {
            let rate = |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.0}", state.per_sec());
            };
            bar.set_style(style.with_key("rate", rate));
        }
        Progress {
            bar,
            start: Instant::now(),
            terminal: std::io::stderr().is_terminal(),
            shown: AtomicBool::new(false),
        }
    }

    fn inc(&self) {
        self.bar.inc(1);
        let elapsed = self.start.elapsed();
        if elapsed > Duration::from_secs(1) && !self.shown.swap(true, Ordering::Relaxed) {
            if self.terminal {
                self.bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            } else {
                // No bar in a log or a pipe: one line, so a long sweep is not silent.
                let (done, total) = (self.bar.position().max(1), self.bar.length().unwrap_or(0));
                let left = elapsed.as_secs_f64() * total.saturating_sub(done) as f64 / done as f64;
                eprintln!("{}", note(done, total, elapsed.as_secs_f64(), left));
            }
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Runs the sweep: one row per variant, `variant` (0-based), the parameter
/// columns, the metrics and `error` (empty, or why the variant could not
/// be evaluated), as CSV text ([`stream::write`] into memory).
pub fn run(sweep: &Sweep) -> Result<String, CliError> {
    let mut out = Vec::new();
    stream::write(sweep, None, crate::units::Units::Si, &mut out)?;
    String::from_utf8(out).map_err(|e| CliError::Failed(format!("sweep output: {e}")))
}

/// Builds a sweep from the command's arguments.
#[allow(clippy::too_many_arguments)]
pub fn build(
    base: RawParams,
    set: &[String],
    vary: &[String],
    samples: Option<usize>,
    seed: u64,
    temps_spec: &str,
    step_spec: &str,
    dt: f64,
    t_end: f64,
) -> Result<Sweep, CliError> {
    let grid = set.iter().map(|s| parse_set(s)).collect::<Result<Vec<_>, _>>()?;
    for (i, a) in grid.iter().enumerate() {
        if grid[..i].iter().any(|b| b.name == a.name) {
            return Err(CliError::Input(format!("--set: {} is given twice", a.name)));
        }
    }
    let vary = vary.iter().map(|s| parse_vary(s)).collect::<Result<Vec<_>, _>>()?;
    for (i, a) in vary.iter().enumerate() {
        if vary[..i].iter().any(|b| b.name == a.name) {
            return Err(CliError::Input(format!("--vary: {} is given twice", a.name)));
        }
    }
    // An absolute tolerance far below the value is most likely a
    // percentage written without its `%` (plunger.spring_rate=5 is +-5 N/m
    // on 23,116 N/m). (A field the file does not have is refused below.)
    for t in vary.iter().filter(|t| !t.relative) {
        if let Ok(v) = base.get(t.name)
            && t.half_width > 0.0
            && t.half_width < 1e-3 * v.abs()
        {
            eprintln!(
                "sweep: WARNING: --vary {}={}: +-{} is {} % of the file's {}; for a relative tolerance write {}%",
                t.name,
                crate::display::sig(t.half_width, 6),
                crate::display::sig(t.half_width, 6),
                crate::display::sig(100.0 * t.half_width / v.abs(), 2),
                crate::display::sig(v, 6),
                crate::display::sig(t.half_width, 6)
            );
        }
    }
    // Every field named is one of the file's (a `[machine]` one needs that
    // section), by the schema's access by name.
    for name in grid.iter().map(|a| a.name).chain(vary.iter().map(|t| t.name)) {
        base.get(name).map_err(|e| CliError::Input(e.to_string()))?;
    }
    let samples = match (samples, vary.is_empty()) {
        (Some(0), _) => return Err(CliError::Input("--samples: must be at least 1".into())),
        (Some(n), false) => n,
        (Some(_), true) => {
            return Err(CliError::Input("--samples: draws need --vary NAME=TOL".into()));
        }
        (None, false) => 100,
        (None, true) => 1,
    };
    let env = crate::envelope::Envelope::of(
        &base,
        &compensator::Params::<f64>::new(&base).map_err(|e| CliError::Input(e.to_string()))?,
    );
    let temps = temps::parse(temps_spec)?;
    env.check_all(&temps, "--temps")?;
    if temps.len() > 100 {
        return Err(CliError::Input("--temps: at most 100 temperatures in a sweep".into()));
    }
    let steps = parse_steps(step_spec).map_err(|e| CliError::Input(e.to_string().replace("--steps", "--step")))?;
    let [step] = steps[..] else {
        return Err(CliError::Input(format!(
            "--step: '{step_spec}' is not one from:to pair"
        )));
    };
    env.check_all(&[step.0, step.1], "--step")?;
    tick_count(t_end, dt)?;
    let sweep = Sweep {
        base,
        grid,
        vary,
        samples,
        seed,
        metrics: Metrics {
            temps,
            step,
            dt,
            t_end,
            reference: false,
        },
    };
    sweep.variant_count()?;
    Ok(sweep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_sweep_without_a_terminal_says_how_long_it_will_take() {
        assert_eq!(
            note(100, 1_000_000, 1.0, 9999.0),
            "sweep: 100 of 1000000 variants after 1.0 s; about 2.8 h to go at this rate"
        );
        assert!(note(10, 100, 1.0, 9.0).ends_with("about 9 s to go at this rate"));
        assert!(note(10, 1000, 1.0, 600.0).ends_with("about 10 min to go at this rate"));
    }

    #[test]
    fn grids_and_tolerances_parse() {
        let a = parse_set("plunger.spring_rate=20e3:30e3:5").unwrap();
        assert_eq!(a.name, "plunger.spring_rate");
        assert_eq!(a.values, vec![20e3, 22.5e3, 25e3, 27.5e3, 30e3]);
        assert_eq!(parse_set("plunger.mass=0.01,0.02").unwrap().values, vec![0.01, 0.02]);
        let t = parse_vary("plunger.diameter=1%").unwrap();
        assert!(t.relative && (t.half_width - 0.01).abs() < 1e-15);
        let e = parse_set("plunger.sprig_rate=1:2:2").unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("plunger.sprig_rate"), "{e}");
        assert!(parse_set("plunger.mass=1:2:0").is_err());
        assert!(parse_vary("plunger.mass=-1%").is_err());
    }

    #[test]
    fn with_value_sets_exactly_the_named_field() {
        let raw = crate::params_file::parse(crate::input::PAPER_PRESET).unwrap();
        let out = with_value(&raw, "plunger.spring_rate", 12345.0).unwrap();
        assert_eq!(out.core.spring_rate, 12345.0);
        let mut back = out;
        back.core.spring_rate = raw.core.spring_rate;
        assert_eq!(back, raw);
        let out = with_value(&raw, "estimator.valid_max", 70.0).unwrap();
        assert_eq!(out.estimator.valid_max, 70.0);
        assert_eq!(out.core, raw.core);
    }
}
