//! `compensator estimate`: the binary's output against the library's
//! estimator run directly over the same readings (every digit), the three
//! kinds of reading column against each other through the firmware's
//! driver, the output formats and the figure, and bad input that leaves
//! nothing written. The user mistakes (times, gaps, units, sizes, columns)
//! are in `mistakes.rs`; the round trip of a board's telemetry in
//! `host-tests/tests/cli_estimate.rs`.

mod common;
use common::{csv, root, run, temp_dir};
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, StateEstimate};
use compensator::params::RawParams;
use compensator::sensor::TemperatureSource;
use compensator::sensor::max31865::{Max31865, Settings, code_of};
use compensator::sensor::simulated::SimulatedMax31865;

const P: &str = "presets/paper.toml";
const LOG: &str = "data/logs/probe-warm-up.csv";

fn paper() -> RawParams {
    compensator_cli::load(&root().join(P)).unwrap()
}

/// The log's rows (time, t_c), read without the CLI's reader.
fn log_rows() -> Vec<(f64, f64)> {
    std::fs::read_to_string(root().join(LOG))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            let (t, v) = l.split_once(',').unwrap();
            (t.parse().unwrap(), v.parse().unwrap())
        })
        .collect()
}

/// The estimator run directly: readings every 20 ms (the observer designed
/// for that), each on the tick of its time at 1 kHz; (tick, estimate,
/// whether a reading arrived, whether the firmware publishes).
fn direct(raw: &RawParams, rows: &[(f64, f32)]) -> Vec<(u64, StateEstimate, bool, bool)> {
    let params = Params::<f32>::new(raw).unwrap();
    let config = EstimatorConfig::with_sample_period(raw, 0.02).unwrap();
    let mut e = Estimator::new(&params, config, rows[0].1).unwrap();
    let t0 = rows[0].0;
    let ticks: Vec<u64> = rows.iter().map(|r| ((r.0 - t0) * 1e3).round() as u64).collect();
    let mut out = Vec::new();
    let mut next = 0;
    for k in 0..=*ticks.last().unwrap() {
        let delivered = ticks.get(next) == Some(&k);
        let sample = if delivered {
            next += 1;
            Ok(Some(rows[next - 1].1))
        } else {
            Ok(None)
        };
        let s = e.tick(sample);
        out.push((k, s, delivered, e.telemetry_due()));
    }
    out
}

/// The estimate's fields in the output's column order.
fn fields(e: &StateEstimate) -> [f32; 13] {
    let u = &e.uncertainty;
    [
        e.t_probe,
        e.temperature,
        u.t_oil,
        e.x,
        u.x,
        e.p_a,
        u.p_a,
        e.p_b,
        u.p_b,
        e.q_total,
        u.q_total,
        e.compensation_error,
        u.compensation_error,
    ]
}

/// Every cell of `out` against the direct run's estimates `expected`
/// (time, estimate), bit for bit.
fn assert_same(out: &str, expected: &[(f64, &StateEstimate)]) {
    let (header, rows) = csv(out);
    assert_eq!(
        header.join(","),
        "time_s,t_probe_c,t_oil_c,t_oil_sd_c,x_m,x_sd_m,p_a_pa,p_a_sd_pa,p_b_pa,p_b_sd_pa,q_total_m3s,\
         q_total_sd_m3s,compensation_error_m3s,compensation_error_sd_m3s,reseats,flags"
    );
    assert_eq!(rows.len(), expected.len());
    for (row, (t, e)) in rows.iter().zip(expected) {
        let time: f64 = row[0].parse().unwrap();
        assert!((time - t).abs() < 1e-9, "time {time} against {t}");
        for (i, v) in fields(e).iter().enumerate() {
            let got: f32 = row[i + 1].parse().unwrap();
            assert!(
                got.to_bits() == v.to_bits() || (got.is_nan() && v.is_nan()),
                "t = {t}, {}: {got} against {v}",
                header[i + 1]
            );
        }
        assert_eq!(row[14], e.reseats.to_string());
        assert_eq!(row[15], e.flags.names().collect::<Vec<_>>().join("|"));
    }
}

#[test]
fn the_output_is_the_library_estimators_to_every_digit() {
    let raw = paper();
    let rows: Vec<(f64, f32)> = log_rows().into_iter().map(|(t, v)| (t, v as f32)).collect();
    let run_direct = direct(&raw, &rows);
    let t0 = rows[0].0;
    let time = |k: u64| t0 + k as f64 * 1e-3;
    // One row per reading.
    let (code, out, err) = run(&["estimate", "--params", P, "--sensor-data", LOG, "--every-sample"]);
    assert_eq!(code, 0, "{err}");
    let per_reading: Vec<(f64, &StateEstimate)> =
        run_direct.iter().filter(|r| r.2).map(|r| (time(r.0), &r.1)).collect();
    assert_eq!(per_reading.len(), rows.len());
    assert_same(&out, &per_reading);
    assert!(
        err.contains(&format!("{} readings (t_c)", rows.len())) && err.contains("one every 20 ms"),
        "{err}"
    );
    // One row per telemetry period: the ticks the firmware publishes on.
    let (code, out, err) = run(&["estimate", "--params", P, "--sensor-data", LOG]);
    assert_eq!(code, 0, "{err}");
    let published: Vec<(f64, &StateEstimate)> = run_direct.iter().filter(|r| r.3).map(|r| (time(r.0), &r.1)).collect();
    assert!(published.len() >= 200, "{}", published.len());
    assert_same(&out, &published);
}

