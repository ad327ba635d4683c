//! `cargo xtask fmu`: the twin as a co-simulation FMU (FMI 2.0 or 3.0),
//! and the check `cargo xtask test` runs on it with a real importer (FMPy).
//!
//! The FMU is a zip archive:
//!
//! ```text
//! modelDescription.xml                    generated (compensator_fmu::description)
//! binaries/linux64/compensator.so         the cdylib per platform (compensator_fmu::platforms:
//! binaries/win64/compensator.dll            FMI 2.0 folders; FMI 3.0: x86_64-linux, x86_64-windows,
//! binaries/aarch64-linux/compensator.so     aarch64-linux), the host's by default
//! resources/params.toml                   the parameter file (start values, read at instantiation)
//! ```

use crate::process;
use compensator_fmu::description::{FmiVersion, MODEL_IDENTIFIER, model_description};
use compensator_fmu::platforms::{PLATFORMS, Platform};
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

/// The binary of one platform, built.
#[derive(Clone, Debug)]
pub struct Binary {
    /// Its platform.
    pub platform: Platform,
    /// The shared library in cargo's output folder.
    pub path: PathBuf,
}

/// Deadline of `rustup target add` (rustup may not reach its server).
const RUSTUP_DEADLINE: Duration = Duration::from_secs(120);

/// Whether the C compiler `cc` runs.
fn runs(cc: &str) -> bool {
    process::capture(Command::new(cc).arg("--version"), Duration::from_secs(30)).ok()
}

/// Makes a cross platform buildable: its Rust target (rustup's, added under
/// a 120 s deadline when missing) and its C cross compiler (the linker).
///
/// # Errors
///
/// Why not, with what to install: the target rustup could not add, or the
/// compiler's Debian package.
pub fn provision(root: &Path, p: Platform) -> Result<(), String> {
    let Some(cc) = p.cross_compiler else { return Ok(()) };
    let installed = process::capture(
        Command::new("rustup")
            .args(["target", "list", "--installed"])
            .current_dir(root),
        Duration::from_secs(30),
    );
    if !installed.stdout.lines().any(|l| l.trim() == p.rust_target) {
        eprintln!(
            "xtask: rustup target add {} (deadline {RUSTUP_DEADLINE:?})",
            p.rust_target
        );
        let added = process::capture(
            Command::new("rustup")
                .args(["target", "add", p.rust_target])
                .current_dir(root),
            RUSTUP_DEADLINE,
        );
        if !added.ok() {
            return Err(format!(
                "{}: rustup could not add the target {} ({}); no other toolchain builds its standard library here",
                p.tuple,
                p.rust_target,
                if added.timed_out {
                    "its server did not answer in time".to_string()
                } else {
                    added.stderr.lines().last().unwrap_or("failed").to_string()
                }
            ));
        }
    }
    if !runs(cc) {
        return Err(format!(
            "{}: the cross linker {cc} is missing (apt-get install {})",
            p.tuple, p.compiler_package
        ));
    }
    Ok(())
}

/// Builds the FMU's shared library for `p` (the host's without `--target`,
/// so that it is the one `cargo test --workspace` built).
///
/// # Errors
///
/// [`provision`]'s, or a failed build.
pub fn binary(root: &Path, p: Platform, profile: Profile) -> Result<Binary, String> {
    let host = Platform::host() == Some(p);
    if !host {
        provision(root, p)?;
    }
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
    let mut out = root.join("target");
    if !host {
        cmd.args(["--target", p.rust_target]);
        if let Some(cc) = p.cross_compiler {
            cmd.env(p.linker_variable(), cc);
        }
        out.push(p.rust_target);
    }
    let code = process::run(&mut cmd, Duration::from_secs(30 * 60));
    if code != Some(0) {
        return Err(format!("cargo build --package compensator-fmu for {} failed", p.tuple));
    }
    Ok(Binary {
        platform: p,
        path: out.join(dir).join(p.cargo_file),
    })
}

