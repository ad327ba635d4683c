//! `cargo xtask profile`: where the firmware's instructions go, function by
//! function.
//!
//! The profile image (`src/bin/profile.rs`) runs two sections between calls
//! of its `profile_mark`: 200 ticks of the twin as built, then 200 ticks of
//! the estimator (telemetry every 100). QEMU runs it one instruction per
//! translation block without chaining (`-singlestep -d exec,nochain`), so
//! that its log has one `Trace` line per executed instruction with the
//! guest's program counter; the runner streams that log (never to disk: the
//! Cortex-M0's run is several million lines), finds the sections by the
//! entry address of `profile_mark` and charges every instruction to the
//! function whose symbol covers its address (inlined code counts to the
//! function it was inlined into). The counts are exact instruction counts,
//! the same measure as `cargo xtask bench` (`-icount shift=0`), not samples.

use crate::cycles::{Core, Timing};
use crate::firmware::{self, Image};
use crate::qemu::Machine;
use crate::toolchain::Toolchain;
use object::{Object, ObjectSymbol, SymbolKind};
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Ticks in each section of the profile image (`src/bin/profile.rs`).
pub const TICKS: u64 = 200;

/// QEMU messages (non-trace lines of its log) kept for an error.
const MESSAGES: usize = 6;

/// Longest run of the profile image before it is stopped (the Cortex-M0's
/// takes about 30 s).
const TIMEOUT: Duration = Duration::from_secs(300);

/// The sections, in the order the image runs them: the first two in
/// every image, the third (the condition monitor's update, a reading a
/// "tick") in an image built for a second sensor.
pub const SECTIONS: [&str; 3] = ["twin tick", "estimator tick", "monitor update (a tick is one reading)"];

/// The sections the profile image built for `params` runs.
pub fn sections_for(params: Option<&Path>) -> usize {
    if firmware::names_second_sensor(params) {
        SECTIONS.len()
    } else {
        2
    }
}

/// The function symbols of an ELF: `(start, end, name)`, sorted by start,
/// the Thumb bit cleared, names demangled without their hash.
#[derive(Debug, Default)]
pub struct Symbols {
    ranges: Vec<(u64, u64, String)>,
}

impl Symbols {
    /// The text symbols of `elf` (the ELF's bytes).
    ///
    /// # Errors
    ///
    /// The bytes are not an ELF `object` reads.
    pub fn of_elf(elf: &[u8]) -> Result<Self, String> {
        let file = object::File::parse(elf).map_err(|e| format!("not an ELF: {e}"))?;
        let symbols = file
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
            .filter_map(|s| {
                let name = s.name().ok()?;
                Some((s.address() & !1, s.size(), name.to_string()))
            });
        Ok(Self::new(symbols))
    }

    /// From `(address, size, mangled name)` triples.
    pub fn new(symbols: impl IntoIterator<Item = (u64, u64, String)>) -> Self {
        let mut ranges: Vec<(u64, u64, String)> = symbols
            .into_iter()
            .map(|(a, size, name)| {
                (
                    a & !1,
                    (a & !1) + size,
                    format!("{:#}", rustc_demangle::demangle(&name)),
                )
            })
            .collect();
        ranges.sort_by(|a, b| a.0.cmp(&b.0).then(a.2.cmp(&b.2)));
        // Aliases (two names at one address: `DefaultPreInit` and a defmt
        // timestamp, say) become one range named by both.
        let mut merged: Vec<(u64, u64, String)> = Vec::with_capacity(ranges.len());
        for r in ranges {
            match merged.last_mut() {
                Some(last) if last.0 == r.0 => {
                    last.1 = last.1.max(r.1);
                    if last.2 != r.2 {
                        last.2 = format!("{} = {}", last.2, r.2);
                    }
                }
                _ => merged.push(r),
            }
        }
        Symbols { ranges: merged }
    }

    /// The start and name of the function holding `pc`, if a symbol covers it.
    pub fn covering(&self, pc: u64) -> Option<(u64, &str)> {
        let i = self.ranges.partition_point(|r| r.0 <= pc);
        let r = self.ranges.get(i.checked_sub(1)?)?;
        (pc < r.1).then_some((r.0, r.2.as_str()))
    }

