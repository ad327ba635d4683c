//! Core cycles of executed instructions: each instruction of an image
//! (from `llvm-objdump -d`) given its cycle count on a core, from Arm's
//! Technical Reference Manuals, so that a trace of executed instructions
//! (`cargo xtask profile`) becomes cycles.
//!
//! Sources: Cortex-M0 TRM (DDI 0432C) table 3-1; Cortex-M3 TRM (DDI
//! 0337I) table 18-1; Cortex-M4 TRM (DDI 0439B) table 3-1 and its FPU's
//! table 7-1 (Cortex-M4 with FPU TRM). Zero-wait-state memory throughout
//! (the nRF51's flash at 16 MHz; an STM32F405 at 168 MHz runs its flash
//! with 5 wait states behind the ART accelerator, whose hit rate decides
//! what it adds: not modelled).
//!
//! Where the manuals give a range, both ends are kept ([`Cost`]: a lower
//! and an upper count):
//! * a taken branch costs its pipeline refill `P`, 1 to 3 cycles on the
//!   Cortex-M3/M4 (target width and alignment, speculation), 2 on the M0
//!   (3 for `pop {pc}`);
//! * a load or store is 2 cycles, 1 when pipelined with the one before on
//!   the M3/M4 (taken as 1-2);
//! * `sdiv`/`udiv` 2-12 (early termination); the M3's long multiplies 3-5.
//!
//! A branch counts as taken when the next executed instruction is not the
//! one after it in memory; an instruction that writes the PC (`pop {pc}`,
//! `ldr pc`, `mov pc`, `add pc`, `bx`) is a branch. The Cortex-M0's
//! multiplier is the single-cycle one (Arm's option; the small one takes
//! 32 cycles); the nRF51's is single-cycle.

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

/// The cores timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Core {
    /// Cortex-M0 (ARMv6-M).
    M0,
    /// Cortex-M3 (ARMv7-M).
    M3,
    /// Cortex-M4 with its single-precision FPU (ARMv7E-M).
    M4F,
}

impl Core {
    /// The core a target's images run on.
    pub fn of_target(target: &str) -> Core {
        match target {
            "thumbv6m-none-eabi" => Core::M0,
            "thumbv7m-none-eabi" => Core::M3,
            _ => Core::M4F,
        }
    }
}

/// Cycles of one execution of an instruction: `low..=high` when it runs
/// on to the next instruction, plus `taken` (`low..=high`) when the next
/// executed instruction is elsewhere (a taken branch).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cost {
    /// Bytes of the instruction (2 or 4).
    pub size: u8,
    /// Cycles, lower and upper.
    pub base: (u32, u32),
    /// Cycles added when the branch is taken, lower and upper (0 for an
    /// instruction that does not write the PC).
    pub taken: (u32, u32),
}

impl Cost {
    /// `(low, high)` cycles of one execution, taken or not.
    pub fn cycles(&self, taken: bool) -> (u64, u64) {
        let (b, t) = (self.base, if taken { self.taken } else { (0, 0) });
        (u64::from(b.0 + t.0), u64::from(b.1 + t.1))
    }
}

/// The cost of every instruction of an image, by address.
#[derive(Debug, Default)]
pub struct Timing {
    by_pc: HashMap<u64, Cost>,
}

impl Timing {
    /// Timing of `elf` on `core` from `llvm-objdump -d`.
    ///
    /// # Errors
    ///
    /// `llvm-objdump` is missing or fails.
    pub fn of_elf(elf: &Path, core: Core) -> Result<Timing, String> {
        let out = Command::new("llvm-objdump")
            .arg("-d")
            .arg(elf)
            .output()
            .map_err(|e| format!("llvm-objdump: {e} (apt-get install llvm)"))?;
        if !out.status.success() {
            return Err(format!(
                "llvm-objdump -d {}: {}",
                elf.display(),
                String::from_utf8_lossy(&out.stderr).trim()
            ));
        }
        Ok(Timing::of_disassembly(&String::from_utf8_lossy(&out.stdout), core))
    }

    /// Timing from the text of `llvm-objdump -d` (lines `addr: bytes \t
    /// mnemonic \t operands`; other lines are skipped).
    pub fn of_disassembly(text: &str, core: Core) -> Timing {
        let mut by_pc = HashMap::new();
        for line in text.lines() {
            let Some((address, rest)) = line.trim_start().split_once(':') else {
                continue;
            };
            let Ok(pc) = u64::from_str_radix(address, 16) else {
                continue;
            };
            let mut fields = rest.split('\t');
            let bytes = fields.next().unwrap_or("").split_whitespace().count();
            let mnemonic = fields.next().unwrap_or("").trim();
            let operands = fields.next().unwrap_or("").trim();
            if !(bytes == 2 || bytes == 4) || mnemonic.is_empty() || mnemonic.starts_with('.') {
                continue;
            }
            by_pc.insert(pc, cost(core, bytes as u8, mnemonic, operands));
        }
        Timing { by_pc }
    }