/// Builds `out_dir/compensator.fmu` for `version` with the parameter file
/// `params` (`None`: the paper preset) and a binary for each of
/// `platforms`; returns its path.
///
/// # Errors
///
/// A parameter file the chooser cannot configure a twin for, a platform
/// that cannot be built here (the reason and what to install), a failed
/// build, or a file that cannot be written.
pub fn build(
    root: &Path,
    params: Option<&Path>,
    version: FmiVersion,
    profile: Profile,
    out_dir: &Path,
    platforms: &[Platform],
) -> Result<PathBuf, String> {
    let binaries = platforms
        .iter()
        .map(|p| binary(root, *p, profile))
        .collect::<Result<Vec<_>, _>>()?;
    package(root, params, version, &binaries, out_dir)
}

/// The archive: the model description for `version` and the parameter
/// file `params` (`None`: the paper preset), and `binaries`.
///
/// # Errors
///
/// As [`build`].
pub fn package(
    root: &Path,
    params: Option<&Path>,
    version: FmiVersion,
    binaries: &[Binary],
    out_dir: &Path,
) -> Result<PathBuf, String> {
    let params_path = params.map_or_else(|| root.join("presets/paper.toml"), Path::to_path_buf);
    let text = std::fs::read_to_string(&params_path).map_err(|e| format!("{}: {e}", params_path.display()))?;
    let raw = compensator_params::file::parse(&text).map_err(|e| format!("{}: {e}", params_path.display()))?;
    let config = compensator_fmu::chosen_config(&raw)?;
    eprintln!(
        "xtask: FMU (FMI {}) for {}: the twin runs {}, {} substep(s) per {} s tick; binaries for {}",
        match version {
            FmiVersion::V2 => "2.0",
            FmiVersion::V3 => "3.0",
        },
        params_path.display(),
        config.scheme.name(),
        config.substeps,
        config.tick,
        binaries.iter().map(|b| b.platform.tuple).collect::<Vec<_>>().join(", ")
    );
    let xml = model_description(version, &raw, &config);
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let path = out_dir.join(format!("{MODEL_IDENTIFIER}.fmu"));
    let file = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let deflated = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let mut entries: Vec<(String, Vec<u8>)> = vec![("modelDescription.xml".into(), xml.into_bytes())];
    for b in binaries {
        let bytes = std::fs::read(&b.path).map_err(|e| format!("{}: {e}", b.path.display()))?;
        entries.push((b.platform.archive_path(version), bytes));
    }
    entries.push((
        format!("resources/{}", compensator_fmu::PARAMS_RESOURCE),
        text.into_bytes(),
    ));
    for (name, bytes) in entries {
        zip.start_file(name.as_str(), deflated)
            .and_then(|()| zip.write_all(&bytes).map_err(Into::into))
            .map_err(|e| format!("{}: {name}: {e}", path.display()))?;
    }
    zip.finish().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// The platforms `cargo xtask fmu-check` builds for and where each binary
/// runs: the host's natively, the aarch64 Linux one under qemu-user, the
/// Windows one under wine (its export table checked first).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Runner {
    Native,
    Qemu,
    Wine,
}

fn runner(p: Platform) -> Runner {
    match p.tuple {
        "aarch64-linux" => Runner::Qemu,
        "x86_64-windows" => Runner::Wine,
        _ => Runner::Native,
    }
}

/// The venv's python (`.ci/fmu-venv`), or `None` where python3's venv
/// module cannot be had (the check is skipped, saying so).
fn venv(root: &Path) -> Result<Option<PathBuf>, String> {
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
    Ok(Some(root.join(venv.stdout.trim())))
}

/// Runs a checking script; its output goes to the terminal, its last line
/// is the result.
fn script(cmd: &mut Command, what: &str, timeout: Duration) -> Result<String, String> {
    let t0 = Instant::now();
    let out = process::capture(cmd, timeout);
    eprint!("{}", out.stdout);
    if !out.ok() {
        eprint!("{}", out.stderr);
        return Err(format!("{what} failed"));
    }
    Ok(format!(
        "{what}: {} ({:.1} s)",
        out.stdout.lines().last().unwrap_or(""),
        t0.elapsed().as_secs_f64()
    ))
}

