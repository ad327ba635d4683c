//! Single-precision multiply, add and subtract for ARMv6-M (the
//! Cortex-M0/M0+, no FPU, no long multiply): the symbols the compiler
//! calls for `f32` arithmetic on that core (`__aeabi_fmul`,
//! `__aeabi_fadd`, `__aeabi_fsub`, Arm's *Run-time ABI*, section 4.1.2),
//! taken by `compensator::softfloat`'s fast paths for normal operands
//! with a normal result, and by `compiler_builtins`' full routines
//! (`__mulsf3`, `__addsf3`, `__subsf3`) for the rest. `compiler_builtins`
//! defines its `__aeabi_*` symbols weak, so these replace them at link
//! time; every other core keeps its own.
//!
//! What they save (`cargo xtask bench`, `docs/bench.md`): the product's
//! 64 x 64 multiply (`__aeabi_lmul`) and the generic addition's
//! bookkeeping, on every `f32` operation of the estimator on that core.
//! [`self_check`] compares them with the full routines on the core.

/// A fast path's answer that differs from `compiler_builtins`' routine:
/// the operation (`"mul"`, `"add"`, `"sub"`), its operands' and its
/// result's words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// `"mul"`, `"add"` or `"sub"`.
    pub operation: &'static str,
    /// The operands' words.
    pub operands: (u32, u32),
    /// The fast path's word.
    pub got: u32,
    /// The full routine's word.
    pub want: u32,
}

#[cfg(all(target_arch = "arm", target_os = "none", not(target_has_atomic = "32")))]
mod v6m {
    // compiler_builtins' full routines, which the fast paths fall back to,
    // and the fast paths themselves (below).
    unsafe extern "C" {
        pub fn __mulsf3(a: f32, b: f32) -> f32;
        pub fn __addsf3(a: f32, b: f32) -> f32;
        pub fn __subsf3(a: f32, b: f32) -> f32;
    }
    unsafe extern "aapcs" {
        pub fn __aeabi_fmul(a: f32, b: f32) -> f32;
        pub fn __aeabi_fadd(a: f32, b: f32) -> f32;
        pub fn __aeabi_fsub(a: f32, b: f32) -> f32;
    }

