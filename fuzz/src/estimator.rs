//! Target `estimator`: the estimator driven by arbitrary sensor answers,
//! directly (`Estimator::tick` with any `Result<Option<f32>,
//! SensorFault>`) or through the MAX31865 driver reading a simulated
//! converter (`Max31865<SimulatedMax31865>`: temperatures, fault causes,
//! forced codes, bus errors, MISO stuck high, reads at any pace).
//!
//! Input ([`arbitrary::Unstructured`], in this order):
//!
//! * a byte: the preset, `% 2` (paper, model-example);
//! * six bytes of `[estimator]` settings, each 0 for the default: tick
//!   rate `[1000, 500, 2000, 250, 4000][b % 5]` Hz; filter time constant
//!   `0.2 s * 2^(i / 64)` (`i` the byte as `i8`: 0.05-0.8 s); spike
//!   threshold `5 C * 2^(i / 32)` (0.3-80 C); spike limit `(5 + b) % 12`;
//!   telemetry `[2, 0, 10, 50][b % 4]` Hz; mains `[50, 60][b % 2]` Hz;
//! * a byte: the source, `% 2` (0: samples given directly, 1: the driver
//!   and the simulated converter);
//! * a 16-bit code: the start temperature ([`input::temperature`]);
//! * then steps, up to 256, while bytes remain (4,096 ticks at most in
//!   all): a kind byte `k`, a 16-bit code `c` and a gap byte `g`.
//!   - directly: the sample of one tick is, by `k % 8`, 0-4
//!     `Ok(Some(temperature(c)))`, 5 `Ok(None)`, 6 `Err(fault)` (`c % 7`
//!     of seven `SensorFault`s, one of each cause), 7 `Ok(Some(f32::from_bits(c << 16)))`
//!     (any `f32`); then `g % 64` ticks of `Ok(None)`;
//!   - through the driver: the converter's RTD is put at
//!     `temperature(c)`; `k % 8` picks its fault cause (0-3 none, 4 RTD
//!     high, 5 RTD low, 6 a REFIN-/RTDIN- wiring fault, 7 over/under
//!     voltage); bit 3 fails the bus, bit 4 sticks MISO high, bit 5 forces
//!     the code `c & 0x7FFF`; bits 6-7 the pace of the reads for the step's
//!     `1 + g % 64` ticks (0, 1: one per conversion period, as the firmware;
//!     2: every tick; 3: none).
//!
//! Checks, every tick: the estimate is finite (`StateEstimate::is_finite`,
//! the estimator's promise on any input); `0 <= x <= stroke`; the
//! pressures within `PRESSURE_MARGIN` (4) `dp` of `[p_c, p_p]`; the
//! filtered temperature within the hull of the start and the oil's range
//! (`[oil_min, oil_max]`, all a sample can bring); `OUT_OF_RANGE` exactly
//! outside the validated range; `AT_STOP` only on a stop; a sample that is
//! an error, not finite or outside the oil's range raises `SENSOR_FAULT`
//! (directly); no re-seat of the twin by the consistency check on the
//! presets (`reseats` stays 0: docs/firmware.md, the SDIRK twin never
//! settles off the closed form).
//!
//! Then the last temperature a sample brought within the oil's range (else
//! the start's) is held: given every conversion period with the converter
//! healthy. The estimate must come to rest on that temperature (within
//! 0.01 C directly, 0.1 C through the converter's 15-bit code) and on the
//! closed-form equilibrium there (`Params<f32>`, the estimator's) within
//! [`check::AT_REST`] (1e-3) of the stroke and of `dp`: the hold lasts
//! until both have held (the state within a tenth of the tolerance) for
//! three of the twin's slowest time constants, and at most the time the
//! spike filter, the low-pass filter (15 time constants), the twin's slew
//! over the oil's viscosity range and 20 of its slowest time constants
//! need, when it must be within them.

use crate::check;
use crate::input::{Design, byte, presets, temperature, word};
use arbitrary::Unstructured;
use compensator::dynamics::DynamicState;
use compensator::dynamics::linear::linearise;
use compensator::dynamics::twin::PRESSURE_MARGIN;
use compensator::equilibrium::equilibrium;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate, TWIN_SLEW};
use compensator::params::RawEstimator;
use compensator::sensor::max31865::{Max31865, Settings, fault};
use compensator::sensor::simulated::SimulatedMax31865;
use compensator::sensor::{Detail, SensorFault, TemperatureSource};
use compensator::{Params, RawParams};

