//! `calibrate`: spreadsheet CSV accepted, bad data refused naming row and
//! column, fits the data cannot determine refused, and the reported
//! standard errors honest on synthetic data from known parameters.

use compensator_cli::calibration::{self, DisplacementPoint, PressurePoint};
use compensator_cli::{input, params_file};
mod common;
use common::{root, run};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::path::PathBuf;

/// A file in a fresh temporary directory.
fn temp_file(name: &str, contents: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-calibrate-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

const PRESSURE: &str = "data/calibration/paper-pressure.csv";
const DISPLACEMENT: &str = "data/calibration/paper-displacement.csv";

#[test]
fn a_spreadsheet_export_with_bom_semicolons_quotes_and_decimal_commas_is_read() {
    // The paper's pressure data as a European spreadsheet writes it:
    // BOM, `;` separators, quoted header and cells, decimal commas (bar
    // values scaled back to Pa through a decimal: 0,7e5 is not used; the
    // cells are written as "70000,0").
    let text = std::fs::read_to_string(root().join(PRESSURE)).unwrap();
    let mut sheet = String::from("\u{feff}\"t_c\";\"dp_pa\";\"dp_ab_pa\"\r\n");
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        sheet.push_str(&format!("\"{}\";{},0;\"{},0\"\r\n", cells[0], cells[1], cells[2]));
    }
    let path = temp_file("sheet.csv", sheet.as_bytes());
    let args = |p: &str| ["calibrate", "--pressure-data", p, "--displacement-data", DISPLACEMENT].map(str::to_string);
    let a = args(&path.to_string_lossy());
    let (code, out, err) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{err}");
    let b = args(PRESSURE);
    let (code, reference, _) = run(&b.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0);
    assert_eq!(out, reference, "the spreadsheet's numbers are the same data");
}