    // `compensator::softfloat::{mul, add, sub}` in Thumb-1, step for step
    // (that module's docs give the algorithm; its host tests check it
    // against IEEE 754): the Rust compiled to about as many instructions
    // as compiler_builtins' routines on this core, spilling its values to
    // the stack. The operands are kept in r12 and lr (lr is pushed) for
    // the full routine, which every other case calls; the pushes keep the
    // stack 8-byte aligned for that call (AAPCS), r3 pushed as padding.
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".section .text.compensator_softfloat,\"ax\",%progbits",
        ".balign 4",
        // ---- a * b ----
        ".global __aeabi_fmul",
        ".type __aeabi_fmul,%function",
        ".thumb_func",
        "__aeabi_fmul:",
        "push {{r4, r5, r6, lr}}",
        "mov r12, r0",
        "mov lr, r1",
        // The biased exponents, both normal (1..=254).
        "lsls r2, r0, #1",
        "lsrs r2, r2, #24",
        "lsls r3, r1, #1",
        "lsrs r3, r3, #24",
        "subs r4, r2, #1",
        "cmp r4, #253",
        "bhi 80f",
        "subs r4, r3, #1",
        "cmp r4, #253",
        "bhi 81f",
        "adds r6, r2, r3",
        // The product's sign.
        "movs r5, r0",
        "eors r5, r1",
        "lsrs r5, r5, #31",
        "lsls r5, r5, #31",
        // The significands (24 bits), split in 16-bit halves.
        "movs r4, #1",
        "lsls r4, r4, #23",
        "lsls r0, r0, #9",
        "lsrs r0, r0, #9",
        "orrs r0, r4",
        "lsls r1, r1, #9",
        "lsrs r1, r1, #9",
        "orrs r1, r4",
        "lsrs r2, r0, #16",
        "uxth r0, r0",
        "lsrs r3, r1, #16",
        "uxth r1, r1",
        // lo = al bl, mid = ah bl + al bh + lo >> 16, top = ah bh 2^16 + mid.
        "movs r4, r0",
        "muls r4, r1, r4",
        "muls r1, r2, r1",
        "muls r0, r3, r0",
        "muls r2, r3, r2",
        "adds r1, r1, r0",
        "lsrs r0, r4, #16",
        "adds r1, r1, r0",
        "uxth r4, r4",
        "lsls r2, r2, #16",
        "adds r2, r2, r1",
        // top >= 2^31: 24 bits from bit 31, else from bit 30.
        "bmi 1f",
        "subs r6, #127",
        "lsls r3, r2, #25",
        "lsrs r2, r2, #7",
        "b 2f",
        "1:",
        "subs r6, #126",
        "lsls r3, r2, #24",
        "lsrs r2, r2, #8",
        "2:",
        // r3: the bits below, left-aligned; the product's low half sticky.
        "cmp r4, #0",
        "beq 3f",
        "adds r3, #1",
        "3:",
        "lsls r3, r3, #1",
        "bcc 5f",
        "bne 4f",
        "lsrs r4, r2, #1",
        "bcc 5f",
        "4:",
        "adds r2, #1",
        "lsrs r4, r2, #24",
        "beq 5f",
        "lsrs r2, r2, #1",
        "adds r6, #1",
        "5:",
        // A normal result only.
        "subs r4, r6, #1",
        "cmp r4, #253",
        "bhi 90f",
        "lsls r2, r2, #9",
        "lsrs r2, r2, #9",
        "lsls r6, r6, #23",
        "orrs r2, r6",
        "orrs r2, r5",
        "movs r0, r2",
        "pop {{r4, r5, r6, pc}}",
        // A zero times a finite number: a zero of the product's sign.
        "80:",
        "lsls r4, r0, #1",
        "bne 90f",
        "cmp r3, #255",
        "beq 90f",
        "b 82f",
        "81:",
        "lsls r4, r1, #1",
        "bne 90f",
        "82:",
        "eors r0, r1",
        "lsrs r0, r0, #31",
        "lsls r0, r0, #31",
        "pop {{r4, r5, r6, pc}}",
        "90:",
        "mov r0, r12",
        "mov r1, lr",
        "bl __mulsf3",
        "pop {{r4, r5, r6, pc}}",
        ".size __aeabi_fmul, . - __aeabi_fmul",
        // ---- a - b: a + (-b) ----
        ".balign 2",
        ".global __aeabi_fsub",
        ".type __aeabi_fsub,%function",
        ".thumb_func",
        "__aeabi_fsub:",
        "movs r2, #1",
        "lsls r2, r2, #31",
        "eors r1, r2",
        ".size __aeabi_fsub, . - __aeabi_fsub",
        // ---- a + b (falls through from the subtraction) ----
        ".global __aeabi_fadd",
        ".type __aeabi_fadd,%function",
        ".thumb_func",
        "__aeabi_fadd:",
        "push {{r3, r4, r5, r6, r7, lr}}",
        "mov r12, r0",
        "mov lr, r1",
        // The larger magnitude in r0 (its sign is the sum's).
        "lsls r2, r0, #1",
        "lsls r3, r1, #1",
        "cmp r2, r3",
        "bhs 1f",
        "movs r4, r0",
        "movs r0, r1",
        "movs r1, r4",
        "movs r4, r2",
        "movs r2, r3",
        "movs r3, r4",
        "1:",
        "lsrs r4, r2, #24",
        "lsrs r5, r3, #24",
        "subs r6, r4, #1",
        "cmp r6, #253",
        "bls 11f",
        // Two zeros: +0 unless both are -0 (the words' AND).
        "cmp r2, #0",
        "bne 90f",
        "mov r0, r12",
        "mov r1, lr",
        "ands r0, r1",
        "pop {{r3, r4, r5, r6, r7, pc}}",
        "11:",
        // The smaller is finite; a zero leaves the larger, a subnormal
        // goes to the full routine.
        "subs r6, r5, #1",
        "cmp r6, #253",
        "bls 2f",
        "cmp r3, #0",
        "bne 90f",
        "pop {{r3, r4, r5, r6, r7, pc}}",
        "2:",
        // The significands with three bits below (27 bits).
        "movs r7, #1",
        "lsls r7, r7, #26",
        "lsls r2, r0, #9",
        "lsrs r2, r2, #6",
        "orrs r2, r7",
        "lsls r3, r1, #9",
        "lsrs r3, r3, #6",
        "orrs r3, r7",
        // The smaller aligned, what is shifted out a sticky bit.
        "subs r5, r4, r5",
        "beq 4f",
        "cmp r5, #27",
        "bhs 3f",
        "movs r6, #32",
        "subs r6, r6, r5",
        "movs r7, r3",
        "lsls r7, r6",
        "lsrs r3, r5",
        "cmp r7, #0",
        "beq 4f",
        "movs r7, #1",
        "orrs r3, r7",
        "b 4f",
        "3:",
        "movs r3, #1",
        "4:",
        "movs r6, r0",
        "eors r6, r1",
        "bmi 6f",
        // Same signs: the sum, one bit right on a carry (sticky kept).
        "adds r2, r2, r3",
        "lsrs r6, r2, #27",
        "beq 7f",
        "movs r6, #1",
        "ands r6, r2",
        "lsrs r2, r2, #1",
        "orrs r2, r6",
        "adds r4, #1",
        "b 7f",
        // Opposite signs: the difference, renormalised; an exact zero is +0.
        "6:",
        "subs r2, r2, r3",
        "beq 8f",
        "lsrs r6, r2, #26",
        "bne 7f",
        "5:",
        "lsls r2, r2, #1",
        "subs r4, #1",
        "lsrs r6, r2, #26",
        "beq 5b",
        "cmp r4, #0",
        "ble 90f",
        // Round to nearest, ties to even.
        "7:",
        "movs r6, #7",
        "ands r6, r2",
        "lsrs r2, r2, #3",
        "cmp r6, #4",
        "blo 9f",
        "bhi 10f",
        "lsrs r6, r2, #1",
        "bcc 9f",
        "10:",
        "adds r2, #1",
        "lsrs r6, r2, #24",
        "beq 9f",
        "lsrs r2, r2, #1",
        "adds r4, #1",
        "9:",
        "cmp r4, #254",
        "bhi 90f",
        "lsls r2, r2, #9",
        "lsrs r2, r2, #9",
        "lsls r4, r4, #23",
        "orrs r2, r4",
        "lsrs r0, r0, #31",
        "lsls r0, r0, #31",
        "orrs r0, r2",
        "pop {{r3, r4, r5, r6, r7, pc}}",
        "8:",
        "movs r0, #0",
        "pop {{r3, r4, r5, r6, r7, pc}}",
        "90:",
        "mov r0, r12",
        "mov r1, lr",
        "bl __addsf3",
        "pop {{r3, r4, r5, r6, r7, pc}}",
        ".size __aeabi_fadd, . - __aeabi_fadd",
    );
}

