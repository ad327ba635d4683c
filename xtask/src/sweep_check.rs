//! The sweep's scale-out recipe checked (`cargo xtask sweep-check`, part of
//! `cargo xtask test`): `cli/scale-out/dask_sweep.py` maps the shards of a
//! sweep over a Dask `LocalCluster` (two worker processes) with the CLI
//! built here, merges them and compares the result with the single run
//! byte for byte. Its Python is a venv made by `.ci/dask-venv`
//! (dask.distributed); when Python's venv cannot be had the check is
//! skipped, saying so.

use crate::process;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// The sweep the check shards: a grid of 3 spring rates with 700
/// tolerance draws each (2,100 variants), in 7 shards (uneven: 300 each,
/// the draws of shard K replayed past the 300 (K - 1) before it).
pub const SWEEP: [&str; 11] = [
    "sweep",
    "--params",
    "presets/paper.toml",
    "--set",
    "plunger.spring_rate=20e3:30e3:3",
    "--vary",
    "plunger.diameter=2%",
    "--samples",
    "700",
    "--seed",
    "3",
];

/// Shards of [`SWEEP`].
pub const SHARDS: usize = 7;

/// Runs the check (module docs); returns its summary line, or `None` with
/// the reason printed when Python's venv cannot be had.
///
/// # Errors
///
/// The CLI does not build, the venv cannot be made, or the merged shards
/// differ from the single run.
pub fn check(root: &Path) -> Result<Option<String>, String> {
    let started = Instant::now();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    if process::run(
        Command::new(&cargo)
            .args([
                "build",
                "--quiet",
                "--package",
                "compensator-cli",
                "--bin",
                "compensator",
            ])
            .current_dir(root),
        Duration::from_secs(1200),
    ) != Some(0)
    {
        return Err("building the compensator CLI failed".into());
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), Into::into);
    let binary = target.join("debug/compensator");
    let venv = process::capture_stdout(
        Command::new("bash").arg(root.join(".ci/dask-venv")).current_dir(root),
        Duration::from_secs(20 * 60),
    );
    if venv.code == Some(3) {
        eprintln!(
            "xtask: SKIPPED the Dask sweep check: python3 with its venv module is missing and could not be installed"
        );
        return Ok(None);
    }
    if !venv.ok() {
        return Err("the Dask check's Python environment (.ci/dask-venv) could not be made".into());
    }
    let python = root.join(venv.stdout.trim());
    let shards = SHARDS.to_string();
    let out = process::capture(
        Command::new(&python)
            .arg(root.join("cli/scale-out/dask_sweep.py"))
            .arg("--binary")
            .arg(&binary)
            .args(["--shards", &shards, "--workers", "2", "--check", "--"])
            .args(SWEEP)
            .current_dir(root),
        Duration::from_secs(600),
    );
    if !out.ok() {
        eprint!("{}{}", out.stdout, out.stderr);
        return Err("cli/scale-out/dask_sweep.py --check failed".into());
    }
    Ok(Some(format!(
        "{} ({:.0} s)",
        out.stdout.lines().last().unwrap_or(""),
        started.elapsed().as_secs_f64()
    )))
}
