//! `--plot FILE.svg|FILE.png`: a figure of what a command printed, drawn
//! with `plotters`: SVG (the viewer draws the text) or PNG (plotters'
//! bitmap backend into memory, the text rasterised by `ab_glyph` from
//! DejaVu Sans, built into the binary by the `dejavu` crate, encoded by
//! the `png` crate). Neither needs a system library.
//!
//! A figure is built from the command's CSV output (the SI columns of its
//! header), so the plots show exactly the numbers the command printed, in
//! the units of `--units` (SI: m, Pa, m^3/s; eng: mm, bar, L/min). A figure
//! is one or more panels stacked over a shared x axis, each with its
//! quantity and unit and a legend. Rows that could not be computed (an
//! `error` column) are left out of the curves.

use crate::csv;
use crate::error::CliError;
use crate::units::{Scale, Units};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// One curve of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text (empty: no legend entry, e.g. the second of two
    /// series that share one).
    pub label: String,
    /// Points (x, y); non-finite ones are skipped.
    pub points: Vec<(f64, f64)>,
    /// Dashed (an overlay, e.g. the reference solution).
    pub dashed: bool,
    /// Marks at the points (for coarse tables, e.g. one row per 10 C).
    pub marks: bool,
    /// Joined by a line (off: marks only, e.g. published data points).
    pub line: bool,
    /// Colour index (default: the series' place in its panel), so that a
    /// curve and its data points can share one.
    pub color: Option<usize>,
    /// A band shaded in the series' colour behind its line: (x, low, high)
    /// points (an uncertainty band; empty: none). Non-finite ones are
    /// skipped.
    pub band: Vec<(f64, f64, f64)>,
}

impl Series {
    /// A solid line through `points`, without marks.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            dashed: false,
            marks: false,
            line: true,
            color: None,
            band: Vec::new(),
        }
    }

    /// Marks at `points` without a line (published data).
    pub fn points(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            dashed: false,
            marks: true,
            line: false,
            color: None,
            band: Vec::new(),
        }
    }
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

/// File format of a figure, from its name.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FileFormat {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics (a bitmap).
    Png,
}

/// The format of a figure file by its extension (case-insensitive).
pub fn file_format(path: &Path) -> Option<FileFormat> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase) {
        Some(e) if e == "svg" => Some(FileFormat::Svg),
        Some(e) if e == "png" => Some(FileFormat::Png),
        _ => None,
    }
}

/// The `--plot` argument's parser: a path ending in `.svg` or `.png`.
/// Anything else is refused by clap as an invalid value for `--plot` (exit
/// status 2).
pub fn parse_path(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    match file_format(&path) {
        Some(_) => Ok(path),
        None => Err("the figure file must end in .svg or .png".to_string()),
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

/// Width of the figure [px]; each panel is `PANEL_HEIGHT` high (a figure
/// of one panel `SINGLE_PANEL_HEIGHT`).
const WIDTH: u32 = 900;
const PANEL_HEIGHT: u32 = 300;
const SINGLE_PANEL_HEIGHT: u32 = 460;

/// Height of a panel of `fig` [px].
fn panel_height(fig: &Figure) -> u32 {
    if fig.panels.len() == 1 {
        SINGLE_PANEL_HEIGHT
    } else {
        PANEL_HEIGHT
    }
}

/// The legend's height as a fraction of a panel's plotting area `height`
/// [px] high: about 23 px a labelled series and a margin.
fn legend_height(panel: &Panel, height: u32) -> f64 {
    let lines = panel.series.iter().filter(|s| !s.label.is_empty()).count() as f64;
    let per_line = 23.0 / (height as f64 - 70.0).max(100.0);
    0.06 + per_line * lines
}

fn finite(points: &[(f64, f64)], log_y: bool) -> Vec<(f64, f64)> {
    points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log_y || *y > 0.0))
        .collect()
}

