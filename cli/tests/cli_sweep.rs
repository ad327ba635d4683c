//! `sweep`: grids and tolerance draws of named parameters, each variant's
//! metrics against the single commands run on the same design, bad names
//! and implausible values, and output independent of the thread count.

mod common;
use common::{column, csv, paper_preset, root, run, run_env, run_in};

const P: &str = "presets/paper.toml";

/// Parameter-file `text` with `key = value` replaced in `[section]`.
fn with(text: &str, section: &str, key: &str, value: f64) -> String {
    let mut out = String::new();
    let mut current = String::new();
    let mut replaced = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            current = t.trim_matches(|c| c == '[' || c == ']').to_string();
        }
        if current == section && t.split('=').next().map(str::trim) == Some(key) {
            out.push_str(&format!("{key} = {value:e}\n"));
            replaced = true;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(replaced, "{section}.{key} not in the preset");
    out
}

#[test]
fn a_grid_row_is_what_the_single_commands_compute_for_that_design() {
    let (code, out, err) = run(&[
        "sweep",
        "--params",
        P,
        "--set",
        "plunger.spring_rate=20e3:30e3:3",
        "--set",
        "plunger.mass=0.01,0.03",
        "--temps",
        "40,70",
    ]);
    assert_eq!(code, 0, "{err}");
    let (header, rows) = csv(&out);
    assert_eq!(
        header,
        [
            "variant",
            "plunger.spring_rate",
            "plunger.mass",
            "x_40c_m",
            "x_70c_m",
            "monotonic",
            "min_dx_dt_m_k",
            "dominant_re",
            "settling_time_s",
            "comp_error_rms_m3s",
            "error"
        ]
    );
    assert_eq!(rows.len(), 6);
    assert_eq!(
        column(&out, "plunger.spring_rate"),
        [20e3, 20e3, 25e3, 25e3, 30e3, 30e3]
    );
    assert_eq!(column(&out, "plunger.mass"), [0.01, 0.03, 0.01, 0.03, 0.01, 0.03]);
    // Variant 4 (spring 30e3, mass 0.01) through the single commands.
    let text = with(&paper_preset(), "plunger", "spring_rate", 30e3);
    let text = with(&text, "plunger", "mass", 0.01);
    let here = root();
    let (code, eq, err) = run_in(
        &here,
        &["equilibrium", "--params", "-", "--temps", "40,70"],
        text.as_bytes(),
    );
    assert_eq!(code, 0, "{err}");
    let row = &rows[4];
    assert_eq!(row[3].parse::<f64>().unwrap(), column(&eq, "x_m")[0]);
    assert_eq!(row[4].parse::<f64>().unwrap(), column(&eq, "x_m")[1]);
    let (_, ind, _) = run_in(
        &here,
        &["indicators", "--params", "-", "--steps", "40:50", "--t-end", "0.2"],
        text.as_bytes(),
    );
    assert_eq!(row[7].parse::<f64>().unwrap(), column(&ind, "dominant_re")[0]);
    // The settling time from the f64 twin is the reference solver's (what
    // `indicators` runs) to a sample here; with --reference it is the
    // reference's itself.
    let settling = row[8].parse::<f64>().unwrap();
    let reference = column(&ind, "settling_time_s")[0];
    assert!((settling - reference).abs() <= 1.5e-4, "{settling} vs {reference}");
    let (code, checked, err) = run(&[
        "sweep",
        "--params",
        P,
        "--set",
        "plunger.spring_rate=20e3:30e3:3",
        "--set",
        "plunger.mass=0.01,0.03",
        "--temps",
        "40,70",
        "--reference",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(column(&checked, "settling_time_s")[4], reference);
    assert_eq!(column(&checked, "dominant_re"), column(&out, "dominant_re"));
    // Compensation error RMS over the validated range (26-78 C) at 1 C.
    let (_, comp, _) = run_in(
        &here,
        &["compensation", "--params", "-", "--temps", "26:78:1"],
        text.as_bytes(),
    );
    let e = column(&comp, "error_m3s");
    let rms = (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt();
    let got: f64 = row[9].parse().unwrap();
    assert!((got - rms).abs() <= 1e-12 * rms, "{got} vs {rms}");
    // Eq. (32): the sensitivity over the range never changes sign, and the
    // smallest |dx/dt| is no larger than any sampled one.
    assert_eq!(row[5], "true");
    let (_, sens, _) = run_in(
        &here,
        &["sensitivity", "--params", "-", "--temps", "26:78:2"],
        text.as_bytes(),
    );
    let min_sampled = column(&sens, "dx_dt_branch_m_k")
        .iter()
        .fold(f64::INFINITY, |m, v| m.min(v.abs()));
    let worst: f64 = row[6].parse().unwrap();
    assert!(
        worst > 0.0 && worst <= min_sampled * (1.0 + 1e-12),
        "{worst} vs {min_sampled}"
    );
}

#[test]
fn tolerance_draws_stay_in_their_band_and_repeat_with_the_seed() {
    let args = [
        "sweep",
        "--params",
        P,
        "--vary",
        "plunger.diameter=1%",
        "--vary",
        "slot.diameter=1e-5",
        "--samples",
        "40",
        "--seed",
        "7",
        "--t-end",
        "0.1",
    ];
    let (code, a, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    let raw = compensator_cli::params_file::parse(&paper_preset()).unwrap();
    let d = column(&a, "plunger.diameter");
    let s = column(&a, "slot.diameter");
    assert_eq!(d.len(), 40);
    let nominal = raw.core.plunger_diameter;
    assert!(
        d.iter().all(|v| (v - nominal).abs() <= 0.01 * nominal * (1.0 + 1e-12)),
        "{d:?}"
    );
    assert!(
        s.iter()
            .all(|v| (v - raw.core.slot_diameter).abs() <= 1e-5 * (1.0 + 1e-9))
    );
    // The draws spread over the band (not one value, not a corner).
    let lo = d.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = d.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(hi - lo > 0.01 * nominal, "{lo}..{hi}");
    let (_, again, _) = run(&args);
    assert_eq!(a, again);
    let mut other = args.to_vec();
    other[10] = "8";
    let (_, b, _) = run(&other);
    assert_ne!(a, b);
}

#[test]
fn the_output_does_not_depend_on_the_thread_count() {
    let args = [
        "sweep",
        "--params",
        P,
        "--set",
        "plunger.spring_rate=15e3:35e3:3",
        "--vary",
        "plunger.diameter=2%",
        "--samples",
        "6",
        "--t-end",
        "0.1",
    ];
    let (code, one, err) = run_env(&args, &[("RAYON_NUM_THREADS", "1")]);
    assert_eq!(code, 0, "{err}");
    let (code, two, err) = run_env(&args, &[("RAYON_NUM_THREADS", "2")]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(one, two);
    assert_eq!(one.lines().count(), 1 + 18);
}

#[test]
fn unknown_names_are_bad_input_and_implausible_values_are_rows_with_an_error() {
    for (flag, arg) in [
        ("--set", "plunger.sprng_rate=1:2:2"),
        ("--vary", "plunger.diametre=1%"),
        ("--set", "spring_rate=1,2"),
    ] {
        let (code, out, err) = run(&["sweep", "--params", P, flag, arg]);
        assert_eq!(code, 2, "{arg}: {err}");
        assert!(out.is_empty());
        let name = arg.split('=').next().unwrap();
        assert!(err.contains(name) && err.contains(flag), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    for bad in [
        &["--set", "plunger.mass=1:2:0"][..],
        &["--set", "plunger.mass=x"][..],
        &["--vary", "plunger.mass=-1%"][..],
        &["--samples", "5"][..],
        &["--step", "40:50,50:60"][..],
        // Draws alone beyond the variant bound were not checked and ran for hours.
        &["--vary", "plunger.mass=5%", "--samples", "100000000000"][..],
        &["--set", "plunger.mass=1:2:100000", "--set", "plunger.stroke=1:2:100001"][..],
        // One axis is held in memory: at most 1e6 values.
        &["--set", "plunger.mass=1:2:1000001"][..],
    ] {
        let (code, out, err) = run(&[&["sweep", "--params", P][..], bad].concat());
        assert_eq!(code, 2, "{bad:?}: {err}");
        assert!(out.is_empty());
    }
    // The plunger mass's plausible range starts at 1e-6 kg: the first
    // variant is refused naming the field, the second computed.
    let (code, out, err) = run(&[
        "sweep",
        "--params",
        P,
        "--set",
        "plunger.mass=1e-9,0.02",
        "--t-end",
        "0.1",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("1 of 2 rows"), "{err}");
    let (header, rows) = csv(&out);
    assert_eq!(header.last().unwrap(), "error");
    assert!(rows[0].last().unwrap().contains("plunger.mass"), "{out}");
    assert_eq!(rows[0][1], "0.000000001");
    assert!(rows[1].last().unwrap().is_empty());
    // A tolerance that draws across the range's edge: only those rows fail.
    let (code, out, _) = run(&[
        "sweep",
        "--params",
        P,
        "--vary",
        "slot.discharge_coefficient=0.5",
        "--samples",
        "30",
        "--t-end",
        "0.1",
    ]);
    assert_eq!(code, 1);
    let eta = column(&out, "slot.discharge_coefficient");
    let (_, rows) = csv(&out);
    for (v, row) in eta.iter().zip(&rows) {
        let failed = !row.last().unwrap().is_empty();
        assert_eq!(failed, !(0.1..=1.0).contains(v), "{v}: {row:?}");
    }
}
