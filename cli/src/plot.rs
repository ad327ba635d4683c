//! `--plot FILE.svg`: a figure of what a command printed, drawn with
//! `plotters`' SVG backend (no system libraries: the viewer draws the text).
//!
//! A figure is built from the command's CSV output (the SI columns of its
//! header), so the plots show exactly the numbers the command printed, in
//! readable units (mm, bar, L/min). A figure is one or more panels stacked
//! over a shared x axis, each with its quantity and unit and a legend.
//! Only `.svg` is written: PNG would need plotters' bitmap backend and a
//! font library, so `.png` is refused naming `--plot` (exit status 2).

use crate::csv;
use crate::error::CliError;
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One curve of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points (x, y); non-finite ones are skipped.
    pub points: Vec<(f64, f64)>,
    /// Dashed (an overlay, e.g. the reference solution).
    pub dashed: bool,
    /// Marks at the points (for coarse tables, e.g. one row per 10 C).
    pub marks: bool,
}

/// One panel: a y quantity over the figure's x axis.
#[derive(Clone, Debug)]
pub struct Panel {
    /// The y axis: quantity and unit, e.g. `x [mm]`.
    pub y_desc: String,
    /// Logarithmic y axis (positive values only).
    pub log_y: bool,
    /// A legend (off where the panel below names the same curves).
    pub legend: bool,
    /// The curves.
    pub series: Vec<Series>,
}

/// A figure: a title, the x axis, panels stacked top to bottom.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title over the figure.
    pub title: String,
    /// The x axis: quantity and unit, e.g. `temperature [C]`.
    pub x_desc: String,
    /// The panels.
    pub panels: Vec<Panel>,
}

/// The `--plot` argument's parser: a path ending in `.svg`. Anything else is
/// refused by clap as an invalid value for `--plot` (exit status 2).
pub fn parse_path(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase) {
        Some(e) if e == "svg" => Ok(path),
        Some(e) if e == "png" => Err("PNG is not supported (it would need system font libraries); \
             write FILE.svg and convert it if needed"
            .to_string()),
        _ => Err("the figure file must end in .svg".to_string()),
    }
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Width of the figure [px]; each panel is `PANEL_HEIGHT` high.
const WIDTH: u32 = 900;
const PANEL_HEIGHT: u32 = 300;

fn finite(points: &[(f64, f64)], log_y: bool) -> Vec<(f64, f64)> {
    points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log_y || *y > 0.0))
        .collect()
}

/// Points per curve beyond which a curve is thinned.
const MAX_POINTS: usize = 4000;

/// At most about `MAX_POINTS` of `points` (sorted along x), keeping each
/// bucket's first, lowest, highest and last point in order, so that a
/// peak survives: a long run (`step --t-end 100`) stays a small file.
fn thin(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points;
    }
    let per = points.len().div_ceil(MAX_POINTS / 4);
    let mut out = Vec::with_capacity(MAX_POINTS + 4);
    for bucket in points.chunks(per) {
        let lo = bucket
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map_or(0, |m| m.0);
        let hi = bucket
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map_or(0, |m| m.0);
        let mut keep = [0, lo, hi, bucket.len() - 1];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                out.push(bucket[k]);
                last = k;
            }
        }
    }
    out
}

/// The range of `values`, padded by 5 % (a flat series gets a unit band).
fn padded(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        return (lo / 1.5, hi * 1.5);
    }
    let span = hi - lo;
    if span <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
        let d = if hi == 0.0 { 1.0 } else { 0.05 * hi.abs() };
        return (lo - d, hi + d);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// The corner of the panel where the legend hides the fewest points (in