/// The outline of a band, its upper edge left to right and its lower edge
/// back, each thinned as a curve ([`thin`]); a stretch of non-finite
/// points is skipped.
fn band_polygon(band: &[(f64, f64, f64)], log_y: bool) -> Vec<(f64, f64)> {
    let ok =
        |&&(x, lo, hi): &&(f64, f64, f64)| x.is_finite() && lo.is_finite() && hi.is_finite() && (!log_y || lo > 0.0);
    let upper = thin(band.iter().filter(ok).map(|&(x, _, hi)| (x, hi)).collect());
    let lower = thin(band.iter().filter(ok).map(|&(x, lo, _)| (x, lo)).collect());
    upper.into_iter().chain(lower.into_iter().rev()).collect()
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
fn legend_corner(panel: &Panel, h: f64, x: (f64, f64), y: (f64, f64)) -> (SeriesLabelPosition, usize) {
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

/// A tick label on an axis spanning `[lo, hi]`: zero as `0` (a tick
/// computed as a multiple of the step lands a rounding error away from
/// it); on an axis whose largest magnitude is below 1e-3 or from 1e6 on,
/// every tick in scientific notation with up to three significant digits
/// (1.5e-5, not 2e-5); otherwise integers without a fraction and other
/// values to six decimals at most.
fn tick(v: f64, lo: f64, hi: f64) -> String {
    let span = (hi - lo).abs();
    if v == 0.0 || v.abs() <= 1e-9 * span {
        return "0".into();
    }
    let mag = lo.abs().max(hi.abs());
    if !(1e-3..1e6).contains(&mag) {
        let s = format!("{v:.2e}");
        return match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        };
    }
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

type DrawResult<T> = Result<T, Box<dyn std::error::Error>>;

fn draw_panel<DB: DrawingBackend, Y>(
    area: &DrawingArea<DB, Shift>,
    x_range: (f64, f64),
    y_range: Y,
    y_bounds: (f64, f64),
    legend: SeriesLabelPosition,
    x_desc: &str,
    panel: &Panel,
) -> DrawResult<()>
where
    DB::ErrorType: 'static,
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
        .x_label_formatter(&|v: &f64| tick(*v, x_range.0, x_range.1))
        .y_label_formatter(&|v: &f64| tick(*v, y_bounds.0, y_bounds.1))
        .x_desc(x_desc)
        .y_desc(panel.y_desc.as_str())
        .axis_desc_style(("sans-serif", 16))
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()?;
    // A zero line where a linear panel spans 0.
    if !panel.log_y && y_bounds.0 < 0.0 && y_bounds.1 > 0.0 {
        let (x0, x1) = x_range;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(x0, 0.0), (x1, 0.0)],
            BLACK.mix(0.5).stroke_width(1),
        )))?;
    }
    for (i, s) in panel.series.iter().enumerate() {
        let color = COLORS[s.color.unwrap_or(i) % COLORS.len()];
        let band = band_polygon(&s.band, panel.log_y);
        if band.len() >= 3 {
            chart.draw_series(std::iter::once(Polygon::new(band, color.mix(0.22).filled())))?;
        }
    }
    for (i, s) in panel.series.iter().enumerate() {
        let color = COLORS[s.color.unwrap_or(i) % COLORS.len()];
        let style = color.stroke_width(2);
        let points = thin(finite(&s.points, panel.log_y));
        if !s.line {
            let anno = chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, color.stroke_width(2))))?;
            if !s.label.is_empty() {
                anno.label(s.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.stroke_width(2)));
            }
            continue;
        }
        if s.marks {
            chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
        }
        let anno = if s.dashed {
            chart.draw_series(DashedLineSeries::new(points.clone(), 8, 5, style))?
        } else {
            chart.draw_series(LineSeries::new(points.clone(), style))?
        };
        let dashed = s.dashed;
        if s.label.is_empty() {
            continue;
        }
        anno.label(s.label.as_str()).legend(move |(x, y)| {
            if dashed {
                PathElement::new(vec![(x, y), (x + 8, y)], style)
            } else {
                PathElement::new(vec![(x, y), (x + 20, y)], style)
            }
        });
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

/// Size of `fig` in pixels.
fn size(fig: &Figure) -> (u32, u32) {
    let n = fig.panels.len().max(1) as u32;
    (WIDTH, n * panel_height(fig) + 40)
}

/// Registers DejaVu Sans (built in) as the `sans-serif` family for the
/// text's layout and rasterisation, once.
fn register_font() -> DrawResult<()> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err("the built-in font DejaVu Sans could not be loaded".into())
    }
}

