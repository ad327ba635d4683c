//! The profile image, run by `cargo xtask profile` (`xtask/src/profile.rs`,
//! docs/profile.md); `cargo xtask build` does not build this image.
//!
//! Runs two sections, each between two calls of [`profile_mark`], which the
//! runner finds in QEMU's instruction trace (`-singlestep -d exec,nochain`)
//! to charge every instruction executed inside a section to its function:
//!
//! 1. `twin`: the twin as built for the parameter file, in the core's
//!    arithmetic (Q12.20 without an FPU, `f32` with one), 200 ticks of the
//!    bench's 30 -> 40 C step after its graded first tick;
//! 2. `estimator`: the estimator's tick (twin, filter, rotating job,
//!    consistency check; telemetry packed every 100 ticks) over the
//!    bench's step workload, 200 ticks.
#![no_std]
#![no_main]

use compensator::Params;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator_firmware::qemu::exit;
use cortex_m as _;
use cortex_m_rt::entry;
use defmt::info;

include!(concat!(env!("OUT_DIR"), "/params.rs"));

/// The twin's arithmetic on this core: `f32` with an FPU, Q12.20 without.
#[cfg(target_abi = "eabihf")]
type Scalar = f32;
/// The twin's arithmetic on this core: `f32` with an FPU, Q12.20 without.
#[cfg(not(target_abi = "eabihf"))]
type Scalar = compensator::scalar::Fixed;

/// The section boundary a trace runner looks for (by its symbol).
#[inline(never)]
#[unsafe(no_mangle)]
pub extern "C" fn profile_mark(section: u32) {
    core::hint::black_box(section);
}

/// The start of a tick inside a section (the runner's per-tick counts and
/// worst tick).
#[inline(never)]
#[unsafe(no_mangle)]
pub extern "C" fn profile_tick() {
    core::hint::black_box(());
}

fn run() -> Result<(), &'static str> {
    let params = Params::<f32>::new(&RAW_PARAMS).map_err(|_| "parameters")?;
    let scheme = Scheme::from_name(TWIN_SCHEME).ok_or("scheme")?;
    let config = TwinConfig {
        scheme,
        tick: 1e-3,
        substeps: TWIN_SUBSTEPS,
    };
    let mut twin = Twin::<f32, Scalar>::new(&params, config, 30.0).map_err(|_| "twin")?;
    twin.set_temperature(40.0).map_err(|_| "40 C")?;
    twin.tick().map_err(|_| "graded tick")?;
    profile_mark(1);
    for _ in 0..200 {
        profile_tick();
        twin.tick().map_err(|_| "tick")?;
    }
    profile_mark(1);

    let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY)
        .map_err(|_| "estimator settings")?;
    compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS)?;
    config.telemetry_every = 100;
    let mut est = Estimator::<Scalar, _, _>::with_scalar(&params, config, 30.0).map_err(|_| "estimator")?;
    profile_mark(2);
    for k in 0..200u32 {
        profile_tick();
        let sample = if k % 20 == 0 { Ok(Some(40.0)) } else { Ok(None) };
        let e = est.tick(core::hint::black_box(sample));
        if est.telemetry_due() {
            info!("estimate {}", e);
        }
    }
    profile_mark(2);
    Ok(())
}

#[entry]
fn main() -> ! {
    match run() {
        Ok(()) => exit(true),
        Err(what) => {
            defmt::error!("profile: {=str}", what);
            exit(false)
        }
    }
}

compensator_firmware::qemu_hard_fault_handler!();
