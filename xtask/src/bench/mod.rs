//! `cargo xtask bench`: cost, footprint and stack of the firmware on the
//! emulated microcontrollers, and the budget check CI runs.
//!
//! * Instructions: the `bench` image runs under `qemu -icount shift=0`
//!   (one nanosecond of emulated time per instruction) and reports SysTick
//!   counts; its calibration loop of known length converts them (0.168
//!   counts per instruction on the netduinoplus2 STM32F405, 0.120 on the
//!   netduino2 STM32F205, 0.016 on the microbit nRF51, whose 16 MHz
//!   SysTick makes one count 62.5 instructions: its per-tick worst cases
//!   are resolved to that). Deterministic: the same image gives the same
//!   numbers on every run and machine.
//! * Flash and static RAM: the ELF sections of the images (`.vector_table`,
//!   `.text`, `.rodata`, `.data` in flash; `.data`, `.bss`, `.uninit` in RAM).
//! * Stack: each core's QEMU twin measures its own peak by stack painting.
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
    m3: Costs,
    /// The bench image on the microbit (Cortex-M0).
    m0: Costs,
    /// Peak stack of the QEMU twin run on the Cortex-M4F [bytes].
    stack: u64,
    /// Peak stack of the twin runs on the Cortex-M3 and the Cortex-M0 [bytes].
    fixed_stacks: [u64; 2],
    /// The board image's, the QEMU twin image's, then the Cortex-M3 and
    /// Cortex-M0 twin images'.
    footprints: Vec<Footprint>,
    /// The images built with the condition monitor: their bench on the
    /// Cortex-M4F and their board image (`None`: not measured).
    pub monitor: Option<Monitored>,
    /// Cycles per instruction of the estimator's tick on the Cortex-M4F,
    /// M3 and M0, lower and upper (`profile::cycles_per_instruction`;
    /// `None` where not measured).
    #[cfg_attr(not(feature = "host"), allow(dead_code, reason = "read by the host-only report"))]
    cpi: Option<[(f64, f64); 3]>,
}

/// What the images built with the condition monitor measured.
pub struct Monitored {
    /// The device file they were built for (file name).
    pub params: String,
    /// The Cortex-M4F bench image's costs (its `monitor=true` rows and
    /// `monitor-update-*` pieces).
    pub costs: Costs,
}

/// The device file the monitor's costs are measured with, unless the one
/// given names a second sensor itself.
pub const MONITOR_PRESET: &str = "presets/paper-monitor.toml";

/// The footprint label of the board image with the monitor.
pub const MONITOR_BOARD: &str = "board image with the monitor";

/// The images the monitor's costs need, built for `params` when it names
/// a second sensor, else for [`MONITOR_PRESET`]: the Cortex-M4F bench and
/// the board, copied under `target/xtask/monitor/` (a build for another
/// file writes the same paths). Build them after the other images have
/// been measured or copied, or before they are built.
pub fn monitor_images(
    tc: &crate::toolchain::Toolchain,
    root: &Path,
    params: Option<&Path>,
) -> Result<(PathBuf, Vec<(Image, PathBuf)>), String> {
    let file = match params {
        Some(p) if crate::firmware::names_second_sensor(Some(p)) => p.to_path_buf(),
        _ => root.join(MONITOR_PRESET),
    };
    let mut elfs = Vec::new();
    for img in [Image::BENCH_M4, Image::BOARD] {
        eprintln!(
            "xtask: building {} ({}, features {}) for {}",
            img.bin,
            img.target,
            crate::firmware::features(&img, Some(&file)),
            file.display()
        );
        let built = crate::firmware::build(tc, root, &img, Some(&file))?;
        // Kept apart: the next build of the image for another file writes
        // the same path (the plain images' footprints and benches must not
        // read these).
        let kept = root.join(format!("target/xtask/monitor/{}/{}", img.target, img.bin));
        std::fs::create_dir_all(kept.parent().expect("has a parent")).map_err(|e| e.to_string())?;
        std::fs::copy(&built, &kept).map_err(|e| format!("{}: {e}", kept.display()))?;
        elfs.push((img, kept));
    }
    Ok((file, elfs))
}

/// The footprint label of the Cortex-M3 twin image.
pub const M3_TWIN: &str = "Cortex-M3 twin image";
/// The footprint label of the Cortex-M4F QEMU twin image.
pub const QEMU_TWIN: &str = "QEMU twin image";
/// The footprint label of the Cortex-M0 twin image.
pub const M0_TWIN: &str = "Cortex-M0 twin image";

