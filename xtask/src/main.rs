//! `cargo xtask`: the project's automation.
//!
//! ```text
//! cargo xtask run [--params F] [--csv FILE]      the twin firmware on QEMU (the main job)
//! cargo xtask flash [--params F] [--csv FILE] [--debug] [--seconds S]
//!                                                build the board image, flash it with probe-rs
//! cargo xtask test [--bless]                     everything CI checks (the test command)
//! cargo xtask build [--params F]                 build every firmware image
//! cargo xtask fmu [--params F] [--fmi-version 2|3] [--out DIR] [--debug] [--platforms LIST]
//!                                                the twin as a co-simulation FMU (target/fmu/compensator.fmu)
//! cargo xtask fmu-check                          the FMU checked by FMPy, libcosim and on each platform (part of `test`)
//! cargo xtask bench [--params F] [--write]       cost (the twin as built for F), footprint and stack on the emulated MCUs
//! cargo xtask profile [--params F] [--core C]... [--top N]
//!                                                instructions per function of the twin's and the estimator's tick
//! cargo xtask callgrind [--bless]                host instruction counts against the baseline
//! cargo xtask msrv                               rust-version against the locked dependencies
//! cargo xtask target-tests                       the core's tests on the emulated Cortex-M4F
//! cargo xtask fuzz [--seconds N] [--runs N] [--jobs J] [--keep-going] [--target T]...
//!                                                the cargo-fuzz targets of fuzz/ (docs/fuzzing.md)
//! cargo xtask toolchain                          find or provision the cross toolchain
//! cargo xtask qemu-runner ELF [ARGS...]          run an ELF on QEMU (cargo runner for on-target tests)
//! ```
//!
//! Arguments are parsed by clap ([`Cli`]): an unknown command or flag (a
//! misspelt `--bles`) is an error with exit status 2, never ignored;
//! `cargo xtask help [COMMAND]` and `--help` describe each command.
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
mod cycles;
mod firmware;
mod flash;
mod fmu;
mod fuzz;
mod msrv;
mod panic_free;
mod params;
mod process;
mod profile;
mod qemu;
mod replica;
mod sweep_check;
mod telemetry;
mod toolchain;

use clap::{Args, Parser, Subcommand};
use std::ffi::OsString;
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

/// The command line of `cargo xtask`.
#[derive(Parser, Debug)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    about = "The project's automation: firmware builds, QEMU runs, benchmarks, CI",
    arg_required_else_help = true,
    after_help = "A parameter file (--params or COMPENSATOR_PARAMS) is relative to the current directory."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The parameter file of a firmware build.
#[derive(Args, Debug, Clone, PartialEq, Eq)]
struct ParamsArg {
    /// Parameter file (TOML, docs/model.md section 8), relative to the
    /// current directory [default: $COMPENSATOR_PARAMS, else the paper preset]
    #[arg(long, value_name = "F")]
    params: Option<String>,
}

