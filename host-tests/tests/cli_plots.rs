//! `--plot FILE.svg` (docs/plots.md): each command that draws writes an SVG
//! with its axis quantities and legend names (here in `--units eng`: mm,
//! bar, L/min), leaves its CSV output as it was, and refuses a file that is
//! neither `.svg` nor `.png` naming `--plot` (status 2). PNG figures and
//! SI axes: `cli/tests/cli_report.rs`.

use host_tests::run_cli;
use std::path::PathBuf;

/// A fresh folder for this test's figures.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli_plots_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `args --units eng` with `--plot DIR/name.svg`; checks the CSV is
/// the one without `--plot`, the file is an SVG and shows every string of
/// `shows`.
fn plots(name: &str, args: &[&str], shows: &[&str]) {
    let dir = temp_dir(name);
    let file = dir.join(format!("{name}.svg"));
    let file_arg = file.to_str().unwrap();
    let mut args = args.to_vec();
    args.extend(["--units", "eng"]);
    let args = &args[..];
    let mut with_plot = args.to_vec();
    with_plot.extend(["--plot", file_arg]);
    let (code, out, err) = run_cli(&with_plot);
    assert_eq!(code, 0, "{name}: {err}");
    // The same run without the figure (an overlay needs one).
    let plain_args: Vec<&str> = args.iter().copied().filter(|a| *a != "--overlay-reference").collect();
    let (code, plain, _) = run_cli(&plain_args);
    assert_eq!(code, 0);
    assert_eq!(out, plain, "{name}: --plot changes the CSV");
    let svg = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    let start = svg.trim_start();
    assert!(
        start.starts_with("<svg") || start.starts_with("<?xml"),
        "{name}: not an SVG"
    );
    assert!(svg.trim_end().ends_with("</svg>"), "{name}: SVG not closed");
    for s in shows {
        assert!(svg.contains(s), "{name}: the figure does not show '{s}'");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

const P: &str = "presets/paper.toml";

#[test]
fn equilibrium_plots_displacement_pressures_and_flows() {
    plots(
        "equilibrium",
        &["equilibrium", "--params", P],
        &[
            "temperature [C]",
            "x [mm]",
            "p [bar]",
            "Q [L/min]",
            "chamber pressure p_a",
            "chamber pressure p_b",
            "total flow Q_total",
        ],
    );
}

#[test]
fn asymptotic_plots_the_series_beside_the_quasi_static_displacement() {
    plots(
        "asymptotic",
        &["asymptotic", "--params", P, "--order", "2", "--reading", "temperature"],
        &[
            "temperature [C]",
            "x [mm]",
            "error [um]",
            "quasi-static x",
            "asymptotic x, order 2",
        ],
    );
}

#[test]
fn step_plots_the_twin_and_overlays_the_reference() {
    let args = ["step", "--params", P, "--from", "40", "--to", "50", "--t-end", "0.05"];
    plots(
        "step",
        &args,
        &[
            "time [s]",
            "x [mm]",
            "v [mm/s]",
            "p [bar]",
            "x, twin, f64",
            "Step 40 C to 50 C",
        ],
    );
    let mut overlay = args.to_vec();
    overlay.push("--overlay-reference");
    plots(
        "step_overlay",
        &overlay,
        &["x, twin, f64", "x, reference (Radau5)", "p_b, reference (Radau5)"],
    );
    // Without --plot there is nothing to overlay on.
    let (code, out, err) = run_cli(&overlay);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert!(err.contains("--plot"), "{err}");
}

#[test]
fn eigen_plots_decay_rates_and_frequencies() {
    plots(
        "eigen",
        &["eigen", "--params", P],
        &[
            "temperature [C]",
            "decay rate -Re(lambda) [1/s]",
            "oscillation Im(lambda) [rad/s]",
            "damping ratio [-]",
            "lambda_1",
            "lambda_4",
        ],
    );
}

#[test]
fn compensation_plots_supply_against_demand() {
    plots(
        "compensation",
        &["compensation", "--params", P, "--temps", "26:78:2"],
        &[
            "temperature [C]",
            "Q [L/min]",
            "error [L/min]",
            "x [mm]",
            "supply (total flow)",
            "demand (leakage + machine)",
            "x the demand requires",
        ],
    );
}

#[test]
fn a_file_that_is_neither_svg_nor_png_is_refused_naming_plot() {
    let dir = temp_dir("bad");
    for (command, extra) in [
        ("equilibrium", &[][..]),
        ("asymptotic", &["--order", "1", "--reading", "property"][..]),
        ("step", &["--from", "40", "--to", "50"][..]),
        ("eigen", &[][..]),
        ("compensation", &[][..]),
    ] {
        for file in ["figure.pdf", "figure.jpg", "figure"] {
            let path = dir.join(file);
            let mut args = vec![command, "--params", P];
            args.extend(extra);
            args.extend(["--plot", path.to_str().unwrap()]);
            let (code, out, err) = run_cli(&args);
            assert_eq!(code, 2, "{command} {file}: {err}");
            assert!(out.is_empty(), "{command} {file}: wrote {out}");
            assert!(err.contains("--plot"), "{command} {file}: {err}");
            assert_eq!(err.trim().lines().count(), 1, "{command} {file}: {err}");
            assert!(!path.exists(), "{command} {file}: a file was written");
        }
    }
    // An SVG in a folder that does not exist: bad input naming --plot, no CSV.
    let path = dir.join("no/such/folder/figure.svg");
    let (code, out, err) = run_cli(&["eigen", "--params", P, "--plot", path.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--plot"), "{err}");
    // stdout: the CSV is not printed when the figure fails.
    assert!(out.is_empty(), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_long_run_makes_a_small_figure_that_keeps_its_peak() {
    let dir = temp_dir("long");
    let file = dir.join("long.svg");
    let args = [
        "step", "--params", P, "--from", "40", "--to", "50", "--dt", "0.0001", "--t-end", "2", "--plot",
    ];
    let mut with_plot = args.to_vec();
    with_plot.push(file.to_str().unwrap());
    let (code, out, err) = run_cli(&with_plot);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 20_002);
    let size = std::fs::metadata(&file).unwrap().len();
    assert!(size < 300_000, "{size} bytes for 20,001 samples");
    let _ = std::fs::remove_dir_all(&dir);
}
