//! Bad input gets a typed error naming the field, never a panic, NaN or
//! hang: parameter files, the core's conversions, and the CLI's contract
//! (exit status 2, one line on stderr, nothing on stdout).

use compensator::equilibrium::equilibrium;
use compensator::params::{ParamError, Problem};
use compensator::{ModelError, Params};
use compensator_cli::{LoadError, params_file};
use host_tests::repo_root;

fn preset_text() -> String {
    std::fs::read_to_string(repo_root().join("presets/paper.toml")).unwrap()
}

/// The preset with `key = ...` inside `[section]` replaced (or removed when
/// `value` is `None`).
fn edited(section: &str, key: &str, value: Option<&str>) -> String {
    let mut out = String::new();
    let mut current = String::new();
    let mut hit = false;
    for line in preset_text().lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            current = trimmed.trim_matches(|c| c == '[' || c == ']').to_string();
        }
        let is_key = trimmed.split('=').next().map(str::trim) == Some(key);
        if current == section && is_key {
            hit = true;
            if let Some(v) = value {
                out.push_str(&format!("{key} = {v}\n"));
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    assert!(hit, "{section}.{key} not in the preset");
    out
}

fn param_error(text: &str) -> ParamError {
    match params_file::parse(text) {
        Err(LoadError::Param(e)) => e,
        other => panic!("expected a parameter error, got {other:?}"),
    }
}

#[test]
fn every_required_field_is_reported_missing_by_name() {
    for f in compensator::params::CORE_FIELDS.iter() {
        let e = param_error(&edited(f.section, f.key, None));
        assert_eq!((e.field, e.problem), (f.path, Problem::Missing));
        assert_eq!(e.to_string(), format!("{}: missing", f.path));
    }
}

#[test]
fn every_field_rejects_nan_and_infinity() {
    for f in compensator::params::CORE_FIELDS.iter() {
        let e = param_error(&edited(f.section, f.key, Some("nan")));
        assert_eq!((e.field, e.problem), (f.path, Problem::NotANumber));
        let e = param_error(&edited(f.section, f.key, Some("-inf")));
        assert_eq!((e.field, e.problem), (f.path, Problem::Infinite));
    }
}

#[test]
fn non_physical_values_name_the_field_and_the_rule() {
    let cases: &[(&str, &str, &str, &str)] = &[
        (
            "plunger",
            "spring_rate",
            "-25000.0",
            "plunger.spring_rate = -25000: must lie in [0.1, 1e9] N/m (plausible range)",
        ),
        (
            "plunger",
            "mass",
            "0",
            "plunger.mass = 0: must lie in [1e-6, 1000] kg (plausible range)",
        ),
        (
            "plunger",
            "damping",
            "-1.0",
            "plunger.damping = -1: must be 0 or [1e-6, 1e6] N s/m (plausible range)",
        ),
        (
            "plunger",
            "preload",
            "0.002",
            "plunger.preload = 0.002: beyond plunger.stroke",
        ),
        (
            "turbulent_throttle",
            "discharge_coefficient",
            "1.2",
            "turbulent_throttle.discharge_coefficient = 1.2: must lie in [0.1, 1] (plausible range)",
        ),
        (
            "slot",
            "discharge_coefficient",
            "0.0",
            "slot.discharge_coefficient = 0: must lie in [0.1, 1] (plausible range)",
        ),
        (
            "chambers",
            "volume_a",
            "1.0e-7",
            "chambers.volume_a = 1e-7: must exceed 1.1780972450961727e-7 (the volume the plunger sweeps, pi/4 plunger.diameter^2 plunger.stroke)",
        ),
        (
            "operating",
            "pressure_drop",
            "0.0",
            "operating.pressure_drop = 0: must lie in [1000, 1e8] Pa (plausible range)",
        ),
        (
            "fluid",
            "expansion",
            "0.5",
            "fluid.expansion = 0.5: must be 0 or [1e-6, 0.01] 1/K (plausible range)",
        ),
    ];
    for (section, key, value, message) in cases {
        let e = param_error(&edited(section, key, Some(value)));
        assert_eq!(e.to_string(), *message);
    }
}

#[test]
fn estimator_settings_the_loop_cannot_honour_are_rejected() {
    let cases: &[(&str, &str)] = &[
        // Counted samples.
        (
            "spike_limit = 2.5",
            "estimator.spike_limit = 2.5: must be a whole number",
        ),
        // The counter must be able to exceed the limit.
        (
            "spike_limit = 65535",
            "estimator.spike_limit = 65535: must lie in [0, 65534] (plausible range)",
        ),
        // Telemetry every tick would starve the rotating jobs.
        (
            "telemetry_hz = 1000",
            "estimator.telemetry_hz = 1000: must lie in [0, 500] (at most half of estimator.tick_hz)",
        ),
        (
            "tick_hz = 100\ntelemetry_hz = 60",
            "estimator.telemetry_hz = 60: must lie in [0, 50] (at most half of estimator.tick_hz)",
        ),
    ];
    for (lines, message) in cases {
        let text = format!("{}\n[estimator]\n{lines}\n", preset_text());
        assert_eq!(param_error(&text).to_string(), *message, "{lines}");
    }
}

#[test]
fn sensor_settings_are_checked_alone_and_against_the_oil_range() {
    let cases: &[(&str, &str)] = &[
        (
            "rtd_wires = 5",
            "estimator.rtd_wires = 5: must lie in [2, 4] (plausible range)",
        ),
        ("rtd_wires = 2.5", "estimator.rtd_wires = 2.5: must be a whole number"),
        ("mains_hz = 55", "estimator.mains_hz = 55: must be 50 or 60"),
        (
            "rtd_a = 0.039",
            "estimator.rtd_a = 0.039: must lie in [0.001, 0.01] 1/C (plausible range)",
        ),
        // R(t) falling above 195 C: A + 2 B t < 0 there, inside oil_max = 300.
        (
            "oil_max = 300\nrtd_reference = 4000\nrtd_b = -1.0e-5",
            "estimator.rtd_b = -1e-5: the RTD's resistance (estimator.rtd_a, estimator.rtd_b, estimator.rtd_c) must rise with temperature over estimator.oil_min..estimator.oil_max",
        ),
        // A PT1000 on a board fitted for a PT100: R(150 C) = 1573.251 ohm
        // (IEC 60751, by hand: 1000 (1 + 0.58625 - 0.01299)) and two codes
        // of margin, 1573.251 * 32768 / 32766 = 1573.347 ohm.
        ("rtd_r0 = 1000", "estimator.rtd_reference = 430: must exceed 1573.3472"),
        // The default PT100 at a hotter oil_max: R(300 C) = 212.0515 ohm.
        (
            "oil_max = 300\nrtd_reference = 212",
            "estimator.rtd_reference = 212: must exceed 212.06",
        ),
    ];
    for (lines, message) in cases {
        let text = format!("{}\n[estimator]\n{lines}\n", preset_text());
        let e = param_error(&text).to_string();
        assert!(e.starts_with(message), "{lines}: {e}");
    }
    // The board's own settings are accepted: 4 wires, 60 Hz, a calibrated
    // curve, a PT1000 with its 4300 ohm reference.
    let text = format!(
        "{}\n[estimator]\nrtd_wires = 4\nmains_hz = 60\nrtd_r0 = 1000\nrtd_reference = 4300\nrtd_a = 3.9122e-3\nrtd_b = -5.781e-7\n",
        preset_text()
    );
    let raw = params_file::parse(&text).unwrap();
    assert_eq!((raw.estimator.rtd_wires, raw.estimator.mains_hz), (4.0, 60.0));
}

#[test]
fn unknown_keys_wrong_types_and_partial_sections_are_errors() {
    let typo = preset_text().replace("spring_rate", "spring_rat");
    assert!(matches!(params_file::parse(&typo), Err(LoadError::UnknownKey(k)) if k == "plunger.spring_rat"));
    let text = edited("plunger", "mass", Some("\"heavy\""));
    assert!(matches!(
        params_file::parse(&text),
        Err(LoadError::NotANumber {
            field: "plunger.mass",
            found: "string"
        })
    ));
    let without_machine: String = preset_text().split("[machine]").next().unwrap().to_string();
    let partial = format!("{without_machine}\n[machine]\nworking_flow = 1e-5\n");
    let e = param_error(&partial);
    assert_eq!((e.field, e.problem), ("machine.leakage_reference", Problem::Missing));
    assert!(matches!(params_file::parse("[fluid\nx = 1"), Err(LoadError::Syntax(_))));
}

#[test]
fn values_beyond_the_plausible_range_are_refused_before_any_conversion() {
    // 1e300 N/m fits f64 but not f32; no spring has it, so the file is
    // refused by name before any scalar type is chosen (every plausible
    // value fits f32: the model's own tests check the ranges' ends).
    let e = param_error(&edited("plunger", "spring_rate", Some("1e300")));
    assert_eq!(
        e.to_string(),
        "plunger.spring_rate = 1e300: must lie in [0.1, 1e9] N/m (plausible range)"
    );
    let raw = params_file::parse(&edited("plunger", "spring_rate", Some("1e9"))).unwrap();
    assert!(Params::<f32>::new(&raw).is_ok());
    assert!(Params::<f64>::new(&raw).is_ok());
}

#[test]
fn temperatures_outside_the_oil_range_are_typed_errors() {
    let raw = params_file::parse(&preset_text()).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    for t in [
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
        -300.0,
        -273.15,
        1.0e6,
        400.0,
        -250.0,
        f32::MAX,
    ] {
        match equilibrium(&p, t) {
            Err(ModelError::NonFinite(_)) | Err(ModelError::OutOfRange(_)) => {}
            other => panic!("t = {t}: {other:?}"),
        }
    }
}

fn run(args: &[&str]) -> (i32, String, String) {
    host_tests::run_cli(args)
}

#[track_caller]
fn assert_bad_input(args: &[&str], names: &str) {
    let (code, stdout, stderr) = run(args);
    assert_eq!(code, 2, "{args:?}: exit {code}, stderr {stderr}");
    assert!(stdout.is_empty(), "{args:?}: stdout {stdout}");
    // One line, or two for a command-line error: clap's problem, then its
    // tip (the nearest valid name) or the usage.
    assert!((1..=2).contains(&stderr.lines().count()), "{args:?}: stderr {stderr:?}");
    assert!(stderr.contains(names), "{args:?}: '{stderr}' does not name {names}");
}

#[test]
fn cli_bad_input_exits_2_with_one_line_naming_the_field() {
    let dir = std::env::temp_dir().join(format!("compensator-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let missing = write("missing.toml", &edited("plunger", "spring_rate", None));
    let negative = write("negative.toml", &edited("laminar_throttle", "length", Some("-0.02")));
    let nan = write("nan.toml", &edited("fluid", "density_15", Some("nan")));
    assert_bad_input(&["equilibrium", "--params", &missing], "plunger.spring_rate");
    assert_bad_input(&["equilibrium", "--params", &negative], "laminar_throttle.length");
    assert_bad_input(
        &["asymptotic", "--params", &nan, "--order", "1", "--reading", "property"],
        "fluid.density_15",
    );
    assert_bad_input(
        &["equilibrium", "--params", "presets/paper.toml", "--temps", "30:80:0"],
        "--temps",
    );
    assert_bad_input(
        &["equilibrium", "--params", "presets/paper.toml", "--temps", "30,abc"],
        "--temps",
    );
    // A temperature beyond the file's oil model (the paper oil's ends at
    // 105.9 C, where its viscosity reaches 2 cSt) is refused by the
    // envelope check, naming the limit.
    assert_bad_input(
        &["equilibrium", "--params", "presets/paper.toml", "--temps", "500"],
        "--temps: 500 C is above the oil model's range -20 to 105.9 C",
    );
    assert_bad_input(
        &["equilibrium", "--params", "/nonexistent/p.toml"],
        "/nonexistent/p.toml",
    );
    // A PT1000 on a 430 ohm board: every reading would saturate.
    let pt1000 = write(
        "pt1000.toml",
        &format!("{}\n[estimator]\nrtd_r0 = 1000\n", preset_text()),
    );
    assert_bad_input(&["equilibrium", "--params", &pt1000], "estimator.rtd_reference");
    assert_bad_input(
        &[
            "asymptotic",
            "--params",
            "presets/paper.toml",
            "--order",
            "3",
            "--reading",
            "property",
        ],
        "--order",
    );
    assert_bad_input(
        &[
            "asymptotic",
            "--params",
            "presets/paper.toml",
            "--order",
            "1",
            "--reading",
            "x",
        ],
        "--reading",
    );
    assert_bad_input(
        &[
            "asymptotic",
            "--params",
            "presets/paper.toml",
            "--order",
            "1",
            "--reading",
            "property",
            "--t0",
            "hot",
        ],
        "--t0",
    );
    assert_bad_input(
        &["equilibrium", "--params", "presets/paper.toml", "--precision", "f16"],
        "--precision",
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn cli_equilibrium_and_asymptotic_write_the_documented_columns() {
    let (code, out, err) = run(&["equilibrium", "--params", "presets/paper.toml", "--temps", "30:80:10"]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[0],
        "t_c,a_sqrt_pa,p_a_pa,p_b_pa,dp_ab_pa,x_m,q_branch_m3s,q_throt_m3s,q_total_m3s,nu_m2s,envelope,error"
    );
    assert_eq!(lines.len(), 7);
    assert!(lines[5].ends_with(",validated,"), "{}", lines[5]);
    let row: Vec<f64> = lines[5].split(',').take(10).map(|v| v.parse().unwrap()).collect();
    assert_eq!(row[0], 70.0);
    let raw = params_file::parse(&preset_text()).unwrap();
    let r = host_tests::reference::equilibrium(&raw.core, 70.0);
    assert!(host_tests::isclose(row[5], r.x, 1e-12, 1e-15));
    let (code32, out32, _) = run(&[
        "equilibrium",
        "--params",
        "presets/paper.toml",
        "--temps",
        "70",
        "--precision",
        "f32",
    ]);
    assert_eq!(code32, 0);
    let row32: Vec<f64> = out32
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .take(10)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((row32[5] - r.x).abs() < 1e-5 * raw.core.stroke);

    let (code, out, err) = run(&[
        "asymptotic",
        "--params",
        "presets/paper.toml",
        "--order",
        "2",
        "--reading",
        "property",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "t_c,x_qs_m,x_asym_m,envelope,error");
    assert_eq!(lines.len(), 7);
}

#[test]
fn malformed_paper_tables_exit_2_naming_the_file() {
    let table2 = std::fs::read_to_string(repo_root().join("data/paper/table2.csv")).unwrap();
    let cases: &[(&str, &str, &str)] = &[
        // Only the temperature column.
        ("t_c\n30\n40\n", "no dp_ab_<N>bar column", "table1.csv"),
        // A header and no rows.
        ("t_c,dp_ab_4bar\n", "at least two rows", "table1.csv"),
        // A NaN.
        ("t_c,dp_ab_4bar\n30,1.0\n40,nan\n", "not a finite number", "table1.csv"),
        // The first column is not the temperature.
        (
            "dp_ab_4bar,t_c\n1.0,30\n1.0,40\n",
            "first column must be t_c",
            "table1.csv",
        ),
    ];
    for (i, (table1, why, file)) in cases.iter().enumerate() {
        let dir = std::env::temp_dir().join(format!("compensator-bad-tables-{}-{i}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("table1.csv"), table1).unwrap();
        std::fs::write(dir.join("table2.csv"), &table2).unwrap();
        let data = dir.to_string_lossy().into_owned();
        // (`calibrate` reads the long form: cli/tests/calibrate.rs.)
        let args = ["paper", "--params", "presets/paper.toml", "--data", &data];
        assert_bad_input(&args, file);
        let (_, _, stderr) = run(&args);
        assert!(stderr.contains(why), "paper {table1:?}: {stderr}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn negative_temperatures_are_values_not_flags() {
    // -10 C is inside the oil model's range of the preset only if Walther
    // accepts it; either way the argument must parse as a number.
    let (_, _, stderr) = run(&["eigen", "--params", "presets/paper.toml", "--temps", "-10"]);
    assert!(!stderr.contains("unexpected argument"), "{stderr}");
    let (code, out, err) = run(&["equilibrium", "--params", "presets/paper.toml", "--temps", "-10,30"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 3, "{out}");
}

#[test]
fn toml_syntax_errors_name_their_line() {
    for (text, line) in [
        // A duplicate key: the error starts at the beginning of line 3.
        ("[plunger]\nmass = 0.01\nmass = 0.02\n", 3),
        // A value missing at the end of line 2.
        ("[plunger]\nmass =\n", 2),
        ("mass = 0.01 0.02\n", 1),
    ] {
        match params_file::parse(text) {
            Err(LoadError::Syntax(m)) => assert!(m.starts_with(&format!("line {line}:")), "{text:?}: {m}"),
            other => panic!("{text:?}: {other:?}"),
        }
    }
}