#[derive(Subcommand, Debug, PartialEq, Eq)]
enum Command {
    /// Build the QEMU twin firmware and run it (the main job)
    Run {
        #[command(flatten)]
        params: ParamsArg,
        /// Also write the telemetry to FILE as CSV (every digit, SI units)
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
    },
    /// Build the board image and run it with probe-rs (RTT log, CSV)
    Flash {
        #[command(flatten)]
        params: ParamsArg,
        /// Also write the telemetry to FILE as CSV (every digit, SI units)
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        /// Build the dev profile (debug assertions; the board keeps its
        /// debug port clocked in sleep) instead of release
        #[arg(long)]
        debug: bool,
        /// Stop after S seconds (exit status 0) instead of running until Ctrl-C
        #[arg(long, value_name = "S")]
        seconds: Option<u64>,
    },
    /// Every check CI runs (host tests, clippy, cross builds, QEMU)
    Test {
        /// Rewrite the twin firmware's QEMU snapshot instead of checking it
        #[arg(long)]
        bless: bool,
    },
    /// Build every firmware image
    Build {
        #[command(flatten)]
        params: ParamsArg,
    },
    /// The twin as a co-simulation FMU for Modelica tools, Simulink, Hopsan, Python (docs/fmu.md)
    Fmu {
        #[command(flatten)]
        params: ParamsArg,
        /// FMI version: 2 (FMI 2.0, what Simulink, Hopsan and OpenModelica import most
        /// reliably) or 3 (FMI 3.0)
        #[arg(long, value_name = "2|3", default_value = "2", value_parser = ["2", "3"])]
        fmi_version: String,
        /// Folder to write compensator.fmu to, relative to the current directory
        /// [default: target/fmu]
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Build the binary with the dev profile (quicker; debug assertions on;
        /// the same f32 arithmetic) instead of release
        #[arg(long)]
        debug: bool,
        /// Platforms to carry a binary for, comma-separated FMI 3.0 platform tuples
        /// (cross builds need rustup's target and the C cross compiler: docs/fmu.md)
        /// [default: the host's]
        #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = ["x86_64-linux", "x86_64-windows", "aarch64-linux"])]
        platforms: Vec<String>,
    },
    /// The FMU (FMI 2.0 and 3.0, every platform) checked by FMPy and libcosim in a venv and
    /// by a C driver on each platform (part of `test`)
    FmuCheck,
    /// A sweep's shards mapped over a Dask LocalCluster, merged and compared with the single run (part of `test`)
    SweepCheck,
    /// Instructions per tick (the twin as built for F), flash, RAM and stack
    Bench {
        #[command(flatten)]
        params: ParamsArg,
        /// Also write the report to docs/bench.md
        #[arg(long)]
        write: bool,
    },
    /// Instructions per function of the twin's and the estimator's tick on the
    /// emulated cores (every executed instruction, from QEMU's trace)
    Profile {
        #[command(flatten)]
        params: ParamsArg,
        /// Cores to profile (repeatable) [default: all three]
        #[arg(long = "core", value_name = "C", value_parser = ["m4f", "m3", "m0"])]
        cores: Vec<String>,
        /// Functions listed per section and in its worst tick (at least 1)
        #[arg(long, value_name = "N", default_value_t = 15, value_parser = clap::value_parser!(u16).range(1..))]
        top: u16,
    },
    /// Host instruction counts (valgrind) against the baseline
    Callgrind {
        /// Rewrite the baseline instead of checking against it
        #[arg(long)]
        bless: bool,
    },
    /// The workspace's rust-version against the locked dependencies
    Msrv,
    /// The core's tests on the emulated Cortex-M4F (defmt-test)
    TargetTests,
    /// The cargo-fuzz targets of fuzz/, each for a bounded time or number
    /// of executions (docs/fuzzing.md; installs cargo-fuzz if missing)
    Fuzz {
        /// Seconds per target [default: 30 unless --runs or a --target T=N is given]
        #[arg(long, value_name = "N")]
        seconds: Option<u64>,
        /// Executions per target
        #[arg(long, value_name = "N")]
        runs: Option<u64>,
        /// Parallel fuzzing processes per target (libFuzzer -fork)
        #[arg(long, value_name = "J", default_value_t = 0)]
        jobs: u32,
        /// Go on after a crash, collecting every crash input (fails at the end)
        #[arg(long)]
        keep_going: bool,
        /// Only this target, T or T=N for N executions of it (repeatable, run
        /// in this order) [default: all]
        #[arg(long = "target", value_name = "T")]
        targets: Vec<String>,
    },
    /// Find or provision the thumbv7em/thumbv7m toolchain
    Toolchain,
    /// Run an ELF on QEMU (netduinoplus2, or netduino2 for thumbv7m)
    QemuRunner {
        /// The ELF to run
        elf: PathBuf,
        /// What cargo passes after the ELF as a runner (the test binary's
        /// arguments): accepted and not used
        #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
        args: Vec<OsString>,
    },
}

fn main() -> ExitCode {
    // Usage errors (an unknown command or flag, a missing value) exit 2
    // with clap's message; `--help` exits 0.
    let cli = Cli::try_parse().unwrap_or_else(|e| e.exit());
    let result: Outcome = match cli.command {
        Command::Run { params, csv } => cmd_run(&params, csv.as_deref()),
        Command::Flash {
            params,
            csv,
            debug,
            seconds,
        } => params_file(&params)
            .and_then(|params| flash::cmd(&root(), params.as_deref(), csv.as_deref(), debug, seconds)),
        Command::Test { bless } => cmd_test(bless),
        Command::Bench { params, write } => cmd_bench(&params, write),
        Command::Build { params } => cmd_build(&params),
        Command::Fmu {
            params,
            fmi_version,
            out,
            debug,
            platforms,
        } => cmd_fmu(&params, &fmi_version, out.as_deref(), debug, &platforms),
        Command::FmuCheck => cmd_fmu_check(),
        Command::SweepCheck => cmd_sweep_check(),
        Command::Msrv => msrv::check(&root()).map(|_| 0).map_err(Failure::from),
        Command::Toolchain => toolchain::get(&root(), &firmware::TARGETS)
            .map(|t| {
                println!("{}", t.description);
                0
            })
            .map_err(Failure::from),
        Command::QemuRunner { elf, args: _ } => cmd_qemu_runner(&elf),
        Command::Profile { params, cores, top } => cmd_profile(&params, &cores, usize::from(top)),
        Command::Callgrind { bless } => callgrind::check(&root(), bless).map(|_| 0).map_err(Failure::from),
        Command::Fuzz {
            seconds,
            runs,
            jobs,
            keep_going,
            targets,
        } => {
            let opts = fuzz::Options {
                // 30 s unless executions bound the run (--runs or T=N).
                seconds: seconds.or(if runs.is_none() && !targets.iter().any(|t| t.contains('=')) {
                    Some(30)
                } else {
                    None
                }),
                runs,
                jobs,
                keep_going,
                targets,
            };
            fuzz::run(&root(), &opts).map(|_| 0).map_err(Failure::from)
        }
        Command::TargetTests => toolchain::get(&root(), &[firmware::M4])
            .and_then(|tc| qemu::ensure().and_then(|_| firmware::on_target_tests(&tc, &root())))
            .map(|_| 0)
            .map_err(Failure::from),
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

/// The parameter file of a build (`--params`, else `COMPENSATOR_PARAMS`),
/// resolved against the current directory and checked: an absolute path,
/// or `None` for the default preset.
fn params_file(arg: &ParamsArg) -> Result<Option<PathBuf>, Failure> {
    params::from_args(arg.params.as_deref()).map_err(Failure::Input)
}

/// The main job: the twin firmware on QEMU's STM32F405, log decoded live
/// (telemetry rounded for reading; `--csv FILE`: every digit, SI units).
fn cmd_run(params: &ParamsArg, csv_path: Option<&Path>) -> Outcome {
    let root = root();
    let params = params_file(params)?;
    // Created before the build: a path that cannot be written fails fast.
    let mut csv = match csv_path {
        Some(p) => Some(telemetry::CsvFile::create(p).map_err(Failure::Input)?),
        None => None,
    };
    let tc = toolchain::get(&root, &[firmware::M4])?;
    eprintln!("xtask: toolchain: {}", tc.description);
    qemu::ensure()?;
    let elf = firmware::build(&tc, &root, &firmware::Image::TWIN, params.as_deref())?;
    eprintln!("xtask: running {} on QEMU {}", elf.display(), qemu::NETDUINO.name);
    let run = qemu::run(&elf, qemu::NETDUINO, true, Duration::from_secs(300), qemu::Show::Stream)?;
    if let (Some(csv), Some(p)) = (csv.as_mut(), csv_path) {
        for line in &run.lines {
            csv.line(line)?;
        }
        eprintln!("xtask: wrote {} telemetry records to {}", csv.rows, p.display());
    }
    eprintln!("xtask: firmware exit code {}", run.code);
    Ok(run.code)
}

/// `cargo xtask profile [--params F] [--core C]... [--top N]`.
fn cmd_profile(params: &ParamsArg, cores: &[String], top: usize) -> Outcome {
    let params = params_file(params)?;
    let mut targets: Vec<&'static str> = Vec::new();
    for c in cores {
        let t = match c.as_str() {
            "m3" => firmware::M3,
            "m0" => firmware::M0,
            _ => firmware::M4,
        };
        // A core named twice is profiled once.
        if !targets.contains(&t) {
            targets.push(t);
        }
    }
    if targets.is_empty() {
        targets = firmware::TARGETS.to_vec();
    }
    let root = root();
    qemu::ensure()?;
    let tc = toolchain::get(&root, &targets)?;
    profile::cmd(&tc, &root, params.as_deref(), &targets, top)?;
    Ok(0)
}

/// `cargo xtask build [--params F]`.
fn cmd_build(params: &ParamsArg) -> Outcome {
    let params = params_file(params)?;
    firmware::build_all(&root(), params.as_deref())?;
    Ok(0)
}

/// `cargo xtask fmu [--params F] [--fmi-version 2|3] [--out DIR] [--debug] [--platforms LIST]`.
fn cmd_fmu(params: &ParamsArg, fmi_version: &str, out: Option<&Path>, debug: bool, platforms: &[String]) -> Outcome {
    let params = params_file(params)?;
    let version = match fmi_version {
        "3" => compensator_fmu::description::FmiVersion::V3,
        _ => compensator_fmu::description::FmiVersion::V2,
    };
    let root = root();
    let out = match out {
        Some(o) => std::env::current_dir().map_err(|e| e.to_string())?.join(o),
        None => root.join("target/fmu"),
    };
    let profile = if debug {
        fmu::Profile::Dev
    } else {
        fmu::Profile::Release
    };
    let platforms = if platforms.is_empty() {
        vec![compensator_fmu::platforms::Platform::host().ok_or(
            "this host is none of the FMU's platforms (x86_64-linux, x86_64-windows, aarch64-linux): name them with --platforms",
        )?]
    } else {
        platforms
            .iter()
            .filter_map(|p| compensator_fmu::platforms::Platform::named(p))
            .collect()
    };
    let path = fmu::build(&root, params.as_deref(), version, profile, &out, &platforms)?;
    println!("{}", path.display());
    Ok(0)
}

/// `cargo xtask fmu-check`: what `cargo xtask test` checks of the FMU.
fn cmd_fmu_check() -> Outcome {
    if let Some(summary) = fmu::check(&root())? {
        eprintln!("xtask: {summary}");
    }
    Ok(0)
}

/// `cargo xtask sweep-check`: what `cargo xtask test` checks of the
/// sweep's scale-out recipe.
fn cmd_sweep_check() -> Outcome {
    if let Some(summary) = sweep_check::check(&root())? {
        eprintln!("xtask: {summary}");
    }
    Ok(0)
}

/// cargo runner: `xtask qemu-runner ELF [args...]` (the arguments after the
/// ELF are the test binary's; QEMU runs the image as it is).
fn cmd_qemu_runner(elf: &Path) -> Outcome {
    let run = qemu::run(
        elf,
        qemu::machine_of(elf),
        true,
        Duration::from_secs(300),
        qemu::Show::Stream,
    )?;
    Ok(run.code)
}

/// Runs this xtask again with the `host` feature (the commands that need
/// the host-side crates), with `args`.
#[cfg_attr(feature = "host", allow(dead_code))]
fn with_host_feature(args: &[OsString], timeout: Duration) -> Outcome {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = std::process::Command::new(cargo);
    cmd.args(["run", "--quiet", "--package", "xtask", "--features", "host", "--"])
        .args(args)
        .current_dir(root());
    process::run(&mut cmd, timeout).ok_or_else(|| {
        let shown: Vec<_> = args.iter().map(|a| a.to_string_lossy()).collect();
        Failure::Other(format!("xtask --features host {} failed", shown.join(" ")))
    })
}

/// `cargo xtask bench [--params F] [--write]`. The parameter file is
/// resolved and checked here, against the user's directory: without the
/// `host` feature the bench runs in a second xtask whose directory is the
/// workspace root, and gets the absolute path.
fn cmd_bench(params: &ParamsArg, write: bool) -> Outcome {
    let params = params_file(params)?;
    #[cfg(feature = "host")]
    {
        Ok(bench::cmd(&root(), params.as_deref(), write)?)
    }
    #[cfg(not(feature = "host"))]
    {
        let mut args: Vec<OsString> = vec!["bench".into()];
        if let Some(p) = params {
            args.push("--params".into());
            args.push(p.into_os_string());
        }
        if write {
            args.push("--write".into());
        }
        with_host_feature(&args, Duration::from_secs(3600))
    }
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
/// the validated range 20-95 C (the reported file that made `build.rs`
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

/// The twin's peak stack on QEMU must stay within this \[bytes\] (as the
/// bench's budget for the RTD device).
const TWIN_STACK_BUDGET: u64 = 6 << 10;

/// The same for the twin built with the condition monitor: the estimator
/// carries the monitor's state (the probe's lag of 11 signals through two
/// stages, the 6-state health filter, a reading's pending stages), which
/// start-up builds on its frames before it moves in: 6,848 bytes measured
/// for `presets/paper-monitor.toml`, of the STM32F405's 128 KiB \[bytes\].
const TWIN_MONITOR_STACK_BUDGET: u64 = 7 << 10;

/// The soak image built for the NTC preset (`presets/paper-ntc.toml`: the
/// NTC on the STM32F4's ADC, simulated at register level), run on QEMU: it
/// exits 0 (no check violated; the host soak of `host-tests/tests/soak.rs`
/// runs the same walk).
fn ntc_soak(tc: &toolchain::Toolchain, root: &Path, timeout: Duration) -> Result<(), String> {
    let file = root.join("presets/paper-ntc.toml");
    let elf = firmware::build(tc, root, &firmware::Image::SOAK, Some(&file))?;
    let started = std::time::Instant::now();
    let run = qemu::run(&elf, qemu::NETDUINO, false, timeout, qemu::Show::Quiet).map_err(|e| e.to_string())?;
    if run.code != 0 {
        for l in &run.lines {
            eprintln!("{l}");
        }
        return Err(format!(
            "the soak built for {} exited with {} (124: past its deadline)",
            file.display(),
            run.code
        ));
    }
    eprintln!(
        "xtask: NTC {} ({:.0} s)",
        run.lines
            .iter()
            .rev()
            .find(|l| l.contains("soak:"))
            .map_or("", String::as_str),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The twin built for a preset, run on QEMU: its self-checks pass, its
/// peak stack is within [`TWIN_STACK_BUDGET`] ([`TWIN_MONITOR_STACK_BUDGET`]
/// for the `monitor` label), its output matches its
/// snapshot (`tests/snapshots/<snapshot>.log`; `bless` rewrites it) when
/// it has one, and its telemetry is the host replica's, row by row;
/// nothing reachable from its tick paths, nor from the board image's built
/// for the same file, panics. `label` names the preset in the messages
/// (`NTC`, `monitor`).
fn preset_twin(
    tc: &toolchain::Toolchain,
    root: &Path,
    timeout: Duration,
    preset: &str,
    label: &str,
    snapshot: Option<(&str, bool)>,
) -> Result<(), String> {
    let file = root.join(preset);
    let built = firmware::build_with(
        tc,
        root,
        &firmware::Image::TWIN,
        firmware::Options {
            params: Some(&file),
            debug: false,
        },
    )?;
    let run = qemu::run(&built.elf, qemu::NETDUINO, true, timeout, qemu::Show::Quiet).map_err(|e| e.to_string())?;
    if run.code != 0 {
        for l in &run.lines {
            eprintln!("{}", telemetry::humanize(l));
        }
        return Err(format!(
            "the twin built for {} exited with {}",
            file.display(),
            run.code
        ));
    }
    let stack = run
        .lines
        .iter()
        .find_map(|l| {
            l.split("[measure] peak stack ")
                .nth(1)?
                .split_whitespace()
                .next()?
                .parse::<u64>()
                .ok()
        })
        .ok_or(format!("the {label} twin reported no peak stack"))?;
    let budget = if label == "monitor" {
        TWIN_MONITOR_STACK_BUDGET
    } else {
        TWIN_STACK_BUDGET
    };
    if stack > budget {
        return Err(format!("the {label} twin's peak stack {stack} bytes exceeds {budget}"));
    }
    if let Some((name, bless)) = snapshot {
        let shown: Vec<String> = run.lines.iter().map(|l| telemetry::humanize(l)).collect();
        firmware::check_snapshot(root, name, &shown, bless)?;
    }
    let csv_path = root.join(format!("target/xtask/twin-{}-telemetry.csv", label.to_lowercase()));
    let mut csv = telemetry::CsvFile::create(&csv_path)?;
    for line in &run.lines {
        csv.line(line)?;
    }
    drop(csv);
    let decoded = telemetry::read_csv(&csv_path)?;
    let schedule = replica::read_schedule(built.out_dir.as_deref().ok_or("no build script output directory")?)?;
    let raw = compensator_params::file::load(&file).map_err(|e| e.to_string())?;
    let host = replica::run(&raw, &schedule)?;
    eprintln!(
        "xtask: the {label} twin passed: {}; peak stack {stack} bytes; {}",
        run.lines
            .iter()
            .rev()
            .find(|l| l.contains("checks:"))
            .map_or("", String::as_str),
        replica::compare(&decoded, &host)?
    );
    // Its tick paths, on QEMU and on the board (the sensor's registers),
    // link no panic either.
    eprintln!(
        "xtask: {label} twin: {}",
        panic_free::check(&built.elf, &["tick_path", "telemetry_path"], &[])?
    );
    let board = firmware::build(tc, root, &firmware::Image::BOARD, Some(&file))?;
    eprintln!(
        "xtask: {label} board: {}",
        panic_free::check(&board, &["tick_path"], &["_defmt_acquire", "_defmt_release"])?
    );
    Ok(())
}

/// Everything CI checks; `bless` rewrites the twin's QEMU snapshot.
fn cmd_test(bless: bool) -> Outcome {
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
    step("fuzzing: every cargo-fuzz target of fuzz/ for 25 s (cargo xtask fuzz --seconds 25)");
    fuzz::run(
        &root,
        &fuzz::Options {
            seconds: Some(25),
            runs: None,
            jobs: 0,
            keep_going: false,
            targets: Vec::new(),
        },
    )?;
    step(
        "FMU: FMI 2.0 and 3.0 for three platforms (cargo xtask fmu), checked by FMPy and libcosim against compensator step and the reference, each binary where it runs",
    );
    if let Some(summary) = fmu::check(&root)? {
        eprintln!("xtask: {summary}");
    }
    step("sweep: shards mapped over a Dask LocalCluster, merged and compared with the single run");
    if let Some(summary) = sweep_check::check(&root)? {
        eprintln!("xtask: {summary}");
    }
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
    step(
        "an NTC device file (presets/paper-ntc.toml) builds the twin and the board; on QEMU the twin passes its checks within the stack budget and matches the host replica; neither tick links a panic",
    );
    preset_twin(&tc, &root, minutes(5), "presets/paper-ntc.toml", "NTC", None)?;
    step(
        "a device file with the condition monitor's second sensor (presets/paper-monitor.toml) builds the twin and the board with the monitor; on QEMU the twin reads its transducer, passes its checks within the stack budget, matches its snapshot and the host replica; neither tick links a panic",
    );
    preset_twin(
        &tc,
        &root,
        minutes(5),
        "presets/paper-monitor.toml",
        "monitor",
        Some(("twin-monitor", bless)),
    )?;
    step(
        "QEMU: the soak built for the NTC device file (presets/paper-ntc.toml: its sensor behind its driver, every tick checked)",
    );
    ntc_soak(&tc, &root, minutes(3))?;
    step("a parameter file the CLI refuses fails the firmware build in one line naming the field");
    firmware::check_refused_file(&tc, &root)?;
    step("firmware images (the Cortex-M4F bench and the board for the monitor's preset first, kept apart)");
    let monitor = bench::monitor_images(&tc, &root, None)?;
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
    let schedule = replica::read_schedule(twin.out_dir.as_deref().ok_or("no build script output directory")?)?;
    let raw = compensator_params::file::load(&root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let host = replica::run(&raw, &schedule)?;
    eprintln!("xtask: {}: {}", csv_path.display(), replica::compare(&decoded, &host)?);
    step(
        "QEMU: the whole estimator with a Q12.20 twin on the Cortex-M3 (netduino2) and the Cortex-M0 (microbit): the replay and its self-checks",
    );
    let mut twin_runs = vec![(firmware::Image::TWIN, run.lines.clone())];
    for img in [firmware::Image::TWIN_M3, firmware::Image::TWIN_M0] {
        let elf = &elfs
            .iter()
            .find(|(i, _)| *i == img)
            .ok_or("no fixed-point twin image")?
            .1;
        let started = std::time::Instant::now();
        let r = qemu::run(elf, img.machine(), true, minutes(5), qemu::Show::Quiet)?;
        if r.code != 0 {
            for l in &r.lines {
                eprintln!("{}", telemetry::humanize(l));
            }
            return Err(format!(
                "the twin on {} ({}) exited with {}",
                img.target,
                img.machine().name,
                r.code
            )
            .into());
        }
        eprintln!(
            "xtask: the twin on {} ({}) passed: {} ({:.0} s)",
            img.target,
            img.machine().name,
            r.lines
                .iter()
                .rev()
                .find(|l| l.contains("checks:"))
                .map_or("", String::as_str),
            started.elapsed().as_secs_f64()
        );
        twin_runs.push((img, r.lines));
    }
    step("QEMU: the soak (1e6 ticks of a seeded walk with injected sensor faults, every tick checked)");
    let soak = &elfs
        .iter()
        .find(|(i, _)| *i == firmware::Image::SOAK)
        .ok_or("no soak image")?
        .1;
    let started = std::time::Instant::now();
    let soak_run = qemu::run(soak, qemu::NETDUINO, false, minutes(3), qemu::Show::Quiet)?;
    if soak_run.code != 0 {
        for l in &soak_run.lines {
            eprintln!("{l}");
        }
        return Err(format!("the soak exited with {} (124: past its deadline)", soak_run.code).into());
    }
    eprintln!(
        "xtask: {} ({:.0} s)",
        soak_run
            .lines
            .iter()
            .rev()
            .find(|l| l.contains("soak:"))
            .map_or("", String::as_str),
        started.elapsed().as_secs_f64()
    );
    step("QEMU: a HardFault reports and exits 1 at once");
    let fault = firmware::build(&tc, &root, &firmware::Image::FAULT, None)?;
    flash::check_fault_report(&fault)?;
    step("board image: stack in CCM below nothing, no debug logging compiled in");
    let board = &elfs.iter().find(|(i, _)| i.bin == "board").ok_or("no board image")?.1;
    flash::check_board_layout(board)?;
    for (img, elf) in &elfs {
        flash::check_no_debug_logs(elf).map_err(|e| format!("{} ({}): {e}", img.bin, img.target))?;
    }
    step(
        "the tick links no panic: nothing reachable from the images' tick_path (and the twin's telemetry_path) panics",
    );
    eprintln!(
        "xtask: twin: {}",
        panic_free::check(&twin.elf, &["tick_path", "telemetry_path"], &[])?
    );
    let board = &elfs.iter().find(|(i, _)| i.bin == "board").ok_or("no board image")?.1;
    // defmt-rtt's acquire/release panic if the logger is taken re-entrantly;
    // the board logs from `main` only (never from an interrupt).
    eprintln!(
        "xtask: board: {}",
        panic_free::check(board, &["tick_path"], &["_defmt_acquire", "_defmt_release"])?
    );
    step("QEMU: the core's tests on the emulated Cortex-M4F");
    firmware::on_target_tests(&tc, &root)?;
    step("QEMU: cost, footprint and stack budgets");
    bench::check(&elfs, &twin_runs, &monitor)?;
    step("QEMU: the profile runner on the Cortex-M4F (instructions per function, docs/profile.md)");
    profile::cmd(&tc, &root, None, &[firmware::M4], 5)?;
    eprintln!("\nxtask: all checks passed");
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use clap::error::ErrorKind;

    fn parse(args: &[&str]) -> Result<Command, ErrorKind> {
        Cli::try_parse_from(std::iter::once("xtask").chain(args.iter().copied()))
            .map(|c| c.command)
            .map_err(|e| e.kind())
    }

    #[test]
    fn the_parser_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn every_command_and_flag_parses() {
        let params = |p: Option<&str>| ParamsArg {
            params: p.map(String::from),
        };
        assert_eq!(parse(&["test"]), Ok(Command::Test { bless: false }));
        assert_eq!(parse(&["test", "--bless"]), Ok(Command::Test { bless: true }));
        assert_eq!(
            parse(&["run", "--params", "presets/paper.toml", "--csv", "out.csv"]),
            Ok(Command::Run {
                params: params(Some("presets/paper.toml")),
                csv: Some("out.csv".into()),
            })
        );
        assert_eq!(
            parse(&["flash", "--debug", "--seconds", "60", "--params=f.toml"]),
            Ok(Command::Flash {
                params: params(Some("f.toml")),
                csv: None,
                debug: true,
                seconds: Some(60),
            })
        );
        assert_eq!(parse(&["build"]), Ok(Command::Build { params: params(None) }));
        assert_eq!(
            parse(&["bench", "--write", "--params", "f.toml"]),
            Ok(Command::Bench {
                params: params(Some("f.toml")),
                write: true,
            })
        );
        assert_eq!(
            parse(&["profile", "--core", "m0", "--core", "m4f", "--top", "3"]),
            Ok(Command::Profile {
                params: params(None),
                cores: vec!["m0".into(), "m4f".into()],
                top: 3,
            })
        );
        assert_eq!(parse(&["profile", "--core", "m7"]), Err(ErrorKind::InvalidValue));
        assert_eq!(parse(&["profile", "--top", "0"]), Err(ErrorKind::ValueValidation));
        assert_eq!(
            parse(&["fmu"]),
            Ok(Command::Fmu {
                params: params(None),
                fmi_version: "2".into(),
                out: None,
                debug: false,
                platforms: vec![],
            })
        );
        assert_eq!(
            parse(&[
                "fmu",
                "--params",
                "f.toml",
                "--fmi-version",
                "3",
                "--out",
                "dist",
                "--debug",
                "--platforms",
                "x86_64-linux,aarch64-linux"
            ]),
            Ok(Command::Fmu {
                params: params(Some("f.toml")),
                fmi_version: "3".into(),
                out: Some("dist".into()),
                debug: true,
                platforms: vec!["x86_64-linux".into(), "aarch64-linux".into()],
            })
        );
        assert_eq!(parse(&["fmu-check"]), Ok(Command::FmuCheck));
        assert_eq!(parse(&["sweep-check"]), Ok(Command::SweepCheck));
        assert_eq!(parse(&["callgrind", "--bless"]), Ok(Command::Callgrind { bless: true }));
        assert_eq!(parse(&["msrv"]), Ok(Command::Msrv));
        assert_eq!(parse(&["toolchain"]), Ok(Command::Toolchain));
        assert_eq!(parse(&["target-tests"]), Ok(Command::TargetTests));
        assert_eq!(
            parse(&["fuzz", "--seconds", "60", "--target", "twin", "--target", "estimator"]),
            Ok(Command::Fuzz {
                seconds: Some(60),
                runs: None,
                jobs: 0,
                keep_going: false,
                targets: vec!["twin".into(), "estimator".into()],
            })
        );
        // As a cargo runner: whatever follows the ELF is the test binary's.
        assert_eq!(
            parse(&["qemu-runner", "target/x.elf", "--quiet", "-x"]),
            Ok(Command::QemuRunner {
                elf: "target/x.elf".into(),
                args: vec!["--quiet".into(), "-x".into()],
            })
        );
    }

    #[test]
    fn misspelt_or_unknown_arguments_are_errors() {
        // The reported case: `test --bles` used to run the tests without blessing.
        assert_eq!(parse(&["test", "--bles"]), Err(ErrorKind::UnknownArgument));
        assert_eq!(parse(&["bench", "--wrte"]), Err(ErrorKind::UnknownArgument));
        assert_eq!(parse(&["run", "extra"]), Err(ErrorKind::UnknownArgument));
        assert_eq!(parse(&["msrv", "--bless"]), Err(ErrorKind::UnknownArgument));
        assert_eq!(parse(&["tset"]), Err(ErrorKind::InvalidSubcommand));
        // A flag where a value belongs, a value that is not one.
        assert_eq!(parse(&["run", "--params", "--csv", "x"]), Err(ErrorKind::InvalidValue));
        assert_eq!(parse(&["flash", "--seconds", "soon"]), Err(ErrorKind::ValueValidation));
        assert_eq!(parse(&["qemu-runner"]), Err(ErrorKind::MissingRequiredArgument));
        assert_eq!(parse(&["fmu", "--fmi-version", "1"]), Err(ErrorKind::InvalidValue));
        assert_eq!(parse(&["fmu", "--platforms", "win64"]), Err(ErrorKind::InvalidValue));
        // No command: the help, as an error (exit status 2).
        assert_eq!(parse(&[]), Err(ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand));
    }
}
