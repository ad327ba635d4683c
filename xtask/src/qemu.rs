//! Running firmware on QEMU and decoding its defmt log (semihosting).

use crate::process::{capture, is_root};
use defmt_decoder::{DecodeError, Table};
use std::io::{Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// An emulated board.
#[derive(Clone, Copy, Debug)]
pub struct Machine {
    /// `-machine`.
    pub name: &'static str,
    /// `-cpu`.
    pub cpu: &'static str,
}

/// QEMU's STM32F405 board (Cortex-M4F).
pub const NETDUINO: Machine = Machine {
    name: "netduinoplus2",
    cpu: "cortex-m4",
};
/// QEMU's Netduino 2 (STM32F205, Cortex-M3, no FPU): the same memory map
/// as the STM32F405, so one layout (`memory.x` with the QEMU STM32s' stack in SRAM) serves both targets.
pub const NETDUINO2: Machine = Machine {
    name: "netduino2",
    cpu: "cortex-m3",
};

/// QEMU's BBC micro:bit (nRF51822, Cortex-M0: no hardware divide, no
/// 32x32->64 multiply, no FPU; 256 KiB flash, 16 KiB RAM).
pub const MICROBIT: Machine = Machine {
    name: "microbit",
    cpu: "cortex-m0",
};

/// The emulated board of a target: netduinoplus2 (Cortex-M4F) unless the
/// target is the Cortex-M3's or the Cortex-M0's.
pub fn machine(target: &str) -> Machine {
    match target {
        crate::firmware::M3 => NETDUINO2,
        crate::firmware::M0 => MICROBIT,
        _ => NETDUINO,
    }
}

/// The emulated board of an ELF built by cargo (its path names the target).
pub fn machine_of(elf: &Path) -> Machine {
    let path = elf.to_string_lossy();
    crate::firmware::TARGETS
        .iter()
        .find(|t| path.contains(&format!("/{t}/")))
        .map_or(NETDUINO, |t| machine(t))
}

const QEMU: &str = "qemu-system-arm";

/// Makes sure `qemu-system-arm` runs: installs Debian's package when
/// missing and permitted (root), else says the exact command.
pub fn ensure() -> Result<(), String> {
    let ok = |_: ()| capture(Command::new(QEMU).arg("--version"), Duration::from_secs(20)).ok();
    if ok(()) {
        return Ok(());
    }
    let install = "apt-get install -y --no-install-recommends qemu-system-arm";
    if !is_root() {
        return Err(format!(
            "{QEMU} is missing; install it with: sudo apt-get update && sudo {install}"
        ));
    }
    eprintln!("xtask: installing {QEMU} ({install})");
    let attempt = || {
        capture(
            Command::new("apt-get")
                .args(["install", "-y", "--no-install-recommends", "qemu-system-arm"])
                .env("DEBIAN_FRONTEND", "noninteractive"),
            Duration::from_secs(900),
        )
    };
    if !attempt().ok() {
        let upd = capture(Command::new("apt-get").arg("update"), Duration::from_secs(300));
        if !upd.ok() {
            return Err(format!("apt-get update failed: {}", upd.stderr.trim()));
        }
        let second = attempt();
        if !second.ok() {
            return Err(format!("{install} failed: {}", second.stderr.trim()));
        }
    }
    if ok(()) {
        Ok(())
    } else {
        Err(format!("{QEMU} still does not run after installing it"))
    }
}

/// How decoded lines are shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Show {
    /// Print each line as it arrives (with source locations).
    Stream,
    /// Print nothing; return the lines.
    Quiet,
}

/// Result of a run.
pub struct Run {
    /// QEMU's exit code (the firmware's semihosting exit code); 124 on timeout.
    pub code: i32,
    /// Decoded log lines, `LEVEL message` (no locations), every digit as
    /// the firmware sent it.
    pub lines: Vec<String>,
}

/// Runs `elf` on `machine` with semihosting; `icount` makes the emulated
/// clock advance exactly one nanosecond per instruction (deterministic
/// SysTick deltas).
pub fn run(elf: &Path, machine: Machine, icount: bool, timeout: Duration, show: Show) -> Result<Run, String> {
    let bytes = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let table = Table::parse(&bytes)
        .map_err(|e| format!("{}: {e}", elf.display()))?
        .ok_or_else(|| format!("{}: no .defmt section", elf.display()))?;
    let locations = table.get_locations(&bytes).ok().filter(|l| !l.is_empty());
    let mut decoder = table.new_stream_decoder();

    let mut cmd = Command::new(QEMU);
    cmd.args([
        "-machine",
        machine.name,
        "-cpu",
        machine.cpu,
        "-nographic",
        "-monitor",
        "none",
        "-serial",
        "none",
    ])
    .args(["-semihosting-config", "enable=on,target=native"]);
    if icount {
        cmd.args(["-icount", "shift=0"]);
    }
    cmd.arg("-kernel").arg(elf);
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{QEMU}: {e}"))?;
    let mut out = child.stdout.take().expect("piped");
    let mut err = child.stderr.take().expect("piped");
    let (tx, rx) = mpsc::channel::<Vec<u8>>();
    std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        loop {
            match out.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    if tx.send(buf[..n].to_vec()).is_err() {
                        break;
                    }
                }
            }
        }
    });
    let stderr = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });

    let deadline = Instant::now() + timeout;
    let mut lines = Vec::new();
    let stdout = std::io::stdout();
    let mut timed_out = false;
    loop {
        match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(chunk) => {
                decoder.received(&chunk);
                loop {
                    match decoder.decode() {
                        Ok(frame) => {
                            let level = frame
                                .level()
                                .map(|l| l.as_str().to_uppercase())
                                .unwrap_or_else(|| "PRINT".into());
                            let line = format!("{level:<5} {}", frame.display_message());
                            if show == Show::Stream {
                                let mut o = stdout.lock();
                                // Telemetry rounded for reading (`lines` keeps every digit).
                                let _ = write!(o, "{}", crate::telemetry::humanize(&line));
                                if let Some(loc) = locations.as_ref().and_then(|l| l.get(&frame.index()))
                                    && level != "INFO"
                                    && level != "PRINT"
                                {
                                    let _ = write!(o, "  ({}:{})", loc.file.display(), loc.line);
                                }
                                let _ = writeln!(o);
                            }
                            lines.push(line);
                        }
                        Err(DecodeError::UnexpectedEof) => break,
                        Err(DecodeError::Malformed) => {
                            lines.push("ERROR malformed defmt frame".into());
                            if !table.encoding().can_recover() {
                                break;
                            }
                        }
                    }
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                timed_out = true;
                break;
            }
        }
    }
    if timed_out {
        crate::process::kill_tree(&mut child);
        let _ = child.wait();
        eprintln!("xtask: {} did not finish within {timeout:?}; killed", elf.display());
        return Ok(Run { code: 124, lines });
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    let stderr = stderr.join().unwrap_or_default();
    // QEMU warns about unimplemented peripherals; only show the unexpected.
    for l in stderr.lines().filter(|l| !l.contains("Timer with period zero")) {
        eprintln!("qemu: {l}");
    }
    Ok(Run {
        code: status.code().unwrap_or(1),
        lines,
    })
}
