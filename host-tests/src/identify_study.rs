//! The identification campaign's designs, records and scoring
//! (`examples/identify_campaign.rs`), shared with the test that runs a
//! bounded slice of it (`tests/identify_campaign.rs`).
//!
//! A design is a random physical compensator ([`physical_params`]) whose
//! plunger mass and viscous friction are chosen for a damping ratio:
//! underdamped (0.15-0.35, as the plungers of small valves with light
//! hydraulic damping) or overdamped (1.5-4). Its record is a 45 -> 55 C
//! step of the independent reference solver (Radau5, rtol 1e-10), the
//! displacement alone with seeded Gaussian noise of 0.3 % of the step,
//! sampled 40 times per period (underdamped) or 300 times over the record
//! (overdamped), long enough for the response to settle. The engineer's
//! base file is the truth with the mass, the friction and the bulk modulus
//! wrong: the mass and the friction by a factor up to 2 either way, the
//! bulk modulus up to 1.5. `compensator identify` is run on it with its
//! default fit (mass, damping, bulk modulus) through the library
//! ([`compensator_cli::identify::identify_params`], what the command runs).

use crate::random::{Rng, physical_params};
use compensator::Params;
use compensator::dynamics::linear::linearise;
use compensator::params::RawParams;
use compensator_cli::identify::{self, Transient};
use compensator_reference::dynamics::{Method, Mode, Profile, simulate};

/// The step of every record [C].
pub const STEP: (f64, f64) = (45.0, 55.0);

/// Displacement noise, as a fraction of the step's travel.
pub const NOISE_OF_STEP: f64 = 3e-3;

/// Kinds of design.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Dominant damping ratio 0.15-0.35: an overshoot and a few periods of
    /// ringing.
    Underdamped,
    /// Dominant damping ratio 1.5-4 (real eigenvalues): a creep.
    Overdamped,
}

/// A design of the campaign and how its record is taken.
#[derive(Clone, Debug)]
pub struct Design {
    /// The device.
    pub truth: RawParams,
    /// Its class.
    pub class: Class,
    /// The plunger's damping ratio at the step's final temperature,
    /// hydraulic and viscous (the core's linearisation,
    /// `plunger_damping_ratio`).
    pub zeta: f64,
    /// Sample interval of the record [s].
    pub dt: f64,
    /// Length of the record [s].
    pub t_end: f64,
    /// Displacement noise [m] (standard deviation).
    pub sigma_x: f64,
}

/// Design `index` of class `class` for campaign `seed` (rejecting draws
/// that do not fit the class: a plunger against a stop, a mass outside
/// 0.5 g..1 kg, a damping ratio outside the class's band). The same
/// arguments give the same design on every machine.
pub fn design(class: Class, seed: u64, index: u64) -> Design {
    let mut rng = Rng::new(
        seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03)
            ^ if class == Class::Overdamped { 0xA5A5 } else { 0 },
    );
    loop {
        if let Some(d) = try_design(class, &mut rng) {
            return d;
        }
    }
}

