//! # compensator-codegen
//!
//! What the firmware's build script generates from a parameter file, as
//! functions that return text: the firmware's `build.rs` is a thin driver
//! that reads the file, calls them and writes their output to `OUT_DIR`,
//! and host tests call the same functions.
//!
//! * [`params_rs`]: the parameter set as constants (`RAW_PARAMS`, by field
//!   name) and the twin's configuration for the design, chosen from its
//!   own dynamics (`compensator::dynamics::config::choose`), so that the
//!   cost per tick is decided before anything is flashed; with a second
//!   sensor, its transducer's and the condition monitor's settings
//!   ([`monitor_settings`]).
//! * [`replay`]: the QEMU twin's replay schedule adapted to the device's
//!   ranges ([`replay::adapt`]), its text form for the host-side replica
//!   ([`replay::Schedule`]), and (feature `replay`) the bounds the twin
//!   checks itself against and the on-target tests' expectations, computed
//!   in `f64` by the independent reference (`compensator-reference`), never
//!   by the core.
//!
//! The QEMU images' build enables `replay`; the board image's does not, and
//! its build script compiles no reference.
#![deny(missing_docs)]

pub mod replay;

use compensator::monitor::{MonitorSettings, ProbeModel};
use compensator::sensor::transducer;
use compensator_params::{Field, Named, RawCore, RawEstimator, RawMachine, RawMonitor, RawParams, RawProbe};

/// The generated `params.rs` and what the build should say about it.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamsRs {
    /// The Rust source: `RAW_PARAMS`, `OBSERVER`, `OBSERVER_WITHOUT_LAG`,
    /// `UNCERTAINTY`, `PARAMS_SOURCE`, `TWIN_SCHEME`, `TWIN_SUBSTEPS`,
    /// `TWIN_ESTIMATED_ERROR_PCT`, `MONITOR_TRANSDUCER`, `MONITOR`.
    pub code: String,
    /// Warnings for the build (the twin's accuracy target not met).
    pub warnings: Vec<String>,
}

/// The twin's configuration for `raw` at its tick over its validated range
/// and down to its coldest oil (`compensator::dynamics::config::choose`).
///
/// # Errors
///
/// The parameters do not make a model, or the chooser found no
/// configuration (its message).
pub fn twin_configuration(raw: &RawParams) -> Result<compensator::dynamics::config::Choice, String> {
    let p = compensator::Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let e = &raw.estimator;
    compensator::dynamics::config::choose(&p, 1.0 / e.tick_hz, (e.valid_min, e.valid_max)).map_err(|e| e.to_string())
}

/// A struct literal by field name (`spring_rate: 25684.5`): the constants
/// do not depend on the order of the fields.
fn literal(ty: &str, fields: &[(Field, Named)]) -> String {
    let body = fields
        .iter()
        .map(|(f, n)| format!("{}: {:?}", f.name, n.value))
        .collect::<Vec<_>>()
        .join(", ");
    format!("::compensator::params::{ty} {{ {body} }}")
}

