//! The envelope survey: seeded random designs scattered around the two
//! presets, each driven through abrupt steps over the whole envelope
//! (heating, cooling onto the closed stop, onto the open stop, partial
//! steps across the validated range, cold oil down to the oil range's
//! bottom and back), checked against the independent closed form
//! ([`crate::reference`]) and the adaptive reference solver.
//!
//! `cargo test -p host-tests --test survey` runs it on 200 designs;
//! `cargo run --release -p host-tests --example survey -- --designs 10000`
//! is the long run (`docs/dynamics.md` has its figures).

use crate::random::{Rng, walther_through};
use compensator::dynamics::TwinConfig;
use compensator::dynamics::config::{Choice, choose};
use compensator::dynamics::linear::linearise;
use compensator::params::RawCore;
use compensator::{Params, RawParams};
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::{self as reference, Method, Profile};
use rayon::prelude::*;

/// Spread of every scattered value: up to this many decades either way.
pub const DECADES: f64 = 0.3;

/// Kinematic viscosity [cSt] of a Walther oil at `t` [C].
pub fn viscosity_cst(a: f64, b: f64, t: f64) -> f64 {
    10f64.powf(10f64.powf(a - b * (t + 273.15).log10())) - 0.7
}

/// `base` with every value multiplied by `10^U(-DECADES, DECADES)`, then
/// made physically consistent:
/// * the oil is scattered through its viscosities at 40 and 100 C (not its
///   Walther constants, whose scatter would make no oil), keeping
///   `nu40 / nu100` between 2 and 12 (viscosity indices of mineral oils)
///   and `nu100 >= 1.5 cSt`;
/// * density within 750-1000 kg/m^3, bulk modulus within 0.5-3 GPa,
///   discharge coefficients within 0.5-0.9 (what oils and sharp edges give);
/// * preload at most 90 % of the stroke; each chamber at least 1.2 times
///   the swept volume (it must hold the plunger's stroke);
/// * the outlet pressure scattered only if the preset's is not zero.
///
/// Every returned set passes the parameter file's validation.
pub fn scattered(base: &RawCore, rng: &mut Rng) -> RawCore {
    let mut f = |v: f64| v * 10f64.powf(rng.uniform(-DECADES, DECADES));
    let (nu40, nu100) = (
        viscosity_cst(base.walther_a, base.walther_b, 40.0),
        viscosity_cst(base.walther_a, base.walther_b, 100.0),
    );
    let (mut n40, mut n100);
    loop {
        (n40, n100) = (f(nu40), f(nu100));
        if n100 >= 1.5 && (2.0..=12.0).contains(&(n40 / n100)) {
            break;
        }
    }
    let (walther_a, walther_b) = walther_through(n40, n100);
    let mut c = RawCore {
        walther_a,
        walther_b,
        density_15: f(base.density_15).clamp(750.0, 1000.0),
        expansion: f(base.expansion),
        bulk_modulus: f(base.bulk_modulus).clamp(0.5e9, 3.0e9),
        laminar_diameter: f(base.laminar_diameter),
        laminar_length: f(base.laminar_length),
        turbulent_diameter: f(base.turbulent_diameter),
        turbulent_discharge: f(base.turbulent_discharge).clamp(0.5, 0.9),
        plunger_diameter: f(base.plunger_diameter),
        mass: f(base.mass),
        damping: f(base.damping),
        spring_rate: f(base.spring_rate),
        preload: f(base.preload),
        stroke: f(base.stroke),
        slot_diameter: f(base.slot_diameter),
        slot_discharge: f(base.slot_discharge).clamp(0.5, 0.9),
        volume_a: f(base.volume_a),
        volume_b: f(base.volume_b),
        pressure_drop: f(base.pressure_drop),
        outlet_pressure: if base.outlet_pressure > 0.0 {
            f(base.outlet_pressure)
        } else {
            0.0
        },
    };
    c.preload = c.preload.min(0.9 * c.stroke);
    let swept = std::f64::consts::FRAC_PI_4 * c.plunger_diameter * c.plunger_diameter * c.stroke;
    c.volume_a = c.volume_a.max(1.2 * swept);
    c.volume_b = c.volume_b.max(1.2 * swept);
    c.validate().expect("scattered sets are valid");
    c
}

