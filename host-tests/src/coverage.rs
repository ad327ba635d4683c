//! Is the uncertainty honest? Devices and probes drawn from the declared
//! uncertainties, each simulated by the independent reference, each
//! estimated by the `f32` estimator built for the nominal device: how often
//! does the band of +-1.96 standard deviations hold the truth?
//!
//! One sample: a nominal design (its `[tolerances]`, its `[probe]`), a
//! device drawn from the tolerances (Gaussian, correlated as declared: GUM
//! Supplement 1's choice for a quantity known by its estimate and standard
//! uncertainty, 6.4.7), a probe whose error is `u (a + b |t|)` with `u`
//! uniform in [-1, 1] (inside its class limits, the distribution the
//! estimator assumes), a temperature uniform over the validated range. The
//! truth is the reference's equilibrium of the drawn device at that
//! temperature (`compensator-reference`: bisection, no code shared with the
//! model). The estimate: the estimator of the nominal design, held at the
//! temperature for [`HOLD_TIME_CONSTANTS`] probe time constants, reading it
//! through the probe's error, its noise and the MAX31865's quantization.
//!
//! A band that touches an end stop is one-sided (`compensator::
//! uncertainty`'s module docs): its samples are counted apart.

use crate::random::Rng;
use crate::reference;
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::{CORE_FIELDS, RawParams, RawTolerances};
use compensator::sensor::max31865::{Settings, code_of};

/// How long each sample holds its temperature before it is read, in probe
/// time constants (`probe.time_constant + probe.well_time_constant`), and
/// at least until the observer's gains are at the end of their schedule
/// from the fast mode to the hold mode (`ObserverDesign::schedule_time`:
/// 42 s for the default 8 s probe, within the 48 s).
pub const HOLD_TIME_CONSTANTS: f64 = 6.0;

/// The reported quantities checked, in [`Uncertainty`](compensator::uncertainty::Uncertainty) order.
pub const OUTPUTS: [&str; 5] = ["t_oil", "x", "p_a", "p_b", "q_total"];

/// A design office's tolerances for `raw`, as standard uncertainties of a
/// uniform distribution within the limits (`T / sqrt(3)`): +-10 um on the
/// throttles' and the window's diameters, +-5 um on the plunger's, +-0.1 mm
/// on the capillary's length, +-0.02 on the discharge coefficients, +-5 %
/// on the spring rate, +-10 um on the preload and the stroke, +-1 % on the
/// density, and the ISO VG grade's +-10 % of the viscosity at 40 C as
/// Walther's `a` (`docs/parameters.md`). Each at most a third of its value.
pub fn drawing_tolerances(raw: &RawParams) -> RawTolerances {
    let c = &raw.core;
    let uniform = |half_width: f64| half_width / 3f64.sqrt();
    let nu40 = crate::survey::viscosity_cst(c.walther_a, c.walther_b, 40.0);
    let w = (nu40 + 0.7).log10();
    let u_a = uniform(0.1 * nu40) / ((nu40 + 0.7) * std::f64::consts::LN_10.powi(2) * w);
    let mut tol = RawTolerances::NONE;
    let mut set = |path: &str, sigma: f64| {
        let value = c
            .named()
            .into_array()
            .iter()
            .find(|n| n.path == path)
            .map_or(0.0, |n| n.value);
        if let Some(s) = tol.get_mut(path) {
            *s = sigma.min(value.abs() / 3.0);
        }
    };
    set("fluid.walther_a", u_a);
    set("fluid.density_15", uniform(0.01 * c.density_15));
    set("laminar_throttle.diameter", uniform(10e-6));
    set("laminar_throttle.length", uniform(0.1e-3));
    set("turbulent_throttle.diameter", uniform(10e-6));
    set("turbulent_throttle.discharge_coefficient", uniform(0.02));
    set("plunger.diameter", uniform(5e-6));
    set("plunger.spring_rate", uniform(0.05 * c.spring_rate));
    set("plunger.preload", uniform(10e-6));
    set("plunger.stroke", uniform(10e-6));
    set("slot.diameter", uniform(10e-6));
    set("slot.discharge_coefficient", uniform(0.02));
    tol
}

