//! `--units si|eng` on every table, and rows that cannot be computed: an
//! `error` column, the rest of the table kept, exit status 1 after it.

mod common;
use common::{csv, run, temp_dir};

const P: &str = "presets/paper.toml";

/// Every command that prints a table, with arguments that keep it short.
fn tabular_commands() -> Vec<Vec<&'static str>> {
    vec![
        vec!["equilibrium", "--params", P, "--temps", "30:80:10"],
        vec![
            "asymptotic",
            "--params",
            P,
            "--order",
            "2",
            "--reading",
            "temperature",
            "--temps",
            "30:80:10",
        ],
        vec!["sensitivity", "--params", P, "--temps", "26:78:4"],
        vec!["step", "--params", P, "--from", "40", "--to", "50", "--t-end", "0.02"],
        vec!["twin-config", "--params", P],
        vec!["eigen", "--params", P, "--temps", "30,60"],
        vec!["indicators", "--params", P, "--steps", "40:50", "--t-end", "0.2"],
        vec!["compensation", "--params", P, "--temps", "30:80:10"],
        vec![
            "estimate",
            "--params",
            P,
            "--sensor-data",
            "data/logs/probe-warm-up.csv",
        ],
        vec![
            "sweep",
            "--params",
            P,
            "--set",
            "plunger.mass=0.01,0.02",
            "--t-end",
            "0.1",
        ],
    ]
}

/// The engineering name and factor of an SI column, restated from the
/// units' definitions: 1 bar = 1e5 Pa, 1 L/min = 1e-3/60 m^3/s, 1 mm =
/// 1e-3 m, 1 cSt = 1e-6 m^2/s.
fn expected(si: &str) -> (String, f64) {
    let table: [(&str, &str, f64); 9] = [
        ("_sqrt_pa", "_sqrt_bar", 1.0 / 1e5f64.sqrt()),
        ("_m3s_k", "_lpm_k", 60_000.0),
        ("_m3s", "_lpm", 60_000.0),
        ("_m2s", "_cst", 1e6),
        ("_m2", "_mm2", 1e6),
        ("_m_s", "_mm_s", 1e3),
        ("_m_k", "_mm_k", 1e3),
        ("_pa", "_bar", 1e-5),
        ("_m", "_mm", 1e3),
    ];
    for (from, to, f) in table {
        if let Some(stem) = si.strip_suffix(from) {
            return (format!("{stem}{to}"), f);
        }
    }
    (si.to_string(), 1.0)
}

