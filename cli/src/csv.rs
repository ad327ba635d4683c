//! CSV output with a header row; numbers in Rust's shortest round-trip form,
//! so that a value read back is bit-identical, and compact ([`number`]).

/// A CSV table built in memory and printed only when complete, so that a
/// failure half-way leaves standard output empty.
///
/// A table whose rows can fail ([`Table::new`]) ends with an `error`
/// column, empty where the row was computed: a row that could not be
/// ([`Table::row_error`]) keeps its leading cells (the temperature, say),
/// leaves the others empty and says why there. The header is the same
/// whether rows fail or not. A table whose rows cannot fail one by one
/// (a time series: the run fails whole) has no such column
/// ([`Table::complete`]).
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
    /// A table with the given header and an `error` column after it.
    pub fn new(header: &[&str]) -> Self {
        let mut t = Table::complete(header);
        t.has_error = true;
        t.text.insert_str(t.text.len() - 1, &format!(",{ERROR_COLUMN}"));
        t
    }

    /// A table with the given header and no `error` column: every row is
    /// computed or the command fails.
    pub fn complete(header: &[&str]) -> Self {
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
            self.text.push_str(&number(*v));
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

    /// A row per temperature of `temps`: `t` and the cells `cells(t)`
    /// computes, or, where it fails, `t` and the error's message
    /// ([`Self::row_error`]).
    pub fn rows_at<E: std::fmt::Display>(&mut self, temps: &[f64], mut cells: impl FnMut(f64) -> Result<Vec<f64>, E>) {
        for &t in temps {
            match cells(t) {
                Ok(c) => {
                    let mut row = Vec::with_capacity(c.len() + 1);
                    row.push(t);
                    row.extend(c);
                    self.row(&row);
                }
                Err(e) => self.row_error(&[t], &e.to_string()),
            }
        }
    }

    /// Appends a row that could not be computed: its first cells `leading`
    /// (e.g. the temperature), empty cells for the rest, and `message` in
    /// the `error` column (a table made by [`Table::complete`] has none:
    /// a bug, caught in debug builds; the message then goes in the last cell).
    pub fn row_error(&mut self, leading: &[f64], message: &str) {
        debug_assert!(leading.len() <= self.columns);
        debug_assert!(self.has_error, "row_error on a table without an error column");
        let mut cells: Vec<String> = leading.iter().map(|v| format!("{v}")).collect();
        cells.resize(self.columns, String::new());
        if self.has_error {
            cells.push(error_cell(message));
        } else if let Some(last) = cells.last_mut() {
            *last = error_cell(message);
        }
        self.text.push_str(&cells.join(","));
        self.text.push('\n');
    }

    /// Whether some row could not be computed.
    pub fn has_errors(&self) -> bool {
        failed_rows(&self.text).0 > 0
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

/// A table of numbers read from a data file: its header and its rows, with
/// each row's line number in the file (for error messages).
#[derive(Debug, Clone, PartialEq)]
pub struct Numeric {
    /// Column names, trimmed.
    pub header: Vec<String>,
    /// Rows of finite numbers, each as wide as the header.
    pub rows: Vec<Vec<f64>>,
    /// Line of each row in the file (1-based).
    pub lines: Vec<u64>,
}

impl Numeric {
    /// Index of column `name`, if present.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }
}

/// The field separator of a data file: `;` or a tab when its header line
/// (the first line that is neither blank nor a `#` comment) has one and no
/// comma, else `,`.
fn detect_delimiter(text: &str) -> u8 {
    let header = text
        .lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .unwrap_or("");
    if header.contains(',') {
        b','
    } else if header.contains(';') {
        b';'
    } else if header.contains('\t') {
        b'\t'
    } else {
        b','
    }
}

/// Reads a data file's text (as a spreadsheet exports it) into numbers,
/// with the `csv` crate: a UTF-8 byte-order mark is skipped, the separator
/// is detected (`,`, `;` or tab, [`detect_delimiter`]), cells may be quoted
/// and padded with spaces, lines starting with `#` are comments, blank
/// lines are skipped. With `;` or tab separators a decimal comma (`0,5`) is
/// read as a decimal point, as such spreadsheets write it.
///
/// Errors (one line each): an empty file, a row whose width differs from
/// the header's, a cell that is not a finite number; a cell's error names
/// its data row (1-based, the header not counted), its line in the file
/// and its column by name.
pub fn read_numeric(text: &str) -> Result<Numeric, String> {
    read(text, true, None)
}

/// [`read_numeric`] reading only the columns named in `wanted`: a cell of
/// any other column (a spreadsheet's comment or date column) is not parsed
/// and reads as `NaN`, so "other columns are ignored" holds for text too.
///
/// Errors: those of [`read_numeric`] for the wanted columns, and a wanted
/// column that appears twice in the header (which one is meant is unknown).
pub fn read_columns(text: &str, wanted: &[&str]) -> Result<Numeric, String> {
    read(text, true, Some(wanted))
}

/// [`read_columns`] where an empty cell (or `NaN`) of a column in `sparse`
/// reads as `NaN` (no value on that row: a log whose sensors read at different
/// rates), and a cell of a column in `unchecked` is not held to its
/// plausible range of [`crate::data::DATA_COLUMNS`] (the caller checks it
/// against a range of its own, the device file's).
///
/// # Errors
///
/// As [`read_columns`].
pub fn read_columns_with(text: &str, wanted: &[&str], sparse: &[&str], unchecked: &[&str]) -> Result<Numeric, String> {
    read_spec(text, true, Some(wanted), sparse, unchecked)
}

/// The header row's names of a data file (as [`read_numeric`] reads it:
/// byte-order mark, separator, comments), without reading its rows.
///
/// # Errors
///
/// The `csv` crate's error on a header it cannot read.
pub fn header(text: &str) -> Result<Vec<String>, String> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut reader = ::csv::ReaderBuilder::new()
        .delimiter(detect_delimiter(text))
        .comment(Some(b'#'))
        .trim(::csv::Trim::All)
        .flexible(true)
        .has_headers(true)
        .from_reader(text.as_bytes());
    Ok(reader
        .headers()
        .map_err(|e| format!("header: {e}"))?
        .iter()
        .map(str::to_string)
        .collect())
}

/// [`read_numeric`], accepting `NaN` and infinities unless `finite_only`,
/// parsing only the columns in `wanted` (all when `None`).
fn read(text: &str, finite_only: bool, wanted: Option<&[&str]>) -> Result<Numeric, String> {
    read_spec(text, finite_only, wanted, &[], &[])
}

/// [`read`] with the `sparse` and `unchecked` columns of
/// [`read_columns_with`].
fn read_spec(
    text: &str,
    finite_only: bool,
    wanted: Option<&[&str]>,
    sparse: &[&str],
    unchecked: &[&str],
) -> Result<Numeric, String> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let delimiter = detect_delimiter(text);
    let mut reader = ::csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .comment(Some(b'#'))
        .trim(::csv::Trim::All)
        .flexible(true)
        .has_headers(true)
        .from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| format!("header: {e}"))?
        .iter()
        .map(str::to_string)
        .collect();
    if header.iter().all(String::is_empty) {
        return Err("empty file: no header row".into());
    }
    if let Some(w) = wanted {
        for name in w {
            if header.iter().filter(|h| h == name).count() > 1 {
                return Err(format!(
                    "column {name} appears twice in the header ({})",
                    header.join(",")
                ));
            }
        }
    }
    let parsed_column: Vec<bool> = header
        .iter()
        .map(|h| wanted.is_none_or(|w| w.contains(&h.as_str())))
        .collect();
    let mut out = Numeric {
        header,
        rows: Vec::new(),
        lines: Vec::new(),
    };
    for (i, record) in reader.records().enumerate() {
        let row_no = i + 1;
        let record = record.map_err(|e| format!("row {row_no}: {e}"))?;
        let line = record.position().map_or(0, |p| p.line());
        if record.iter().all(str::is_empty) {
            continue;
        }
        if record.len() != out.header.len() {
            return Err(format!(
                "row {row_no} (line {line}): {} cells, the header has {} columns",
                record.len(),
                out.header.len()
            ));
        }
        let row = record
            .iter()
            .zip(&out.header)
            .zip(&parsed_column)
            .map(|((cell, name), &parse)| {
                if !parse || ((cell.is_empty() || cell.eq_ignore_ascii_case("nan")) && sparse.contains(&name.as_str()))
                {
                    return Ok(f64::NAN);
                }
                let parsed = cell.parse::<f64>().or_else(|e| {
                    if delimiter != b',' && cell.matches(',').count() == 1 && !cell.contains('.') {
                        cell.replace(',', ".").parse::<f64>()
                    } else {
                        Err(e)
                    }
                });
                match parsed {
                    Ok(v) if wanted.is_some() && v.is_finite() && !unchecked.contains(&name.as_str()) => {
                        match crate::data::column(name) {
                            Some(col) => {
                                crate::data::check(col, v, &format!("row {row_no} (line {line}), column {name}"))
                                    .map(|()| v)
                            }
                            None => Ok(v),
                        }
                    }
                    Ok(v) if v.is_finite() || !finite_only => Ok(v),
                    Ok(_) => Err(format!(
                        "row {row_no} (line {line}), column {name}: '{cell}' is not a finite number"
                    )),
                    Err(_) => Err(format!(
                        "row {row_no} (line {line}), column {name}: '{cell}' is not a number"
                    )),
                }
            })
            .collect::<Result<Vec<f64>, String>>()?;
        out.rows.push(row);
        out.lines.push(line);
    }
    Ok(out)
}