    /// The start address of the function named `name` (demangled; one of
    /// an alias's names).
    pub fn address(&self, name: &str) -> Option<u64> {
        self.ranges
            .iter()
            .find(|r| r.2.split(" = ").any(|n| n == name))
            .map(|r| r.0)
    }

    /// `function+0xoffset` of `pc` (a call site without line information).
    pub fn describe(&self, pc: u64) -> String {
        match self.covering(pc) {
            Some((start, name)) => format!("{name}+{:#x}", pc - start),
            None => format!("{pc:#010x}"),
        }
    }
}

/// Instructions per function in one section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    /// Instructions executed in the section.
    pub total: u64,
    /// Per function (`?` for an address no symbol covers).
    pub functions: HashMap<String, u64>,
    /// Per function and call site: the instructions of each call of the
    /// function charged to the address of the instruction that entered it
    /// (its `bl`; 0 where the section began inside the function).
    pub sites: HashMap<String, HashMap<u64, u64>>,
    /// The costliest tick (between two entries of the tick marker, the
    /// section's last tick ending at its closing mark): its index from 0,
    /// and its instructions per function.
    pub worst: Option<(usize, HashMap<String, u64>)>,
    /// Ticks marked in the section (0: the image marks none).
    pub ticks: u64,
    /// Core cycles of the section's instructions, lower and upper
    /// ([`crate::cycles`]; 0 without a timing).
    pub cycles: (u64, u64),
    /// Core cycles of the worst tick, lower and upper.
    pub worst_cycles: (u64, u64),
}

impl Section {
    /// The ticks the section's means are over ([`TICKS`] when the image
    /// marks none).
    pub fn tick_count(&self) -> u64 {
        if self.ticks > 0 { self.ticks } else { TICKS }
    }

    /// `n` instructions per tick of the section.
    pub fn per_tick(&self, n: u64) -> String {
        format!("{:.1}", n as f64 / self.tick_count() as f64)
    }

    /// Instructions of the worst tick.
    pub fn worst_total(&self) -> u64 {
        self.worst.as_ref().map_or(0, |(_, f)| f.values().sum())
    }

    /// Core cycles per instruction over the section, lower and upper
    /// (NaN without a timing).
    pub fn cycles_per_instruction(&self) -> (f64, f64) {
        if self.total == 0 || self.cycles.1 == 0 {
            return (f64::NAN, f64::NAN);
        }
        let t = self.total as f64;
        (self.cycles.0 as f64 / t, self.cycles.1 as f64 / t)
    }
}

/// The tick being counted: its index, instructions per function, cycles.
type Tick = (usize, HashMap<String, u64>, (u64, u64));

/// The guest program counter of a QEMU `-d exec` line (`Trace 0: 0x... [flags/PC/...] name`).
pub fn pc_of(line: &str) -> Option<u64> {
    let rest = line.strip_prefix("Trace ")?;
    let inside = rest.split_once('[')?.1;
    let pc = inside.split('/').nth(1)?;
    u64::from_str_radix(pc.trim_end_matches(']'), 16).ok()
}

