//! Dynamic-model commands: step and ramp responses, eigenvalues, and the
//! step-response indicators of the paper's Table 3.

use crate::csv::Table;
use crate::error::CliError;
use crate::input::load_params;
use compensator::ModelError;
use compensator::dynamics::config::{Choice, TARGET_PCT, choose};
use compensator::dynamics::linear::linearise;
use compensator::dynamics::reduced::ReducedTwin;
use compensator::dynamics::{Dynamic, DynamicState, Scheme, Twin, TwinConfig};
use compensator::equilibrium::equilibrium;
use compensator::scalar::Fixed;
use compensator::{Float, Params, RawParams, Real};
use compensator_reference::dynamics::{self as reference, Method, Profile};
use std::path::Path;

/// Scalar type (or solver) of a dynamic computation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Precision {
    /// The twin in `f32`.
    F32,
    /// The twin in `f64`.
    F64,
    /// The twin in the shipped fixed-point format, Q12.20 (fluid
    /// properties in `f32`).
    Fixed,
    /// The twin in Q16.16 (coarser resolution; for comparison).
    FixedQ16,
    /// The twin in Q8.24 (finer resolution, too little range; for comparison).
    FixedQ24,
    /// The reduced (quasi-steady pressure) model in `f64`.
    Reduced,
    /// The adaptive stiff reference solver (Radau5, rtol 1e-12).
    Reference,
}

/// A simulated response sampled every tick.
#[derive(Clone, Debug)]
pub struct Response {
    /// Times [s].
    pub time: Vec<f64>,
    /// States.
    pub state: Vec<DynamicState<f64>>,
}

/// The temperature profile of a step (`ramp = None`) or a ramp [C/s].
pub fn profile(from: f64, to: f64, ramp: Option<f64>) -> Result<Profile, CliError> {
    for (name, v) in [("--from", from), ("--to", to)] {
        if !v.is_finite() {
            return Err(CliError::Input(format!("{name}: {v} is not finite")));
        }
    }
    match ramp {
        None => Ok(Profile::Step { from, to }),
        Some(rate) if rate.is_finite() && rate > 0.0 => Ok(Profile::Ramp { from, to, rate }),
        Some(rate) => Err(CliError::Input(format!("--ramp: {rate} must be a positive rate"))),
    }
}

fn widen<F: Float>(s: DynamicState<F>) -> DynamicState<f64> {
    DynamicState {
        x: s.x.to_f64(),
        v: s.v.to_f64(),
        p_a: s.p_a.to_f64(),
        p_b: s.p_b.to_f64(),
    }
}

/// `n` ticks of `config.tick` along `prof`, from a twin at rest at its
/// start, with the coefficients at each tick's midpoint (a ramp followed
/// to second order).
fn run<F: Float>(
    twin: Result<impl Dynamic<F>, ModelError>,
    config: &TwinConfig,
    prof: &Profile,
    n: usize,
) -> Result<Response, CliError> {
    let tick = config.tick;
    let mut twin = twin.map_err(|e| CliError::Input(format!("--from: {e}")))?;
    let mut out = Response {
        time: vec![0.0],
        state: vec![widen(twin.state())],
    };
    for k in 0..n {
        let t_mid = prof.temperature((k as f64 + 0.5) * tick);
        twin.set_temperature(F::from_f64(t_mid))
            .map_err(|e| CliError::Input(format!("temperature {t_mid} C: {e}")))?;
        twin.tick().map_err(|e| {
            CliError::Failed(format!(
                "tick {k} (t = {} s), {}: {e}",
                k as f64 * tick,
                describe(config)
            ))
        })?;
        out.time.push((k + 1) as f64 * tick);
        out.state.push(widen(twin.state()));
    }
    Ok(out)
}

fn run_twin<F: Float, T: Real>(
    params: &Params<F>,
    config: TwinConfig,
    prof: &Profile,
    n: usize,
) -> Result<Response, CliError> {
    let twin = Twin::<F, T>::new(params, config, F::from_f64(prof.start()));
    run(twin, &config, prof, n)
}