/// `count` designs, alternately around `presets/paper.toml` and
/// `presets/model-example.toml`, from `seed`. A design whose oil leaves
/// Walther's range above the preset's coldest oil temperature gets that
/// range's bottom (to the next whole degree) as `estimator.oil_min`: the
/// oil range of a device file is where its oil model holds.
pub fn designs(count: usize, seed: u64) -> Vec<RawParams> {
    let root = crate::repo_root();
    let presets = [
        compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset"),
        compensator_cli::load(&root.join("presets/model-example.toml")).expect("example preset"),
    ];
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|i| {
            let base = &presets[i % 2];
            let mut raw = RawParams {
                core: scattered(&base.core, &mut rng),
                machine: None,
                estimator: base.estimator,
                probe: base.probe,
                monitor: compensator::params::RawMonitor::NONE,
                tolerances: compensator::params::RawTolerances::NONE,
            };
            let p = Params::<f64>::new(&raw).expect("scattered sets are valid");
            while p.oil.state(raw.estimator.oil_min).is_err() && raw.estimator.oil_min < raw.estimator.valid_min {
                raw.estimator.oil_min = raw.estimator.oil_min.floor() + 1.0;
            }
            raw
        })
        .collect()
}

/// What a step exercises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Bottom to top of the validated range.
    Heating,
    /// Top to bottom of the validated range (onto the closed stop where the
    /// design's window closes in range).
    Cooling,
    /// Between two random temperatures of the validated range.
    Partial,
    /// From the validated range to the oil range's bottom (cold oil, the
    /// window shut).
    ColdOil,
    /// From the oil range's bottom back into the validated range.
    Rewarm,
}

/// A step of one design.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    /// What it exercises.
    pub kind: Kind,
    /// Temperatures [C].
    pub from: f64,
    /// Final temperature [C].
    pub to: f64,
}

/// The steps every design goes through.
pub fn steps(raw: &RawParams, rng: &mut Rng) -> Vec<Step> {
    let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
    let cold = raw.estimator.oil_min;
    let mid = rng.uniform(lo, hi);
    let mut v = vec![
        Step {
            kind: Kind::Heating,
            from: lo,
            to: hi,
        },
        Step {
            kind: Kind::Cooling,
            from: hi,
            to: lo,
        },
    ];
    for _ in 0..2 {
        v.push(Step {
            kind: Kind::Partial,
            from: rng.uniform(lo, hi),
            to: rng.uniform(lo, hi),
        });
    }
    v.push(Step {
        kind: Kind::ColdOil,
        from: mid,
        to: cold,
    });
    v.push(Step {
        kind: Kind::Rewarm,
        from: cold,
        to: mid,
    });
    v
}

/// Simulated time that lets a step settle: ten slow time constants of the
/// linearisation at both ends, at least 0.2 s, at most 5 s.
pub fn settle_time(raw: &RawParams, step: &Step) -> f64 {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let mut t: f64 = 0.2;
    for temp in [step.from, step.to] {
        if let Ok(l) = linearise(&p, temp) {
            t = t.max(10.0 / l.dominant.re.abs());
        }
    }
    t.min(5.0)
}

/// One step's outcome for one precision.
#[derive(Clone, Copy, Debug)]
pub struct Outcome {
    /// End state minus the closed-form equilibrium: `|x|` / stroke.
    pub x_end: f64,
    /// `max(|p_a|, |p_b|)` / `dp`.
    pub p_end: f64,
    /// `max |x - x_ref|` in percent of the reference's step, when the
    /// reference moves by at least 1 % of the stroke (else `None`).
    pub trajectory_pct: Option<f64>,
}

/// A step solved by the reference, ready to compare twins against.
#[derive(Clone, Debug)]
pub struct Solved {
    /// The design.
    pub raw: RawParams,
    /// The step.
    pub step: Step,
    /// Ticks of 1 ms.
    pub ticks: usize,
    /// Reference displacement per tick [m].
    pub x_ref: Vec<f64>,
}

/// Longest simulated step [s].
pub const MAX_SETTLE: f64 = 20.0;

/// Tick of the survey [s] (the firmware's default).
pub const TICK: f64 = 1e-3;

