//! The deadline on QEMU: the estimator on the emulated Cortex-M0
//! (microbit) at a tick rate it cannot sustain, paced by SysTick as the
//! board's loop is (`cargo xtask test` runs it under `-icount shift=0`,
//! one instruction per nanosecond: a 50 kHz tick leaves 20,000
//! instructions per period, fewer than the Q12.20 estimator's tick takes).
//!
//! At a steady 55 C the twin starts off its equilibrium and relaxes. Every
//! tick that starts after the next one was due is late: the loop hands the
//! elapsed periods to `Estimator::tick_after`, which counts them (the
//! telemetry record's `missed=`), flags `DEADLINE_MISSED` and catches the
//! twin up. The image checks that late ticks occurred and were counted
//! exactly, that the estimator's tick counter is the real one, that no
//! tick was lost, and that the late twin is where a second, punctual
//! estimator's twin is after the same number of real ticks; it exits 0 or
//! 1.
#![no_std]
#![no_main]

use compensator::Params;
use compensator::Real;
use compensator::dynamics::DynamicState;
use compensator::estimator::{Estimator, EstimatorConfig, Flags};
use compensator::uncertainty::UncertaintyTable;
use compensator_firmware::deadline::TickPace;
use compensator_firmware::qemu::{CORE, TwinScalar, exit};
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use defmt::{error, info};

include!(concat!(env!("OUT_DIR"), "/params.rs"));

compensator_firmware::qemu_hard_fault_handler!();

/// The tick rate the core cannot sustain [Hz].
const TICK_HZ: f64 = 50_000.0;
/// SysTick's clock on QEMU's microbit (the nRF51's 16 MHz core clock).
const CORE_HZ: u32 = 16_000_000;
/// Real ticks the paced run lasts (40 ms).
const REAL_TICKS: u32 = 2000;
/// The oil's steady temperature [C].
const TEMPERATURE: f32 = 55.0;

/// Tick periods elapsed (the SysTick interrupt's; a load and a store,
/// ARMv6-M has no atomic read-modify-write, and only the interrupt writes).
static TICKS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    TICKS.store(TICKS.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
}

/// An estimator at `TEMPERATURE` with its twin displaced (the plunger
/// half-way, the chamber pressures swapped).
fn displaced(
    params: &Params<f32>,
    config: EstimatorConfig<&'static UncertaintyTable>,
) -> Option<Estimator<TwinScalar, &'static UncertaintyTable>> {
    let mut est = Estimator::<TwinScalar, _>::with_scalar(params, config, TEMPERATURE).ok()?;
    let s = est.twin().state();
    est.twin_mut().set_state(&DynamicState {
        x: 0.5 * params.plunger.stroke,
        v: 0.0,
        p_a: s.p_b,
        p_b: s.p_a,
    });
    Some(est)
}

fn sample(tick: u32) -> Result<Option<f32>, compensator::sensor::SensorFault> {
    if tick.is_multiple_of(20) {
        Ok(Some(TEMPERATURE))
    } else {
        Ok(None)
    }
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        exit(false)
    };
    let Ok(params) = Params::<f32>::new(&RAW_PARAMS) else {
        error!("parameters rejected");
        exit(false)
    };
    let mut raw = RAW_PARAMS;
    raw.estimator.tick_hz = TICK_HZ;
    // The observer is designed for this image's tick here; the
    // uncertainty table (which no tick changes) is the build's.
    let mut config = match EstimatorConfig::with_table(&raw, &UNCERTAINTY) {
        Ok(c) => c,
        Err(_) => {
            error!("estimator settings rejected at {=f64} Hz", TICK_HZ);
            exit(false)
        }
    };
    if compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS).is_err() {
        exit(false)
    }
    let Some(mut late) = displaced(&params, config) else {
        error!("estimator cannot start");
        exit(false)
    };
    let reload = CORE_HZ / TICK_HZ as u32 - 1;
    info!(
        "deadline on the emulated {=str}: the estimator ({=str} twin) at {=f64} Hz, {=u32} core cycles per tick",
        CORE,
        <TwinScalar as Real>::NAME,
        TICK_HZ,
        reload + 1
    );
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(reload);
    cp.SYST.clear_current();
    cp.SYST.enable_interrupt();
    cp.SYST.enable_counter();

    let mut pace = TickPace::new(TICKS.load(Ordering::Relaxed));
    let (mut ran, mut missed, mut late_ticks, mut worst) = (0u32, 0u32, 0u32, 1u32);
    let mut last = None;
    loop {
        while !pace.due(TICKS.load(Ordering::Relaxed)) {}
        let now = TICKS.load(Ordering::Relaxed);
        if now > REAL_TICKS {
            break;
        }
        let elapsed = pace.take(now);
        let e = late.tick_after(sample(now), elapsed);
        ran += 1;
        missed += elapsed - 1;
        worst = worst.max(elapsed);
        if e.flags.contains(Flags::DEADLINE_MISSED) {
            late_ticks += 1;
        }
        last = Some((now, e));
    }
    cp.SYST.disable_interrupt();
    cp.SYST.disable_counter();
    let Some((real, e)) = last else { exit(false) };
    info!(
        "{=u32} real ticks: {=u32} ticks ran, {=u32} late, {=u32} deadlines missed (at most {=u32} periods between ticks), {=u32} lost",
        real,
        ran,
        late_ticks,
        e.deadline_misses,
        worst,
        late.lost_ticks()
    );
    info!("{=u32} ms {}", (real as f64 * 1e3 / TICK_HZ) as u32, e);

    // The same twin, ticked on time for the same real ticks.
    let Some(mut punctual) = displaced(&params, config) else {
        exit(false)
    };
    for k in 1..=real {
        punctual.tick(sample(k));
    }
    let (a, b) = (punctual.twin().raw_state(), late.twin().raw_state());
    let mut off = 0.0f64;
    for i in 0..4 {
        off = off.max((a[i].to_f64() - b[i].to_f64()).abs());
    }
    info!(
        "late twin against the punctual one after {=u32} ticks: x {=f64} vs {=f64} of the stroke, largest difference {=f64}",
        real,
        b[0].to_f64(),
        a[0].to_f64(),
        off
    );
    let checks = [
        (late_ticks > 0 && missed > 0, "the unsustainable rate made ticks late"),
        (e.deadline_misses == missed, "every missed deadline counted"),
        (e.tick == real, "the estimator's tick counter is the real one"),
        (late.lost_ticks() == 0, "no tick lost to the twin"),
        ((a[0].to_f64() - 0.5).abs() > 0.01, "the displaced twin relaxed"),
        (off <= 1e-5, "the late twin where the punctual one is"),
    ];
    let mut failed = 0;
    for (ok, what) in checks {
        if !ok {
            error!("check failed: {=str}", what);
            failed += 1;
        }
    }
    info!(
        "deadline checks: {=u32} passed, {=u32} failed",
        checks.len() as u32 - failed,
        failed
    );
    exit(failed == 0)
}
