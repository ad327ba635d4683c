//! The step response of a sweep's variant from the `f64` twin: its 2 %
//! settling time on the output grid `k dt`, `k = 0..=round(t_end / dt)`,
//! as [`crate::dynamics::indicators_of`] takes it from the reference
//! solver's samples (the time of the sample after the last one outside
//! `+-2 % |x*|`, infinite when the last sample is outside).
//!
//! Why not tick at `dt`: the reference solver and a twin ticking at the
//! output interval both take at least `t_end / dt` steps (2,000 for the
//! defaults), milliseconds per variant. The response only needs as many
//! steps as its own dynamics: the twin ticks at `k dt`, the largest
//! multiple of `dt` within [`KAPPA`] over the fastest mode the response
//! must follow ([`plan`]), and the samples in between come from the cubic
//! Hermite interpolant of the displacement and velocity at the tick ends
//! (error `h^4 max|x''''| / 384`: 1e-5 of the step at `KAPPA`). Only the
//! tick interval where the response last leaves the band is interpolated:
//! walking back from the end, an interval whose interpolant cannot reach
//! the band's edge (`max |x - x*| + 4/27 h (|v_0| + |v_1|)`, the Hermite
//! basis' bound) is skipped whole.
//!
//! The run ends early once the response is at rest for good: the
//! mechanical deviation `|x - x*| + |v| / w_min` (`w_min` the smallest
//! eigenvalue modulus: the slowest mode's amplitude bound, an energy of
//! the plunger that only decays) below [`REST_FRACTION`] of the band.
//! A tick with a stop event (an impact or a release, where the velocity
//! jumps and the interpolant does not hold) makes the whole run start
//! again at a tick of `dt` (no interpolation).
//!
//! `host-tests/tests/sweep_twin.rs` checks the responses and settling
//! times against the reference solver's on many variants.

use compensator::Params;
use compensator::dynamics::linear::Linearisation;
use compensator::dynamics::twin::MAX_SUBSTEPS;
use compensator::dynamics::{Scheme, Twin, TwinConfig};

/// Largest `|lambda| h` of a twin step for the modes the response follows
/// ([`plan`]): SDIRK3's error
/// per step of an oscillation is about `(|lambda| h)^4 / 24` of its
/// amplitude; at 0.1 the response stays within 0.05 % of the step of the
/// reference over the variants of `cli/tests/sweep_twin.rs`.
pub const KAPPA: f64 = 0.1;

/// Fewest ticks over `t_end` (a response slower than the record is still
/// sampled by the twin's own ticks).
pub const MIN_TICKS: f64 = 50.0;

/// The run stops when the plunger's deviation from `x*` is below this
/// fraction of the 2 % band ([`settling_time`]).
pub const REST_FRACTION: f64 = 0.01;

/// How the twin is run for a step response.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// The twin's configuration (tick a multiple of `dt`).
    pub config: TwinConfig,
    /// Output samples per tick.
    pub per_tick: usize,
    /// With coarse ticks (`per_tick > 1`): the first samples, taken one
    /// twin tick of `dt` each while the modes the coarse ticks leave out
    /// decay ([`GONE`] e-folds, at most one coarse tick).
    pub window: usize,
    /// Substeps of those ticks of `dt`: enough for a fast oscillation still
    /// alive there (`KAPPA / |lambda|` steps), 1 when there is none.
    pub window_substeps: u8,
}

/// A mode the coarse ticks do not resolve must have decayed by this many
/// e-folds within the first coarse tick (taken at `dt`, [`settling_time`]):
/// what is left of it, 1e-3 of its start, is below the error budget.
pub const GONE: f64 = 7.0;