/// A path as a `&str` (every path here is the workspace's).
fn utf8(p: &Path) -> Result<&str, String> {
    p.to_str().ok_or_else(|| format!("{}: not UTF-8", p.display()))
}

/// Communication steps the importers are checked at [s], beside the tick:
/// sub-tick, between two counts of ticks, not a decimal fraction, and
/// libcosim's 1/3 ms (its clock counts whole nanoseconds).
const GRIDS: [(&str, f64); 4] = [
    ("0.1ms", 1e-4),
    ("2.5ms", 2.5e-3),
    ("third-ms", 1e-3 / 3.0),
    ("333333ns", 333_333e-9),
];

/// The check `cargo xtask test` runs, for FMI 2.0 and 3.0 with the paper
/// preset and a binary for every platform that can be built here (in CI:
/// all, or it fails):
///
/// * FMPy (`fmu/python/check_fmu.py`): `validate_fmu` on the
///   multi-platform archive; a step and a ramp against `compensator step
///   --precision f32`, and the step at each communication step of [`GRIDS`]
///   against the CLI run on the same grid; a variable step sequence
///   against the reference solver; state round trips; refusals;
/// * libcosim (`fmu/python/cosim_check.py`, FMI 2.0): the same step at the
///   tick and at every grid against the CLI;
/// * the circuit (`fmu/python/circuit.py`, FMI 2.0) against the reference
///   solution of the coupled circuit;
/// * each binary through the C driver (`fmu/c/driver.c`) where it runs:
///   natively, the aarch64 one under qemu-user, the Windows one under wine
///   after its export table; the outputs equal the host's to the bit.
///
/// Returns a summary line, or `None` when Python's venv cannot be had.
///
/// # Errors
///
/// A failed build, CLI run or check.
pub fn check(root: &Path) -> Result<Option<String>, String> {
    let started = Instant::now();
    let Some(python) = venv(root)? else { return Ok(None) };
    let venv_s = started.elapsed().as_secs_f64();
    let work = root.join("target/fmu/check");
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let params = root.join("presets/paper.toml");
    let raw = compensator_params::file::load(&params).map_err(|e| format!("{}: {e}", params.display()))?;
    let config = compensator_fmu::chosen_config(&raw)?;
    let (from, to, ramp) = ("30", "70", "200");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let cli = |name: &str, extra: &[String]| -> Result<PathBuf, String> {
        let out = work.join(name);
        let mut args: Vec<String> = [
            "run",
            "--quiet",
            "--package",
            "compensator-cli",
            "--",
            "step",
            "--params",
        ]
        .map(String::from)
        .into();
        args.extend(
            [
                utf8(&params)?,
                "--from",
                from,
                "--to",
                to,
                "--t-end",
                "0.3",
                "-o",
                utf8(&out)?,
            ]
            .map(String::from),
        );
        args.extend(extra.iter().cloned());
        if process::run(
            Command::new(&cargo).args(&args).current_dir(root),
            Duration::from_secs(600),
        ) != Some(0)
        {
            return Err(format!("compensator {}: failed", args[5..].join(" ")));
        }
        Ok(out)
    };
    let f32 = ["--precision".to_string(), "f32".into()];
    let step_csv = cli("step.csv", &f32)?;
    let ramp_csv = cli(
        "ramp.csv",
        &[f32[0].clone(), f32[1].clone(), "--ramp".into(), ramp.into()],
    )?;
    // The CLI on each grid: the tick h / ceil(h / tick) with the chosen
    // substeps, a row every communication step.
    let mut grid_args: Vec<String> = Vec::new();
    for (name, h) in GRIDS {
        let n = (h / config.tick - 1e-6).ceil().max(1.0);
        let csv = cli(
            &format!("grid-{name}.csv"),
            &[
                f32[0].clone(),
                f32[1].clone(),
                "--dt".into(),
                format!("{:?}", h / n),
                "--substeps".into(),
                config.substeps.to_string(),
                "--sample".into(),
                format!("{h:?}"),
            ],
        )?;
        grid_args.extend(["--grid".into(), format!("{h:?}"), utf8(&csv)?.to_string()]);
    }
    // The reference for the variable sequence (a row every 10 us).
    let reference_csv = cli(
        "reference.csv",
        &["--precision".into(), "reference".into(), "--dt".into(), "1e-5".into()],
    )?;
    let circuit_dir = work.join("circuit");
    if process::run(
        Command::new(&cargo)
            .args([
                "run",
                "--quiet",
                "--package",
                "compensator-fmu",
                "--example",
                "circuit_reference",
                "--",
            ])
            .arg(&circuit_dir)
            .current_dir(root),
        Duration::from_secs(1200),
    ) != Some(0)
    {
        return Err("cargo run --example circuit_reference failed".into());
    }

    // Every platform's binary, or why not.
    let ci = std::env::var("CI").is_ok_and(|v| v == "true");
    let mut binaries = Vec::new();
    let mut skipped = Vec::new();
    for p in PLATFORMS {
        match binary(root, p, Profile::Dev) {
            Ok(b) => binaries.push(b),
            Err(e) if !ci && Platform::host() != Some(p) => {
                eprintln!("xtask: SKIPPED the {} binary: {e}", p.tuple);
                skipped.push(p.tuple);
            }
            Err(e) => return Err(e),
        }
    }
    let mut summaries = Vec::new();
    let mut fmu2 = None;
    for version in [FmiVersion::V2, FmiVersion::V3] {
        let dir = work.join(match version {
            FmiVersion::V2 => "fmi2",
            FmiVersion::V3 => "fmi3",
        });
        let fmu = package(root, None, version, &binaries, &dir)?;
        summaries.push(script(
            Command::new(&python)
                .arg(root.join("fmu/python/check_fmu.py"))
                .arg(&fmu)
                .args(["--step-csv", utf8(&step_csv)?, "--ramp-csv", utf8(&ramp_csv)?])
                .args(["--from", from, "--to", to, "--ramp", ramp])
                .args(&grid_args)
                .args(["--reference-csv", utf8(&reference_csv)?])
                .args([
                    "--platforms",
                    &binaries.iter().map(|b| b.platform.tuple).collect::<Vec<_>>().join(","),
                ])
                .current_dir(&dir),
            &format!("FMPy, {}", fmu.display()),
            Duration::from_secs(600),
        )?);
        if version == FmiVersion::V2 {
            fmu2 = Some((fmu, dir));
        }
    }
    let (fmu, dir) = fmu2.ok_or("the FMI 2.0 FMU")?;
    summaries.push(script(
        Command::new(&python)
            .arg(root.join("fmu/python/cosim_check.py"))
            .arg(&fmu)
            .args(["--step-csv", utf8(&step_csv)?, "--from", from, "--to", to])
            .args(&grid_args)
            .current_dir(&dir),
        "libcosim",
        Duration::from_secs(600),
    )?);
    summaries.push(script(
        Command::new(&python)
            .arg(root.join("fmu/python/circuit.py"))
            .arg(&fmu)
            .arg(&circuit_dir)
            .args(["--steps", "1e-3", "1e-4", "--csv", utf8(&circuit_dir.join("fmu.csv"))?])
            .current_dir(&dir),
        "circuit",
        Duration::from_secs(600),
    )?);
    // The example of docs/fmu.md on the measured temperature history.
    let example = work.join("example.csv");
    script(
        Command::new(&python)
            .arg(root.join("fmu/python/drive_fmu.py"))
            .arg(&fmu)
            .arg(root.join("data/fmu/oil-temperature.csv"))
            .args(["--csv", utf8(&example)?, "--no-plot"])
            .current_dir(&dir),
        "fmu/python/drive_fmu.py",
        Duration::from_secs(120),
    )?;
    summaries.push(platforms::check(root, &work, &binaries)?);
    if !skipped.is_empty() {
        summaries.push(format!("SKIPPED: {}", skipped.join(", ")));
    }
    Ok(Some(format!(
        "{}; venv {venv_s:.1} s, all {:.0} s",
        summaries.join("; "),
        started.elapsed().as_secs_f64()
    )))
}

