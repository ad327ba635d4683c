//! The dynamic commands of the CLI: their columns, their first rows, and
//! their bad-input contract.

use host_tests::{isclose, repo_root, run_cli};

fn rows(out: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = out.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    (
        header,
        lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
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
fn eigen_and_indicators_write_their_columns() {
    let (code, out, err) = run_cli(&["eigen", "--params", "presets/paper.toml", "--temps", "30,80"]);
    assert_eq!(code, 0, "{err}");
    let (header, r) = rows(&out);
    assert_eq!(header.len(), 11);
    assert_eq!(header[9..], ["zeta_dominant", "omega_n_dominant"]);
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