/// The twin's tick and substeps for a response sampled every `dt` over
/// `t_end` with linearisation `lin` at the final temperature: steps `h` of
/// at most `KAPPA / |lambda|` for every mode the coarse ticks must follow,
/// the dominant one and any other that has not decayed by [`GONE`] e-folds
/// within one step (`|Re lambda| h < GONE`): the chambers' stiff modes and
/// an overdamped plunger's fast one decay within the first coarse tick,
/// which is taken at `dt`, and SDIRK3 is L-stable. The tick is `k dt`, `k`
/// the largest whole number of samples within `h` and within
/// `t_end / MIN_TICKS`, or `dt` in as many substeps as `h` needs (at most
/// `MAX_SUBSTEPS`).
pub fn plan(lin: &Linearisation<f64>, dt: f64, t_end: f64) -> Plan {
    let modulus = |l: &compensator::dynamics::linear::Complex<f64>| l.re.hypot(l.im);
    let mut modes: Vec<(f64, f64)> = lin.eigenvalues.iter().map(|l| (modulus(l), l.re.abs())).collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut h = (t_end / MIN_TICKS).max(dt);
    let dominant = modulus(&lin.dominant);
    if dominant > 0.0 && dominant.is_finite() {
        h = h.min(KAPPA / dominant);
    }
    // Ascending modulus: a step shortened for one mode resolves every
    // slower one, so each is decided once.
    for (w, decay) in modes {
        if w.is_finite() && w * h > KAPPA && decay * h < GONE {
            h = KAPPA / w;
        }
    }
    let (per_tick, substeps) = if h >= dt {
        (((h / dt).floor() as usize).max(1), 1)
    } else {
        (1, ((dt / h).ceil().min(f64::from(MAX_SUBSTEPS))) as u8)
    };
    // The first samples at `dt`, until the modes the coarse ticks leave out
    // have decayed; a fast oscillation among them still alive over one
    // sample is followed by substeps.
    let coarse = per_tick as f64 * dt;
    let (mut window, mut w_sub) = (1usize, 1.0f64);
    for l in &lin.eigenvalues {
        let (w, decay) = (modulus(l), l.re.abs());
        if !(w.is_finite() && w * coarse > KAPPA) || decay == 0.0 {
            continue;
        }
        window = window.max((GONE / (decay * dt)).ceil().min(per_tick as f64) as usize);
        if l.im != 0.0 && decay * dt < GONE {
            w_sub = w_sub.max((w * dt / KAPPA).ceil());
        }
    }
    Plan {
        config: TwinConfig {
            scheme: Scheme::Sdirk3,
            tick: coarse,
            substeps,
        },
        per_tick,
        window: window.min(per_tick),
        window_substeps: w_sub.min(f64::from(MAX_SUBSTEPS)) as u8,
    }
}

/// A state the twin computed: at output sample `k`, displacement [m] and
/// velocity [m/s].
#[derive(Clone, Copy, Debug)]
struct End {
    k: usize,
    x: f64,
    v: f64,
}

/// Outcome of a run ([`settling_time`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settling {
    /// 2 % settling time [s] on the output grid (infinite: still outside
    /// the band at `t_end`).
    pub time: f64,
    /// Twin ticks run (the fine ones of the first coarse tick included).
    pub ticks: usize,
    /// The run was repeated at a tick of `dt` (a stop event).
    pub fine: bool,
}

/// When a run may stop before `t_end`: the final displacement, the rest
/// threshold and the smallest eigenvalue modulus ([`settling_time`]).
#[derive(Clone, Copy, Debug)]
struct Rest {
    x_star: f64,
    threshold: f64,
    w_min: f64,
}

/// A step response to run: the step `from -> to` [C] of `p`, sampled
/// every `dt` [s] to `samples`, or to rest when `rest` is given.
#[derive(Clone, Copy)]
struct Run<'a> {
    p: &'a Params<f64>,
    from: f64,
    to: f64,
    dt: f64,
    samples: usize,
    rest: Option<Rest>,
}

impl<'a> Run<'a> {
    /// The step `from -> to` of `p` sampled every `dt` to
    /// `round(t_end / dt) dt`, run to the end.
    fn new(p: &'a Params<f64>, from: f64, to: f64, dt: f64, t_end: f64) -> Self {
        Run {
            p,
            from,
            to,
            dt,
            samples: (t_end / dt).round() as usize,
            rest: None,
        }
    }
}

/// The twin's states at the output samples `run` lands on, from 0 to at
/// least `samples` (or to rest): the first `plan.window` samples one twin
/// tick of `dt` each (the transient right after the step is not a cubic
/// over a coarse tick), then one coarse tick per `plan.per_tick` samples,
/// the coarse twin started from the fine one's state. `None` when a coarse
/// tick has a stop event (the caller runs again at a tick of `dt`).
fn integrate(run: Run, plan: Plan) -> Result<Option<Vec<End>>, String> {
    let Run {
        p,
        from,
        to,
        dt,
        samples,
        rest,
    } = run;
    let fine = TwinConfig {
        tick: dt,
        substeps: if plan.per_tick > 1 {
            plan.window_substeps
        } else {
            plan.config.substeps
        },
        ..plan.config
    };
    let mut twin = Twin::<f64, f64>::new(p, fine, from).map_err(|e| format!("twin at {from} C: {e}"))?;
    twin.set_temperature(to).map_err(|e| format!("twin at {to} C: {e}"))?;
    let s = twin.state();
    let mut ends = vec![End { k: 0, x: s.x, v: s.v }];
    let at_rest = |e: &End| rest.is_some_and(|r| (e.x - r.x_star).abs() + e.v.abs() / r.w_min <= r.threshold);
    let window = if plan.per_tick > 1 {
        plan.window.min(samples)
    } else {
        samples
    };
    for k in 1..=window {
        let report = twin
            .tick()
            .map_err(|e| format!("twin tick {} (t = {} s): {e}", k - 1, (k - 1) as f64 * dt))?;
        let s = twin.state();
        ends.push(End { k, x: s.x, v: s.v });
        if !(report.impact || report.release) && at_rest(&ends[ends.len() - 1]) {
            return Ok(Some(ends));
        }
    }
    if window >= samples {
        return Ok(Some(ends));
    }
    let mut coarse = Twin::<f64, f64>::new(p, plan.config, to).map_err(|e| format!("twin at {to} C: {e}"))?;
    coarse.set_state(&twin.state());
    let mut k = window;
    while k < samples {
        let report = coarse
            .tick()
            .map_err(|e| format!("twin tick at t = {} s: {e}", k as f64 * dt))?;
        if report.impact || report.release {
            return Ok(None);
        }
        k += plan.per_tick;
        let s = coarse.state();
        ends.push(End { k, x: s.x, v: s.v });
        if at_rest(&ends[ends.len() - 1]) {
            break;
        }
    }
    Ok(Some(ends))
}