/// A device drawn from `nominal`'s tolerances: each uncertain field
/// Gaussian around its value with its standard uncertainty, correlated as
/// declared (through the Cholesky factor of the correlation matrix); drawn
/// again (at most 100 times) while the device is one the parameter file
/// refuses.
pub fn draw(nominal: &RawParams, rng: &mut Rng) -> Option<RawParams> {
    let tol = &nominal.tolerances;
    let fields: Vec<(&'static str, f64)> = CORE_FIELDS
        .iter()
        .zip(tol.core.into_array())
        .chain(compensator::params::MACHINE_FIELDS.iter().zip(tol.machine.into_array()))
        .filter(|(_, s)| *s > 0.0)
        .map(|(f, s)| (f.path, s))
        .collect();
    let n = fields.len();
    // Cholesky of the correlation matrix.
    let mut l = vec![0.0f64; n * n];
    for j in 0..n {
        let d = 1.0 - (0..j).map(|k| l[j * n + k] * l[j * n + k]).sum::<f64>();
        let d = d.max(0.0).sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let r = tol.correlation(fields[i].0, fields[j].0);
            let s = r - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            l[i * n + j] = if d > 1e-12 { s / d } else { 0.0 };
        }
    }
    for _ in 0..100 {
        let z: Vec<f64> = (0..n).map(|_| normal(rng)).collect();
        let mut raw = *nominal;
        for (i, (path, sigma)) in fields.iter().enumerate() {
            let e: f64 = (0..=i).map(|k| l[i * n + k] * z[k]).sum();
            let shift = |v: f64| v + sigma * e;
            raw.core = raw.core.map(|f| if f.path == *path { shift(f.value) } else { f.value });
            if let Some(m) = &mut raw.machine {
                *m = m.map(|f| if f.path == *path { shift(f.value) } else { f.value });
            }
        }
        raw.tolerances = RawTolerances::NONE;
        if raw.validate().is_ok() {
            return Some(raw);
        }
    }
    None
}

/// A standard normal deviate (Box-Muller).
pub fn normal(rng: &mut Rng) -> f64 {
    let u = rng.unit().max(1e-300);
    let v = rng.unit();
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// One estimate against its truth.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Index of the nominal design.
    pub design: usize,
    /// The oil temperature [C].
    pub t: f64,
    /// Estimate minus truth, per [`OUTPUTS`].
    pub error: [f64; 5],
    /// The reported standard deviation, per [`OUTPUTS`].
    pub sd: [f64; 5],
    /// The displacement's band +-1.96 sd reaches an end stop (then the
    /// displacement's and the total flow's bands are one-sided).
    pub at_stop: bool,
}

impl Sample {
    /// Whether the band +-1.96 sd of output `o` holds the truth.
    pub fn covered(&self, o: usize) -> bool {
        self.error[o].abs() <= 1.96 * self.sd[o]
    }
}

/// The estimate of `nominal`'s estimator (`config`) held at `t` [C], read
/// through a probe whose error at `t` is `offset` [C] with the file's
/// noise, quantised by the MAX31865; after [`HOLD_TIME_CONSTANTS`] probe
/// time constants, and no sooner than the end of the observer's schedule.
pub fn estimate_at(
    p32: &Params<f32>,
    config: EstimatorConfig,
    nominal: &RawParams,
    t: f64,
    offset: f64,
    rng: &mut Rng,
) -> Result<compensator::estimator::StateEstimate, String> {
    let settings = Settings::from_params(&nominal.estimator);
    let read = |rng: &mut Rng| {
        let probe = t + offset + nominal.probe.noise * normal(rng);
        let r = settings.cvd.resistance(settings.r0, probe as f32);
        let code = code_of(&settings, r);
        settings
            .cvd
            .temperature(settings.r0, f32::from(code) * settings.reference / 32768.0)
            .ok_or("a reading the RTD cannot have".to_string())
    };
    let first = read(rng)?;
    let mut est = Estimator::new(p32, config, first).map_err(|e| e.to_string())?;
    let every = config.ticks_per(config.sample_period() as f32);
    let lag = nominal.probe.time_constant + nominal.probe.well_time_constant;
    let hold = (HOLD_TIME_CONSTANTS * lag).max(f64::from(config.observer.schedule_time()));
    let ticks = (hold / f64::from(config.tick())).ceil() as u32 + 10 * every;
    let mut last = None;
    for k in 0..ticks {
        let reading = if k % every == 0 { Ok(Some(read(rng)?)) } else { Ok(None) };
        last = Some(est.tick(reading));
    }
    // The uncertainty of the last refresh is at most five ticks old.
    let mut e = last.ok_or("no tick")?;
    e.uncertainty = est.uncertainty_now();
    Ok(e)
}