fn try_design(class: Class, rng: &mut Rng) -> Option<Design> {
    let (from, to) = STEP;
    let mut raw = physical_params(rng);
    let (zeta_target, share) = match class {
        Class::Underdamped => (rng.uniform(0.15, 0.35), rng.uniform(0.1, 0.5)),
        Class::Overdamped => (rng.uniform(1.5, 4.0), rng.uniform(0.1, 0.5)),
    };
    // The hydraulic damping ratio at the mass m, zeta_h(m), scales as
    // 1 / sqrt(m); the friction is `share` of the total damping; the mass
    // is iterated until the plunger's total damping ratio is the target.
    raw.core.mass = 0.01;
    let c = raw.core.spring_rate;
    for _ in 0..6 {
        raw.core.damping = 0.0;
        let p = Params::<f64>::new(&raw).ok()?;
        let zeta_h = linearise(&p, to).ok()?.plunger_damping_ratio;
        if !(zeta_h > 0.0) {
            return None;
        }
        let total = zeta_h / (1.0 - share);
        raw.core.mass *= (total / zeta_target).powi(2);
        if !(5e-4..=1.0).contains(&raw.core.mass) {
            return None;
        }
    }
    raw.core.damping = 0.0;
    let zeta_h = linearise(&Params::<f64>::new(&raw).ok()?, to)
        .ok()?
        .plunger_damping_ratio;
    raw.core.damping = 2.0 * (c * raw.core.mass).sqrt() * zeta_h * share / (1.0 - share);
    raw.validate().ok()?;
    let p = Params::<f64>::new(&raw).ok()?;
    let lin = linearise(&p, to).ok()?;
    if lin.on_stop || linearise(&p, from).ok()?.on_stop {
        return None;
    }
    let dom = lin.dominant;
    let zeta = lin.plunger_damping_ratio;
    let (dt, t_end) = match class {
        Class::Underdamped => {
            if !(dom.im.abs() > 0.0 && (0.1..=0.45).contains(&lin.damping_ratio[0])) {
                return None;
            }
            let period = 2.0 * std::f64::consts::PI / dom.im.abs();
            (period / 40.0, 8.0 / -dom.re)
        }
        Class::Overdamped => {
            if !(dom.im == 0.0 && lin.plunger_damping_ratio >= 1.2) {
                return None;
            }
            let t_end = 8.0 / -dom.re;
            (t_end / 300.0, t_end)
        }
    };
    let x = |t: f64| compensator_reference::statics::equilibrium(&raw.core, t).x;
    let travel = (x(to) - x(from)).abs();
    // Off the stops by a margin, with the overshoot (an underdamped one
    // overshoots by at most the step).
    let margin = 0.02 * raw.core.stroke + if class == Class::Underdamped { travel } else { 0.0 };
    for t in [from, to] {
        if !(x(t) > margin && x(t) < raw.core.stroke - margin) {
            return None;
        }
    }
    if !(travel > 1e-3 * raw.core.stroke) {
        return None;
    }
    Some(Design {
        truth: raw,
        class,
        zeta,
        dt,
        t_end,
        sigma_x: NOISE_OF_STEP * travel,
    })
}

/// SplitMix64-based standard normal deviate (Box-Muller).
fn normal(rng: &mut Rng) -> f64 {
    let u1 = rng.unit().max(1e-300);
    let u2 = rng.unit();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// The record of `d`: the reference solver's step sampled every `d.dt`,
/// the displacement with noise from `noise_seed`. `None` when the
/// reference solver fails or the plunger touches a stop.
pub fn record(d: &Design, noise_seed: u64) -> Option<Transient> {
    let (from, to) = STEP;
    let tr = simulate(
        &d.truth.core,
        Profile::Step { from, to },
        d.t_end,
        d.dt,
        Method::Radau5,
        1e-10,
    )
    .ok()?;
    if tr.events.iter().any(|(_, m)| *m != Mode::Free) {
        return None;
    }
    let mut rng = Rng::new(noise_seed);
    Some(Transient {
        t_c: (0..tr.time.len()).map(|k| if k == 0 { from } else { to }).collect(),
        x_m: tr.state.iter().map(|s| s[0] + d.sigma_x * normal(&mut rng)).collect(),
        time_s: tr.time,
        p_pa: None,
    })
}

/// The engineer's base file for `d`: the truth with the mass and the
/// friction scaled by 2^u and the bulk modulus by 1.5^u (u uniform in
/// [-1, 1], drawn from `seed`).
pub fn base(d: &Design, seed: u64) -> RawParams {
    let mut rng = Rng::new(seed);
    let mut b = d.truth;
    b.core.mass *= 2f64.powf(rng.uniform(-1.0, 1.0));
    b.core.damping *= 2f64.powf(rng.uniform(-1.0, 1.0));
    b.core.bulk_modulus *= 1.5f64.powf(rng.uniform(-1.0, 1.0));
    b
}

/// One parameter's outcome against the truth.
#[derive(Clone, Debug, PartialEq)]
pub struct Scored {
    /// Its path.
    pub path: &'static str,
    /// The true value.
    pub truth: f64,
    /// Estimate, standard error and 95 % interval, when identified.
    pub estimate: Option<identify::Estimate>,
    /// Why not, when not.
    pub reason: String,
}

impl Scored {
    /// Relative error of the estimate.
    pub fn rel_error(&self) -> Option<f64> {
        self.estimate.map(|e| (e.value - self.truth).abs() / self.truth.abs())
    }
    /// The reported standard error says the estimate is within `tol`
    /// (relative): its 95 % interval lies within `+-tol` of the value.
    pub fn claims_within(&self, tol: f64) -> bool {
        self.estimate
            .is_some_and(|e| e.ci95.0 >= e.value * (1.0 - tol) && e.ci95.1 <= e.value * (1.0 + tol))
    }
    /// The 95 % interval holds the truth.
    pub fn covered(&self) -> Option<bool> {
        self.estimate.map(|e| (e.ci95.0..=e.ci95.1).contains(&self.truth))
    }
}

/// One design's identification.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Design index.
    pub index: u64,
    /// Its class.
    pub class: Class,
    /// Dominant damping ratio.
    pub zeta: f64,
    /// `Err`: the command failed (its message).
    pub result: Result<Vec<Scored>, String>,
    /// Residual RMS over the noise, when it ran.
    pub rms_over_noise: f64,
}

