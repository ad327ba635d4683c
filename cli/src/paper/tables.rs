//! The paper's published tables (`data/paper/`), Table 1 inverted for the
//! property `A`, and a parameter set's residuals against both tables.
//!
//! * [`Table1`]: `p_b - p_a` [bar] at 30-80 C for dp = 4, 5, 6 bar.
//! * [`Table2`]: quasi-static and "asymptotic" displacement [mm] at 30-80 C.

use crate::csv;
use compensator::Params;
use compensator::equilibrium::{equilibrium, pressure_difference};
use std::path::Path;

/// One bar in pascals.
pub const BAR: f64 = 1.0e5;

/// Table 1: `p_b - p_a` [bar] by temperature and pressure drop.
#[derive(Debug, Clone, PartialEq)]
pub struct Table1 {
    /// Temperatures [C].
    pub temps: Vec<f64>,
    /// Pressure drops [bar] of the columns.
    pub drops_bar: Vec<f64>,
    /// `values[i][j]`: at `temps[i]`, drop `drops_bar[j]` [bar].
    pub values: Vec<Vec<f64>>,
}

/// Table 2: displacements [mm].
#[derive(Debug, Clone, PartialEq)]
pub struct Table2 {
    /// Temperatures [C].
    pub temps: Vec<f64>,
    /// Quasi-static column [mm].
    pub x_qs_mm: Vec<f64>,
    /// "Asymptotic" column [mm].
    pub x_asym_mm: Vec<f64>,
}

/// The text of a data file.
fn read_file(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// A table of finite numbers whose first column is `t_c`, with at least two
/// rows (the fits and the Walther start need two temperatures).
fn read(path: &Path, text: &str) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let (header, rows) = csv::parse(text).map_err(|e| format!("{}: {e}", path.display()))?;
    if header.first().map(String::as_str) != Some("t_c") {
        return Err(format!("{}: the first column must be t_c", path.display()));
    }
    if rows.len() < 2 {
        return Err(format!(
            "{}: at least two rows needed, found {}",
            path.display(),
            rows.len()
        ));
    }
    if let Some(i) = rows.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
        return Err(format!("{}: row {}: not a finite number", path.display(), i + 1));
    }
    Ok((header, rows))
}

impl Table1 {
    /// Reads `t_c,dp_ab_<N>bar,...`.
    pub fn load(path: &Path) -> Result<Self, String> {
        Self::parse(path, &read_file(path)?)
    }

    /// As [`Self::load`], from the text of the file `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, String> {
        let (header, rows) = read(path, text)?;
        if header.len() < 2 {
            return Err(format!("{}: no dp_ab_<N>bar column", path.display()));
        }
        let drops_bar = header[1..]
            .iter()
            .map(|h| {
                h.strip_prefix("dp_ab_")
                    .and_then(|s| s.strip_suffix("bar"))
                    .and_then(|s| s.parse::<f64>().ok())
                    .ok_or_else(|| format!("{}: column '{h}' is not dp_ab_<N>bar", path.display()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Table1 {
            temps: rows.iter().map(|r| r[0]).collect(),
            drops_bar,
            values: rows.iter().map(|r| r[1..].to_vec()).collect(),
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.temps.len() * self.drops_bar.len()
    }

    /// `true` without points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Table2 {
    /// Reads `t_c,x_qs_mm,x_asym_mm,...`.
    pub fn load(path: &Path) -> Result<Self, String> {
        Self::parse(path, &read_file(path)?)
    }

    /// As [`Self::load`], from the text of the file `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Self, String> {
        let (header, rows) = read(path, text)?;
        let col = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| format!("{}: no column {name}", path.display()))
        };
        let (qs, asym) = (col("x_qs_mm")?, col("x_asym_mm")?);
        Ok(Table2 {
            temps: rows.iter().map(|r| r[0]).collect(),
            x_qs_mm: rows.iter().map(|r| r[qs]).collect(),
            x_asym_mm: rows.iter().map(|r| r[asym]).collect(),
        })
    }
}

/// The tables shipped in `data/paper/`, found from the workspace root.
pub fn paper_tables(root: &Path) -> Result<(Table1, Table2), String> {
    let dir = root.join("data").join("paper");
    Ok((
        Table1::load(&dir.join("table1.csv"))?,
        Table2::load(&dir.join("table2.csv"))?,
    ))
}

/// Table 1 inverted for `A`: `A^2 = (dp - y)^2 / (2 (dp + y))` [Pa], per column.
#[derive(Debug, Clone)]
pub struct Inversion {
    /// `a[i][j]`: `A` at `temps[i]` from column `j` [sqrt(Pa)].
    pub a: Vec<Vec<f64>>,
    /// Per temperature: (max - min) / mean of the columns' `A`.
    pub spread: Vec<f64>,
}

/// Inverts each column of Table 1 for `A(t)` (`docs/model.md` section 4).
pub fn invert_table1(t1: &Table1) -> Inversion {
    let a: Vec<Vec<f64>> = t1
        .values
        .iter()
        .map(|row| {
            row.iter()
                .zip(&t1.drops_bar)
                .map(|(&y, &dp)| ((dp - y).powi(2) / (2.0 * (dp + y)) * BAR).sqrt())
                .collect()
        })
        .collect();
    let spread = a
        .iter()
        .map(|row| {
            let (lo, hi) = row
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
            let mean = row.iter().sum::<f64>() / row.len() as f64;
            (hi - lo) / mean
        })
        .collect();
    Inversion { a, spread }
}

/// Model residuals against Table 1 [bar], row by row (temperature-major).
/// A point the model cannot evaluate gives an infinite residual.
pub fn table1_residuals(params: &Params<f64>, t1: &Table1) -> Vec<f64> {
    let mut r = Vec::with_capacity(t1.len());
    for (i, &t) in t1.temps.iter().enumerate() {
        let fluid = params.oil.state(t);
        for (j, &dp) in t1.drops_bar.iter().enumerate() {
            let model = match fluid {
                Ok(f) => pressure_difference(compensator::equilibrium::a_parameter(params, &f), dp * BAR) / BAR,
                Err(_) => f64::INFINITY,
            };
            r.push(model - t1.values[i][j]);
        }
    }
    r
}

/// Model residuals against Table 2's quasi-static column [mm] at the
/// parameter set's own pressure drop.
pub fn table2_residuals(params: &Params<f64>, t2: &Table2) -> Vec<f64> {
    t2.temps
        .iter()
        .zip(&t2.x_qs_mm)
        .map(|(&t, &x)| match equilibrium(params, t) {
            Ok(e) => e.x * 1e3 - x,
            Err(_) => f64::INFINITY,
        })
        .collect()
}

/// Tables 1 and 2 from `data`'s `table1.csv` and `table2.csv`, or the
/// copies built into the binary (`data/paper/`) without `data`.
pub fn load_tables(data: Option<&Path>) -> Result<(Table1, Table2), String> {
    match data {
        Some(dir) => Ok((
            Table1::load(&dir.join("table1.csv"))?,
            Table2::load(&dir.join("table2.csv"))?,
        )),
        None => Ok((
            Table1::parse(Path::new("data/paper/table1.csv"), crate::input::TABLE1_CSV)?,
            Table2::parse(Path::new("data/paper/table2.csv"), crate::input::TABLE2_CSV)?,
        )),
    }
}
