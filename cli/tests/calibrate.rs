//! `calibrate`: spreadsheet CSV accepted, bad data refused naming row and
//! column, fits the data cannot determine refused, the reported standard
//! errors honest on synthetic data from known parameters, and the
//! calibrated file's `[tolerances]` and `[[correlation]]` the fit's
//! covariance (checked against one computed here from finite-difference
//! Jacobians in the file's own fields).

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
            "row 2 (line 3), column dp_pa: 1e308 Pa is not a plausible inlet-outlet pressure drop",
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
    // A drop of 1e308 Pa is no drop a compensator sees: refused by the
    // data's plausible range before it could overflow the fit.
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
        (
            "huge.csv",
            huge.as_str(),
            "row 4 (line 5), column dp_pa: 1e308 Pa is not a plausible",
        ),
        (
            "hot.csv",
            hot.as_str(),
            "row 4 (line 5), column t_c: 5000 C is not a plausible oil temperature",
        ),
        ("twice.csv", twice.as_str(), "column dp_pa appears twice"),
        (
            "range.csv",
            out_of_range.as_str(),
            "column dp_ab_pa: 1e308 Pa is not a plausible chamber pressure difference",
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

// ---- the tolerances written into the calibrated file ----

use compensator::RawParams;
use compensator::params::RawCore;
use nalgebra::DMatrix;

/// The fitted fields, in the fit's order.
const FITTED: [&str; 5] = [
    "fluid.walther_a",
    "fluid.walther_b",
    "laminar_throttle.length",
    "plunger.spring_rate",
    "plunger.preload",
];

/// `core` with the fitted fields `FITTED[..n]` set to `theta`.
fn with(core: &RawCore, fields: &[&str], theta: &[f64]) -> RawCore {
    let mut c = *core;
    for (f, v) in fields.iter().zip(theta) {
        *c.value_mut(f).unwrap() = *v;
    }
    c
}

/// Central-difference Jacobian (n x p) of `r` over the file's fields
/// `fields` at `core`, steps 1e-6 of each value.
fn jacobian(core: &RawCore, fields: &[&str], r: &dyn Fn(&RawCore) -> Vec<f64>) -> DMatrix<f64> {
    let theta: Vec<f64> = fields.iter().map(|f| core.value(f).unwrap()).collect();
    let n = r(core).len();
    let mut j = DMatrix::zeros(n, fields.len());
    for k in 0..fields.len() {
        let h = 1e-6 * theta[k].abs();
        let (mut up, mut down) = (theta.clone(), theta.clone());
        up[k] += h;
        down[k] -= h;
        let (ru, rd) = (r(&with(core, fields, &up)), r(&with(core, fields, &down)));
        for i in 0..n {
            j[(i, k)] = (ru[i] - rd[i]) / (2.0 * h);
        }
    }
    j
}

/// The two-step fit's covariance of the five fitted fields at `core` (the
/// optimum), from scratch in the file's fields: `C1 = s1^2 (J1^T J1)^-1`
/// for the pressure stage, `C2 = s2^2 (J2^T J2)^-1 + M C1 M^T` with `M =
/// -(J2^T J2)^-1 J2^T J21` for the displacement stage, `C21 = M C1`.
fn covariance_from_scratch(core: &RawCore, p: &[PressurePoint], d: &[DisplacementPoint]) -> DMatrix<f64> {
    let r1 = |c: &RawCore| calibration::pressure_residuals(c, p).unwrap();
    let r2 = |c: &RawCore| calibration::displacement_residuals(c, d).unwrap();
    let s2 = |r: &[f64], k: usize| r.iter().map(|v| v * v).sum::<f64>() / (r.len() - k) as f64;
    let j1 = jacobian(core, &FITTED[..3], &r1);
    let c1 = (j1.transpose() * &j1).try_inverse().unwrap() * s2(&r1(core), 3);
    let j2 = jacobian(core, &FITTED[3..], &r2);
    let j21 = jacobian(core, &FITTED[..3], &r2);
    let inv = (j2.transpose() * &j2).try_inverse().unwrap();
    let m = -(&inv * j2.transpose() * &j21);
    let c22 = &inv * s2(&r2(core), 2) + &m * &c1 * m.transpose();
    let c21 = &m * &c1;
    let mut c = DMatrix::zeros(5, 5);
    c.view_mut((0, 0), (3, 3)).copy_from(&c1);
    c.view_mut((3, 3), (2, 2)).copy_from(&c22);
    c.view_mut((3, 0), (2, 3)).copy_from(&c21);
    c.view_mut((0, 3), (3, 2)).copy_from(&c21.transpose());
    c
}

/// The written covariance of the fitted fields: `u_i r_ij u_j` from the
/// file's tolerances and correlations (1 on the diagonal, 0 undeclared).
fn written_covariance(raw: &RawParams) -> DMatrix<f64> {
    let t = &raw.tolerances;
    DMatrix::from_fn(5, 5, |i, j| {
        t.get(FITTED[i]).unwrap() * t.correlation(FITTED[i], FITTED[j]) * t.get(FITTED[j]).unwrap()
    })
}

/// `a` and `b` agree: standard deviations within `rel` relative,
/// correlations within `abs` (entries with |r| <= the write threshold may
/// be left out of the file, so they compare against 0 within it).
fn assert_same_covariance(a: &DMatrix<f64>, b: &DMatrix<f64>, rel: f64, abs: f64, what: &str) {
    for i in 0..5 {
        let (sa, sb) = (a[(i, i)].sqrt(), b[(i, i)].sqrt());
        assert!((sa - sb).abs() <= rel * sb, "{what}: {}: {sa:e} vs {sb:e}", FITTED[i]);
        for j in 0..5 {
            let ra = a[(i, j)] / (a[(i, i)] * a[(j, j)]).sqrt();
            let rb = b[(i, j)] / (b[(i, i)] * b[(j, j)]).sqrt();
            let slack = if rb.abs() <= calibration::CORR_WRITE_MIN {
                calibration::CORR_WRITE_MIN
            } else {
                0.0
            };
            assert!(
                (ra - rb).abs() <= abs + slack,
                "{what}: r({}, {}) = {ra} vs {rb}",
                FITTED[i],
                FITTED[j]
            );
        }
    }
}

/// Writes pressure and displacement data as the CSV files calibrate reads.
fn data_files(tag: &str, p: &[PressurePoint], d: &[DisplacementPoint]) -> (PathBuf, PathBuf) {
    let mut pt = String::from("t_c,dp_pa,dp_ab_pa\n");
    for q in p {
        pt.push_str(&format!("{:?},{:?},{:?}\n", q.t_c, q.dp_pa, q.dp_ab_pa));
    }
    let mut dt = String::from("t_c,x_m\n");
    for q in d {
        dt.push_str(&format!("{:?},{:?}\n", q.t_c, q.x_m));
    }
    (
        temp_file(&format!("{tag}-p.csv"), pt.as_bytes()),
        temp_file(&format!("{tag}-x.csv"), dt.as_bytes()),
    )
}

/// Runs `calibrate --params base --pressure-data ... --displacement-data
/// ... --write-preset` and reads the written file back.
fn calibrate_to_file(
    tag: &str,
    base: &std::path::Path,
    p: &std::path::Path,
    d: &std::path::Path,
) -> (RawParams, String) {
    let out = temp_file(&format!("{tag}-out.toml"), b"");
    let (code, _, err) = run(&[
        "calibrate",
        "--params",
        &base.to_string_lossy(),
        "--pressure-data",
        &p.to_string_lossy(),
        "--displacement-data",
        &d.to_string_lossy(),
        "--write-preset",
        &out.to_string_lossy(),
    ]);
    assert_eq!(code, 0, "{err}");
    (params_file::load(&out).unwrap_or_else(|e| panic!("{e}")), err)
}

/// The paper preset's design measured well: 8 temperatures at 3 drops
/// with 300 Pa of noise, 13 displacements with 1 um: every fitted field
/// determined within a third of its value.
fn well_measured() -> (RawParams, Vec<PressurePoint>, Vec<DisplacementPoint>) {
    let truth = params_file::parse(input::PAPER_PRESET).unwrap();
    let mut rng = StdRng::seed_from_u64(0x7013);
    let mut p = Vec::new();
    for t in (2..=9).map(|k| 10.0 * k as f64) {
        for dp in [3e5, 5e5, 7e5] {
            let y = calibration::pressure_residuals(
                &truth.core,
                &[PressurePoint {
                    t_c: t,
                    dp_pa: dp,
                    dp_ab_pa: 0.0,
                }],
            )
            .unwrap()[0];
            p.push(PressurePoint {
                t_c: t,
                dp_pa: dp,
                dp_ab_pa: y + 300.0 * normal(&mut rng),
            });
        }
    }
    let d = (0..13)
        .map(|k| {
            let t = 25.0 + 4.0 * k as f64;
            let x = calibration::model_displacement(&truth.core, t, None).unwrap();
            DisplacementPoint {
                t_c: t,
                x_m: x + 1e-6 * normal(&mut rng),
                dp_pa: None,
            }
        })
        .collect();
    (truth, p, d)
}

#[test]
fn the_written_tolerances_are_the_fits_covariance() {
    // Base: the model example (its prior tolerances); data from the paper
    // design, well measured, so that every fitted field is determined.
    let (_, p, d) = well_measured();
    let (pf, df) = data_files("cov", &p, &d);
    let (written, err) = calibrate_to_file("cov", &root().join("presets/model-example.toml"), &pf, &df);
    assert!(!err.contains("its tolerance is the base file's"), "{err}");
    let scratch = covariance_from_scratch(&written.core, &p, &d);
    // Finite differences of 1e-6 (here and in the fit, in other
    // coordinates): agreement to 1e-4 of each standard deviation.
    assert_same_covariance(&written_covariance(&written), &scratch, 1e-4, 1e-4, "well measured");
    // Every fitted field within a third of its value: none held.
    for (i, f) in FITTED.iter().enumerate() {
        assert!(
            scratch[(i, i)].sqrt() < written.core.value(f).unwrap().abs() / 3.0,
            "{f}"
        );
    }
    // The other fields' tolerances are the base file's, unchanged.
    let base = params_file::parse(input::MODEL_EXAMPLE).unwrap();
    for f in compensator::params::CORE_FIELDS
        .iter()
        .filter(|f| !FITTED.contains(&f.path))
    {
        assert_eq!(
            written.tolerances.get(f.path),
            base.tolerances.get(f.path),
            "{}",
            f.path
        );
    }
}

#[test]
fn the_calibrated_file_round_trips_and_its_correlation_matrix_is_positive_semi_definite() {
    let (_, p, d) = well_measured();
    let (pf, df) = data_files("rt", &p, &d);
    let (written, _) = calibrate_to_file("rt", &root().join("presets/model-example.toml"), &pf, &df);
    let again = params_file::parse(&params_file::to_toml(&written)).unwrap();
    assert_eq!(again, written, "parse(to_toml(file)) is the file");
    // Only pairs beyond the threshold, each once.
    for c in written.tolerances.correlations() {
        assert!(c.coefficient.abs() > calibration::CORR_WRITE_MIN, "{c:?}");
    }
    // Eigenvalues of the written correlation matrix (nalgebra's symmetric
    // eigensolver, not the reader's Cholesky).
    let cov = written_covariance(&written);
    let corr = compensator_cli::lsq::correlation(&cov);
    let min = corr.symmetric_eigen().eigenvalues.min();
    assert!(min > -1e-9, "smallest eigenvalue {min}");
    // The paper fit, whose matrix is nearly singular (walther_a and
    // walther_b correlated +0.99998), read back too.
    let out = temp_file("paper-rt.toml", b"");
    let (code, _, err) = run(&["calibrate", "--write-preset", &out.to_string_lossy()]);
    assert_eq!(code, 0, "{err}");
    let paper = params_file::load(&out).unwrap();
    let corr = compensator_cli::lsq::correlation(&written_covariance(&paper));
    assert!(corr.symmetric_eigen().eigenvalues.min() > -1e-9);
    assert_eq!(params_file::parse(&params_file::to_toml(&paper)).unwrap(), paper);
}

#[test]
fn a_field_the_data_do_not_determine_takes_the_base_files_tolerance() {
    // The paper's tables: the capillary length (53 %) and the preload
    // (118 %) are not determined; their tolerances are the model
    // example's, and the others' covariance the fit's conditioned on them.
    let base = params_file::parse(input::MODEL_EXAMPLE).unwrap();
    let p = calibration::read_pressure(input::PAPER_PRESSURE_CSV).unwrap();
    let d = calibration::read_displacement(input::PAPER_DISPLACEMENT_CSV).unwrap();
    let cal = calibration::fit(&base, &p, Some(&d)).unwrap();
    let full = covariance_from_scratch(&cal.params.core, &p, &d);
    assert_same_covariance(&cal.covariance, &full, 1e-3, 1e-4, "paper fit");
    let w = cal.written(&base).unwrap();
    // What the library returns is what a file holds, read back.
    let mut file = cal.params;
    file.tolerances = w.tolerances;
    assert_eq!(params_file::parse(&params_file::to_toml(&file)).unwrap(), file);
    let held: Vec<&str> = w.held.iter().map(|h| h.path).collect();
    assert_eq!(held, ["laminar_throttle.length", "plunger.preload"]);
    // Conditioning by hand: free f = (a, b, k), held h = (L, x0).
    let (f, h) = ([0usize, 1, 3], [2usize, 4]);
    let sub = |r: &[usize], c: &[usize]| DMatrix::from_fn(r.len(), c.len(), |i, j| full[(r[i], c[j])]);
    let u = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![5.8e-5f64.powi(2), 2.9e-6f64.powi(2)]));
    let m = sub(&f, &h) * sub(&h, &h).try_inverse().unwrap();
    let c_ff = sub(&f, &f) - &m * sub(&h, &f) + &m * &u * m.transpose();
    let c_fh = &m * &u;
    let mut want = DMatrix::zeros(5, 5);
    for (a, &i) in f.iter().enumerate() {
        for (b, &j) in f.iter().enumerate() {
            want[(i, j)] = c_ff[(a, b)];
        }
        for (b, &j) in h.iter().enumerate() {
            want[(i, j)] = c_fh[(a, b)];
            want[(j, i)] = c_fh[(a, b)];
        }
    }
    for (a, &i) in h.iter().enumerate() {
        want[(i, i)] = u[(a, a)];
    }
    let mut raw = cal.params;
    raw.tolerances = w.tolerances;
    assert_same_covariance(&written_covariance(&raw), &want, 1e-3, 1e-3, "held");
    assert_eq!(raw.tolerances.get("laminar_throttle.length"), Some(5.8e-5));
    assert_eq!(raw.tolerances.get("plunger.preload"), Some(2.9e-6));
    // Every written tolerance is one a file holds.
    raw.validate().unwrap();
    for (i, f) in FITTED.iter().enumerate() {
        let u = raw.tolerances.get(f).unwrap();
        assert!(u > 0.0 && u <= cal.estimates[i].value.abs() / 3.0, "{f}: {u}");
    }
    // The data place the length 0.07 of its standard error from the base's
    // 25 mm: the update the file implies would move no output by more.
    assert!(w.held[0].shift < 0.1, "{:?}", w.held[0]);
}

