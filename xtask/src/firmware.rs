//! Building the firmware images, the on-target tests, and the QEMU
//! output snapshots.

use crate::process;
use crate::toolchain::Toolchain;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Cortex-M4F (STM32F405, QEMU netduinoplus2).
pub const M4: &str = "thumbv7em-none-eabihf";
/// Cortex-M3 (QEMU netduino2): no FPU, hardware divide and long multiply.
pub const M3: &str = "thumbv7m-none-eabi";
/// Cortex-M0/M0+ (QEMU microbit, nRF51): no FPU, no divide, no long
/// multiply.
pub const M0: &str = "thumbv6m-none-eabi";
/// Every target the project builds for.
pub const TARGETS: [&str; 3] = [M4, M3, M0];

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
    /// The benchmark on the Cortex-M3 (fixed point and soft-float `f32`).
    pub const BENCH_M3: Image = Image {
        bin: "bench",
        target: M3,
        features: "qemu",
    };
    /// The benchmark on the Cortex-M0 (fixed point and soft-float `f32`).
    pub const BENCH_M0: Image = Image {
        bin: "bench",
        target: M0,
        features: "qemu",
    };
    /// The QEMU twin on the Cortex-M3 (netduino2): the whole estimator
    /// with a Q12.20 twin, the replay and its self-checks.
    pub const TWIN_M3: Image = Image {
        bin: "twin",
        target: M3,
        features: "qemu",
    };
    /// The QEMU twin on the Cortex-M0 (microbit, 16 KiB RAM): the whole
    /// estimator with a Q12.20 twin, the replay and its self-checks.
    pub const TWIN_M0: Image = Image {
        bin: "twin",
        target: M0,
        features: "qemu",
    };
    /// The real board's firmware (STM32F405, MAX31865, RTT).
    pub const BOARD: Image = Image {
        bin: "board",
        target: M4,
        features: "board",
    };
    /// A deliberate HardFault on QEMU (the fault handler's test).
    pub const FAULT: Image = Image {
        bin: "fault",
        target: M4,
        features: "qemu",
    };
    /// The soak on QEMU: a seeded temperature walk with injected sensor
    /// faults through the estimator, every tick checked (`docs/soak.md`).
    pub const SOAK: Image = Image {
        bin: "soak",
        target: M4,
        features: "qemu",
    };
    /// The images a parameter file goes into.
    pub const ALL: [Image; 8] = [
        Image::TWIN,
        Image::TWIN_M3,
        Image::TWIN_M0,
        Image::BENCH_M4,
        Image::BENCH_M3,
        Image::BENCH_M0,
        Image::BOARD,
        Image::SOAK,
    ];

    /// The emulated board the image runs on.
    pub fn machine(&self) -> crate::qemu::Machine {
        crate::qemu::machine(self.target)
    }
}

/// Where firmware builds go (separate from host builds, which use another
/// compiler on the Debian route).
pub fn target_dir(root: &Path) -> PathBuf {
    root.join("target/firmware")
}

/// How an image is built.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options<'a> {
    /// The parameter file (absolute; `None`: `presets/paper.toml`, or the
    /// `COMPENSATOR_PARAMS` xtask resolved and checked).
    pub params: Option<&'a Path>,
    /// The dev profile (debug assertions: the board keeps its debug port
    /// clocked in sleep) instead of release.
    pub debug: bool,
}

/// A built image.
#[derive(Clone, Debug)]
pub struct Built {
    /// The ELF.
    pub elf: PathBuf,
    /// The build script's output directory of the `compensator-firmware` package
    /// (for the QEMU twin: its replay schedule, `replay.txt`).
    pub out_dir: Option<PathBuf>,
}

/// Builds `image` in release; returns the ELF's path.
pub fn build(tc: &Toolchain, root: &Path, image: &Image, params: Option<&Path>) -> Result<PathBuf, String> {
    build_with(tc, root, image, Options { params, debug: false }).map(|b| b.elf)
}

/// Whether the parameter file names the condition monitor's second sensor
/// (`None`: the paper preset, which does not; a file that cannot be read
/// is left to the build script to refuse, naming its field).
pub fn names_second_sensor(params: Option<&Path>) -> bool {
    params.is_some_and(|p| compensator_params::file::load(p).is_ok_and(|raw| raw.monitor.has_sensor()))
}

