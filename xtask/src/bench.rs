//! `cargo xtask bench`: cost, footprint and stack of the firmware on the
//! emulated microcontrollers, and the budget check CI runs.
//!
//! * Instructions: the `bench` image runs under `qemu -icount shift=0`
//!   (one nanosecond of emulated time per instruction) and reports SysTick
//!   counts; its calibration loop of known length converts them (0.168
//!   counts per instruction on the netduinoplus2 STM32F405, 0.120 on the
//!   netduino2 STM32F205). Deterministic: the same image gives the same
//!   numbers on every run and machine.
//! * Flash and static RAM: the ELF sections of the images (`.vector_table`,
//!   `.text`, `.rodata`, `.data` in flash; `.data`, `.bss`, `.uninit` in RAM).
//! * Stack: the QEMU twin measures its own peak by stack painting.

use crate::firmware::Image;
use crate::qemu;
#[cfg(feature = "host")]
use compensator::dynamics::TwinConfig;
use object::{Object, ObjectSection};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The budgets of the firmware issue.
pub const BUDGET_INSTRUCTIONS: f64 = 3000.0;
/// The twin's plain tick on the paper preset (the configuration its build
/// chooses) [instructions].
pub const BUDGET_TWIN_PAPER: f64 = 1600.0;
/// Flash budget [bytes].
pub const BUDGET_FLASH: u64 = 64 * 1024;
/// Static RAM budget [bytes].
pub const BUDGET_RAM: u64 = 8 * 1024;
/// Peak stack budget [bytes]. The peak is reached once, at start: `main`
/// (the replay's state, the estimator) calling `Estimator::new` calling
/// `Twin::new`, which builds the 512-byte twin on its own frame before it
/// moves in (4.3-4.6 KiB since the twin carries its graded-piece scheme,
/// its flow unit and the stop events; frames in the disassembly: `main`
/// 3.0 KiB, `Twin::new` 1.1 KiB, a twin tick's about 0.5 KiB).
/// The board's stack has the 64 KiB CCM to itself (`link/memory-board.x`),
/// so 6 KiB keeps a margin of ten.
pub const BUDGET_STACK: u64 = 6 * 1024;

/// One `[measure] kind key=value ...` line.
#[derive(Debug, Clone)]
struct Measure {
    kind: String,
    fields: BTreeMap<String, String>,
}

fn parse(lines: &[String]) -> Vec<Measure> {
    lines
        .iter()
        .filter_map(|l| l.split("[measure] ").nth(1))
        .map(|rest| {
            let mut words = rest.split_whitespace();
            let kind = words.next().unwrap_or_default().to_string();
            let fields = words
                .filter_map(|w| w.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect();
            Measure { kind, fields }
        })
        .collect()
}

impl Measure {
    fn num(&self, key: &str) -> Result<f64, String> {
        self.fields
            .get(key)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| format!("{} line without {key}", self.kind))
    }
    fn str(&self, key: &str) -> &str {
        self.fields.get(key).map(String::as_str).unwrap_or("?")
    }
}

/// Instructions per SysTick count, from the calibration line.
fn calibration(ms: &[Measure]) -> Result<f64, String> {
    let c = ms
        .iter()
        .find(|m| m.kind == "calibration")
        .ok_or("no calibration line")?;
    Ok(c.num("instructions")? / c.num("total")?)
}

/// Results of one bench image.
pub struct Costs {
    /// `(scheme, substeps, scalar) -> (mean, worst)` instructions per tick.
    pub twin: Vec<(String, u32, String, f64, f64)>,
    /// `(scheme, substeps, scalar) -> instructions` of the graded tick after
    /// the abrupt step.
    pub graded: Vec<(String, u32, String, f64)>,
    /// The configuration the build chose: `(scheme, substeps, parameter file)`.
    pub built: Option<(String, u32, String)>,
    /// `(kind, mean, worst)` of the built twin through slow ramps across
    /// the opening (`release`, `impact`).
    pub events: Vec<(String, f64, f64)>,
    /// `name -> instructions`.
    pub pieces: Vec<(String, f64)>,
    /// `(telemetry, mean, worst)` instructions per estimator tick.
    pub estimator: Vec<(bool, f64, f64)>,
    /// Instructions per SysTick count.
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    pub per_count: f64,
}

