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
const CFSR: *const u32 = 0xE000_ED28 as *const u32;
/// HardFault Status Register (FORCED: an escalated fault).
const HFSR: *const u32 = 0xE000_ED2C as *const u32;
/// BusFault Address Register (valid when CFSR.BFARVALID, bit 15).
const BFAR: *const u32 = 0xE000_ED38 as *const u32;

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
/// section with the twin configuration the build chose (`TWIN_SCHEME`,
/// `TWIN_SUBSTEPS`); a refused section or configuration is logged (the
/// field, or what is wrong) and ends the run with exit code 1.
pub fn built_estimator_config(
    raw: &compensator::params::RawEstimator,
    scheme: &str,
    substeps: u8,
) -> compensator::estimator::EstimatorConfig {
    let mut config = match compensator::estimator::EstimatorConfig::new(raw) {
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
    // ARMv7-M, read-only here.
    let (cfsr, hfsr, bfar) = unsafe { (CFSR.read_volatile(), HFSR.read_volatile(), BFAR.read_volatile()) };
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
