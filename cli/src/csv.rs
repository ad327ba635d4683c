//! CSV output with a header row; numbers in Rust's shortest round-trip form,
//! so that a value read back is bit-identical, and compact ([`number`]).

/// A CSV table built in memory and printed only when complete, so that a
/// failure half-way leaves standard output empty.
#[derive(Debug, Default, Clone)]
pub struct Table {
    text: String,
    columns: usize,
}

impl Table {
    /// A table with the given header.
    pub fn new(header: &[&str]) -> Self {
        let mut t = Table {
            text: String::new(),
            columns: header.len(),
        };
        t.text.push_str(&header.join(","));
        t.text.push('\n');
        t
    }

    /// Appends a row of numbers; panics in debug builds on a wrong width.
    pub fn row(&mut self, values: &[f64]) {
        debug_assert_eq!(values.len(), self.columns);
        for (i, v) in values.iter().enumerate() {
            if i > 0 {
                self.text.push(',');
            }
            self.text.push_str(&number(*v));
        }
        self.text.push('\n');
    }

    /// The CSV text.
    pub fn as_str(&self) -> &str {
        &self.text
    }
}

/// `v` as the shorter of `f64`'s two shortest round-trip forms: positional
/// (`Display`: `1`, `0.25`, `-12369.4`) or with an exponent (`Debug`:
/// `4.5e-6`, `1e300`), so that no cell spells out the zeros of a tiny or
/// huge value (`0.00000000000000000039928` was 38 characters; at most 24
/// now: sign, 17 digits, point and a 4-character exponent).
pub fn number(v: f64) -> String {
    let (plain, exp) = (format!("{v}"), format!("{v:?}"));
    if exp.len() < plain.len() { exp } else { plain }
}

/// Parses CSV text with a header row into (header, rows of numbers).
/// Lines starting with `#` are comments.
pub fn parse(text: &str) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let mut lines = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .ok_or("empty CSV")?
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let row: Vec<f64> = line
            .split(',')
            .map(|s| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("row {}: '{}' is not a number", i + 1, s.trim()))
            })
            .collect::<Result<_, _>>()?;
        if row.len() != header.len() {
            return Err(format!(
                "row {}: {} columns, header has {}",
                i + 1,
                row.len(),
                header.len()
            ));
        }
        rows.push(row);
    }
    Ok((header, rows))
}

/// Output format of a table: the CSV itself, JSON (an array of one object
/// per row, keyed by the header), or aligned columns for a terminal.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Comma-separated values with a header row.
    #[default]
    Csv,
    /// A JSON array of objects, one per row, keyed by column name.
    Json,
    /// Right-aligned columns separated by two spaces.
    Table,
}

/// Splits CSV text (as written by [`Table`]) into its header and rows of cells.
fn cells(text: &str) -> (Vec<&str>, Vec<Vec<&str>>) {
    let mut lines = text.lines().filter(|l| !l.is_empty());
    let header = lines.next().map(|l| l.split(',').collect()).unwrap_or_default();
    (header, lines.map(|l| l.split(',').collect()).collect())
}

/// A cell as a JSON value: a finite number, `true`/`false`, `null` for a
/// non-finite number (JSON has none), else a string.
fn json_value(cell: &str) -> serde_json::Value {
    use serde_json::Value;
    match cell {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ if !cell.is_empty() && cell.bytes().all(|b| b.is_ascii_digit() || b == b'-') => {
            cell.parse::<i64>().map_or_else(|_| json_value_f64(cell), Value::from)
        }
        _ => json_value_f64(cell),
    }
}

/// A non-integer cell as a JSON number, `null` or string.
fn json_value_f64(cell: &str) -> serde_json::Value {
    use serde_json::Value;
    match cell.parse::<f64>() {
        Ok(v) => serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number),
        Err(_) => Value::String(cell.to_string()),
    }
}

/// Renders CSV text with a header row in `format`.
pub fn render(text: &str, format: Format) -> String {
    match format {
        Format::Csv => text.to_string(),
        Format::Json => {
            // Objects written by hand so that keys keep the header's order.
            let (header, rows) = cells(text);
            let key = |h: &str| serde_json::Value::String(h.to_string()).to_string();
            let objects: Vec<String> = rows
                .iter()
                .map(|row| {
                    let fields: Vec<String> = header
                        .iter()
                        .zip(row)
                        .map(|(h, c)| format!("{}: {}", key(h), json_value(c)))
                        .collect();
                    format!("  {{{}}}", fields.join(", "))
                })
                .collect();
            if objects.is_empty() {
                "[]\n".to_string()
            } else {
                format!("[\n{}\n]\n", objects.join(",\n"))
            }
        }
        Format::Table => {
            let (header, rows) = cells(text);
            let mut width: Vec<usize> = header.iter().map(|h| h.len()).collect();
            for row in &rows {
                for (w, c) in width.iter_mut().zip(row) {
                    *w = (*w).max(c.len());
                }
            }
            let mut out = String::new();
            for row in std::iter::once(&header).chain(&rows) {
                let line: Vec<String> = row.iter().zip(&width).map(|(c, w)| format!("{c:>w$}")).collect();
                out.push_str(&line.join("  "));
                out.push('\n');
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_compact_and_read_back_exactly() {
        for (v, want) in [
            (1.0, "1"),
            (0.25, "0.25"),
            (-12369.436589746598, "-12369.436589746598"),
            (-3.9928418951076473e-19, "-3.9928418951076473e-19"),
            (4.5e-6, "4.5e-6"),
            (1e300, "1e300"),
            (f64::MIN_POSITIVE, "2.2250738585072014e-308"),
            (5e-324, "5e-324"),
            (0.0, "0"),
        ] {
            assert_eq!(number(v), want);
            assert_eq!(number(v).parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
        // Never longer than 24 characters.
        let mut x = 1.2345678901234567e-300;
        while x < 1e300 {
            assert!(number(x).len() <= 24 && number(-x).len() <= 24, "{}", number(-x));
            x *= 13.7;
        }
    }
}
