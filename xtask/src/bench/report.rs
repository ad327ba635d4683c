//! The Markdown of `cargo xtask bench` (and of `docs/bench.md` with
//! `--write`): the budget table, and with the `host` feature the full
//! report (estimator pieces, the twin's tick by scheme, accuracy against
//! cost).

use super::Firmware;
#[cfg(feature = "host")]
use super::QEMU_TWIN;
use super::budgets::{
    BUDGET_FIXED_FLASH, BUDGET_FIXED_OVER_SOFT, BUDGET_FIXED_RAM, BUDGET_FIXED_TWIN_M3, BUDGET_INSTRUCTIONS,
    BUDGET_RAM, BUDGET_STACK, BUDGET_TWIN_PAPER, Budget, flash_budget,
};
use super::{M0_TWIN, M3_TWIN};
#[cfg(feature = "host")]
use super::{accuracy::Accuracy, measure::Config, measure::Costs};
use std::fmt::Write as _;

/// The budget table.
pub fn budget_table(fw: &Firmware, budget: &Budget) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "| what | measured | goal |\n| --- | --- | --- |");
    for e in &budget.estimator {
        let built = match (&fw.monitor, e.monitor) {
            (Some(m), true) => format!(", as built for {}", m.params),
            _ => String::new(),
        };
        let _ = writeln!(
            t,
            "| {}{built}, Cortex-M4F f32 (step and ramps) | mean {:.0}, worst {:.0} instructions | <= {BUDGET_INSTRUCTIONS:.0} |",
            e.what(),
            e.mean,
            e.worst
        );
    }
    if let Some(m) = &fw.monitor {
        let piece = |name: &str| m.costs.piece(name).unwrap_or(f64::NAN);
        let _ = writeln!(
            t,
            "| the monitor's update alone (one reading: filter, tests, isolation), Cortex-M4F f32 | mean {:.0}, worst {:.0} instructions | measured (in a job's place) |",
            piece("monitor-update-mean"),
            piece("monitor-update-worst")
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
    for f in &budget.fixed {
        let paper = if f.core == "Cortex-M3" && twin.on_paper_preset() {
            format!(", worst <= {BUDGET_FIXED_TWIN_M3:.0} (paper preset)")
        } else {
            String::new()
        };
        let _ = writeln!(
            t,
            "| twin tick as built ({}), {}, Q12.20 against soft-float f32 | mean {:.0} (worst {:.0}) against {:.0} instructions: {:.2} | <= {BUDGET_FIXED_OVER_SOFT}{paper} |",
            twin.built.config,
            f.core,
            f.fixed,
            f.fixed_worst,
            f.soft,
            f.fixed / f.soft
        );
    }
    let mut fixed_stacks = fw.fixed_stacks.iter();
    for f in &fw.footprints {
        if f.label == M3_TWIN || f.label == M0_TWIN {
            let stack = fixed_stacks.next().copied().unwrap_or(0);
            let _ = writeln!(
                t,
                "| flash, {} | {:.1} KiB | <= {} KiB |",
                f.label,
                f.flash as f64 / 1024.0,
                BUDGET_FIXED_FLASH / 1024
            );
            let _ = writeln!(
                t,
                "| static RAM and peak stack, {} | {} + {stack} bytes | <= {} KiB |",
                f.label,
                f.ram,
                BUDGET_FIXED_RAM / 1024
            );
            continue;
        }
        let _ = writeln!(
            t,
            "| flash, {} | {:.1} KiB | <= {} KiB |",
            f.label,
            f.flash as f64 / 1024.0,
            flash_budget(f.label) / 1024
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

#[cfg(feature = "host")]
/// Clock rates of the tick-rate table [MHz].
pub const CLOCKS_MHZ: [f64; 3] = [48.0, 72.0, 168.0];

#[cfg(feature = "host")]
/// The per-core section: each core's twin and estimator in the arithmetic
/// it can use, footprint and stack, and the tick rate it sustains.
pub fn cores_section(fw: &Firmware) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "\n## The whole estimator per core\n\nThe twin as built (200 ticks of the 30 -> 40 C step), the estimator's tick with telemetry \
         packing (mean over the step workload, worst over the step and the ramps), in Q12.20 and in \
         `f32` (the FPU's on the Cortex-M4F, in software on the others); the footprint and the peak \
         stack of each core's QEMU twin image (the replay with its self-checks; Q12.20 on the FPU-less \
         cores, `f32` on the Cortex-M4F).\n"
    );
    let _ = writeln!(
        t,
        "| core (QEMU board) | twin Q12.20 mean / worst | twin f32 mean / worst | estimator Q12.20 mean / worst | estimator f32 mean / worst | flash | static RAM | peak stack |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let built = fw.m4.built.as_ref().map(|b| b.config.clone()).unwrap_or_default();
    let stacks = [fw.stack, fw.fixed_stacks[0], fw.fixed_stacks[1]];
    let labels = [QEMU_TWIN, M3_TWIN, M0_TWIN];
    for (i, (core, board, costs, f32_name)) in [
        ("Cortex-M4F", "netduinoplus2", &fw.m4, "f32"),
        ("Cortex-M3", "netduino2", &fw.m3, "f32-soft"),
        ("Cortex-M0", "microbit", &fw.m0, "f32-soft"),
    ]
    .into_iter()
    .enumerate()
    {
        let twin = |scalar: &str| {
            costs
                .twin(&built, scalar)
                .map_or("-".into(), |r| format!("{:.0} / {:.0}", r.mean, r.worst))
        };
        let est = |scalar: &str| {
            costs
                .estimator(scalar, true)
                .map_or("-".into(), |(m, w)| format!("{m:.0} / {w:.0}"))
        };
        let f = fw.footprints.iter().find(|f| f.label == labels[i]);
        let _ = writeln!(
            t,
            "| {core} ({board}) | {} | {} | {} | {} | {} | {} | {} bytes |",
            twin("q12.20"),
            twin(f32_name),
            est("q12.20"),
            est(f32_name),
            f.map_or("-".into(), |f| format!("{:.1} KiB", f.flash as f64 / 1024.0)),
            f.map_or("-".into(), |f| format!("{} bytes", f.ram)),
            stacks[i]
        );
    }
    let _ = writeln!(
        t,
        "\n### The highest tick rate each core sustains\n\nWith 50 % headroom: the worst estimator tick (telemetry included) in the core's arithmetic \
         (f32 with the FPU, Q12.20 without) may take half of the tick's period, at the core's cycles \
         per instruction: the estimator tick of `src/bin/profile.rs` traced on QEMU instruction by \
         instruction (`cargo xtask profile`, docs/profile.md), each executed instruction given its \
         cycles from Arm's Technical Reference Manuals (`xtask/src/cycles.rs`: Cortex-M0 DDI 0432C \
         table 3-1, Cortex-M3 DDI 0337I table 18-1, Cortex-M4 DDI 0439B table 3-1 and its FPU's; a \
         taken branch as taken; zero-wait-state memory), the lower and upper ends of the manuals' \
         ranges (branch refill 1-3 cycles, pipelined loads, division 2-12). The rate uses the upper \
         end: rate = clock / (2 x cycles per instruction x worst instructions).\n"
    );
    let _ = write!(
        t,
        "| core | arithmetic | worst tick [instructions] | cycles per instruction |"
    );
    for mhz in CLOCKS_MHZ {
        let _ = write!(t, " at {mhz:.0} MHz |");
    }
    let _ = writeln!(t, "\n| --- | --- | --- | --- |{}", " --- |".repeat(CLOCKS_MHZ.len()));
    for (core, costs, scalar) in [
        ("Cortex-M4F", &fw.m4, "f32"),
        ("Cortex-M3", &fw.m3, "q12.20"),
        ("Cortex-M0", &fw.m0, "q12.20"),
    ] {
        let i = ["Cortex-M4F", "Cortex-M3", "Cortex-M0"]
            .iter()
            .position(|c| *c == core)
            .unwrap_or(0);
        let (low, cpi) = fw.cpi.map_or((f64::NAN, f64::NAN), |c| c[i]);
        let worst = costs.estimator(scalar, true).map_or(f64::NAN, |(_, w)| w);
        let _ = write!(t, "| {core} | {scalar} | {worst:.0} | {low:.2}-{cpi:.2} |");
        for mhz in CLOCKS_MHZ {
            let _ = write!(t, " {:.0} Hz |", mhz * 1e6 / (2.0 * cpi * worst));
        }
        let _ = writeln!(t);
    }
    t
}

#[cfg(feature = "host")]
/// The cost of each operation of the Q12.20 tick per core, and of what it
/// replaces or competes with.
pub fn operations_section(fw: &Firmware) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "\n## Fixed-point operations per core\n\nOne operation out of line, the mean over 16 operand pairs spanning the tick's ranges (an \
         empty call subtracted; for `f32`, the conversions from Q12.20 too), in instructions. `mul`, \
         `div`, `sqrt`: Q12.20 rounded to nearest and saturating (`model/src/scalar/kernels.rs`); \
         `sqrt-recip`: the root of a sum of two exact products and its reciprocal, what the stage root \
         takes (`Real::sqrt_recip_sum_products`); `i64-mul`: a 32 x 32 -> 64 product (one `SMULL` on \
         the Cortex-M3/M4, `__aeabi_lmul` on the Cortex-M0); `i64-div`: a 64-bit quotient \
         (`compiler_builtins`, what the quotient was before).\n"
    );
    let names = [
        "mul",
        "div",
        "sqrt",
        "sqrt-recip",
        "add",
        "i64-mul",
        "i64-div",
        "f32-mul",
        "f32-div",
        "f32-sqrt",
    ];
    let _ = writeln!(
        t,
        "| operation | Cortex-M4F | Cortex-M3 | Cortex-M0 |\n| --- | --- | --- | --- |"
    );
    for name in names {
        let cell = |c: &Costs| c.operation(name).map_or("-".into(), |v| format!("{v:.0}"));
        let _ = writeln!(t, "| {name} | {} | {} | {} |", cell(&fw.m4), cell(&fw.m3), cell(&fw.m0));
    }
    t
}

/// The telemetry record's cost by field kind: the `telemetry-field-*`
/// pieces (encoding one field) and `telemetry-byte` (what a byte adds to
/// sending the record), from the bench image's pieces.
#[cfg(feature = "host")]
fn telemetry_section(m4: &Costs) -> String {
    use compensator::estimator::telemetry::{Encoding, FIELDS, HEALTH_FROM, SIZE, SIZE_MONITOR};
    let piece = |name: &str| m4.pieces.iter().find(|p| p.name == name).map(|p| p.instructions);
    let mut t = String::new();
    let _ = writeln!(t, "\n## Telemetry record (Cortex-M4F)\n");
    let _ = writeln!(
        t,
        "The record (`model/src/estimator/telemetry.rs`) is {SIZE} bytes: a 2-byte layout tag, {HEALTH_FROM} fields, \
         the 4-byte flags ({SIZE_MONITOR} bytes and {} fields in an image with the condition monitor, whose \
         health parameters it adds). Sending it whole (`telemetry`: packing and the defmt frame through the QEMU \
         logger) costs {:.0} instructions, packing alone (`telemetry-pack`) {:.0}. A field costs its \
         encoding plus its bytes at `telemetry-byte` each (the QEMU logger's copy into its frame buffer; on the board, defmt-rtt's copy into its ring buffer):\n",
        FIELDS.len(),
        piece("telemetry").unwrap_or(f64::NAN),
        piece("telemetry-pack").unwrap_or(f64::NAN),
    );
    let _ = writeln!(
        t,
        "| field kind | bytes | encoding (instructions) | sending its bytes | per field |\n| --- | --- | --- | --- | --- |"
    );
    let per_byte = piece("telemetry-byte").unwrap_or(f64::NAN);
    for (kind, encoding) in [
        ("f32", Encoding::F32),
        ("u16 x step", Encoding::U16 { step: 1.0 }),
        ("i16 x step", Encoding::I16 { step: 1.0 }),
        ("u32", Encoding::U32),
    ] {
        let name = format!("telemetry-field-{}", &kind[..3]);
        let encode = piece(&name).unwrap_or(f64::NAN);
        let bytes = encoding.size() as f64;
        let _ = writeln!(
            t,
            "| {kind} | {bytes:.0} | {encode:.1} | {:.1} | {:.0} |",
            bytes * per_byte,
            encode + bytes * per_byte
        );
    }
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
    let _ = writeln!(
        t,
        "{:.3} on netduino2, {:.1} on microbit, whose 16 MHz SysTick resolves the Cortex-M0's worst ticks to that).\n",
        m3.per_count, fw.m0.per_count
    );
    let _ = writeln!(t, "## Budget\n");
    t.push_str(&budget_table(fw, budget));

    t.push_str(&cores_section(fw));
    t.push_str(&operations_section(fw));

    let _ = writeln!(t, "\n## Estimator pieces (Cortex-M4F, f32, one call each)\n");
    let _ = writeln!(t, "| piece | instructions |\n| --- | --- |");
    for p in &m4.pieces {
        let _ = writeln!(t, "| {} | {:.0} |", p.name, p.instructions);
    }

    t.push_str(&telemetry_section(m4));

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
        "| scheme | steps per tick | Cortex-M4F f32 mean / worst (graded) | Cortex-M4F Q12.20 mean / worst (graded) | Cortex-M3 Q12.20 mean / worst (graded) | Cortex-M3 soft f32 mean / worst (graded) | Cortex-M0 Q12.20 mean / worst (graded) | Cortex-M0 soft f32 mean / worst (graded) |"
    );
    let _ = writeln!(t, "| --- | --- | --- | --- | --- | --- | --- | --- |");
    let cell = |c: &Costs, config: &Config, scalar: &str| {
        c.twin(config, scalar)
            .map(|r| format!("{:.0} / {:.0} ({:.0})", r.mean, r.worst, r.graded))
            .unwrap_or_else(|| "-".into())
    };
    for config in &m4.configs() {
        let _ = writeln!(
            t,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            config.scheme,
            config.substeps,
            cell(m4, config, "f32"),
            cell(m4, config, "q12.20"),
            cell(m3, config, "q12.20"),
            cell(m3, config, "f32-soft"),
            cell(&fw.m0, config, "q12.20"),
            cell(&fw.m0, config, "f32-soft")
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
    t
}
