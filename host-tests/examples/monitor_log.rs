//! A log for `compensator estimate` and `compensator monitor`: the records
//! of a seeded device of a parameter file with its second sensor
//! (`host_tests::campaign`), a fault injected, as a CSV of `time_s`, the
//! probe's `t_c` and the second sensor's column (empty where a sensor has
//! no reading on that tick).
//!
//!     cargo run --release -p host-tests --example monitor_log -- PARAMS.toml LOG.csv [fault] [seed]
//!
//! * `PARAMS.toml`: a device file with a `[monitor]` section
//!   (`presets/paper-monitor.toml`); its sensor's quantity names the
//!   column, the campaign's default sensor for it reads (class 0.1, noise
//!   0.05 % of the span, 12 bits, 100 Hz).
//! * `fault`: `name:severity` as `campaign_data` takes it. Default
//!   `capillary:0.8`, at 60 s.
//! * `seed`: the as-built device, the sensors' offsets and noises. Default 11.
//!
//! The history: 60 s at 60 C, then a cooling at 0.1 C/s to 40 C, then 30 s
//! at 40 C (290 s).

use host_tests::campaign::{Fault, Injection, Profile, Quantity, Scenario, SecondSensor};
use std::fmt::Write;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(params), Some(out)) = (args.first(), args.get(1)) else {
        return Err("usage: monitor_log PARAMS.toml LOG.csv [fault] [seed]".into());
    };
    let raw = compensator_cli::load(std::path::Path::new(params)).map_err(|e| format!("{params}: {e}"))?;
    let fault = Fault::parse(args.get(2).map_or("capillary:0.8", String::as_str))?;
    let seed: u64 = args
        .get(3)
        .map_or(Ok(11), |s| s.parse())
        .map_err(|_| "seed: a whole number")?;
    let names = ["none", "p_a", "p_b", "dp_ab", "x"];
    let name = names.get(raw.monitor.sensor as usize).copied().unwrap_or("none");
    let quantity = Quantity::parse(name).ok_or(format!("{params}: no second sensor (monitor.sensor = \"none\")"))?;
    let column = format!("{name}_{}", quantity.unit().to_ascii_lowercase());
    let sensor = SecondSensor::default_for(quantity, &raw.core);
    let injection = Injection { fault, onset: 60.0 };
    let profile = Profile::ramp(60.0, 40.0, 0.1, 60.0);
    let scenario = Scenario::new(&raw, sensor, injection, profile, 290.0, seed);
    let mut text = format!("time_s,t_c,{column}\n");
    let cell = |v: Option<f64>| v.filter(|v| v.is_finite()).map_or(String::new(), |v| format!("{v}"));
    let mut rows = 0;
    for s in scenario.records()? {
        let (probe, second) = (cell(s.probe), cell(s.second));
        if probe.is_empty() && second.is_empty() {
            continue;
        }
        let _ = writeln!(text, "{},{probe},{second}", s.t);
        rows += 1;
    }
    std::fs::write(out, text).map_err(|e| format!("{out}: {e}"))?;
    eprintln!("monitor_log: {rows} rows ({fault} at 60 s, seed {seed}) to {out}");
    Ok(())
}