/// the panel's fractions: the legend is about 40 % wide, 10 % high per line).
fn legend_corner(panel: &Panel, x: (f64, f64), y: (f64, f64)) -> (SeriesLabelPosition, usize) {
    let h = 0.06 + 0.1 * panel.series.len() as f64;
    let fy = |v: f64| if panel.log_y { v.ln() } else { v };
    let corners = [
        (SeriesLabelPosition::UpperRight, 0.6, 1.0 - h),
        (SeriesLabelPosition::UpperLeft, 0.0, 1.0 - h),
        (SeriesLabelPosition::LowerRight, 0.6, 0.0),
        (SeriesLabelPosition::LowerLeft, 0.0, 0.0),
    ];
    let hidden = |&(_, x0, y0): &(SeriesLabelPosition, f64, f64)| {
        panel
            .series
            .iter()
            .flat_map(|s| finite(&s.points, panel.log_y))
            .filter(|&(px, py)| {
                let u = (px - x.0) / (x.1 - x.0);
                let w = (fy(py) - y.0) / (y.1 - y.0);
                u >= x0 - 0.02 && u <= x0 + 0.42 && w >= y0 - 0.02 && w <= y0 + h + 0.02
            })
            .count()
    };
    let best = corners.iter().min_by_key(|c| hidden(c)).unwrap_or(&corners[0]);
    (best.0.clone(), hidden(best))
}

/// A tick label: integers without a fraction, others to six decimals at
/// most, large magnitudes in scientific notation.
fn tick(v: &f64) -> String {
    let v = *v;
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e6 || v.abs() < 1e-4 {
        format!("{v:.0e}")
    } else if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

fn draw_panel<'a, Y>(
    area: &DrawingArea<SVGBackend<'a>, Shift>,
    x_range: (f64, f64),
    y_range: Y,
    legend: SeriesLabelPosition,
    zero_inside: bool,
    x_desc: &str,
    panel: &Panel,
) -> DrawResult<()>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.0..x_range.1, y_range)?;
    chart
        .configure_mesh()
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .x_desc(x_desc)
        .y_desc(panel.y_desc.as_str())
        .axis_desc_style(("sans-serif", 16))
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()?;
    if !panel.log_y && zero_inside {
        let (x0, x1) = x_range;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(x0, 0.0), (x1, 0.0)],
            BLACK.mix(0.5).stroke_width(1),
        )))?;
    }
    for (i, s) in panel.series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let style = color.stroke_width(2);
        let points = thin(finite(&s.points, panel.log_y));
        let anno = if s.dashed {
            chart.draw_series(DashedLineSeries::new(points.clone(), 8, 5, style))?
        } else {
            chart.draw_series(LineSeries::new(points.clone(), style))?
        };
        let dashed = s.dashed;
        anno.label(s.label.as_str()).legend(move |(x, y)| {
            if dashed {
                PathElement::new(vec![(x, y), (x + 8, y)], style)
            } else {
                PathElement::new(vec![(x, y), (x + 20, y)], style)
            }
        });
        if s.marks {
            chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
        }
    }
    if !panel.legend {
        return Ok(());
    }
    chart
        .configure_series_labels()
        .position(legend)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 14))
        .draw()?;
    Ok(())
}