/// `devices` devices per design, each estimated at `temperatures`
/// temperatures drawn over the validated range, from `seed`.
pub fn study(designs: &[RawParams], devices: usize, temperatures: usize, seed: u64) -> Result<Vec<Sample>, String> {
    let mut rng = Rng::new(seed);
    let mut out = Vec::new();
    for (d, nominal) in designs.iter().enumerate() {
        let p32 = Params::<f32>::new(nominal).map_err(|e| e.to_string())?;
        let config = EstimatorConfig::new(nominal).map_err(|e| e.to_string())?;
        let (lo, hi) = (nominal.estimator.valid_min, nominal.estimator.valid_max);
        for _ in 0..devices {
            let device = draw(nominal, &mut rng).ok_or("no valid device drawn")?;
            let u = rng.uniform(-1.0, 1.0);
            for _ in 0..temperatures {
                let t = rng.uniform(lo, hi);
                let offset = u * nominal.probe.tolerance_at(t);
                let e = estimate_at(&p32, config, nominal, t, offset, &mut rng)?;
                let truth = reference::equilibrium(&device.core, t);
                let u = e.uncertainty;
                let x_sd = f64::from(u.x);
                let stroke = f64::from(p32.plunger.stroke);
                let x = f64::from(e.x);
                out.push(Sample {
                    design: d,
                    t,
                    error: [
                        f64::from(e.temperature) - t,
                        x - truth.x,
                        f64::from(e.p_a) - truth.p_a,
                        f64::from(e.p_b) - truth.p_b,
                        f64::from(e.q_total) - truth.q_total,
                    ],
                    sd: [
                        f64::from(u.t_oil),
                        x_sd,
                        f64::from(u.p_a),
                        f64::from(u.p_b),
                        f64::from(u.q_total),
                    ],
                    at_stop: x - 1.96 * x_sd <= 0.0 || x + 1.96 * x_sd >= stroke,
                });
            }
        }
    }
    Ok(out)
}

/// Coverage of output `o` over `samples` (those away from the stops, or
/// those at a stop): (covered, count).
pub fn coverage(samples: &[Sample], o: usize, at_stop: bool) -> (usize, usize) {
    let s: Vec<&Sample> = samples
        .iter()
        .filter(|s| !stop_effect(o) || s.at_stop == at_stop)
        .collect();
    (s.iter().filter(|s| s.covered(o)).count(), s.len())
}

/// Whether output `o`'s band is one-sided at a stop (the displacement and
/// the total flow through the window; the pressures do not depend on it).
fn stop_effect(o: usize) -> bool {
    o == 1 || o == 4
}

/// Root mean square of the normalised errors `error / sd` of output `o`
/// away from the stops (1 for an honest standard deviation of a normal
/// error).
pub fn z_rms(samples: &[Sample], o: usize) -> f64 {
    let z: Vec<f64> = samples
        .iter()
        .filter(|s| !stop_effect(o) || !s.at_stop)
        .map(|s| s.error[o] / s.sd[o])
        .collect();
    (z.iter().map(|z| z * z).sum::<f64>() / z.len().max(1) as f64).sqrt()
}

/// The study's table: coverage of each output away from the stops, with
/// its binomial standard error, the normalised errors' RMS, and the
/// one-sided bands' coverage at the stops.
pub fn table(samples: &[Sample]) -> String {
    let mut s = String::from(
        "| quantity | samples | inside +-1.96 sd | (binomial s.e.) | RMS of error / sd | band at a stop: samples, inside |\n\
         |---|---:|---:|---:|---:|---:|\n",
    );
    for (o, name) in OUTPUTS.iter().enumerate() {
        let (c, n) = coverage(samples, o, false);
        let p = c as f64 / n.max(1) as f64;
        let se = (p * (1.0 - p) / n.max(1) as f64).sqrt();
        let stop = if stop_effect(o) {
            let (cs, ns) = coverage(samples, o, true);
            format!("{ns}, {:.1} %", 100.0 * cs as f64 / ns.max(1) as f64)
        } else {
            "(no stop effect)".into()
        };
        s += &format!(
            "| {name} | {n} | {:.1} % | {:.1} % | {:.2} | {stop} |\n",
            100.0 * p,
            100.0 * se,
            z_rms(samples, o)
        );
    }
    s
}
