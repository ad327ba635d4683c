//! The soak on QEMU (netduinoplus2, Cortex-M4F): `cargo xtask test` runs it,
//! `cargo xtask qemu-runner target/firmware/thumbv7em-none-eabihf/release/soak`
//! after `cargo xtask build`.
//!
//! [`TICKS`] ticks (1,000 s of oil at 1 kHz) of a seeded temperature walk
//! (abrupt steps, holds, ramps, cold excursions to the oil range's bottom)
//! with injected sensor faults (spikes, bus errors, dropouts, stuck codes,
//! a stuck converter, open and shorted element, out-of-range codes),
//! through the parameter file's sensor simulated at register level and read
//! by its real driver (the MAX31865 by default; with `estimator.sensor =
//! "ntc"` the NTC on the STM32F4's ADC: `build.rs` sets `cfg(sensor_ntc)`),
//! and the estimator every tick, built for the parameter file as the twin
//! image is. Every tick is
//! checked (`compensator_testbench::soak`, shared with the host soak of
//! `host-tests/src/soak.rs`, which runs the same walk for the same seed):
//! no NaN, no re-seat of the twin, `SENSOR_FAULT` exactly on the unusable
//! samples, `DEGRADED` exactly `stale_after` ticks after the last accepted
//! sample, `SPIKE` on every spiked sample, each fault's flag within its
//! bound, recovery within its bound, no sensor flag while the sensor is
//! healthy, and every settled hold's estimate on the `f64` closed form
//! within 1e-3 of the stroke and of `dp`. Prints a summary (faults per
//! kind, worst latencies, violations per check) and exits 0 when nothing
//! was violated, else 1. `docs/soak.md` has the figures.
#![no_std]
#![no_main]

use compensator::Params;
use compensator_firmware::qemu::exit;
use cortex_m as _; // links the critical-section implementation defmt needs
use cortex_m_rt::entry;
use defmt::{error, info};
// The walk, the faults and the checks, shared with the host soak.
use compensator_testbench::soak::{CHECKS, Kind, Soak};

include!(concat!(env!("OUT_DIR"), "/params.rs"));

/// The parameter file's sensor behind its real driver, simulated at
/// register level: the MAX31865 ...
#[cfg(not(sensor_ntc))]
type Sensor = compensator::sensor::simulated::SimulatedRtd;
/// ... or the NTC on the STM32F4's ADC (`estimator.sensor = "ntc"`).
#[cfg(sensor_ntc)]
type Sensor = compensator::sensor::simulated::SimulatedNtc;

// A fault reports its registers and exits 1 (not a spin until the deadline).
compensator_firmware::qemu_hard_fault_handler!();

/// Ticks of the soak (1e6 on QEMU: 1,000 s of oil at 1 kHz).
const TICKS: u32 = 1_000_000;

/// The walk's seed (the host soak's default: `cargo test -p host-tests
/// --test soak` runs the same walk on the host).
const SEED: u64 = 2025;

/// A progress line every this many ticks.
const PROGRESS_EVERY: u32 = 100_000;

#[entry]
fn main() -> ! {
    let params = match Params::<f32>::new(&RAW_PARAMS) {
        Ok(p) => p,
        Err(e) => {
            error!("parameters rejected: {=str}", e.field);
            exit(false)
        }
    };
    let params64 = match Params::<f64>::new(&RAW_PARAMS) {
        Ok(p) => p,
        Err(e) => {
            error!("parameters rejected in f64: {=str}", e.field);
            exit(false)
        }
    };
    let config = compensator_firmware::qemu::built_estimator_config(
        &RAW_PARAMS.estimator,
        &OBSERVER_WITHOUT_LAG,
        &UNCERTAINTY,
        TWIN_SCHEME,
        TWIN_SUBSTEPS,
    );
    let mut soak = match Soak::<Sensor, _, _>::new(&params, &params64, config, &RAW_PARAMS.estimator, SEED) {
        Ok(s) => s,
        Err(what) => {
            error!("soak: {=str}", what);
            exit(false)
        }
    };
    let lim = soak.limits;
    info!(
        "soak: {=u32} ticks, seed {=u64}, parameters {=str}, twin {=str} x{=u8} (estimated within {=f32} % of a step)",
        TICKS, SEED, PARAMS_SOURCE, TWIN_SCHEME, TWIN_SUBSTEPS, TWIN_ESTIMATED_ERROR_PCT
    );
    info!(
        "sensor {=str}; walk {=f32}..{=f32} C, cold excursions {=f32}..{=f32} C; a read every {=u32} ticks; bounds: flag {=u32}, DEGRADED {=u32}, recovery {=u32} ticks",
        compensator::sensor::device::SensorKind::of(&RAW_PARAMS.estimator).name(),
        lim.range.0,
        lim.range.1,
        lim.cold.0,
        lim.cold.1,
        lim.sensor_every,
        lim.detection_bound(),
        lim.degraded_bound(),
        lim.recovery_bound()
    );
    for k in 0..TICKS {
        soak.step();
        if (k + 1) % PROGRESS_EVERY == 0 {
            info!(
                "{=u32} ticks, {=u32} faults, {=u32} violations",
                k + 1,
                soak.stats.total_injected(),
                soak.stats.total_violations()
            );
        }
    }
    let st = &soak.stats;
    info!("kind: injected, unread, worst flag [ticks], long, worst DEGRADED [ticks], worst recovery [ticks]");
    for kind in Kind::ALL {
        let i = kind.index();
        info!(
            "  {=str}: {=u32}, {=u32}, {=u32}, {=u32}, {=u32}, {=u32}",
            kind.name(),
            st.injected[i],
            st.unread[i],
            st.detection[i],
            st.long[i],
            st.degraded[i],
            st.recovery[i]
        );
    }
    info!(
        "walk: {=u32} segments, {=u32} steps (worst recovery {=u32} ticks), {=u32} cold excursions, oil {=f32}..{=f32} C",
        st.segments, st.steps, st.step_recovery, st.cold_excursions, st.span.0, st.span.1
    );
    info!(
        "samples: {=u32} read, {=u32} unusable, {=u32} rejected as spikes",
        st.samples, st.unusable, st.spikes
    );
    info!(
        "holds: {=u32} checked against the f64 closed form, {=u32} too short; worst {=f64} of the stroke, {=f64} of dp",
        st.holds_checked, st.holds_skipped, st.hold_x, st.hold_p
    );
    info!("twin re-seated {=u32} times", st.reseats);
    for (i, what) in CHECKS.iter().enumerate() {
        if st.violations[i] > 0 {
            error!(
                "violated {=u32} times, first at tick {=u32}: {=str}",
                st.violations[i], st.first_violation[i], what
            );
        }
    }
    let ok = st.total_violations() == 0 && st.total_injected() > 0;
    info!(
        "soak: {=u32} ticks, {=u32} faults, {=u32} violations",
        st.ticks,
        st.total_injected(),
        st.total_violations()
    );
    exit(ok)
}
