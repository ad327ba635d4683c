//! The firmware's `[measure] kind key=value ...` lines, read into named
//! costs. The bench image reports raw SysTick counts; its calibration line
//! converts them to instructions.

use std::collections::BTreeMap;
use std::fmt;

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

/// A twin configuration as the firmware names it. Shown as
/// `scheme xsubsteps` (`sdirk3 x1`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Config {
    /// The one-step scheme's name (`Scheme::name`).
    pub scheme: String,
    /// Steps per tick.
    pub substeps: u32,
}

impl fmt::Display for Config {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} x{}", self.scheme, self.substeps)
    }
}

/// The twin's tick cost in one configuration and scalar type
/// (200 ticks of the 30 -> 40 C step) [instructions].
#[derive(Debug, Clone)]
pub struct TwinCost {
    pub config: Config,
    /// `f32`, `q12.20`, `f32-soft`, ...
    pub scalar: String,
    /// Mean over the ticks after the first.
    pub mean: f64,
    /// Worst over the ticks after the first.
    pub worst: f64,
    /// The first tick after the abrupt step (graded).
    pub graded: f64,
}

impl TwinCost {
    /// `true` for this configuration in this scalar type.
    pub fn is(&self, config: &Config, scalar: &str) -> bool {
        self.config == *config && self.scalar == scalar
    }
}

/// The configuration the build chose.
#[derive(Debug, Clone)]
pub struct Built {
    pub config: Config,
    /// The parameter file it was chosen for (file name).
    pub params: String,
}

/// The built twin through a slow ramp across the opening [instructions per tick].
#[derive(Debug, Clone)]
pub struct EventCost {
    /// `release` (from the closed stop) or `impact` (on it).
    pub kind: String,
    pub mean: f64,
    pub worst: f64,
}

/// One estimator piece [instructions per call].
#[derive(Debug, Clone)]
#[cfg_attr(not(feature = "host"), allow(dead_code))]
pub struct PieceCost {
    pub name: String,
    pub instructions: f64,
}

/// The estimator's tick through one workload [instructions per tick].
#[derive(Debug, Clone)]
pub struct EstimatorCost {
    /// The twin's scalar type (`f32`, `f32-soft`, `q12.20`).
    pub scalar: String,
    /// With telemetry packing.
    pub telemetry: bool,
    /// With the condition monitor fitted and its sensor read.
    pub monitor: bool,
    pub mean: f64,
    pub worst: f64,
}

/// Results of one bench image.
pub struct Costs {
    /// Twin ticks by configuration and scalar type, in the image's order.
    pub twin: Vec<TwinCost>,
    pub built: Option<Built>,
    pub events: Vec<EventCost>,
    pub pieces: Vec<PieceCost>,
    /// The arithmetic of the Q12.20 tick and what it competes with, one
    /// operation each (`[measure] fixed`).
    pub operations: Vec<PieceCost>,
    /// Per workload (the step first, then the ramps), with and without telemetry.
    pub estimator: Vec<EstimatorCost>,
    /// Instructions per SysTick count.
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    pub per_count: f64,
}