/// Simulates `prof` for `n` ticks of `config.tick` with the chosen precision.
pub fn simulate(
    raw: &RawParams,
    precision: Precision,
    config: TwinConfig,
    prof: &Profile,
    n: usize,
) -> Result<Response, CliError> {
    let p64 = || Params::<f64>::new(raw).map_err(|e| CliError::Input(e.to_string()));
    let p32 = || Params::<f32>::new(raw).map_err(|e| CliError::Input(e.to_string()));
    match precision {
        Precision::F64 => run_twin::<f64, f64>(&p64()?, config, prof, n),
        Precision::F32 => run_twin::<f32, f32>(&p32()?, config, prof, n),
        Precision::Fixed => run_twin::<f32, Fixed>(&p32()?, config, prof, n),
        Precision::FixedQ16 => run_twin::<f32, compensator::scalar::Q16_16>(&p32()?, config, prof, n),
        Precision::FixedQ24 => run_twin::<f32, compensator::scalar::Q8_24>(&p32()?, config, prof, n),
        Precision::Reduced => {
            let twin = ReducedTwin::<f64, f64>::new(&p64()?, config, prof.start());
            run(twin, &config, prof, n)
        }
        Precision::Reference => {
            // The profile's temperatures must be evaluable before the solver runs.
            let p = p64()?;
            for t in [prof.start(), prof.end()] {
                p.oil
                    .state(t)
                    .map_err(|e| CliError::Input(format!("temperature {t} C: {e}")))?;
            }
            let tr = reference::simulate(
                &raw.core,
                *prof,
                n as f64 * config.tick,
                config.tick,
                Method::Radau5,
                1e-12,
            )
            .map_err(CliError::Failed)?;
            Ok(Response {
                time: tr.time,
                state: tr
                    .state
                    .iter()
                    .map(|s| DynamicState {
                        x: s[0],
                        v: s[1],
                        p_a: s[2],
                        p_b: s[3],
                    })
                    .collect(),
            })
        }
    }
}

/// Default simulated time: the ramp's duration plus settling, or 0.5 s.
pub fn default_t_end(prof: &Profile) -> f64 {
    prof.kinks().first().copied().unwrap_or(0.0) + 0.5
}

/// Number of ticks for `t_end`, bounded to keep the output sane.
pub fn tick_count(t_end: f64, dt: f64) -> Result<usize, CliError> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(CliError::Input(format!("--dt: {dt} must be positive")));
    }
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(CliError::Input(format!("--t-end: {t_end} must be positive")));
    }
    if dt > t_end {
        return Err(CliError::Input(format!(
            "--dt: {dt} s is longer than --t-end {t_end} s"
        )));
    }
    let n = (t_end / dt).round();
    if n > 10_000_000.0 {
        return Err(CliError::Input(format!(
            "--t-end / --dt: {n} ticks is more than 10,000,000"
        )));
    }
    Ok(n as usize)
}

/// `scheme x substeps per tick`, e.g. `sdirk3, 2 substeps per 0.001 s tick`.
pub fn describe(config: &TwinConfig) -> String {
    format!(
        "{}, {} substep{} per {} s tick",
        config.scheme.name(),
        config.substeps,
        if config.substeps == 1 { "" } else { "s" },
        config.tick
    )
}

/// The chooser's configuration of the twin for a parameter file at `tick`
/// [s], over the file's validated range (`[estimator] valid_min`,
/// `valid_max`).
///
/// Errors: [`CliError::Input`] for parameters the model refuses or a tick
/// that is not a positive duration; [`CliError::Failed`] when the chooser
/// fails.
pub fn chosen(raw: &RawParams, tick: f64) -> Result<Choice, CliError> {
    let p = Params::<f64>::new(raw).map_err(|e| CliError::Input(e.to_string()))?;
    if !(tick > 0.0 && tick.is_finite()) {
        return Err(CliError::Input(format!(
            "tick {tick} s (--dt, the data's sample interval or 1/estimator.tick_hz): not a positive duration"
        )));
    }
    let valid = (raw.estimator.valid_min, raw.estimator.valid_max);
    choose(&p, tick, valid).map_err(|e| {
        CliError::Failed(format!(
            "choosing the twin's substeps over {}-{} C at a {tick} s tick: {e}",
            valid.0, valid.1
        ))
    })
}

/// `--substeps` within `1..=MAX_SUBSTEPS`.
fn check_substeps(substeps: Option<u8>) -> Result<(), CliError> {
    match substeps {
        Some(n) if n == 0 || n > compensator::dynamics::twin::MAX_SUBSTEPS => Err(CliError::Input(format!(
            "--substeps: {n} is not in 1..={}",
            compensator::dynamics::twin::MAX_SUBSTEPS
        ))),
        _ => Ok(()),
    }
}

