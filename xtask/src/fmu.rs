//! `cargo xtask fmu`: the twin as a co-simulation FMU (FMI 2.0 or 3.0),
//! and the check `cargo xtask test` runs on it with a real importer (FMPy).
//!
//! The FMU is a zip archive:
//!
//! ```text
//! modelDescription.xml                    generated (compensator_fmu::description)
//! binaries/linux64/compensator.so         FMI 2.0 (x86_64-linux for FMI 3.0): the cdylib
//! resources/params.toml                   the parameter file (start values, read at instantiation)
//! ```

use crate::process;
use compensator_fmu::description::{FmiVersion, MODEL_IDENTIFIER, model_description};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The cargo profile of the FMU's binary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Profile {
    /// `release`: what `cargo xtask fmu` ships.
    Release,
    /// `dev` (`cargo xtask fmu --debug`, and the check in `cargo xtask
    /// test`, which reuses the binary `cargo test --workspace` built: about
    /// a second instead of 80 s for a release tree): the same source and
    /// the same `f32` arithmetic (no fast-math at any optimisation level;
    /// the workspace's dev profile optimises the model crate at level 3),
    /// with debug assertions on.
    Dev,
}

/// Builds `out_dir/compensator.fmu` for `version` with the parameter file
/// `params` (`None`: the paper preset); returns its path.
///
/// # Errors
///
/// A parameter file the chooser cannot configure a twin for, a failed
/// build, or a file that cannot be written.
pub fn build(
    root: &Path,
    params: Option<&Path>,
    version: FmiVersion,
    profile: Profile,
    out_dir: &Path,
) -> Result<PathBuf, String> {
    if !(cfg!(target_os = "linux") && cfg!(target_arch = "x86_64")) {
        return Err("cargo xtask fmu packages Linux x86-64 binaries only: run it on such a host".into());
    }
    let params_path = params.map_or_else(|| root.join("presets/paper.toml"), Path::to_path_buf);
    let text = std::fs::read_to_string(&params_path).map_err(|e| format!("{}: {e}", params_path.display()))?;
    let raw = compensator_params::file::parse(&text).map_err(|e| format!("{}: {e}", params_path.display()))?;
    let config = compensator_fmu::chosen_config(&raw)?;
    eprintln!(
        "xtask: FMU (FMI {}) for {}: the twin runs {}, {} substep(s) per {} s tick",
        match version {
            FmiVersion::V2 => "2.0",
            FmiVersion::V3 => "3.0",
        },
        params_path.display(),
        config.scheme.name(),
        config.substeps,
        config.tick
    );
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.args(["build", "--quiet", "--package", "compensator-fmu", "--lib"])
        .current_dir(root);
    let dir = match profile {
        Profile::Release => {
            cmd.arg("--release");
            "release"
        }
        Profile::Dev => "debug",
    };
    let code = process::run(&mut cmd, Duration::from_secs(20 * 60));
    if code != Some(0) {
        return Err("cargo build --package compensator-fmu failed".into());
    }
    let so = root.join("target").join(dir).join("libcompensator_fmu.so");
    let binary = std::fs::read(&so).map_err(|e| format!("{}: {e}", so.display()))?;
    let xml = model_description(version, &raw, &config);
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let path = out_dir.join(format!("{MODEL_IDENTIFIER}.fmu"));
    let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let deflated = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let entries: [(String, &[u8]); 3] = [
        ("modelDescription.xml".into(), xml.as_bytes()),
        (
            format!("binaries/{}/{MODEL_IDENTIFIER}.so", version.linux_x86_64_dir()),
            &binary,
        ),
        (
            format!("resources/{}", compensator_fmu::PARAMS_RESOURCE),
            text.as_bytes(),
        ),
    ];
    for (name, bytes) in entries {
        zip.start_file(name.as_str(), deflated)
            .and_then(|()| zip.write_all(bytes).map_err(Into::into))
            .map_err(|e| format!("{}: {name}: {e}", path.display()))?;
    }
    zip.finish().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// The check `cargo xtask test` runs: for FMI 2.0 and 3.0, the FMU of the
/// paper preset validated and simulated by FMPy (`fmu/python/check_fmu.py`:
/// a step and a ramp against `compensator step --precision f32`, state
/// round trips, an invalid parameter), and the example script run on the
/// measured temperature history. Returns a summary line, or `None` with
/// the reason printed when Python's venv cannot be had (the check is
/// skipped).
///
/// # Errors
///
/// A failed build, CLI run or check.
pub fn check(root: &Path) -> Result<Option<String>, String> {
    let started = Instant::now();
    let venv = process::capture_stdout(
        Command::new("bash").arg(root.join(".ci/fmu-venv")).current_dir(root),
        Duration::from_secs(20 * 60),
    );
    if venv.code == Some(3) {
        eprintln!("xtask: SKIPPED the FMU check: python3 with its venv module is missing and could not be installed");
        return Ok(None);
    }
    if !venv.ok() {
        return Err("the FMU check's Python environment (.ci/fmu-venv) could not be made".into());
    }
    let python = root.join(venv.stdout.trim());
    let venv_s = started.elapsed().as_secs_f64();
    let work = root.join("target/fmu/check");
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let params = root.join("presets/paper.toml");
    let (from, to, ramp) = ("30", "70", "200");
    let cli = |name: &str, extra: &[&str]| -> Result<PathBuf, String> {
        let out = work.join(name);
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut args = vec![
            "run",
            "--quiet",
            "--package",
            "compensator-cli",
            "--",
            "step",
            "--params",
        ];
        let p = params.to_str().ok_or("a UTF-8 path")?;
        let o = out.to_str().ok_or("a UTF-8 path")?;
        args.extend([
            p,
            "--from",
            from,
            "--to",
            to,
            "--precision",
            "f32",
            "--t-end",
            "0.3",
            "-o",
            o,
        ]);
        args.extend(extra);
        if process::run(
            Command::new(cargo).args(&args).current_dir(root),
            Duration::from_secs(600),
        ) != Some(0)
        {
            return Err(format!("compensator {}: failed", args[5..].join(" ")));
        }
        Ok(out)
    };
    let step_csv = cli("step.csv", &[])?;
    let ramp_csv = cli("ramp.csv", &["--ramp", ramp])?;
    let mut summaries = Vec::new();
    for version in [FmiVersion::V2, FmiVersion::V3] {
        let dir = work.join(version.linux_x86_64_dir());
        let fmu = build(root, None, version, Profile::Dev, &dir)?;
        let t0 = Instant::now();
        let out = process::capture(
            Command::new(&python)
                .arg(root.join("fmu/python/check_fmu.py"))
                .arg(&fmu)
                .args(["--step-csv", step_csv.to_str().ok_or("a UTF-8 path")?])
                .args(["--ramp-csv", ramp_csv.to_str().ok_or("a UTF-8 path")?])
                .args(["--from", from, "--to", to, "--ramp", ramp])
                .current_dir(&dir),
            Duration::from_secs(300),
        );
        eprint!("{}", out.stdout);
        if !out.ok() {
            eprint!("{}", out.stderr);
            return Err(format!("the FMU check failed for {}", fmu.display()));
        }
        summaries.push(format!(
            "{}: {} ({:.1} s)",
            fmu.display(),
            out.stdout.lines().last().unwrap_or(""),
            t0.elapsed().as_secs_f64()
        ));
        if version == FmiVersion::V2 {
            // The example of docs/fmu.md on the measured temperature history.
            let csv = work.join("example.csv");
            let ex = process::capture(
                Command::new(&python)
                    .arg(root.join("fmu/python/drive_fmu.py"))
                    .arg(&fmu)
                    .arg(root.join("data/fmu/oil-temperature.csv"))
                    .args(["--csv", csv.to_str().ok_or("a UTF-8 path")?, "--no-plot"])
                    .current_dir(&dir),
                Duration::from_secs(120),
            );
            eprint!("{}", ex.stdout);
            if !ex.ok() {
                eprint!("{}", ex.stderr);
                return Err("fmu/python/drive_fmu.py failed".into());
            }
        }
    }
    Ok(Some(format!(
        "{}; venv {venv_s:.1} s, all {:.0} s",
        summaries.join("; "),
        started.elapsed().as_secs_f64()
    )))
}
