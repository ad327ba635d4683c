//! Cost benchmark on QEMU: `cargo xtask bench`.
//!
//! Instructions are counted with SysTick under `qemu -icount shift=0`: the
//! emulated clock then advances exactly one nanosecond per instruction, so
//! SysTick deltas are deterministic and proportional to the instructions
//! executed. The ratio is calibrated at start-up with a loop of known
//! length (`subs; bne`, two instructions per iteration), so the method
//! does not depend on the board's clock settings.
//!
//! Every result line starts with `[measure]` and carries raw SysTick counts;
//! `cargo xtask bench` converts them with the calibration line.
//!
//! On every core (Cortex-M4F `thumbv7em-none-eabihf` on netduinoplus2,
//! Cortex-M3 `thumbv7m-none-eabi` on netduino2, Cortex-M0 `thumbv6m-none-eabi`
//! on microbit): the fixed-point kernels checked against plain integer
//! arithmetic, then the cost of each operation of a Q12.20 tick; the
//! twin's tick in `f32` (the FPU's on the Cortex-M4F, software elsewhere)
//! and Q12.20 for every scheme and substep count; the estimator's pieces;
//! the whole estimator tick (mean and worst, with and without telemetry)
//! with its twin in `f32` and in Q12.20. On the Cortex-M4F also the twin
//! through ramps across the opening (releases and impacts).
//!
//! Built for a device file with the condition monitor's second sensor
//! (feature `monitor`), the Cortex-M4F's `f32` estimator also runs its
//! workloads with the monitor (`monitor=true`: a reading every
//! `1 / monitor.sample_hz` in a job's place), and the monitor's update
//! alone is measured (`monitor-update-*`).
#![no_std]
#![no_main]

use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::scalar::Fixed;
use compensator::{Params, Real};
use compensator_firmware::qemu::exit;
use cortex_m::peripheral::{SYST, syst::SystClkSource};
use cortex_m_rt::entry;
use defmt::{error, info};

include!(concat!(env!("OUT_DIR"), "/params.rs"));

/// Ticks per measured run.
const TICKS: u32 = 200;

/// Exactly `2 n` instructions.
#[inline(always)]
fn spin(n: u32) {
    // SAFETY: a register-only countdown loop.
    unsafe {
        core::arch::asm!("2:", "subs {n}, #1", "bne 2b", n = inout(reg) n => _, options(nomem, nostack));
    }
}

/// SysTick counts spent in `f` (SysTick counts down, 24 bits).
#[inline(always)]
fn counts<R>(f: impl FnOnce() -> R) -> (R, u32) {
    let t0 = SYST::get_current();
    let r = f();
    let t1 = SYST::get_current();
    (r, t0.wrapping_sub(t1) & 0x00FF_FFFF)
}

/// Measures 200 ticks of one configuration. An error stops the image with
/// a failure: a missing row must never pass for a cheap one.
fn twin_cost<T: Real>(params: &Params<f32>, scheme: Scheme, substeps: u8, scalar: &str) -> Result<(), &'static str> {
    let config = TwinConfig {
        scheme,
        tick: 1e-3,
        substeps,
    };
    let mut twin = Twin::<f32, T>::new(params, config, 30.0).map_err(|_| "twin cannot start")?;
    twin.set_temperature(40.0).map_err(|_| "twin refuses 40 C")?;
    // The first tick after the abrupt step is graded (its substep in
    // pieces, `Twin::tick`): reported on its own. The release from the
    // stop follows within the next ticks; all are measured.
    let (r, first) = counts(|| twin.tick());
    let mut failed = r.is_err();
    let mut total = first;
    let mut worst = 0u32;
    for _ in 1..TICKS {
        let (r, c) = counts(|| twin.tick());
        failed |= r.is_err();
        total += c;
        worst = worst.max(c);
    }
    info!(
        "[measure] twin scheme={=str} substeps={=u8} scalar={=str} ticks={=u32} total={=u32} worst={=u32} graded={=u32} ok={=bool}",
        scheme.name(),
        substeps,
        scalar,
        TICKS,
        total,
        worst,
        first,
        !failed
    );
    Ok(())
}

