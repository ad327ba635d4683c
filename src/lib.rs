//! # compensator-firmware
//!
//! The firmware around the `compensator` model crate: the images in
//! `src/bin` (`twin` and `bench` on QEMU, `board` on an STM32F405, `fault`
//! for the fault handler's test), and the hardware glue they share.
//!
//! * [`clock`]: real time from the tick counter (defmt timestamps).
//! * [`deadline`]: the tick periods elapsed between ticks (late ticks).
//! * [`softfloat`]: `f32` multiply, add and subtract for the Cortex-M0
//!   (`__aeabi_fmul`, `__aeabi_fadd`, `__aeabi_fsub`) and their start-up
//!   check.
//! * `qemu` (QEMU images): semihosting exit, the shared panic and
//!   HardFault handling, the defmt logger over semihosting.
//!
//! The parameter file becomes constants at build time (`build.rs`), which
//! also chooses the twin's configuration for it.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]
#![forbid(unsafe_op_in_unsafe_fn)]

pub mod clock;
pub mod deadline;
pub mod softfloat;

#[cfg(all(feature = "qemu", target_os = "none"))]
pub mod qemu;
#[cfg(all(feature = "qemu", target_os = "none"))]
mod qemu_log;

use compensator::dynamics::{Scheme, TwinConfig};
use compensator::estimator::{Estimator, EstimatorConfig, ObserverDesign};
use compensator::uncertainty::UncertaintyTable;

/// The estimator's settings as the images hold them: the uncertainty table
/// and the observer's design by reference to the build's statics in flash
/// (`UNCERTAINTY`, `OBSERVER`), so that no copy of either (0.75 KiB and
/// 0.9 KiB) sits on the stack.
pub type BuiltConfig = EstimatorConfig<&'static UncertaintyTable, &'static ObserverDesign>;

/// The estimator with [`BuiltConfig`], its twin integrating in `T`.
pub type BuiltEstimator<T = f32> = Estimator<T, &'static UncertaintyTable, &'static ObserverDesign>;

/// Puts the twin configuration chosen at build time (`TWIN_SCHEME`,
/// `TWIN_SUBSTEPS` of the generated `params.rs`) into `config`, keeping
/// its tick.
///
/// Errors: an unknown scheme name or a substep count outside
/// `1..=MAX_SUBSTEPS` (a build script out of step with the model).
pub fn use_built_twin<U, O>(
    config: &mut EstimatorConfig<U, O>,
    scheme: &str,
    substeps: u8,
) -> Result<(), &'static str> {
    let scheme = Scheme::from_name(scheme).ok_or("unknown twin scheme")?;
    let twin = TwinConfig {
        scheme,
        substeps,
        ..config.twin
    };
    twin.validate().map_err(|_| "twin configuration out of range")?;
    config.twin = twin;
    Ok(())
}