    /// The cost of the instruction at `pc`.
    pub fn at(&self, pc: u64) -> Option<Cost> {
        self.by_pc.get(&pc).copied()
    }
}

/// Registers in a register list (`{r4, r5, r7, lr}`, `{r4-r7}`,
/// `{d8-d15}`: a `d` register is two words); 1 without a list.
fn registers(operands: &str) -> u32 {
    let Some(list) = operands
        .split_once('{')
        .and_then(|(_, r)| r.split_once('}'))
        .map(|(l, _)| l)
    else {
        return 1;
    };
    list.split(',')
        .map(|r| {
            let r = r.trim();
            let words = if r.starts_with('d') { 2 } else { 1 };
            let n = match r.split_once('-') {
                Some((a, b)) => {
                    let num = |s: &str| {
                        s.trim()
                            .trim_start_matches(|c: char| c.is_ascii_alphabetic())
                            .parse::<u32>()
                    };
                    match (num(a), num(b)) {
                        (Ok(a), Ok(b)) if b >= a => b - a + 1,
                        _ => 1,
                    }
                }
                None => 1,
            };
            n * words
        })
        .sum()
}

const CONDITIONS: [&str; 15] = [
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt",
];

/// The cost of one instruction (`mnemonic` as objdump writes it, with its
/// width and condition suffixes) on `core`.
pub fn cost(core: Core, size: u8, mnemonic: &str, operands: &str) -> Cost {
    let m = mnemonic.to_ascii_lowercase();
    // `ldr.w` is `ldr`; a VFP mnemonic keeps its type (`vadd.f32` is `vadd`).
    let base = m.split('.').next().unwrap_or("");
    let writes_pc = operands.starts_with("pc") || (operands.contains("pc}") && !base.starts_with("push"));
    // P: the pipeline refill of a taken branch.
    let p = match core {
        Core::M0 => (2, 2),
        _ => (1, 3),
    };
    let memory = match core {
        Core::M0 => (2, 2),
        _ => (1, 2),
    };
    let n = registers(operands);
    let c = |base: (u32, u32), taken: (u32, u32)| Cost { size, base, taken };
    let branch = base == "b"
        || base == "bl"
        || base == "bx"
        || base == "blx"
        || base == "cbz"
        || base == "cbnz"
        || (base.len() == 3 && base.starts_with('b') && CONDITIONS.contains(&&base[1..]));
    if branch {
        return match (core, base) {
            // BL: 4 on the M0, 1 + P on the M3/M4; always taken.
            (Core::M0, "bl") => c((2, 2), (2, 2)),
            _ => c((1, 1), p),
        };
    }
    match base {
        "tbb" | "tbh" => c((2, 2), p),
        "push" | "stm" | "stmia" | "stmdb" | "stmea" | "stmfd" => c((1 + n, 1 + n), (0, 0)),
        "pop" | "ldm" | "ldmia" | "ldmdb" | "ldmfd" => {
            let taken = if writes_pc {
                match core {
                    Core::M0 => (3, 3),
                    _ => p,
                }
            } else {
                (0, 0)
            };
            c((1 + n, 1 + n), taken)
        }
        "ldrd" | "strd" => c((3, 3), (0, 0)),
        "ldr" | "ldrb" | "ldrh" | "ldrsb" | "ldrsh" | "ldrex" | "ldrexb" | "ldrexh" | "ldrt" | "str" | "strb"
        | "strh" | "strex" | "strexb" | "strexh" | "strt" => {
            if writes_pc && base == "ldr" {
                c((2, 2), p)
            } else {
                c(memory, (0, 0))
            }
        }
        "sdiv" | "udiv" => c((2, 12), (0, 0)),
        "umull" | "smull" | "umlal" | "smlal" => match core {
            Core::M3 => c((3, 5), (0, 0)),
            _ => c((1, 1), (0, 0)),
        },
        "mla" | "mls" => match core {
            Core::M3 => c((2, 2), (0, 0)),
            _ => c((1, 1), (0, 0)),
        },
        "dmb" | "dsb" | "isb" => match core {
            Core::M0 => c((4, 4), (0, 0)),
            _ => c((1, 4), (0, 0)),
        },
        // The FPU (Cortex-M4F).
        "vdiv" | "vsqrt" => c((14, 14), (0, 0)),
        "vmla" | "vmls" | "vnmla" | "vnmls" | "vfma" | "vfms" | "vfnma" | "vfnms" => c((3, 3), (0, 0)),
        "vldr" | "vstr" => c((2, 2), (0, 0)),
        "vpush" | "vpop" | "vldm" | "vldmia" | "vldmdb" | "vstm" | "vstmia" | "vstmdb" => c((1 + n, 1 + n), (0, 0)),
        // Two core registers to or from a double register or a pair.
        "vmov" if operands.matches(',').count() >= 2 => c((2, 2), (0, 0)),
        // Data processing, compares, moves, shifts, extends, `it`, `nop`;
        // writing the PC (`mov pc`, `add pc`) is a branch.
        _ => c(
            (1, 1),
            if writes_pc {
                match core {
                    Core::M0 => (2, 2),
                    _ => p,
                }
            } else {
                (0, 0)
            },
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DISASSEMBLY: &str = "\
08000400 <__stext>:
 8000400: 08 f0 09 fc  \tbl\t0x8008c16 <_defmt_timestamp> @ imm = #34834
 8000404: 12 48        \tldr\tr0, [pc, #72]           @ 0x8000450 <$d>
 800040c: 01 d0        \tbeq\t0x8000412 <__stext+0x12> @ imm = #2
 800040e: 2d e9 f0 4f  \tpush.w\t{r4, r5, r6, r7, r8, r9, r10, r11, lr}
 8000412: bd e8 f0 8f  \tpop.w\t{r4, r5, r6, r7, r8, r9, r10, r11, pc}
 8000416: 80 ee 01 0a  \tvdiv.f32\ts0, s0, s2
 800041a: 2d ed 10 8b  \tvpush\t{d8-d15}
 800041e: 41 f2 ff 70  \tsdiv\tr0, r1, r2
 8000450: 00 00 00 00  \t.word\t0x00000000
";

    #[test]
    fn each_line_of_objdump_is_timed_by_its_core() {
        let m4 = Timing::of_disassembly(DISASSEMBLY, Core::M4F);
        let at = |pc| m4.at(pc).unwrap();
        assert_eq!(at(0x800_0400).size, 4);
        assert_eq!(at(0x800_0400).cycles(true), (2, 4));
        assert_eq!(at(0x800_0404).size, 2);
        assert_eq!(at(0x800_0404).cycles(false), (1, 2));
        // A conditional branch: 1 untaken, 1 + P taken.
        assert_eq!(at(0x800_040c).cycles(false), (1, 1));
        assert_eq!(at(0x800_040c).cycles(true), (2, 4));
        assert_eq!(at(0x800_040e).cycles(false), (10, 10));
        assert_eq!(at(0x800_0412).cycles(true), (11, 13));
        assert_eq!(at(0x800_0416).cycles(false), (14, 14));
        assert_eq!(at(0x800_041a).cycles(false), (17, 17));
        assert_eq!(at(0x800_041e).cycles(false), (2, 12));
        assert_eq!(m4.at(0x800_0450), None, "data is not an instruction");
        let m0 = Timing::of_disassembly(DISASSEMBLY, Core::M0);
        assert_eq!(m0.at(0x800_0400).unwrap().cycles(true), (4, 4));
        assert_eq!(m0.at(0x800_040c).unwrap().cycles(true), (3, 3));
        assert_eq!(m0.at(0x800_0412).unwrap().cycles(true), (13, 13));
        assert_eq!(m0.at(0x800_0404).unwrap().cycles(false), (2, 2));
    }

    #[test]
    fn register_lists_count_words() {
        assert_eq!(registers("{r4, r5, r7, lr}"), 4);
        assert_eq!(registers("{r4-r7}"), 4);
        assert_eq!(registers("{d8-d15}"), 16);
        assert_eq!(registers("{s16-s31}"), 16);
        assert_eq!(registers("r0, [r1]"), 1);
    }

    #[test]
    fn the_m3_multiplies_long_in_three_to_five() {
        assert_eq!(cost(Core::M3, 4, "umull", "r0, r1, r2, r3").base, (3, 5));
        assert_eq!(cost(Core::M4F, 4, "umull", "r0, r1, r2, r3").base, (1, 1));
        assert_eq!(cost(Core::M3, 2, "muls", "r0, r1, r0").base, (1, 1));
        assert_eq!(cost(Core::M3, 2, "bx", "lr").taken, (1, 3));
        assert_eq!(cost(Core::M3, 2, "mov", "pc, r0").taken, (1, 3));
        assert_eq!(cost(Core::M3, 2, "mov", "r1, r0").taken, (0, 0));
    }
}
