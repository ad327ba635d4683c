//! The dynamic commands of the CLI: their columns, their first rows, the
//! twin configuration they run, failures that name their cause, and
//! their bad-input contract.

use host_tests::{isclose, repo_root, run_cli};

/// The numeric columns of a command's CSV (the `envelope` and `error`
/// columns, words, are left out; so is a time series' `t_c`, the
/// profile's temperature, checked in
/// `step_writes_the_temperature_each_tick_ran_at`, so that the positions
/// below are `time_s, x_m, v_m_s, p_a_pa, p_b_pa`).
fn rows(out: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = out.lines();
    let all: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let series = all.first().is_some_and(|h| h == "time_s");
    let keep: Vec<usize> = (0..all.len())
        .filter(|&i| all[i] != "envelope" && all[i] != "error" && !(series && all[i] == "t_c"))
        .collect();
    let header = keep.iter().map(|&i| all[i].clone()).collect();
    (
        header,
        lines
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                keep.iter().map(|&i| cells[i].parse().unwrap()).collect()
            })
            .collect(),
    )
}

#[test]
fn step_starts_at_the_equilibrium_and_writes_one_row_per_tick() {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let eq = host_tests::reference::equilibrium(&raw.core, 40.0);
    for precision in ["f64", "f32", "fixed", "reference"] {
        let (code, out, err) = run_cli(&[
            "step",
            "--params",
            "presets/paper.toml",
            "--from",
            "40",
            "--to",
            "50",
            "--t-end",
            "0.2",
            "--precision",
            precision,
        ]);
        assert_eq!(code, 0, "{precision}: {err}");
        let (header, r) = rows(&out);
        assert_eq!(header, ["time_s", "x_m", "v_m_s", "p_a_pa", "p_b_pa"]);
        assert_eq!(r.len(), 201, "{precision}");
        assert_eq!(r[0][0], 0.0);
        assert!(
            isclose(r[0][1], eq.x, 1e-5, 1e-9),
            "{precision}: x0 {} vs {}",
            r[0][1],
            eq.x
        );
        assert!(isclose(r[0][3], eq.p_a, 1e-5, 0.0), "{precision}: p_a0");
        assert!(isclose(r[200][0], 0.2, 1e-12, 0.0));
    }
    // A ramp: 1 C/s from 40 to 41 C, then half a second more.
    let (code, out, _) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "40",
        "--to",
        "41",
        "--ramp",
        "1",
    ]);
    assert_eq!(code, 0);
    assert_eq!(rows(&out).1.len(), 1501);
}

#[test]
fn step_writes_the_temperature_each_tick_ran_at() {
    // A ramp 40 -> 41 C at 10 C/s, 1 ms ticks: tick k runs at its midpoint.
    let (code, out, err) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "40",
        "--to",
        "41",
        "--ramp",
        "10",
        "--t-end",
        "0.2",
    ]);
    assert_eq!(code, 0, "{err}");
    let mut lines = out.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        ["time_s", "t_c", "x_m", "v_m_s", "p_a_pa", "p_b_pa", "envelope"]
    );
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let (t, t_c): (f64, f64) = (cells[0].parse().unwrap(), cells[1].parse().unwrap());
        let want = if t == 0.0 {
            40.0
        } else {
            (40.0 + 10.0 * (t - 0.0005)).min(41.0)
        };
        assert!((t_c - want).abs() <= 1e-9, "{t}: {t_c} vs {want}");
        assert_eq!(cells[6], "validated");
    }
}

#[test]
fn eigen_and_indicators_write_their_columns() {
    let (code, out, err) = run_cli(&["eigen", "--params", "presets/paper.toml", "--temps", "30,80"]);
    assert_eq!(code, 0, "{err}");
    let (header, r) = rows(&out);
    assert_eq!(header.len(), 12);
    assert_eq!(header[9..], ["zeta_dominant", "omega_n_dominant", "zeta_plunger"]);
    assert!(r.iter().all(|row| row[1] < 0.0), "dominant real parts negative");
    let (code, out, err) = run_cli(&["indicators", "--params", "presets/paper.toml", "--steps", "30:40,70:80"]);
    assert_eq!(code, 0, "{err}");
    let (header, r) = rows(&out);
    assert_eq!(
        header,
        [
            "from_c",
            "to_c",
            "x_star_m",
            "settling_time_s",
            "overshoot_pct",
            "dominant_re"
        ]
    );
    assert_eq!(r.len(), 2);
}

#[track_caller]
fn bad(args: &[&str], names: &str) {
    let (code, out, err) = run_cli(args);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err:?}");
    assert!(err.contains(names), "'{err}' does not name {names}");
}

