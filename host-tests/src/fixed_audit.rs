//! The fixed-point audit: the range every quantity on the
//! twin's tick path spans, over designs and the whole oil range.
//!
//! * [`coefficients`]: the twin's coefficients, by name, at the oil range's
//!   two ends and the validated range's (`Coefficients<f64>`, what the
//!   firmware converts to Q12.20).
//! * [`probe_design`]: the twin run through [`scenarios`] (holds at both
//!   ends of the oil range, abrupt steps across the validated range and
//!   into and out of cold and hot oil) with [`Probe`] scalars: every
//!   arithmetic operation's results recorded by its place in the source,
//!   in `f64` (what the algorithm needs) and in Q12.20 (what the shipped
//!   twin computes).
//! * [`extremes`]: from many survey designs, the few at the ends of each
//!   coefficient's range (stiffest and slowest chambers, largest and
//!   smallest couplings), so that a short run covers the survey's
//!   envelope.
//!
//! `cargo run --release -p host-tests --example fixed_ranges -- --designs 1000`
//! prints the tables of `docs/dynamics.md` ("Fixed-point ranges");
//! `cargo test -p host-tests --test fixed_point` asserts the headroom.

use crate::probe::{Probe, Ranges, Recording, merge};
use crate::survey::{chosen, designs};
use compensator::dynamics::fsi::Coefficients;
use compensator::dynamics::linear::linearise;
use compensator::dynamics::{Model, Twin, TwinConfig};
use compensator::scalar::Fixed;
use compensator::{Params, RawParams, Real};
use compensator_reference::dynamics::Profile;

/// Q12.20's largest magnitude.
pub const Q12_20_MAX: f64 = 2048.0;
/// Q12.20's resolution (one LSB).
pub const Q12_20_LSB: f64 = 1.0 / (1u64 << 20) as f64;

/// The oil range's ends for a design: `estimator.oil_min` and
/// `estimator.oil_max`, the latter lowered to the hottest whole degree the
/// oil model accepts (a thin oil leaves Walther's range, 2 cSt, below
/// 150 C: there the oil model refuses the temperature with a named error
/// and the twin never sees it).
pub fn oil_ends(raw: &RawParams) -> (f64, f64) {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let e = &raw.estimator;
    let mut hot = e.oil_max;
    while p.oil.state(hot).is_err() && hot > e.valid_max {
        hot = (hot - 1.0).ceil();
    }
    (e.oil_min, hot)
}

/// The names of [`Coefficients`]' fields, in [`coefficient_values`]' order.
pub const COEFFICIENTS: [&str; 13] = [
    "a_x",
    "1/a_x",
    "phi/a_x",
    "2 zeta",
    "xi0",
    "1/omega_a0",
    "1/omega_b0",
    "eps_a",
    "eps_b",
    "sigma",
    "u_tr",
    "q_t",
    "g_l",
];

/// The coefficients the twin's tick uses (not `omega_a0`, `omega_b0`,
/// which only the explicit schemes read), in [`COEFFICIENTS`]' order.
pub fn coefficient_values(c: &Coefficients<f64>) -> [f64; 13] {
    [
        c.a_x,
        c.inv_a_x,
        c.phi_over_a_x,
        c.two_zeta,
        c.xi0,
        c.inv_omega_a0,
        c.inv_omega_b0,
        c.eps_a,
        c.eps_b,
        c.sigma,
        c.u_tr,
        c.q_t,
        c.g_l,
    ]
}

/// The range `(min |v|, max |v|)` of each coefficient over `temps`.
pub fn coefficients(raw: &RawParams, temps: &[f64]) -> [(f64, f64); 13] {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let model = Model::new(&p).expect("a model");
    let mut out = [(f64::INFINITY, 0.0f64); 13];
    for &t in temps {
        let fluid = p.oil.state(t).expect("temperature in the oil range");
        let c: Coefficients<f64> = model.coefficients(&fluid).expect("coefficients in f64");
        for (o, v) in out.iter_mut().zip(coefficient_values(&c)) {
            o.0 = o.0.min(v.abs());
            o.1 = o.1.max(v.abs());
        }
    }
    out
}

/// The temperatures a design's coefficients are measured at: both ends of
/// the oil range and of the validated range.
pub fn temperatures(raw: &RawParams) -> [f64; 4] {
    let (cold, hot) = oil_ends(raw);
    [cold, raw.estimator.valid_min, raw.estimator.valid_max, hot]
}