/// Charges the trace's instructions to the sections between the entries
/// of the function at `mark` (an entry opens a section, the next closes
/// it), and to ticks between the entries of the function at `tick` (when
/// the image has one); the markers' own instructions are not counted.
/// With a `timing`, each instruction's cycles are counted too, a branch as
/// taken when the next executed instruction is not the one after it.
///
/// # Errors
///
/// Fewer marks than two per section, or an odd number (the image did not
/// run to its end).
pub fn attribute(
    trace: impl BufRead,
    symbols: &Symbols,
    mark: u64,
    tick: Option<u64>,
    sections: usize,
    timing: Option<&Timing>,
    messages: &mut Vec<String>,
) -> Result<Vec<Section>, String> {
    let mut out = vec![Section::default(); sections];
    let mut marks = 0usize;
    let mut names: HashMap<u64, (u64, &str)> = HashMap::new();
    // The call site each function was last entered from.
    let mut entered: HashMap<&str, u64> = HashMap::new();
    let mut previous: Option<(u64, &str)> = None;
    // The current tick of the open section: its index and its counts.
    let mut current: Option<Tick> = None;
    // The last counted instruction, whose cycles wait for the next
    // executed address (taken or not).
    let mut pending: Option<u64> = None;
    let close = |current: &mut Option<Tick>, section: Option<&mut Section>| {
        if let (Some((index, counts, cycles)), Some(section)) = (current.take(), section) {
            let total: u64 = counts.values().sum();
            if total > section.worst_total() {
                section.worst = Some((index, counts));
                section.worst_cycles = cycles;
            }
        }
    };
    for line in trace.lines() {
        let line = line.map_err(|e| format!("trace: {e}"))?;
        let Some(pc) = pc_of(&line) else {
            // QEMU's own messages share the log: the last few are kept for
            // the error a failed run reports.
            if !line.trim().is_empty() {
                if messages.len() == MESSAGES {
                    messages.remove(0);
                }
                messages.push(line);
            }
            continue;
        };
        if let Some((from, cost)) = pending.take().and_then(|from| Some((from, timing?.at(from)?))) {
            let (lo, hi) = cost.cycles(pc != from + u64::from(cost.size));
            if let Some(section) = out.get_mut(marks / 2) {
                section.cycles.0 += lo;
                section.cycles.1 += hi;
            }
            if let Some((_, _, c)) = current.as_mut() {
                c.0 += lo;
                c.1 += hi;
            }
        }
        if pc == mark {
            if !marks.is_multiple_of(2) {
                close(&mut current, out.get_mut(marks / 2));
            }
            marks += 1;
            previous = None;
            entered.clear();
            continue;
        }
        if Some(pc) == tick && !marks.is_multiple_of(2) {
            let next = current.as_ref().map_or(0, |c| c.0 + 1);
            close(&mut current, out.get_mut(marks / 2));
            current = Some((next, HashMap::new(), (0, 0)));
            if let Some(section) = out.get_mut(marks / 2) {
                section.ticks += 1;
            }
        }
        let (start, name) = *names
            .entry(pc)
            .or_insert_with(|| symbols.covering(pc).unwrap_or((u64::MAX, "?")));
        if pc == start
            && let Some((site, from)) = previous
            && from != name
        {
            entered.insert(name, site);
        }
        previous = Some((pc, name));
        if marks.is_multiple_of(2) || name == "profile_mark" || name == "profile_tick" {
            continue;
        }
        let Some(section) = out.get_mut(marks / 2) else {
            continue;
        };
        section.total += 1;
        pending = Some(pc);
        *section.functions.entry(name.to_string()).or_insert(0) += 1;
        let site = entered.get(name).copied().unwrap_or(0);
        *section
            .sites
            .entry(name.to_string())
            .or_default()
            .entry(site)
            .or_insert(0) += 1;
        if let Some((_, counts, _)) = current.as_mut() {
            *counts.entry(name.to_string()).or_insert(0) += 1;
        }
    }
    if marks != 2 * sections {
        return Err(format!(
            "the trace has {marks} section marks, expected {}",
            2 * sections
        ));
    }
    Ok(out)
}

/// Source lines of addresses, from the ELF's DWARF: the innermost inlined
/// frame in the workspace's own code (`src/...`, `model/src/...`), else the
/// innermost frame; `None` without debug information.
pub struct Lines {
    loader: Option<addr2line::Loader>,
    root: String,
    /// The image's symbols: `function+offset` where a line is unknown.
    pub symbols: Symbols,
}

impl Lines {
    /// The lines of `elf` (its `symbols` already read), paths shown
    /// relative to `root`.
    pub fn new(elf: &Path, root: &Path, symbols: Symbols) -> Self {
        Lines {
            loader: addr2line::Loader::new(elf).ok(),
            root: format!("{}/", root.display()),
            symbols,
        }
    }

    /// `file:line` of `address`.
    pub fn at(&self, address: u64) -> Option<String> {
        let loader = self.loader.as_ref()?;
        let mut frames = loader.find_frames(address).ok()?;
        let mut first = None;
        while let Ok(Some(frame)) = frames.next() {
            let Some(loc) = frame.location else { continue };
            let (Some(file), Some(line)) = (loc.file, loc.line) else {
                continue;
            };
            let own = file.starts_with(self.root.as_str());
            let file = shorten(file, &self.root);
            let shown = format!("{file}:{line}");
            if own {
                return Some(shown);
            }
            first.get_or_insert(shown);
        }
        first
    }
}