#[test]
fn dynamic_commands_reject_bad_input_with_one_line() {
    fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        ["step", "--params", "presets/paper.toml"]
            .iter()
            .chain(extra.iter())
            .copied()
            .collect()
    }
    bad(&with(&["--from", "40", "--to", "50", "--dt", "0"]), "--dt");
    bad(&with(&["--from", "40", "--to", "50", "--dt", "-1e-3"]), "--dt");
    bad(&with(&["--from", "nan", "--to", "50"]), "--from");
    bad(&with(&["--from", "40", "--to", "50", "--ramp", "-1"]), "--ramp");
    bad(&with(&["--from", "40", "--to", "50", "--substeps", "0"]), "--substeps");
    bad(&with(&["--from", "40", "--to", "50", "--t-end", "1e9"]), "--t-end");
    bad(&with(&["--from", "40", "--to", "500"]), "500");
    bad(
        &with(&["--from", "40", "--to", "50", "--precision", "f16"]),
        "--precision",
    );
    bad(
        &["indicators", "--params", "presets/paper.toml", "--steps", "30-40"],
        "--steps",
    );
    bad(&["eigen", "--params", "presets/paper.toml", "--temps", "x"], "--temps");
}

/// One CSV data row of `twin-config`, by column.
fn twin_config(params: &str, dt: &str) -> std::collections::HashMap<String, String> {
    let (code, out, err) = run_cli(&["twin-config", "--params", params, "--dt", dt]);
    assert_eq!(code, 0, "{err}");
    let mut lines = out.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "scheme",
            "substeps",
            "tick_s",
            "valid_min_c",
            "valid_max_c",
            "estimated_error_pct",
            "target_pct",
            "goal_met"
        ]
    );
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert!(lines.next().is_none(), "one row: {out}");
    header
        .iter()
        .zip(row)
        .map(|(h, v)| (h.to_string(), v.to_string()))
        .collect()
}

#[test]
fn twin_config_prints_the_choosers_choice_over_the_validated_range() {
    use compensator::dynamics::config::{TARGET_PCT, choose};
    for (file, dt) in [("presets/model-example.toml", "0.001"), ("presets/paper.toml", "0.005")] {
        let raw = compensator_cli::load(&repo_root().join(file)).unwrap();
        let p = compensator::Params::<f64>::new(&raw).unwrap();
        let tick: f64 = dt.parse().unwrap();
        let c = choose(&p, tick, (raw.estimator.valid_min, raw.estimator.valid_max)).unwrap();
        let row = twin_config(file, dt);
        assert_eq!(row["scheme"], c.config.scheme.name(), "{file}");
        assert_eq!(row["substeps"].parse::<u8>().unwrap(), c.config.substeps, "{file}");
        assert_eq!(row["tick_s"].parse::<f64>().unwrap(), tick);
        assert_eq!(row["valid_min_c"].parse::<f64>().unwrap(), raw.estimator.valid_min);
        assert_eq!(row["valid_max_c"].parse::<f64>().unwrap(), raw.estimator.valid_max);
        assert_eq!(
            row["estimated_error_pct"].parse::<f64>().unwrap(),
            c.estimated_error_pct
        );
        assert_eq!(row["target_pct"].parse::<f64>().unwrap(), TARGET_PCT);
        assert_eq!(row["goal_met"], c.goal_met.to_string());
    }
    bad(&["twin-config", "--params", "presets/paper.toml", "--dt", "0"], "--dt");
}

#[test]
fn step_runs_the_chosen_configuration_unless_overridden() {
    // The example design needs 4 substeps at 1 ms (neither 1 nor the
    // former default 2), the paper preset 4 at 5 ms.
    for (file, dt) in [("presets/model-example.toml", "0.001"), ("presets/paper.toml", "0.005")] {
        let row = twin_config(file, dt);
        let n: u8 = row["substeps"].parse().unwrap();
        let step = |extra: &[&str]| {
            let mut args = vec![
                "step", "--params", file, "--from", "30", "--to", "78", "--dt", dt, "--t-end", "0.1",
            ];
            args.extend_from_slice(extra);
            let (code, out, err) = run_cli(&args);
            assert_eq!(code, 0, "{extra:?}: {err}");
            (out, err)
        };
        let (chosen, note) = step(&[]);
        assert_eq!(note.lines().count(), 1, "{note}");
        let named = format!("twin: {}, {n} substep", row["scheme"]);
        assert!(note.starts_with(&named), "'{note}' does not name {named}");
        assert!(note.contains(&format!("per {dt} s tick")), "{note}");
        assert!(note.contains("chosen over the validated 26-78 C"), "{note}");
        let estimate: f64 = row["estimated_error_pct"].parse().unwrap();
        assert!(note.contains(&format!("estimated error {estimate:.3} %")), "{note}");
        assert!(
            note.ends_with(if row["goal_met"] == "true" { ": met\n" } else { ")\n" }),
            "{note}"
        );
        // Bit-identical to the same configuration given explicitly (and
        // to --substeps alone, which runs sdirk3), different from another.
        let n_s = n.to_string();
        let (given, note_given) = step(&["--scheme", &row["scheme"], "--substeps", &n_s]);
        assert_eq!(chosen, given, "{file}");
        assert!(note_given.contains("from --scheme and --substeps"), "{note_given}");
        assert_eq!(chosen, step(&["--substeps", &n_s]).0, "{file}");
        let other = (if n == 1 { 2 } else { n - 1 }).to_string();
        assert_ne!(chosen, step(&["--substeps", &other]).0, "{file}: {n} vs {other}");
        // --scheme alone keeps the chosen substeps.
        let (_, note_scheme) = step(&["--scheme", "ros3"]);
        assert!(
            note_scheme.starts_with(&format!("twin: ros3, {n} substep")),
            "{note_scheme}"
        );
    }
}