fn draw(path: &Path, fig: &Figure) -> DrawResult<()> {
    register_font()?;
    match file_format(path) {
        Some(FileFormat::Png) => {
            let (w, h) = size(fig);
            let mut rgb = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
                draw_on(root, fig)?;
            }
            let file = std::io::BufWriter::new(std::fs::File::create(path)?);
            let mut encoder = png::Encoder::new(file, w, h);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            // Adaptive filtering and the best compression: a three-panel
            // figure takes about a third of the bytes of the defaults.
            encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
            encoder.set_compression(png::Compression::Best);
            let mut writer = encoder.write_header()?;
            writer.write_image_data(&rgb)?;
            writer.finish()?;
            Ok(())
        }
        _ => {
            let root = SVGBackend::new(path, size(fig)).into_drawing_area();
            draw_on(root, fig)
        }
    }
}

fn draw_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure) -> DrawResult<()>
where
    DB::ErrorType: 'static,
{
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
                .flat_map(|s| {
                    let band = s
                        .band
                        .iter()
                        .flat_map(|&(x, lo, hi)| [(x, lo), (x, hi)])
                        .collect::<Vec<_>>();
                    finite(&s.points, panel.log_y)
                        .into_iter()
                        .chain(finite(&band, panel.log_y))
                })
                .map(|p| p.1)
        };
        let (lo, mut hi) = padded(ys(), panel.log_y);
        let h = legend_height(panel, panel_height(fig));
        if panel.log_y {
            let (mut legend, hidden) = legend_corner(panel, h, x_range, (lo.ln(), hi.ln()));
            if hidden > 0 && panel.legend {
                let h = h.min(0.6);
                hi = (hi.ln() + (hi.ln() - lo.ln()) * (h + 0.04) / (1.0 - h - 0.04)).exp();
                legend = legend_corner(panel, h, x_range, (lo.ln(), hi.ln())).0;
            }
            draw_panel(
                area,
                x_range,
                (lo..hi).log_scale(),
                (lo, hi),
                legend,
                &fig.x_desc,
                panel,
            )?;
        } else {
            let (mut legend, hidden) = legend_corner(panel, h, x_range, (lo, hi));
            if hidden > 0 && panel.legend {
                // No free corner: headroom over the data for the legend.
                let h = h.min(0.6);
                hi += (hi - lo) * (h + 0.04) / (1.0 - h - 0.04);
                legend = legend_corner(panel, h, x_range, (lo, hi)).0;
            }
            draw_panel(area, x_range, lo..hi, (lo, hi), legend, &fig.x_desc, panel)?;
        }
    }
    root.present()?;
    Ok(())
}

/// Writes `fig` to `path`: PNG if the name ends in `.png`, else SVG. A file
/// that cannot be written is bad input naming `--plot`.
pub fn write(path: &Path, fig: &Figure) -> Result<(), CliError> {
    draw(path, fig).map_err(|e| CliError::Input(format!("--plot: {}: {e}", path.display())))
}

/// The command's CSV output as columns by header name.
struct Columns {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Columns {
    /// The numeric columns of a command's CSV output; the `error` and
    /// `envelope` columns are dropped and an empty cell (a row that could not be computed) is
    /// NaN, which the curves skip.
    fn parse(text: &str) -> Result<Self, CliError> {
        let (header, rows) = csv::cells(text);
        let text = [csv::ERROR_COLUMN, crate::envelope::ENVELOPE_COLUMN];
        let keep: Vec<usize> = (0..header.len()).filter(|&i| !text.contains(&header[i])).collect();
        let rows = rows
            .iter()
            .enumerate()
            .map(|(r, row)| {
                keep.iter()
                    .map(|&i| match row.get(i).copied().unwrap_or("") {
                        "" => Ok(f64::NAN),
                        c => c
                            .parse::<f64>()
                            .map_err(|_| CliError::Failed(format!("--plot: row {}: '{c}' is not a number", r + 1))),
                    })
                    .collect::<Result<Vec<f64>, _>>()
            })
            .collect::<Result<_, _>>()?;
        Ok(Columns {
            header: keep.iter().map(|&i| header[i].to_string()).collect(),
            rows,
        })
    }

    fn col(&self, name: &str) -> Result<Vec<f64>, CliError> {
        let i = self
            .header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| CliError::Failed(format!("--plot: no column {name}")))?;
        Ok(self.rows.iter().map(|r| r[i]).collect())
    }

    /// A series of column `y` (SI) in `scale` over column `x`.
    fn series(&self, x: &str, y: &str, scale: Scale, label: &str) -> Result<Series, CliError> {
        let xs = self.col(x)?;
        let ys = self.col(y)?;
        Ok(Series {
            label: label.to_string(),
            points: xs.into_iter().zip(ys).map(|(x, y)| (x, scale.apply(y))).collect(),
            dashed: false,
            marks: self.rows.len() <= 30,
            line: true,
            color: None,
            band: Vec::new(),
        })
    }
}