/// A source path as the report shows it: relative to the workspace `root`
/// (with its trailing `/`), the standard library's as `library/...`
/// (without the compiler's `/rustc/<commit>/`), a dependency's as
/// `crate-version/...` (without the registry's directory).
pub fn shorten<'a>(file: &'a str, root: &str) -> &'a str {
    let file = file.strip_prefix(root).unwrap_or(file);
    let file = match file.strip_prefix("/rustc/").and_then(|f| f.split_once('/')) {
        Some((_, rest)) => rest,
        None => file,
    };
    match file.split_once("/registry/src/").and_then(|(_, f)| f.split_once('/')) {
        Some((_, rest)) => rest,
        None => file,
    }
}

/// Runs the profile image `elf` on `machine` and charges its instructions
/// to its `sections` ([`sections_for`]).
///
/// # Errors
///
/// QEMU cannot start, the image fails (non-zero exit: its defmt log says
/// why under `cargo xtask qemu-runner`), or its marks are missing.
pub fn run(
    elf: &Path,
    symbols: &Symbols,
    timing: Option<&Timing>,
    machine: Machine,
    timeout: Duration,
    sections: usize,
) -> Result<Vec<Section>, String> {
    let mark = symbols
        .address("profile_mark")
        .ok_or_else(|| format!("{}: no profile_mark symbol", elf.display()))?;
    let tick = symbols.address("profile_tick");
    let mut child = Command::new("qemu-system-arm")
        .args(["-machine", machine.name, "-cpu", machine.cpu])
        .args(["-nographic", "-monitor", "none", "-serial", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-singlestep", "-d", "exec,nochain", "-D", "/dev/stderr"])
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("qemu-system-arm: {e}"))?;
    let pid = child.id();
    let mut stdout = child.stdout.take().expect("piped");
    // The defmt frames are not decoded here: drained so that QEMU never blocks.
    let drain = std::thread::spawn(move || {
        let mut sink = Vec::new();
        let _ = stdout.read_to_end(&mut sink);
    });
    // Kills QEMU if it has not finished within `timeout` (and only then:
    // the pid is not reused while the child is not yet waited for).
    let (finished, wait_for_it) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        let late = wait_for_it.recv_timeout(timeout).is_err();
        if late {
            let _ = Command::new("kill").arg(pid.to_string()).status();
        }
        late
    });
    let stderr = BufReader::with_capacity(1 << 20, child.stderr.take().expect("piped"));
    let mut messages = Vec::new();
    let sections = attribute(stderr, symbols, mark, tick, sections, timing, &mut messages);
    // The trace ended (QEMU closed its log) or could not be read: the
    // watchdog is told before `wait`, so that it never kills a reused pid,
    // and QEMU is stopped if its log was abandoned.
    let _ = finished.send(());
    let timed_out = watchdog.join().unwrap_or(false);
    if sections.is_err() {
        let _ = child.kill();
    }
    let status = child.wait().map_err(|e| format!("qemu-system-arm: {e}"))?;
    let _ = drain.join();
    let said = if messages.is_empty() {
        String::new()
    } else {
        format!("; QEMU said: {}", messages.join(" | "))
    };
    if timed_out {
        return Err(format!(
            "{}: QEMU did not finish within {} s and was stopped{said}",
            elf.display(),
            timeout.as_secs()
        ));
    }
    if !status.success() {
        return Err(format!(
            "{}: QEMU exited with {status}{said} (`cargo xtask qemu-runner {}` shows the image's own log)",
            elf.display(),
            elf.display()
        ));
    }
    sections.map_err(|e| format!("{}: {e}{said}", elf.display()))
}