fn draw(path: &Path, fig: &Figure) -> DrawResult<()> {
    let n = fig.panels.len().max(1) as u32;
    let root = SVGBackend::new(path, (WIDTH, n * PANEL_HEIGHT + 40)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(&fig.title, ("sans-serif", 20))?;
    let areas = root.split_evenly((fig.panels.len().max(1), 1));
    let x_range = padded(
        fig.panels
            .iter()
            .flat_map(|p| p.series.iter())
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .filter(|x| x.is_finite()),
        false,
    );
    for (area, panel) in areas.iter().zip(&fig.panels) {
        let ys = || {
            panel
                .series
                .iter()
                .flat_map(|s| finite(&s.points, panel.log_y))
                .map(|p| p.1)
        };
        let (lo, mut hi) = padded(ys(), panel.log_y);
        if panel.log_y {
            let (mut legend, hidden) = legend_corner(panel, x_range, (lo.ln(), hi.ln()));
            if hidden > 0 && panel.legend {
                let h = (0.06 + 0.1 * panel.series.len() as f64).min(0.6);
                hi = (hi.ln() + (hi.ln() - lo.ln()) * (h + 0.04) / (1.0 - h - 0.04)).exp();
                legend = legend_corner(panel, x_range, (lo.ln(), hi.ln())).0;
            }
            draw_panel(area, x_range, (lo..hi).log_scale(), legend, false, &fig.x_desc, panel)?;
        } else {
            let (mut legend, hidden) = legend_corner(panel, x_range, (lo, hi));
            if hidden > 0 && panel.legend {
                // No free corner: headroom over the data for the legend.
                let h = (0.06 + 0.1 * panel.series.len() as f64).min(0.6);
                hi += (hi - lo) * (h + 0.04) / (1.0 - h - 0.04);
                legend = legend_corner(panel, x_range, (lo, hi)).0;
            }
            draw_panel(area, x_range, lo..hi, legend, lo < 0.0 && hi > 0.0, &fig.x_desc, panel)?;
        }
    }
    root.present()?;
    Ok(())
}

/// Writes `fig` to `path` (SVG). A file that cannot be written is bad input
/// naming `--plot`.
pub fn write(path: &Path, fig: &Figure) -> Result<(), CliError> {
    draw(path, fig).map_err(|e| CliError::Input(format!("--plot: {}: {e}", path.display())))
}

/// The command's CSV output as columns by header name.
struct Columns {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Columns {
    fn parse(text: &str) -> Result<Self, CliError> {
        let (header, rows) = csv::parse(text).map_err(|e| CliError::Failed(format!("--plot: {e}")))?;
        Ok(Columns { header, rows })
    }

    fn col(&self, name: &str) -> Result<Vec<f64>, CliError> {
        let i = self
            .header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| CliError::Failed(format!("--plot: no column {name}")))?;
        Ok(self.rows.iter().map(|r| r[i]).collect())
    }

    /// A series of column `y` scaled by `scale` over column `x`.
    fn series(&self, x: &str, y: &str, scale: f64, label: &str) -> Result<Series, CliError> {
        let xs = self.col(x)?;
        let ys = self.col(y)?;
        Ok(Series {
            label: label.to_string(),
            points: xs.into_iter().zip(ys).map(|(x, y)| (x, y * scale)).collect(),
            dashed: false,
            marks: self.rows.len() <= 30,
        })
    }
}

const MM: f64 = 1e3;
const BAR: f64 = 1e-5;
/// m^3/s to L/min.
const L_MIN: f64 = 6e4;
const TEMPERATURE: &str = "temperature [C]";

fn panel(y_desc: &str, series: Vec<Series>) -> Panel {
    Panel {
        y_desc: y_desc.to_string(),
        log_y: false,
        legend: true,
        series,
    }
}

/// `equilibrium`: displacement, chamber pressures and flows over temperature.
pub fn equilibrium(csv: &str) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    Ok(Figure {
        title: "Quasi-static equilibrium".into(),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            panel("x [mm]", vec![c.series("t_c", "x_m", MM, "spool displacement x")?]),
            panel(
                "p [bar]",
                vec![
                    c.series("t_c", "p_a_pa", BAR, "chamber pressure p_a")?,
                    c.series("t_c", "p_b_pa", BAR, "chamber pressure p_b")?,
                ],
            ),
            panel(
                "Q [L/min]",
                vec![
                    c.series("t_c", "q_total_m3s", L_MIN, "total flow Q_total")?,
                    c.series("t_c", "q_throt_m3s", L_MIN, "throttle flow Q_throt")?,
                    c.series("t_c", "q_branch_m3s", L_MIN, "branch flow Q_branch")?,
                ],
            ),
        ],
    })
}

/// `asymptotic`: the series beside the quasi-static displacement, and their
/// difference.
pub fn asymptotic(csv: &str, order: usize) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let qs = c.series("t_c", "x_qs_m", MM, "quasi-static x")?;
    let mut asym = c.series("t_c", "x_asym_m", MM, &format!("asymptotic x, order {order}"))?;
    asym.dashed = true;
    let diff = Series {
        label: format!("order-{order} series minus quasi-static"),
        points: qs
            .points
            .iter()
            .zip(&asym.points)
            .map(|(q, a)| (q.0, (a.1 - q.1) * 1e3))
            .collect(),
        dashed: false,
        marks: qs.marks,
    };
    Ok(Figure {
        title: format!("Asymptotic displacement (order {order}) and the quasi-static one"),
        x_desc: TEMPERATURE.into(),
        panels: vec![panel("x [mm]", vec![qs, asym]), panel("error [um]", vec![diff])],
    })
}

