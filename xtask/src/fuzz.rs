//! `cargo xtask fuzz`: the libFuzzer targets of `fuzz/` (docs/fuzzing.md),
//! each for a bounded time or number of executions.
//!
//! * cargo-fuzz: used if installed (on `PATH` or under `target/tools`),
//!   else `cargo install cargo-fuzz --version CARGO_FUZZ --locked --root
//!   target/tools` within a deadline (crates.io), kept with the build
//!   cache; a failed install is an error that says so.
//! * The build: `cargo fuzz build --release --debug-assertions --sanitizer
//!   none` with `RUSTC_BOOTSTRAP=1` on the workspace's stable toolchain
//!   (cargo-fuzz's coverage flags are nightly-only; no nightly is needed,
//!   nor rustup). Debug assertions and overflow checks stay on; no
//!   sanitizer: the core has no `unsafe` (it forbids `unsafe_op_in_unsafe_fn`
//!   and has none), what is looked for is panics and broken promises.
//! * The runs: `cargo fuzz run` per target with the committed seeds
//!   (`fuzz/corpus/<target>`, read only) and the findings' inputs
//!   (`fuzz/artifacts/<target>`, read only) behind a working corpus under
//!   `target/fuzz/corpus/<target>` (where libFuzzer adds what it finds),
//!   crash inputs under `target/fuzz/artifacts/<target>/`, libFuzzer's log
//!   under `target/fuzz/logs/<target>.log`. A crash fails the command
//!   with the input's path, the panic message and the command that
//!   replays it.
//!
//! The summary (executions, coverage, corpus, crashes per target) is a
//! Markdown table, the one docs/fuzzing.md records for the long run.

use crate::process;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The targets, in the order they run.
pub const TARGETS: [&str; 4] = ["params_file", "raw_params", "twin", "estimator"];

/// The cargo-fuzz installed when none is: the newest on crates.io when
/// this was written, built by Rust 1.93-1.95.
pub const CARGO_FUZZ: &str = "0.13.2";

/// What to run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// Seconds per target (libFuzzer `-max_total_time`).
    pub seconds: Option<u64>,
    /// Executions per target (libFuzzer `-runs`).
    pub runs: Option<u64>,
    /// Parallel fuzzing processes per target (libFuzzer `-fork`); with
    /// `keep_going`, at least one.
    pub jobs: u32,
    /// Go on after a crash (libFuzzer `-ignore_crashes=1`, in fork mode),
    /// collecting every crash input; the command still fails at the end.
    pub keep_going: bool,
    /// The targets, in the order they run (all of [`TARGETS`] when
    /// empty), each `T` or `T=N`: `N` executions of `T` instead of `runs`
    /// (the long run weights the fast targets this way).
    pub targets: Vec<String>,
}

/// One target's run, from libFuzzer's log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// The target.
    pub target: String,
    /// Inputs executed.
    pub runs: u64,
    /// Wall time [s].
    pub seconds: f64,
    /// Coverage: edges (`cov`) and features (`ft`) at the end.
    pub cov: u64,
    /// See `cov`.
    pub ft: u64,
    /// Inputs in the corpus at the end.
    pub corpus: u64,
    /// Crash inputs written.
    pub crashes: Vec<PathBuf>,
}

/// Where cargo-fuzz is installed when it is missing (`cargo install
/// --root`), with its build cache beside it: under `target/`, so that CI
/// keeps it with the build cache and reruns skip the install.
pub const TOOLS: &str = "target/tools";

/// `PATH` with `root/TOOLS/bin` first (a cargo-fuzz installed there wins).
fn tools_path(root: &Path) -> std::ffi::OsString {
    let bin = root.join(TOOLS).join("bin");
    let rest = std::env::var_os("PATH").unwrap_or_default();
    std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(&rest))).unwrap_or(rest)
}