/// Most steps of an input.
pub const STEPS: usize = 256;
/// Most ticks of the steps of an input.
pub const STEP_TICKS: u32 = 4096;

const FAULTS: [SensorFault; 7] = [
    SensorFault::Bus,
    SensorFault::OpenCircuit(Detail::max31865_status(fault::RTD_HIGH)),
    SensorFault::ShortCircuit(Detail::code(0)),
    SensorFault::Wiring(Detail::max31865_status(fault::REFIN_LOW)),
    SensorFault::Supply(Detail::max31865_status(fault::VOLTAGE)),
    SensorFault::OutOfRange(Detail::NONE),
    SensorFault::Stale,
];

/// The `[estimator]` section of six setting bytes (0: the default).
pub fn settings(u: &mut Unstructured, base: &RawEstimator) -> RawEstimator {
    let mut e = *base;
    e.tick_hz = [1000.0, 500.0, 2000.0, 250.0, 4000.0][usize::from(byte(u) % 5)];
    e.max_oil_rate = [1.0, 0.2, 5.0, 20.0][usize::from(byte(u) % 4)];
    e.spike_threshold *= (f64::from(byte(u) as i8) / 32.0).exp2();
    e.spike_limit = f64::from((5 + u16::from(byte(u))) % 12);
    e.telemetry_hz = [2.0, 0.0, 10.0, 50.0][usize::from(byte(u) % 4)];
    e.mains_hz = [50.0, 60.0][usize::from(byte(u) % 2)];
    e
}

/// One step of an input.
#[derive(Clone, Copy, Debug)]
struct Step {
    kind: u8,
    code: u16,
    gap: u8,
}

