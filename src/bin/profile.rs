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
//!    bench's step workload, 200 ticks;
//! 3. with the condition monitor (feature `monitor`: the file names a
//!    second sensor), `monitor`: its update, one reading a tick, over the
//!    bench's monitor sequence (400 readings at the closed-form
//!    equilibrium over a 4 K warming, the second half moved by a tenth of
//!    the pressure drop or the stroke: detected, fitted, named).
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

    #[cfg(feature = "monitor")]
    {
        use compensator::monitor::{Monitor, PlantView, ProbeSample, Quantity};
        let settings = MONITOR.ok_or("the monitor's image without a second sensor")?;
        let mut monitor = Monitor::new(&params, settings).map_err(|_| "monitor settings")?;
        let n = 400u32;
        // The inputs, outside the readings' ticks: the plant at eight
        // temperatures 0.5 K apart, each held for 50 readings.
        let mut views = [None; 8];
        for (j, v) in views.iter_mut().enumerate() {
            let t = 40.0 + 0.5 * j as f32;
            let point = params.oil.point(t).map_err(|_| "fluid point")?;
            let eq = compensator::equilibrium::equilibrium(&params, t).map_err(|_| "equilibrium")?;
            let y = match settings.quantity {
                Quantity::ChamberA => eq.p_a,
                Quantity::ChamberB => eq.p_b,
                Quantity::Difference => eq.p_b - eq.p_a,
                Quantity::Displacement => eq.x,
            };
            let view = PlantView {
                oil: point,
                x: eq.x,
                p_a: eq.p_a,
                p_b: eq.p_b,
                dt: settings.sample_period,
                probe: None,
            };
            *v = Some((view, y));
        }
        let step = if settings.quantity == Quantity::Displacement {
            0.1 * params.plunger.stroke
        } else {
            0.1 * params.pressure_drop
        };
        // The probe reads with every reading, through its lag (backward
        // Euler of its time constant), as the bench's monitor pieces.
        let lag = settings.sample_period / (settings.probe.time_constant + settings.sample_period);
        let mut probe = 40.0f32;
        profile_mark(3);
        for k in 0..n {
            let Some((mut view, y)) = views[(k / 50) as usize % 8] else {
                return Err("a view");
            };
            probe += lag * (view.oil.state.temperature - probe);
            view.probe = Some(ProbeSample { value: probe, age: 0.0 });
            let y = if k >= n / 2 { y + step } else { y };
            profile_tick();
            core::hint::black_box(monitor.update(&params, core::hint::black_box(&view), Ok::<f32, ()>(y)));
        }
        // The last reading's tick ends here.
        profile_tick();
        profile_mark(3);
    }
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