/// The costs a bench image reported. An `ERROR` line, a twin run with a
/// failed tick or a line without its numbers is an error, never a cheap
/// (or missing) row.
fn costs(lines: &[String]) -> Result<Costs, String> {
    if let Some(l) = lines.iter().find(|l| l.contains("ERROR")) {
        return Err(format!("the bench firmware reported an error: {l}"));
    }
    let ms = parse(lines);
    let k = calibration(&ms)?;
    let mut out = Costs {
        twin: vec![],
        graded: vec![],
        built: None,
        events: vec![],
        pieces: vec![],
        estimator: vec![],
        per_count: k,
    };
    for m in &ms {
        match m.kind.as_str() {
            "twin" => {
                let ticks = m.num("ticks")?;
                let (scheme, substeps, scalar) = (m.str("scheme"), m.num("substeps")? as u32, m.str("scalar"));
                if m.str("ok") != "true" {
                    return Err(format!("twin {scheme} x{substeps} {scalar}: a tick failed"));
                }
                out.twin.push((
                    scheme.to_string(),
                    substeps,
                    scalar.to_string(),
                    // Mean and worst over the ticks after the graded first.
                    (m.num("total")? - m.num("graded")?) * k / (ticks - 1.0).max(1.0),
                    m.num("worst")? * k,
                ));
                out.graded
                    .push((scheme.to_string(), substeps, scalar.to_string(), m.num("graded")? * k));
            }
            "built" => {
                out.built = Some((
                    m.str("scheme").to_string(),
                    m.num("substeps")? as u32,
                    m.str("params").to_string(),
                ))
            }
            "twin-events" => {
                if m.str("ok") != "true" {
                    return Err(format!("twin through the {} ramp: a tick failed", m.str("kind")));
                }
                let ticks = m.num("ticks")?;
                out.events.push((
                    m.str("kind").to_string(),
                    m.num("total")? * k / ticks,
                    m.num("worst")? * k,
                ));
            }
            "piece" => out.pieces.push((m.str("name").to_string(), m.num("total")? * k)),
            "estimator" => {
                let ticks = m.num("ticks")?;
                out.estimator.push((
                    m.str("telemetry") == "true",
                    m.num("total")? * k / ticks,
                    m.num("worst")? * k,
                ));
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Flash and static RAM of an ELF image [bytes].
pub fn footprint(elf: &Path) -> Result<(u64, u64), String> {
    let data = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let file = object::File::parse(&*data).map_err(|e| format!("{}: {e}", elf.display()))?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let name = s.name().unwrap_or_default();
        let size = s.size();
        match name {
            ".vector_table" | ".text" | ".rodata" => flash += size,
            ".data" => {
                flash += size; // initial values, copied at reset
                ram += size;
            }
            ".bss" | ".uninit" => ram += size,
            _ => {}
        }
    }
    Ok((flash, ram))
}

/// Peak stack [bytes] reported by the QEMU twin.
fn stack_peak(lines: &[String]) -> Option<u64> {
    lines.iter().find_map(|l| {
        let rest = l.split("[measure] peak stack ").nth(1)?;
        rest.split_whitespace().next()?.parse().ok()
    })
}

fn run_image(elf: &Path, machine: qemu::Machine) -> Result<Vec<String>, String> {
    let run = qemu::run(elf, machine, true, Duration::from_secs(600), qemu::Show::Quiet)?;
    if run.code != 0 {
        return Err(format!("{} exited with {}", elf.display(), run.code));
    }
    Ok(run.lines)
}

/// What the firmware images measured on QEMU.
pub struct Firmware {
    m4: Costs,
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    m3: Costs,
    /// Peak stack of the QEMU twin run [bytes].
    stack: u64,
    /// `(label, flash, static RAM)` [bytes].
    footprints: Vec<(&'static str, u64, u64)>,
}

/// Runs the bench images on QEMU and reads the footprints. `twin_lines`:
/// the output of a twin run already made (the snapshot check), else the
/// twin is run here for its stack peak.
pub fn measure_firmware(elfs: &[(Image, PathBuf)], twin_lines: Option<&[String]>) -> Result<Firmware, String> {
    let find = |img: Image| {
        elfs.iter()
            .find(|(i, _)| *i == img)
            .map(|(_, p)| p.clone())
            .ok_or_else(|| format!("missing image {}", img.bin))
    };
    let m4 = costs(&run_image(&find(Image::BENCH_M4)?, qemu::NETDUINO)?)?;
    let m3 = costs(&run_image(&find(Image::BENCH_M3)?, qemu::NETDUINO2)?)?;
    let stack = match twin_lines {
        Some(lines) => stack_peak(lines),
        None => stack_peak(&run_image(&find(Image::TWIN)?, qemu::NETDUINO)?),
    }
    .ok_or("the twin reported no stack peak")?;
    let mut footprints = Vec::new();
    for (img, label) in [(Image::BOARD, "board image"), (Image::TWIN, "QEMU twin image")] {
        let (flash, ram) = footprint(&find(img)?)?;
        footprints.push((label, flash, ram));
    }
    Ok(Firmware {
        m4,
        m3,
        stack,
        footprints,
    })
}

/// The budget table (Markdown) and the budgets missed. A measurement the
/// budget needs and the images did not report is an error.
pub fn budget(fw: &Firmware) -> Result<(String, Vec<String>), String> {
    let mut t = String::new();
    let mut over = Vec::new();
    let _ = writeln!(t, "| what | measured | goal |\n| --- | --- | --- |");
    for telemetry in [true, false] {
        // The worst of every workload, the mean of the first (the step).
        let rows: Vec<_> = fw.m4.estimator.iter().filter(|e| e.0 == telemetry).collect();
        let first = rows.first().ok_or("the bench image reported no estimator tick cost")?;
        let mean = first.1;
        let worst = rows.iter().map(|e| e.2).fold(0.0, f64::max);
        let what = if telemetry {
            "estimator tick with telemetry packing"
        } else {
            "estimator tick, no telemetry"
        };
        let _ = writeln!(
            t,
            "| {what}, Cortex-M4F f32 (step and ramps) | mean {mean:.0}, worst {worst:.0} instructions | <= {BUDGET_INSTRUCTIONS:.0} |"
        );
        if worst > BUDGET_INSTRUCTIONS {
            over.push(format!(
                "{what}: worst {worst:.0} instructions > {BUDGET_INSTRUCTIONS:.0}"
            ));
        }
    }
    let (scheme, substeps, params) = fw
        .m4
        .built
        .clone()
        .ok_or("the bench image reported no built configuration")?;
    let (_, _, _, mean, worst) = fw
        .m4
        .twin
        .iter()
        .find(|r| r.0 == scheme && r.1 == substeps && r.2 == "f32")
        .ok_or("the bench image reported no cost of the built twin")?;
    let graded = fw
        .m4
        .graded
        .iter()
        .find(|r| r.0 == scheme && r.1 == substeps && r.2 == "f32")
        .map_or(0.0, |r| r.3);
    let paper = params == "paper.toml";
    let goal = if paper {
        format!("<= {BUDGET_TWIN_PAPER:.0} (paper preset)")
    } else {
        "measured".to_string()
    };
    let _ = writeln!(
        t,
        "| twin tick alone, as built for {params} ({scheme} x{substeps}, f32), Cortex-M4F | mean {mean:.0}, worst {worst:.0} instructions (the graded tick after an abrupt step: {graded:.0}) | {goal} |"
    );
    if paper && *worst > BUDGET_TWIN_PAPER {
        over.push(format!(
            "twin tick on the paper preset: worst {worst:.0} instructions > {BUDGET_TWIN_PAPER:.0}"
        ));
    }
    for (kind, mean, worst) in &fw.m4.events {
        let _ = writeln!(
            t,
            "| twin tick through a 1 C/s ramp across the opening ({kind}s), Cortex-M4F | mean {mean:.0}, worst {worst:.0} instructions | measured (the estimator defers its job then) |"
        );
    }
    for (label, flash, ram) in &fw.footprints {
        let _ = writeln!(t, "| flash, {label} | {:.1} KiB | <= 64 KiB |", *flash as f64 / 1024.0);
        let _ = writeln!(t, "| static RAM, {label} | {ram} bytes | <= 8 KiB |");
        if *flash > BUDGET_FLASH {
            over.push(format!("flash of the {label}: {flash} bytes"));
        }
        if *ram > BUDGET_RAM {
            over.push(format!("static RAM of the {label}: {ram} bytes"));
        }
    }
    let stack = fw.stack;
    let _ = writeln!(
        t,
        "| peak stack, QEMU twin run (stack painting) | {stack} bytes | <= 6 KiB |"
    );
    if stack > BUDGET_STACK {
        over.push(format!("peak stack {stack} bytes"));
    }
    Ok((t, over))
}

/// The full report: budget, pieces, the scheme cost table and the
/// accuracy-against-cost table (host simulations).
#[cfg(feature = "host")]
pub fn report(fw: &Firmware) -> Result<(String, Vec<String>), String> {
    let (m4, m3) = (&fw.m4, &fw.m3);
    let (budget_table, over) = budget(fw)?;
    let mut t = String::new();
    let _ = writeln!(t, "# Firmware cost, footprint and stack\n");
    let _ = writeln!(
        t,
        "Measured by `cargo xtask bench` (deterministic: QEMU 7.2 `-icount shift=0`, SysTick"
    );
    let _ = writeln!(
        t,
        "calibrated against a loop of known length: {:.3} instructions per count on netduinoplus2,",
        m4.per_count
    );
    let _ = writeln!(t, "{:.3} on netduino2).\n", m3.per_count);
    let _ = writeln!(t, "## Budget (firmware issue)\n");
    t.push_str(&budget_table);

    let _ = writeln!(t, "\n## Estimator pieces (Cortex-M4F, f32, one call each)\n");
    let _ = writeln!(t, "| piece | instructions |\n| --- | --- |");
    for (name, n) in &m4.pieces {
        let _ = writeln!(t, "| {name} | {n:.0} |");
    }

    let _ = writeln!(
        t,
        "\n## Twin tick by scheme (200 ticks of the 30 -> 40 C step from the closed stop)\n"
    );
    let _ = writeln!(
        t,
        "Mean and worst over the ticks after the first; the first tick after the abrupt step is graded \
         (its substep in pieces from 0.5 us, `Twin::tick`; host simulations only: the estimator slews \
         the twin's oil instead) and reported on its own.\n"
    );
    let _ = writeln!(
        t,
        "| scheme | steps per tick | Cortex-M4F f32 mean / worst (graded) | Cortex-M4F Q12.20 mean / worst (graded) | Cortex-M3 Q12.20 mean / worst (graded) |"
    );
    let _ = writeln!(t, "| --- | --- | --- | --- | --- |");
    let get = |c: &Costs, s: &str, n: u32, scalar: &str| {
        let graded = c
            .graded
            .iter()
            .find(|r| r.0 == s && r.1 == n && r.2 == scalar)
            .map(|r| r.3)
            .unwrap_or(f64::NAN);
        c.twin
            .iter()
            .find(|r| r.0 == s && r.1 == n && r.2 == scalar)
            .map(|r| format!("{:.0} / {:.0} ({graded:.0})", r.3, r.4))
            .unwrap_or_else(|| "-".into())
    };
    let mut configs: Vec<(String, u32)> = m4.twin.iter().map(|r| (r.0.clone(), r.1)).collect();
    configs.dedup();
    for (s, n) in &configs {
        let _ = writeln!(
            t,
            "| {s} | {n} | {} | {} | {} |",
            get(m4, s, *n, "f32"),
            get(m4, s, *n, "q12.20"),
            get(m3, s, *n, "q12.20")
        );
    }
    let _ = writeln!(t, "\n## Accuracy against cost: the choice of scheme\n");
    let _ = writeln!(
        t,
        "Worst max |x - x_ref| over the paper preset's six steps and 1 C/s ramp, in % of the step \
         (host simulation against the Radau5 reference, `host_tests::accuracy`), beside the \
         Cortex-M4F f32 instructions per 1 ms tick. A configuration is on the Pareto front when no \
         other is both more accurate and cheaper. Goals: f64 <= 0.1 %, f32 <= 0.5 %, fixed point <= 1 %.\n"
    );
    let _ = writeln!(
        t,
        "| scheme | steps per tick | f64 error | f32 error | Q12.20 error | M4 f32 instructions (mean) | Pareto (f32) |"
    );
    let _ = writeln!(t, "| --- | --- | --- | --- | --- | --- | --- |");
    let points = accuracy_points(&configs)?;
    let cost_of = |a: &Accuracy| {
        m4.twin
            .iter()
            .find(|r| r.0 == a.scheme && r.1 == a.substeps && r.2 == "f32")
            .map(|r| r.3)
            .unwrap_or(f64::NAN)
    };
    let built = m4.built.clone().unwrap_or_default();
    for (i, a) in points.iter().enumerate() {
        let cost = cost_of(a);
        let dominated = points.iter().enumerate().any(|(j, b)| {
            let c2 = cost_of(b);
            j != i && b.f32 <= a.f32 && c2 <= cost && (b.f32 < a.f32 || c2 < cost)
        });
        let shipped = if a.scheme == built.0 && a.substeps == built.1 {
            " (built)"
        } else {
            ""
        };
        let fmt = |e: f64| {
            if e.is_finite() {
                format!("{e:.4} %")
            } else {
                "unstable".into()
            }
        };
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {cost:.0} | {}{shipped} |",
            a.scheme,
            a.substeps,
            fmt(a.f64),
            fmt(a.f32),
            fmt(a.fixed),
            if dominated || !a.f32.is_finite() { "" } else { "yes" }
        );
    }
    if let Some(r) = m3.twin.iter().find(|r| r.2 == "f32-soft") {
        let _ = writeln!(
            t,
            "\nFor comparison, {} x{} in soft-float f32 on the Cortex-M3: mean {:.0}, worst {:.0} instructions per tick.",
            r.0, r.1, r.3, r.4
        );
    }
    Ok((t, over))
}

/// Worst error (% of the step) over the paper cases of one configuration;
/// infinite where the scheme is unstable at that step.
#[cfg(feature = "host")]
struct Accuracy {
    scheme: String,
    substeps: u32,
    f64: f64,
    f32: f64,
    fixed: f64,
}

#[cfg(feature = "host")]
fn accuracy_points(configs: &[(String, u32)]) -> Result<Vec<Accuracy>, String> {
    use compensator::dynamics::Scheme;
    use compensator_cli::dynamics::Precision;
    let root = crate::root();
    let raw = compensator_cli::load(&root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let cases = host_tests::accuracy::paper_cases(&raw);
    let mut out = Vec::new();
    for (name, n) in configs {
        let scheme = Scheme::from_name(name).ok_or_else(|| format!("unknown scheme {name}"))?;
        let config = TwinConfig {
            scheme,
            tick: host_tests::accuracy::TICK,
            substeps: *n as u8,
        };
        let worst = |p: Precision| {
            cases
                .iter()
                .map(
                    |c| match compensator_cli::dynamics::simulate(&c.raw, p, config, &c.profile, c.ticks) {
                        Ok(r) => {
                            let x: Vec<f64> = r.state.iter().map(|s| s.x).collect();
                            let e = c.error_pct(&x);
                            if e.is_finite() { e } else { f64::INFINITY }
                        }
                        Err(_) => f64::INFINITY,
                    },
                )
                .fold(0.0, f64::max)
        };
        out.push(Accuracy {
            scheme: name.clone(),
            substeps: *n,
            f64: worst(Precision::F64),
            f32: worst(Precision::F32),
            fixed: worst(Precision::Fixed),
        });
    }
    Ok(out)
}

/// `cargo xtask bench [--params F] [--write]` (the accuracy table needs
/// the `host` feature; `main` re-runs xtask with it): the images built for
/// `params` (resolved and checked by `main`; `None`: the paper preset), the
/// budget table with the twin configuration the build chose for it, written
/// to `docs/bench.md` with `write`.
#[cfg(feature = "host")]
pub fn cmd(root: &Path, params: Option<&Path>, write: bool) -> Result<i32, String> {
    let tc = crate::toolchain::get(root, &crate::firmware::TARGETS)?;
    eprintln!("xtask: toolchain: {}", tc.description);
    qemu::ensure()?;
    let elfs = crate::firmware::build_all_params(&tc, root, params)?;
    let (text, over) = report(&measure_firmware(&elfs, None)?)?;
    print!("{text}");
    if write {
        let path = root.join("docs/bench.md");
        std::fs::write(&path, &text).map_err(|e| e.to_string())?;
        eprintln!("xtask: wrote {}", path.display());
    }
    for o in &over {
        eprintln!("xtask: over budget: {o}");
    }
    Ok(if over.is_empty() { 0 } else { 1 })
}

/// The budget check of `cargo xtask test` (firmware measurements only; the
/// accuracy tables are `cargo xtask bench`'s). `twin_lines`: the output of
/// the snapshot run, for the stack peak.
pub fn check(elfs: &[(Image, PathBuf)], twin_lines: &[String]) -> Result<(), String> {
    let (table, over) = budget(&measure_firmware(elfs, Some(twin_lines))?)?;
    eprint!("{table}");
    if over.is_empty() {
        eprintln!("xtask: every budget met");
        Ok(())
    } else {
        Err(format!("over budget: {}", over.join("; ")))
    }
}