impl Solved {
    /// Solves the reference (Radau5, rtol 1e-10) for `step`, long enough
    /// for the reference to settle on the closed form (within 1e-5 of the
    /// stroke and 1e-4 of `dp`): [`settle_time`] first, doubled up to
    /// [`MAX_SETTLE`]. A reference that has not settled by then is an error.
    pub fn new(raw: &RawParams, step: Step) -> Result<Solved, String> {
        let prof = Profile::Step {
            from: step.from,
            to: step.to,
        };
        let eq = crate::reference::equilibrium(&raw.core, step.to);
        let mut time = settle_time(raw, &step);
        loop {
            let ticks = (time / TICK).round() as usize;
            let tr = reference::simulate(&raw.core, prof, ticks as f64 * TICK, TICK, Method::Radau5, 1e-10)?;
            let end = tr.state[ticks];
            let settled = (end[0] - eq.x).abs() <= 1e-5 * raw.core.stroke
                && (end[2] - eq.p_a).abs().max((end[3] - eq.p_b).abs()) <= 1e-4 * raw.core.pressure_drop;
            if settled {
                return Ok(Solved {
                    raw: *raw,
                    step,
                    ticks,
                    x_ref: tr.state.iter().map(|s| s[0]).collect(),
                });
            }
            if time >= MAX_SETTLE {
                return Err(format!("the reference has not settled after {time} s"));
            }
            time = (2.0 * time).min(MAX_SETTLE);
        }
    }

    /// The twin in `precision` with `config`, against the closed form at
    /// the end and the reference along the way.
    pub fn outcome(&self, precision: Precision, config: TwinConfig) -> Result<Outcome, String> {
        let prof = Profile::Step {
            from: self.step.from,
            to: self.step.to,
        };
        let r = simulate(&self.raw, precision, config, &prof, self.ticks).map_err(|e| e.to_string())?;
        let end = r.state[self.ticks];
        let eq = crate::reference::equilibrium(&self.raw.core, self.step.to);
        let core = &self.raw.core;
        let x_end = (end.x - eq.x).abs() / core.stroke;
        let p_end = (end.p_a - eq.p_a).abs().max((end.p_b - eq.p_b).abs()) / core.pressure_drop;
        let moved = (self.x_ref[self.ticks] - self.x_ref[0]).abs();
        let trajectory_pct = (moved >= 0.01 * core.stroke).then(|| {
            r.state
                .iter()
                .zip(&self.x_ref)
                .map(|(s, x)| (s.x - x).abs())
                .fold(0.0, f64::max)
                / moved
                * 100.0
        });
        Ok(Outcome {
            x_end,
            p_end,
            trajectory_pct,
        })
    }
}

/// The precisions the survey checks, with their trajectory goals (max
/// `|x - x_ref|` in % of the step).
pub const PRECISIONS: [(Precision, &str, f64); 3] = [
    (Precision::F64, "f64", 0.1),
    (Precision::F32, "f32", 0.5),
    (Precision::Fixed, "Q12.20", 1.0),
];

/// End state within this fraction of the stroke and of `dp` of the closed form.
pub const END_TOLERANCE: f64 = 1e-3;

/// Figures of one precision over a survey.
#[derive(Clone, Copy, Debug, Default)]
pub struct Figures {
    /// Steps simulated.
    pub steps: usize,
    /// Largest end-state deviation (stroke or `dp` fraction).
    pub worst_end: f64,
    /// Steps whose end state is off by more than [`END_TOLERANCE`].
    pub end_failures: usize,
    /// Steps whose trajectory is measured (the plunger moves by 1 % of the stroke or more).
    pub trajectories: usize,
    /// Largest trajectory error [% of the step].
    pub worst_trajectory: f64,
    /// Trajectories beyond the precision's goal.
    pub trajectory_failures: usize,
    /// Steps from or into cold oil (outside the validated range, where the
    /// goal is the end state): trajectories measured, and the largest error
    /// [% of the step].
    pub cold_trajectories: usize,
    /// Largest trajectory error of a cold step [% of the step].
    pub worst_cold_trajectory: f64,
}

/// What a survey found.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Designs surveyed.
    pub designs: usize,
    /// How many designs got each substep count: `(substeps, designs)`.
    pub substeps: Vec<(u8, usize)>,
    /// Designs whose chooser estimate stayed above its target.
    pub chooser_misses: usize,
    /// Per precision, in [`PRECISIONS`]' order.
    pub figures: [Figures; 3],
    /// Every failure, one line each (design index, step, precision, what).
    pub failures: Vec<String>,
}