mod platforms {
    //! Each binary where it runs, through the C driver (`fmu/c/driver.c`).

    use super::{Binary, Runner, runner};
    use crate::process;
    use compensator_fmu::description::token;
    use std::path::{Path, PathBuf};
    use std::process::Command;
    use std::time::{Duration, Instant};

    /// The FMI functions a binary exports (`nm -D` of a shared object,
    /// `objdump -p`'s export table of a DLL), sorted.
    fn exports(b: &Binary) -> Result<Vec<String>, String> {
        let (tool, args): (&str, &[&str]) = match runner(b.platform) {
            Runner::Wine => ("x86_64-w64-mingw32-objdump", &["-p"]),
            _ => ("nm", &["-D", "--defined-only"]),
        };
        let out = process::capture(Command::new(tool).args(args).arg(&b.path), Duration::from_secs(60));
        if !out.ok() {
            return Err(format!("{tool} {}: {}", b.path.display(), out.stderr.trim()));
        }
        let mut names: Vec<String> = out
            .stdout
            .split_whitespace()
            .filter(|w| w.starts_with("fmi2") || w.starts_with("fmi3"))
            .map(String::from)
            .collect();
        names.sort();
        names.dedup();
        Ok(names)
    }

    /// The C driver built for `b`'s platform.
    fn driver(work: &Path, b: &Binary, source: &Path) -> Result<PathBuf, String> {
        let (cc, exe, libs): (&str, &str, &[&str]) = match runner(b.platform) {
            Runner::Native => ("cc", "driver", &["-ldl"]),
            Runner::Qemu => ("aarch64-linux-gnu-gcc", "driver-aarch64", &["-ldl"]),
            Runner::Wine => ("x86_64-w64-mingw32-gcc", "driver.exe", &[]),
        };
        let out = work.join(exe);
        let built = process::capture(
            Command::new(cc)
                .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O1"])
                .arg(source)
                .arg("-o")
                .arg(&out)
                .args(libs),
            Duration::from_secs(120),
        );
        if !built.ok() {
            return Err(format!("{cc} fmu/c/driver.c: {}", built.stderr.trim()));
        }
        Ok(out)
    }

