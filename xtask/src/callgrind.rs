//! `cargo xtask callgrind [--bless]`: host instruction counts of the core's
//! hot paths under valgrind's callgrind (repeatable where wall time is not),
//! as a regression benchmark against `host-tests/benches/callgrind-baseline.txt`.
//!
//! Each workload of `host-tests/benches/host.rs` runs in its own valgrind
//! process; the `setup` workload (reading the preset) is subtracted, and
//! the rest divided by the operation count. A workload more than
//! [`TOLERANCE`] off its baseline fails the check. The workloads and the
//! count come from the bench itself (`host list`), so that xtask needs no
//! host-side crate of the workspace.

use crate::process;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Allowed relative change against the baseline.
pub const TOLERANCE: f64 = 0.05;

fn baseline_path(root: &Path) -> PathBuf {
    root.join("host-tests/benches/callgrind-baseline.txt")
}

/// Builds the bench and returns its executable.
fn bench_executable(root: &Path) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = process::capture(
        Command::new(cargo)
            .args([
                "bench",
                "-p",
                "host-tests",
                "--bench",
                "host",
                "--no-run",
                "--message-format=json",
            ])
            .current_dir(root),
        Duration::from_secs(1200),
    );
    if !out.ok() {
        return Err(format!("building the host bench failed: {}", out.stderr.trim()));
    }
    out.stdout
        .lines()
        .filter(|l| l.contains("\"target\":{") && l.contains("\"name\":\"host\""))
        .find_map(|l| {
            let rest = l.split("\"executable\":\"").nth(1)?;
            Some(PathBuf::from(rest.split('"').next()?))
        })
        .ok_or_else(|| "no executable for the host bench".into())
}

/// The bench's operation count and workload names (`host list`).
fn workloads(exe: &Path) -> Result<(f64, Vec<String>), String> {
    let out = process::capture(Command::new(exe).arg("list"), Duration::from_secs(60));
    if !out.ok() {
        return Err(format!("{} list: {}", exe.display(), out.stderr.trim()));
    }
    let count = out
        .stdout
        .lines()
        .find_map(|l| l.strip_prefix("count ")?.trim().parse::<f64>().ok())
        .ok_or("the host bench reported no operation count")?;
    let names: Vec<String> = out
        .stdout
        .lines()
        .filter_map(|l| l.strip_prefix("workload "))
        .map(|w| w.trim().to_string())
        .collect();
    if names.is_empty() {
        return Err("the host bench reported no workload".into());
    }
    Ok((count, names))
}

/// Total instructions (Ir) of one run of `exe workload`.
fn instructions(exe: &Path, workload: &str, dir: &Path) -> Result<f64, String> {
    let file = dir.join(format!("{workload}.out"));
    let out = process::capture(
        Command::new("valgrind")
            .arg("--tool=callgrind")
            .arg(format!("--callgrind-out-file={}", file.display()))
            .arg(exe)
            .arg(workload),
        Duration::from_secs(600),
    );
    if !out.ok() {
        return Err(format!(
            "valgrind {workload}: {}",
            out.stderr.lines().last().unwrap_or("failed")
        ));
    }
    let text = std::fs::read_to_string(&file).map_err(|e| e.to_string())?;
    text.lines()
        .find_map(|l| l.strip_prefix("summary:").or_else(|| l.strip_prefix("totals:")))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .ok_or_else(|| format!("{}: no instruction total", file.display()))
}

/// Measures every workload: `(name, instructions per operation)`.
pub fn measure(root: &Path) -> Result<Vec<(String, f64)>, String> {
    if !process::capture(Command::new("valgrind").arg("--version"), Duration::from_secs(20)).ok() {
        return Err("valgrind is missing (apt-get install valgrind)".into());
    }
    let exe = bench_executable(root)?;
    let (count, workloads) = workloads(&exe)?;
    let dir = root.join("target/callgrind");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let setup = instructions(&exe, "setup", &dir)?;
    workloads
        .iter()
        .map(|w| Ok((w.to_string(), (instructions(&exe, w, &dir)? - setup) / count)))
        .collect()
}

/// The baseline's counts and the compiler that produced them.
fn read_baseline(root: &Path) -> (Vec<(String, f64)>, Option<String>) {
    let text = std::fs::read_to_string(baseline_path(root)).unwrap_or_default();
    let compiler = text
        .lines()
        .find_map(|l| l.strip_prefix("# compiler: "))
        .map(str::to_string);
    let counts = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            Some((w.next()?.to_string(), w.next()?.parse().ok()?))
        })
        .collect();
    (counts, compiler)
}

/// `rustc -V` of the host compiler cargo uses.
fn host_compiler() -> String {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    process::capture(Command::new(rustc).arg("-V"), Duration::from_secs(20))
        .stdout
        .trim()
        .to_string()
}

/// Measures, prints, and compares with (or, `bless`, writes) the baseline.
pub fn check(root: &Path, bless: bool) -> Result<(), String> {
    let now = measure(root)?;
    let (base, base_compiler) = read_baseline(root);
    let compiler = host_compiler();
    let mut bad = Vec::new();
    println!(
        "{:16} {:>14} {:>14} {:>8}",
        "workload", "instr/op", "baseline", "change"
    );
    for (name, v) in &now {
        let b = base.iter().find(|(n, _)| n == name).map(|(_, b)| *b);
        let change = b.map(|b| (v - b) / b);
        println!(
            "{name:16} {v:14.1} {:>14} {:>8}",
            b.map(|b| format!("{b:.1}")).unwrap_or_else(|| "-".into()),
            change
                .map(|c| format!("{:+.1} %", c * 100.0))
                .unwrap_or_else(|| "new".into())
        );
        match change {
            Some(c) if c.abs() > TOLERANCE => bad.push(format!("{name}: {:+.1} %", c * 100.0)),
            None if !bless => bad.push(format!("{name}: no baseline")),
            _ => {}
        }
    }
    if bless {
        let mut text = String::from(
            "# Host instructions per operation (x86-64, valgrind callgrind), written by\n\
             # `cargo xtask callgrind --bless`; `cargo xtask callgrind` checks within 5 %\n\
             # when built by the same compiler (another one only reports).\n",
        );
        text.push_str(&format!("# compiler: {compiler}\n"));
        for (name, v) in &now {
            text.push_str(&format!("{name} {v:.1}\n"));
        }
        std::fs::write(baseline_path(root), text).map_err(|e| e.to_string())?;
        eprintln!("xtask: wrote {}", baseline_path(root).display());
        return Ok(());
    }
    if bad.is_empty() {
        Ok(())
    } else if base_compiler.as_deref() != Some(compiler.as_str()) {
        // Code generation moves with the compiler: not a regression of ours.
        eprintln!(
            "xtask: host instruction counts moved ({}), but the baseline was built by {} and this \
             run by {compiler}: reported, not failed (cargo xtask callgrind --bless to adopt)",
            bad.join(", "),
            base_compiler.as_deref().unwrap_or("an unrecorded compiler")
        );
        Ok(())
    } else {
        Err(format!(
            "host instruction counts moved beyond {:.0} %: {} (if intended: cargo xtask callgrind --bless)",
            TOLERANCE * 100.0,
            bad.join(", ")
        ))
    }
}