/// The twin configuration of a run: the chooser's for the file at `tick`
/// [s], with `--scheme` and `--substeps` overriding their fields (an
/// explicit `--substeps` alone runs SDIRK3, the chooser's scheme, without
/// running the chooser). Also returns the one line saying so.
pub fn resolve_config(
    raw: &RawParams,
    tick: f64,
    scheme: Option<Scheme>,
    substeps: Option<u8>,
) -> Result<(TwinConfig, String), CliError> {
    check_substeps(substeps)?;
    if let Some(substeps) = substeps {
        let config = TwinConfig {
            scheme: scheme.unwrap_or(Scheme::Sdirk3),
            tick,
            substeps,
        };
        let given = if scheme.is_some() {
            "--scheme and --substeps"
        } else {
            "--substeps"
        };
        let line = format!("{}; from {given}, accuracy not estimated", describe(&config));
        return Ok((config, line));
    }
    let choice = chosen(raw, tick)?;
    let estimate = format!(
        "over the validated {}-{} C: estimated error {:.3} % of a step, target {TARGET_PCT} %: {}",
        raw.estimator.valid_min,
        raw.estimator.valid_max,
        choice.estimated_error_pct,
        if choice.goal_met {
            "met"
        } else {
            "NOT met (the finest candidate)"
        }
    );
    Ok(match scheme {
        Some(scheme) if scheme != choice.config.scheme => {
            let config = TwinConfig {
                scheme,
                ..choice.config
            };
            let line = format!(
                "{}; scheme from --scheme, substeps chosen for {} {estimate}",
                describe(&config),
                choice.config.scheme.name()
            );
            (config, line)
        }
        _ => (
            choice.config,
            format!("{}; chosen {estimate}", describe(&choice.config)),
        ),
    })
}

/// What `step` writes: the response table (standard output) and the one
/// line naming what computed it (standard error).
#[derive(Clone, Debug)]
pub struct StepOutput {
    /// CSV `time_s,x_m,v_m_s,p_a_pa,p_b_pa`.
    pub csv: String,
    /// What the command prints: CSV
    /// `time_s,t_c,x_m,v_m_s,p_a_pa,p_b_pa,envelope` (the temperature each
    /// tick ran at, and its zone of the file's envelope).
    pub table: String,
    /// The configuration used, in one line.
    pub note: String,
}

/// `step`: response table. The twin's configuration is the chooser's for
/// the file at `dt` unless `scheme` or `substeps` override it
/// ([`resolve_config`]).
#[allow(clippy::too_many_arguments)]
pub fn step(
    path: &Path,
    from: f64,
    to: f64,
    ramp: Option<f64>,
    dt: f64,
    t_end: Option<f64>,
    precision: Precision,
    scheme: Option<Scheme>,
    substeps: Option<u8>,
) -> Result<StepOutput, CliError> {
    let (raw, _, env) = crate::input::load_with_envelope(path)?;
    let prof = profile(from, to, ramp)?;
    env.check(from, "--from")?;
    env.check(to, "--to")?;
    let n = tick_count(t_end.unwrap_or_else(|| default_t_end(&prof)), dt)?;
    check_substeps(substeps)?;
    let (config, note) = if precision == Precision::Reference {
        if n > reference::MAX_SAMPLES {
            return Err(CliError::Input(format!(
                "--t-end / --dt: {n} output samples exceed the reference solver's limit of {} \
                 (at least one solver step each); use a larger --dt or a shorter --t-end",
                reference::MAX_SAMPLES
            )));
        }
        let config = TwinConfig {
            tick: dt,
            ..TwinConfig::SHIPPED
        };
        (
            config,
            format!("reference: Radau5 (rtol 1e-12), sampled every {dt} s; --scheme and --substeps do not apply"),
        )
    } else {
        let (config, line) = resolve_config(&raw, dt, scheme, substeps)?;
        let model = if precision == Precision::Reduced {
            format!(
                "reduced model (runs {} for {})",
                config.scheme.generic().name(),
                config.scheme.name()
            )
        } else {
            "twin".to_string()
        };
        (config, format!("{model}: {line}"))
    };
    let r = simulate(&raw, precision, config, &prof, n)?;
    let mut table = Table::complete(&["time_s", "x_m", "v_m_s", "p_a_pa", "p_b_pa"]);
    let mut with_t = Table::complete(&["time_s", "t_c", "x_m", "v_m_s", "p_a_pa", "p_b_pa"]);
    for (t, s) in r.time.iter().zip(&r.state) {
        // The temperature the tick that ended here ran at (its midpoint,
        // as `run` sets it), the start's at t = 0: what `identify` reads.
        let t_c = if *t == 0.0 {
            prof.start()
        } else {
            prof.temperature(*t - 0.5 * dt)
        };
        table.row(&[*t, s.x, s.v, s.p_a, s.p_b]);
        with_t.row(&[*t, t_c, s.x, s.v, s.p_a, s.p_b]);
    }
    Ok(StepOutput {
        csv: table.as_str().to_string(),
        table: env.mark(with_t.as_str(), &["t_c"]),
        note,
    })
}

