//! Numbers for people: `--format table` and messages round to what the
//! model and the data resolve, as the firmware's telemetry display does
//! (`xtask/src/telemetry.rs`); CSV and JSON keep every digit.
//!
//! A table column's rounding comes from its name, in one list
//! ([`RESOLUTIONS`]: the unit suffix of the column, in SI and in
//! engineering units, and the finest step a reading of that quantity
//! resolves); a fitted value is rounded to two significant digits of its
//! standard error (GUM 7.2.6), a correlation to three decimals, any other
//! number to six significant digits.

/// Column-name endings (or exact names) and the finest step a table shows
/// for them, in the column's own unit. The longest matching ending
/// applies (`_m_s` before `_m`).
pub const RESOLUTIONS: &[(&str, f64)] = &[
    // Temperatures [C]: a PT100 through the MAX31865 resolves 0.03 C.
    ("_c", 0.01),
    // Displacements: 0.01 um.
    ("_m", 1e-8),
    ("_mm", 1e-5),
    ("_m_s", 1e-6),
    ("_mm_s", 1e-3),
    ("_m_k", 1e-10),
    ("_mm_k", 1e-7),
    // Pressures: 1 Pa.
    ("_pa", 1.0),
    ("_bar", 1e-5),
    ("_sqrt_pa", 1e-3),
    ("_sqrt_bar", 1e-5),
    // Flows: 1e-10 m^3/s = 6e-6 L/min.
    ("_m3s", 1e-10),
    ("_lpm", 1e-5),
    ("_m3s_k", 1e-12),
    ("_lpm_k", 1e-7),
    ("_m2", 1e-12),
    ("_mm2", 1e-6),
    // Viscosity: 0.001 cSt.
    ("_m2s", 1e-9),
    ("_cst", 1e-3),
    // Times [s]: 1 us; percentages: 0.001 %.
    ("_s", 1e-6),
    ("_pct", 1e-3),
    // Eigenvalues, natural frequencies [1/s, rad/s], damping ratios [-].
    ("dominant_re", 1e-2),
    ("zeta", 1e-3),
    ("omega", 1e-2),
];

/// The resolution of a column by its name (see [`RESOLUTIONS`]; the
/// eigenvalue columns `re_N`, `im_N` are 0.01 1/s).
pub fn resolution(column: &str) -> Option<f64> {
    if (column.starts_with("re_") || column.starts_with("im_")) && column[3..].bytes().all(|b| b.is_ascii_digit()) {
        return Some(1e-2);
    }
    RESOLUTIONS
        .iter()
        .filter(|(end, _)| match end.strip_prefix('_') {
            Some(_) => column.len() > end.len() && column.ends_with(end),
            None => column.starts_with(end),
        })
        .max_by_key(|(end, _)| end.len())
        .map(|&(_, r)| r)
}

/// `v` with `decimals` decimals, trailing zeros and a lone sign of a
/// rounded zero dropped: `short(0.008700000000000001, 4)` is `0.0087`.
pub fn short(v: f64, decimals: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let s = fixed(v, decimals);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// `v` with `decimals` decimals, without a sign on a rounded zero.
pub fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// `v` to `digits` significant digits, in plain form for ordinary
/// magnitudes (1e-4 to 1e7) and with an exponent otherwise: `sig(1.5000000000000001e-4, 4)`
/// is `0.00015`, `sig(23116.42, 3)` is `23100`, `sig(3.2e-9, 2)` is `3.2e-9`.
pub fn sig(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = digits.max(1);
    let exp = v.abs().log10().floor() as i32;
    if !(-4..7).contains(&exp) {
        let s = format!("{:.*e}", digits - 1, v);
        // `1.50e-4` -> `1.5e-4`.
        return match s.split_once('e') {
            Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            _ => s,
        };
    }
    let decimals = (digits as i32 - 1 - exp).max(0) as usize;
    let rounded = if decimals == 0 {
        let scale = 10f64.powi(exp + 1 - digits as i32);
        (v / scale).round() * scale
    } else {
        v
    };
    short(rounded, decimals)
}

/// How one column of a table is printed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    /// Fixed decimals for the column's resolution.
    Step(f64),
    /// Rounded as the uncertainty in the column with this index.
    ByUncertainty(usize),
    /// Significant digits.
    Sig(usize),
    /// A correlation coefficient: three decimals.
    Correlation,
}

fn decimals_of(step: f64) -> usize {
    (-step.log10().floor()).max(0.0) as usize
}

/// The rule of each column of `header`.
fn rules(header: &[&str]) -> Vec<Rule> {
    let index = |name: &str| header.iter().position(|h| *h == name);
    header
        .iter()
        .map(|h| match *h {
            "value" | "ci95_low" | "ci95_high" => index("std_error").map_or(Rule::Sig(6), Rule::ByUncertainty),
            "std_error" | "rel_std_error" => Rule::Sig(2),
            "residual_rms" => Rule::Sig(3),
            h if h.starts_with("corr_") => Rule::Correlation,
            h => resolution(h).map_or(Rule::Sig(6), Rule::Step),
        })
        .collect()
}