/// `cargo fuzz`, installing it under [`TOOLS`] if missing.
fn ensure_cargo_fuzz(cargo: &str, root: &Path) -> Result<(), String> {
    let version = process::capture(
        Command::new(cargo)
            .env("PATH", tools_path(root))
            .args(["fuzz", "--version"]),
        Duration::from_secs(60),
    );
    if version.ok() {
        eprintln!("xtask: {}", version.stdout.trim());
        return Ok(());
    }
    let tools = root.join(TOOLS);
    eprintln!(
        "xtask: cargo-fuzz is not installed: cargo install cargo-fuzz --version {CARGO_FUZZ} --locked --root {}",
        tools.display()
    );
    let installed = process::run(
        Command::new(cargo)
            .args(["install", "cargo-fuzz", "--version", CARGO_FUZZ, "--locked", "--root"])
            .arg(&tools)
            .arg("--target-dir")
            .arg(tools.join("build")),
        Duration::from_secs(15 * 60),
    );
    if installed != Some(0) {
        return Err(format!(
            "cargo-fuzz is missing and `cargo install cargo-fuzz --version {CARGO_FUZZ} --locked` failed \
             (exit {installed:?}, deadline 15 min): the fuzz targets cannot run"
        ));
    }
    Ok(())
}

/// The flags of `cargo fuzz build` and `cargo fuzz run` (the same, so that
/// the run reuses the build).
const BUILD_FLAGS: [&str; 5] = [
    "--fuzz-dir",
    "fuzz",
    "--release",
    "--debug-assertions",
    "--sanitizer=none",
];

fn cargo_fuzz(cargo: &str, root: &Path) -> Command {
    let mut cmd = Command::new(cargo);
    cmd.current_dir(root)
        .env("RUSTC_BOOTSTRAP", "1")
        .env("PATH", tools_path(root))
        .arg("fuzz");
    cmd
}

/// Builds every target, then runs those of `opts`; the summary per target.
pub fn run(root: &Path, opts: &Options) -> Result<Vec<Summary>, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let targets: Vec<(String, Option<u64>)> = if opts.targets.is_empty() {
        TARGETS.iter().map(|t| (t.to_string(), opts.runs)).collect()
    } else {
        opts.targets
            .iter()
            .map(|t| parse_target(t, opts.runs))
            .collect::<Result<_, _>>()?
    };
    ensure_cargo_fuzz(&cargo, root)?;
    let t0 = Instant::now();
    let built = process::run(
        cargo_fuzz(&cargo, root).arg("build").args(BUILD_FLAGS),
        Duration::from_secs(30 * 60),
    );
    if built != Some(0) {
        return Err("cargo fuzz build (RUSTC_BOOTSTRAP=1, stable toolchain) failed".into());
    }
    eprintln!("xtask: fuzz targets built in {:.0} s", t0.elapsed().as_secs_f64());
    let mut summaries = Vec::new();
    let mut failures = Vec::new();
    for (t, runs) in &targets {
        let s = run_target(
            &cargo,
            root,
            t,
            &Options {
                runs: *runs,
                ..opts.clone()
            },
        )?;
        eprintln!(
            "xtask: {t}: {} executions in {:.0} s, cov {} ft {}, corpus {}, {} crash input(s)",
            s.runs,
            s.seconds,
            s.cov,
            s.ft,
            s.corpus,
            s.crashes.len()
        );
        if !s.crashes.is_empty() {
            failures.push(crash_report(root, t, &s.crashes));
        }
        summaries.push(s);
    }
    println!("{}", table(&summaries));
    if failures.is_empty() {
        Ok(summaries)
    } else {
        Err(failures.join("\n"))
    }
}

/// `T` or `T=N` (`N` executions of target `T`; `runs` otherwise).
fn parse_target(spec: &str, runs: Option<u64>) -> Result<(String, Option<u64>), String> {
    let (name, runs) = match spec.split_once('=') {
        Some((name, n)) => (
            name,
            Some(
                n.parse::<u64>()
                    .map_err(|_| format!("--target {spec}: {n:?} is not a number of executions"))?,
            ),
        ),
        None => (spec, runs),
    };
    if !TARGETS.contains(&name) {
        return Err(format!("no fuzz target {name:?} (the targets: {})", TARGETS.join(", ")));
    }
    Ok((name.to_string(), runs))
}