#[test]
fn a_diverging_tick_exits_non_zero_naming_the_cause() {
    // RK4 at a 2 ms tick is unstable on the paper preset's pressures: the
    // twin stops with StepError::Diverged instead of printing 4.5e61 Pa.
    let (code, out, err) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "30",
        "--to",
        "80",
        "--scheme",
        "rk4",
        "--substeps",
        "1",
        "--dt",
        "0.002",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "no table after a failed tick");
    assert_eq!(err.lines().count(), 1, "{err:?}");
    let cause = compensator::dynamics::schemes::StepError::Diverged.to_string();
    assert!(err.contains(&cause), "'{err}' does not name '{cause}'");
    assert!(err.contains("rk4, 1 substep per 0.002 s tick"), "{err}");
    assert!(err.starts_with("error: tick "), "{err}");
    // The chosen configuration at the same tick runs it through.
    let (code, _, err) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "30",
        "--to",
        "80",
        "--dt",
        "0.002",
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn the_reference_completes_a_long_ramp() {
    // 30 -> 80 C at 0.1 C/s: 500 s, then 0.5 s at 80 C. At a 4 ms output
    // step the solver needs ~125,000 steps in the ramp's phase, beyond the
    // library's default budget of 100,000 that stopped it half-way.
    let (code, out, err) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "30",
        "--to",
        "80",
        "--ramp",
        "0.1",
        "--dt",
        "0.004",
        "--precision",
        "reference",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, r) = rows(&out);
    assert_eq!(r.len(), 125_126);
    let last = r.last().unwrap();
    assert!(isclose(last[0], 500.5, 1e-12, 0.0), "ends at {}", last[0]);
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let eq = host_tests::reference::equilibrium(&raw.core, 80.0);
    let (stroke, dp) = (raw.core.stroke, raw.core.pressure_drop);
    assert!((last[1] - eq.x).abs() <= 1e-6 * stroke, "x {} vs {}", last[1], eq.x);
    assert!((last[3] - eq.p_a).abs() <= 1e-6 * dp, "p_a {} vs {}", last[3], eq.p_a);
    assert!((last[4] - eq.p_b).abs() <= 1e-6 * dp, "p_b {} vs {}", last[4], eq.p_b);
    // Half-way through the ramp (55 C at 250 s) it follows the equilibrium
    // closely too: the ramp is slow against the plunger's time constants.
    let mid = &r[62_500];
    assert!(isclose(mid[0], 250.0, 1e-12, 0.0));
    let eq_mid = host_tests::reference::equilibrium(&raw.core, 55.0);
    assert!(
        (mid[1] - eq_mid.x).abs() <= 1e-3 * stroke,
        "x(250 s) {} vs {}",
        mid[1],
        eq_mid.x
    );
}

#[test]
fn a_reference_run_too_long_is_refused_up_front() {
    let limit = compensator_reference::dynamics::MAX_SAMPLES;
    // One sample too many at 1 ms (within the twin's tick limit).
    let t_end = ((limit + 1) as f64 * 1e-3).to_string();
    let (code, out, err) = run_cli(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "30",
        "--to",
        "80",
        "--t-end",
        &t_end,
        "--precision",
        "reference",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err:?}");
    let samples = format!("{} output samples", limit + 1);
    for named in [
        "--t-end / --dt",
        &samples,
        &format!("limit of {limit}"),
        "use a larger --dt",
    ] {
        assert!(err.contains(named), "'{err}' does not name {named}");
    }
    // The library refuses it as well, before solving.
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let profile = compensator_reference::dynamics::Profile::Step { from: 30.0, to: 80.0 };
    let e = compensator_reference::dynamics::simulate(
        &raw.core,
        profile,
        (limit + 1) as f64 * 1e-3,
        1e-3,
        compensator_reference::dynamics::Method::Radau5,
        1e-12,
    )
    .unwrap_err();
    assert!(e.contains(&limit.to_string()) && e.contains("exceed"), "{e}");
}