/// The cargo features of `image` built for `params`: its own, and the
/// firmware's `monitor` when the file names a second sensor (the build
/// script requires it then, and refuses it otherwise).
pub fn features(image: &Image, params: Option<&Path>) -> String {
    if names_second_sensor(params) {
        format!("{},monitor", image.features)
    } else {
        image.features.to_string()
    }
}

/// Builds `image` (only it: `--package compensator-firmware --bin ...`, no host
/// crate of the workspace), with the `monitor` feature for a file that
/// names a second sensor ([`features`]); returns the ELF and the build
/// script's output directory.
pub fn build_with(tc: &Toolchain, root: &Path, image: &Image, options: Options<'_>) -> Result<Built, String> {
    let mut cmd = tc.cargo();
    cmd.current_dir(root).args([
        "build",
        "--quiet",
        "--package",
        "compensator-firmware",
        "--bin",
        image.bin,
    ]);
    if !options.debug {
        cmd.arg("--release");
    }
    cmd.args([
        "--target",
        image.target,
        "--no-default-features",
        "--features",
        &features(image, options.params),
        "--message-format=json-render-diagnostics",
    ])
    .arg("--target-dir")
    .arg(target_dir(root))
    .args(tc.build_args());
    match options.params {
        Some(p) => {
            cmd.env("COMPENSATOR_PARAMS", p);
        }
        None => {
            // Resolved by xtask against the user's directory; never left for
            // the build script to guess.
            cmd.env_remove("COMPENSATOR_PARAMS");
        }
    }
    let out = process::capture_stdout(&mut cmd, Duration::from_secs(1200));
    if !out.ok() {
        return Err(format!("building {} for {} failed", image.bin, image.target));
    }
    let (elf, out_dir) = artifacts(&out.stdout, image.bin);
    let profile = if options.debug { "debug" } else { "release" };
    Ok(Built {
        elf: elf.unwrap_or_else(|| target_dir(root).join(image.target).join(profile).join(image.bin)),
        out_dir,
    })
}

/// The executable named `bin` and the `compensator-firmware` build script's output
/// directory, from cargo's JSON messages.
fn artifacts(json_lines: &str, bin: &str) -> (Option<PathBuf>, Option<PathBuf>) {
    let (mut elf, mut out_dir) = (None, None);
    for line in json_lines.lines() {
        let Ok(v) = serde_json::from_str::<serde_json::Value>(line) else {
            continue;
        };
        let is_ours = v["package_id"]
            .as_str()
            .is_some_and(|id| id.contains("#compensator-firmware@") || id.starts_with("compensator-firmware "));
        match v["reason"].as_str() {
            Some("build-script-executed") if is_ours => {
                out_dir = v["out_dir"].as_str().map(PathBuf::from);
            }
            Some("compiler-artifact") if v["target"]["name"].as_str() == Some(bin) => {
                if let Some(e) = v["executable"].as_str() {
                    elf = Some(PathBuf::from(e));
                }
            }
            _ => {}
        }
    }
    (elf, out_dir)
}

/// Builds every image with the given toolchain.
pub fn build_all_with(tc: &Toolchain, root: &Path) -> Result<Vec<(Image, PathBuf)>, String> {
    build_all_params(tc, root, None)
}

/// Builds every image with the parameter file `params`.
pub fn build_all_params(tc: &Toolchain, root: &Path, params: Option<&Path>) -> Result<Vec<(Image, PathBuf)>, String> {
    Image::ALL
        .iter()
        .map(|img| {
            eprintln!(
                "xtask: building {} ({}, features {})",
                img.bin,
                img.target,
                features(img, params)
            );
            build(tc, root, img, params).map(|p| (*img, p))
        })
        .collect()
}

/// `cargo xtask build`: every image, with the parameter file resolved and
/// checked by the caller.
pub fn build_all(root: &Path, params: Option<&Path>) -> Result<(), String> {
    let tc = crate::toolchain::get(root, &TARGETS)?;
    eprintln!("xtask: toolchain: {}", tc.description);
    for (img, path) in build_all_params(&tc, root, params)? {
        println!("{} ({}): {}", img.bin, img.target, path.display());
    }
    Ok(())
}