/// One target's libFuzzer run.
fn run_target(cargo: &str, root: &Path, target: &str, opts: &Options) -> Result<Summary, String> {
    let dir = root.join("target/fuzz");
    let work = dir.join("corpus").join(target);
    let artifacts = dir.join("artifacts").join(target);
    let logs = dir.join("logs");
    for d in [&work, &artifacts, &logs] {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let before: Vec<PathBuf> = crash_files(&artifacts);
    let log_path = logs.join(format!("{target}.log"));
    let log = std::fs::File::create(&log_path).map_err(|e| format!("{}: {e}", log_path.display()))?;
    let mut cmd = cargo_fuzz(cargo, root);
    cmd.arg("run")
        .args(BUILD_FLAGS)
        .arg(target)
        .arg(&work)
        .arg(root.join("fuzz/corpus").join(target));
    // The findings' inputs (docs/fuzzing.md), replayed as regressions.
    let findings = root.join("fuzz/artifacts").join(target);
    if findings.is_dir() {
        cmd.arg(findings);
    }
    cmd.arg("--")
        .arg(format!("-artifact_prefix={}/", artifacts.display()))
        // One input running for a minute is a hang, reported as a crash.
        .arg("-timeout=60")
        .arg("-max_len=4096")
        .arg("-print_final_stats=1");
    if let Some(s) = opts.seconds {
        cmd.arg(format!("-max_total_time={s}"));
    }
    if let Some(n) = opts.runs {
        cmd.arg(format!("-runs={n}"));
    }
    let jobs = if opts.keep_going { opts.jobs.max(1) } else { opts.jobs };
    if jobs > 0 {
        cmd.arg(format!("-fork={jobs}"));
    }
    if opts.keep_going {
        cmd.arg("-ignore_crashes=1");
    }
    let stderr = log.try_clone().map_err(|e| e.to_string())?;
    cmd.stdout(log).stderr(stderr);
    eprintln!("xtask: fuzzing {target} (log {})", log_path.display());
    // The deadline: the run's own bound and the rebuild check, or a month.
    let deadline = Duration::from_secs(opts.seconds.map_or(30 * 86_400, |s| s + 300));
    let t0 = Instant::now();
    let code = process::run(&mut cmd, deadline);
    let seconds = t0.elapsed().as_secs_f64();
    let text = std::fs::read_to_string(&log_path).unwrap_or_default();
    let mut s = parse_log(&text);
    s.target = target.to_string();
    s.seconds = seconds;
    s.crashes = crash_files(&artifacts)
        .into_iter()
        .filter(|p| !before.contains(p))
        .collect();
    if code != Some(0) && s.crashes.is_empty() {
        let tail: Vec<&str> = text.lines().rev().take(20).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(format!(
            "fuzzing {target} failed (exit {code:?}) without a crash input; the end of {}:\n{}",
            log_path.display(),
            tail.join("\n")
        ));
    }
    // The first panic's location and message, for the report.
    let mut lines = text.lines();
    while let Some(l) = lines.next() {
        if l.contains("panicked at") {
            let msg = lines.next().unwrap_or_default();
            eprintln!("xtask: {target}: {l}\n{}", msg.chars().take(2000).collect::<String>());
            break;
        }
    }
    Ok(s)
}

fn crash_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| ["crash-", "timeout-", "oom-"].iter().any(|k| n.starts_with(k)))
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn crash_report(root: &Path, target: &str, crashes: &[PathBuf]) -> String {
    let mut out = format!("fuzz target {target} found {} failing input(s):", crashes.len());
    for c in crashes {
        let shown = c.strip_prefix(root).unwrap_or(c);
        let _ = write!(
            out,
            "\n  {}\n    replay: RUSTC_BOOTSTRAP=1 cargo fuzz run {} {target} {}",
            shown.display(),
            BUILD_FLAGS.join(" "),
            shown.display()
        );
    }
    out
}