/// [`integrate`], again at a tick of `dt` throughout when the plan's
/// coarse ticks meet a stop event; and whether it was.
fn states(run: Run, plan: Plan) -> Result<(Vec<End>, bool), String> {
    if let Some(ends) = integrate(run, plan)? {
        return Ok((ends, false));
    }
    let fine = Plan {
        config: TwinConfig {
            tick: run.dt,
            substeps: plan.window_substeps,
            ..plan.config
        },
        per_tick: 1,
        window: 1,
        window_substeps: plan.window_substeps,
    };
    let ends = integrate(run, fine)?.ok_or("unreachable: a run at the output interval has no coarse tick")?;
    Ok((ends, true))
}

/// The 2 % settling time of the step `from -> to` [C] of `p`, on the grid
/// `k dt` up to `round(t_end / dt) dt`, with `lin` the linearisation at
/// `to` and `x_star` the equilibrium there (module docs).
///
/// Errors: the twin refuses the design or a temperature, or a tick fails
/// (the message names it).
pub fn settling_time(
    p: &Params<f64>,
    lin: &Linearisation<f64>,
    from: f64,
    to: f64,
    dt: f64,
    t_end: f64,
    x_star: f64,
) -> Result<Settling, String> {
    let run = Run::new(p, from, to, dt, t_end);
    let samples = run.samples;
    let band = 0.02 * x_star.abs();
    let rest = Rest {
        x_star,
        threshold: REST_FRACTION * band,
        w_min: lin
            .eigenvalues
            .iter()
            .map(|l| l.re.hypot(l.im))
            .fold(f64::INFINITY, f64::min),
    };
    let run = Run {
        rest: Some(rest),
        ..run
    };
    let (ends, fine) = states(run, plan(lin, dt, t_end))?;
    let ticks = ends.len() - 1;
    let done = |k: usize| Settling {
        time: if k < samples {
            (k + 1) as f64 * dt
        } else {
            f64::INFINITY
        },
        ticks,
        fine,
    };
    let outside = |x: f64| (x - x_star).abs() > band;
    // Walk back to the last sample outside the band.
    for i in (0..ends.len() - 1).rev() {
        let (a, b) = (ends[i], ends[i + 1]);
        let h = (b.k - a.k) as f64 * dt;
        let reach = (a.x - x_star).abs().max((b.x - x_star).abs()) + 4.0 / 27.0 * h * (a.v.abs() + b.v.abs());
        if !(reach > band) {
            continue;
        }
        for k in (a.k + 1..=b.k).rev() {
            if k > samples {
                continue;
            }
            let x = if k == b.k {
                b.x
            } else {
                hermite(a, b, h, (k - a.k) as f64 / (b.k - a.k) as f64)
            };
            if outside(x) {
                return Ok(done(k));
            }
        }
    }
    if outside(ends[0].x) {
        return Ok(done(0));
    }
    // Never outside (a step smaller than the band).
    Ok(Settling { time: 0.0, ticks, fine })
}

/// The displacement [m] at every output sample `k dt`, `k = 0..=round(t_end
/// / dt)`, as [`settling_time`] sees it: the twin's states and the Hermite
/// interpolant between them, run to the end (no early stop). For checking
/// against the reference solver.
///
/// Errors: as [`settling_time`].
pub fn sampled(
    p: &Params<f64>,
    lin: &Linearisation<f64>,
    from: f64,
    to: f64,
    dt: f64,
    t_end: f64,
) -> Result<Vec<f64>, String> {
    let run = Run::new(p, from, to, dt, t_end);
    let samples = run.samples;
    let (ends, _) = states(run, plan(lin, dt, t_end))?;
    let mut out = vec![ends[0].x];
    for w in ends.windows(2) {
        let (a, b) = (w[0], w[1]);
        let h = (b.k - a.k) as f64 * dt;
        for k in a.k + 1..=b.k.min(samples) {
            out.push(if k == b.k {
                b.x
            } else {
                hermite(a, b, h, (k - a.k) as f64 / (b.k - a.k) as f64)
            });
        }
    }
    Ok(out)
}

/// The cubic Hermite interpolant of the displacement between twin states
/// `a` and `b`, `h` apart, at fraction `s` of the way.
fn hermite(a: End, b: End, h: f64, s: f64) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    h00 * a.x + h10 * h * a.v + h01 * b.x + h11 * h * b.v
}