#[test]
fn a_field_the_data_do_not_determine_without_a_base_tolerance_is_refused_naming_it() {
    // The model example without its preload tolerance: the paper's tables
    // do not determine the preload, and the file would claim it exact.
    let text = input::MODEL_EXAMPLE.replace("plunger.preload = 2.9e-6", "");
    let base = temp_file("no-preload-tolerance.toml", text.as_bytes());
    let out = temp_file("refused.toml", b"untouched");
    let (code, _, err) = run(&[
        "calibrate",
        "--params",
        &base.to_string_lossy(),
        "--write-preset",
        &out.to_string_lossy(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("plunger.preload") && err.contains("do not determine it") && err.contains("gives it no tolerance"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "untouched");
    // Without --write-preset the fit is reported as before.
    let (code, _, err) = run(&["calibrate", "--params", &base.to_string_lossy()]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_calibrated_file_reports_a_narrower_band_than_its_prior() {
    // The fitted fields' contributions alone (every other tolerance
    // zero), the paper preset's values: the model example's tolerances
    // (the prior) against the calibrated file's, at every temperature of
    // the uncertainty table's grid inside the validated range.
    let out = temp_file("band.toml", b"");
    let (code, _, err) = run(&["calibrate", "--write-preset", &out.to_string_lossy()]);
    assert_eq!(code, 0, "{err}");
    let after = params_file::load(&out).unwrap();
    let prior = params_file::parse(input::MODEL_EXAMPLE).unwrap();
    let only_fitted = |tol: &compensator::params::RawTolerances| {
        let mut raw = after;
        raw.tolerances = compensator::params::RawTolerances::NONE;
        for f in FITTED {
            *raw.tolerances.get_mut(f).unwrap() = tol.get(f).unwrap();
        }
        for c in tol
            .correlations()
            .iter()
            .filter(|c| FITTED.contains(&c.a) && FITTED.contains(&c.b))
        {
            raw.tolerances.push_correlation(c.a, c.b, c.coefficient).unwrap();
        }
        raw
    };
    let table = |raw: &RawParams| *compensator::estimator::EstimatorConfig::new(raw).unwrap().table();
    let (before, calibrated) = (
        table(&only_fitted(&prior.tolerances)),
        table(&only_fitted(&after.tolerances)),
    );
    let e = &after.estimator;
    let mut checked = 0;
    for k in 0..before.sd_params.len() {
        let t = f64::from(before.t0) + f64::from(before.step) * k as f64;
        if t < e.valid_min || t > e.valid_max {
            continue;
        }
        for (o, name) in [(0, "x"), (1, "p_a"), (3, "q_total")] {
            let (b, a) = (before.sd_params[k][o], calibrated.sd_params[k][o]);
            assert!(
                a.is_finite() && a > 0.0 && a < 0.8 * b,
                "{name} at {t:.1} C: {a:e} after, {b:e} before"
            );
        }
        checked += 1;
    }
    assert!(checked >= 3, "{checked} grid temperatures in the validated range");
}
