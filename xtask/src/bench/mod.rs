//! `cargo xtask bench`: cost, footprint and stack of the firmware on the
//! emulated microcontrollers, and the budget check CI runs.
//!
//! * Instructions: the `bench` image runs under `qemu -icount shift=0`
//!   (one nanosecond of emulated time per instruction) and reports SysTick
//!   counts; its calibration loop of known length converts them (0.168
//!   counts per instruction on the netduinoplus2 STM32F405, 0.120 on the
//!   netduino2 STM32F205). Deterministic: the same image gives the same
//!   numbers on every run and machine.
//! * Flash and static RAM: the ELF sections of the images (`.vector_table`,
//!   `.text`, `.rodata`, `.data` in flash; `.data`, `.bss`, `.uninit` in RAM).
//! * Stack: the QEMU twin measures its own peak by stack painting.
//!
//! Here the images are run and the commands put together; [`measure`]
//! reads the images' `[measure]` lines, [`footprint`] their ELF sections,
//! [`budgets`] checks the results, [`report`] writes the Markdown, and
//! `accuracy` (`host` feature) simulates the measured configurations on
//! the host.

#[cfg(feature = "host")]
mod accuracy;
mod budgets;
mod footprint;
mod measure;
mod report;

use crate::firmware::Image;
use crate::qemu;
use budgets::Budget;
use footprint::{Footprint, footprint};
use measure::{Costs, stack_peak};
use std::path::{Path, PathBuf};
use std::time::Duration;

fn run_image(elf: &Path, machine: qemu::Machine) -> Result<Vec<String>, String> {
    let run = qemu::run(elf, machine, true, Duration::from_secs(600), qemu::Show::Quiet)?;
    if run.code != 0 {
        return Err(format!("{} exited with {}", elf.display(), run.code));
    }
    Ok(run.lines)
}

/// What the firmware images measured on QEMU.
pub struct Firmware {
    /// The bench image on the netduinoplus2 (Cortex-M4F).
    m4: Costs,
    /// The bench image on the netduino2 (Cortex-M3).
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    m3: Costs,
    /// Peak stack of the QEMU twin run [bytes].
    stack: u64,
    /// The board image's, then the QEMU twin image's.
    footprints: Vec<Footprint>,
}

/// Runs the bench images on QEMU and reads the footprints. `twin_lines`:
/// the output of a twin run already made (the snapshot check), else the
/// twin is run here for its stack peak.
pub fn measure_firmware(elfs: &[(Image, PathBuf)], twin_lines: Option<&[String]>) -> Result<Firmware, String> {
    let find = |img: Image| {
        elfs.iter()
            .find(|(i, _)| *i == img)
            .map(|(_, p)| p.clone())
            .ok_or_else(|| format!("missing image {}", img.bin))
    };
    let m4 = Costs::parse(&run_image(&find(Image::BENCH_M4)?, qemu::NETDUINO)?)?;
    let m3 = Costs::parse(&run_image(&find(Image::BENCH_M3)?, qemu::NETDUINO2)?)?;
    let stack = match twin_lines {
        Some(lines) => stack_peak(lines),
        None => stack_peak(&run_image(&find(Image::TWIN)?, qemu::NETDUINO)?),
    }
    .ok_or("the twin reported no stack peak")?;
    let mut footprints = Vec::new();
    for (img, label) in [(Image::BOARD, "board image"), (Image::TWIN, "QEMU twin image")] {
        footprints.push(footprint(label, &find(img)?)?);
    }
    Ok(Firmware {
        m4,
        m3,
        stack,
        footprints,
    })
}

/// `cargo xtask bench [--params F] [--write]` (the accuracy table needs
/// the `host` feature; `main` re-runs xtask with it): the images built for
/// `params` (resolved and checked by `main`; `None`: the paper preset), the
/// budget table with the twin configuration the build chose for it, written
/// to `docs/bench.md` with `write`.
#[cfg(feature = "host")]
pub fn cmd(root: &Path, params: Option<&Path>, write: bool) -> Result<i32, String> {
    let tc = crate::toolchain::get(root, &crate::firmware::TARGETS)?;
    eprintln!("xtask: toolchain: {}", tc.description);
    qemu::ensure()?;
    let elfs = crate::firmware::build_all_params(&tc, root, params)?;
    let fw = measure_firmware(&elfs, None)?;
    let budget = Budget::of(&fw)?;
    let accuracy = accuracy::points(&fw.m4.configs())?;
    let text = report::document(&fw, &budget, &accuracy);
    print!("{text}");
    if write {
        let path = root.join("docs/bench.md");
        std::fs::write(&path, &text).map_err(|e| e.to_string())?;
        eprintln!("xtask: wrote {}", path.display());
    }
    for o in &budget.over {
        eprintln!("xtask: over budget: {o}");
    }
    Ok(if budget.over.is_empty() { 0 } else { 1 })
}

/// The budget check of `cargo xtask test` (firmware measurements only; the
/// accuracy tables are `cargo xtask bench`'s). `twin_lines`: the output of
/// the snapshot run, for the stack peak.
pub fn check(elfs: &[(Image, PathBuf)], twin_lines: &[String]) -> Result<(), String> {
    let fw = measure_firmware(elfs, Some(twin_lines))?;
    let budget = Budget::of(&fw)?;
    eprint!("{}", report::budget_table(&fw, &budget));
    if budget.over.is_empty() {
        eprintln!("xtask: every budget met");
        Ok(())
    } else {
        Err(format!("over budget: {}", budget.over.join("; ")))
    }
}