/// One input.
pub fn run(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let preset = usize::from(byte(&mut u) % 2);
    let mut raw: RawParams = presets()[preset];
    raw.estimator = settings(&mut u, &raw.estimator);
    // The readings are held oil temperatures: a probe of 10 ms to 0.2 s,
    // so that the observer reaches a held reading in bounded time.
    raw.probe.time_constant = [0.01, 0.03, 0.1, 0.2][usize::from(byte(&mut u) % 4)];
    raw.probe.well_time_constant = 0.0;
    let through_driver = byte(&mut u) % 2 == 1;
    let start = temperature(word(&mut u)) as f32;
    let mut steps = Vec::with_capacity(STEPS);
    while !u.is_empty() && steps.len() < STEPS {
        steps.push(Step {
            kind: byte(&mut u),
            code: word(&mut u),
            gap: byte(&mut u),
        });
    }
    let (Ok(p), Ok(cfg)) = (Params::<f32>::new(&raw), EstimatorConfig::new(&raw)) else {
        panic!("preset {preset} with {:?} is refused", raw.estimator);
    };
    let Ok(est) = Estimator::new(&p, cfg, start) else {
        return;
    };
    let mut run = Run {
        raw,
        design: Design::Preset(preset),
        p,
        cfg,
        est,
        start,
        ticks: 0,
    };
    let settings = Settings::from_params(&raw.estimator);
    let sensor_every = cfg.ticks_per(settings.mains.conversion_period());
    if through_driver {
        let mut sensor = Max31865::new(SimulatedMax31865::new(settings, start), settings);
        let _ = sensor.configure();
        let mut last = None;
        for (i, s) in steps.iter().enumerate() {
            let t = temperature(s.code) as f32;
            {
                let sim = sensor.device_mut();
                sim.temperature = t;
                sim.fault = match s.kind & 7 {
                    4 => fault::RTD_HIGH,
                    5 => fault::RTD_LOW,
                    6 => fault::REFIN_LOW | fault::RTDIN_LOW,
                    7 => fault::VOLTAGE,
                    _ => 0,
                };
                sim.bus_error = s.kind & 0x08 != 0;
                sim.miso_stuck_high = s.kind & 0x10 != 0;
                sim.forced_code = (s.kind & 0x20 != 0).then_some(s.code & 0x7FFF);
            }
            for _ in 0..=s.gap % 64 {
                if run.ticks >= STEP_TICKS {
                    break;
                }
                let read = match s.kind >> 6 {
                    2 => true,
                    3 => false,
                    _ => run.ticks.is_multiple_of(sensor_every),
                };
                let sample = if read { sensor.read() } else { Ok(None) };
                if let Ok(Some(v)) = sample {
                    last = Some(v);
                }
                run.tick(sample, &|| format!("step {i} {s:?} through the driver"));
            }
        }
        // Inside the oil's range by half a degree: the converter's fault
        // band is that range, and its code's resolution (0.03 C) would
        // put a reading at either end on the wrong side of it.
        let compensator::estimator::TemperatureRange { min: lo, max: hi } = run.cfg.oil;
        let target = last.unwrap_or(start).max(lo + 0.5).min(hi - 0.5);
        if !run.in_oil(target) {
            return;
        }
        {
            let sim = sensor.device_mut();
            sim.temperature = target;
            sim.fault = 0;
            sim.forced_code = None;
            sim.bus_error = false;
            sim.miso_stuck_high = false;
        }
        run.hold("through the driver", target, 0.1, sensor_every, |k| {
            if k.is_multiple_of(sensor_every) {
                sensor.read()
            } else {
                Ok(None)
            }
        });
    } else {
        let mut last = None;
        for (i, s) in steps.iter().enumerate() {
            let sample = match s.kind % 8 {
                0..=4 => Ok(Some(temperature(s.code) as f32)),
                5 => Ok(None),
                6 => Err(FAULTS[usize::from(s.code) % FAULTS.len()]),
                _ => Ok(Some(f32::from_bits(u32::from(s.code) << 16))),
            };
            if let Ok(Some(v)) = sample
                && run.in_oil(v)
            {
                last = Some(v);
            }
            for k in 0..=u32::from(s.gap % 64) {
                if run.ticks >= STEP_TICKS {
                    break;
                }
                let given = if k == 0 { sample } else { Ok(None) };
                let e = run.tick(given, &|| format!("step {i} {s:?}, tick {k}"));
                let bad = match given {
                    Ok(Some(v)) => !run.in_oil(v),
                    Ok(None) => false,
                    Err(_) => true,
                };
                assert_eq!(
                    bad,
                    e.flags.contains(Flags::SENSOR_FAULT),
                    "step {i} {s:?}, tick {k}: sample {given:?}, flags {:?}",
                    e.flags
                );
            }
        }
        let target = last.unwrap_or(start);
        if !run.in_oil(target) {
            return;
        }
        run.hold("directly", target, 0.01, sensor_every, |k| {
            if k.is_multiple_of(sensor_every) {
                Ok(Some(target))
            } else {
                Ok(None)
            }
        });
    }
}

/// An estimator under test.
struct Run {
    raw: RawParams,
    design: Design,
    p: Params<f32>,
    cfg: EstimatorConfig,
    est: Estimator,
    start: f32,
    ticks: u32,
}

impl Run {
    /// A sample the estimator takes as a temperature (finite, in the oil's range).
    fn in_oil(&self, t: f32) -> bool {
        let compensator::estimator::TemperatureRange { min: lo, max: hi } = self.cfg.oil;
        t.is_finite() && t >= lo && t <= hi
    }

    /// One tick and the checks on its estimate.
    fn tick(&mut self, sample: Result<Option<f32>, SensorFault>, what: &dyn Fn() -> String) -> StateEstimate {
        self.ticks += 1;
        let e = self.est.tick(sample);
        let what = || format!("{}, estimator tick {}, sample {sample:?}: {e:?}", what(), self.ticks);
        self.check(&e, &what);
        e
    }