#[test]
fn eng_units_rename_and_convert_every_tables_columns() {
    for args in tabular_commands() {
        let (code, si, err) = run(&args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let (code, eng, err) = run(&[&args[..], &["--units", "eng"]].concat());
        assert_eq!(code, 0, "{args:?}: {err}");
        let (hs, rs) = csv(&si);
        let (he, re) = csv(&eng);
        assert_eq!(rs.len(), re.len(), "{args:?}");
        let mut converted = 0;
        for (i, h) in hs.iter().enumerate() {
            let (name, factor) = expected(h);
            assert_eq!(he[i], name, "{args:?}");
            if factor != 1.0 {
                converted += 1;
            }
            for (a, b) in rs.iter().zip(&re) {
                match (a[i].parse::<f64>(), b[i].parse::<f64>()) {
                    (Ok(x), Ok(y)) => assert!(
                        (x * factor - y).abs() <= 1e-12 * (x * factor).abs().max(1e-300),
                        "{args:?} {h}: {x} -> {y}"
                    ),
                    _ => assert_eq!(a[i], b[i], "{args:?} {h}"),
                }
            }
        }
        // The units the brief names, where a command has them.
        let joined = he.join(",");
        assert!(!joined.contains("_pa,") && !joined.ends_with("_pa"), "{joined}");
        if args[0] != "twin-config" && args[0] != "eigen" {
            assert!(converted > 0, "{args:?}: no column converted");
        }
    }
    let (_, eng, _) = run(&["equilibrium", "--params", P, "--temps", "50", "--units", "eng"]);
    for name in ["dp_ab_bar", "q_total_lpm", "x_mm", "t_c"] {
        assert!(eng.lines().next().unwrap().split(',').any(|h| h == name), "{eng}");
    }
}

#[test]
fn units_are_not_offered_where_the_output_is_a_parameter_file_or_text() {
    for args in [
        &["size", "--params", P, "--for", "machine"][..],
        &["calibrate"][..],
        &["paper"][..],
    ] {
        let (code, out, err) = run(&[args, &["--units", "eng"]].concat());
        assert_eq!(code, 2, "{args:?}");
        assert!(out.is_empty());
        // Refused by name, with the commands that do take it.
        assert!(err.contains("unexpected argument '--units'"), "{err}");
        assert!(err.contains("tip: --units is taken by equilibrium"), "{err}");
        assert!(err.lines().count() <= 2, "{err}");
        let (_, help, _) = run(&[args[0], "--help"]);
        assert!(!help.contains("--units"), "{args:?} offers --units: {help}");
        let (code, _, err) = run(args);
        assert_eq!(code, 0, "{args:?}: {err}");
    }
}

#[test]
fn eng_units_reach_the_figures() {
    let dir = temp_dir("units-plot");
    for (units, shows) in [
        ("si", ["x [m]", "p [Pa]", "Q [m^3/s]"]),
        ("eng", ["x [mm]", "p [bar]", "Q [L/min]"]),
    ] {
        let file = dir.join(format!("{units}.svg"));
        let (code, _, err) = run(&[
            "equilibrium",
            "--params",
            P,
            "--units",
            units,
            "--plot",
            file.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let svg = std::fs::read_to_string(&file).unwrap();
        for s in shows {
            assert!(svg.contains(s), "{units}: no '{s}'");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Commands whose rows are temperatures.
fn per_temperature() -> Vec<Vec<&'static str>> {
    vec![
        vec!["equilibrium", "--params", P],
        vec!["asymptotic", "--params", P, "--order", "1", "--reading", "property"],
        vec!["sensitivity", "--params", P],
        vec!["eigen", "--params", P],
        vec!["compensation", "--params", P],
    ]
}

#[test]
fn a_temperature_outside_the_oil_model_is_refused_and_rows_outside_the_validated_range_are_flagged() {
    for args in per_temperature() {
        // 200 C: beyond the paper oil's viscosity law (below 2 cSt from 105.9 C).
        let (code, out, err) = run(&[&args[..], &["--temps", "30,200,50"]].concat());
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.contains("--temps: 200 C is above the oil model's range -20 to 105.9 C")
                && err.contains("viscosity below 2 cSt")
                && err.contains("validated 26 to 78 C"),
            "{args:?}: {err}"
        );
        // Below estimator.oil_min (-20 C): refused too, naming the field.
        let (code, _, err) = run(&[&args[..], &["--temps=-30"]].concat());
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("-30 C is below") && err.contains("estimator.oil_min"),
            "{err}"
        );
        // Inside the oil model: computed, each row flagged by its zone;
        // the header is the same whether rows fail or not.
        let (code, out, err) = run(&[&args[..], &["--temps", "20,50,90"]].concat());
        assert_eq!(code, 0, "{args:?}: {err}");
        let (header, rows) = csv(&out);
        assert_eq!(&header[header.len() - 2..], ["envelope", "error"], "{args:?}");
        let zones: Vec<&str> = rows.iter().map(|r| r[r.len() - 2].as_str()).collect();
        assert_eq!(zones, ["oil_model", "validated", "oil_model"], "{args:?}");
        assert!(rows.iter().all(|r| r.last().unwrap().is_empty()), "{args:?}");
        let (_, good, _) = run(&[&args[..], &["--temps", "50"]].concat());
        assert_eq!(csv(&good).0, header, "{args:?}");
    }
}

#[test]
fn failed_rows_still_reach_the_output_file_and_bad_input_stays_status_2() {
    let dir = temp_dir("errors");
    let file = dir.join("out.csv");
    // A variant outside its field's plausible range keeps its row.
    let sweep = [
        "sweep",
        "--params",
        P,
        "--set",
        "plunger.mass=0.01,-1",
        "--t-end",
        "0.05",
    ];
    let (code, out, err) = run(&[&sweep[..], &["-o", file.to_str().unwrap()]].concat());
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("1 of 2 rows"), "{err}");
    assert!(out.is_empty());
    let written = std::fs::read_to_string(&file).unwrap();
    let (header, rows) = csv(&written);
    assert_eq!(header.last().map(String::as_str), Some("error"));
    assert!(rows[0].last().unwrap().is_empty(), "{written}");
    assert!(rows[1].last().unwrap().contains("plunger.mass"), "{written}");
    // JSON: the failed row has its reason and nulls.
    let (code, json, _) = run(&[&sweep[..], &["--format", "json"]].concat());
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(
        v[1]["error"].as_str().is_some_and(|s| s.contains("plunger.mass")),
        "{json}"
    );
    assert!(v[0]["error"].is_null() && v[1]["x_30c_m"].is_null(), "{json}");
    // A list that is not a list, a file that is not valid, a step beyond
    // the oil model: status 2, nothing printed.
    for args in [
        &["equilibrium", "--params", P, "--temps", "30,x"][..],
        &["equilibrium", "--params", "/nonexistent.toml"][..],
        &["indicators", "--params", P, "--steps", "40:50,40:200", "--t-end", "0.1"][..],
    ] {
        let (code, out, _) = run(args);
        assert_eq!(code, 2, "{args:?}");
        assert!(out.is_empty());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