impl Costs {
    /// The costs a bench image reported. An `ERROR` line, a twin run with a
    /// failed tick or a line without its numbers is an error, never a cheap
    /// (or missing) row.
    pub fn parse(lines: &[String]) -> Result<Costs, String> {
        if let Some(l) = lines.iter().find(|l| l.contains("ERROR")) {
            return Err(format!("the bench firmware reported an error: {l}"));
        }
        let ms = parse(lines);
        let k = calibration(&ms)?;
        let mut out = Costs {
            twin: vec![],
            built: None,
            events: vec![],
            pieces: vec![],
            operations: vec![],
            estimator: vec![],
            per_count: k,
        };
        for m in &ms {
            match m.kind.as_str() {
                "twin" => {
                    let ticks = m.num("ticks")?;
                    let config = Config {
                        scheme: m.str("scheme").to_string(),
                        substeps: m.num("substeps")? as u32,
                    };
                    let scalar = m.str("scalar").to_string();
                    if m.str("ok") != "true" {
                        return Err(format!("twin {config} {scalar}: a tick failed"));
                    }
                    out.twin.push(TwinCost {
                        config,
                        scalar,
                        // Mean and worst over the ticks after the graded first.
                        mean: (m.num("total")? - m.num("graded")?) * k / (ticks - 1.0).max(1.0),
                        worst: m.num("worst")? * k,
                        graded: m.num("graded")? * k,
                    });
                }
                "built" => {
                    out.built = Some(Built {
                        config: Config {
                            scheme: m.str("scheme").to_string(),
                            substeps: m.num("substeps")? as u32,
                        },
                        params: m.str("params").to_string(),
                    })
                }
                // A design whose window never opens inside 26-78 C has no
                // release or impact to ramp across: no rows, no failure.
                "twin-events" if m.fields.contains_key("skipped") => {}
                "twin-events" => {
                    if m.str("ok") != "true" {
                        return Err(format!("twin through the {} ramp: a tick failed", m.str("kind")));
                    }
                    let ticks = m.num("ticks")?;
                    out.events.push(EventCost {
                        kind: m.str("kind").to_string(),
                        mean: m.num("total")? * k / ticks,
                        worst: m.num("worst")? * k,
                    });
                }
                // One fixed-point (or comparison) operation, `calls` times.
                "fixed" => out.operations.push(PieceCost {
                    name: m.str("name").to_string(),
                    instructions: m.num("total")? * k / m.num("calls")?,
                }),
                // `calls=N`: the piece ran N times, its cost is per call.
                "piece" => out.pieces.push(PieceCost {
                    name: m.str("name").to_string(),
                    instructions: m.num("total")? * k
                        / if m.fields.contains_key("calls") {
                            m.num("calls")?
                        } else {
                            1.0
                        },
                }),
                "estimator" => {
                    let ticks = m.num("ticks")?;
                    out.estimator.push(EstimatorCost {
                        // The Cortex-M4F's f32 twin unless the line says.
                        scalar: m.fields.get("scalar").map_or("f32", String::as_str).to_string(),
                        telemetry: m.str("telemetry") == "true",
                        monitor: m.str("monitor") == "true",
                        mean: m.num("total")? * k / ticks,
                        worst: m.num("worst")? * k,
                    });
                }
                _ => {}
            }
        }
        Ok(out)
    }

    /// The estimator's mean over the first workload (the step) and worst
    /// over every workload, with its twin in `scalar`, with or without
    /// telemetry, if measured.
    #[cfg_attr(not(feature = "host"), allow(dead_code, reason = "the host-only report's"))]
    pub fn estimator(&self, scalar: &str, telemetry: bool) -> Option<(f64, f64)> {
        self.estimator_with(scalar, telemetry, false)
    }

    /// As [`Costs::estimator`], with the condition monitor fitted
    /// (`monitor`) or without.
    pub fn estimator_with(&self, scalar: &str, telemetry: bool, monitor: bool) -> Option<(f64, f64)> {
        let rows: Vec<_> = self
            .estimator
            .iter()
            .filter(|e| e.scalar == scalar && e.telemetry == telemetry && e.monitor == monitor)
            .collect();
        let first = rows.first()?;
        Some((first.mean, rows.iter().map(|e| e.worst).fold(0.0, f64::max)))
    }

    /// One piece's cost (`[measure] piece name=...`), if measured.
    pub fn piece(&self, name: &str) -> Option<f64> {
        self.pieces.iter().find(|p| p.name == name).map(|p| p.instructions)
    }

    /// One operation's cost (`[measure] fixed name=...`), if measured.
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    pub fn operation(&self, name: &str) -> Option<f64> {
        self.operations.iter().find(|p| p.name == name).map(|p| p.instructions)
    }

    /// The twin's cost in a configuration and scalar type, if measured.
    pub fn twin(&self, config: &Config, scalar: &str) -> Option<&TwinCost> {
        self.twin.iter().find(|r| r.is(config, scalar))
    }

    /// The configurations measured, in the image's order.
    #[cfg_attr(not(feature = "host"), allow(dead_code))]
    pub fn configs(&self) -> Vec<Config> {
        let mut configs: Vec<Config> = self.twin.iter().map(|r| r.config.clone()).collect();
        configs.dedup();
        configs
    }
}

