//! How closely the estimate follows a warm-up through a probe that lags:
//! the estimator's own dynamic error, against the independent reference
//! driven by the true oil temperature.
//!
//! A run: the device held at `from` until the probe and the estimator have
//! settled ([`SETTLE_TIME_CONSTANTS`] probe time constants), then the oil
//! ramps at `rate` to `to` and holds. The probe is simulated exactly (its
//! first-order lags' response to the ramp, in `f64`), read every 20 ms with
//! its noise and the MAX31865's quantization; the estimator is the `f32`
//! one built for the device file with that probe. The truth is
//! `compensator-reference`'s Radau5 solution of the same device driven by
//! the oil's temperature. The probe's tolerance and the device's
//! tolerances are left out: they are systematic, and in the band
//! (`host_tests::coverage`); this is what the estimator adds.

use crate::coverage::normal;
use crate::random::Rng;
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::RawParams;
use compensator::sensor::max31865::{Settings, code_of};
use compensator_reference::dynamics::{Method, Profile, simulate};

/// Probe time constants the device holds before the ramp.
pub const SETTLE_TIME_CONSTANTS: f64 = 6.0;

/// Sampling of the comparison [s] (the reference's output grid).
pub const GRID: f64 = 0.1;

/// What one run measured.
#[derive(Clone, Copy, Debug)]
pub struct Run {
    /// The probe's time constant and its well's [s].
    pub lag: (f64, f64),
    /// The ramp's rate [C/s].
    pub rate: f64,
    /// Largest `|x - x_ref|` during the ramp, once two probe time constants
    /// (both lags) have passed since it began [strokes].
    pub ramp: f64,
    /// Largest during the first two time constants of the ramp [strokes].
    pub onset: f64,
    /// Largest once two time constants have passed since the ramp ended
    /// [strokes].
    pub after: f64,
    /// What the reading lags the oil by in the ramp, `rate (tau + tau_w)`,
    /// as displacement at the design's mean `|dx/dt|` over the ramp
    /// [strokes]: the error of an estimator that took the reading for the
    /// oil.
    pub reading_lag: f64,
}

/// A first-order lag `tc dy/dt = u - y` advanced by `dt` [s] exactly for
/// an input linear over the step, `u(t) = u0 + slope t`: the probe's
/// (and its well's) response, as the host runs simulate it.
pub fn lag_step(y: f64, u0: f64, slope: f64, tc: f64, dt: f64) -> f64 {
    let e = (-dt / tc).exp();
    u0 + slope * dt - slope * tc + (y - u0 + slope * tc) * e
}

/// One run of `raw` (its `[probe]`) from `from` to `to` [C] at `rate`
/// [C/s], noise and quantization from the file, from `seed`.
pub fn run(raw: &RawParams, from: f64, to: f64, rate: f64, seed: u64) -> Result<Run, String> {
    run_traced(raw, from, to, rate, seed, false)
}

/// As [`run`], printing the trajectory every second.
pub fn debug_run(raw: &RawParams, from: f64, to: f64, rate: f64, seed: u64) -> Result<Run, String> {
    run_traced(raw, from, to, rate, seed, true)
}

fn run_traced(raw: &RawParams, from: f64, to: f64, rate: f64, seed: u64, trace: bool) -> Result<Run, String> {
    let p32 = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let config = EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let settings = Settings::from_params(&raw.estimator);
    let (tau, tau_w) = (raw.probe.time_constant, raw.probe.well_time_constant);
    let lag = tau + tau_w;
    let mut rng = Rng::new(seed);
    let span = (to - from).abs() / rate;
    let t_end = span + 2.0 * lag + 30.0;
    let profile = Profile::Ramp { from, to, rate };
    let reference = simulate(&raw.core, profile, t_end, GRID, Method::Radau5, 1e-8)?;
    let stroke = raw.core.stroke;
    let tick = f64::from(config.tick());
    let every = config.ticks_per(config.sample_period() as f32);
    let read = |probe: f64, rng: &mut Rng| -> Result<f32, String> {
        let y = probe + raw.probe.noise * normal(rng);
        let r = settings.cvd.resistance(settings.r0, y as f32);
        let code = code_of(&settings, r);
        settings
            .cvd
            .temperature(settings.r0, f32::from(code) * settings.reference / 32768.0)
            .ok_or_else(|| "a reading the RTD cannot have".to_string())
    };
    let mut est = Estimator::new(&p32, config, read(from, &mut rng)?).map_err(|e| e.to_string())?;
    // Settled at `from`.
    let settle = (SETTLE_TIME_CONSTANTS * lag / tick).ceil() as u64;
    for k in 0..settle {
        let r = if k % u64::from(every) == 0 {
            Ok(Some(read(from, &mut rng)?))
        } else {
            Ok(None)
        };
        est.tick(r);
    }
    // The ramp, the probe's lags exact per tick (a linear input over it).
    let (mut well, mut probe) = (from, from);
    let per_grid = (GRID / tick).round() as u64;
    let mut out = Run {
        lag: (tau, tau_w),
        rate,
        ramp: 0.0,
        onset: 0.0,
        after: 0.0,
        reading_lag: 0.0,
    };
    let ticks = (t_end / tick).round() as u64;
    for k in 0..ticks {
        let t0 = k as f64 * tick;
        let (oil0, oil1) = (profile.temperature(t0), profile.temperature(t0 + tick));
        let slope = (oil1 - oil0) / tick;
        let advance = |y: f64, u0: f64, s: f64, tc: f64| lag_step(y, u0, s, tc, tick);
        if tau_w > 0.0 {
            let w0 = well;
            well = advance(well, oil0, slope, tau_w);
            probe = advance(probe, w0, (well - w0) / tick, tau);
        } else {
            probe = advance(probe, oil0, slope, tau);
        }
        let r = if (settle + k).is_multiple_of(u64::from(every)) {
            Ok(Some(read(probe, &mut rng)?))
        } else {
            Ok(None)
        };
        let e = est.tick(r);
        if (k + 1) % per_grid == 0 {
            let i = ((k + 1) / per_grid) as usize;
            let t = (k + 1) as f64 * tick;
            let Some(state) = reference.state.get(i) else { break };
            let err = (f64::from(e.x) - state[0]).abs() / stroke;
            if trace && i.is_multiple_of(10) {
                println!(
                    "t {t:.1} s: oil {:.3} probe {probe:.3} estimate {:.3} C, x {:.4e} reference {:.4e} m, {:?}",
                    profile.temperature(t),
                    e.temperature,
                    e.x,
                    state[0],
                    e.flags
                );
            }
            if t <= span {
                if t >= 2.0 * lag {
                    out.ramp = out.ramp.max(err);
                } else {
                    out.onset = out.onset.max(err);
                }
            } else if t >= span + 2.0 * lag {
                out.after = out.after.max(err);
            }
        }
    }
    let x = |t: f64| crate::reference::equilibrium(&raw.core, t).x;
    out.reading_lag = ((x(to) - x(from)) / (to - from)).abs() * rate * lag / stroke;
    Ok(out)
}
