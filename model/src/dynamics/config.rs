//! Choosing the twin's configuration for one design, from its own dynamics.
//!
//! How many substeps a 1 ms tick needs depends on the design: an
//! overdamped plunger (the paper's) is followed to 0.1 % of a step by one
//! SDIRK3 step per tick; an underdamped one whose period spans a few ticks,
//! or one whose release from a stop rides a pressure transient of tens of
//! microseconds, needs more. [`choose`] decides it before anything is
//! flashed: it runs the twin (`f64`) on abrupt probe steps over the
//! validated range ([`probes`]) at each candidate substep count of
//! [`LADDER`], measures the largest deviation from the same twin at
//! [`MAX_SUBSTEPS`] (converged to ~0.01 % of a step), and takes the
//! cheapest count whose deviation stays within [`TARGET_PCT`] on every
//! probe: half the `f64` goal of 0.1 % of the step, the other half left for
//! what the finest twin still misses. The host survey
//! (`host-tests/tests/survey.rs`) checks the choice against the
//! independent reference on every surveyed design.
//!
//! The cost is a few hundred thousand twin substeps in `f64` on the host
//! (about a second in release builds); the firmware's build and the CLI
//! run it, never the controller.

use super::linear::linearise;
use super::schemes::Scheme;
use super::twin::{MAX_SUBSTEPS, Twin, TwinConfig};
use crate::error::ModelError;
use crate::params::Params;

/// Candidate substep counts, cheapest first.
pub const LADDER: [u8; 10] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32];

/// Largest deviation from the finest twin accepted, in % of a probe's step.
pub const TARGET_PCT: f64 = 0.05;

/// Probe steps moving the plunger by less than this fraction of the stroke
/// measure nothing (the error is a percentage of the step).
pub const MIN_STEP: f64 = 0.01;

/// Longest probe \[s\]: the errors of a step arise in its first transient.
pub const MAX_PROBE: f64 = 0.5;

/// The probe steps `(from, to)` \[C\] over a validated range: both ways
/// across it, from its middle to either end and back, and between its
/// quarter points both ways. Outside the validated range the twin's
/// promise is its end state (the closed-form equilibrium), not its
/// trajectory: cold oil needs no probe.
pub fn probes(valid: (f64, f64)) -> [(f64, f64); PROBES] {
    let (lo, hi) = valid;
    let mid = 0.5 * (lo + hi);
    let (q1, q3) = (0.75 * lo + 0.25 * hi, 0.25 * lo + 0.75 * hi);
    [
        (lo, hi),
        (hi, lo),
        (mid, hi),
        (hi, mid),
        (mid, lo),
        (lo, mid),
        (q1, q3),
        (q3, q1),
    ]
}

/// Number of probe steps.
pub const PROBES: usize = 8;

/// The configuration [`choose`] settled on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    /// Scheme, tick and substeps.
    pub config: TwinConfig,
    /// Largest deviation from the finest twin over the probes, in % of the
    /// probe's step.
    pub estimated_error_pct: f64,
    /// `estimated_error_pct <= TARGET_PCT` (otherwise the finest candidate
    /// of [`LADDER`] is returned, with its estimate).
    pub goal_met: bool,
}

/// Displacements [m] of an `f64` twin over `ticks` ticks of a step.
fn run(p: &Params<f64>, config: TwinConfig, from: f64, to: f64, out: &mut [f64]) -> Result<(), ModelError> {
    let mut twin = Twin::<f64, f64>::new(p, config, from)?;
    twin.set_temperature(to)?;
    out[0] = twin.state().x;
    for x in out.iter_mut().skip(1) {
        twin.tick().map_err(|_| ModelError::NoConvergence("twin probe"))?;
        *x = twin.state().x;
    }
    Ok(())
}

/// Longest probe in ticks (the probe is cut at [`MAX_PROBE`] or here).
const MAX_TICKS: usize = 500;

/// Chooses the substeps per `tick` \[s\] of the SDIRK3 twin for `params`
/// over the validated range `valid` \[C\]. Probe temperatures the oil model
/// refuses are left out.
///
/// # Errors
///
/// * `OutOfRange("tick")`: `tick` is not a positive, finite duration;
/// * a probe's twin cannot be built ([`Twin::new`]'s errors);
/// * `NoConvergence("twin probe")`: a probe's twin fails a tick.
pub fn choose(params: &Params<f64>, tick: f64, valid: (f64, f64)) -> Result<Choice, ModelError> {
    if !(tick > 0.0 && tick.is_finite()) {
        return Err(ModelError::OutOfRange("tick"));
    }
    let stroke = params.plunger.stroke;
    let config = |substeps: u8| TwinConfig {
        scheme: Scheme::Sdirk3,
        tick,
        substeps,
    };
    // The finest twin on every probe that moves the plunger.
    let mut fine = [[0.0f64; MAX_TICKS + 1]; PROBES];
    let mut used = [(0.0, 0.0, 0usize, 0.0); PROBES];
    let mut count = 0;
    for (from, to) in probes(valid) {
        let Ok(lin) = linearise(params, to) else { continue };
        if params.oil.state(from).is_err() {
            continue;
        }
        // Five slow time constants, cut at MAX_PROBE, but at least 20
        // ticks (a tick longer than MAX_PROBE / 20 wins over the cut: not
        // `clamp`, which panics when its bounds cross).
        let duration = (5.0 / lin.dominant.re.abs()).min(MAX_PROBE).max(20.0 * tick);
        let ticks = ((duration / tick) as usize).clamp(1, MAX_TICKS);
        let x = &mut fine[count][..=ticks];
        run(params, config(MAX_SUBSTEPS), from, to, x)?;
        let step = (x[ticks] - x[0]).abs();
        if step >= MIN_STEP * stroke {
            used[count] = (from, to, ticks, step);
            count += 1;
        }
    }
    // The cheapest candidate within the target on every probe.
    let mut coarse = [0.0f64; MAX_TICKS + 1];
    let mut last = (LADDER[LADDER.len() - 1], 0.0f64);
    for &n in &LADDER {
        let mut worst = 0.0f64;
        for (p, &(from, to, ticks, step)) in used[..count].iter().enumerate() {
            run(params, config(n), from, to, &mut coarse[..=ticks])?;
            let dev = fine[p][..=ticks]
                .iter()
                .zip(&coarse[..=ticks])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            worst = worst.max(dev / step * 100.0);
            if worst > TARGET_PCT {
                break;
            }
        }
        last = (n, worst);
        if worst <= TARGET_PCT {
            break;
        }
    }
    Ok(Choice {
        config: config(last.0),
        estimated_error_pct: last.1,
        goal_met: last.1 <= TARGET_PCT,
    })
}