/// The twin (f32, the configuration built for the parameter file) through
/// slow ramps across the temperature at which the window opens: the ticks
/// with a release from the closed stop and with an impact on it.
#[cfg(target_abi = "eabihf")]
fn twin_event_cost(params: &Params<f32>) -> Result<(), &'static str> {
    let scheme = Scheme::from_name(TWIN_SCHEME).ok_or("unknown twin scheme")?;
    let config = TwinConfig {
        scheme,
        tick: 1e-3,
        substeps: TWIN_SUBSTEPS,
    };
    // Where the equilibrium leaves the closed stop: the first of 26..78 C
    // (0.1 C apart) with the window open.
    let mut opening = None;
    for k in 0..520 {
        let t = 26.0 + 0.1 * k as f32;
        if compensator::equilibrium::equilibrium(params, t)
            .map_err(|_| "equilibrium")?
            .x
            > 0.0
        {
            opening = Some(t);
            break;
        }
    }
    let Some(t_open) = opening else {
        info!("[measure] twin-events skipped=no-opening-in-range");
        return Ok(());
    };
    for (name, from, to) in [
        ("release", t_open - 2.0, t_open + 2.0),
        ("impact", t_open + 2.0, t_open - 2.0),
    ] {
        let mut twin = Twin::<f32, f32>::new(params, config, from).map_err(|_| "twin cannot start")?;
        // 1 C/s over 4 C: 4,000 ticks.
        let (mut total, mut worst, mut failed) = (0u32, 0u32, false);
        let n = 4000u32;
        for k in 0..n {
            let t = from + (to - from) * (k as f32 + 0.5) / n as f32;
            twin.set_temperature(t).map_err(|_| "twin refuses the ramp")?;
            let (r, c) = counts(|| twin.tick());
            failed |= r.is_err();
            total += c;
            worst = worst.max(c);
        }
        info!(
            "[measure] twin-events kind={=str} scheme={=str} substeps={=u8} ticks={=u32} total={=u32} worst={=u32} ok={=bool}",
            name, TWIN_SCHEME, TWIN_SUBSTEPS, n, total, worst, !failed
        );
    }
    Ok(())
}