/// `step`: displacement, velocity and pressures over time; `overlay` (a
/// second run's CSV and its name) is drawn dashed over each curve.
pub fn step(csv: &str, name: &str, overlay: Option<(&str, &str)>, title: &str) -> Result<Figure, CliError> {
    let runs: Vec<(Columns, &str, bool)> = std::iter::once(Ok((Columns::parse(csv)?, name, false)))
        .chain(overlay.map(|(o, n)| Columns::parse(o).map(|c| (c, n, true))))
        .collect::<Result<_, CliError>>()?;
    let mut x = Vec::new();
    let mut v = Vec::new();
    let mut p = Vec::new();
    for (c, name, dashed) in &runs {
        let tag = |s: Series| Series {
            dashed: *dashed,
            marks: false,
            ..s
        };
        x.push(tag(c.series("time_s", "x_m", MM, &format!("x, {name}"))?));
        v.push(tag(c.series("time_s", "v_m_s", MM, &format!("v, {name}"))?));
        p.push(tag(c.series("time_s", "p_a_pa", BAR, &format!("p_a, {name}"))?));
        p.push(tag(c.series("time_s", "p_b_pa", BAR, &format!("p_b, {name}"))?));
    }
    // Pressures: p_a and p_b of a run in two colours, the overlay in the
    // same two colours; reorder so that colours pair up by quantity.
    if p.len() == 4 {
        p.swap(1, 2);
    }
    Ok(Figure {
        title: title.to_string(),
        x_desc: "time [s]".into(),
        panels: vec![panel("x [mm]", x), panel("v [mm/s]", v), panel("p [bar]", p)],
    })
}

/// `eigen`: the decay rates -Re(lambda) (log scale) and the oscillation
/// frequencies Im(lambda) of the four eigenvalues over temperature.
pub fn eigen(csv: &str) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let mut re = Vec::new();
    let mut im = Vec::new();
    for k in 1..=4 {
        re.push(c.series("t_c", &format!("re_{k}"), -1.0, &format!("lambda_{k}"))?);
        im.push(c.series("t_c", &format!("im_{k}"), 1.0, &format!("lambda_{k}"))?);
    }
    Ok(Figure {
        title: "Eigenvalues of the linearisation at the equilibrium (colours as in the legend below)".into(),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            Panel {
                y_desc: "decay rate -Re(lambda) [1/s]".into(),
                log_y: true,
                legend: false,
                series: re,
            },
            panel("oscillation Im(lambda) [rad/s]", im),
            panel(
                "damping ratio [-]",
                vec![c.series("t_c", "zeta_dominant", 1.0, "zeta, dominant mode")?],
            ),
        ],
    })
}

/// `compensation`: demand against supply, the error, and the displacement
/// against the one the demand needs.
pub fn compensation(csv: &str) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let mut required = c.series("t_c", "required_x_m", MM, "x the demand requires")?;
    required.dashed = true;
    let mut demand = c.series("t_c", "demand_m3s", L_MIN, "demand (leakage + machine)")?;
    demand.dashed = true;
    Ok(Figure {
        title: "Compensation: flow supplied against the machine's demand".into(),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            panel(
                "Q [L/min]",
                vec![c.series("t_c", "supply_m3s", L_MIN, "supply (total flow)")?, demand],
            ),
            panel(
                "error [L/min]",
                vec![c.series("t_c", "error_m3s", L_MIN, "supply minus demand")?],
            ),
            panel(
                "x [mm]",
                vec![c.series("t_c", "x_m", MM, "spool displacement x")?, required],
            ),
        ],
    })
}