/// The report: per core and section, instructions per tick and the `top`
/// functions, each with its two costliest call sites (`lines` of the
/// core's image).
pub fn report(results: &[(&str, Vec<Section>, Lines)], top: usize) -> String {
    let mut s = String::new();
    for (core, sections, lines) in results {
        for (name, section) in SECTIONS.iter().zip(sections) {
            let (lo, hi) = section.cycles_per_instruction();
            s += &format!(
                "\n### {core}: {name} ({} instructions per tick, mean over {} ticks; {}-{} cycles per tick, {lo:.2}-{hi:.2} per instruction)\n\n| function | per tick | share | called from (per tick) |\n| --- | ---: | ---: | --- |\n",
                section.per_tick(section.total),
                section.tick_count(),
                section.per_tick(section.cycles.0),
                section.per_tick(section.cycles.1),
            );
            let mut rows: Vec<(&String, &u64)> = section.functions.iter().collect();
            rows.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
            let shown: u64 = rows.iter().take(top).map(|r| *r.1).sum();
            for (f, n) in rows.iter().take(top) {
                // Call sites by source line (one line may hold several calls).
                let mut by_line: HashMap<String, u64> = HashMap::new();
                for (a, n) in section.sites.get(*f).into_iter().flatten() {
                    if *a != 0 {
                        let at = lines.at(*a).unwrap_or_else(|| lines.symbols.describe(*a));
                        *by_line.entry(at).or_insert(0) += n;
                    }
                }
                let mut sites: Vec<(String, u64)> = by_line.into_iter().collect();
                sites.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
                let called: Vec<String> = sites
                    .iter()
                    .take(2)
                    .map(|(at, n)| format!("`{at}` {}", section.per_tick(*n)))
                    .collect();
                s += &format!(
                    "| `{f}` | {} | {:.1} % | {} |\n",
                    section.per_tick(**n),
                    share(**n, section.total),
                    called.join(", ")
                );
            }
            if rows.len() > top {
                let rest = section.total - shown;
                s += &format!(
                    "| {} other functions | {} | {:.1} % | |\n",
                    rows.len() - top,
                    section.per_tick(rest),
                    share(rest, section.total)
                );
            }
            if let Some((k, counts)) = &section.worst {
                let mut rows: Vec<(&String, &u64)> = counts.iter().collect();
                rows.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
                let parts: Vec<String> = rows.iter().take(top).map(|(f, n)| format!("`{f}` {n}")).collect();
                s += &format!(
                    "\nWorst tick: tick {k}, {} instructions ({}-{} cycles): {}.\n",
                    section.worst_total(),
                    section.worst_cycles.0,
                    section.worst_cycles.1,
                    parts.join(", ")
                );
            }
        }
    }
    s
}

fn share(n: u64, total: u64) -> f64 {
    if total == 0 {
        0.0
    } else {
        100.0 * n as f64 / total as f64
    }
}

/// The profile image for `target`.
pub fn image(target: &'static str) -> Image {
    Image {
        bin: "profile",
        target,
        features: "qemu",
    }
}

