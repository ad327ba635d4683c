//! The sweep's step responses from the `f64` twin against the reference
//! solver (`compensator sweep`'s settling time, `cli/src/sweep/step_response.rs`):
//! the variants, the comparison, shared by the test
//! (`tests/sweep_twin.rs`) and the survey (`examples/sweep_twin.rs`).
//!
//! Variants: alternately a random physical design
//! ([`crate::random::physical_params`]) and the paper preset with its
//! plunger mass, friction, spring rate, plunger and window diameters and
//! chamber volumes each scaled by `4^u`, `u` uniform in [-1, 1] (the kind of
//! grid a sweep runs), those the validation refuses skipped.

use crate::random::{Rng, physical_params};
use compensator::Params;
use compensator::dynamics::linear::linearise;
use compensator::equilibrium::equilibrium;
use compensator::params::RawParams;
use compensator_cli::dynamics::indicators_of;
use compensator_cli::sweep::step_response::{plan, sampled, settling_time};
use compensator_reference::dynamics::{Method, Profile, simulate};

/// Variant `index` of seed `seed` (module docs).
pub fn variant(seed: u64, index: u64, paper: &RawParams) -> RawParams {
    let mut rng = Rng::new(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index.wrapping_mul(0xBF58_476D_1CE4_E5B9));
    loop {
        let raw = if index.is_multiple_of(2) {
            physical_params(&mut rng)
        } else {
            let mut r = *paper;
            let mut scale = |v: &mut f64| *v *= 4f64.powf(rng.uniform(-1.0, 1.0));
            scale(&mut r.core.mass);
            scale(&mut r.core.damping);
            scale(&mut r.core.spring_rate);
            scale(&mut r.core.plunger_diameter);
            scale(&mut r.core.slot_diameter);
            scale(&mut r.core.volume_a);
            scale(&mut r.core.volume_b);
            r
        };
        if raw.validate().is_ok() {
            return raw;
        }
    }
}

/// Steps tried on a variant, in order, until one moves the plunger: the
/// sweep's default first, then wider ones (onto a stop, or from one).
pub const STEPS: [(f64, f64); 5] = [(40.0, 50.0), (30.0, 60.0), (60.0, 30.0), (20.0, 80.0), (80.0, 20.0)];

/// [`compare`] on the first of [`STEPS`] that moves the plunger.
pub fn compare_first(raw: &RawParams, dt: f64, t_end: f64) -> Result<((f64, f64), Compared), String> {
    let mut last = String::new();
    for (from, to) in STEPS {
        match compare(raw, from, to, dt, t_end) {
            Ok(c) => return Ok(((from, to), c)),
            Err(e) => last = e,
        }
    }
    Err(last)
}

/// One variant's twin response against the reference solver's.
#[derive(Clone, Debug)]
pub struct Compared {
    /// Largest `|x_twin - x_ref|` over the samples, in % of the step
    /// `|x(t_end) - x(0)|` of the reference.
    pub max_error_pct: f64,
    /// Where [s].
    pub max_error_at: f64,
    /// The step `|x* - x0|` [m].
    pub step: f64,
    /// Settling time of the reference's samples [s].
    pub settling_reference: f64,
    /// Settling time the sweep reports from the twin [s].
    pub settling_twin: f64,
    /// How far apart the two may be: one sample, plus the shift of the
    /// band crossing that an error of 0.1 % of the step makes at the
    /// reference's slope there [s].
    pub allowed: f64,
    /// Output samples per twin tick, substeps per tick.
    pub plan: (usize, u8),
    /// Twin ticks the sweep ran (with its early stop).
    pub ticks: usize,
    /// The run met a stop event and was repeated at a tick of `dt`.
    pub fine: bool,
}

impl Compared {
    /// The settling times agree within [`Compared::allowed`] (both
    /// infinite counts as agreeing).
    pub fn settling_agrees(&self) -> bool {
        self.settling_twin == self.settling_reference
            || (self.settling_twin - self.settling_reference).abs() <= self.allowed
    }
}

/// The step `from -> to` of `raw` sampled every `dt` over `t_end`, by the
/// twin as the sweep runs it and by the reference solver (Radau5, rtol
/// 1e-10); `None` where either cannot run or the step does not move the
/// plunger (less than 1e-6 of the stroke): `Err` says which.
pub fn compare(raw: &RawParams, from: f64, to: f64, dt: f64, t_end: f64) -> Result<Compared, String> {
    let p = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let x_star = equilibrium(&p, to).map_err(|e| e.to_string())?.x;
    equilibrium(&p, from).map_err(|e| e.to_string())?;
    let lin = linearise(&p, to).map_err(|e| e.to_string())?;
    let tr = simulate(&raw.core, Profile::Step { from, to }, t_end, dt, Method::Radau5, 1e-10)
        .map_err(|e| format!("reference: {e}"))?;
    let x_ref: Vec<f64> = tr.state.iter().map(|s| s[0]).collect();
    let x_twin = sampled(&p, &lin, from, to, dt, t_end).map_err(|e| format!("twin: {e}"))?;
    let settled = settling_time(&p, &lin, from, to, dt, t_end, x_star).map_err(|e| format!("twin: {e}"))?;
    let step = (x_star - x_ref[0]).abs();
    if !(step > 1e-6 * raw.core.stroke) {
        return Err("no step: the plunger stays on a stop".into());
    }
    if x_twin.len() != x_ref.len() {
        return Err(format!("{} twin samples, {} reference", x_twin.len(), x_ref.len()));
    }
    let (k_max, max_error) = x_twin
        .iter()
        .zip(&x_ref)
        .map(|(a, b)| (a - b).abs())
        .enumerate()
        .fold((0, 0.0), |m, (k, e)| if e > m.1 { (k, e) } else { m });
    let max_error_pct = max_error / step * 100.0;
    let max_error_at = tr.time[k_max];
    let (settling_reference, _) = indicators_of(&tr.time, &x_ref, x_star);
    // The reference's slope where it last leaves the band.
    let k = ((settling_reference / dt).round() as usize).min(x_ref.len() - 1);
    let slope = if k >= 1 {
        ((x_ref[k] - x_ref[k - 1]) / dt).abs()
    } else {
        0.0
    };
    let allowed = dt
        + if slope > 0.0 {
            1e-3 * step / slope
        } else {
            f64::INFINITY
        };
    let pl = plan(&lin, dt, t_end);
    Ok(Compared {
        max_error_pct,
        max_error_at,
        step,
        settling_reference,
        settling_twin: settled.time,
        allowed,
        plan: (pl.per_tick, pl.config.substeps),
        ticks: settled.ticks,
        fine: settled.fine,
    })
}