/// A quantity without conversion (C, 1/s, rad/s, -).
const ONE: Scale = Scale {
    mul: 1.0,
    div: 1.0,
    unit: "",
};
/// A quantity with its sign reversed.
const MINUS_ONE: Scale = Scale {
    mul: -1.0,
    div: 1.0,
    unit: "",
};
const TEMPERATURE: &str = "temperature [C]";

/// A linear panel with a legend.
pub fn panel(y_desc: &str, series: Vec<Series>) -> Panel {
    Panel {
        y_desc: y_desc.to_string(),
        log_y: false,
        legend: true,
        series,
    }
}

/// `quantity [unit]` for an axis.
fn desc(quantity: &str, scale: Scale) -> String {
    format!("{quantity} [{}]", scale.unit)
}

/// `equilibrium`: displacement, chamber pressures and flows over temperature.
pub fn equilibrium(csv: &str, u: Units) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let (len, pr, q) = (u.length(), u.pressure(), u.flow());
    Ok(Figure {
        title: "Quasi-static equilibrium".into(),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            panel(
                &desc("x", len),
                vec![c.series("t_c", "x_m", len, "spool displacement x")?],
            ),
            panel(
                &desc("p", pr),
                vec![
                    c.series("t_c", "p_a_pa", pr, "chamber pressure p_a")?,
                    c.series("t_c", "p_b_pa", pr, "chamber pressure p_b")?,
                ],
            ),
            panel(
                &desc("Q", q),
                vec![
                    c.series("t_c", "q_total_m3s", q, "total flow Q_total")?,
                    c.series("t_c", "q_throt_m3s", q, "throttle flow Q_throt")?,
                    c.series("t_c", "q_branch_m3s", q, "branch flow Q_branch")?,
                ],
            ),
        ],
    })
}

/// `asymptotic`: the series beside the quasi-static displacement, and their
/// difference.
pub fn asymptotic(csv: &str, order: usize, u: Units) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let len = u.length();
    let small = u.small_length();
    let qs_si = c.series("t_c", "x_qs_m", ONE, "quasi-static x")?;
    let asym_si = c.series("t_c", "x_asym_m", ONE, "")?;
    let qs = c.series("t_c", "x_qs_m", len, "quasi-static x")?;
    let mut asym = c.series("t_c", "x_asym_m", len, &format!("asymptotic x, order {order}"))?;
    asym.dashed = true;
    let diff = Series {
        label: format!("order-{order} series minus quasi-static"),
        points: qs_si
            .points
            .iter()
            .zip(&asym_si.points)
            .map(|(q, a)| (q.0, small.apply(a.1 - q.1)))
            .collect(),
        dashed: false,
        marks: qs.marks,
        line: true,
        color: None,
        band: Vec::new(),
    };
    Ok(Figure {
        title: format!("Asymptotic displacement (order {order}) and the quasi-static one"),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            panel(&desc("x", len), vec![qs, asym]),
            panel(&desc("error", small), vec![diff]),
        ],
    })
}

/// `step`: displacement, velocity and pressures over time; `overlay` (a
/// second run's CSV and its name) is drawn dashed over each curve.
pub fn step(csv: &str, name: &str, overlay: Option<(&str, &str)>, title: &str, u: Units) -> Result<Figure, CliError> {
    let runs: Vec<(Columns, &str, bool)> = std::iter::once(Ok((Columns::parse(csv)?, name, false)))
        .chain(overlay.map(|(o, n)| Columns::parse(o).map(|c| (c, n, true))))
        .collect::<Result<_, CliError>>()?;
    let (len, vel, pr) = (u.length(), u.velocity(), u.pressure());
    let mut x = Vec::new();
    let mut v = Vec::new();
    let mut p = Vec::new();
    for (c, name, dashed) in &runs {
        let tag = |s: Series| Series {
            dashed: *dashed,
            marks: false,
            ..s
        };
        x.push(tag(c.series("time_s", "x_m", len, &format!("x, {name}"))?));
        v.push(tag(c.series("time_s", "v_m_s", vel, &format!("v, {name}"))?));
        p.push(tag(c.series("time_s", "p_a_pa", pr, &format!("p_a, {name}"))?));
        p.push(tag(c.series("time_s", "p_b_pa", pr, &format!("p_b, {name}"))?));
    }
    // Pressures: p_a and p_b of a run in two colours, the overlay in the
    // same two colours; reorder so that colours pair up by quantity.
    if p.len() == 4 {
        p.swap(1, 2);
    }
    Ok(Figure {
        title: title.to_string(),
        x_desc: "time [s]".into(),
        panels: vec![
            panel(&desc("x", len), x),
            panel(&desc("v", vel), v),
            panel(&desc("p", pr), p),
        ],
    })
}

