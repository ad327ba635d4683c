//! `cargo xtask flash [--params F] [--csv FILE] [--debug] [--seconds S]`:
//! builds the board image alone (no host-side crate of the workspace) and
//! runs it on the board with `probe-rs run --chip STM32F405RGTx` (flash,
//! reset, RTT log decoded by probe-rs), showing the telemetry rounded for
//! reading and, with `--csv`, writing it as CSV like `cargo xtask run`.
//! Without probe-rs it says how to install it and where the ELF is.
//!
//! Also the firmware checks of `cargo xtask test` that need no board: the
//! board image's memory layout (stack overflow faults), the default
//! images' logging (no `debug!`/`trace!` compiled in), the QEMU fault
//! report.

use crate::firmware::{self, Image, Options};
use crate::{Failure, Outcome, process, qemu, telemetry, toolchain};
use object::{Object, ObjectSection, ObjectSymbol};
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// probe-rs's name of the board's chip.
pub const CHIP: &str = "STM32F405RGTx";

/// What to do without probe-rs.
pub fn install_advice(elf: &Path) -> String {
    format!(
        "probe-rs is not installed. Install it with `cargo install probe-rs-tools --locked` \
         (or the installer script of https://probe.rs), then run `cargo xtask flash` again, \
         or flash the image yourself: probe-rs run --chip {CHIP} {}",
        elf.display()
    )
}

fn probe_rs_version() -> Option<String> {
    let out = process::capture(Command::new("probe-rs").arg("--version"), Duration::from_secs(10));
    out.ok()
        .then(|| out.stdout.lines().next().unwrap_or("probe-rs").trim().to_string())
}

/// `cargo xtask flash`: `params` resolved and checked by the caller
/// (`None`: the default preset), `csv` the file for the telemetry as CSV,
/// `debug` the debug-level logs compiled in, `seconds` a deadline (exit
/// status 0 when it passes).
pub fn cmd(root: &Path, params: Option<&Path>, csv_path: Option<&Path>, debug: bool, seconds: Option<u64>) -> Outcome {
    let mut csv = match csv_path {
        Some(p) => Some(telemetry::CsvFile::create(p).map_err(Failure::Input)?),
        None => None,
    };
    let tc = toolchain::get(root, &[firmware::M4])?;
    eprintln!("xtask: toolchain: {}", tc.description);
    let built = firmware::build_with(&tc, root, &Image::BOARD, Options { params, debug })?;
    eprintln!("xtask: board image {}", built.elf.display());
    let Some(version) = probe_rs_version() else {
        eprintln!("xtask: {}", install_advice(&built.elf));
        return Ok(1);
    };
    eprintln!("xtask: {version}: probe-rs run --chip {CHIP} (Ctrl-C stops)");
    let mut child = Command::new("probe-rs")
        .args(["run", "--chip", CHIP])
        .arg(&built.elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("probe-rs: {e}"))?;
    let stdout = child.stdout.take().expect("piped");
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let deadline = seconds.map(|s| Instant::now() + Duration::from_secs(s));
    let out = std::io::stdout();
    loop {
        let wait = deadline.map_or(Duration::from_secs(3600), |d| {
            d.saturating_duration_since(Instant::now())
        });
        match rx.recv_timeout(wait) {
            Ok(line) => {
                let _ = writeln!(out.lock(), "{}", telemetry::humanize(&line));
                if let Some(csv) = csv.as_mut() {
                    csv.line(&line)?;
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) if deadline.is_some_and(|d| Instant::now() >= d) => {
                process::kill_tree(&mut child);
                break;
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    if let (Some(csv), Some(p)) = (&csv, csv_path) {
        eprintln!("xtask: wrote {} telemetry records to {}", csv.rows, p.display());
    }
    Ok(if seconds.is_some() {
        0
    } else {
        status.code().unwrap_or(1)
    })
}

/// The address of `name` in an ELF's symbol table.
fn symbol(file: &object::File<'_>, name: &str) -> Option<u64> {
    file.symbols().find(|s| s.name() == Ok(name)).map(|s| s.address())
}

/// The board image keeps its stack alone in the core-coupled RAM, below
/// which nothing is mapped (an overflow faults), and its statics in SRAM.
pub fn check_board_layout(elf: &Path) -> Result<(), String> {
    let data = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let file = object::File::parse(&*data).map_err(|e| format!("{}: {e}", elf.display()))?;
    let start = symbol(&file, "_stack_start").ok_or("no _stack_start")?;
    let end = symbol(&file, "_stack_end").ok_or("no _stack_end")?;
    if (end, start) != (0x1000_0000, 0x1001_0000) {
        return Err(format!(
            "{}: the stack spans {end:#x}..{start:#x}, not the CCM 0x10000000..0x10010000",
            elf.display()
        ));
    }
    for s in file.sections() {
        let name = s.name().unwrap_or_default();
        if matches!(name, ".bss" | ".data" | ".uninit")
            && s.size() > 0
            && !(0x2000_0000..0x2002_0000).contains(&s.address())
        {
            return Err(format!(
                "{}: {name} at {:#x}, outside the SRAM",
                elf.display(),
                s.address()
            ));
        }
    }
    eprintln!("xtask: board image: stack {end:#x}..{start:#x} (CCM; below it nothing is mapped), statics in SRAM");
    Ok(())
}

/// The `debug!`/`trace!` format strings compiled into an image.
pub fn debug_logs(elf: &Path) -> Result<Vec<String>, String> {
    let data = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let table = defmt_decoder::Table::parse(&data)
        .map_err(|e| format!("{}: {e}", elf.display()))?
        .ok_or_else(|| format!("{}: no .defmt section", elf.display()))?;
    Ok(table
        .raw_symbols()
        .filter(|s| s.contains("\"tag\":\"defmt_debug\"") || s.contains("\"tag\":\"defmt_trace\""))
        .map(str::to_string)
        .collect())
}

/// The default images log nothing below `info` (the sensor's bring-up
/// logging is compiled out unless `DEFMT_LOG` asks for it).
pub fn check_no_debug_logs(elf: &Path) -> Result<(), String> {
    let found = debug_logs(elf)?;
    if found.is_empty() {
        Ok(())
    } else {
        Err(format!("debug/trace logging compiled in: {}", found.join("; ")))
    }
}

/// The fault image on QEMU: a HardFault reported with its registers and
/// exit code 1, well before any deadline.
pub fn check_fault_report(elf: &Path) -> Result<(), String> {
    let t0 = Instant::now();
    let run = qemu::run(elf, qemu::NETDUINO, true, Duration::from_secs(60), qemu::Show::Quiet)?;
    let took = t0.elapsed();
    let report = run
        .lines
        .iter()
        .find(|l| l.starts_with("ERROR") && l.contains("HardFault: pc"));
    match report {
        Some(line) if run.code == 1 && took < Duration::from_secs(30) => {
            eprintln!("xtask: {line} (exit 1 after {:.1} s)", took.as_secs_f64());
            Ok(())
        }
        _ => Err(format!(
            "the fault image exited with {} after {:.1} s; its log: {:?}",
            run.code,
            took.as_secs_f64(),
            run.lines
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_probe_rs_the_advice_names_the_install_and_the_elf() {
        let a = install_advice(Path::new("/w/target/firmware/thumbv7em-none-eabihf/release/board"));
        assert!(a.contains("cargo install probe-rs-tools --locked"));
        assert!(a.contains("probe-rs run --chip STM32F405RGTx /w/target/firmware/thumbv7em-none-eabihf/release/board"));
    }
}
