//! `cargo xtask`: the project's automation.
//!
//! ```text
//! cargo xtask run [--params FILE]   build the QEMU firmware and run it (the main job)
//! cargo xtask test [--bless]        everything CI checks (the test command)
//! cargo xtask bench [--write]       cost, footprint and stack on the emulated MCUs
//! cargo xtask callgrind [--bless]   host instruction counts against the baseline
//! cargo xtask build                 build every firmware image
//! cargo xtask toolchain             find or provision the cross toolchain
//! cargo xtask qemu-runner ELF       run an ELF on QEMU (cargo runner for on-target tests)
//! ```

mod bench;
mod callgrind;
mod firmware;
mod process;
mod qemu;
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

fn usage() -> ExitCode {
    eprintln!(
        "usage: cargo xtask <command>\n\
         \n  run [--params FILE]   build the QEMU firmware and run it (the main job)\
         \n  test [--bless]        every check CI runs (host tests, clippy, cross builds, QEMU)\
         \n  bench [--write]       instructions per tick, flash, RAM and stack on the emulated MCUs\
         \n  callgrind [--bless]   host instruction counts (valgrind) against the baseline\
         \n  build                 build every firmware image\
         \n  target-tests          the core's tests on the emulated Cortex-M4F (defmt-test)\
         \n  toolchain             find or provision the thumbv7em/thumbv7m toolchain\
         \n  qemu-runner ELF       run an ELF on QEMU (netduinoplus2, or netduino2 for thumbv7m)"
    );
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("run") => cmd_run(&args[1..]),
        Some("test") => cmd_test(&args[1..]),
        Some("bench") => bench::cmd(&root(), &args[1..]),
        Some("build") => firmware::build_all(&root()).map(|_| 0),
        Some("toolchain") => toolchain::get(&root(), &firmware::TARGETS).map(|t| {
            println!("{}", t.description);
            0
        }),
        Some("qemu-runner") => cmd_qemu_runner(&args[1..]),
        Some("callgrind") => callgrind::check(&root(), args.iter().any(|a| a == "--bless")).map(|_| 0),
        Some("target-tests") => toolchain::get(&root(), &[firmware::M4])
            .and_then(|tc| qemu::ensure().and_then(|_| firmware::on_target_tests(&tc, &root())))
            .map(|_| 0),
        _ => return usage(),
    };
    match result {
        Ok(code) => ExitCode::from(code.clamp(0, 255) as u8),
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

fn flag_value(args: &[String], flag: &str) -> Result<Option<String>, String> {
    match args.iter().position(|a| a == flag) {
        None => Ok(None),
        Some(i) => args
            .get(i + 1)
            .cloned()
            .map(Some)
            .ok_or_else(|| format!("{flag} needs a value")),
    }
}

/// The main job: the twin firmware on QEMU's STM32F405, log decoded live.
fn cmd_run(args: &[String]) -> Result<i32, String> {
    let root = root();
    let params =
        flag_value(args, "--params")?.map(|p| std::fs::canonicalize(&p).map_err(|e| format!("--params {p}: {e}")));
    let params = params.transpose()?;
    let tc = toolchain::get(&root, &[firmware::M4])?;
    eprintln!("xtask: toolchain: {}", tc.description);
    qemu::ensure()?;
    let elf = firmware::build(&tc, &root, &firmware::Image::TWIN, params.as_deref())?;
    eprintln!("xtask: running {} on QEMU {}", elf.display(), qemu::NETDUINO.name);
    let run = qemu::run(&elf, qemu::NETDUINO, true, Duration::from_secs(300), qemu::Show::Stream)?;
    eprintln!("xtask: firmware exit code {}", run.code);
    Ok(run.code)
}

/// cargo runner: `xtask qemu-runner ELF [args...]`.
fn cmd_qemu_runner(args: &[String]) -> Result<i32, String> {
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

/// Everything CI checks.
fn cmd_test(args: &[String]) -> Result<i32, String> {
    let bless = args.iter().any(|a| a == "--bless");
    let root = root();
    let minutes = |m: u64| Duration::from_secs(60 * m);
    step("format");
    host_cargo(&root, &["fmt", "--all", "--check"], minutes(2))?;
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
    step("host instruction counts (valgrind callgrind) against the baseline");
    callgrind::check(&root, false)?;
    step("cross toolchain");
    let tc = toolchain::get(&root, &firmware::TARGETS)?;
    eprintln!("xtask: {}", tc.description);
    qemu::ensure()?;
    step("firmware images");
    let elfs = firmware::build_all_with(&tc, &root)?;
    step("QEMU: the twin firmware against its snapshot");
    let twin = elfs
        .iter()
        .find(|(i, _)| i.bin == "twin")
        .map(|(_, p)| p.clone())
        .ok_or("no twin image")?;
    let run = qemu::run(&twin, qemu::NETDUINO, true, minutes(5), qemu::Show::Quiet)?;
    if run.code != 0 {
        for l in &run.lines {
            eprintln!("{l}");
        }
        return Err(format!("the twin firmware exited with {}", run.code));
    }
    firmware::check_snapshot(&root, "twin", &run.lines, bless)?;
    step("QEMU: the core's tests on the emulated Cortex-M4F");
    firmware::on_target_tests(&tc, &root)?;
    step("QEMU: cost, footprint and stack budgets");
    bench::check(&elfs, &run.lines)?;
    eprintln!("\nxtask: all checks passed");
    Ok(0)
}