/// `eigen`: the decay rates -Re(lambda) (log scale) and the oscillation
/// frequencies Im(lambda) of the four eigenvalues over temperature (no
/// unit depends on `--units`).
pub fn eigen(csv: &str) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let mut re = Vec::new();
    let mut im = Vec::new();
    for k in 1..=4 {
        re.push(c.series("t_c", &format!("re_{k}"), MINUS_ONE, &format!("lambda_{k}"))?);
        im.push(c.series("t_c", &format!("im_{k}"), ONE, &format!("lambda_{k}"))?);
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
                vec![
                    c.series("t_c", "zeta_plunger", ONE, "zeta, plunger with hydraulic damping")?,
                    c.series("t_c", "zeta_dominant", ONE, "zeta, dominant mode")?,
                ],
            ),
        ],
    })
}

/// `compensation`: demand against supply, the error, and the displacement
/// against the one the demand needs.
pub fn compensation(csv: &str, u: Units) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let (len, q) = (u.length(), u.flow());
    let mut required = c.series("t_c", "required_x_m", len, "x the demand requires")?;
    required.dashed = true;
    let mut demand = c.series("t_c", "demand_m3s", q, "demand (leakage + machine)")?;
    demand.dashed = true;
    Ok(Figure {
        title: "Compensation: flow supplied against the machine's demand".into(),
        x_desc: TEMPERATURE.into(),
        panels: vec![
            panel(
                &desc("Q", q),
                vec![c.series("t_c", "supply_m3s", q, "supply (total flow)")?, demand],
            ),
            panel(
                &desc("error", q),
                vec![c.series("t_c", "error_m3s", q, "supply minus demand")?],
            ),
            panel(
                &desc("x", len),
                vec![c.series("t_c", "x_m", len, "spool displacement x")?, required],
            ),
        ],
    })
}

/// Coverage factor of the bands `estimate` draws: 1.96 standard
/// uncertainties, the 95 % interval of a normal error (GUM 6.2).
pub const BAND_K: f64 = 1.96;

/// `estimate`: over time, the probe's reading and the estimated oil
/// temperature with its band, and the displacement with its band (clipped
/// to the plunger's travel `0..=stroke` [m], where the true displacement
/// lies: `docs/firmware.md`, reading the band).
pub fn estimate(csv: &str, stroke: f64, title: &str, u: Units) -> Result<Figure, CliError> {
    let c = Columns::parse(csv)?;
    let len = u.length();
    let time = c.col("time_s")?;
    let band = |y: &str, sd: &str, scale: Scale, clip: (f64, f64)| -> Result<Vec<(f64, f64, f64)>, CliError> {
        let (y, sd) = (c.col(y)?, c.col(sd)?);
        Ok(time
            .iter()
            .zip(y.iter().zip(&sd))
            .map(|(&t, (&v, &s))| {
                let (lo, hi) = ((v - BAND_K * s).max(clip.0), (v + BAND_K * s).min(clip.1));
                (t, scale.apply(lo), scale.apply(hi))
            })
            .collect())
    };
    let plain = |mut s: Series| {
        s.marks = false;
        s
    };
    let reading = plain(c.series("time_s", "t_probe_c", ONE, "probe reading")?);
    let oil = Series {
        band: band("t_oil_c", "t_oil_sd_c", ONE, (f64::NEG_INFINITY, f64::INFINITY))?,
        ..plain(c.series("time_s", "t_oil_c", ONE, "oil, estimated (band: +-1.96 u, 95 %)")?)
    };
    let x = Series {
        band: band("x_m", "x_sd_m", len, (0.0, stroke))?,
        ..plain(c.series("time_s", "x_m", len, "x, estimated (band: +-1.96 u within the stroke)")?)
    };
    Ok(Figure {
        title: title.to_string(),
        x_desc: "time [s]".into(),
        panels: vec![
            panel(
                "temperature [C]",
                vec![
                    Series {
                        color: Some(1),
                        ..reading
                    },
                    Series { color: Some(0), ..oil },
                ],
            ),
            panel(&desc("x", len), vec![x]),
        ],
    })
}