/// The fast paths this core links against `compiler_builtins`' full
/// routines on `cases` operand pairs of every magnitude (a few within a
/// binade of each other, for the cancelling sums): what a Cortex-M0 image
/// runs at start-up. `Ok` on the other cores, which link the full
/// routines only.
pub fn self_check(cases: u32) -> Result<(), Mismatch> {
    #[cfg(all(target_arch = "arm", target_os = "none", not(target_has_atomic = "32")))]
    {
        // Zeros, the smallest and largest normals, a subnormal, the
        // infinities and a NaN, each with each, then random pairs.
        const EDGES: [u32; 12] = [
            0,
            0x8000_0000,
            0x0000_0001,
            0x0080_0000,
            0x3F80_0000,
            0xBF80_0001,
            0x7F7F_FFFF,
            0xFF7F_FFFF,
            0x7F80_0000,
            0xFF80_0000,
            0x7FC0_0000,
            0x3F7F_FFFF,
        ];
        let edges = EDGES.len() as u32;
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        for k in 0..cases + edges * edges {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let (a, b) = if k < edges * edges {
                (EDGES[(k / edges) as usize], EDGES[(k % edges) as usize])
            } else if k % 4 == 0 {
                // Within a binade or two of `a`, either sign.
                let a = s as u32;
                let b = (a & 0xFF80_0000).wrapping_sub(1 << 23)
                    ^ (((s >> 32) as u32) >> 9)
                    ^ (((s >> 40) as u32) & 0x8000_0000);
                (a, b)
            } else {
                (s as u32, (s >> 32) as u32)
            };
            let (x, y) = (f32::from_bits(a), f32::from_bits(b));
            let pairs = [
                // SAFETY: plain functions of two floats.
                ("mul", unsafe { v6m::__aeabi_fmul(x, y) }, unsafe {
                    v6m::__mulsf3(x, y)
                }),
                ("add", unsafe { v6m::__aeabi_fadd(x, y) }, unsafe {
                    v6m::__addsf3(x, y)
                }),
                ("sub", unsafe { v6m::__aeabi_fsub(x, y) }, unsafe {
                    v6m::__subsf3(x, y)
                }),
            ];
            for (operation, got, want) in pairs {
                // NaNs compare as NaNs (their payloads are the routines').
                if got.to_bits() != want.to_bits() && !(got.is_nan() && want.is_nan()) {
                    return Err(Mismatch {
                        operation,
                        operands: (a, b),
                        got: got.to_bits(),
                        want: want.to_bits(),
                    });
                }
            }
        }
    }
    let _ = cases;
    Ok(())
}
