//! A deliberate HardFault on QEMU (an undefined instruction): `cargo xtask
//! test` checks that the handler the QEMU images share
//! (`compensator_firmware::qemu_hard_fault_handler!`) reports the fault and ends the
//! run with exit code 1 at once, instead of spinning until the host's
//! deadline.
#![no_std]
#![no_main]

use cortex_m as _; // the critical-section implementation defmt needs
use cortex_m_rt::entry;

compensator_firmware::qemu_hard_fault_handler!();

#[entry]
fn main() -> ! {
    defmt::info!("executing an undefined instruction");
    cortex_m::asm::udf()
}
