//! CSV output with a header row; numbers in Rust's shortest round-trip form
//! (`f64`'s `Display`), so that a value read back is bit-identical.

use std::fmt::Write;

/// A CSV table built in memory and printed only when complete, so that a
/// failure half-way leaves standard output empty.
///
/// A row that could not be computed ([`Table::row_error`]) keeps its
/// leading cells (the temperature, say), leaves the others empty and says
/// why in a last column `error`, which the table gains with its first
/// such row (a table without failures has no `error` column).
#[derive(Debug, Default, Clone)]
pub struct Table {
    text: String,
    columns: usize,
    has_error: bool,
}

/// Name of the column that says why a row could not be computed.
pub const ERROR_COLUMN: &str = "error";

/// `message` as one CSV cell: commas become semicolons and line breaks
/// spaces, so that the cell needs no quoting; never empty.
pub fn error_cell(message: &str) -> String {
    let cell: String = message
        .chars()
        .map(|c| match c {
            ',' => ';',
            '\n' | '\r' => ' ',
            c => c,
        })
        .collect();
    if cell.trim().is_empty() {
        "failed".to_string()
    } else {
        cell.trim().to_string()
    }
}

impl Table {
    /// A table with the given header.
    pub fn new(header: &[&str]) -> Self {
        let mut t = Table {
            text: String::new(),
            columns: header.len(),
            has_error: false,
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
            let _ = write!(self.text, "{v}");
        }
        if self.has_error {
            self.text.push(',');
        }
        self.text.push('\n');
    }

    /// Appends a row of cells already formatted (numbers as `{}` of `f64`,
    /// `true`/`false`, text without commas); panics in debug builds on a
    /// wrong width.
    pub fn row_cells(&mut self, cells: &[String]) {
        debug_assert_eq!(cells.len(), self.columns);
        self.text.push_str(&cells.join(","));
        if self.has_error {
            self.text.push(',');
        }
        self.text.push('\n');
    }

    /// Appends a row that could not be computed: its first cells `leading`
    /// (e.g. the temperature), empty cells for the rest, and `message` in
    /// the `error` column (added to the header and to the rows so far
    /// with this first failure).
    pub fn row_error(&mut self, leading: &[f64], message: &str) {
        debug_assert!(leading.len() <= self.columns);
        if !self.has_error {
            self.has_error = true;
            let mut text = String::with_capacity(self.text.len() + 16);
            for (i, line) in self.text.lines().enumerate() {
                text.push_str(line);
                text.push_str(if i == 0 { ",error\n" } else { ",\n" });
            }
            self.text = text;
        }
        let mut cells: Vec<String> = leading.iter().map(|v| format!("{v}")).collect();
        cells.resize(self.columns, String::new());
        cells.push(error_cell(message));
        self.text.push_str(&cells.join(","));
        self.text.push('\n');
    }

    /// Whether some row could not be computed.
    pub fn has_errors(&self) -> bool {
        self.has_error
    }

    /// The CSV text.
    pub fn as_str(&self) -> &str {
        &self.text
    }
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

/// Splits CSV text (as written by [`Table`]: no quoted cells) into its
/// header and rows of cells.
pub fn cells(text: &str) -> (Vec<&str>, Vec<Vec<&str>>) {
    let mut lines = text.lines().filter(|l| !l.is_empty());
    let header = lines.next().map(|l| l.split(',').collect()).unwrap_or_default();
    (header, lines.map(|l| l.split(',').collect()).collect())
}

/// A cell as a JSON value: a finite number, `true`/`false`, `null` for a
/// non-finite number (JSON has none) or an empty cell (a row that could not
/// be computed), else a string.
fn json_value(cell: &str) -> serde_json::Value {
    use serde_json::Value;
    match cell {
        "" => Value::Null,
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

/// Rows of CSV text (as written by [`Table`]) whose `error` cell is not
/// empty, and all rows: (failed, total).
pub fn failed_rows(text: &str) -> (usize, usize) {
    let (header, rows) = cells(text);
    let Some(col) = header.iter().position(|h| *h == ERROR_COLUMN) else {
        return (0, rows.len());
    };
    let failed = rows
        .iter()
        .filter(|r| r.get(col).is_some_and(|c| !c.is_empty()))
        .count();
    (failed, rows.len())
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
