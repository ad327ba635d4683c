//! The host side of condition monitoring against the library run directly:
//! a seeded degraded device's records (`host_tests::campaign`: a capillary
//! restricted to 0.8 of its conductance during a cooling, the probe every
//! 20 ms and a chamber (a) pressure transducer every 10 ms) written as a
//! log, replayed by `compensator estimate` and summarised by `compensator
//! monitor`, compared row by row with the firmware's `f32` estimator and
//! its monitor run here on the same readings; and the logs the commands
//! refuse (a pressure in bar, a displacement in mm, a column for another
//! quantity than the file's sensor), each naming its row and column; and
//! `monitor --format json`'s units, strings as in its CSV.

use compensator::Params;
use compensator::estimator::health::{HEALTH_FIELDS, HealthUnit};
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate};
use compensator::monitor::MonitorSettings;
use compensator::params::RawParams;
use host_tests::campaign::{Fault, Injection, Profile, Quantity, Scenario, SecondSensor};
use host_tests::run_cli;
use std::path::PathBuf;

/// The paper preset with its chamber (a) transducer and its 6 s probe:
/// the monitor tests the device through the probe's lag
/// (`docs/monitoring.md`).
const PARAMS_TEXT: &str = include_str!("../../presets/paper-monitor.toml");

fn params_text() -> String {
    PARAMS_TEXT.to_string()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-cli-monitor-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// One row of the log: time \[s\], the probe's reading \[C\], the second
/// sensor's \[Pa or m\].
type Row = (f64, Option<f64>, Option<f64>);

/// The scenario's records as log rows: every tick with a reading.
fn scenario_rows(raw: &RawParams) -> Vec<Row> {
    // The transducer as the file describes it (`monitor.noise`): with a
    // fast probe the monitor's test is only as good as that noise.
    let sensor = SecondSensor {
        noise_sd: raw.monitor.noise,
        ..SecondSensor::default_for(Quantity::PA, &raw.core)
    };
    let injection = Injection {
        fault: Fault::CapillaryRestricted(0.8),
        onset: 60.0,
    };
    let profile = Profile::ramp(60.0, 40.0, 0.1, 60.0);
    let scenario = Scenario::new(raw, sensor, injection, profile, 150.0, 11);
    scenario
        .records()
        .unwrap()
        .map(|s| (s.t, s.probe.filter(|v| v.is_finite()), s.second))
        .filter(|r| r.1.is_some() || r.2.is_some())
        .collect()
}

fn write_log(path: &std::path::Path, column: &str, rows: &[Row], scale: f64) {
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
    let mut text = format!("time_s,t_c,{column}\n");
    for &(t, probe, second) in rows {
        text.push_str(&format!("{t},{},{}\n", cell(probe), cell(second.map(|v| v * scale))));
    }
    std::fs::write(path, text).unwrap();
}

/// The firmware's estimator with its monitor over `rows`, as the module
/// docs of `compensator_cli::estimate` say the replay runs: each row on
/// its tick, the second sensor's reading offered before the tick, the
/// probe's given to it; `each` sees every tick's number, the row delivered
/// on it and the estimate after it.
fn replay(raw: &RawParams, rows: &[Row], mut each: impl FnMut(u64, Option<usize>, &StateEstimate)) {
    let tick = 1.0 / raw.estimator.tick_hz;
    let p32 = Params::<f32>::new(raw).unwrap();
    // The probe every 20 ticks, the second sensor every 10: the medians.
    let config = EstimatorConfig::with_sample_period(raw, 20.0 * tick).unwrap();
    let settings = MonitorSettings {
        sample_period: (10.0 * tick) as f32,
        ..MonitorSettings::from_raw(raw).unwrap().unwrap()
    };
    let mut est = Estimator::new(&p32, config, rows[0].1.unwrap() as f32)
        .unwrap()
        .with_monitor(settings)
        .unwrap();
    let mut k = 0u64;
    for (i, &(t, probe, second)) in rows.iter().enumerate() {
        let due = (t * raw.estimator.tick_hz + 1e-6).floor() as u64;
        while k < due {
            each(k, None, &est.tick(Ok(None)));
            k += 1;
        }
        if let Some(y) = second {
            est.offer_second(Ok(y as f32));
        }
        each(k, Some(i), &est.tick(Ok(probe.map(|v| v as f32))));
        k += 1;
    }
}

/// [`replay`]'s estimate after each row's tick.
fn direct(raw: &RawParams, rows: &[Row]) -> Vec<StateEstimate> {
    let mut out = Vec::with_capacity(rows.len());
    replay(raw, rows, |_, row, e| {
        if row.is_some() {
            out.push(*e);
        }
    });
    out
}

/// A CSV's header and rows of cells.
fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines().filter(|l| !l.is_empty());
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    (
        header,
        lines.map(|l| l.split(',').map(String::from).collect()).collect(),
    )
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// The estimate's health value of `field` as the CLI writes it: `f32`
/// digits, empty for NaN.
fn cell_of(value: f64, unit: HealthUnit) -> String {
    if !value.is_finite() {
        String::new()
    } else if unit == HealthUnit::Count {
        format!("{value}")
    } else {
        compensator_cli::estimate::f32_cell(value as f32)
    }
}

struct Fixture {
    dir: PathBuf,
    params: PathBuf,
    raw: RawParams,
    rows: Vec<Row>,
    log: PathBuf,
}

fn fixture(name: &str) -> Fixture {
    let dir = temp_dir(name);
    let params = dir.join("device.toml");
    std::fs::write(&params, params_text()).unwrap();
    let raw = compensator_cli::parse(&params_text()).unwrap();
    let rows = scenario_rows(&raw);
    let log = dir.join("log.csv");
    write_log(&log, "p_a_pa", &rows, 1.0);
    Fixture {
        dir,
        params,
        raw,
        rows,
        log,
    }
}

fn path(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn estimate_reports_the_health_estimate_of_the_library_per_row() {
    let f = fixture("estimate");
    let (code, out, err) = run_cli(&[
        "estimate",
        "--params",
        path(&f.params),
        "--sensor-data",
        path(&f.log),
        "--every-sample",
    ]);
    assert_eq!(code, 0, "{err}");
    let second = f.rows.iter().filter(|r| r.2.is_some()).count();
    let probe = f.rows.iter().filter(|r| r.1.is_some()).count();
    assert!(
        err.contains(&format!("{probe} readings (t_c)"))
            && err.contains(&format!(
                "{second} readings of the second sensor (p_a_pa), one every 10 ms"
            )),
        "{err}"
    );
    let (header, cells) = table(&out);
    assert_eq!(cells.len(), f.rows.len());
    let expected = direct(&f.raw, &f.rows);
    let flags = col(&header, "flags");
    let mut named = None;
    for (i, (row, e)) in cells.iter().zip(&expected).enumerate() {
        for field in HEALTH_FIELDS {
            let name = format!(
                "{}{}",
                field.name,
                field.unit.suffix(compensator::monitor::Quantity::ChamberA)
            );
            assert_eq!(
                row[col(&header, &name)],
                cell_of((field.value)(&e.health), field.unit),
                "row {}: {name}",
                i + 1
            );
        }
        let want: Vec<&str> = e.flags.names().collect();
        assert_eq!(row[flags], want.join("|"), "row {}", i + 1);
        assert_eq!(row[col(&header, "p_a_pa")], compensator_cli::estimate::f32_cell(e.p_a));
        if named.is_none() && e.flags.0 & compensator::monitor::LATCHED.0 != 0 {
            named = Some((i, e.flags));
        }
    }
    // The health estimate is the monitor's, not NaN, once it has readings:
    // the divider's factor moves to the restriction's 1 / 0.8 (A goes with
    // the capillary's resistance), within 5 % by the end.
    let last = &expected[expected.len() - 1].health;
    assert!(last.divider.is_finite() && last.sd_divider.is_finite(), "{last:?}");
    let (i, flags) = named.expect("the restriction is named");
    assert!(flags.contains(Flags::CAPILLARY_RESTRICTED), "{flags:?}");
    assert!(f.rows[i].0 > 60.0 && f.rows[i].0 < 120.0, "named at {} s", f.rows[i].0);
    assert!(
        (f64::from(last.divider) - 1.25).abs() < 0.05 * 1.25,
        "divider {}",
        last.divider
    );
    let _ = std::fs::remove_dir_all(&f.dir);
}

#[test]
fn a_log_in_bar_is_refused_naming_the_row() {
    let f = fixture("bar");
    let bar = f.dir.join("bar.csv");
    write_log(&bar, "p_a_pa", &f.rows, 1e-5);
    // The row of the column's largest reading.
    let (i, _) = f
        .rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| r.2.map(|v| (i, v)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    for command in ["estimate", "monitor"] {
        let (code, out, err) = run_cli(&[command, "--params", path(&f.params), "--sensor-data", path(&bar)]);
        assert_eq!(code, 2, "{command}: {err}");
        assert!(out.is_empty(), "{command}");
        let at = format!("row {} (line {}), column p_a_pa", i + 1, i + 2);
        assert!(err.contains(&at) && err.contains("written in bar?"), "{command}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    // In MPa: the same column, the unit named.
    let mpa = f.dir.join("mpa.csv");
    write_log(&mpa, "p_a_pa", &f.rows, 1e-6);
    let (code, _, err) = run_cli(&["estimate", "--params", path(&f.params), "--sensor-data", path(&mpa)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("written in MPa?"), "{err}");
    let _ = std::fs::remove_dir_all(&f.dir);
}

#[test]
fn a_column_the_device_file_does_not_measure_is_refused_naming_it() {
    let dir = temp_dir("columns");
    let monitor = dir.join("monitor.toml");
    std::fs::write(&monitor, params_text()).unwrap();
    let log = dir.join("x.csv");
    std::fs::write(&log, "time_s,t_c,x_m\n0,40,0.0002\n0.02,40,0.0002\n0.04,40,0.0002\n").unwrap();
    let (code, _, err) = run_cli(&["estimate", "--params", path(&monitor), "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("column x_m:") && err.contains("monitor.sensor = \"p_a\"") && err.contains("p_a_pa"),
        "{err}"
    );
    // Without a second sensor in the file, its column is refused too.
    let log = dir.join("p_a.csv");
    std::fs::write(&log, "time_s,t_c,p_a_pa\n0,40,2e5\n0.02,40,2e5\n0.04,40,2e5\n").unwrap();
    let (code, _, err) = run_cli(&[
        "estimate",
        "--params",
        "presets/paper.toml",
        "--sensor-data",
        path(&log),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("column p_a_pa:") && err.contains("monitor.sensor = \"none\""),
        "{err}"
    );
    // A displacement in mm: outside the sensor's band, the unit named.
    let x = dir.join("x.toml");
    std::fs::write(&x, displacement_params_text()).unwrap();
    let log = dir.join("mm.csv");
    std::fs::write(&log, "time_s,t_c,x_m\n0,40,0.18\n0.01,,0.19\n0.02,40,0.2\n0.03,,0.7\n").unwrap();
    let (code, _, err) = run_cli(&["estimate", "--params", path(&x), "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("row 1 (line 2), column x_m: 0.18 m is outside the second sensor's measuring band")
            && err.contains("(0.18 mm = 0.00018 m)"),
        "{err}"
    );
    // A row with neither reading, and a first row without the probe's.
    let log = dir.join("holes.csv");
    std::fs::write(&log, "time_s,t_c,x_m\n0,40,0.0002\n0.01,,\n0.02,40,0.0002\n").unwrap();
    let (code, _, err) = run_cli(&["estimate", "--params", path(&x), "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("row 2 (line 3): neither a probe reading (t_c) nor"),
        "{err}"
    );
    let log = dir.join("late.csv");
    std::fs::write(&log, "time_s,t_c,x_m\n0,,0.0002\n0.01,40,0.0002\n0.02,40,0.0002\n").unwrap();
    let (code, _, err) = run_cli(&["estimate", "--params", path(&x), "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("row 1 (line 2), column t_c: no probe reading"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn monitor_summarises_the_flags_as_the_library_raised_them() {
    let f = fixture("monitor");
    let png = f.dir.join("monitor.png");
    let (code, out, err) = run_cli(&[
        "monitor",
        "--params",
        path(&f.params),
        "--sensor-data",
        path(&f.log),
        "--plot",
        path(&png),
    ]);
    assert_eq!(code, 0, "{err}");
    // The first tick carrying each of the monitor's flags, the row on or
    // before it, and the estimate at the end, from the library.
    let mut first: Vec<(u32, usize, f64, u64)> = Vec::new();
    let mut row = 0;
    let mut last = None;
    let tick = 1.0 / f.raw.estimator.tick_hz;
    replay(&f.raw, &f.rows, |k, r, e| {
        row = r.unwrap_or(row);
        last = Some(*e);
        let flags = e.flags.0 & compensator::estimator::health::MONITOR_FLAGS.0;
        for bit in 0..32 {
            if flags & (1 << bit) == 0 {
                continue;
            }
            match first.iter_mut().find(|x| x.0 == bit) {
                Some(x) => x.3 += 1,
                None => first.push((bit, row, k as f64 * tick, 1)),
            }
        }
    });
    first.sort_by_key(|x| x.0);
    let last = last.unwrap().health;
    let (header, cells) = table(&out);
    assert_eq!(cells.len(), first.len(), "{out}");
    assert!(
        first.iter().any(|x| Flags(1 << x.0) == Flags::CAPILLARY_RESTRICTED),
        "{out}"
    );
    for (row, &(bit, r, t, ticks)) in cells.iter().zip(&first) {
        let name = Flags(1 << bit).names().next().unwrap();
        assert_eq!(row[col(&header, "flag")], name);
        assert_eq!(row[col(&header, "first_row")], (r + 1).to_string(), "{name}");
        assert_eq!(row[col(&header, "first_line")], (r + 2).to_string(), "{name}");
        let time: f64 = row[col(&header, "first_time_s")].parse().unwrap();
        assert!((time - t).abs() < 1e-9, "{name}: {time} against {t}");
        assert_eq!(row[col(&header, "ticks")], ticks.to_string(), "{name}");
        if name == "CAPILLARY_RESTRICTED" {
            assert_eq!(row[col(&header, "parameter")], "divider");
            let estimate: f64 = row[col(&header, "estimate")].parse().unwrap();
            let sd: f64 = row[col(&header, "sd")].parse().unwrap();
            let z: f64 = row[col(&header, "z")].parse().unwrap();
            assert_eq!(estimate, f64::from(last.divider));
            assert_eq!(sd, f64::from(last.sd_divider));
            assert!((z - estimate.ln() / sd).abs() <= 1e-12 * z.abs(), "{z}");
            // The onset is at 60 s; the restriction is named after it, and
            // the CUSUM crossed its threshold of 10 before.
            assert!(t > 60.0, "{t}");
            let cusum: f64 = row[col(&header, "cusum_max")].parse().unwrap();
            assert!(cusum > 10.0, "{cusum}");
        }
    }
    assert!(err.contains("monitor: at the log's end divider"), "{err}");
    let bytes = std::fs::read(&png).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n") && bytes.len() > 10_000,
        "{} bytes",
        bytes.len()
    );
    // Without a second sensor in the file there is nothing to monitor.
    let probe = f.dir.join("probe.csv");
    std::fs::write(&probe, "time_s,t_c\n0,40\n0.02,40\n").unwrap();
    let (code, _, err) = run_cli(&[
        "monitor",
        "--params",
        "presets/paper.toml",
        "--sensor-data",
        path(&probe),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("monitor.sensor = \"none\""), "{err}");
    // A log without the sensor's column.
    let (code, _, err) = run_cli(&["monitor", "--params", path(&f.params), "--sensor-data", path(&probe)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("no column p_a_pa"), "{err}");
    let _ = std::fs::remove_dir_all(&f.dir);
}

#[test]
fn the_documented_log_is_what_the_example_writes() {
    use host_tests::monitor_log::{DOCUMENTED_BAR_LOG, DOCUMENTED_LOG, documented, in_bar};
    let written = documented().unwrap();
    for (path, text) in [
        (DOCUMENTED_LOG, written.clone()),
        (DOCUMENTED_BAR_LOG, in_bar(&written, 1.0)),
    ] {
        let committed = std::fs::read_to_string(host_tests::repo_root().join(path)).unwrap();
        assert!(
            text == committed,
            "{path} is stale: cargo run --release -p host-tests --example monitor_log"
        );
    }
}

/// The device file with a displacement sensor over 0-1.8 mm (the
/// preset's stroke is 1.5 mm) and a micrometre of noise.
fn displacement_params_text() -> String {
    params_text()
        .replace("sensor = \"p_a\"", "sensor = \"x\"")
        .replace("range_max = 500000.0    # Pa", "range_max = 0.0018    # m")
        .replace("noise = 100.0    # Pa", "noise = 1e-6    # m")
}

/// `--format json` wrote a dimensionless value's unit, `1`, as the number
/// 1, where the CSV's `1` and the other rows' `Pa` or `m` are text: a
/// reader keying on the unit's string found none. A transducer whose zero
/// moves by a share of its span at 20 s, then a cooling at 0.1 C/s: the
/// change is detected (`cusum`, unit `1`) and named once the oil has moved
/// 3 C (`offset`: `SENSOR_OFFSET` in Pa for a chamber pressure,
/// `PRELOAD_LOST` in m for the displacement, whose zero moving up is a
/// lost preload to it).
#[test]
fn monitor_s_json_writes_each_unit_as_the_csv_does() {
    use compensator::monitor::Quantity as Monitored;
    let dir = temp_dir("json");
    for (quantity, monitored, column, text, offset) in [
        (Quantity::PA, Monitored::ChamberA, "p_a_pa", params_text(), 0.01),
        (
            Quantity::X,
            Monitored::Displacement,
            "x_m",
            displacement_params_text(),
            0.02,
        ),
    ] {
        let params = dir.join(format!("{column}.toml"));
        std::fs::write(&params, &text).unwrap();
        let raw = compensator_cli::parse(&text).unwrap();
        let sensor = SecondSensor {
            noise_sd: raw.monitor.noise,
            ..SecondSensor::default_for(quantity, &raw.core)
        };
        let injection = Injection {
            fault: Fault::SensorOffset(offset),
            onset: 20.0,
        };
        let profile = Profile::ramp(60.0, 50.0, 0.1, 20.0);
        let rows: Vec<Row> = Scenario::new(&raw, sensor, injection, profile, 60.0, 11)
            .records()
            .unwrap()
            .map(|s| (s.t, s.probe.filter(|v| v.is_finite()), s.second))
            .filter(|r| r.1.is_some() || r.2.is_some())
            .collect();
        let log = dir.join(format!("{column}.csv"));
        write_log(&log, column, &rows, 1.0);
        let args = ["monitor", "--params", path(&params), "--sensor-data", path(&log)];
        let (code, csv, err) = run_cli(&args);
        assert_eq!(code, 0, "{column}: {err}");
        let (code, json, err) = run_cli(&[&args[..], &["--format", "json"]].concat());
        assert_eq!(code, 0, "{column}: {err}");
        let objects: Vec<serde_json::Value> = serde_json::from_str(&json).unwrap();
        let (header, cells) = table(&csv);
        assert_eq!(objects.len(), cells.len(), "{column}: {json}");
        let mut units = Vec::new();
        for (object, row) in objects.iter().zip(&cells) {
            let flag = &row[col(&header, "flag")];
            let parameter = &row[col(&header, "parameter")];
            let unit = object["unit"]
                .as_str()
                .unwrap_or_else(|| panic!("{column} {flag}: {object}"));
            // As the CSV writes it, and the symbol of its health field's
            // unit for the sensor's quantity.
            assert_eq!(unit, row[col(&header, "unit")], "{column} {flag}");
            let field = HEALTH_FIELDS.iter().find(|f| f.name == parameter).unwrap();
            assert_eq!(unit, field.unit.symbol(monitored), "{column} {flag}");
            // The numbers stay numbers.
            assert_eq!(
                object["first_row"].as_u64().map(|r| r.to_string()).as_ref(),
                Some(&row[col(&header, "first_row")]),
                "{column} {flag}"
            );
            units.push(unit.to_string());
        }
        let reading = if quantity == Quantity::PA { "Pa" } else { "m" };
        assert!(
            units.iter().any(|u| u == "1") && units.iter().any(|u| u == reading),
            "{column}: {json}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