/// A parameter file the CLI refuses (a PT1000 on the 430 ohm board) fails a
/// plain `cargo build` of the board image, run from `presets/` with the
/// file's path relative to there, with one line naming the field and no
/// panic: the build script's contract, for users who build without xtask.
/// So does a file that names a second sensor built without the firmware's
/// `monitor` feature, naming `monitor.sensor`.
pub fn check_refused_file(tc: &Toolchain, root: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let file = root.join("target/xtask/pt1000-on-430-ohm.toml");
    std::fs::create_dir_all(file.parent().expect("has a parent")).map_err(|e| e.to_string())?;
    std::fs::write(&file, format!("{text}\n[estimator]\nrtd_r0 = 1000\n")).map_err(|e| e.to_string())?;
    let presets = root.join("presets");
    let mut cmd = tc.cargo();
    cmd.current_dir(&presets)
        // What a shell sets: the directory the user typed the command in.
        .env("PWD", &presets)
        .env("COMPENSATOR_PARAMS", "../target/xtask/pt1000-on-430-ohm.toml")
        .args([
            "build",
            "--quiet",
            "--release",
            "--package",
            "compensator-firmware",
            "--bin",
            "board",
        ])
        .args(["--target", M4, "--no-default-features", "--features", "board"])
        .arg("--target-dir")
        .arg(target_dir(root))
        .args(tc.build_args());
    let out = process::capture(&mut cmd, Duration::from_secs(600));
    let naming: Vec<&str> = out
        .stderr
        .lines()
        .filter(|l| l.contains("estimator.rtd_reference"))
        .collect();
    let expected = format!("{}: estimator.rtd_reference = 430: must exceed", file.display());
    if out.code == Some(0) || naming.len() != 1 || !naming[0].contains(&expected) || out.stderr.contains("panicked") {
        return Err(format!(
            "a refused parameter file should fail the build with one line naming estimator.rtd_reference; cargo said (exit {:?}):\n{}",
            out.code, out.stderr
        ));
    }
    eprintln!("xtask: {}", naming[0].trim());
    // A file that names a second sensor, built without the monitor (a
    // plain `cargo build --features board`): refused naming monitor.sensor,
    // never an image that ignores the sensor.
    let mut cmd = tc.cargo();
    cmd.current_dir(root)
        .env("COMPENSATOR_PARAMS", root.join("presets/paper-monitor.toml"))
        .args([
            "build",
            "--quiet",
            "--release",
            "--package",
            "compensator-firmware",
            "--bin",
            "board",
        ])
        .args(["--target", M4, "--no-default-features", "--features", "board"])
        .arg("--target-dir")
        .arg(target_dir(root))
        .args(tc.build_args());
    let out = process::capture(&mut cmd, Duration::from_secs(600));
    let naming: Vec<&str> = out.stderr.lines().filter(|l| l.contains("monitor.sensor")).collect();
    if out.code == Some(0) || naming.len() != 1 || !naming[0].contains("`monitor` feature") {
        return Err(format!(
            "a file naming a second sensor, built without the monitor, should fail in one line naming monitor.sensor; cargo said (exit {:?}):\n{}",
            out.code, out.stderr
        ));
    }
    eprintln!("xtask: {}", naming[0].trim());
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
        .args([
            "test",
            "--release",
            "--package",
            "compensator-firmware",
            "--test",
            "on_target",
        ])
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

#[cfg(test)]
mod tests {
    use super::TARGETS;

    #[test]
    fn rust_toolchain_toml_names_every_firmware_target() {
        // rustup installs what the file names: the targets xtask builds for.
        let text = std::fs::read_to_string(crate::root().join("rust-toolchain.toml")).unwrap();
        let targets = text.lines().find(|l| l.starts_with("targets")).unwrap();
        for t in TARGETS {
            assert!(targets.contains(&format!("\"{t}\"")), "{t} missing from {targets}");
        }
        assert!(text.contains("channel = \"stable\""));
    }
}