/// Most points a curve of [`monitor`] draws: a day of readings at 100 Hz
/// is 8.6 million, far beyond what a figure resolves.
pub const MONITOR_POINTS: usize = 4000;

/// `monitor`: over time, the standardised innovation of each reading the
/// monitor took (with the gate), the CUSUM (with its threshold), the
/// health factors (divider and spring, each with its 95 % band,
/// `exp(ln f +- 1.96 sd)`), and the reading's offset (with its band), from
/// the monitor's `trace`; every `n`-th reading where there are more than
/// [`MONITOR_POINTS`].
pub fn monitor(trace: &[crate::monitor::Point], pressure: bool, title: &str) -> Figure {
    use compensator::monitor::{CUSUM_THRESHOLD, GATE};
    let every = trace.len().div_ceil(MONITOR_POINTS).max(1);
    let points: Vec<&crate::monitor::Point> = trace.iter().step_by(every).collect();
    let (t0, t1) = (
        trace.first().map_or(0.0, |p| p.time_s),
        trace.last().map_or(1.0, |p| p.time_s),
    );
    let series = |label: &str, f: &dyn Fn(&compensator::monitor::HealthEstimate) -> f64| {
        Series::line(label, points.iter().map(|p| (p.time_s, f(&p.health))).collect())
    };
    let level = |label: &str, y: f64| Series {
        dashed: true,
        color: Some(1),
        ..Series::line(label, vec![(t0, y), (t1, y)])
    };
    let factor = |label: &str, v: fn(&compensator::monitor::HealthEstimate) -> (f32, f32), color: usize| Series {
        color: Some(color),
        band: points
            .iter()
            .map(|p| {
                let (f, sd) = v(&p.health);
                let (ln, sd) = (f64::from(f).ln(), f64::from(sd));
                (p.time_s, (ln - BAND_K * sd).exp(), (ln + BAND_K * sd).exp())
            })
            .collect(),
        ..series(label, &|h| f64::from(v(h).0))
    };
    let offset = Series {
        band: points
            .iter()
            .map(|p| {
                let (o, sd) = (f64::from(p.health.offset), f64::from(p.health.sd_offset));
                (p.time_s, o - BAND_K * sd, o + BAND_K * sd)
            })
            .collect(),
        ..series("offset (band: +-1.96 sd, 95 %)", &|h| f64::from(h.offset))
    };
    Figure {
        title: title.to_string(),
        x_desc: "time [s]".into(),
        panels: vec![
            panel(
                "standardised innovation [-]",
                vec![
                    series("innovation of each reading", &|h| f64::from(h.innovation)),
                    level("gate +-6", f64::from(GATE)),
                    level("", -f64::from(GATE)),
                ],
            ),
            panel(
                "CUSUM [-]",
                vec![
                    series("CUSUM (the larger side)", &|h| f64::from(h.cusum)),
                    level("threshold 10: DEVICE_CHANGED", f64::from(CUSUM_THRESHOLD)),
                ],
            ),
            panel(
                "health factor [-]",
                vec![
                    factor("divider A / A_file (band: 95 %)", |h| (h.divider, h.sd_divider), 0),
                    factor("spring c / c_file (band: 95 %)", |h| (h.spring, h.sd_spring), 2),
                ],
            ),
            panel(if pressure { "offset [Pa]" } else { "offset [m]" }, vec![offset]),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::tick;

    #[test]
    fn tick_labels_read_as_their_axis() {
        // A rounding error at zero is zero.
        assert_eq!(tick(-3.39e-21, -2.5e-5, 1.7e-5), "0");
        // One notation per axis: small quantities in scientific notation,
        // three significant digits.
        assert_eq!(tick(-1.5e-5, -2.5e-5, 1.7e-5), "-1.5e-5");
        assert_eq!(tick(1.0e-4, 0.0, 1.5e-4), "1e-4");
        assert_eq!(tick(1.25e-4, 0.0, 1.5e-4), "1.25e-4");
        assert_eq!(tick(2.0e6, 0.0, 4.5e6), "2e6");
        // Ordinary magnitudes in decimals.
        assert_eq!(tick(0.0005, 0.0, 0.001), "0.0005");
        assert_eq!(tick(40.0, 26.0, 80.0), "40");
        assert_eq!(tick(2.5, 0.0, 5.0), "2.5");
    }
}