    /// The driver's output for `b` (lines normalised: wine's C library
    /// writes CRLF).
    fn run(root: &Path, work: &Path, b: &Binary, resources: &Path, version: &str) -> Result<String, String> {
        let exe = driver(work, b, &root.join("fmu/c/driver.c"))?;
        let token = token();
        let mut cmd = match runner(b.platform) {
            Runner::Native => Command::new(&exe),
            Runner::Qemu => {
                let mut c = Command::new("qemu-aarch64");
                c.args(["-L", "/usr/aarch64-linux-gnu"]).arg(&exe);
                c
            }
            Runner::Wine => {
                // wine 8.0 (Debian 12) has no bcryptprimitives.dll, whose
                // ProcessPrng Rust's std imports on Windows: a shim beside
                // the driver (not shipped in the FMU).
                let shim = work.join("bcryptprimitives.dll");
                let built = process::capture(
                    Command::new("x86_64-w64-mingw32-gcc")
                        .args(["-Wall", "-Wextra", "-Werror", "-shared", "-O1", "-o"])
                        .arg(&shim)
                        .arg(root.join("fmu/c/bcryptprimitives.c"))
                        .arg("-ladvapi32"),
                    Duration::from_secs(120),
                );
                if !built.ok() {
                    return Err(format!("the wine shim: {}", built.stderr.trim()));
                }
                let mut c = Command::new("/usr/lib/wine/wine64");
                c.env("WINEDEBUG", "-all")
                    .env("WINEPREFIX", work.join("wine"))
                    .env("WINEDLLOVERRIDES", "mscoree,mshtml=")
                    .arg(&exe);
                c
            }
        };
        cmd.arg(&b.path).arg(resources).arg(&token).arg(version);
        let out = process::capture(&mut cmd, Duration::from_secs(600));
        if !out.ok() {
            return Err(format!(
                "the C driver on the {} binary (FMI {version}): {}{}",
                b.platform.tuple,
                out.stderr.trim(),
                if out.timed_out { " (timed out)" } else { "" }
            ));
        }
        Ok(out.stdout.replace("\r\n", "\n"))
    }

