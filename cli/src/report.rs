//! `report`: the paper's Tables 1-3 recomputed beside the published
//! numbers (CSV and a markdown summary `report.md`), and the paper's
//! Figures 2-5 with an eigenvalue map and the compensation error curve, in
//! one folder.
//!
//! The comparisons are those of `paper` ([`crate::paper`]: Table 1 and 2
//! residuals, the expansion that best reproduces Table 2's "asym" column,
//! the findings text), Table 3 is `indicators`
//! ([`crate::dynamics::step_indicators`]), the eigenvalue map is `eigen`
//! and the compensation curve `compensation`; the figures are drawn by
//! [`crate::plot`].

use crate::csv::{self, Table};
use crate::dynamics::{Precision, eigen_table, simulate, step_indicators};
use crate::error::CliError;
use crate::input::load_or_paper;
use crate::paper::tables::{BAR, Table1, Table2, load_tables, table1_residuals, table2_residuals};
use crate::paper::{self, AsymptoticMatch, asymptotic_search};
use crate::plot::{self, Figure, Series, panel};
use crate::sizing::compensation_of;
use crate::statics::find_balance;
use crate::units::Units;
use compensator::asymptotic::{Expansion, Reading};
use compensator::dynamics::TwinConfig;
use compensator::equilibrium::{a_parameter, equilibrium, pressure_difference};
use compensator::{Params, RawParams};
use compensator_reference::dynamics::Profile;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Table 3 of the paper (`data/paper/table3.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct Table3 {
    /// Steps (from, to) [C].
    pub steps: Vec<(f64, f64)>,
    /// Final displacement `x*` [mm].
    pub x_star_mm: Vec<f64>,
    /// Settling time relative to the paper's undefined `t_c` [-].
    pub settling_rel: Vec<f64>,
    /// Overshoot [%].
    pub overshoot_pct: Vec<f64>,
    /// Dominant eigenvalue's real part [1/s].
    pub dominant_re: Vec<f64>,
}

impl Table3 {
    /// Parses `from_c,to_c,x_star_mm,settling_rel,overshoot_pct,dominant_re`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, String> {
        let (header, rows) = csv::parse(text).map_err(|e| format!("{}: {e}", path.display()))?;
        let col = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| format!("{}: no column {name}", path.display()))
        };
        let c = [
            col("from_c")?,
            col("to_c")?,
            col("x_star_mm")?,
            col("settling_rel")?,
            col("overshoot_pct")?,
            col("dominant_re")?,
        ];
        if rows.is_empty() || rows.iter().flatten().any(|v| !v.is_finite()) {
            return Err(format!("{}: no rows, or a number that is not finite", path.display()));
        }
        let get = |k: usize| rows.iter().map(|r| r[c[k]]).collect::<Vec<f64>>();
        Ok(Table3 {
            steps: rows.iter().map(|r| (r[c[0]], r[c[1]])).collect(),
            x_star_mm: get(2),
            settling_rel: get(3),
            overshoot_pct: get(4),
            dominant_re: get(5),
        })
    }

    /// `data`'s `table3.csv`, or the copy built into the binary.
    pub fn load(data: Option<&Path>) -> Result<Self, String> {
        match data {
            Some(dir) => {
                let path = dir.join("table3.csv");
                let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
                Self::parse(&path, &text)
            }
            None => Self::parse(Path::new("data/paper/table3.csv"), crate::input::TABLE3_CSV),
        }
    }
}

/// What `report` is asked for.
#[derive(Debug, Clone)]
pub struct Options<'a> {
    /// Parameter file (default: the built-in `presets/paper.toml`).
    pub params: Option<&'a Path>,
    /// Folder with the paper's tables (default: the built-in `data/paper`).
    pub data: Option<&'a Path>,
    /// Output folder (created if absent).
    pub out: &'a Path,
    /// Also write each figure as PNG.
    pub png: bool,
    /// Units of the tables and figures.
    pub units: Units,
}

/// Sampling of the step responses of Figures 4 and 5 [s] and their length.
const STEP_DT: f64 = 2.0e-4;
const STEP_T_END: f64 = 0.1;
/// Table 3's indicators: the `indicators` command's defaults.
const INDICATOR_DT: f64 = 1.0e-4;
const INDICATOR_T_END: f64 = 1.0;

/// A number for a markdown table: four significant digits.
fn sig(v: f64) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    if v.fract() == 0.0 && v.abs() < 1e6 {
        return format!("{v:.0}");
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-3..6).contains(&mag) {
        return format!("{v:.3e}");
    }
    let decimals = (3 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// CSV text (converted to `units`) as a markdown table.
fn markdown(csv_text: &str) -> String {
    let (header, rows) = csv::cells(csv_text);
    let mut o = format!("| {} |\n|{}\n", header.join(" | "), "---|".repeat(header.len()));
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .map(|c| c.parse::<f64>().map_or_else(|_| c.to_string(), sig))
            .collect();
        let _ = writeln!(o, "| {} |", cells.join(" | "));
    }
    o
}

fn write_file(path: &Path, text: &str) -> Result<(), CliError> {
    std::fs::write(path, text).map_err(|e| CliError::Input(format!("--dir: {}: {e}", path.display())))
}

/// A sampled response: times [s] and displacements [m].
type Run = (Vec<f64>, Vec<f64>);

/// The steps' responses x(t) from the reference solver (Radau5), sampled
/// every `STEP_DT` over `STEP_T_END`: (times [s], x [m]) per step.
fn responses(raw: &RawParams, steps: &[(f64, f64)]) -> Result<Vec<Run>, CliError> {
    let n = (STEP_T_END / STEP_DT).round() as usize;
    steps
        .par_iter()
        .map(|&(from, to)| {
            let config = TwinConfig {
                tick: STEP_DT,
                ..TwinConfig::SHIPPED
            };
            let r = simulate(raw, Precision::Reference, config, &Profile::Step { from, to }, n)?;
            Ok((r.time, r.state.iter().map(|s| s.x).collect()))
        })
        .collect()
}

/// What the report is computed from: the parameter set, the paper's
/// tables and the expansion that best reproduces Table 2's "asym" column
/// (as `paper` finds it).
struct Inputs {
    raw: RawParams,
    p: Params<f64>,
    t1: Table1,
    t2: Table2,
    t3: Table3,
    expansion: Option<(AsymptoticMatch, Expansion<f64>)>,
}

impl Inputs {
    fn load(opts: &Options) -> Result<Self, CliError> {
        let (raw, p) = load_or_paper(opts.params)?;
        let (t1, t2) = load_tables(opts.data).map_err(CliError::Input)?;
        let t3 = Table3::load(opts.data).map_err(CliError::Input)?;
        let balance = find_balance(&raw, &p).ok();
        let (best, _) = asymptotic_search(&p, &t2, 26.0, 80.0, balance);
        let best = best.into_iter().min_by(|a, b| a.rms_mm.total_cmp(&b.rms_mm));
        let expansion = best.and_then(|b| Expansion::new(&p, b.t0, b.reading).ok().map(|e| (b, e)));
        Ok(Inputs {
            raw,
            p,
            t1,
            t2,
            t3,
            expansion,
        })
    }

    /// The best expansion's displacement at `t` [m] (NaN without one, or
    /// where it cannot be evaluated).
    fn asym_x(&self, t: f64) -> f64 {
        self.expansion
            .as_ref()
            .and_then(|(b, e)| e.at(t).ok().map(|terms| terms.x(b.order).0))
            .unwrap_or(f64::NAN)
    }
}

/// Table 1: p_b - p_a at the three drops, the paper's beside the model's
/// (SI CSV), and the residuals [bar].
fn table1(inp: &Inputs) -> (Table, Vec<f64>) {
    let t1 = &inp.t1;
    let r1 = table1_residuals(&inp.p, t1);
    let mut table = Table::new(&["t_c", "dp_pa", "paper_dp_ab_pa", "model_dp_ab_pa", "residual_pa"]);
    let nd = t1.drops_bar.len();
    for (i, &t) in t1.temps.iter().enumerate() {
        for (j, &dp) in t1.drops_bar.iter().enumerate() {
            let paper = t1.values[i][j];
            let r = r1[i * nd + j];
            if r.is_finite() {
                table.row(&[t, dp * BAR, paper * BAR, (paper + r) * BAR, r * BAR]);
            } else {
                table.row_error(
                    &[t, dp * BAR, paper * BAR],
                    "the model cannot evaluate this temperature",
                );
            }
        }
    }
    (table, r1)
}

/// Table 2: quasi-static and "asymptotic" displacement, the paper's beside
/// the model's (SI CSV), and the quasi-static residuals [mm].
fn table2(inp: &Inputs) -> (Table, Vec<f64>) {
    let t2 = &inp.t2;
    let r2 = table2_residuals(&inp.p, t2);
    let mut table = Table::new(&[
        "t_c",
        "paper_x_qs_m",
        "model_x_qs_m",
        "residual_qs_m",
        "paper_x_asym_m",
        "model_x_asym_m",
        "residual_asym_m",
    ]);
    for (i, &t) in t2.temps.iter().enumerate() {
        let (pq, pa) = (t2.x_qs_mm[i] * 1e-3, t2.x_asym_mm[i] * 1e-3);
        let mq = pq + r2[i] * 1e-3;
        let ma = inp.asym_x(t);
        if mq.is_finite() && ma.is_finite() {
            table.row(&[t, pq, mq, mq - pq, pa, ma, ma - pa]);
        } else {
            table.row_error(&[t, pq], "the model cannot evaluate this temperature");
        }
    }
    (table, r2)
}

/// Table 3: the step indicators (reference solver, steps in parallel),
/// the paper's beside the model's (SI CSV).
fn table3(inp: &Inputs) -> Table {
    let t3 = &inp.t3;
    let indicators: Vec<Result<crate::dynamics::Indicators, CliError>> = t3
        .steps
        .par_iter()
        .map(|&(from, to)| step_indicators(&inp.raw, &inp.p, from, to, INDICATOR_DT, INDICATOR_T_END))
        .collect();
    let mut table = Table::new(&[
        "from_c",
        "to_c",
        "paper_x_star_m",
        "model_x_star_m",
        "paper_settling_rel",
        "model_settling_time_s",
        "paper_overshoot_pct",
        "model_overshoot_pct",
        "paper_dominant_re",
        "model_dominant_re",
    ]);
    for (k, ind) in indicators.iter().enumerate() {
        let (from, to) = t3.steps[k];
        match ind {
            Ok(ind) => table.row(&[
                from,
                to,
                t3.x_star_mm[k] * 1e-3,
                ind.x_star,
                t3.settling_rel[k],
                ind.settling_time,
                t3.overshoot_pct[k],
                ind.overshoot_pct,
                t3.dominant_re[k],
                ind.dominant_re,
            ]),
            Err(e) => table.row_error(&[from, to], &e.to_string()),
        }
    }
    table
}

/// A figure of the report: its file name (without extension), its caption
/// in `report.md`, the figure.
type Named = (&'static str, &'static str, Figure);

/// The temperatures the figures' model curves are drawn at [C].
fn fine() -> Vec<f64> {
    (0..=112).map(|i| 26.0 + 0.5 * i as f64).collect()
}

/// Figure 2: p_b - p_a over temperature at the three drops, the model's
/// lines and the paper's Table 1 points.
fn figure2(inp: &Inputs, u: Units) -> Named {
    let (p, t1, pr) = (&inp.p, &inp.t1, u.pressure());
    let mut fig2 = Vec::new();
    for (j, &dp) in t1.drops_bar.iter().enumerate() {
        let curve: Vec<(f64, f64)> = fine()
            .iter()
            .filter_map(|&t| {
                let f = p.oil.state(t).ok()?;
                Some((t, pr.apply(pressure_difference(a_parameter(p, &f), dp * BAR))))
            })
            .collect();
        let mut line = Series::line(format!("model, dp = {dp} bar"), curve);
        line.color = Some(j);
        fig2.push(line);
    }
    for j in 0..t1.drops_bar.len() {
        let pts = t1
            .temps
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, pr.apply(t1.values[i][j] * BAR)));
        // One legend entry for the three drops' points (colours as the lines).
        let label = if j == 0 {
            "paper Table 1 (circles)".to_string()
        } else {
            String::new()
        };
        let mut s = Series::points(label, pts.collect());
        s.color = Some(j);
        fig2.push(s);
    }
    (
        "fig2_pressure_difference",
        "Figure 2: the pressure difference p_b - p_a between the chambers against temperature at the three pressure drops (lines: model; circles: the paper's Table 1)",
        Figure {
            title: "Figure 2: pressure difference between the chambers".into(),
            x_desc: "temperature [C]".into(),
            panels: vec![panel(&format!("p_b - p_a [{}]", pr.unit), fig2)],
        },
    )
}

/// Figure 3: quasi-static against asymptotic displacement, the model's
/// lines and the paper's Table 2 points.
fn figure3(inp: &Inputs, u: Units) -> Named {
    let (t2, len) = (&inp.t2, u.length());
    let fine = fine();
    let qs: Vec<(f64, f64)> = fine
        .iter()
        .filter_map(|&t| equilibrium(&inp.p, t).ok().map(|e| (t, len.apply(e.x))))
        .collect();
    let mut fig3 = vec![Series::line("model, quasi-static", qs)];
    if let Some((b, _)) = &inp.expansion {
        let reading = match b.reading {
            Reading::Temperature => "temperature",
            Reading::Property => "property",
        };
        let mut s = Series::line(
            format!("model, order-{} series in {reading}, t0 = {:.1} C", b.order, b.t0),
            fine.iter().map(|&t| (t, len.apply(inp.asym_x(t)))).collect(),
        );
        s.dashed = true;
        s.color = Some(1);
        fig3.push(s);
    }
    for (label, column, color) in [
        ("paper Table 2, quasi-static", &t2.x_qs_mm, 0),
        ("paper Table 2, asymptotic", &t2.x_asym_mm, 1),
    ] {
        let mut s = Series::points(
            label,
            t2.temps
                .iter()
                .zip(column)
                .map(|(&t, &x)| (t, len.apply(x * 1e-3)))
                .collect(),
        );
        s.color = Some(color);
        fig3.push(s);
    }
    (
        "fig3_displacement",
        "Figure 3: quasi-static against asymptotic equilibrium displacement (lines: model, the expansion that best reproduces the paper's column; circles: the paper's Table 2)",
        Figure {
            title: "Figure 3: quasi-static and asymptotic displacement".into(),
            x_desc: "temperature [C]".into(),
            panels: vec![panel(&format!("x [{}]", len.unit), fig3)],
        },
    )
}

/// Figures 4 and 5: the step responses of Table 3 (reference solver),
/// absolute and normalised with the settling band.
fn figures45(inp: &Inputs, u: Units) -> Result<[Named; 2], CliError> {
    let len = u.length();
    let runs = responses(&inp.raw, &inp.t3.steps)?;
    let mut abs = Vec::new();
    let mut norm = Vec::new();
    for (&(from, to), (time, x)) in inp.t3.steps.iter().zip(&runs) {
        let label = format!("{from} -> {to} C");
        abs.push(Series::line(
            label.clone(),
            time.iter().zip(x).map(|(&t, &x)| (t * 1e3, len.apply(x))).collect(),
        ));
        let x_star = equilibrium(&inp.p, to).map(|e| e.x).unwrap_or(f64::NAN);
        let x0 = x.first().copied().unwrap_or(f64::NAN);
        norm.push(Series::line(
            label,
            time.iter()
                .zip(x)
                .map(|(&t, &x)| (t * 1e3, (x - x0) / (x_star - x0)))
                .collect(),
        ));
    }
    // The settling band as one dashed outline.
    let end = STEP_T_END * 1e3;
    let mut band = Series::line(
        "+-2 % settling band",
        vec![(0.0, 0.98), (end, 0.98), (end, 1.02), (0.0, 1.02)],
    );
    band.dashed = true;
    band.color = Some(5);
    norm.push(band);
    Ok([
        (
            "fig4_step_responses",
            "Figure 4: plunger displacement after the temperature steps of Table 3 (reference solver, Radau5)",
            Figure {
                title: "Figure 4: step responses of the plunger displacement".into(),
                x_desc: "time [ms]".into(),
                panels: vec![panel(&format!("x [{}]", len.unit), abs)],
            },
        ),
        (
            "fig5_normalised_responses",
            "Figure 5: the same responses normalised, (x - x0) / (x* - x0), with the +-2 % band of the settling time",
            Figure {
                title: "Figure 5: normalised step responses".into(),
                x_desc: "time [ms]".into(),
                panels: vec![panel("(x - x0) / (x* - x0) [-]", norm)],
            },
        ),
    ])
}

/// The eigenvalue map over the validated range and, with a `[machine]`,
/// the compensation error curve.
fn validated_range_figures(inp: &Inputs, u: Units) -> Result<Vec<Named>, CliError> {
    let (lo, hi) = (inp.raw.estimator.valid_min, inp.raw.estimator.valid_max);
    let grid: Vec<f64> = (0..=((hi - lo) / 0.5).floor() as usize)
        .map(|i| lo + 0.5 * i as f64)
        .collect();
    let eig = eigen_table(&inp.p, &grid);
    let mut figures = vec![(
        "eigenvalues",
        "Eigenvalue map: decay rates, oscillation frequencies and the dominant damping ratio of the linearisation over the validated range",
        plot::eigen(eig.as_str())?,
    )];
    if inp.p.machine.is_some() {
        let comp = compensation_of(&inp.p, &grid);
        figures.push((
            "compensation",
            "Compensation: the flow supplied against the machine's demand, their difference, and the displacement the demand requires",
            plot::compensation(comp.as_str(), u)?,
        ));
    }
    Ok(figures)
}

/// Writes `figures` into `opts.out` as SVG (and PNG with `--png`), adding
/// the files to `written`; returns their captions and links for
/// `report.md`.
fn write_figures(opts: &Options, figures: &[Named], written: &mut Vec<PathBuf>) -> Result<String, CliError> {
    let mut links = String::new();
    for (name, caption, fig) in figures {
        let svg = opts.out.join(format!("{name}.svg"));
        plot::write(&svg, fig).map_err(|e| CliError::Input(e.to_string().replace("--plot", "--dir")))?;
        written.push(svg);
        let _ = write!(links, "\n{caption}.\n\n![{name}]({name}.svg)");
        if opts.png {
            let png = opts.out.join(format!("{name}.png"));
            plot::write(&png, fig).map_err(|e| CliError::Input(e.to_string().replace("--plot", "--dir")))?;
            written.push(png);
            let _ = write!(links, " ([PNG]({name}.png))");
        }
        links.push('\n');
    }
    Ok(links)
}

/// The tables as written (in the report's units) and their residuals.
struct Tables {
    table1: String,
    table2: String,
    table3: String,
    /// Table 1's residuals [bar].
    r1: Vec<f64>,
    /// Table 2's quasi-static residuals [mm].
    r2: Vec<f64>,
}

/// `report.md`: the tables with their residuals, the best expansion, the
/// figures (`figure_links`) and the findings of `compensator paper`.
fn summary(opts: &Options, inp: &Inputs, tables: &Tables, figure_links: &str) -> Result<String, CliError> {
    let u = opts.units;
    let shown = opts
        .params
        .map_or("presets/paper.toml (built in)".into(), |p| p.display().to_string());
    let units_note = match u {
        Units::Si => "SI units (m, Pa, m^3/s)",
        Units::Eng => "engineering units (mm, bar, L/min)",
    };
    let mut md = String::new();
    let _ = writeln!(md, "# The paper's tables and figures recomputed\n");
    let _ = writeln!(
        md,
        "Parameters: {shown}. Tables in {units_note}; each model value beside the paper's. \
         Regenerate with `compensator report --dir DIR{}{}`.\n",
        opts.params
            .map_or(String::new(), |p| format!(" --params {}", p.display())),
        match (u, opts.png) {
            (Units::Eng, true) => " --units eng --png",
            (Units::Eng, false) => " --units eng",
            (Units::Si, true) => " --png",
            (Units::Si, false) => "",
        }
    );
    let fin = |v: &[f64]| v.iter().copied().filter(|x| x.is_finite()).collect::<Vec<_>>();
    let (r1f, r2f) = (fin(&tables.r1), fin(&tables.r2));
    let _ = writeln!(
        md,
        "## Table 1: pressure difference p_b - p_a (`table1.csv`)\n\nRMS residual {:.4} bar, max {:.4} bar over {} of {} points.\n",
        crate::lsq::rms(&r1f),
        crate::lsq::max_abs(&r1f),
        r1f.len(),
        tables.r1.len()
    );
    md.push_str(&markdown(&tables.table1));
    let _ = writeln!(
        md,
        "\n## Table 2: equilibrium displacement (`table2.csv`)\n\nQuasi-static column: RMS residual {:.4} mm, max {:.4} mm.",
        crate::lsq::rms(&r2f),
        crate::lsq::max_abs(&r2f)
    );
    if let Some((b, _)) = &inp.expansion {
        let _ = writeln!(
            md,
            "\"asym\" column: best reproduced by the order-{} series in {} about t0 = {:.1} C (RMS {:.4} mm, max {:.4} mm).",
            b.order,
            match b.reading {
                Reading::Temperature => "temperature",
                Reading::Property => "the property A",
            },
            b.t0,
            b.rms_mm,
            b.max_mm
        );
    }
    md.push('\n');
    md.push_str(&markdown(&tables.table2));
    let _ = writeln!(
        md,
        "\n## Table 3: step-response indicators (`table3.csv`)\n\n\
         Model: reference solver (Radau5), sampled every {INDICATOR_DT} s over {INDICATOR_T_END} s; settling into +-2 % of x*, \
         overshoot in % of the step, dominant eigenvalue at the final temperature. The paper's settling times are relative to a \
         time scale it does not define, and its Table 3 is illustrative (docs/paper.md: the physical model is overdamped).\n"
    );
    md.push_str(&markdown(&tables.table3));
    let _ = writeln!(md, "\n## Figures\n{figure_links}");
    let findings = paper::report(opts.params, opts.data)?;
    let _ = writeln!(md, "## Findings (`compensator paper`)\n\n```text\n{}```", findings);
    Ok(md)
}

/// Writes the report into `opts.out`; returns the list of files written
/// (one per line).
pub fn report(opts: &Options) -> Result<String, CliError> {
    let u = opts.units;
    let inp = Inputs::load(opts)?;
    std::fs::create_dir_all(opts.out).map_err(|e| CliError::Input(format!("--dir: {}: {e}", opts.out.display())))?;
    let mut written: Vec<PathBuf> = Vec::new();
    let ((table1, r1), (table2, r2)) = (table1(&inp), table2(&inp));
    let tables = Tables {
        table1: u.convert_csv(table1.as_str()),
        table2: u.convert_csv(table2.as_str()),
        table3: u.convert_csv(table3(&inp).as_str()),
        r1,
        r2,
    };
    for (name, text) in [
        ("table1.csv", &tables.table1),
        ("table2.csv", &tables.table2),
        ("table3.csv", &tables.table3),
    ] {
        let path = opts.out.join(name);
        write_file(&path, text)?;
        written.push(path);
    }
    let mut figures = vec![figure2(&inp, u), figure3(&inp, u)];
    figures.extend(figures45(&inp, u)?);
    figures.extend(validated_range_figures(&inp, u)?);
    let figure_links = write_figures(opts, &figures, &mut written)?;
    let md_path = opts.out.join("report.md");
    write_file(&md_path, &summary(opts, &inp, &tables, &figure_links)?)?;
    written.insert(0, md_path);
    let mut listing = String::new();
    for path in written {
        let _ = writeln!(listing, "{}", path.display());
    }
    Ok(listing)
}
