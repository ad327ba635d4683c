//! `cargo xtask`: the project's automation.
//!
//! ```text
//! cargo xtask run [--params F] [--csv FILE]      the twin firmware on QEMU (the main job)
//! cargo xtask flash [--params F] [--csv FILE] [--debug] [--seconds S]
//!                                                build the board image, flash it with probe-rs
//! cargo xtask test [--bless]                     everything CI checks (the test command)
//! cargo xtask build [--params F]                 build every firmware image
//! cargo xtask bench [--params F] [--write]       cost (the twin as built for F), footprint and stack on the emulated MCUs
//! cargo xtask callgrind [--bless]                host instruction counts against the baseline
//! cargo xtask msrv                               rust-version against the locked dependencies
//! cargo xtask toolchain                          find or provision the cross toolchain
//! cargo xtask qemu-runner ELF                    run an ELF on QEMU (cargo runner for on-target tests)
//! ```
//!
//! A parameter file (`--params`, or `COMPENSATOR_PARAMS`) is taken relative
//! to the directory the command is run in and checked before any build: a
//! refused file is one line naming the field, exit status 2, as with the
//! CLI.
//!
//! Without the `host` feature (the default: what `cargo xtask` builds),
//! xtask compiles none of the workspace's host-side crates (CLI, reference
//! ODE solver, host tests): `bench`, whose accuracy table needs them, runs
//! xtask again with `--features host` (`callgrind` runs the host bench as
//! its own process).

mod bench;
mod callgrind;
mod firmware;
mod flash;
mod msrv;
mod params;
mod process;
mod qemu;
mod replica;
mod telemetry;
mod toolchain;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

/// The workspace root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask sits in the workspace")
        .to_path_buf()
}

/// Why a command failed.
#[derive(Debug)]
enum Failure {
    /// Bad input (a parameter file, an argument): one line, exit 2.
    Input(String),
    /// Anything else: exit 1.
    Other(String),
}

impl From<String> for Failure {
    fn from(e: String) -> Self {
        Failure::Other(e)
    }
}

impl From<&str> for Failure {
    fn from(e: &str) -> Self {
        Failure::Other(e.to_string())
    }
}

type Outcome = Result<i32, Failure>;