fn pieces(params: &Params<f32>) -> Result<(), &'static str> {
    use compensator::asymptotic::sensitivity_at;
    use compensator::dynamics::fsi::{Contact, DynamicState, Fsi, Model};
    use compensator::dynamics::linear::hurwitz_stable;
    use compensator::dynamics::schemes::OdeSystem;
    use compensator::equilibrium::{a_parameter, equilibrium_for};
    use compensator::estimator::{Estimator, EstimatorConfig, telemetry};
    use core::hint::black_box;

    let t = black_box(55.5f32);
    let (point, c) = counts(|| params.oil.point(black_box(t)));
    info!("[measure] piece name=fluid-point total={=u32}", c);
    let point = point.map_err(|_| "fluid point")?;
    let (eq, c) = counts(|| equilibrium_for(params, point.state, a_parameter(params, &point.state)));
    info!("[measure] piece name=equilibrium total={=u32}", c);
    let (_, c) = counts(|| black_box(sensitivity_at(params, &point)));
    info!("[measure] piece name=sensitivity total={=u32}", c);
    let eq = eq.map_err(|_| "equilibrium")?;
    let model = Model::new(params).map_err(|_| "model")?;
    let coef = model.coefficients::<f32>(&point.state).map_err(|_| "coefficients")?;
    let (_, c) = counts(|| {
        let y: [f32; 4] = model.equilibrium_state(&eq);
        black_box(hurwitz_stable(
            &Fsi {
                coefficients: &coef,
                contact: Contact::Free,
            }
            .jacobian(&y),
        ))
    });
    info!("[measure] piece name=stability total={=u32}", c);

    // The f32 elementary functions the fluid laws use: the crate's own
    // kernels against libm's and micromath's.
    let x = black_box(1.234f32);
    let pieces: [(&str, fn(f32) -> f32); 7] = [
        ("exp10-mathf", compensator::mathf::exp10),
        ("exp10-libm", libm::exp10f),
        ("exp2-libm", libm::exp2f),
        ("exp-libm", libm::expf),
        ("exp-micromath", micromath::F32Ext::exp),
        ("ln1p-libm", libm::log1pf),
        ("ln-micromath", micromath::F32Ext::ln),
    ];
    for (name, f) in pieces {
        let (_, c) = counts(|| black_box(f(black_box(x))));
        info!("[measure] piece name={=str} total={=u32}", name, c);
    }

    // Telemetry packing alone: one estimate, encoded by defmt.
    let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY)
        .map_err(|_| "estimator settings")?;
    compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS)?;
    let mut est = Estimator::new(params, config, 40.0).map_err(|_| "estimator cannot start")?;
    let e = est.tick(Ok(Some(40.0)));
    let (_, c) = counts(|| info!("estimate {}", black_box(e)));
    info!("[measure] piece name=telemetry total={=u32}", c);
    // Its parts: the record packed (`telemetry::encode`), and per field
    // kind the cost of one field (sixteen values of that kind encoded and
    // stored, `calls=16`: the report divides).
    let (_, c) = counts(|| black_box(telemetry::encode(black_box(&e))));
    info!("[measure] piece name=telemetry-pack total={=u32}", c);
    let values: [f32; 16] = black_box(core::array::from_fn(|i| 1.5e-6 * i as f32 - 3e-6));
    let (_, c) = counts(|| black_box(black_box(values).map(|v| v.to_bits().to_le_bytes())));
    info!("[measure] piece name=telemetry-field-f32 calls=16 total={=u32}", c);
    let per = black_box(1.0 / 1e-7f32);
    let (_, c) = counts(|| black_box(black_box(values).map(|v| telemetry::u16_code(v, per).to_le_bytes())));
    info!("[measure] piece name=telemetry-field-u16 calls=16 total={=u32}", c);
    let (_, c) = counts(|| black_box(black_box(values).map(|v| telemetry::i16_code(v, per).to_le_bytes())));
    info!("[measure] piece name=telemetry-field-i16 calls=16 total={=u32}", c);
    let counts16: [u32; 16] = black_box(core::array::from_fn(|i| i as u32));
    let (_, c) = counts(|| black_box(black_box(counts16).map(u32::to_le_bytes)));
    info!("[measure] piece name=telemetry-field-u32 calls=16 total={=u32}", c);
    // What a byte of the record adds to sending it (the logger's copy):
    // a 64-byte string against an empty one.
    let bytes = black_box([0x5Au8; 64]);
    let (_, empty) = counts(|| info!("bytes {=[u8]}", black_box(&bytes[..0])));
    let (_, full) = counts(|| info!("bytes {=[u8]}", black_box(&bytes[..])));
    info!(
        "[measure] piece name=telemetry-byte calls=64 total={=u32}",
        full.saturating_sub(empty)
    );

    // The tick that re-seats the twin (consistency check): an estimator
    // steady at 55 C for its settling window, its twin forced off the
    // equilibrium; the next round of jobs re-seats it. Its worst tick is
    // that one (the Equilibrium job, the check and the re-seat).
    let mut est = Estimator::new(params, config, 55.0).map_err(|_| "estimator cannot start")?;
    let settle = est.settle_ticks();
    if settle > 100_000 {
        return Err("no settling window at 55 C: the consistency check cannot run");
    }
    for k in 0..settle + 100 {
        est.tick(if k % 20 == 0 { Ok(Some(55.0)) } else { Ok(None) });
    }
    let s = est.twin().state();
    est.twin_mut().set_state(&DynamicState {
        x: if s.x > 0.5 * params.plunger.stroke {
            0.0
        } else {
            params.plunger.stroke
        },
        v: 0.0,
        p_a: s.p_b,
        p_b: s.p_a,
    });
    let mut worst = 0u32;
    for _ in 0..5 {
        let (_, c) = counts(|| black_box(est.tick(black_box(Ok(None)))));
        worst = worst.max(c);
    }
    if est.tick(Ok(None)).reseats != 1 {
        return Err("the forced wrong state was not re-seated");
    }
    info!("[measure] piece name=estimator-reseat-tick total={=u32}", worst);

    #[cfg(feature = "monitor")]
    monitor_pieces(params)?;
    Ok(())
}