/// The log's temperatures as the MAX31865 codes that read them, and those
/// codes read back through the firmware's driver (a simulated converter
/// forced to each code).
fn codes_and_readings(raw: &RawParams, rows: &[(f64, f64)]) -> (Vec<u16>, Vec<f32>) {
    // No fault-detection cycle after the one at start-up: every call reads.
    let settings = Settings {
        diagnosis_every: 0,
        ..Settings::from_params(&raw.estimator)
    };
    let mut driver = Max31865::new(SimulatedMax31865::new(settings, 40.0), settings);
    driver.configure().unwrap();
    while !matches!(driver.read(), Ok(Some(_))) {}
    let mut codes = Vec::new();
    let mut readings = Vec::new();
    for &(_, t) in rows {
        let code = code_of(&settings, settings.cvd.resistance(settings.r0, t as f32));
        driver.device_mut().forced_code = Some(code);
        codes.push(code);
        readings.push(driver.read().unwrap().unwrap());
    }
    (codes, readings)
}

#[test]
fn codes_and_resistances_read_as_the_firmwares_driver_reads_them() {
    let raw = paper();
    let rows = log_rows();
    let dir = temp_dir("estimate-kinds");
    let (codes, readings) = codes_and_readings(&raw, &rows);
    let settings = Settings::from_params(&raw.estimator);
    let mut by_code = String::from("time_s,code,note\n");
    let mut by_reading = String::from("time_s;t_c\n");
    let mut by_ohm = String::from("# resistances\ntime_s,rtd_ohm\n");
    for (((t, _), code), reading) in rows.iter().zip(&codes).zip(&readings) {
        by_code.push_str(&format!("{t},{code},x\n"));
        by_reading.push_str(&format!("{};{}\n", t, reading.to_string().replace('.', ",")));
        let ohm = f32::from(*code) * settings.reference / 32768.0;
        by_ohm.push_str(&format!("{t},{ohm}\n"));
    }
    let out = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let (code, out, err) = run(&[
            "estimate",
            "--params",
            P,
            "--sensor-data",
            path.to_str().unwrap(),
            "--every-sample",
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        out
    };
    // A code log (with a text column beside it) is the log of the
    // temperatures the driver reads from those codes (written the
    // spreadsheet way: ';' and decimal commas).
    let (a, b) = (out("code.csv", &by_code), out("reading.csv", &by_reading));
    assert_eq!(a, b);
    // A resistance log, through the file's Callendar-Van Dusen curve: the
    // same temperatures to the last bit or two of f32.
    let c = out("ohm.csv", &by_ohm);
    let (x_a, x_c) = (common::column(&a, "x_m"), common::column(&c, "x_m"));
    let worst = x_a.iter().zip(&x_c).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-9, "x differs by {worst} m");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn json_table_units_and_the_figure() {
    let dir = temp_dir("estimate-formats");
    let (code, json, err) = run(&["estimate", "--params", P, "--sensor-data", LOG, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let first = &v[0];
    assert!(first["x_sd_m"].as_f64().is_some_and(|s| s > 0.0), "{first}");
    assert!(first["reseats"].is_u64(), "{first}");
    let (code, table, _) = run(&["estimate", "--params", P, "--sensor-data", LOG, "--format", "table"]);
    assert_eq!(code, 0);
    assert!(
        table.lines().next().unwrap().trim_start().starts_with("time_s"),
        "{table}"
    );
    let (code, eng, _) = run(&["estimate", "--params", P, "--sensor-data", LOG, "--units", "eng"]);
    assert_eq!(code, 0);
    let (header, _) = csv(&eng);
    for name in ["x_mm", "x_sd_mm", "p_a_bar", "q_total_lpm", "t_oil_sd_c"] {
        assert!(header.iter().any(|h| h == name), "{header:?}");
    }
    for (units, shows) in [("si", "x [m]"), ("eng", "x [mm]")] {
        let svg = dir.join(format!("{units}.svg"));
        let (code, _, err) = run(&[
            "estimate",
            "--params",
            P,
            "--sensor-data",
            LOG,
            "--units",
            units,
            "--plot",
            svg.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let text = std::fs::read_to_string(&svg).unwrap();
        for s in [shows, "temperature [C]", "probe reading", "95 %", "<polygon"] {
            assert!(text.contains(s), "{units}: no '{s}' in the figure");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_leaves_no_output_file_and_no_figure() {
    let dir = temp_dir("estimate-nothing");
    let huge = "time_s,t_c\n0,40\n".to_string() + &"0.02,40\n".repeat(compensator_cli::estimate::MAX_ROWS);
    for (name, text, at) in [
        (
            "gap.csv",
            "time_s,t_c\n0,40\n0.02,40\n0.9,40\n".to_string(),
            "row 3 (line 4), column time_s",
        ),
        (
            "back.csv",
            "time_s,t_c\n0,40\n0.02,40\n0.01,40\n".into(),
            "row 3 (line 4), column time_s",
        ),
        (
            "hot.csv",
            "time_s,t_c\n0,40\n0.02,40\n0.04,300000\n".into(),
            "row 3 (line 4), column t_c",
        ),
        ("empty.csv", String::new(), "empty file"),
        ("huge.csv", huge, "more than the limit of 1000000 readings"),
    ] {
        let log = dir.join(name);
        std::fs::write(&log, text).unwrap();
        let (out, fig) = (dir.join("out.csv"), dir.join("out.svg"));
        let (code, stdout, err) = run(&[
            "estimate",
            "--params",
            P,
            "--sensor-data",
            log.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--plot",
            fig.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            stdout.is_empty() && err.contains(at) && err.lines().count() == 1,
            "{name}: {err}"
        );
        assert!(!out.exists() && !fig.exists(), "{name}: output written");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