    /// What the platform check needs that may be missing, per runner.
    fn missing(r: Runner) -> Option<&'static str> {
        let has = |cmd: &str, arg: &str| {
            process::capture(Command::new(cmd).arg(arg), Duration::from_secs(60))
                .code
                .is_some()
        };
        match r {
            Runner::Native => (!has("cc", "--version")).then_some("cc (apt-get install gcc)"),
            Runner::Qemu => (!has("qemu-aarch64", "--version")).then_some("qemu-aarch64 (apt-get install qemu-user)"),
            Runner::Wine => {
                (!std::path::Path::new("/usr/lib/wine/wine64").exists()).then_some("wine64 (apt-get install wine64)")
            }
        }
    }

    /// Each binary through the C driver, FMI 2.0 and 3.0; the outputs equal
    /// the host's to the bit. Returns the summary.
    ///
    /// # Errors
    ///
    /// A driver that fails or differs, exports that differ from the host
    /// binary's; in CI also a runner that is missing.
    pub fn check(root: &Path, work: &Path, binaries: &[Binary]) -> Result<String, String> {
        let t0 = Instant::now();
        let ci = std::env::var("CI").is_ok_and(|v| v == "true");
        let resources = work.join("resources");
        std::fs::create_dir_all(&resources).map_err(|e| format!("{}: {e}", resources.display()))?;
        std::fs::copy(
            root.join("presets/paper.toml"),
            resources.join(compensator_fmu::PARAMS_RESOURCE),
        )
        .map_err(|e| format!("{}: {e}", resources.display()))?;
        let host = binaries
            .iter()
            .find(|b| runner(b.platform) == Runner::Native)
            .ok_or("no host binary")?;
        let want_exports = exports(host)?;
        let mut want = Vec::new();
        for version in ["2", "3"] {
            want.push(run(root, work, host, &resources, version)?);
        }
        let steps = want[0].lines().filter(|l| l.starts_with("0x")).count();
        let mut done = vec![format!("{} natively", host.platform.tuple)];
        for b in binaries.iter().filter(|b| runner(b.platform) != Runner::Native) {
            let got_exports = exports(b)?;
            if got_exports != want_exports {
                return Err(format!(
                    "the {} binary exports {} FMI functions, the host's {}",
                    b.platform.tuple,
                    got_exports.len(),
                    want_exports.len()
                ));
            }
            if let Some(what) = missing(runner(b.platform)) {
                if ci {
                    return Err(format!("running the {} binary needs {what}", b.platform.tuple));
                }
                eprintln!(
                    "xtask: SKIPPED running the {} binary: {what} is missing",
                    b.platform.tuple
                );
                done.push(format!("{} exports only", b.platform.tuple));
                continue;
            }
            for (version, want) in ["2", "3"].iter().zip(&want) {
                let got = run(root, work, b, &resources, version)?;
                if &got != want {
                    let at = got.lines().zip(want.lines()).position(|(a, b)| a != b).unwrap_or(0);
                    return Err(format!(
                        "the {} binary (FMI {version}) differs from the host's at line {}: {:?} vs {:?}",
                        b.platform.tuple,
                        at + 1,
                        got.lines().nth(at),
                        want.lines().nth(at)
                    ));
                }
            }
            done.push(format!(
                "{} {}",
                b.platform.tuple,
                match runner(b.platform) {
                    Runner::Qemu => "under qemu-aarch64",
                    _ => "under wine",
                }
            ));
        }
        let text = format!(
            "C driver: {} ({} exports, {steps} steps each, FMI 2.0 and 3.0, equal to the bit) ({:.1} s)",
            done.join(", "),
            want_exports.len(),
            t0.elapsed().as_secs_f64()
        );
        eprintln!("xtask: {text}");
        Ok(text)
    }
}