/// One cell by its column's rule (`row` gives the uncertainty's cell).
fn cell(c: &str, rule: Rule, row: &[&str]) -> String {
    // Words, empty cells and whole numbers (counts, variant numbers) stay.
    let Ok(v) = c.parse::<f64>() else {
        return c.to_string();
    };
    let whole = c.bytes().all(|b| b.is_ascii_digit() || b == b'-');
    if !v.is_finite() || whole && matches!(rule, Rule::Sig(_)) {
        return c.to_string();
    }
    match rule {
        Rule::Step(_) if v.abs() >= 1e9 => sig(v, 6),
        Rule::Step(step) => fixed(v, decimals_of(step)),
        Rule::Sig(n) => sig(v, n),
        Rule::Correlation => fixed(v, 3),
        Rule::ByUncertainty(i) => match row.get(i).and_then(|u| u.parse::<f64>().ok()) {
            Some(u) if u > 0.0 && u.is_finite() => {
                // Two significant digits of the uncertainty fix the last digit.
                let last = u.log10().floor() as i32 - 1;
                if last < 0 && v.abs() < 1e7 {
                    fixed(v, (-last) as usize)
                } else {
                    let digits = (v.abs().log10().floor() as i32 - last + 1).max(1) as usize;
                    sig(v, digits)
                }
            }
            _ => sig(v, 6),
        },
    }
}

/// A header for reading: a correlation column keeps the key of its
/// parameter (`corr_fluid.walther_a` -> `corr_walther_a`).
fn heading(h: &str) -> String {
    match h.strip_prefix("corr_").and_then(|p| p.split_once('.')) {
        Some((_, key)) => format!("corr_{key}"),
        None => h.to_string(),
    }
}

/// A table's header and rows of cells (CSV as the commands write it,
/// `crate::csv::cells`) as right-aligned columns separated by two spaces, each number
/// rounded by its column's rule.
pub fn table(header: &[&str], rows: &[Vec<&str>]) -> String {
    let rules = rules(header);
    let mut grid: Vec<Vec<String>> = vec![header.iter().map(|h| heading(h)).collect()];
    for row in rows {
        grid.push(
            row.iter()
                .enumerate()
                .map(|(i, c)| cell(c, rules.get(i).copied().unwrap_or(Rule::Sig(6)), row))
                .collect(),
        );
    }
    let columns = grid.iter().map(Vec::len).max().unwrap_or(0);
    let width: Vec<usize> = (0..columns)
        .map(|i| {
            grid.iter()
                .filter_map(|r| r.get(i))
                .map(|c| c.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for row in &grid {
        let line: Vec<String> = row.iter().zip(&width).map(|(c, w)| format!("{c:>w$}")).collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_lose_their_float_noise() {
        assert_eq!(short(0.008700000000000001, 4), "0.0087");
        assert_eq!(short(-0.00001, 3), "0");
        assert_eq!(sig(1.5000000000000001e-4, 4), "0.00015");
        assert_eq!(sig(0.0016500000000000002, 4), "0.00165");
        assert_eq!(sig(23116.42, 3), "23100");
        assert_eq!(sig(3.2e-9, 2), "3.2e-9");
        assert_eq!(sig(1e308, 3), "1e308");
    }

    #[test]
    fn columns_round_to_their_quantity() {
        assert_eq!(resolution("x_m"), Some(1e-8));
        assert_eq!(resolution("v_m_s"), Some(1e-6));
        assert_eq!(resolution("x_30c_m"), Some(1e-8));
        assert_eq!(resolution("overshoot_pct"), Some(1e-3));
        assert_eq!(resolution("re_1"), Some(1e-2));
        assert_eq!(resolution("t_c"), Some(1e-2));
        assert_eq!(resolution("plunger.mass"), None);
        let table = |csv: &str| {
            let (h, r) = crate::csv::cells(csv);
            super::table(&h, &r)
        };
        let t = table("t_c,x_m,overshoot_pct,error\n30,0.00123456789,3.07e-8,\n40.5,0.0015,0,x\n");
        assert_eq!(
            t,
            "  t_c         x_m  overshoot_pct  error\n30.00  0.00123457          0.000\n40.50  0.00150000          0.000      x\n"
        );
        // A fitted value to two digits of its standard error.
        let t = table("parameter,value,std_error\nplunger.spring_rate,25683.9511,463.04\na,13.40612,2.1836\n");
        assert!(
            t.contains("25680") && t.contains("460") && t.contains("13.4") && t.contains("2.2"),
            "{t}"
        );
    }
}