#[test]
fn a_bad_cell_exits_2_naming_file_row_and_column() {
    let text = "t_c,dp_pa,dp_ab_pa\n30,400000,-80000\n40,400000,70000\n50,400000,oops\n60,400000,230000\n";
    let path = temp_file("bad.csv", text.as_bytes());
    let p = path.to_string_lossy().into_owned();
    let (code, out, err) = run(&["calibrate", "--pressure-data", &p]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--pressure-data") && err.contains("bad.csv") && err.contains("row 3 (line 4)"),
        "{err}"
    );
    assert!(err.contains("column dp_ab_pa") && err.contains("'oops'"), "{err}");
    // A missing column, a physically impossible pressure, a short row.
    for (text, why) in [
        ("t_c,x_m\n30,0\n", "no column dp_pa"),
        (
            "t_c,dp_pa,dp_ab_pa\n30,400000,500000\n",
            "row 1 (line 2), column dp_ab_pa",
        ),
        ("t_c,dp_pa,dp_ab_pa\n30,-4,0\n", "row 1 (line 2), column dp_pa"),
        ("t_c,dp_pa,dp_ab_pa\n30,400000\n", "row 1 (line 2): 2 cells"),
        ("", "empty file"),
    ] {
        let path = temp_file("bad2.csv", text.as_bytes());
        let (code, _, err) = run(&["calibrate", "--pressure-data", &path.to_string_lossy()]);
        assert_eq!(code, 2, "{text:?}: {err}");
        assert!(err.contains(why), "{text:?}: {err}");
    }
    // A displacement in mm read as m; a drop the model cannot take.
    for (text, why) in [
        (
            "t_c,x_m\n30,0\n40,0.18\n50,4e-4\n60,6e-4\n",
            "data row 2, column x_m: 0.18 m is outside the plunger's travel",
        ),
        (
            "t_c,x_m,dp_pa\n30,0,400000\n40,1e-4,1e308\n50,4e-4,400000\n",
            "first at data row 2: 40 C, drop 1e308 Pa",
        ),
    ] {
        let path = temp_file("badx2.csv", text.as_bytes());
        let (code, _, err) = run(&[
            "calibrate",
            "--pressure-data",
            PRESSURE,
            "--displacement-data",
            &path.to_string_lossy(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(why), "{text:?}: {err}");
    }
    let path = temp_file("badx.csv", b"t_c,x_m\n30,0\n40,1e-4\n50,nan\n");
    let (code, _, err) = run(&[
        "calibrate",
        "--pressure-data",
        PRESSURE,
        "--displacement-data",
        &path.to_string_lossy(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("row 3 (line 4), column x_m") && err.contains("not a finite number"),
        "{err}"
    );
}

#[test]
fn hostile_spreadsheets_are_read_or_refused_in_one_line() {
    let text = std::fs::read_to_string(root().join(PRESSURE)).unwrap();
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).skip(1).collect();
    let (_, reference, _) = run(&["calibrate", "--pressure-data", PRESSURE]);
    // A text column (a spreadsheet's note) is ignored, as the docs say.
    let mut noted = String::from("t_c,dp_pa,note,dp_ab_pa\n");
    for r in &rows {
        let c: Vec<&str> = r.split(',').collect();
        noted.push_str(&format!("{},{},\"bench 2, run A\",{}\n", c[0], c[1], c[2]));
    }
    let path = temp_file("noted.csv", noted.as_bytes());
    let (code, out, err) = run(&["calibrate", "--pressure-data", &path.to_string_lossy()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, reference);
    // A drop of 1e308 Pa passes every cell check but overflows the residual
    // sum of squares: refused, not a fit with zero standard errors.
    let mut huge = String::from("t_c,dp_pa,dp_ab_pa\n");
    for (i, r) in rows.iter().enumerate() {
        huge.push_str(&if i == 3 {
            "50,1e308,0".to_string()
        } else {
            r.to_string()
        });
        huge.push('\n');
    }
    // A temperature the oil model cannot take is named by row; a wanted
    // column twice is ambiguous; a huge value is printed short.
    let hot = huge.replace("50,1e308,0", "5000,400000,0");
    let twice = text.replace("t_c,dp_pa,dp_ab_pa", "t_c,dp_pa,dp_pa");
    let out_of_range = huge.replace("50,1e308,0", "50,400000,1e308");
    for (name, text, why) in [
        ("huge.csv", huge.as_str(), "residual sum of squares overflows"),
        ("hot.csv", hot.as_str(), "data row 4, column t_c: 5000 C"),
        ("twice.csv", twice.as_str(), "column dp_pa appears twice"),
        (
            "range.csv",
            out_of_range.as_str(),
            "column dp_ab_pa: 1e308 Pa is not inside",
        ),
    ] {
        let path = temp_file(name, text.as_bytes());
        let (code, out, err) = run(&["calibrate", "--pressure-data", &path.to_string_lossy()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(out.is_empty(), "{name}: {out}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.contains(why) && err.len() < 400, "{name}: {err}");
    }
}

#[test]
fn as_many_points_as_parameters_is_refused() {
    // Three pressure points for three parameters: an exact fit, no noise estimate.
    let text = "t_c,dp_pa,dp_ab_pa\n30,400000,-80000\n50,400000,170000\n80,400000,300000\n";
    let path = temp_file("three.csv", text.as_bytes());
    let (code, out, err) = run(&["calibrate", "--pressure-data", &path.to_string_lossy()]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert!(
        err.contains("--pressure-data")
            && err.contains("3 points for 3 parameters")
            && err.contains("0 degrees of freedom"),
        "{err}"
    );
    // Two displacement points for the spring rate and the preload.
    let path = temp_file("two.csv", b"t_c,x_m\n50,5e-4\n80,9e-4\n");
    let (code, _, err) = run(&[
        "calibrate",
        "--pressure-data",
        PRESSURE,
        "--displacement-data",
        &path.to_string_lossy(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--displacement-data") && err.contains("plunger.spring_rate, plunger.preload"),
        "{err}"
    );
}

#[test]
fn one_temperature_cannot_separate_the_oil_from_the_throttle() {
    // Many drops at one temperature determine A(40 C) only: the viscosity
    // law and the capillary length are confounded (rank-deficient).
    let mut text = String::from("t_c,dp_pa,dp_ab_pa\n");
    for (dp, y) in [(4e5, 70000.0), (5e5, 110000.0), (6e5, 160000.0), (7e5, 205000.0)] {
        text.push_str(&format!("40,{dp},{y}\n"));
    }
    let path = temp_file("one-t.csv", text.as_bytes());
    let (code, _, err) = run(&["calibrate", "--pressure-data", &path.to_string_lossy()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("do not separate"), "{err}");
    assert!(
        err.contains("fluid.walther_b") && err.contains("laminar_throttle.length"),
        "{err}"
    );
}

#[test]
fn the_paper_fit_reports_its_uncertainty_and_warns_about_what_it_cannot_determine() {
    let preset = temp_file("preset.toml", b"");
    let svg = temp_file("fit.svg", b"");
    let (code, out, err) = run(&[
        "calibrate",
        "--write-preset",
        &preset.to_string_lossy(),
        "--plot",
        &svg.to_string_lossy(),
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<serde_json::Value> = serde_json::from_str(&out).unwrap();
    assert_eq!(rows.len(), 5);
    let get = |name: &str| rows.iter().find(|r| r["parameter"] == name).unwrap();
    let spring = get("plunger.spring_rate");
    assert_eq!(spring["dof"], 4);
    assert_eq!(get("fluid.walther_a")["dof"], 15);
    assert_eq!(get("fluid.walther_a")["corr_fluid.walther_a"], 1.0);
    let rel = spring["rel_std_error"].as_f64().unwrap();
    assert!(rel > 0.0 && rel < 0.1, "{spring}");
    // The digitised table's scatter: sqrt(RSS / 15) between 4 and 8 kPa.
    let s = get("fluid.walther_b")["residual_rms"].as_f64().unwrap();
    assert!((4e3..8e3).contains(&s), "{s}");
    assert!(
        err.contains("15 degrees of freedom") && err.contains("4 degrees of freedom"),
        "{err}"
    );
    assert!(err.contains("WARNING: plunger.preload"), "{err}");
    // The preset round-trips with the fitted values.
    let written = params_file::load(&preset).unwrap();
    assert!((written.core.spring_rate - spring["value"].as_f64().unwrap()).abs() < 1e-9 * written.core.spring_rate);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
}

// ---- synthetic data from known parameters ----

/// A standard normal deviate (Box-Muller).
fn normal(rng: &mut StdRng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Noise of the synthetic measurements: 3 kPa on p_b - p_a (a 0.1 %
/// full-scale transducer at 25 bar) and 5 um on the displacement.
const SIGMA_P: f64 = 3e3;
const SIGMA_X: f64 = 5e-6;

/// A random plausible design around the paper preset (oil of 10-40 cSt at
/// 40 C with Walther slope 4-6, capillary 0.6-1.6 times, spring 0.6-1.6
/// times, preload 5-50 um) and a random measurement plan (6-12 temperatures
/// in 20-90 C at 2-4 drops of 3-8 bar; 6-12 displacement temperatures),
/// with at least five displacement points off the stops.
fn design(rng: &mut StdRng) -> (compensator::RawParams, Vec<PressurePoint>, Vec<DisplacementPoint>) {
    let paper = params_file::parse(input::PAPER_PRESET).unwrap();
    loop {
        let mut truth = paper;
        let c = &mut truth.core;
        let nu40: f64 = rng.random_range(10.0..40.0);
        c.walther_b = rng.random_range(4.0..6.0);
        c.walther_a = (nu40 + 0.7).log10().log10() + c.walther_b * 313.15f64.log10();
        c.laminar_length *= rng.random_range(0.6..1.6);
        c.spring_rate *= rng.random_range(0.6..1.6);
        c.preload = rng.random_range(5e-6..5e-5);
        if truth.validate().is_err() {
            continue;
        }
        let temps = |rng: &mut StdRng| -> Vec<f64> {
            let n = rng.random_range(6..=12);
            (0..n).map(|_| rng.random_range(20.0..90.0)).collect()
        };
        let mut drops = vec![3e5, 4e5, 5e5, 6e5, 7e5, 8e5];
        let keep = rng.random_range(2..=4);
        while drops.len() > keep {
            let i = rng.random_range(0..drops.len());
            drops.remove(i);
        }
        let core = truth.core;
        let mut pressure = Vec::new();
        for t in temps(rng) {
            for &dp in &drops {
                let exact = calibration::pressure_residuals(
                    &core,
                    &[PressurePoint {
                        t_c: t,
                        dp_pa: dp,
                        dp_ab_pa: 0.0,
                    }],
                );
                let Some(exact) = exact else { continue };
                pressure.push(PressurePoint {
                    t_c: t,
                    dp_pa: dp,
                    dp_ab_pa: exact[0] + SIGMA_P * normal(rng),
                });
            }
        }
        let mut displacement = Vec::new();
        let mut free = 0;
        for t in temps(rng) {
            let Some(x) = calibration::model_displacement(&core, t, None) else {
                continue;
            };
            if x > 0.0 && x < core.stroke {
                free += 1;
            }
            displacement.push(DisplacementPoint {
                t_c: t,
                x_m: x + SIGMA_X * normal(rng),
                dp_pa: None,
            });
        }
        if free >= 5 {
            return (truth, pressure, displacement);
        }
    }
}

#[test]
fn synthetic_data_recover_the_parameters_within_their_reported_standard_errors() {
    // 24 random designs and measurement plans, each fitted from the
    // model example's values of the fitted fields: every estimate within
    // 3.5 of its standard errors, and the standard errors calibrated (the
    // RMS of the normalised errors over all 120 estimates near 1: a
    // too-small standard error shows as a large RMS, a too-large one as a
    // small RMS).
    let example = params_file::parse(input::MODEL_EXAMPLE).unwrap();
    let mut z_all = Vec::new();
    for seed in 0..24u64 {
        let mut rng = StdRng::seed_from_u64(0x5eed_0000 + seed);
        let (truth, pressure, displacement) = design(&mut rng);
        let mut base = truth;
        base.core.walther_a = example.core.walther_a;
        base.core.walther_b = example.core.walther_b;
        base.core.laminar_length = example.core.laminar_length;
        base.core.spring_rate = example.core.spring_rate;
        base.core.preload = example.core.preload;
        let cal =
            calibration::fit(&base, &pressure, Some(&displacement)).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let t = truth.core;
        let want = [t.walther_a, t.walther_b, t.laminar_length, t.spring_rate, t.preload];
        for (e, want) in cal.estimates.iter().zip(want) {
            // Normalised error in the fit's own coordinates, where the
            // linearisation behind the standard error is made: the
            // capillary length as log10 G (relative error), the spring as
            // its compliance A_p / c, the others as they are.
            let z = match e.path {
                "laminar_throttle.length" => (e.value / want).ln() / (e.std_error / e.value),
                "plunger.spring_rate" => (1.0 / e.value - 1.0 / want) / (e.std_error / (e.value * e.value)),
                _ => (e.value - want) / e.std_error,
            };
            assert!(
                z.abs() <= 3.5,
                "seed {seed}: {} = {} +- {}, true {want} (z = {z:.2})",
                e.path,
                e.value,
                e.std_error
            );
            z_all.push(z);
        }
    }
    let rms = (z_all.iter().map(|z| z * z).sum::<f64>() / z_all.len() as f64).sqrt();
    let within2 = z_all.iter().filter(|z| z.abs() <= 2.0).count() as f64 / z_all.len() as f64;
    let worst = z_all.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    eprintln!(
        "normalised errors: RMS {rms:.3}, {:.1} % within 2 standard errors, largest {worst:.2}",
        100.0 * within2
    );
    assert!((0.7..=1.3).contains(&rms), "RMS of normalised errors {rms}");
    assert!(within2 >= 0.88, "{within2}");
}