fn usage() -> ExitCode {
    eprintln!(
        "usage: cargo xtask <command>\n\
         \n  run [--params F] [--csv FILE]   build the QEMU twin firmware and run it (the main job)\
         \n  flash [--params F] [--csv FILE] [--debug] [--seconds S]\
         \n                                  build the board image and run it with probe-rs (RTT log, CSV)\
         \n  test [--bless]                  every check CI runs (host tests, clippy, cross builds, QEMU)\
         \n  build [--params F]              build every firmware image\
         \n  bench [--params F] [--write]    instructions per tick (the twin as built for F), flash, RAM and stack\
         \n  callgrind [--bless]             host instruction counts (valgrind) against the baseline\
         \n  msrv                            the workspace's rust-version against the locked dependencies\
         \n  target-tests                    the core's tests on the emulated Cortex-M4F (defmt-test)\
         \n  toolchain                       find or provision the thumbv7em/thumbv7m toolchain\
         \n  qemu-runner ELF                 run an ELF on QEMU (netduinoplus2, or netduino2 for thumbv7m)\
         \n\
         \nA parameter file (--params or COMPENSATOR_PARAMS) is relative to the current directory."
    );
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rest = args.get(1..).unwrap_or_default();
    let result: Outcome = match args.first().map(String::as_str) {
        Some("run") => cmd_run(rest),
        Some("flash") => flash::cmd(&root(), rest),
        Some("test") => cmd_test(rest),
        Some("bench") => cmd_bench(&args),
        Some("build") => cmd_build(rest),
        Some("msrv") => msrv::check(&root()).map(|_| 0).map_err(Failure::from),
        Some("toolchain") => toolchain::get(&root(), &firmware::TARGETS)
            .map(|t| {
                println!("{}", t.description);
                0
            })
            .map_err(Failure::from),
        Some("qemu-runner") => cmd_qemu_runner(rest),
        Some("callgrind") => cmd_callgrind(&args),
        Some("target-tests") => toolchain::get(&root(), &[firmware::M4])
            .and_then(|tc| qemu::ensure().and_then(|_| firmware::on_target_tests(&tc, &root())))
            .map(|_| 0)
            .map_err(Failure::from),
        _ => return usage(),
    };
    match result {
        Ok(code) => ExitCode::from(code.clamp(0, 255) as u8),
        Err(Failure::Input(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Other(e)) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

fn flag_value(args: &[String], flag: &str) -> Result<Option<String>, Failure> {
    match args.iter().position(|a| a == flag) {
        None => Ok(None),
        Some(i) => args
            .get(i + 1)
            .filter(|v| !v.starts_with("--"))
            .cloned()
            .map(Some)
            .ok_or_else(|| Failure::Input(format!("{flag} needs a value"))),
    }
}

/// The parameter file of a build (`--params`, else `COMPENSATOR_PARAMS`),
/// resolved against the current directory and checked.
fn params_arg(args: &[String]) -> Result<Option<PathBuf>, Failure> {
    let flag = flag_value(args, "--params")?;
    params::from_args(flag.as_deref()).map_err(Failure::Input)
}

/// The main job: the twin firmware on QEMU's STM32F405, log decoded live
/// (telemetry rounded for reading; `--csv FILE`: every digit, SI units).
fn cmd_run(args: &[String]) -> Outcome {
    let root = root();
    let params = params_arg(args)?;
    let csv_path = flag_value(args, "--csv")?;
    // Created before the build: a path that cannot be written fails fast.
    let mut csv = match &csv_path {
        Some(p) => Some(telemetry::CsvFile::create(Path::new(p)).map_err(Failure::Input)?),
        None => None,
    };
    let tc = toolchain::get(&root, &[firmware::M4])?;
    eprintln!("xtask: toolchain: {}", tc.description);
    qemu::ensure()?;
    let elf = firmware::build(&tc, &root, &firmware::Image::TWIN, params.as_deref())?;
    eprintln!("xtask: running {} on QEMU {}", elf.display(), qemu::NETDUINO.name);
    let run = qemu::run(&elf, qemu::NETDUINO, true, Duration::from_secs(300), qemu::Show::Stream)?;
    if let (Some(csv), Some(p)) = (csv.as_mut(), &csv_path) {
        for line in &run.lines {
            csv.line(line)?;
        }
        eprintln!("xtask: wrote {} telemetry records to {p}", csv.rows);
    }
    eprintln!("xtask: firmware exit code {}", run.code);
    Ok(run.code)
}

/// `cargo xtask build [--params F]`.
fn cmd_build(args: &[String]) -> Outcome {
    let params = params_arg(args)?;
    firmware::build_all(&root(), params.as_deref())?;
    Ok(0)
}

/// cargo runner: `xtask qemu-runner ELF [args...]`.
fn cmd_qemu_runner(args: &[String]) -> Outcome {
    let elf = args.first().ok_or("qemu-runner needs an ELF")?;
    let machine = if elf.contains("thumbv7m-none-eabi") {
        qemu::NETDUINO2
    } else {
        qemu::NETDUINO
    };
    let run = qemu::run(
        Path::new(elf),
        machine,
        true,
        Duration::from_secs(300),
        qemu::Show::Stream,
    )?;
    Ok(run.code)
}

/// Runs this xtask again with the `host` feature (the commands that need
/// the host-side crates), with the same arguments.
#[cfg_attr(feature = "host", allow(dead_code))]
fn with_host_feature(args: &[String], timeout: Duration) -> Outcome {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = std::process::Command::new(cargo);
    cmd.args(["run", "--quiet", "--package", "xtask", "--features", "host", "--"])
        .args(args)
        .current_dir(root());
    process::run(&mut cmd, timeout)
        .ok_or_else(|| Failure::Other(format!("xtask --features host {} failed", args.join(" "))))
}

fn cmd_bench(args: &[String]) -> Outcome {
    #[cfg(feature = "host")]
    {
        Ok(bench::cmd(&root(), &args[1..])?)
    }
    #[cfg(not(feature = "host"))]
    {
        with_host_feature(args, Duration::from_secs(3600))
    }
}

fn cmd_callgrind(args: &[String]) -> Outcome {
    callgrind::check(&root(), args.iter().any(|a| a == "--bless"))?;
    Ok(0)
}

fn step(name: &str) {
    eprintln!("\n==> {name}");
}

fn host_cargo(root: &Path, args: &[&str], timeout: Duration) -> Result<(), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let code = process::run(std::process::Command::new(cargo).args(args).current_dir(root), timeout);
    if code == Some(0) {
        Ok(())
    } else {
        Err(format!("cargo {} failed", args.join(" ")))
    }
}

/// A parameter file for a device with wide ranges: the paper's preset with
/// the validated range 20-95 C (the issue's file that made `build.rs`
/// panic), written under `target/`.
fn wide_device_file(root: &Path) -> Result<PathBuf, String> {
    let text = std::fs::read_to_string(root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let path = root.join("target/xtask/wide-device.toml");
    std::fs::create_dir_all(path.parent().expect("has a parent")).map_err(|e| e.to_string())?;
    std::fs::write(
        &path,
        format!("{text}\n# A device validated over 20-95 C (cargo xtask test).\n[estimator]\nvalid_min = 20\nvalid_max = 95\n"),
    )
    .map_err(|e| e.to_string())?;
    Ok(path)
}

/// Everything CI checks.
fn cmd_test(args: &[String]) -> Outcome {
    let bless = args.iter().any(|a| a == "--bless");
    let root = root();
    let minutes = |m: u64| Duration::from_secs(60 * m);
    step("format");
    host_cargo(&root, &["fmt", "--all", "--check"], minutes(2))?;
    step("rust-version against the locked dependencies");
    msrv::check(&root)?;
    step("host tests (cargo test --workspace, which includes -p host-tests)");
    host_cargo(&root, &["test", "--workspace", "--quiet"], minutes(20))?;
    step("clippy on the host crates");
    host_cargo(
        &root,
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--quiet",
            "--",
            "-D",
            "warnings",
        ],
        minutes(10),
    )?;
    host_cargo(
        &root,
        &[
            "clippy",
            "--package",
            "xtask",
            "--features",
            "host",
            "--all-targets",
            "--quiet",
            "--",
            "-D",
            "warnings",
        ],
        minutes(10),
    )?;
    step("host instruction counts (valgrind callgrind) against the baseline");
    callgrind::check(&root, false)?;
    step("cross toolchain");
    let tc = toolchain::get(&root, &firmware::TARGETS)?;
    eprintln!("xtask: {}", tc.description);
    qemu::ensure()?;
    step("a device file with wide ranges (validated 20-95 C) builds every image; its twin passes its checks");
    let wide = wide_device_file(&root)?;
    let wide_elfs = firmware::build_all_params(&tc, &root, Some(&wide))?;
    let wide_twin = &wide_elfs
        .iter()
        .find(|(i, _)| i.bin == "twin")
        .ok_or("no twin image")?
        .1;
    let run = qemu::run(wide_twin, qemu::NETDUINO, true, minutes(5), qemu::Show::Quiet)?;
    if run.code != 0 {
        for l in &run.lines {
            eprintln!("{}", telemetry::humanize(l));
        }
        return Err(format!("the twin built for {} exited with {}", wide.display(), run.code).into());
    }
    eprintln!(
        "xtask: the twin for {} passed: {}",
        wide.display(),
        run.lines
            .iter()
            .rev()
            .find(|l| l.contains("checks:"))
            .map_or("", String::as_str)
    );
    step("a parameter file the CLI refuses fails the firmware build in one line naming the field");
    firmware::check_refused_file(&tc, &root)?;
    step("firmware images");
    let elfs = firmware::build_all_with(&tc, &root)?;
    let twin = firmware::build_with(&tc, &root, &firmware::Image::TWIN, firmware::Options::default())?;
    step("QEMU: the twin firmware against its snapshot");
    let run = qemu::run(&twin.elf, qemu::NETDUINO, true, minutes(5), qemu::Show::Quiet)?;
    if run.code != 0 {
        for l in &run.lines {
            eprintln!("{}", telemetry::humanize(l));
        }
        return Err(format!("the twin firmware exited with {}", run.code).into());
    }
    let shown: Vec<String> = run.lines.iter().map(|l| telemetry::humanize(l)).collect();
    firmware::check_snapshot(&root, "twin", &shown, bless)?;
    step("QEMU twin telemetry as CSV against the host-side estimator fed the same replay");
    let csv_path = root.join("target/xtask/twin-telemetry.csv");
    let mut csv = telemetry::CsvFile::create(&csv_path)?;
    for line in &run.lines {
        csv.line(line)?;
    }
    drop(csv);
    let decoded = telemetry::read_csv(&csv_path)?;
    let schedule = replica::Schedule::read(twin.out_dir.as_deref().ok_or("no build script output directory")?)?;
    let raw = compensator_params::file::load(&root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let host = replica::run(&raw, &schedule)?;
    eprintln!("xtask: {}: {}", csv_path.display(), replica::compare(&decoded, &host)?);
    step("QEMU: a HardFault reports and exits 1 at once");
    let fault = firmware::build(&tc, &root, &firmware::Image::FAULT, None)?;
    flash::check_fault_report(&fault)?;
    step("board image: stack in CCM below nothing, no debug logging compiled in");
    let board = &elfs.iter().find(|(i, _)| i.bin == "board").ok_or("no board image")?.1;
    flash::check_board_layout(board)?;
    for (img, elf) in &elfs {
        flash::check_no_debug_logs(elf).map_err(|e| format!("{} ({}): {e}", img.bin, img.target))?;
    }
    step("QEMU: the core's tests on the emulated Cortex-M4F");
    firmware::on_target_tests(&tc, &root)?;
    step("QEMU: cost, footprint and stack budgets");
    bench::check(&elfs, &run.lines)?;
    eprintln!("\nxtask: all checks passed");
    Ok(0)
}