/// `twin-config`: the chooser's configuration for a parameter file at
/// `dt` [s], one CSV row.
pub fn twin_config(path: &Path, dt: f64) -> Result<String, CliError> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(CliError::Input(format!("--dt: {dt} must be positive")));
    }
    let (raw, _) = load_params::<f64>(path)?;
    let c = chosen(&raw, dt)?;
    Ok(format!(
        "scheme,substeps,tick_s,valid_min_c,valid_max_c,estimated_error_pct,target_pct,goal_met\n\
         {},{},{},{},{},{},{},{}\n",
        c.config.scheme.name(),
        c.config.substeps,
        c.config.tick,
        raw.estimator.valid_min,
        raw.estimator.valid_max,
        c.estimated_error_pct,
        TARGET_PCT,
        c.goal_met
    ))
}

/// `eigen`: eigenvalues of the linearisation per temperature.
pub fn eigen(path: &Path, temps_spec: &str) -> Result<String, CliError> {
    let input = crate::input::load_at_temps(path, temps_spec)?;
    Ok(input.mark(eigen_table(&input.params, &input.temps).as_str()))
}

/// The `eigen` table of a parameter set at `temps` [C]: eigenvalues
/// [1/s] of the linearisation (Eq. 37), the dominant mode's damping ratio
/// and natural frequency [rad/s] (1 and |lambda| for a real mode), and
/// the plunger's damping ratio with the chambers' hydraulic damping,
/// `(b + b_hyd) / (2 sqrt(c m))` (above 1: overdamped); a temperature the
/// model cannot evaluate gets an `error` cell.
pub fn eigen_table(p: &Params<f64>, temps: &[f64]) -> Table {
    let mut table = Table::new(&[
        "t_c",
        "re_1",
        "im_1",
        "re_2",
        "im_2",
        "re_3",
        "im_3",
        "re_4",
        "im_4",
        "zeta_dominant",
        "omega_n_dominant",
        "zeta_plunger",
    ]);
    table.rows_at(temps, |t| {
        let l = linearise(p, t)?;
        let mut row: Vec<f64> = l.eigenvalues.iter().flat_map(|e| [e.re, e.im]).collect();
        row.extend([l.damping_ratio[0], l.natural_frequency[0], l.plunger_damping_ratio]);
        Ok::<_, compensator::ModelError>(row)
    });
    table
}

/// Step-response indicators (Table 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Indicators {
    /// Initial temperature [C].
    pub from: f64,
    /// Final temperature [C].
    pub to: f64,
    /// Final equilibrium displacement `x*` [m].
    pub x_star: f64,
    /// Time to enter and stay within +-2 % of `x*` [s].
    pub settling_time: f64,
    /// Largest excursion beyond `x*` in percent of the step `|x* - x0|`.
    pub overshoot_pct: f64,
    /// Largest real part of the linearisation at `to` [1/s].
    pub dominant_re: f64,
}

/// Indicators of a sampled response.
pub fn indicators_of(time: &[f64], x: &[f64], x_star: f64) -> (f64, f64) {
    let band = 0.02 * x_star.abs();
    let mut settle = 0.0;
    for i in (0..x.len()).rev() {
        if (x[i] - x_star).abs() > band {
            settle = if i + 1 < time.len() { time[i + 1] } else { f64::INFINITY };
            break;
        }
    }
    let x0 = x[0];
    let step = x_star - x0;
    let over = if step != 0.0 {
        x.iter().map(|v| (v - x_star) * step.signum()).fold(0.0f64, f64::max) / step.abs() * 100.0
    } else {
        0.0
    };
    (settle, over)
}