/// `cargo xtask profile`: builds the profile image for each of `targets`
/// with `tc` (which covers them; QEMU installed), runs it and prints the
/// report.
///
/// # Errors
///
/// A build fails, the ELF cannot be read, or a run fails ([`run`]).
pub fn cmd(
    tc: &Toolchain,
    root: &Path,
    params: Option<&Path>,
    targets: &[&'static str],
    top: usize,
) -> Result<(), String> {
    let mut results = Vec::new();
    for &target in targets {
        let (elf, symbols, sections) = profile_target(tc, root, params, target)?;
        results.push((core_name(target), sections, Lines::new(&elf, root, symbols)));
    }
    let file = params.map_or_else(|| "presets/paper.toml".to_string(), |p| p.display().to_string());
    println!(
        "Profile of {file} (the twin as its build chose it)\n{}",
        report(&results, top)
    );
    Ok(())
}

/// The estimator section's cycles per instruction on `target`'s core,
/// lower and upper ([`Section::cycles_per_instruction`]): the profile image
/// built with `tc` for `params`, traced on QEMU and timed by
/// [`crate::cycles`]. What `cargo xtask bench` turns instructions into
/// cycles with.
///
/// # Errors
///
/// As [`cmd`]; `llvm-objdump` missing.
#[cfg_attr(not(feature = "host"), allow(dead_code, reason = "the bench's, a host-only command"))]
pub fn cycles_per_instruction(
    tc: &Toolchain,
    root: &Path,
    params: Option<&Path>,
    target: &'static str,
) -> Result<(f64, f64), String> {
    let (_, _, sections) = profile_target(tc, root, params, target)?;
    let estimator = sections.get(1).ok_or("the profile has no estimator section")?;
    Ok(estimator.cycles_per_instruction())
}

/// The profile image for `target` built with `tc` for `params`, its
/// symbols, and its sections traced on QEMU and timed ([`run`]).
fn profile_target(
    tc: &Toolchain,
    root: &Path,
    params: Option<&Path>,
    target: &'static str,
) -> Result<(std::path::PathBuf, Symbols, Vec<Section>), String> {
    let image = image(target);
    let elf = firmware::build(tc, root, &image, params)?;
    eprintln!(
        "xtask: profiling {} ({target}, QEMU {})",
        core_name(target),
        image.machine().name
    );
    let bytes = std::fs::read(&elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let symbols = Symbols::of_elf(&bytes).map_err(|e| format!("{}: {e}", elf.display()))?;
    let timing = Timing::of_elf(&elf, Core::of_target(target))?;
    let sections = run(
        &elf,
        &symbols,
        Some(&timing),
        image.machine(),
        TIMEOUT,
        sections_for(params),
    )?;
    Ok((elf, symbols, sections))
}

/// The core a target is profiled on.
pub fn core_name(target: &str) -> &'static str {
    match target {
        firmware::M3 => "Cortex-M3",
        firmware::M0 => "Cortex-M0",
        _ => "Cortex-M4F",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn symbols() -> Symbols {
        Symbols::new([
            (0x0800_0101, 0x20, "profile_mark".to_string()),
            (
                0x0800_0201,
                0x40,
                "_ZN11compensator5mathf5exp1017hee4bb093ed8cfc4aE".to_string(),
            ),
            (0x0800_0300, 0x10, "tick".to_string()),
        ])
    }

    fn line(pc: u64) -> String {
        format!("Trace 0: 0x7eff7c197200 [00800400/{pc:08x}/00000010/ff000201] whatever\n")
    }

    #[test]
    fn cycles_follow_each_instruction_and_whether_its_branch_was_taken() {
        // tick: a load, a conditional branch taken once and not once, a
        // return (taken), on the Cortex-M4F.
        let timing = Timing::of_disassembly(
            " 8000300: 12 48        \tldr\tr0, [pc, #72]\n 8000302: 01 d0        \tbeq\t0x8000306\n 8000304: 00 bf        \tnop\n 8000306: 70 47        \tbx\tlr\n",
            Core::M4F,
        );
        let mut trace = line(0x0800_0100);
        for pc in [
            0x0800_0300,
            0x0800_0302,
            0x0800_0306,
            0x0800_0300,
            0x0800_0302,
            0x0800_0304,
            0x0800_0306,
        ] {
            trace += &line(pc);
        }
        // The return's target: back in the (uncounted) caller.
        trace += &line(0x0800_0100);
        trace += &line(0x0800_0100);
        trace += &line(0x0800_0100);
        let s = symbols();
        let out = attribute(
            trace.as_bytes(),
            &s,
            0x0800_0100,
            None,
            2,
            Some(&timing),
            &mut Vec::new(),
        )
        .unwrap();
        // ldr 1-2 twice, beq taken 2-4 and untaken 1, nop 1, bx taken
        // twice (the second time into the mark) 2-4 each.
        assert_eq!(out[0].total, 7);
        assert_eq!(out[0].cycles, (2 + 2 + 1 + 1 + 4, 4 + 4 + 1 + 1 + 8));
        let (lo, hi) = out[0].cycles_per_instruction();
        assert!((lo - 10.0 / 7.0).abs() < 1e-12 && (hi - 18.0 / 7.0).abs() < 1e-12);
        assert_eq!(out[1].cycles, (0, 0));
        assert!(out[1].cycles_per_instruction().0.is_nan());
    }

    #[test]
    fn the_program_counter_is_the_second_field_in_brackets() {
        assert_eq!(
            pc_of("Trace 0: 0x7eff7c197200 [00800400/080078f0/00000010/ff000201] profile_mark"),
            Some(0x0800_78f0)
        );
        assert_eq!(pc_of("IN: profile_mark"), None);
        assert_eq!(pc_of("Trace 0: 0x7eff [00800400/zz/0] f"), None);
    }

    #[test]
    fn symbols_are_demangled_and_cover_their_size_only() {
        let s = symbols();
        assert_eq!(
            s.covering(0x0800_0200),
            Some((0x0800_0200, "compensator::mathf::exp10"))
        );
        assert_eq!(
            s.covering(0x0800_023f),
            Some((0x0800_0200, "compensator::mathf::exp10"))
        );
        assert_eq!(s.covering(0x0800_0240), None);
        assert_eq!(s.covering(0x0800_00ff), None);
        assert_eq!(s.address("profile_mark"), Some(0x0800_0100));
    }

    #[test]
    fn instructions_between_marks_go_to_their_section_and_function() {
        let s = symbols();
        let mut trace = String::new();
        trace += &line(0x0800_0300); // before the first section: not counted
        trace += &line(0x0800_0100); // mark: opens the twin section
        trace += &line(0x0800_0102); // the marker's own body: not counted
        for _ in 0..3 {
            trace += &line(0x0800_0300);
        }
        trace += &line(0x0800_0100); // closes it
        trace += &line(0x0800_0204); // between sections: not counted
        trace += &line(0x0800_0100); // opens the estimator section
        trace += &line(0x0800_0302); // tick's call
        trace += &line(0x0800_0200); // exp10's entry, from 0x0800_0302
        trace += &line(0x0800_0206);
        trace += &line(0x0900_0000); // no symbol
        trace += &line(0x0800_0100);
        let out = attribute(trace.as_bytes(), &s, 0x0800_0100, None, 2, None, &mut Vec::new()).unwrap();
        assert_eq!(out[0].total, 3);
        assert_eq!(out[0].functions["tick"], 3);
        assert_eq!(out[1].total, 4);
        assert_eq!(out[1].functions["compensator::mathf::exp10"], 2);
        assert_eq!(out[1].functions["?"], 1);
        assert_eq!(
            out[1].sites["compensator::mathf::exp10"],
            HashMap::from([(0x0800_0302, 2)])
        );
        // tick was entered before the section opened: no call site.
        assert_eq!(out[1].sites["tick"], HashMap::from([(0, 1)]));
        let none = Lines {
            loader: None,
            root: String::new(),
            symbols: Symbols::default(),
        };
        let r = report(&[("Cortex-M4F", out, none)], 1);
        assert!(
            r.contains("| `compensator::mathf::exp10` | 0.0 | 50.0 % | `0x08000302` 0.0 |"),
            "{r}"
        );
        assert!(r.contains("| 2 other functions | 0.0 | 50.0 % | |"), "{r}");
    }

    #[test]
    fn the_worst_tick_is_the_costliest_between_tick_marks() {
        let s = Symbols::new([
            (0x0800_0100, 0x20, "profile_mark".to_string()),
            (0x0800_0400, 0x10, "profile_tick".to_string()),
            (0x0800_0300, 0x10, "tick".to_string()),
        ]);
        let mut trace = String::new();
        for section in [[2, 3, 1], [4, 1, 1]] {
            trace += &line(0x0800_0100);
            for n in section {
                trace += &line(0x0800_0400);
                trace += &line(0x0800_0402); // the marker's body: not counted
                for _ in 0..n {
                    trace += &line(0x0800_0304);
                }
            }
            trace += &line(0x0800_0100);
        }
        let out = attribute(
            trace.as_bytes(),
            &s,
            0x0800_0100,
            Some(0x0800_0400),
            2,
            None,
            &mut Vec::new(),
        )
        .unwrap();
        assert_eq!(out[0].total, 6);
        assert_eq!(out[0].worst, Some((1, HashMap::from([("tick".to_string(), 3)]))));
        assert_eq!(out[1].worst_total(), 4);
        assert_eq!(out[1].worst.as_ref().map(|w| w.0), Some(0));
    }

    #[test]
    fn a_return_keeps_the_call_site_and_two_callers_are_told_apart() {
        let s = Symbols::new([
            (0x0800_0100, 0x20, "profile_mark".to_string()),
            (0x0800_0200, 0x10, "leaf".to_string()),
            (0x0800_0300, 0x40, "caller".to_string()),
        ]);
        let mut trace = line(0x0800_0100);
        trace += &line(0x0800_0300); // caller's entry, from the marker
        trace += &line(0x0800_0304); // bl leaf
        trace += &line(0x0800_0200);
        trace += &line(0x0800_0202);
        trace += &line(0x0800_0206);
        trace += &line(0x0800_0308); // returns into caller, not at its start
        trace += &line(0x0800_0310); // bl leaf again, from elsewhere
        trace += &line(0x0800_0200);
        trace += &line(0x0800_0312);
        trace += &line(0x0800_0100);
        trace += &line(0x0800_0100);
        trace += &line(0x0800_0100);
        let out = attribute(trace.as_bytes(), &s, 0x0800_0100, None, 2, None, &mut Vec::new()).unwrap();
        assert_eq!(
            out[0].sites["leaf"],
            HashMap::from([(0x0800_0304, 3), (0x0800_0310, 1)])
        );
        // The return did not make leaf the caller's call site.
        assert_eq!(out[0].sites["caller"], HashMap::from([(0, 5)]));
        assert_eq!(out[0].total, 9);
        let lines = Lines {
            loader: None,
            root: String::new(),
            symbols: Symbols::new([(0x0800_0300, 0x40, "caller".to_string())]),
        };
        let r = report(&[("Cortex-M0", out, lines)], 2);
        assert!(
            r.contains("| `leaf` | 0.0 | 44.4 % | `caller+0x4` 0.0, `caller+0x10` 0.0 |"),
            "{r}"
        );
        // Every function shown: no "other functions" row.
        assert!(!r.contains("other functions"), "{r}");
    }

    #[test]
    fn source_paths_are_shown_short() {
        let root = "/work/main/";
        assert_eq!(
            shorten("/work/main/model/src/estimator/mod.rs", root),
            "model/src/estimator/mod.rs"
        );
        assert_eq!(
            shorten(
                "/rustc/59807616e1fa2540724bfbac14d7976d7e4a3860/library/core/src/result.rs",
                root
            ),
            "library/core/src/result.rs"
        );
        assert_eq!(
            shorten(
                "/root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/defmt-1.2.0/src/lib.rs",
                root
            ),
            "defmt-1.2.0/src/lib.rs"
        );
        assert_eq!(shorten("/elsewhere/x.rs", root), "/elsewhere/x.rs");
    }

    #[test]
    fn aliases_are_one_range_named_by_both() {
        let s = Symbols::new([
            (0x0800_0500, 0x8, "DefaultPreInit".to_string()),
            (0x0800_0500, 0x8, "__defmt_default_timestamp".to_string()),
        ]);
        assert_eq!(
            s.covering(0x0800_0504),
            Some((0x0800_0500, "DefaultPreInit = __defmt_default_timestamp"))
        );
        assert_eq!(s.address("__defmt_default_timestamp"), Some(0x0800_0500));
    }

    #[test]
    fn qemu_messages_are_kept_for_the_error() {
        let s = symbols();
        let trace = "qemu-system-arm: -singlestep: invalid option\n\n";
        let mut messages = Vec::new();
        let e = attribute(trace.as_bytes(), &s, 0x0800_0100, None, 2, None, &mut messages).unwrap_err();
        assert!(e.contains("0 section marks"), "{e}");
        assert_eq!(messages, ["qemu-system-arm: -singlestep: invalid option"]);
    }

    #[test]
    fn a_run_that_stops_early_is_an_error() {
        let s = symbols();
        let trace = format!("{}{}", line(0x0800_0100), line(0x0800_0300));
        let e = attribute(trace.as_bytes(), &s, 0x0800_0100, None, 2, None, &mut Vec::new()).unwrap_err();
        assert!(e.contains("1 section marks, expected 4"), "{e}");
    }
}