    fn check(&self, e: &StateEstimate, what: &dyn Fn() -> String) {
        let p = &self.p;
        assert!(
            e.is_finite(),
            "{}: not finite, settings {:?}",
            what(),
            self.raw.estimator
        );
        let s = DynamicState {
            x: e.x,
            v: e.v,
            p_a: e.p_a,
            p_b: e.p_b,
        };
        check::si_state(&s, p, PRESSURE_MARGIN, what);
        let compensator::estimator::TemperatureRange { min: lo, max: hi } = self.cfg.oil;
        let (lo, hi) = (lo.min(self.start), hi.max(self.start));
        let slack = 1e-5 * (lo.abs().max(hi.abs()) + 1.0);
        assert!(
            e.temperature >= lo - slack && e.temperature <= hi + slack,
            "{}: filtered temperature {} outside [{lo}, {hi}]",
            what(),
            e.temperature
        );
        let compensator::estimator::TemperatureRange { min: vlo, max: vhi } = self.cfg.valid;
        assert_eq!(
            e.flags.contains(Flags::OUT_OF_RANGE),
            !(e.temperature >= vlo && e.temperature <= vhi),
            "{}: OUT_OF_RANGE",
            what()
        );
        if e.flags.contains(Flags::AT_STOP) {
            assert!(
                e.x == 0.0 || e.x == p.plunger.stroke,
                "{}: AT_STOP at x = {}",
                what(),
                e.x
            );
        }
        if matches!(self.design, Design::Preset(_)) {
            assert_eq!(e.reseats, 0, "{}: the consistency check re-seated the twin", what());
        }
    }

    /// Holds `target` [C] with `sample(k)` at hold tick `k`, until at rest
    /// (see the module docs).
    fn hold(
        &mut self,
        how: &str,
        target: f32,
        tol_t: f32,
        sensor_every: u32,
        mut sample: impl FnMut(u32) -> Result<Option<f32>, SensorFault>,
    ) {
        let Ok(lin) = linearise(&self.p, target) else {
            return;
        };
        if !lin.stable {
            return;
        }
        let tick = self.cfg.tick() as f64;
        let slowest = lin
            .eigenvalues
            .iter()
            .map(|l| -f64::from(l.re))
            .fold(f64::INFINITY, f64::min);
        let tau = 1.0 / slowest;
        let raw = &self.raw.estimator;
        // The spike gate (and, through the driver, a detection cycle and
        // its restart), the observer's settling (its gains' schedule from
        // the fast mode to the hold mode, the hold mode over a hundred
        // probe time constants),
        // the twin's slew over the oil's viscosity range (a Fluid job on at
        // least every other tick), the twin's settling.
        let period = sensor_every as f64 * tick;
        let spikes = (raw.spike_limit + 12.0) * period;
        let filter = f64::from(self.cfg.observer.schedule_time()) + 100.0 * self.raw.probe.time_constant + 1.0;
        let mu = |t: f64| self.p.oil.state(t as f32).map(|f| f64::from(f.dynamic_viscosity));
        let (Ok(cold), Ok(hot)) = (mu(raw.oil_min.max(-20.0)), mu(raw.oil_max.min(150.0))) else {
            return;
        };
        let slew = 2.0 * (cold / hot).ln().abs() / f64::from(TWIN_SLEW) * tick + 0.05;
        let cap = spikes + filter + slew + 20.0 * tau + 0.05;
        let max_ticks = (cap / tick).ceil() as u32;
        let resting = ((3.0 * tau / tick).ceil() as u32).max(20);
        // Finding F2 (docs/fuzzing.md), fixed: the observer's sums are
        // compensated and reach their input; no allowance for a stall.
        let mut within = 0u32;
        let mut last = None;
        for k in 0..max_ticks {
            let given = sample(k);
            let e = self.tick(given, &|| format!("held at {target} C {how}, tick {k}"));
            last = Some(e);
            let Ok(eq) = equilibrium(&self.p, e.temperature) else {
                within = 0;
                continue;
            };
            let s = DynamicState {
                x: e.x,
                v: e.v,
                p_a: e.p_a,
                p_b: e.p_b,
            };
            if (e.temperature - target).abs() <= tol_t && check::off_rest(&s, &eq, &self.p) <= 0.1 * check::AT_REST {
                within += 1;
                if within >= resting {
                    return;
                }
            } else {
                within = 0;
            }
        }
        let Some(e) = last else { return };
        let eq = equilibrium(&self.p, e.temperature);
        let s = DynamicState {
            x: e.x,
            v: e.v,
            p_a: e.p_a,
            p_b: e.p_b,
        };
        let off = eq.as_ref().map_or(f64::INFINITY, |eq| check::off_rest(&s, eq, &self.p));
        assert!(
            (e.temperature - target).abs() <= tol_t && off <= check::AT_REST,
            "held at {target} C {how} for {max_ticks} ticks ({cap:.3} s, slowest time constant {tau:.3e} s), \
             settings {:?}: the estimate {e:?} is {off:.3e} from the closed form {eq:?}",
            self.raw.estimator
        );
    }
}