/// What the twin is driven through: held at both ends of the oil range,
/// abrupt steps across the validated range both ways, from its middle
/// into cold and hot oil and back, and from one end of the oil range to
/// the other; then ramps across the validated range both ways in 0.4 s,
/// under the twin's abrupt change per tick, whose stop events in fixed
/// point leave their rests to the next substep (its longest steps, up to
/// three substeps: `dynamics::Owed`).
pub fn scenarios(raw: &RawParams) -> Vec<Profile> {
    let (cold, hot) = oil_ends(raw);
    let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
    let mid = 0.5 * (lo + hi);
    [
        (cold, cold),
        (hot, hot),
        (lo, hi),
        (hi, lo),
        (mid, cold),
        (cold, mid),
        (mid, hot),
        (hot, mid),
        (cold, hot),
        (hot, cold),
    ]
    .into_iter()
    .map(|(from, to)| Profile::Step { from, to })
    .chain([(lo, hi), (hi, lo)].map(|(from, to)| Profile::Ramp {
        from,
        to,
        rate: (hi - lo).abs() / 0.4,
    }))
    .collect()
}

/// Ranges recorded over one design's scenarios, in `f64` and in Q12.20,
/// and how far the Q12.20 twin strays from the `f64` one.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    /// `Twin<f64, Probe<f64>>`: what the algorithm needs.
    pub exact: Ranges,
    /// `Twin<f32, Probe<Fixed>>`: what the shipped twin computes.
    pub fixed: Ranges,
    /// Largest `|xi_Q12.20 - xi_f64|` over every tick (stroke).
    pub worst_xi: f64,
    /// Largest `|pi_Q12.20 - pi_f64|` over every tick (`dp`; a pressure
    /// transient at an impact shifted by a fraction of a substep counts).
    pub worst_pi: f64,
    /// Largest end-state difference of a scenario (stroke or `dp`).
    pub worst_end: f64,
    /// Scenarios in which a twin failed (refused a temperature, or a tick
    /// failed), one line each.
    pub failures: Vec<String>,
}

impl Measured {
    /// Merges another design's measurement.
    pub fn merge(&mut self, o: &Measured) {
        merge(&mut self.exact, &o.exact);
        merge(&mut self.fixed, &o.fixed);
        self.worst_xi = self.worst_xi.max(o.worst_xi);
        self.worst_pi = self.worst_pi.max(o.worst_pi);
        self.worst_end = self.worst_end.max(o.worst_end);
        self.failures.extend(o.failures.iter().cloned());
    }
}

/// The model state `(xi, w, pi_a, pi_b)` after each tick of `prof`.
fn drive<F: compensator::Float, T: Real>(
    p: &Params<F>,
    config: TwinConfig,
    prof: &Profile,
    ticks: usize,
) -> Result<Vec<[f64; 4]>, String> {
    let mut twin = Twin::<F, T>::new(p, config, F::from_f64(prof.start())).map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(ticks);
    for k in 0..ticks {
        let t = prof.temperature((k as f64 + 0.5) * config.tick);
        twin.set_temperature(F::from_f64(t))
            .map_err(|e| format!("{t} C: {e}"))?;
        twin.tick().map_err(|e| format!("tick {k}: {e:?}"))?;
        out.push(twin.raw_state().map(|v| v.to_f64()));
    }
    Ok(out)
}

/// One design through [`scenarios`], `ticks` ticks each, with `config`
/// (`None`: the configuration the chooser picks for it), recorded.
pub fn probe_design(raw: &RawParams, config: Option<TwinConfig>, ticks: usize) -> Measured {
    let mut m = Measured::default();
    let config = match config {
        Some(c) => c,
        None => match chosen(raw) {
            Ok(c) => c.config,
            Err(e) => {
                m.failures.push(format!("no configuration: {e}"));
                return m;
            }
        },
    };
    let p64 = Params::<f64>::new(raw).expect("valid parameters");
    let p32 = Params::<f32>::new(raw).expect("valid parameters");
    for prof in scenarios(raw) {
        let rec = Recording::start();
        let exact = drive::<f64, Probe<f64>>(&p64, config, &prof, ticks);
        merge(&mut m.exact, &rec.finish());
        let rec = Recording::start();
        let fixed = drive::<f32, Probe<Fixed>>(&p32, config, &prof, ticks);
        merge(&mut m.fixed, &rec.finish());
        match (exact, fixed) {
            (Ok(a), Ok(b)) => {
                for (y, z) in a.iter().zip(&b) {
                    m.worst_xi = m.worst_xi.max((y[0] - z[0]).abs());
                    m.worst_pi = m.worst_pi.max((y[2] - z[2]).abs().max((y[3] - z[3]).abs()));
                }
                if let (Some(y), Some(z)) = (a.last(), b.last()) {
                    let end = [0, 2, 3].iter().map(|&i| (y[i] - z[i]).abs()).fold(0.0, f64::max);
                    m.worst_end = m.worst_end.max(end);
                }
            }
            (a, b) => {
                for (name, r) in [("f64", a.err()), ("Q12.20", b.err())] {
                    if let Some(e) = r {
                        m.failures.push(format!("{prof:?} {name}: {e}"));
                    }
                }
            }
        }
    }
    m
}

