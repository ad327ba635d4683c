//! Accuracy of the fixed-step twin against the adaptive reference solver:
//! the trajectory metric of the accuracy goals, shared by the tests and `cargo xtask
//! bench`'s accuracy table.

use compensator::dynamics::TwinConfig;
use compensator::dynamics::linear::linearise;
use compensator::{Params, RawParams};
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::{self as reference, Method, Profile};

/// A reference trajectory and what the twin is compared on.
#[derive(Clone, Debug)]
pub struct Case {
    /// Parameters.
    pub raw: RawParams,
    /// Temperature profile.
    pub profile: Profile,
    /// Ticks simulated (1 ms each).
    pub ticks: usize,
    /// Reference displacement per tick [m].
    pub x_ref: Vec<f64>,
    /// `|x_ref(end) - x_ref(0)|` [m]: the step the error is a fraction of.
    pub step: f64,
}

/// Tick of every case [s].
pub const TICK: f64 = 1e-3;

impl Case {
    /// Solves the reference (Radau5, rtol 1e-10) for `profile` over `t_end`.
    pub fn new(raw: &RawParams, profile: Profile, t_end: f64) -> Case {
        let ticks = (t_end / TICK).round() as usize;
        let tr = reference::simulate(&raw.core, profile, ticks as f64 * TICK, TICK, Method::Radau5, 1e-10)
            .unwrap_or_else(|e| panic!("reference for {profile:?}: {e}"));
        let x_ref: Vec<f64> = tr.state.iter().map(|s| s[0]).collect();
        let step = (x_ref[ticks] - x_ref[0]).abs();
        Case {
            raw: *raw,
            profile,
            ticks,
            x_ref,
            step,
        }
    }

    /// Twin trajectory with `precision` and `config`.
    pub fn twin(&self, precision: Precision, config: TwinConfig) -> Vec<f64> {
        let r = simulate(&self.raw, precision, config, &self.profile, self.ticks)
            .unwrap_or_else(|e| panic!("twin {precision:?} for {:?}: {e}", self.profile));
        r.state.iter().map(|s| s.x).collect()
    }

    /// `max |x - x_ref| / step` in percent.
    pub fn error_pct(&self, x: &[f64]) -> f64 {
        x.iter()
            .zip(&self.x_ref)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / self.step
            * 100.0
    }
}

/// Simulated time that lets a step settle: ten slow time constants at the
/// final temperature, at least 0.2 s, at most 5 s.
pub fn settle_time(raw: &RawParams, to: f64) -> f64 {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let l = linearise(&p, to).expect("linearisation");
    (10.0 / l.dominant.re.abs()).clamp(0.2, 5.0)
}

/// The paper preset's steps (30->40 ... 70->80, 80->30) and its 1 C/s ramp.
pub fn paper_cases(raw: &RawParams) -> Vec<Case> {
    let mut v: Vec<Case> = [
        (30.0, 40.0),
        (40.0, 50.0),
        (50.0, 60.0),
        (60.0, 70.0),
        (70.0, 80.0),
        (80.0, 30.0),
    ]
    .iter()
    .map(|&(from, to)| Case::new(raw, Profile::Step { from, to }, 0.5))
    .collect();
    v.push(Case::new(
        raw,
        Profile::Ramp {
            from: 30.0,
            to: 80.0,
            rate: 1.0,
        },
        50.5,
    ));
    v
}

/// A step of `raw` between two temperatures of `[30, 80]` C at least 10 C
/// apart over which the equilibrium moves by at least 5 % of the stroke
/// (a step that leaves the plunger on one stop has nothing to measure).
/// `None` when 200 draws find none.
pub fn random_step(raw: &RawParams, rng: &mut crate::random::Rng) -> Option<(f64, f64)> {
    for _ in 0..200 {
        let (a, b) = (rng.uniform(30.0, 80.0), rng.uniform(30.0, 80.0));
        let dx = (crate::reference::equilibrium(&raw.core, a).x - crate::reference::equilibrium(&raw.core, b).x).abs();
        if (a - b).abs() >= 10.0 && dx >= 0.05 * raw.core.stroke {
            return Some((a, b));
        }
    }
    None
}

/// The 50 random cases of the accuracy goals: designs from
/// [`crate::random::physical_params`] (seeded), each with a step that moves
/// the plunger by at least 5 % of the stroke. Designs that cannot (their
/// plunger stays on a stop over 30-80 C) are skipped, not counted.
pub fn random_cases(count: usize) -> Vec<Case> {
    let mut rng = crate::random::Rng::new(0x5EED);
    let mut cases = Vec::with_capacity(count);
    while cases.len() < count {
        let raw = crate::random::physical_params(&mut rng);
        if let Some((from, to)) = random_step(&raw, &mut rng) {
            cases.push(Case::new(&raw, Profile::Step { from, to }, settle_time(&raw, to)));
        }
    }
    cases
}
