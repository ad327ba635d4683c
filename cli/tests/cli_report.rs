//! `report` (the paper's tables and figures as files) and `--plot FILE.png`.

mod common;
use common::{column, csv, run, run_in, temp_dir};

/// Width and height of a PNG from its IHDR chunk, if `bytes` is a PNG.
fn png_size(bytes: &[u8]) -> Option<(u32, u32)> {
    if bytes.len() < 24 || &bytes[..8] != b"\x89PNG\r\n\x1a\n" || &bytes[12..16] != b"IHDR" {
        return None;
    }
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    Some((be(16), be(20)))
}

#[test]
fn plot_png_writes_a_bitmap_and_leaves_the_csv() {
    let dir = temp_dir("png");
    let file = dir.join("eq.png");
    let args = ["equilibrium", "--params", "presets/paper.toml", "--units", "eng"];
    let (code, out, err) = run(&[&args[..], &["--plot", file.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    let (_, plain, _) = run(&args);
    assert_eq!(out, plain);
    let bytes = std::fs::read(&file).unwrap();
    // Three panels of 300 px under a 40 px title, 900 px wide.
    assert_eq!(png_size(&bytes), Some((900, 940)));
    // Text and curves make a compressed bitmap far larger than a blank one
    // (a few kB).
    assert!(bytes.len() > 15_000, "{} bytes", bytes.len());
    // Upper-case extension too; the step figure with its overlay.
    let file = dir.join("STEP.PNG");
    let (code, _, err) = run(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "40",
        "--to",
        "50",
        "--t-end",
        "0.05",
        "--plot",
        file.to_str().unwrap(),
        "--overlay-reference",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(png_size(&std::fs::read(&file).unwrap()).is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

const FIGURES: [&str; 6] = [
    "fig2_pressure_difference",
    "fig3_displacement",
    "fig4_step_responses",
    "fig5_normalised_responses",
    "eigenvalues",
    "compensation",
];

#[test]
fn report_writes_tables_figures_and_a_summary_from_any_directory() {
    let dir = temp_dir("report");
    let out_dir = dir.join("out");
    let elsewhere = temp_dir("report-cwd");
    let (code, listing, err) = run_in(
        &elsewhere,
        &["report", "--dir", out_dir.to_str().unwrap(), "--png", "--units", "eng"],
        b"",
    );
    assert_eq!(code, 0, "{err}");
    let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    for name in FIGURES {
        for ext in ["svg", "png"] {
            let file = format!("{name}.{ext}");
            let path = out_dir.join(&file);
            assert!(listing.contains(path.to_str().unwrap()), "{listing}");
            assert!(md.contains(&format!("]({file})")), "report.md does not link {file}");
            let bytes = std::fs::read(&path).unwrap();
            if ext == "png" {
                assert!(png_size(&bytes).is_some(), "{file}");
            } else {
                let svg = String::from_utf8(bytes).unwrap();
                assert!(svg.contains("temperature [C]") || svg.contains("time [ms]"), "{file}");
            }
        }
    }
    let svg = |name: &str| std::fs::read_to_string(out_dir.join(format!("{name}.svg"))).unwrap();
    assert!(svg("fig2_pressure_difference").contains("p_b - p_a [bar]"));
    assert!(svg("fig2_pressure_difference").contains("paper Table 1"));
    assert!(svg("fig3_displacement").contains("x [mm]"));
    assert!(svg("fig5_normalised_responses").contains("settling band"));

    // Table 1: the paper's column is data/paper/table1.csv, the model's is
    // the paper value plus the residual whose RMS `paper` prints.
    let t1 = std::fs::read_to_string(out_dir.join("table1.csv")).unwrap();
    let paper = column(&t1, "paper_dp_ab_bar");
    let model = column(&t1, "model_dp_ab_bar");
    assert_eq!(paper.len(), 18);
    let data = std::fs::read_to_string(common::root().join("data/paper/table1.csv")).unwrap();
    let (_, rows) = csv(&data);
    let published: Vec<f64> = rows
        .iter()
        .flat_map(|r| r[1..].iter().map(|c| c.parse::<f64>().unwrap()))
        .collect();
    for (a, b) in paper.iter().zip(&published) {
        assert!((a - b).abs() < 1e-12, "{a} {b}");
    }
    let rms = (paper.iter().zip(&model).map(|(p, m)| (m - p).powi(2)).sum::<f64>() / 18.0).sqrt();
    let (code, text, _) = run(&["paper"]);
    assert_eq!(code, 0);
    let line = text
        .lines()
        .find(|l| l.starts_with("RMS") && l.contains("bar"))
        .unwrap();
    assert!(line.starts_with(&format!("RMS {rms:.4} bar")), "{line} vs {rms}");
    assert!(md.contains(&format!("RMS residual {rms:.4} bar")), "{md}");

    // Table 3: the model's columns are `indicators` at its defaults.
    let t3 = std::fs::read_to_string(out_dir.join("table3.csv")).unwrap();
    let (code, ind, _) = run(&["indicators", "--params", "presets/paper.toml"]);
    assert_eq!(code, 0);
    assert_eq!(column(&t3, "model_settling_time_s"), column(&ind, "settling_time_s"));
    assert_eq!(column(&t3, "model_dominant_re"), column(&ind, "dominant_re"));
    let x_star: Vec<f64> = column(&ind, "x_star_m").iter().map(|x| x * 1e3).collect();
    for (a, b) in column(&t3, "model_x_star_mm").iter().zip(&x_star) {
        assert!((a - b).abs() <= 1e-12 * b.abs());
    }

    // Without --png, no PNG; in SI the columns are SI.
    let si_dir = dir.join("si");
    let (code, _, err) = run(&["report", "--dir", si_dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(!si_dir.join("eigenvalues.png").exists());
    let t1 = std::fs::read_to_string(si_dir.join("table1.csv")).unwrap();
    assert!(
        t1.starts_with("t_c,dp_pa,paper_dp_ab_pa,model_dp_ab_pa,residual_pa,error\n"),
        "{t1}"
    );

    // An output folder that cannot be made: bad input naming --dir.
    let (code, _, err) = run(&["report", "--dir", "/proc/no/such"]);
    assert_eq!(code, 2);
    assert!(err.contains("--dir"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&elsewhere);
}