/// The designs of a short audit: the two presets, then from `count` survey
/// designs of `seed` those at either end of each coefficient's range over
/// their oil ranges (duplicates removed).
pub fn extremes(count: usize, seed: u64) -> Vec<RawParams> {
    let root = crate::repo_root();
    let mut out: Vec<RawParams> = ["presets/paper.toml", "presets/model-example.toml"]
        .iter()
        .map(|f| compensator_cli::load(&root.join(f)).expect("preset"))
        .collect();
    let all = designs(count, seed);
    let ranges: Vec<[(f64, f64); 13]> = all.iter().map(|raw| coefficients(raw, &temperatures(raw))).collect();
    let mut picks = Vec::new();
    for (k, _) in COEFFICIENTS.iter().enumerate() {
        picks.push((0..all.len()).min_by(|&a, &b| ranges[a][k].0.total_cmp(&ranges[b][k].0)));
        picks.push((0..all.len()).max_by(|&a, &b| ranges[a][k].1.total_cmp(&ranges[b][k].1)));
    }
    // The slowest designs: velocity resolution matters most where the
    // plunger creeps (the largest slowest time constant in model units,
    // over the validated range).
    // And the most strongly damped per step: the momentum row's Newton
    // derivative grows with the hydraulic damping over a step,
    // `h phi' sigma / G` (`G` the chambers' conductance, about
    // `g_l + q_t / 2` at least).
    for key in [
        all.iter().map(slowest_time_constant).collect::<Vec<f64>>(),
        all.iter().map(damping_per_step).collect(),
    ] {
        let mut order: Vec<usize> = (0..all.len()).collect();
        order.sort_by(|&a, &b| key[b].total_cmp(&key[a]));
        picks.extend(order.into_iter().take(3).map(Some));
    }
    for i in picks.into_iter().flatten() {
        if !out.contains(&all[i]) {
            out.push(all[i]);
        }
    }
    out
}

/// The largest hydraulic damping a step of one substep per 1 ms tick
/// meets, `h phi' sigma / (g_l + q_t / 2)` over [`temperatures`].
pub fn damping_per_step(raw: &RawParams) -> f64 {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let model = Model::new(&p).expect("a model");
    let h = 1e-3 / model.scales.time;
    temperatures(raw)
        .iter()
        .filter_map(|&t| p.oil.state(t).ok())
        .filter_map(|f| model.coefficients::<f64>(&f).ok())
        .map(|c| h * c.phi_over_a_x * c.sigma / (c.g_l + 0.5 * c.q_t))
        .fold(0.0, f64::max)
}

/// The slowest time constant of a design at either end of its validated
/// range, in the model's time unit (`1 / |Re lambda|` of the dominant
/// eigenvalue; 0 where the linearisation fails).
pub fn slowest_time_constant(raw: &RawParams) -> f64 {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let unit = Model::new(&p).expect("a model").scales.time;
    [raw.estimator.valid_min, raw.estimator.valid_max]
        .iter()
        .filter_map(|&t| linearise(&p, t).ok())
        .map(|l| 1.0 / (l.dominant.re.abs() * unit))
        .fold(0.0, f64::max)
}

/// `(min |v|, max |v|)` of each coefficient over `designs` at their
/// [`temperatures`] (`oil`), or at the ends of their validated range only.
pub fn coefficient_table(designs: &[RawParams], oil: bool) -> [(f64, f64); 13] {
    let mut out = [(f64::INFINITY, 0.0f64); 13];
    for raw in designs {
        let temps = if oil {
            temperatures(raw).to_vec()
        } else {
            vec![raw.estimator.valid_min, raw.estimator.valid_max]
        };
        for (o, r) in out.iter_mut().zip(coefficients(raw, &temps)) {
            o.0 = o.0.min(r.0);
            o.1 = o.1.max(r.1);
        }
    }
    out
}
