//! The Markdown of `cargo xtask bench` (and of `docs/bench.md` with
//! `--write`): the budget table, and with the `host` feature the full
//! report (estimator pieces, the twin's tick by scheme, accuracy against
//! cost).

use super::Firmware;
use super::budgets::{BUDGET_FLASH, BUDGET_INSTRUCTIONS, BUDGET_RAM, BUDGET_STACK, BUDGET_TWIN_PAPER, Budget};
#[cfg(feature = "host")]
use super::{accuracy::Accuracy, measure::Config, measure::Costs};
use std::fmt::Write as _;

/// The budget table.
pub fn budget_table(fw: &Firmware, budget: &Budget) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "| what | measured | goal |\n| --- | --- | --- |");
    for e in &budget.estimator {
        let _ = writeln!(
            t,
            "| {}, Cortex-M4F f32 (step and ramps) | mean {:.0}, worst {:.0} instructions | <= {BUDGET_INSTRUCTIONS:.0} |",
            e.what(),
            e.mean,
            e.worst
        );
    }
    let twin = &budget.twin;
    let goal = if twin.on_paper_preset() {
        format!("<= {BUDGET_TWIN_PAPER:.0} (paper preset)")
    } else {
        "measured".to_string()
    };
    let _ = writeln!(
        t,
        "| twin tick alone, as built for {} ({}, f32), Cortex-M4F | mean {:.0}, worst {:.0} instructions (the graded tick after an abrupt step: {:.0}) | {goal} |",
        twin.built.params, twin.built.config, twin.mean, twin.worst, twin.graded
    );
    for e in &fw.m4.events {
        let _ = writeln!(
            t,
            "| twin tick through a 1 C/s ramp across the opening ({}s), Cortex-M4F | mean {:.0}, worst {:.0} instructions | measured (the estimator defers its job then) |",
            e.kind, e.mean, e.worst
        );
    }
    for f in &fw.footprints {
        let _ = writeln!(
            t,
            "| flash, {} | {:.1} KiB | <= {} KiB |",
            f.label,
            f.flash as f64 / 1024.0,
            BUDGET_FLASH / 1024
        );
        let _ = writeln!(
            t,
            "| static RAM, {} | {} bytes | <= {} KiB |",
            f.label,
            f.ram,
            BUDGET_RAM / 1024
        );
    }
    let _ = writeln!(
        t,
        "| peak stack, QEMU twin run (stack painting) | {} bytes | <= {} KiB |",
        fw.stack,
        BUDGET_STACK / 1024
    );
    t
}

/// The full report: budget, pieces, the scheme cost table and the
/// accuracy-against-cost table (`accuracy`: the host simulations of the
/// configurations measured).
#[cfg(feature = "host")]
pub fn document(fw: &Firmware, budget: &Budget, accuracy: &[Accuracy]) -> String {
    let (m4, m3) = (&fw.m4, &fw.m3);
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
    let _ = writeln!(t, "## Budget\n");
    t.push_str(&budget_table(fw, budget));

    let _ = writeln!(t, "\n## Estimator pieces (Cortex-M4F, f32, one call each)\n");
    let _ = writeln!(t, "| piece | instructions |\n| --- | --- |");
    for p in &m4.pieces {
        let _ = writeln!(t, "| {} | {:.0} |", p.name, p.instructions);
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
    let cell = |c: &Costs, config: &Config, scalar: &str| {
        c.twin(config, scalar)
            .map(|r| format!("{:.0} / {:.0} ({:.0})", r.mean, r.worst, r.graded))
            .unwrap_or_else(|| "-".into())
    };
    for config in &m4.configs() {
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} |",
            config.scheme,
            config.substeps,
            cell(m4, config, "f32"),
            cell(m4, config, "q12.20"),
            cell(m3, config, "q12.20")
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
    let cost_of = |a: &Accuracy| m4.twin(&a.config, "f32").map_or(f64::NAN, |r| r.mean);
    let built = m4.built.as_ref().map(|b| b.config.clone()).unwrap_or_default();
    let pct = |e: f64| {
        if e.is_finite() {
            format!("{e:.4} %")
        } else {
            "unstable".into()
        }
    };
    for (i, a) in accuracy.iter().enumerate() {
        let cost = cost_of(a);
        let dominated = accuracy.iter().enumerate().any(|(j, b)| {
            let c2 = cost_of(b);
            j != i && b.f32 <= a.f32 && c2 <= cost && (b.f32 < a.f32 || c2 < cost)
        });
        let shipped = if a.config == built { " (built)" } else { "" };
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {cost:.0} | {}{shipped} |",
            a.config.scheme,
            a.config.substeps,
            pct(a.f64),
            pct(a.f32),
            pct(a.fixed),
            if dominated || !a.f32.is_finite() { "" } else { "yes" }
        );
    }
    if let Some(r) = m3.twin.iter().find(|r| r.scalar == "f32-soft") {
        let _ = writeln!(
            t,
            "\nFor comparison, {} in soft-float f32 on the Cortex-M3: mean {:.0}, worst {:.0} instructions per tick.",
            r.config, r.mean, r.worst
        );
    }
    t
}