/// Runs the bench images on QEMU and reads the footprints. `twin_runs`:
/// the output of twin runs already made (the snapshot check, the fixed-point
/// cores' replays), else each twin is run here for its stack peak.
pub fn measure_firmware(
    elfs: &[(Image, PathBuf)],
    twin_runs: &[(Image, Vec<String>)],
    monitor: Option<&(PathBuf, Vec<(Image, PathBuf)>)>,
) -> Result<Firmware, String> {
    let find = |img: Image| {
        elfs.iter()
            .find(|(i, _)| *i == img)
            .map(|(_, p)| p.clone())
            .ok_or_else(|| format!("missing image {} ({})", img.bin, img.target))
    };
    let bench = |img: Image| -> Result<Costs, String> { Costs::parse(&run_image(&find(img)?, img.machine())?) };
    let (m4, m3, m0) = (
        bench(Image::BENCH_M4)?,
        bench(Image::BENCH_M3)?,
        bench(Image::BENCH_M0)?,
    );
    let peak = |img: Image| -> Result<u64, String> {
        match twin_runs.iter().find(|(i, _)| *i == img) {
            Some((_, lines)) => stack_peak(lines),
            None => stack_peak(&run_image(&find(img)?, img.machine())?),
        }
        .ok_or_else(|| format!("the twin on {} reported no stack peak", img.target))
    };
    let stack = peak(Image::TWIN)?;
    let fixed_stacks = [peak(Image::TWIN_M3)?, peak(Image::TWIN_M0)?];
    let mut footprints = Vec::new();
    for (img, label) in [
        (Image::BOARD, "board image"),
        (Image::TWIN, QEMU_TWIN),
        (Image::TWIN_M3, M3_TWIN),
        (Image::TWIN_M0, M0_TWIN),
    ] {
        footprints.push(footprint(label, &find(img)?)?);
    }
    let monitor = match monitor {
        Some((file, elfs)) => {
            let elf = |img: Image| {
                elfs.iter()
                    .find(|(i, _)| *i == img)
                    .map(|(_, p)| p.clone())
                    .ok_or_else(|| format!("missing the monitor's image {} ({})", img.bin, img.target))
            };
            let costs = Costs::parse(&run_image(&elf(Image::BENCH_M4)?, Image::BENCH_M4.machine())?)?;
            footprints.push(footprint(MONITOR_BOARD, &elf(Image::BOARD)?)?);
            Some(Monitored {
                params: file
                    .file_name()
                    .map(|f| f.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                costs,
            })
        }
        None => None,
    };
    Ok(Firmware {
        m4,
        m3,
        m0,
        stack,
        fixed_stacks,
        footprints,
        monitor,
        cpi: None,
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
    // The monitor's images first: they are copied away, and the builds
    // after them write the plain images' paths again.
    let monitor = monitor_images(&tc, root, params)?;
    let elfs = crate::firmware::build_all_params(&tc, root, params)?;
    let mut fw = measure_firmware(&elfs, &[], Some(&monitor))?;
    let mut cpi = [(f64::NAN, f64::NAN); 3];
    for (c, target) in cpi
        .iter_mut()
        .zip([crate::firmware::M4, crate::firmware::M3, crate::firmware::M0])
    {
        *c = crate::profile::cycles_per_instruction(&tc, root, params, target)?;
    }
    fw.cpi = Some(cpi);
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
/// accuracy tables are `cargo xtask bench`'s). `twin_runs`: the output of
/// the twin runs made (the snapshot run, the fixed-point cores' replays),
/// for the stack peaks; `monitor`: the images built with the monitor
/// ([`monitor_images`]).
pub fn check(
    elfs: &[(Image, PathBuf)],
    twin_runs: &[(Image, Vec<String>)],
    monitor: &(PathBuf, Vec<(Image, PathBuf)>),
) -> Result<(), String> {
    let fw = measure_firmware(elfs, twin_runs, Some(monitor))?;
    let budget = Budget::of(&fw)?;
    eprint!("{}", report::budget_table(&fw, &budget));
    if budget.over.is_empty() {
        eprintln!("xtask: every budget met");
        Ok(())
    } else {
        Err(format!("over budget: {}", budget.over.join("; ")))
    }
}