/// Indicators for a step `from -> to`, from the reference solver sampled
/// every `dt` over `t_end`.
pub fn step_indicators(
    raw: &RawParams,
    p: &Params<f64>,
    from: f64,
    to: f64,
    dt: f64,
    t_end: f64,
) -> Result<Indicators, CliError> {
    let x_star = equilibrium(p, to)
        .map_err(|e| CliError::Input(format!("--steps: {to} C: {e}")))?
        .x;
    equilibrium(p, from).map_err(|e| CliError::Input(format!("--steps: {from} C: {e}")))?;
    let tr = reference::simulate(&raw.core, Profile::Step { from, to }, t_end, dt, Method::Radau5, 1e-10)
        .map_err(CliError::Failed)?;
    let x: Vec<f64> = tr.state.iter().map(|s| s[0]).collect();
    let (settling_time, overshoot_pct) = indicators_of(&tr.time, &x, x_star);
    let lin = linearise(p, to).map_err(|e| CliError::Failed(format!("linearisation at {to} C: {e}")))?;
    Ok(Indicators {
        from,
        to,
        x_star,
        settling_time,
        overshoot_pct,
        dominant_re: lin.dominant.re,
    })
}

/// Parses `30:40,40:50,...`.
pub fn parse_steps(spec: &str) -> Result<Vec<(f64, f64)>, CliError> {
    spec.split(',')
        .map(|pair| {
            let mut it = pair.split(':');
            let (a, b) = (it.next(), it.next());
            match (
                a.map(str::trim).and_then(|s| s.parse::<f64>().ok()),
                b.map(str::trim).and_then(|s| s.parse::<f64>().ok()),
                it.next(),
            ) {
                (Some(a), Some(b), None) if a.is_finite() && b.is_finite() => Ok((a, b)),
                _ => Err(CliError::Input(format!("--steps: '{pair}' is not of the form from:to"))),
            }
        })
        .collect()
}

/// `indicators`: the Table 3 columns per step.
pub fn indicators(path: &Path, steps_spec: &str, dt: f64, t_end: f64) -> Result<String, CliError> {
    let (raw, p, env) = crate::input::load_with_envelope(path)?;
    let steps = parse_steps(steps_spec)?;
    for (from, to) in &steps {
        env.check_all(&[*from, *to], "--steps")?;
    }
    tick_count(t_end, dt)?;
    let mut table = Table::new(&[
        "from_c",
        "to_c",
        "x_star_m",
        "settling_time_s",
        "overshoot_pct",
        "dominant_re",
    ]);
    for (from, to) in steps {
        let ind = match step_indicators(&raw, &p, from, to, dt, t_end) {
            Ok(ind) => ind,
            Err(e) => {
                table.row_error(&[from, to], &e.to_string());
                continue;
            }
        };
        table.row(&[
            ind.from,
            ind.to,
            ind.x_star,
            ind.settling_time,
            ind.overshoot_pct,
            ind.dominant_re,
        ]);
    }
    Ok(env.mark(table.as_str(), &["from_c", "to_c"]))
}

/// Ticks per output row for `step --sample S` at tick `dt`: round(S / dt),
/// at least one; without `--sample`, every tick.
pub fn sample_every(sample: Option<f64>, dt: f64) -> Result<usize, CliError> {
    let Some(s) = sample else { return Ok(1) };
    if !(dt > 0.0 && dt.is_finite()) {
        return Ok(1); // `step` names --dt
    }
    if !(s > 0.0 && s.is_finite()) {
        return Err(CliError::Input(format!("--sample: {s} must be positive")));
    }
    let n = (s / dt).round();
    if !(n >= 1.0 && n.is_finite()) {
        return Err(CliError::Input(format!(
            "--sample: {s} s is shorter than half a tick (--dt {dt} s)"
        )));
    }
    Ok(n.min(usize::MAX as f64) as usize)
}

/// CSV text with its header and every `every`-th row from the first.
pub fn every_nth_row(csv: &str, every: usize) -> String {
    if every <= 1 {
        return csv.to_string();
    }
    let mut lines = csv.lines();
    let mut out = String::new();
    for line in lines.next().into_iter().chain(lines.step_by(every)) {
        out.push_str(line);
        out.push('\n');
    }
    out
}
