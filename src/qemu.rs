//! What the QEMU images share besides their logger (`qemu_log`): the
//! semihosting exit, the panic handler and the `HardFault` report.
//!
//! A panic on QEMU logs where it happened and ends the run with exit code 1
//! (the handler lives here, in the library, so every QEMU image and the
//! on-target tests link this one; the board image links `panic-probe`).
//!
//! A fault on QEMU (a bad access, an undefined instruction, a stack
//! overflow into unmapped memory) ends the run at once with the fault's
//! registers and exit code 1, instead of spinning in cortex-m-rt's default
//! handler until the host's deadline. Each image installs the handler with
//! [`qemu_hard_fault_handler!`](crate::qemu_hard_fault_handler).

use cortex_m_rt::ExceptionFrame;
use cortex_m_semihosting::debug;

/// Configurable Fault Status Register (UsageFault, BusFault, MemManage).
#[cfg_attr(not(target_has_atomic = "32"), allow(dead_code))]
const CFSR: *const u32 = 0xE000_ED28 as *const u32;
/// HardFault Status Register (FORCED: an escalated fault).
#[cfg_attr(not(target_has_atomic = "32"), allow(dead_code))]
const HFSR: *const u32 = 0xE000_ED2C as *const u32;
/// BusFault Address Register (valid when CFSR.BFARVALID, bit 15).
#[cfg_attr(not(target_has_atomic = "32"), allow(dead_code))]
const BFAR: *const u32 = 0xE000_ED38 as *const u32;

/// The emulated core, as the images name it (ARMv6-M is the profile
/// without 32-bit atomics: stable Rust exposes no Arm target features).
#[cfg(target_abi = "eabihf")]
pub const CORE: &str = "Cortex-M4F";
/// The emulated core, as the images name it.
#[cfg(all(not(target_abi = "eabihf"), target_has_atomic = "32"))]
pub const CORE: &str = "Cortex-M3";
/// The emulated core, as the images name it.
#[cfg(not(target_has_atomic = "32"))]
pub const CORE: &str = "Cortex-M0";

/// The twin's scalar on this core: `f32` with an FPU, Q12.20 without.
#[cfg(target_abi = "eabihf")]
pub type TwinScalar = f32;
/// The twin's scalar on this core: `f32` with an FPU, Q12.20 without.
#[cfg(not(target_abi = "eabihf"))]
pub type TwinScalar = compensator::scalar::Fixed;
/// The twin integrates in fixed point on this core.
pub const FIXED_TWIN: bool = <TwinScalar as compensator::Real>::SATURATES;

/// Ends the emulation with exit code 0 (`ok`) or 1.
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
    #[allow(clippy::empty_loop)]
    loop {}
}

/// The QEMU images' panic handler: the location (the message would link
/// `core::fmt`'s float printing, 17 KiB) and exit code 1.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    if let Some(loc) = info.location() {
        defmt::error!("panic at {=str}:{=u32}", loc.file(), loc.line());
    }
    exit(false)
}

/// The estimator's settings from the parameter file's `[estimator]`
/// section, the observer and uncertainty table the build designed
/// (`OBSERVER`, `UNCERTAINTY`) and the twin configuration it chose
/// (`TWIN_SCHEME`, `TWIN_SUBSTEPS`); a refused section or configuration is
/// logged (the field, or what is wrong) and ends the run with exit code 1.
pub fn built_estimator_config(
    raw: &compensator::params::RawEstimator,
    observer: &'static compensator::estimator::ObserverDesign,
    uncertainty: &'static compensator::uncertainty::UncertaintyTable,
    scheme: &str,
    substeps: u8,
) -> crate::BuiltConfig {
    let mut config = match compensator::estimator::EstimatorConfig::from_parts(raw, observer, uncertainty) {
        Ok(c) => c,
        Err(e) => {
            defmt::error!("estimator settings rejected: {=str}", e.field);
            exit(false)
        }
    };
    if let Err(what) = crate::use_built_twin(&mut config, scheme, substeps) {
        defmt::error!("twin configuration: {=str}", what);
        exit(false)
    }
    config
}

/// Reports a HardFault (the stacked `pc`, `lr`, `xpsr` and the fault status
/// registers) and ends the emulation with exit code 1.
pub fn hard_fault(frame: &ExceptionFrame) -> ! {
    // SAFETY: the System Control Block's fault registers, always mapped on
    // ARMv7-M, read-only here. ARMv6-M has none of them (its HardFault is
    // the only fault): reported as zero.
    #[cfg(target_has_atomic = "32")]
    let (cfsr, hfsr, bfar) = unsafe { (CFSR.read_volatile(), HFSR.read_volatile(), BFAR.read_volatile()) };
    #[cfg(not(target_has_atomic = "32"))]
    let (cfsr, hfsr, bfar) = (0u32, 0u32, 0u32);
    defmt::error!(
        "HardFault: pc {=u32:#010x}, lr {=u32:#010x}, xpsr {=u32:#010x}, CFSR {=u32:#010x}, HFSR {=u32:#010x}, BFAR {=u32:#010x}",
        frame.pc(),
        frame.lr(),
        frame.xpsr(),
        cfsr,
        hfsr,
        bfar
    );
    exit(false)
}

/// Installs [`hard_fault`] as the image's `HardFault` handler (cortex-m-rt's
/// `#[exception]`, which must be in the binary crate).
#[macro_export]
macro_rules! qemu_hard_fault_handler {
    () => {
        #[cortex_m_rt::exception]
        unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::qemu::hard_fault(frame)
        }
    };
}