impl Outcome {
    /// The scored parameter `path`, when the command ran.
    pub fn get(&self, path: &str) -> Option<&Scored> {
        self.result.as_ref().ok()?.iter().find(|s| s.path == path)
    }
}

/// Design `index` of `class` in campaign `seed` with its record and base
/// file (`None` when the reference solver cannot record it).
pub fn case(class: Class, seed: u64, index: u64) -> Option<(Design, Transient, RawParams)> {
    let d = design(class, seed, index);
    let data = record(&d, seed ^ (index << 20) ^ 0x5EED)?;
    let b = base(&d, seed ^ (index << 20) ^ 0xBA5E);
    Some((d, data, b))
}

/// Runs design `index` of `class` in campaign `seed`: its record, its base
/// file, the default fit. `None` when the reference solver cannot make the
/// record (the design is then skipped by the campaign, and counted).
pub fn run(class: Class, seed: u64, index: u64) -> Option<Outcome> {
    let (d, data, b) = case(class, seed, index)?;
    let result = identify::identify_params(&b, &data, &identify::DEFAULT_FIT);
    let truth = |path: &str| match path {
        "plunger.mass" => d.truth.core.mass,
        "plunger.damping" => d.truth.core.damping,
        "fluid.bulk_modulus" => d.truth.core.bulk_modulus,
        "chambers.volume_a" => d.truth.core.volume_a,
        _ => d.truth.core.volume_b,
    };
    let rms_over_noise = result.as_ref().map_or(f64::NAN, |id| id.rms_x / d.sigma_x);
    Some(Outcome {
        index,
        class,
        zeta: d.zeta,
        rms_over_noise,
        result: result.map_err(|e| e.to_string()).map(|id| {
            id.results
                .iter()
                .map(|r| Scored {
                    path: r.path,
                    truth: truth(r.path),
                    estimate: r.estimate,
                    reason: r.reason.clone(),
                })
                .collect()
        }),
    })
}

/// Totals over a campaign's outcomes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Designs run (records made).
    pub designs: usize,
    /// Of which the command failed.
    pub failed: usize,
    /// Designs whose damping came out identified and within 5 %.
    pub damping_within_5: usize,
    /// Estimates (mass and damping) whose interval lies within +-5 %.
    pub claimed_5: usize,
    /// Of those, within 5 % of the truth.
    pub claimed_5_held: usize,
    /// Identified parameters (all three) with an interval.
    pub intervals: usize,
    /// Of those, holding the truth.
    pub covered: usize,
    /// Per parameter of the default fit: (identified, interval holding the
    /// truth).
    pub by_parameter: [(usize, usize); 3],
}

impl Summary {
    /// The totals of `outcomes`.
    pub fn of(outcomes: &[Outcome]) -> Summary {
        let mut s = Summary {
            designs: outcomes.len(),
            ..Summary::default()
        };
        for o in outcomes {
            let Ok(scored) = &o.result else {
                s.failed += 1;
                continue;
            };
            if o.get("plunger.damping")
                .and_then(Scored::rel_error)
                .is_some_and(|e| e <= 0.05)
            {
                s.damping_within_5 += 1;
            }
            for p in scored {
                if p.path != "fluid.bulk_modulus" && p.claims_within(0.05) {
                    s.claimed_5 += 1;
                    if p.rel_error().is_some_and(|e| e <= 0.05) {
                        s.claimed_5_held += 1;
                    }
                }
                if let Some(c) = p.covered() {
                    s.intervals += 1;
                    s.covered += usize::from(c);
                    if let Some(k) = identify::DEFAULT_FIT.iter().position(|q| *q == p.path) {
                        s.by_parameter[k].0 += 1;
                        s.by_parameter[k].1 += usize::from(c);
                    }
                }
            }
        }
        s
    }
}
