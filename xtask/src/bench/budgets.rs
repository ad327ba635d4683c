//! The firmware's budgets and the check of the measurements against
//! them (`cargo xtask bench`, and `cargo xtask test` through
//! [`super::check`]).

use super::Firmware;
use super::measure::Built;

/// The firmware's budgets.
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
/// moves in (4.3-4.8 KiB since the twin carries its graded-piece scheme,
/// its flow unit and the stop events; frames in the disassembly: `main`
/// 3.0 KiB, `Twin::new` 1.1 KiB, a twin tick's about 0.5 KiB).
/// The board's stack has the 64 KiB CCM to itself (`link/memory-board.x`),
/// so 6 KiB keeps a margin of ten.
pub const BUDGET_STACK: u64 = 6 * 1024;

/// The estimator's tick on the Cortex-M4F, with or without telemetry
/// packing, over every workload [instructions].
#[derive(Debug, Clone)]
pub struct EstimatorBudget {
    pub telemetry: bool,
    /// The mean of the first workload (the step).
    pub mean: f64,
    /// The worst of every workload: what the budget bounds.
    pub worst: f64,
}

impl EstimatorBudget {
    /// The row's name.
    pub fn what(&self) -> &'static str {
        if self.telemetry {
            "estimator tick with telemetry packing"
        } else {
            "estimator tick, no telemetry"
        }
    }
}

/// The twin's tick alone, as built, on the Cortex-M4F in `f32` [instructions].
#[derive(Debug, Clone)]
pub struct TwinBudget {
    pub built: Built,
    pub mean: f64,
    pub worst: f64,
    /// The graded tick after the abrupt step (not bounded).
    pub graded: f64,
}

impl TwinBudget {
    /// Built for the paper preset: the only file with a twin budget.
    pub fn on_paper_preset(&self) -> bool {
        self.built.params == "paper.toml"
    }
}

/// The measurements the budgets bound, and the budgets missed.
#[derive(Debug, Clone)]
pub struct Budget {
    /// With telemetry, then without.
    pub estimator: Vec<EstimatorBudget>,
    pub twin: TwinBudget,
    /// One line per budget missed, in the budget table's order.
    pub over: Vec<String>,
}

impl Budget {
    /// Checks the firmware's measurements. A measurement a budget needs and
    /// the images did not report is an error.
    pub fn of(fw: &Firmware) -> Result<Budget, String> {
        let mut over = Vec::new();
        let mut estimator = Vec::new();
        for telemetry in [true, false] {
            let rows: Vec<_> = fw.m4.estimator.iter().filter(|e| e.telemetry == telemetry).collect();
            let first = rows.first().ok_or("the bench image reported no estimator tick cost")?;
            let e = EstimatorBudget {
                telemetry,
                mean: first.mean,
                worst: rows.iter().map(|e| e.worst).fold(0.0, f64::max),
            };
            if e.worst > BUDGET_INSTRUCTIONS {
                over.push(format!(
                    "{}: worst {:.0} instructions > {BUDGET_INSTRUCTIONS:.0}",
                    e.what(),
                    e.worst
                ));
            }
            estimator.push(e);
        }
        let built = fw
            .m4
            .built
            .clone()
            .ok_or("the bench image reported no built configuration")?;
        let cost = fw
            .m4
            .twin(&built.config, "f32")
            .ok_or("the bench image reported no cost of the built twin")?;
        let twin = TwinBudget {
            mean: cost.mean,
            worst: cost.worst,
            graded: cost.graded,
            built,
        };
        if twin.on_paper_preset() && twin.worst > BUDGET_TWIN_PAPER {
            over.push(format!(
                "twin tick on the paper preset: worst {:.0} instructions > {BUDGET_TWIN_PAPER:.0}",
                twin.worst
            ));
        }
        for f in &fw.footprints {
            if f.flash > BUDGET_FLASH {
                over.push(format!("flash of the {}: {} bytes", f.label, f.flash));
            }
            if f.ram > BUDGET_RAM {
                over.push(format!("static RAM of the {}: {} bytes", f.label, f.ram));
            }
        }
        if fw.stack > BUDGET_STACK {
            over.push(format!("peak stack {} bytes", fw.stack));
        }
        Ok(Budget { estimator, twin, over })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::footprint::Footprint;
    use crate::bench::measure::{Costs, tests::lines};
    use crate::bench::report::budget_table;

    fn firmware(extra: &[&str], flash: u64, stack: u64) -> Firmware {
        let costs = || Costs::parse(&lines(extra)).unwrap();
        Firmware {
            m4: costs(),
            m3: costs(),
            stack,
            footprints: vec![Footprint {
                label: "board image",
                flash,
                ram: 1104,
            }],
        }
    }

    #[test]
    fn within_budget() {
        let fw = firmware(&[], 49766, 4580);
        let b = Budget::of(&fw).unwrap();
        assert!(b.over.is_empty(), "{:?}", b.over);
        assert_eq!(
            budget_table(&fw, &b),
            "| what | measured | goal |\n| --- | --- | --- |\n\
             | estimator tick with telemetry packing, Cortex-M4F f32 (step and ramps) | mean 1800, worst 2400 instructions | <= 3000 |\n\
             | estimator tick, no telemetry, Cortex-M4F f32 (step and ramps) | mean 1500, worst 2700 instructions | <= 3000 |\n\
             | twin tick alone, as built for paper.toml (sdirk3 x1, f32), Cortex-M4F | mean 1020, worst 1020 instructions (the graded tick after an abrupt step: 6000) | <= 1600 (paper preset) |\n\
             | twin tick through a 1 C/s ramp across the opening (releases), Cortex-M4F | mean 900, worst 2220 instructions | measured (the estimator defers its job then) |\n\
             | flash, board image | 48.6 KiB | <= 64 KiB |\n\
             | static RAM, board image | 1104 bytes | <= 8 KiB |\n\
             | peak stack, QEMU twin run (stack painting) | 4580 bytes | <= 6 KiB |\n"
        );
    }

    #[test]
    fn every_budget_missed_is_named() {
        let mut fw = firmware(
            &[
                "[measure] estimator workload=ramps scheme=sdirk3 substeps=1 telemetry=true ticks=1 total=1 worst=600 worst_tick=3",
            ],
            70000,
            7000,
        );
        fw.m4.twin[0].worst = 1700.0;
        assert_eq!(
            Budget::of(&fw).unwrap().over,
            [
                "estimator tick with telemetry packing: worst 3600 instructions > 3000",
                "twin tick on the paper preset: worst 1700 instructions > 1600",
                "flash of the board image: 70000 bytes",
                "peak stack 7000 bytes",
            ]
        );
        // Another design's twin has no budget.
        fw.m4.built.as_mut().unwrap().params = "design.toml".into();
        assert_eq!(Budget::of(&fw).unwrap().over.len(), 3);
        fw.m4.built = None;
        assert_eq!(
            Budget::of(&fw).err().unwrap(),
            "the bench image reported no built configuration"
        );
    }
}