/// The reading the monitor's sensor gives of estimate `e` (the twin's own:
/// a device as the file's), moved by `fault` \[Pa or m\].
#[cfg(feature = "monitor")]
fn second_reading(e: &compensator::estimator::StateEstimate, fault: f32) -> f32 {
    use compensator::monitor::Quantity;
    let settings = MONITOR.map_or(Quantity::ChamberA, |m| m.quantity);
    fault
        + match settings {
            Quantity::ChamberA => e.p_a,
            Quantity::ChamberB => e.p_b,
            Quantity::Difference => e.p_b - e.p_a,
            Quantity::Displacement => e.x,
        }
}

/// The monitor's update alone, per reading (`monitor-update-mean`,
/// `monitor-update-worst`): 400 readings at the closed-form equilibrium
/// over a 4 K warming, the second half moved by a tenth of the pressure
/// drop (or of the stroke), so that the change is detected, fitted over
/// the span by every hypothesis and named: every path of the update. The
/// probe reads with every reading (the worst case: each update tests),
/// through its lag (backward Euler of its time constant).
#[cfg(feature = "monitor")]
fn monitor_pieces(params: &Params<f32>) -> Result<(), &'static str> {
    use compensator::monitor::{Monitor, PlantView, ProbeSample, Quantity};
    use core::hint::black_box;
    let settings = MONITOR.ok_or("the monitor's bench without a second sensor")?;
    let mut monitor = Monitor::new(params, settings).map_err(|_| "monitor settings")?;
    let n = 400u32;
    let dt = settings.sample_period;
    let lag = dt / (settings.probe.time_constant + dt);
    let mut probe = 40.0f32;
    let (mut total, mut worst) = (0u32, 0u32);
    for k in 0..n {
        let t = 40.0 + 0.01 * k as f32;
        probe += lag * (t - probe);
        let point = params.oil.point(t).map_err(|_| "fluid point")?;
        let eq = compensator::equilibrium::equilibrium(params, t).map_err(|_| "equilibrium")?;
        let view = PlantView {
            oil: point,
            x: eq.x,
            p_a: eq.p_a,
            p_b: eq.p_b,
            dt: if k == 0 { 0.0 } else { dt },
            probe: Some(ProbeSample { value: probe, age: 0.0 }),
        };
        let y = match settings.quantity {
            Quantity::ChamberA => eq.p_a,
            Quantity::ChamberB => eq.p_b,
            Quantity::Difference => eq.p_b - eq.p_a,
            Quantity::Displacement => eq.x,
        };
        let step = if settings.quantity == Quantity::Displacement {
            0.1 * params.plunger.stroke
        } else {
            0.1 * params.pressure_drop
        };
        let y = if k >= n / 2 { y + step } else { y };
        let (h, c) = counts(|| monitor.update(params, black_box(&view), black_box(Ok::<f32, ()>(y))));
        black_box(h);
        total += c;
        worst = worst.max(c);
    }
    info!(
        "[measure] piece name=monitor-update-mean calls={=u32} total={=u32}",
        n, total
    );
    info!("[measure] piece name=monitor-update-worst total={=u32}", worst);
    Ok(())
}