/// Parses CSV text with a header row into (header, rows of numbers), as
/// [`read_numeric`] but accepting `NaN` and infinities (a command's own
/// output may hold them).
pub fn parse(text: &str) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let t = read(text, false, None)?;
    Ok((t.header, t.rows))
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
    /// Aligned columns for reading, each number rounded to what its
    /// quantity resolves (csv and json keep every digit).
    Table,
}

/// Splits CSV text (as written by [`Table`]: no quoted cells) into its
/// header and rows of cells.
pub fn cells(text: &str) -> (Vec<&str>, Vec<Vec<&str>>) {
    let mut lines = text.lines().filter(|l| !l.is_empty());
    let header = lines.next().map(|l| l.split(',').collect()).unwrap_or_default();
    (header, lines.map(|l| l.split(',').collect()).collect())
}

/// A column whose cells are text however they read: a unit's symbol
/// (`unit`, `residual_unit`), where a dimensionless value's is `1`. JSON
/// writes its cells as strings, as the CSV's `Pa` and `m` are.
pub fn is_text_column(name: &str) -> bool {
    name == "unit" || name.ends_with("_unit")
}

/// A cell of the column `column` as a JSON value: `null` for an empty cell
/// (a row that could not be computed, a parameter `identify` could not
/// determine), a string in a text column ([`is_text_column`]), else a
/// finite number, `true`/`false`, `null` for a non-finite number (JSON has
/// none), or a string.
fn json_value(column: &str, cell: &str) -> serde_json::Value {
    use serde_json::Value;
    match cell {
        "" => Value::Null,
        _ if is_text_column(column) => Value::String(cell.to_string()),
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
                        .map(|(h, c)| format!("{}: {}", key(h), json_value(h, c)))
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
            crate::display::table(&header, &rows)
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

    #[test]
    fn reads_what_spreadsheets_write() {
        let plain = read_numeric("t_c,x_m\n30,0.5\n40,0.75\n").unwrap();
        assert_eq!(plain.rows, [[30.0, 0.5], [40.0, 0.75]]);
        assert_eq!(plain.lines, [2, 3]);
        // BOM, `;`, quotes, padding, decimal commas, CRLF, comments, blank lines.
        let sheet =
            read_numeric("\u{feff}# exported\r\n\"t_c\";\"x_m\"\r\n\r\n\"30\"; 0,5\r\n 40 ;\"0,75\"\r\n").unwrap();
        assert_eq!(sheet.header, plain.header);
        assert_eq!(sheet.rows, plain.rows);
        let tabs = read_numeric("t_c\tx_m\n30\t0.5\n40\t0,75\n").unwrap();
        assert_eq!(tabs.rows, plain.rows);
        // With `,` separators a decimal comma is a column break, so a bad row.
        let e = read_numeric("t_c,x_m\n30,0,5\n").unwrap_err();
        assert!(e.contains("row 1 (line 2): 3 cells"), "{e}");
    }

    #[test]
    fn errors_name_row_line_and_column() {
        let e = read_numeric("# c\nt_c,x_m\n30,0.5\n40,x\n").unwrap_err();
        assert_eq!(e, "row 2 (line 4), column x_m: 'x' is not a number");
        let e = read_numeric("t_c,x_m\n30,inf\n").unwrap_err();
        assert!(e.contains("column x_m: 'inf' is not a finite number"), "{e}");
        assert!(read_numeric("").unwrap_err().contains("empty file"));
        // The command's own output may hold NaN: `parse` keeps it.
        let (_, rows) = parse("a\nNaN\n").unwrap();
        assert!(rows[0][0].is_nan());
    }

    #[test]
    fn json_keeps_a_unit_column_as_text() {
        let text = "flag,ticks,estimate,unit,residual_unit\nA,3,1.5,1,Pa\nB,4,,m,1\nC,5,2,,\n";
        let rows: Vec<serde_json::Value> = serde_json::from_str(&render(text, Format::Json)).unwrap();
        let get = |r: usize, k: &str| rows[r][k].clone();
        assert_eq!(get(0, "unit"), serde_json::json!("1"));
        assert_eq!(get(0, "residual_unit"), serde_json::json!("Pa"));
        assert_eq!(get(1, "unit"), serde_json::json!("m"));
        assert_eq!(get(1, "residual_unit"), serde_json::json!("1"));
        // Other columns as before: numbers, and null for an empty cell.
        assert_eq!(get(0, "ticks"), serde_json::json!(3));
        assert_eq!(get(0, "estimate"), serde_json::json!(1.5));
        assert_eq!(get(1, "estimate"), serde_json::Value::Null);
        assert_eq!(get(2, "unit"), serde_json::Value::Null);
    }

    #[test]
    fn other_columns_are_ignored_even_when_not_numbers() {
        let t = read_columns("t_c,note,x_m\n30,first run,0.5\n40,,0.75\n", &["t_c", "x_m"]).unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!((t.rows[1][0], t.rows[1][2]), (40.0, 0.75));
        assert!(t.rows[0][1].is_nan());
        // A wanted column still must hold numbers.
        let e = read_columns("t_c,note,x_m\n30,a,b\n", &["t_c", "x_m"]).unwrap_err();
        assert_eq!(e, "row 1 (line 2), column x_m: 'b' is not a number");
        // A wanted column given twice is ambiguous.
        let e = read_columns("t_c,x_m,x_m\n30,0.5,0.6\n", &["t_c", "x_m"]).unwrap_err();
        assert!(e.starts_with("column x_m appears twice"), "{e}");
    }
}