/// A struct's `Debug` text as a Rust expression: its type names taken from
/// the crate (`ObserverDesign { .. }` as `::compensator::estimator::
/// ObserverDesign { .. }`), `NaN` and `inf` as `f32` constants. The
/// structs are plain data of `f32`s, `bool`s and arrays, whose derived
/// `Debug` is their literal (every `f32` in its shortest round-trip form).
pub fn rust_literal(debug: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let w = std::mem::take(word);
        out.push_str(match w.as_str() {
            "NaN" => "f32::NAN",
            "inf" => "f32::INFINITY",
            "ObserverDesign" => "::compensator::estimator::ObserverDesign",
            "ModeGains" => "::compensator::estimator::ModeGains",
            "UncertaintyTable" => "::compensator::uncertainty::UncertaintyTable",
            _ => &w,
        });
    };
    for c in debug.chars() {
        if c.is_alphanumeric() || c == '_' || c == '.' {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// The condition monitor's settings for the file's second sensor, from
/// its transducer's: the noise of one reading with the ADC's quantisation
/// (`lsb^2 / 12`), the accuracy class as a uniform limit (GUM 4.3.7), the
/// reading period. `None` without a sensor.
///
/// The monitor's settings are the core's own conversion of the file
/// ([`MonitorSettings::of_transducer`] with the file's probe,
/// [`ProbeModel::new`]), the one the CLI and the FMU use.
///
/// # Errors
///
/// The section's validation or the transducer's settings refuse a field
/// (the message names it).
pub fn monitor_settings(raw: &RawParams) -> Result<Option<(transducer::Settings, MonitorSettings)>, String> {
    let Some(t) = compensator::sensor::device::monitor_settings(raw).map_err(|e| e.to_string())? else {
        return Ok(None);
    };
    let settings = MonitorSettings::of_transducer(&t, ProbeModel::new(raw));
    Ok(Some((t, settings)))
}

/// `MONITOR_TRANSDUCER` and `MONITOR`, the second sensor's driver
/// settings and the monitor's, as Rust constants (`None` without one).
fn monitor_rs(raw: &RawParams) -> Result<String, String> {
    let (transducer, monitor) = match monitor_settings(raw)? {
        Some((t, m)) => {
            let output = match t.output {
                transducer::Output::Ratiometric { divider } => format!("Ratiometric {{ divider: {divider:?} }}"),
                transducer::Output::Current { shunt } => format!("Current {{ shunt: {shunt:?} }}"),
            };
            let t = format!(
                "Some(::compensator::sensor::transducer::Settings {{ \
                 quantity: ::compensator::sensor::transducer::Quantity::{:?}, \
                 output: ::compensator::sensor::transducer::Output::{output}, range: ({:?}, {:?}), \
                 noise: {:?}, accuracy: {:?}, bits: {}, reference: {:?}, period: {:?}, stuck_after: {}, \
                 noise_limit: {:?} }})",
                t.quantity,
                t.range.0,
                t.range.1,
                t.noise,
                t.accuracy,
                t.bits,
                t.reference,
                t.period,
                t.stuck_after,
                t.noise_limit
            );
            let m = format!(
                "Some(::compensator::monitor::MonitorSettings {{ \
                 quantity: ::compensator::monitor::Quantity::{:?}, sd_noise: {:?}, sd_accuracy: {:?}, \
                 sample_period: {:?}, probe: ::compensator::monitor::ProbeModel {{ time_constant: {:?}, \
                 well_time_constant: {:?}, reading_sd: {:?}, tolerance_a: {:?}, tolerance_b: {:?} }} }})",
                m.quantity,
                m.sd_noise,
                m.sd_accuracy,
                m.sample_period,
                m.probe.time_constant,
                m.probe.well_time_constant,
                m.probe.reading_sd,
                m.probe.tolerance_a,
                m.probe.tolerance_b
            );
            (rust_literal(&t), rust_literal(&m))
        }
        None => ("None".to_string(), "None".to_string()),
    };
    Ok(format!(
        "/// The condition monitor's second sensor, its transducer's settings\n\
         /// (`None`: the file names none; the images then build no monitor).\n\
         pub const MONITOR_TRANSDUCER: Option<::compensator::sensor::transducer::Settings> = {transducer};\n\
         /// The condition monitor's settings for that sensor.\n\
         pub const MONITOR: Option<::compensator::monitor::MonitorSettings> = {monitor};\n"
    ))
}

/// The firmware's constants for the validated parameter set `raw`, read
/// from `path` (shown in the generated comment) named `source` (its file
/// name, what the firmware prints).
///
/// The estimator's observer and uncertainty table are designed here, in
/// `f64` (the firmware links no `f64` design code): `OBSERVER` for the
/// file's probe, `OBSERVER_WITHOUT_LAG` for the soak image (its walk reads
/// the oil directly), `UNCERTAINTY` from the file's tolerances.
///
/// # Errors
///
/// No twin configuration for the design ([`twin_configuration`]), no
/// observer or no uncertainty table for it (the message names the field).
pub fn params_rs(raw: &RawParams, path: &str, source: &str) -> Result<ParamsRs, String> {
    let choice = twin_configuration(raw).map_err(|e| format!("no twin configuration: {e}"))?;
    let mut warnings = Vec::new();
    if !choice.goal_met {
        warnings.push(format!(
            "the twin's {} substeps per tick are estimated {:.3} % of a step off (target {} %)",
            choice.config.substeps,
            choice.estimated_error_pct,
            compensator::dynamics::config::TARGET_PCT
        ));
    }
    let core = literal("RawCore", &RawCore::FIELD.zip(raw.core.named()).into_array());
    let machine = match &raw.machine {
        Some(m) => format!(
            "Some({})",
            literal("RawMachine", &RawMachine::FIELD.zip(m.named()).into_array())
        ),
        None => "None".to_string(),
    };
    let estimator = literal(
        "RawEstimator",
        &RawEstimator::FIELD.zip(raw.estimator.named()).into_array(),
    );
    let probe = literal("RawProbe", &RawProbe::FIELD.zip(raw.probe.named()).into_array());
    let monitor = literal("RawMonitor", &RawMonitor::FIELD.zip(raw.monitor.named()).into_array());
    let config = compensator::estimator::EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let direct = compensator::estimator::observer_settings(raw, config.sample_period()).without_lag();
    let direct = compensator::estimator::ObserverDesign::new(&direct).map_err(|e| format!("probe without lag: {e}"))?;
    let observer = rust_literal(&format!("{:?}", config.observer));
    let direct = rust_literal(&format!("{direct:?}"));
    let uncertainty = rust_literal(&format!("{:?}", config.uncertainty));
    let monitor_consts = monitor_rs(raw)?;
    let code = format!(
        "// Generated by build.rs (compensator-codegen) from {path}\n\
         /// The parameter set the firmware was built with (validated at build time;\n\
         /// its tolerances are in `UNCERTAINTY`).\n\
         pub const RAW_PARAMS: ::compensator::params::RawParams = ::compensator::params::RawParams {{\n    \
         core: {core},\n    \
         machine: {machine},\n    \
         estimator: {estimator},\n    \
         probe: {probe},\n    \
         monitor: {monitor},\n    \
         tolerances: ::compensator::params::RawTolerances::NONE,\n}};\n\
         /// The oil-temperature observer designed at build time for the file's probe.\n\
         pub static OBSERVER: ::compensator::estimator::ObserverDesign = {observer};\n\
         /// The observer for a probe without lag (the soak image's walk reads the oil).\n\
         pub static OBSERVER_WITHOUT_LAG: ::compensator::estimator::ObserverDesign = {direct};\n\
         /// The uncertainty table built at build time from the file's tolerances.\n\
         pub static UNCERTAINTY: ::compensator::uncertainty::UncertaintyTable = {uncertainty};\n\
         /// Where the parameters came from.\n\
         pub const PARAMS_SOURCE: &str = {source:?};\n\
         /// The twin's scheme, by name (`compensator::dynamics::Scheme::from_name`),\n\
         /// chosen at build time for this parameter file.\n\
         pub const TWIN_SCHEME: &str = {:?};\n\
         /// The twin's steps per tick, chosen at build time for this parameter\n\
         /// file from its own dynamics (`compensator::dynamics::config::choose`).\n\
         pub const TWIN_SUBSTEPS: u8 = {};\n\
         /// The chooser's estimate of the twin's error [% of a step].\n\
         pub const TWIN_ESTIMATED_ERROR_PCT: f32 = {:?};\n\
         {monitor_consts}",
        choice.config.scheme.name(),
        choice.config.substeps,
        choice.estimated_error_pct as f32,
    );
    Ok(ParamsRs { code, warnings })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> RawParams {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../presets/paper.toml");
        compensator_params::file::load(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn the_constants_name_every_field_and_the_chosen_twin() {
        let raw = paper();
        let g = params_rs(&raw, "presets/paper.toml", "paper.toml").unwrap();
        assert!(g.warnings.is_empty(), "{:?}", g.warnings);
        assert!(g.code.contains("pub const PARAMS_SOURCE: &str = \"paper.toml\";"));
        assert!(g.code.contains("pub const TWIN_SCHEME: &str = \"sdirk3\";"));
        assert!(g.code.contains("pub const TWIN_SUBSTEPS: u8 = 1;"));
        for f in RawCore::FIELD.into_array() {
            assert!(g.code.contains(&format!("{}: ", f.name)), "{}", f.name);
        }
        assert!(g.code.contains(&format!("spring_rate: {:?}", raw.core.spring_rate)));
        assert!(
            g.code
                .contains(&format!("time_constant: {:?}", raw.probe.time_constant))
        );
        assert!(g.code.contains(
            "pub static OBSERVER: ::compensator::estimator::ObserverDesign = ::compensator::estimator::ObserverDesign {"
        ));
        assert!(g.code.contains("hold: ::compensator::estimator::ModeGains {"));
        assert!(g.code.contains("pub static UNCERTAINTY: ::compensator::uncertainty::UncertaintyTable = ::compensator::uncertainty::UncertaintyTable {"));
    }

    #[test]
    fn a_second_sensor_gives_the_monitors_constants() {
        assert!(
            params_rs(&paper(), "p", "p")
                .unwrap()
                .code
                .contains("pub const MONITOR: Option<::compensator::monitor::MonitorSettings> = None;")
        );
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../presets/paper-monitor.toml");
        let raw = compensator_params::file::load(std::path::Path::new(path)).unwrap();
        let (t, m) = monitor_settings(&raw).unwrap().unwrap();
        // 0.5-4.5 V through 0.66 into 3.3 V at 12 bits: 4 V x 0.66 / 3.3 V
        // of 4096 codes span 5e5 Pa, 152.6 Pa a code; 100 Pa of noise with
        // the code's lsb^2 / 12; class 0.1 % of 5e5 Pa as a uniform limit.
        let lsb = 5e5 / (4.0 * 0.66 / 3.3 * 4096.0);
        assert!((f64::from(t.units_per_code()) / lsb - 1.0).abs() < 1e-6);
        let sd = (100.0f64 * 100.0 + lsb * lsb / 12.0).sqrt();
        assert!((f64::from(m.sd_noise) / sd - 1.0).abs() < 1e-6, "{}", m.sd_noise);
        assert!((f64::from(m.sd_accuracy) / (500.0 / 3f64.sqrt()) - 1.0).abs() < 1e-6);
        assert_eq!(m.sample_period, 0.01);
        assert_eq!(m.quantity, compensator::monitor::Quantity::ChamberA);
        // The probe the monitor tests the device with is the file's.
        assert_eq!(m.probe, ProbeModel::new(&raw));
        assert_eq!(m.probe.time_constant, 6.0);
        let code = params_rs(&raw, path, "paper-monitor.toml").unwrap().code;
        assert!(code.contains(&format!(
            "pub const MONITOR: Option<::compensator::monitor::MonitorSettings> = Some(::compensator::monitor::MonitorSettings {{ quantity: ::compensator::monitor::Quantity::ChamberA, sd_noise: {:?},",
            m.sd_noise
        )));
        assert!(code.contains(&format!(
            "probe: ::compensator::monitor::ProbeModel {{ time_constant: 6.0, well_time_constant: {:?}, reading_sd: {:?},",
            m.probe.well_time_constant, m.probe.reading_sd
        )));
        assert!(code.contains("output: ::compensator::sensor::transducer::Output::Ratiometric { divider: 0.66 }"));
        // A refused section fails the build naming its field.
        let mut bad = raw;
        bad.monitor.range_max = 1e5;
        let e = params_rs(&bad, path, "x").unwrap_err();
        assert!(e.contains("monitor.range_max"), "{e}");
    }

    #[test]
    fn not_a_number_and_infinities_become_constants() {
        assert_eq!(
            rust_literal("T { a: NaN, b: [-inf, 1.5e-7, inf], c: NaN_x }"),
            "T { a: f32::NAN, b: [-f32::INFINITY, 1.5e-7, f32::INFINITY], c: NaN_x }"
        );
    }
}