/// The whole estimator tick with its twin in `T`, as the firmware runs it:
/// a sample every 20 ticks; a 30 -> 40 C step (taken as real by the spike
/// filter, then followed by the twin at its slew), and ramps at 4 C/s from
/// 26 C to 46 C and back (the plunger leaves the closed stop and creeps
/// back onto it: the releases and impacts); with telemetry packed at its
/// cadence (every 100 ticks here), then without telemetry.
fn estimator_cost<T: Real>(params: &Params<f32>, scalar: &str) -> Result<(), &'static str> {
    use compensator::estimator::{Estimator, EstimatorConfig};
    use core::hint::black_box;
    let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY)
        .map_err(|_| "estimator settings")?;
    compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS)?;
    for (workload, n) in [("step", 1000u32), ("ramps", 10_000u32)] {
        for telemetry in [true, false] {
            let mut config = config;
            config.telemetry_every = if telemetry { 100 } else { 0 };
            let start = if workload == "step" { 30.0 } else { 26.0 };
            let mut est =
                Estimator::<T, _, _>::with_scalar(params, config, start).map_err(|_| "estimator cannot start")?;
            let (mut total, mut worst, mut worst_tick) = (0u32, 0u32, 0u32);
            for k in 0..n {
                let temperature = if workload == "step" {
                    40.0f32
                } else {
                    let s = k as f32 * 1e-3;
                    26.0 + 4.0 * if s < 5.0 { s } else { 10.0 - s }
                };
                let sample = if k % 20 == 0 { Ok(Some(temperature)) } else { Ok(None) };
                let (_, c) = counts(|| {
                    let e = est.tick(black_box(sample));
                    if est.telemetry_due() {
                        info!("estimate {}", e);
                    }
                });
                total += c;
                if c > worst {
                    worst = c;
                    worst_tick = k;
                }
            }
            info!(
                "[measure] estimator workload={=str} scheme={=str} substeps={=u8} scalar={=str} telemetry={=bool} ticks={=u32} total={=u32} worst={=u32} worst_tick={=u32}",
                workload,
                config.twin.scheme.name(),
                config.twin.substeps,
                scalar,
                telemetry,
                n,
                total,
                worst,
                worst_tick
            );
        }
    }
    Ok(())
}

/// [`estimator_cost`] with the condition monitor (the image built for a
/// second sensor), its twin in `f32`: the monitor fitted, a reading of its
/// sensor offered every `1 / monitor.sample_hz` (the twin's own reading of
/// the last estimate, moved by a tenth of the pressure drop, or of the
/// stroke, over the workload's second half: the change detected, fitted
/// and named), the offer counted in the tick (the board makes it in its
/// tick path); the lines marked `monitor=true`.
#[cfg(feature = "monitor")]
fn estimator_cost_monitor(params: &Params<f32>, scalar: &str) -> Result<(), &'static str> {
    use compensator::estimator::{Estimator, EstimatorConfig};
    use core::hint::black_box;
    let settings = MONITOR.ok_or("the monitor's bench without a second sensor")?;
    let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY)
        .map_err(|_| "estimator settings")?;
    compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS)?;
    let second_every = config.ticks_per(settings.sample_period);
    let step = if settings.quantity == compensator::monitor::Quantity::Displacement {
        0.1 * params.plunger.stroke
    } else {
        0.1 * params.pressure_drop
    };
    for (workload, n) in [("step", 1000u32), ("ramps", 10_000u32)] {
        for telemetry in [true, false] {
            let mut config = config;
            config.telemetry_every = if telemetry { 100 } else { 0 };
            let start = if workload == "step" { 30.0 } else { 26.0 };
            let mut est = Estimator::new(params, config, start)
                .map_err(|_| "estimator cannot start")?
                .with_monitor(settings)
                .map_err(|_| "monitor settings")?;
            let mut last = est.tick(Ok(None));
            let (mut total, mut worst, mut worst_tick) = (0u32, 0u32, 0u32);
            for k in 0..n {
                let temperature = if workload == "step" {
                    40.0f32
                } else {
                    let s = k as f32 * 1e-3;
                    26.0 + 4.0 * if s < 5.0 { s } else { 10.0 - s }
                };
                let sample = if k % 20 == 0 { Ok(Some(temperature)) } else { Ok(None) };
                let second = k
                    .is_multiple_of(second_every)
                    .then(|| second_reading(&last, if k >= n / 2 { step } else { 0.0 }));
                let (e, c) = counts(|| {
                    if let Some(y) = second {
                        est.offer_second(Ok(black_box(y)));
                    }
                    let e = est.tick(black_box(sample));
                    if est.telemetry_due() {
                        info!("estimate {}", e);
                    }
                    e
                });
                last = e;
                total += c;
                if c > worst {
                    worst = c;
                    worst_tick = k;
                }
            }
            info!(
                "[measure] estimator workload={=str} scheme={=str} substeps={=u8} scalar={=str} monitor=true telemetry={=bool} ticks={=u32} total={=u32} worst={=u32} worst_tick={=u32}",
                workload,
                config.twin.scheme.name(),
                config.twin.substeps,
                scalar,
                telemetry,
                n,
                total,
                worst,
                worst_tick
            );
        }
    }
    Ok(())
}

