//! Building the firmware images, the on-target tests, and the QEMU
//! output snapshots.

use crate::process;
use crate::toolchain::Toolchain;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Cortex-M4F (STM32F405, QEMU netduinoplus2).
pub const M4: &str = "thumbv7em-none-eabihf";
/// Cortex-M3 (QEMU netduino2): the fixed-point benchmark.
pub const M3: &str = "thumbv7m-none-eabi";
/// Every target the project builds for.
pub const TARGETS: [&str; 2] = [M4, M3];

/// One firmware image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Image {
    /// Binary name.
    pub bin: &'static str,
    /// Target triple.
    pub target: &'static str,
    /// Cargo features.
    pub features: &'static str,
}

impl Image {
    /// The QEMU twin: replays temperature profiles through the estimator.
    pub const TWIN: Image = Image {
        bin: "twin",
        target: M4,
        features: "qemu",
    };
    /// The benchmark on the Cortex-M4F (f32).
    pub const BENCH_M4: Image = Image {
        bin: "bench",
        target: M4,
        features: "qemu",
    };
    /// The benchmark on the Cortex-M3 (fixed point).
    pub const BENCH_M3: Image = Image {
        bin: "bench",
        target: M3,
        features: "qemu",
    };
    /// The real board's firmware (STM32F405, MAX31865, RTT).
    pub const BOARD: Image = Image {
        bin: "board",
        target: M4,
        features: "board",
    };
    /// All images.
    pub const ALL: [Image; 4] = [Image::TWIN, Image::BENCH_M4, Image::BENCH_M3, Image::BOARD];
}

/// Where firmware builds go (separate from host builds, which use another
/// compiler on the Debian route).
pub fn target_dir(root: &Path) -> PathBuf {
    root.join("target/firmware")
}

/// Builds `image` in release; returns the ELF's path.
pub fn build(tc: &Toolchain, root: &Path, image: &Image, params: Option<&Path>) -> Result<PathBuf, String> {
    let mut cmd = tc.cargo();
    cmd.current_dir(root)
        .args([
            "build",
            "--release",
            "--quiet",
            "--package",
            "compensator",
            "--bin",
            image.bin,
        ])
        .args([
            "--target",
            image.target,
            "--no-default-features",
            "--features",
            image.features,
        ])
        .arg("--target-dir")
        .arg(target_dir(root))
        .args(tc.build_args());
    if let Some(p) = params {
        cmd.env("COMPENSATOR_PARAMS", p);
    }
    if process::run(&mut cmd, Duration::from_secs(1200)) != Some(0) {
        return Err(format!("building {} for {} failed", image.bin, image.target));
    }
    Ok(target_dir(root).join(image.target).join("release").join(image.bin))
}

/// Builds every image with the given toolchain.
pub fn build_all_with(tc: &Toolchain, root: &Path) -> Result<Vec<(Image, PathBuf)>, String> {
    Image::ALL
        .iter()
        .map(|img| {
            eprintln!(
                "xtask: building {} ({}, features {})",
                img.bin, img.target, img.features
            );
            build(tc, root, img, None).map(|p| (*img, p))
        })
        .collect()
}

/// `cargo xtask build`.
pub fn build_all(root: &Path) -> Result<(), String> {
    let tc = crate::toolchain::get(root, &TARGETS)?;
    eprintln!("xtask: toolchain: {}", tc.description);
    for (img, path) in build_all_with(&tc, root)? {
        println!("{} ({}): {}", img.bin, img.target, path.display());
    }
    Ok(())
}

/// Compares decoded QEMU output, without its `[measure]` lines, with
/// `tests/snapshots/<name>.log` (`--bless` rewrites it).
pub fn check_snapshot(root: &Path, name: &str, lines: &[String], bless: bool) -> Result<(), String> {
    let path = root.join("tests/snapshots").join(format!("{name}.log"));
    // Measurements (stack, costs) are checked against budgets, not frozen:
    // they move with every code change.
    let lines: Vec<String> = lines.iter().filter(|l| !l.contains("[measure]")).cloned().collect();
    let lines = &lines[..];
    let actual = lines.join("\n") + "\n";
    if bless {
        std::fs::create_dir_all(path.parent().expect("has a parent")).map_err(|e| e.to_string())?;
        std::fs::write(&path, &actual).map_err(|e| e.to_string())?;
        eprintln!("xtask: wrote {}", path.display());
        return Ok(());
    }
    let expected = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: {e} (run `cargo xtask test --bless`)", path.display()))?;
    if expected == actual {
        eprintln!("xtask: {} lines match {}", lines.len(), path.display());
        return Ok(());
    }
    let exp: Vec<&str> = expected.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        if exp.get(i) != Some(&line.as_str()) {
            return Err(format!(
                "QEMU output differs from {} at line {}:\n  expected: {}\n  actual:   {}\n(if the change is intended: cargo xtask test --bless)",
                path.display(),
                i + 1,
                exp.get(i).unwrap_or(&"<end of file>"),
                line
            ));
        }
    }
    Err(format!(
        "QEMU output has {} lines, {} expects {}",
        lines.len(),
        path.display(),
        exp.len()
    ))
}

/// Runs the core's tests (`tests/on_target.rs`, defmt-test) on the
/// emulated Cortex-M4F, with this xtask as the cargo runner.
pub fn on_target_tests(tc: &Toolchain, root: &Path) -> Result<(), String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let runner = format!("{} qemu-runner", exe.display());
    let mut cmd = tc.cargo();
    cmd.current_dir(root)
        .args(["test", "--release", "--package", "compensator", "--test", "on_target"])
        .args(["--target", M4, "--no-default-features", "--features", "qemu"])
        .arg("--target-dir")
        .arg(target_dir(root))
        .args(tc.build_args())
        .env("CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUNNER", runner);
    if process::run(&mut cmd, Duration::from_secs(1200)) == Some(0) {
        Ok(())
    } else {
        Err("on-target tests failed".into())
    }
}