impl Report {
    fn merge(&mut self, other: Report) {
        self.designs += other.designs;
        for (n, c) in other.substeps {
            match self.substeps.iter_mut().find(|(m, _)| *m == n) {
                Some((_, d)) => *d += c,
                None => self.substeps.push((n, c)),
            }
        }
        self.substeps.sort();
        self.chooser_misses += other.chooser_misses;
        for (a, b) in self.figures.iter_mut().zip(other.figures) {
            a.steps += b.steps;
            a.worst_end = a.worst_end.max(b.worst_end);
            a.end_failures += b.end_failures;
            a.trajectories += b.trajectories;
            a.worst_trajectory = a.worst_trajectory.max(b.worst_trajectory);
            a.trajectory_failures += b.trajectory_failures;
            a.cold_trajectories += b.cold_trajectories;
            a.worst_cold_trajectory = a.worst_cold_trajectory.max(b.worst_cold_trajectory);
        }
        self.failures.extend(other.failures);
    }

    /// A markdown table of the figures.
    pub fn table(&self) -> String {
        let mut s = String::from(
            "| precision | steps | worst end state (stroke, dp) | end > 1e-3 | trajectories in range | worst | beyond goal (goal) | cold trajectories | worst cold |\n\
             | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
        );
        for ((_, name, goal), f) in PRECISIONS.iter().zip(&self.figures) {
            s += &format!(
                "| {name} | {} | {:.1e} | {} | {} | {:.3} % | {} ({goal} %) | {} | {:.3} % |\n",
                f.steps,
                f.worst_end,
                f.end_failures,
                f.trajectories,
                f.worst_trajectory,
                f.trajectory_failures,
                f.cold_trajectories,
                f.worst_cold_trajectory
            );
        }
        s
    }
}

/// The configuration [`choose`] picks for `raw` at the survey's tick.
pub fn chosen(raw: &RawParams) -> Result<Choice, String> {
    let p = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let e = &raw.estimator;
    choose(&p, TICK, (e.valid_min, e.valid_max)).map_err(|e| e.to_string())
}

/// One design through its steps in every precision, with the chosen configuration.
pub fn survey_design(index: usize, raw: &RawParams, seed: u64) -> Report {
    let mut r = Report {
        designs: 1,
        ..Report::default()
    };
    let choice = match chosen(raw) {
        Ok(c) => c,
        Err(e) => {
            r.failures.push(format!("design {index}: no configuration: {e}"));
            return r;
        }
    };
    r.substeps.push((choice.config.substeps, 1));
    r.chooser_misses += usize::from(!choice.goal_met);
    let mut rng = Rng::new(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    for step in steps(raw, &mut rng) {
        let solved = match Solved::new(raw, step) {
            Ok(s) => s,
            Err(e) => {
                r.failures.push(format!("design {index} {step:?}: reference: {e}"));
                continue;
            }
        };
        for ((precision, name, goal), f) in PRECISIONS.iter().zip(r.figures.iter_mut()) {
            f.steps += 1;
            match solved.outcome(*precision, choice.config) {
                Err(e) => {
                    f.end_failures += 1;
                    r.failures.push(format!("design {index} {step:?} {name}: {e}"));
                }
                Ok(o) => {
                    let end = o.x_end.max(o.p_end);
                    f.worst_end = f.worst_end.max(end);
                    if end > END_TOLERANCE {
                        f.end_failures += 1;
                        r.failures.push(format!(
                            "design {index} {step:?} {name}: end state off by {:.2e} of the stroke, {:.2e} of dp",
                            o.x_end, o.p_end
                        ));
                    }
                    let cold = matches!(step.kind, Kind::ColdOil | Kind::Rewarm);
                    if let (Some(t), true) = (o.trajectory_pct, cold) {
                        f.cold_trajectories += 1;
                        f.worst_cold_trajectory = f.worst_cold_trajectory.max(t);
                    } else if let Some(t) = o.trajectory_pct {
                        f.trajectories += 1;
                        f.worst_trajectory = f.worst_trajectory.max(t);
                        if t > *goal {
                            f.trajectory_failures += 1;
                            r.failures.push(format!(
                                "design {index} {step:?} {name}: trajectory off by {t:.3} % of the step with {} substeps (goal {goal} %)",
                                choice.config.substeps
                            ));
                        }
                    }
                }
            }
        }
    }
    r
}

/// `count` designs from `seed` (see [`designs`]), surveyed on all cores
/// (rayon; `RAYON_NUM_THREADS=N` limits them).
pub fn survey(count: usize, seed: u64) -> Report {
    let all = designs(count, seed);
    let mut report = all
        .par_iter()
        .enumerate()
        .map(|(i, raw)| survey_design(i, raw, seed))
        .reduce(Report::default, |mut a, b| {
            a.merge(b);
            a
        });
    report.failures.sort();
    report
}