/// The value after `key` (`"cov:"`) in a libFuzzer status line.
fn field(line: &str, key: &str) -> Option<u64> {
    let mut words = line.split_whitespace();
    while let Some(w) = words.next() {
        if w == key {
            let v = words.next()?;
            return v.split('/').next()?.parse().ok();
        }
    }
    None
}

/// The last status of a libFuzzer log: executions, coverage, corpus.
/// Plain runs end with `#N DONE cov: C ft: F corp: K/..` and
/// `stat::number_of_executed_units: N`; fork mode reports
/// `#N: cov: C ft: F corp: K exec/s: E ...` lines.
pub fn parse_log(text: &str) -> Summary {
    let mut s = Summary::default();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix('#')
            && let Some(runs) = rest
                .split(|c: char| !c.is_ascii_digit())
                .next()
                .and_then(|n| n.parse::<u64>().ok())
            && let (Some(cov), Some(ft)) = (field(line, "cov:"), field(line, "ft:"))
        {
            s.runs = s.runs.max(runs);
            s.cov = cov;
            s.ft = ft;
            if let Some(c) = field(line, "corp:") {
                s.corpus = c;
            }
        }
        if let Some(n) = line.strip_prefix("stat::number_of_executed_units:")
            && let Ok(n) = n.trim().parse::<u64>()
        {
            s.runs = s.runs.max(n);
        }
    }
    s
}

/// The summaries as a Markdown table, with the total.
pub fn table(summaries: &[Summary]) -> String {
    let mut out = String::from(
        "| target | executions | seconds | exec/s | cov (edges) | ft (features) | corpus | crashes |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let (mut runs, mut seconds, mut crashes) = (0u64, 0.0f64, 0usize);
    for s in summaries {
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} | {:.0} | {} | {} | {} | {} |",
            s.target,
            s.runs,
            s.seconds,
            s.runs as f64 / s.seconds.max(1e-9),
            s.cov,
            s.ft,
            s.corpus,
            s.crashes.len()
        );
        runs += s.runs;
        seconds += s.seconds;
        crashes += s.crashes.len();
    }
    let _ = write!(out, "| all | {runs} | {seconds:.0} | | | | | {crashes} |");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_take_their_own_executions() {
        assert_eq!(parse_target("twin", Some(5)), Ok(("twin".into(), Some(5))));
        assert_eq!(parse_target("twin=150000", None), Ok(("twin".into(), Some(150_000))));
        assert!(parse_target("twin=many", None).unwrap_err().contains("twin=many"));
        assert!(parse_target("tw1n", None).unwrap_err().contains("tw1n"));
    }

    #[test]
    fn libfuzzer_logs_give_the_figures() {
        let plain = "#11\tINITED cov: 754 ft: 1385 corp: 10/14530b exec/s: 0 rss: 28Mb\n\
                     #141547\tDONE   cov: 1859 ft: 7266 corp: 1307/1312Kb lim: 2429 exec/s: 8846 rss: 32Mb\n\
                     Done 141547 runs in 16 second(s)\n\
                     stat::number_of_executed_units: 141547\n";
        let s = parse_log(plain);
        assert_eq!((s.runs, s.cov, s.ft, s.corpus), (141_547, 1859, 7266, 1307));
        let fork = "#135411: cov: 999 ft: 2840 corp: 366 exec/s: 556 oom/timeout/crash: 0/0/0 time: 153s job: 16 dft_time: 0\n\
                    #1407664: cov: 1625 ft: 5527 corp: 1445 exec/s: 5457 oom/timeout/crash: 0/0/1 time: 153s job: 16\n\
                    INFO: exiting: 0 time: 153s\n";
        let s = parse_log(fork);
        assert_eq!((s.runs, s.cov, s.ft, s.corpus), (1_407_664, 1625, 5527, 1445));
        assert_eq!(parse_log("nothing"), Summary::default());
    }
}