/// The operations [`fixed_pieces`] measures, each out of line so that one
/// call is one operation (an identity function's call is subtracted).
mod ops {
    use compensator::Real;
    use compensator::scalar::Fixed;
    fn bits(v: Fixed) -> i64 {
        v.0.to_bits() as i64
    }
    fn f(v: Fixed) -> f32 {
        v.to_f32()
    }
    #[inline(never)]
    pub fn identity(a: Fixed, _b: Fixed) -> i64 {
        bits(a)
    }
    #[inline(never)]
    pub fn mul(a: Fixed, b: Fixed) -> i64 {
        bits(a * b)
    }
    #[inline(never)]
    pub fn div(a: Fixed, b: Fixed) -> i64 {
        bits(a / b)
    }
    #[inline(never)]
    pub fn sqrt(a: Fixed, _b: Fixed) -> i64 {
        bits(a.sqrt())
    }
    #[inline(never)]
    pub fn sqrt_recip(a: Fixed, b: Fixed) -> i64 {
        let (r, i) = Fixed::sqrt_recip_sum_products(a, a, b, b);
        bits(r) ^ bits(i)
    }
    #[inline(never)]
    pub fn add(a: Fixed, b: Fixed) -> i64 {
        bits(a + b)
    }
    #[inline(never)]
    pub fn i64_mul(a: Fixed, b: Fixed) -> i64 {
        bits(a) * bits(b)
    }
    #[inline(never)]
    pub fn i64_div(a: Fixed, b: Fixed) -> i64 {
        (bits(a) << 20) / (bits(b) | 1)
    }
    /// The operands converted once, outside the measured operation (the
    /// conversions are subtracted with the identity's call).
    #[inline(never)]
    pub fn f32_mul(a: Fixed, b: Fixed) -> i64 {
        (f(a) * f(b)).to_bits() as i64
    }
    #[inline(never)]
    pub fn f32_div(a: Fixed, b: Fixed) -> i64 {
        (f(a) / f(b)).to_bits() as i64
    }
    #[inline(never)]
    pub fn f32_sqrt(a: Fixed, _b: Fixed) -> i64 {
        Real::sqrt(f(a)).to_bits() as i64
    }
    #[inline(never)]
    pub fn f32_convert(a: Fixed, b: Fixed) -> i64 {
        (f(a).to_bits() ^ f(b).to_bits()) as i64
    }
}

