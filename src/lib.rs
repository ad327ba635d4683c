//! # compensator-firmware
//!
//! The firmware around the `compensator` model crate: the images in
//! `src/bin` (`twin` and `bench` on QEMU, `board` on an STM32F405, `fault`
//! for the fault handler's test), and the hardware glue they share.
//!
//! * [`clock`]: real time from the tick counter (defmt timestamps).
//! * [`deadline`]: the tick periods elapsed between ticks (late ticks).
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

#[cfg(all(feature = "qemu", target_os = "none"))]
pub mod qemu;
#[cfg(all(feature = "qemu", target_os = "none"))]
mod qemu_log;

use compensator::dynamics::{Scheme, TwinConfig};
use compensator::estimator::EstimatorConfig;

/// Puts the twin configuration chosen at build time (`TWIN_SCHEME`,
/// `TWIN_SUBSTEPS` of the generated `params.rs`) into `config`, keeping
/// its tick.
///
/// Errors: an unknown scheme name or a substep count outside
/// `1..=MAX_SUBSTEPS` (a build script out of step with the model).
pub fn use_built_twin<U>(config: &mut EstimatorConfig<U>, scheme: &str, substeps: u8) -> Result<(), &'static str> {
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
