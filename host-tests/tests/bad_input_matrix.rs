//! Every bad input named: every field of the parameter file's schema
//! (iterated from its field tables) against missing, -1, 0, NaN, inf, a
//! string, an array, 1e300, 5e-324 and values just outside and at the ends
//! of its plausible range, each through the file reader, the validation,
//! the conversion and the equilibrium (`host_tests::matrix`). The table is
//! `docs/parameters.md`'s; `cargo run -p host-tests --example
//! bad_input_matrix -- --write` rewrites it.

use host_tests::matrix::{
    Case, Cell, Outcome, fields, generated_blocks, matrix, summary, tolerance_fields, tolerance_matrix, with_blocks,
};
use host_tests::random::{Rng, physical_params, unsized_params};
use host_tests::repo_root;

#[test]
fn every_bad_value_of_every_field_is_refused_by_its_name_and_every_accepted_one_computes() {
    let cells = matrix();
    assert_eq!(cells.len(), fields().count() * Case::ALL.len());
    check(&cells);
}

/// The same for the standard uncertainty of every field that can have one
/// (`tolerances.section.key`), its plausible range up to a third of the
/// preset's value.
#[test]
fn every_bad_tolerance_is_refused_by_its_name_and_every_accepted_one_computes() {
    let cells = tolerance_matrix();
    assert_eq!(cells.len(), tolerance_fields().len() * Case::ALL.len());
    check(&cells);
}

fn check(cells: &[Cell]) {
    let wrong: Vec<String> = cells
        .iter()
        .filter(|c| !c.is_right())
        .map(|c| format!("{} {:?}: {:?}", c.field.path, c.case, c.outcome))
        .collect();
    assert!(wrong.is_empty(), "{}\n{}", summary(cells), wrong.join("\n"));
    for c in cells {
        match (&c.outcome, c.case) {
            // Every error is one short line.
            (Outcome::Refused(r), _) => {
                assert_eq!(r.message.lines().count(), 1, "{}", r.message);
                assert!(r.message.len() <= 240, "{} bytes: {}", r.message.len(), r.message);
            }
            // Outside the plausible range, and NaN, inf, text, arrays,
            // 1e300: never accepted.
            (
                Outcome::Accepted { .. },
                Case::Nan | Case::Inf | Case::Text | Case::Array | Case::Huge | Case::Below | Case::Above,
            ) => panic!("{} {:?} accepted", c.field.path, c.case),
            (Outcome::Accepted { .. }, _) => {}
        }
        // A required key left out is named as missing.
        if c.case == Case::Missing && c.field.default.is_none() {
            assert!(
                matches!(&c.outcome, Outcome::Refused(r) if r.rule == "missing"),
                "{}: {:?}",
                c.field.path,
                c.outcome
            );
        }
    }
}

#[test]
fn docs_parameters_md_holds_the_current_tables() {
    let path = repo_root().join("docs/parameters.md");
    let doc = std::fs::read_to_string(&path).expect("docs/parameters.md");
    let current = with_blocks(&doc, &generated_blocks()).expect("docs/parameters.md has its GENERATED markers");
    assert!(
        doc == current,
        "docs/parameters.md is stale: run `cargo run -p host-tests --example bad_input_matrix -- --write`"
    );
}

/// Inputs that used to be refused by another field, a temperature
/// argument, or not at all: each is now named by the field that is wrong.
#[test]
fn formerly_misreported_inputs_name_the_wrong_field() {
    use host_tests::matrix::{base_text, edited};
    let base = base_text();
    let field = |path: &str| fields().find(|f| f.path == path).unwrap();
    for (path, value, message) in [
        (
            "fluid.walther_a",
            "20",
            "fluid.walther_a = 20: the oil's viscosity at 40 C (fluid.walther_a, fluid.walther_b) must lie in [2, 1e5] cSt (plausible range)",
        ),
        (
            "plunger.diameter",
            "1e160",
            "plunger.diameter = 1e160: must lie in [1e-4, 1] m (plausible range)",
        ),
        (
            "laminar_throttle.length",
            "5e-324",
            "laminar_throttle.length = 5e-324: must lie in [1e-4, 10] m (plausible range)",
        ),
        (
            "fluid.density_15",
            "1e-3",
            "fluid.density_15 = 0.001: must lie in [500, 2000] kg/m^3 (plausible range)",
        ),
        (
            "plunger.mass",
            "1e-12",
            "plunger.mass = 1e-12: must lie in [1e-6, 1000] kg (plausible range)",
        ),
        (
            "fluid.bulk_modulus",
            "1.0",
            "fluid.bulk_modulus = 1: must lie in [1e7, 1e10] Pa (plausible range)",
        ),
        (
            "fluid.bulk_modulus",
            "1e30",
            "fluid.bulk_modulus = 1e30: must lie in [1e7, 1e10] Pa (plausible range)",
        ),
        (
            "operating.outlet_pressure",
            "1e22",
            "operating.outlet_pressure = 1e22: must be 0 or [1, 1e8] Pa (plausible range)",
        ),
        (
            "estimator.rtd_r0",
            "1e-300",
            "estimator.rtd_r0 = 1e-300: must lie in [1, 1e5] ohm (plausible range)",
        ),
    ] {
        let text = edited(&base, field(path), Some(value));
        let e = compensator_cli::params_file::parse(&text).unwrap_err();
        assert_eq!((e.field(), e.to_string().as_str()), (Some(path), message));
    }
}

/// The CLI says the same, with exit status 2: `equilibrium` and
/// `indicators` (which used to exit 1 with the ODE library's message on a
/// tiny density).
#[test]
fn the_cli_refuses_formerly_misreported_inputs_by_the_wrong_fields_name() {
    use host_tests::matrix::{base_text, edited};
    let base = base_text();
    let dir = std::env::temp_dir().join(format!("compensator-bad-matrix-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (i, (path, value)) in [
        ("fluid.walther_a", "20"),
        ("plunger.diameter", "1e160"),
        ("laminar_throttle.length", "5e-324"),
        ("fluid.density_15", "1e-300"),
    ]
    .into_iter()
    .enumerate()
    {
        let f = fields().find(|f| f.path == path).unwrap();
        let file = dir.join(format!("case{i}.toml"));
        std::fs::write(&file, edited(&base, f, Some(value))).unwrap();
        let file = file.to_string_lossy().into_owned();
        for args in [
            vec!["equilibrium", "--params", &file],
            vec!["indicators", "--params", &file, "--steps", "30:40"],
        ] {
            let (code, stdout, stderr) = host_tests::run_cli(&args);
            assert_eq!(code, 2, "{args:?}: {stderr}");
            assert!(stdout.is_empty());
            assert_eq!(stderr.lines().count(), 1, "{stderr}");
            assert!(stderr.contains(&format!("{path} = ")), "{args:?}: {stderr}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The random designs of the host tests stay inside the plausible ranges,
/// far more of them than any test draws: the generators assert that their
/// sets validate, so drawing is the check.
#[test]
fn the_host_tests_random_designs_stay_inside_the_plausible_ranges() {
    let _ = host_tests::survey::designs(20_000, 0x5EED_2026);
    let _ = host_tests::survey::designs(2_000, 0xC0FFEE);
    for seed in [1, 2, 3, 4, 7, 71, 99, 2024, 0x5EED] {
        let mut rng = Rng::new(seed);
        for _ in 0..3_000 {
            let _ = physical_params(&mut rng);
            let _ = unsized_params(&mut rng);
        }
    }
}
