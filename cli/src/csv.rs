//! CSV output with a header row; numbers in Rust's shortest round-trip form
//! (`f64`'s `Display`), so that a value read back is bit-identical.

use std::fmt::Write;

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
            let _ = write!(self.text, "{v}");
        }
        self.text.push('\n');
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