/// Peak stack [bytes] reported by the QEMU twin (`[measure] peak stack N bytes`).
pub fn stack_peak(lines: &[String]) -> Option<u64> {
    lines.iter().find_map(|l| {
        let rest = l.split("[measure] peak stack ").nth(1)?;
        rest.split_whitespace().next()?.parse().ok()
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A bench image's output: 6 instructions per count.
    pub fn lines(extra: &[&str]) -> Vec<String> {
        [
            "INFO  [measure] calibration instructions=600 total=100",
            "INFO  [measure] built scheme=sdirk3 substeps=1 params=paper.toml",
            "INFO  [measure] twin scheme=sdirk3 substeps=1 scalar=f32 ticks=201 total=35000 worst=170 graded=1000 ok=true",
            "INFO  [measure] twin scheme=sdirk3 substeps=1 scalar=q12.20 ticks=201 total=1 worst=1 graded=1 ok=true",
            "INFO  [measure] twin scheme=ros3 substeps=2 scalar=f32 ticks=201 total=1 worst=1 graded=1 ok=true",
            "INFO  [measure] twin-events kind=release scheme=sdirk3 substeps=1 ticks=4000 total=600000 worst=370 ok=true",
            "INFO  [measure] piece name=telemetry total=210",
            "INFO  [measure] piece name=telemetry-field-u16 calls=16 total=32",
            "INFO  [measure] estimator workload=step scheme=sdirk3 substeps=1 telemetry=true ticks=1000 total=300000 worst=400 worst_tick=3",
            "INFO  [measure] estimator workload=step scheme=sdirk3 substeps=1 telemetry=false ticks=1000 total=250000 worst=300 worst_tick=3",
            "INFO  [measure] estimator workload=ramps scheme=sdirk3 substeps=1 telemetry=false ticks=1000 total=1 worst=450 worst_tick=3",
            "INFO  estimate ...",
        ]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect()
    }

    #[test]
    fn lines_become_named_costs_in_instructions() {
        let c = Costs::parse(&lines(&[])).unwrap();
        assert_eq!(c.per_count, 6.0);
        let sdirk3 = Config {
            scheme: "sdirk3".into(),
            substeps: 1,
        };
        let b = c.built.as_ref().unwrap();
        assert_eq!((&b.config, b.params.as_str()), (&sdirk3, "paper.toml"));
        assert_eq!(sdirk3.to_string(), "sdirk3 x1");
        let t = c.twin(&sdirk3, "f32").unwrap();
        // The graded first tick on its own; the mean over the 200 after it.
        assert_eq!((t.mean, t.worst, t.graded), (1020.0, 1020.0, 6000.0));
        assert_eq!(c.configs().len(), 2);
        assert_eq!((c.events[0].kind.as_str(), c.events[0].mean), ("release", 900.0));
        assert_eq!(
            (c.pieces[0].name.as_str(), c.pieces[0].instructions),
            ("telemetry", 1260.0)
        );
        // A piece run `calls` times costs its total over the calls.
        assert_eq!(
            (c.pieces[1].name.as_str(), c.pieces[1].instructions),
            ("telemetry-field-u16", 12.0)
        );
        let e: Vec<_> = c.estimator.iter().map(|e| (e.telemetry, e.mean, e.worst)).collect();
        assert_eq!(
            e,
            [(true, 1800.0, 2400.0), (false, 1500.0, 1800.0), (false, 0.006, 2700.0)]
        );
        // With the monitor: its own rows, not the plain estimator's.
        let c = Costs::parse(&lines(&[
            "INFO  [measure] estimator workload=step scheme=sdirk3 substeps=1 monitor=true telemetry=true ticks=1000 total=400000 worst=450 worst_tick=3",
            "INFO  [measure] piece name=monitor-update-mean calls=400 total=40000",
        ]))
        .unwrap();
        assert_eq!(c.estimator("f32", true), Some((1800.0, 2400.0)));
        assert_eq!(c.estimator_with("f32", true, true), Some((2400.0, 2700.0)));
        assert_eq!(c.estimator_with("f32", false, true), None);
        assert_eq!(c.piece("monitor-update-mean"), Some(600.0));
    }

    #[test]
    fn a_design_without_an_opening_has_no_event_rows() {
        let c = Costs::parse(&lines(&["INFO  [measure] twin-events skipped=no-opening-in-range"])).unwrap();
        assert_eq!(c.events.len(), 1, "only the release row of the fixture");
    }

    #[test]
    fn a_failed_tick_an_error_or_a_missing_number_is_an_error() {
        let err = |extra: &str| Costs::parse(&lines(&[extra])).err().unwrap();
        assert_eq!(
            err("[measure] twin scheme=ros2 substeps=4 scalar=f32 ticks=2 total=1 worst=1 graded=1 ok=false"),
            "twin ros2 x4 f32: a tick failed"
        );
        assert_eq!(err("[measure] piece name=x"), "piece line without total");
        assert!(err("ERROR parameters rejected").starts_with("the bench firmware reported an error"));
        assert_eq!(
            stack_peak(&lines(&["[measure] peak stack 4580 bytes (stack painting)"])),
            Some(4580)
        );
    }
}