/// What the arithmetic of a Q12.20 tick costs on this core, one operation
/// each, the mean over 16 operand pairs spanning the tick's ranges
/// (`docs/dynamics.md`): the kernels, and what they replace (a 32 x 32 ->
/// 64 product, a 64-bit quotient) or compete with (`f32`, in software
/// without an FPU).
fn fixed_pieces() {
    use core::hint::black_box;
    const N: usize = 16;
    let mut a = [Fixed::ZERO; N];
    let mut b = [Fixed::ZERO; N];
    for k in 0..N {
        a[k] = Fixed::from_f64(0.013 + 7.9 * k as f64 / N as f64);
        b[k] = Fixed::from_f64(0.41 + 0.37 * k as f64);
    }
    let (a, b) = (black_box(a), black_box(b));
    let each = |f: fn(Fixed, Fixed) -> i64| {
        let f = black_box(f);
        counts(|| {
            for k in 0..N {
                black_box(f(a[k], b[k]));
            }
        })
        .1
    };
    let base = each(ops::identity);
    // The f32 rows' two conversions from Q12.20 are subtracted too.
    let convert = each(ops::f32_convert).saturating_sub(base);
    let pieces: [(&str, fn(Fixed, Fixed) -> i64); 10] = [
        ("mul", ops::mul),
        ("div", ops::div),
        ("sqrt", ops::sqrt),
        ("sqrt-recip", ops::sqrt_recip),
        ("add", ops::add),
        ("i64-mul", ops::i64_mul),
        ("i64-div", ops::i64_div),
        ("f32-mul", ops::f32_mul),
        ("f32-div", ops::f32_div),
        ("f32-sqrt", ops::f32_sqrt),
    ];
    for (name, f) in pieces {
        let overhead = if name.starts_with("f32") { base + convert } else { base };
        let c = each(f).saturating_sub(overhead);
        info!(
            "[measure] fixed name={=str} calls={=u32} total={=u32}",
            name, N as u32, c
        );
    }
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        exit(false)
    };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();

    let n = 100_000u32;
    let (_, c) = counts(|| spin(core::hint::black_box(n)));
    info!("[measure] calibration instructions={=u32} total={=u32}", 2 * n, c);

    // The fixed-point kernels of this core against plain integer
    // arithmetic, before anything is measured with them.
    if let Err(m) = compensator::scalar::check_kernels(2000) {
        error!(
            "fixed-point kernel {=str} wrong: operands {=i64} {=i64}, got {=i64}",
            m.kernel, m.operands.0, m.operands.1, m.got
        );
        exit(false)
    }
    // The Cortex-M0's own f32 fast paths against compiler_builtins'.
    if let Err(m) = compensator_firmware::softfloat::self_check(100_000) {
        error!(
            "f32 {=str} wrong: operands {=u32:#x} {=u32:#x}, got {=u32:#x}, want {=u32:#x}",
            m.operation, m.operands.0, m.operands.1, m.got, m.want
        );
        exit(false)
    }
    let Ok(params) = Params::<f32>::new(&RAW_PARAMS) else {
        error!("parameters rejected");
        exit(false)
    };
    info!(
        "[measure] built scheme={=str} substeps={=u8} params={=str}",
        TWIN_SCHEME, TWIN_SUBSTEPS, PARAMS_SOURCE
    );
    let configs: [(Scheme, u8); 17] = [
        (Scheme::Sdirk3, 1),
        (Scheme::Sdirk3, 2),
        (Scheme::Sdirk3, 4),
        (Scheme::Sdirk2, 2),
        (Scheme::Sdirk2, 4),
        (Scheme::LinearlyImplicitEuler, 1),
        (Scheme::LinearlyImplicitEuler, 4),
        (Scheme::Ros2, 1),
        (Scheme::Ros2, 2),
        (Scheme::Ros2, 4),
        (Scheme::Ros3, 1),
        (Scheme::Ros3, 2),
        (Scheme::Ros3, 4),
        (Scheme::Rodas3, 1),
        (Scheme::Rodas3, 2),
        (Scheme::Rk4, 32),
        (Scheme::Rk4, 64),
    ];
    // `f32` is the FPU's on the Cortex-M4F, software elsewhere.
    let f32_name = if cfg!(target_abi = "eabihf") { "f32" } else { "f32-soft" };
    let run = || -> Result<(), &'static str> {
        fixed_pieces();
        for (scheme, substeps) in configs {
            twin_cost::<f32>(&params, scheme, substeps, f32_name)?;
            twin_cost::<Fixed>(&params, scheme, substeps, "q12.20")?;
        }
        #[cfg(target_abi = "eabihf")]
        twin_event_cost(&params)?;
        pieces(&params)?;
        estimator_cost::<f32>(&params, f32_name)?;
        estimator_cost::<Fixed>(&params, "q12.20")?;
        // With the monitor: the Cortex-M4F's f32 estimator, whose budget
        // it shares.
        #[cfg(all(feature = "monitor", target_abi = "eabihf"))]
        estimator_cost_monitor(&params, f32_name)?;
        Ok(())
    };
    match run() {
        Ok(()) => exit(true),
        Err(what) => {
            error!("bench: {=str}", what);
            exit(false)
        }
    }
}

compensator_firmware::qemu_hard_fault_handler!();
