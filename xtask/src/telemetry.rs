//! The firmware's telemetry lines, decoded on the host: CSV for plotting
//! beside `compensator step`, and the human-readable log with its numbers
//! rounded to what the sensor and the model resolve.
//!
//! Every column, unit, encoding and rounding comes from the record's table
//! (`compensator::estimator::telemetry`). A telemetry line (QEMU twin and
//! board alike: a time in ms, then `StateEstimate`'s defmt format, the
//! record's bytes as defmt prints a byte string):
//!
//! ```text
//! 499 ms telemetry [150, 37, 49, 8, 208, 65, ...]
//! ```
//!
//! shown as
//!
//! ```text
//! 499 ms t=26.00 C x=0.0 um v=0.000 mm/s p_a=273.9 p_b=126.1 kPa Q_a=0.241 Q_b=0.241 Q_throt=0.000 Q0=0.481 err=-0.502 l/min reseats=0 [AT_STOP]
//! ```
//!
//! (a unit after the last of a run of fields that share it). The CSV gets
//! every digit the record carries, in SI units: an `f32` field in its
//! shortest round-trip form, which reads back to the same `f32`.

use compensator::estimator::Flags;
use compensator::estimator::telemetry::{self, Encoding, FIELDS, Field};
use std::path::Path;

/// What precedes the record's bytes in a telemetry line.
const MARK: &str = " ms telemetry [";

/// The CSV header, SI units (as `compensator step`'s columns): `time_s`,
/// the table's columns, `flags`.
pub fn header() -> Vec<&'static str> {
    let mut h = vec!["time_s"];
    h.extend(FIELDS.iter().map(|f| f.column));
    h.push("flags");
    h
}

/// One telemetry record, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Time since start [s].
    pub time_s: f64,
    /// The record's fields and flags.
    pub values: telemetry::Record,
}

impl Record {
    /// Flag names joined by `|` (empty: none).
    pub fn flags(&self) -> String {
        self.values.flags.names().collect::<Vec<_>>().join("|")
    }

    /// The human-readable line, rounded (see the module docs): the fields
    /// of the record's layout (the condition monitor's only in a record
    /// that carries them).
    pub fn display(&self) -> String {
        let mut s = format!("{} ms", (self.time_s * 1e3).round());
        let values = self.values.values();
        let fields = self.values.layout().fields();
        for (i, (f, v)) in fields.iter().zip(values).enumerate() {
            s += &format!(" {}={}", f.key, fixed(v * f.scale, f.decimals));
            let last_of_unit = fields.get(i + 1).is_none_or(|g| g.shown_unit != f.shown_unit);
            if last_of_unit && !f.shown_unit.is_empty() {
                s += &format!(" {}", f.shown_unit);
            }
        }
        let flags = self.flags();
        s + &format!(" [{}]", if flags.is_empty() { "-" } else { &flags })
    }
}

/// `v` with `decimals` decimals, without a sign on a rounded zero.
fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// A value in its CSV form: an `f32` field's shortest round-trip `f32`
/// digits, the rest as `f64`.
fn csv_value(field: &Field, v: f64) -> String {
    match field.encoding {
        Encoding::F32 => (v as f32).to_string(),
        _ => v.to_string(),
    }
}

/// [`csv_value`] read back.
fn parse_value(field: &Field, text: &str) -> Option<f64> {
    match field.encoding {
        Encoding::F32 => text.parse::<f32>().ok().map(f64::from),
        _ => text.parse().ok(),
    }
}

/// Where the telemetry message starts in a log line (after a level or
/// timestamp prefix): the digits before [`MARK`].
fn message_start(line: &str) -> Option<usize> {
    let at = line.find(MARK)?;
    let digits = line[..at].bytes().rev().take_while(u8::is_ascii_digit).count();
    (digits > 0).then_some(at - digits)
}

/// The record of a telemetry line; `Ok(None)` for any other line.
///
/// # Errors
///
/// A telemetry line whose bytes do not make a record of this table (cut
/// short, or sent by a firmware built from another table), described.
pub fn parse(line: &str) -> Result<Option<Record>, String> {
    let Some(start) = message_start(line) else {
        return Ok(None);
    };
    let msg = &line[start..];
    let (ms, rest) = msg.split_once(MARK).ok_or("no telemetry mark")?;
    let ms: f64 = ms.parse().map_err(|_| format!("telemetry time {ms:?}"))?;
    let list = rest
        .trim_end()
        .strip_suffix(']')
        .ok_or_else(|| format!("telemetry record not closed: {line}"))?;
    let bytes: Vec<u8> = list
        .split(',')
        .map(|b| b.trim().parse::<u8>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("telemetry record bytes: {line}"))?;
    let values = telemetry::Record::decode(&bytes).map_err(|e| e.to_string())?;
    Ok(Some(Record {
        time_s: ms * 1e-3,
        values,
    }))
}

/// `line` with a telemetry message rounded for reading; other lines as
/// they are (a telemetry line that does not decode says why).
pub fn humanize(line: &str) -> String {
    match (message_start(line), parse(line)) {
        (Some(start), Ok(Some(r))) => format!("{}{}", &line[..start], r.display()),
        (_, Err(e)) => format!("{line} ({e})"),
        _ => line.to_string(),
    }
}

/// A CSV file of telemetry records, written row by row (flushed after
/// each, so a run stopped with Ctrl-C keeps what it decoded).
pub struct CsvFile {
    writer: csv::Writer<std::fs::File>,
    /// Rows written.
    pub rows: usize,
}

impl CsvFile {
    /// Creates `path` with the header row.
    pub fn create(path: &Path) -> Result<CsvFile, String> {
        let mut writer = csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
        writer
            .write_record(header())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(CsvFile { writer, rows: 0 })
    }

    /// Appends the record of `line` if it is a telemetry line.
    pub fn line(&mut self, line: &str) -> Result<(), String> {
        match parse(line)? {
            Some(r) => self.record(&r),
            None => Ok(()),
        }
    }

    /// Appends one record.
    pub fn record(&mut self, r: &Record) -> Result<(), String> {
        let mut row = vec![r.time_s.to_string()];
        row.extend(FIELDS.iter().zip(r.values.values()).map(|(f, v)| csv_value(f, v)));
        row.push(r.flags());
        self.writer.write_record(&row).map_err(|e| e.to_string())?;
        self.writer.flush().map_err(|e| e.to_string())?;
        self.rows += 1;
        Ok(())
    }
}

/// Reads a telemetry CSV written by [`CsvFile`] back into records.
pub fn read_csv(path: &Path) -> Result<Vec<Record>, String> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let found: Vec<String> = reader
        .headers()
        .map_err(|e| e.to_string())?
        .iter()
        .map(str::to_string)
        .collect();
    if found != header() {
        return Err(format!("{}: header {found:?}, expected {:?}", path.display(), header()));
    }
    let mut out = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let row = row.map_err(|e| e.to_string())?;
        let at = |c: usize| row.get(c).unwrap_or_default();
        let bad = |c: usize| format!("{}: row {}, column {}: {:?}", path.display(), i + 1, header()[c], at(c));
        let time_s = at(0).parse().map_err(|_| bad(0))?;
        let mut values = [0.0; FIELDS.len()];
        for (k, f) in FIELDS.iter().enumerate() {
            values[k] = parse_value(f, at(k + 1)).ok_or_else(|| bad(k + 1))?;
        }
        let flags_col = FIELDS.len() + 1;
        let mut flags = Flags::empty();
        for name in at(flags_col).split('|').filter(|n| !n.is_empty()) {
            let bit = Flags::NAMES
                .iter()
                .position(|n| *n == name)
                .ok_or_else(|| bad(flags_col))?;
            flags.insert(Flags(1 << bit));
        }
        out.push(Record {
            time_s,
            values: telemetry::Record::from_values(values, flags),
        });
    }
    Ok(out)
}

/// The documentation's table of the record's columns (docs/firmware.md,
/// between its `telemetry-columns` markers; the test that keeps it
/// current is its only user).
#[cfg(test)]
fn columns_markdown() -> String {
    let mut s = String::from(
        "| column | unit | sent as | shown as | description |\n| --- | --- | --- | --- | --- |\n\
         | `time_s` | s | the line's time in ms (`u32`) | `499 ms` | Time since start. |\n",
    );
    for (i, f) in FIELDS.iter().enumerate() {
        let step = fixed(f.resolution() * f.scale, f.decimals);
        // The monitor's columns: sent by an image with a second sensor
        // only, NaN in the CSV of one without.
        let only = if i >= telemetry::HEALTH_FROM {
            ", with a second sensor only (else NaN)"
        } else {
            ""
        };
        let shown = if f.shown_unit.is_empty() {
            format!("`{}=`, to {step}", f.key)
        } else {
            format!("`{}=` in {}, to {step}", f.key, f.shown_unit)
        };
        s += &format!(
            "| `{}` | {} | {}{only} | {} | {} |\n",
            f.column,
            f.unit,
            f.encoding.describe(),
            shown,
            f.doc.trim()
        );
    }
    // `\|`: a bar inside a table cell, even in code.
    s + "| `flags` | - | `u32` bits | `[AT_STOP\\|SPIKE]`, `[-]` for none | The condition flags' names joined by `\\|`. |\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use compensator::estimator::StateEstimate;

    /// An estimate as the twin's log has one at 12.999 s.
    fn estimate(flags: Flags) -> StateEstimate {
        StateEstimate {
            tick: 12999,
            temperature: 35.789177,
            t_probe: 35.31,
            x: 12.860147e-6,
            v: 0.03813392e-3,
            p_a: 196205.72,
            p_b: 203794.24,
            q_a: 0.30710542 / 6e4,
            q_b: 0.3069253 / 6e4,
            q_throt: 0.0917632 / 6e4,
            q_total: 0.7057939 / 6e4,
            compensation_error: -1.0280564 / 6e4,
            x_equilibrium: 12.9e-6,
            dx_dt: 3.7e-5,
            reseats: 2,
            deadline_misses: 0,
            lost_ticks: 0,
            uncertainty: compensator::uncertainty::Uncertainty {
                t_oil: 0.31,
                x: 7.8e-6,
                p_a: 1275.8,
                p_b: 1275.8,
                q_total: 9.7e-7,
                compensation_error: 2.1e-7,
            },
            health: compensator::monitor::HealthEstimate::NONE,
            flags,
        }
    }

    /// The log line the firmware sends for `e` at `ms` (defmt prints a
    /// byte string as Rust's `Debug` does).
    fn line(prefix: &str, ms: u32, e: &StateEstimate) -> String {
        format!("{prefix}{ms} ms telemetry {:?}", telemetry::encode(e))
    }

    /// The line of an image with the condition monitor.
    fn monitor_line(prefix: &str, ms: u32, e: &StateEstimate) -> String {
        format!("{prefix}{ms} ms telemetry {:?}", telemetry::encode_monitor(e))
    }

    /// `e` with a health estimate, as the monitor publishes it.
    fn monitored(mut e: StateEstimate) -> StateEstimate {
        // Field by field: a parameter the monitor adds keeps its NONE.
        let h = &mut e.health;
        h.divider = 1.0123;
        h.sd_divider = 0.0456;
        h.spring = 1.0;
        h.sd_spring = 0.05;
        h.offset = -12.345678;
        h.sd_offset = 250.5;
        h.friction = 0.0;
        h.cusum = 2.25;
        h.rejected = 3;
        h.probe_bias = -0.125;
        h.sd_probe_bias = 0.25;
        h.oil = 47.5;
        e
    }

    /// The bits of a record's values (NaN equal to itself), its flags.
    fn bits(r: &telemetry::Record) -> (Vec<u64>, Flags) {
        (r.values().iter().map(|v| v.to_bits()).collect(), r.flags)
    }

    #[test]
    fn a_telemetry_line_decodes_to_si_units() {
        let e = estimate(Flags::empty());
        let l = line("INFO  ", 12999, &e);
        let r = parse(&l).unwrap().unwrap();
        assert_eq!(r.time_s, 12.999);
        assert_eq!(r.values.t_oil_c, f64::from(35.789177f32));
        assert_eq!(r.values.t_probe_c, f64::from(35.31f32));
        assert_eq!(r.values.x_sd_m, f64::from(7.8e-6f32));
        assert_eq!(r.values.x_m, f64::from(12.860147e-6f32));
        assert_eq!(r.values.p_a_pa, f64::from(196205.72f32));
        assert_eq!(r.values.reseats, 2.0);
        assert_eq!(bits(&r.values), bits(&telemetry::Record::of(&e)));
        assert!(r.values.divider.is_nan() && r.values.rejected.is_nan());
        assert!(r.flags().is_empty());
        let mut flagged = estimate(Flags::AT_STOP);
        flagged.flags.insert(Flags::SPIKE);
        flagged.compensation_error = f32::NAN;
        let r = parse(&line("INFO  ", 1, &flagged)).unwrap().unwrap();
        assert_eq!(r.flags(), "AT_STOP|SPIKE");
        assert!(r.values.compensation_error_m3s.is_nan());
        // A probe-rs line (timestamp and level first) decodes the same.
        let board = line("0.500000 INFO ", 12999, &e);
        assert_eq!(
            bits(&parse(&board).unwrap().unwrap().values),
            bits(&telemetry::Record::of(&e))
        );
        // A record with the monitor's columns decodes them.
        let m = monitored(e);
        let r = parse(&monitor_line("INFO  ", 12999, &m)).unwrap().unwrap();
        assert_eq!(r.values.divider, f64::from(1.0123f32));
        assert_eq!(r.values.sensor_offset, f64::from(-12.345678f32));
        assert_eq!(r.values.rejected, 3.0);
        assert_eq!(
            bits(&r.values),
            bits(&telemetry::Record::of_layout(&m, telemetry::Layout::Monitor))
        );
        assert!(parse("INFO  checkpoint 26.0 C: x 0.0 um").unwrap().is_none());
        assert!(parse("INFO  replaying 74.0 s: ticks of 1.0 ms").unwrap().is_none());
    }

    #[test]
    fn a_line_that_is_not_a_record_of_this_table_is_an_error() {
        let l = line("INFO  ", 5, &estimate(Flags::empty()));
        // A byte more than its tag's layout packs.
        let short = format!("{}, 1]", l.strip_suffix(']').unwrap());
        assert!(
            parse(&short).unwrap_err().contains("bytes"),
            "{}",
            parse(&short).unwrap_err()
        );
        let mut bytes = telemetry::encode(&estimate(Flags::empty()));
        bytes[0] ^= 0xFF;
        let other = format!("INFO  5 ms telemetry {bytes:?}");
        assert!(parse(&other).unwrap_err().contains("layout"));
        assert!(humanize(&other).contains("different tables"));
        assert!(parse("INFO  5 ms telemetry [1, 2, x]").is_err());
    }

    #[test]
    fn the_readable_line_is_rounded_to_what_the_sensor_resolves() {
        assert_eq!(
            humanize(&line("INFO  ", 12999, &estimate(Flags::empty()))),
            "INFO  12999 ms t_probe=35.31 t=35.79 u_t=0.310 C x=12.9 u_x=7.80 um v=0.038 mm/s p_a=196.2 u_p_a=1.28 p_b=203.8 u_p_b=1.28 kPa Q_a=0.307 Q_b=0.307 Q_throt=0.092 Q0=0.706 u_Q0=0.0582 err=-1.028 u_err=0.0126 l/min reseats=2 missed=0 lost=0 [-]"
        );
        // With the monitor: its fields after the plain ones.
        assert_eq!(
            humanize(&monitor_line("INFO  ", 12999, &monitored(estimate(Flags::empty())))),
            "INFO  12999 ms t_probe=35.31 t=35.79 u_t=0.310 C x=12.9 u_x=7.80 um v=0.038 mm/s p_a=196.2 u_p_a=1.28 p_b=203.8 u_p_b=1.28 kPa Q_a=0.307 Q_b=0.307 Q_throt=0.092 Q0=0.706 u_Q0=0.0582 err=-1.028 u_err=0.0126 l/min reseats=2 missed=0 lost=0 A=1.0123 u_A=0.0456 k=1.0000 u_k=0.0500 off=-12.3456783 u_off=250.5000000 F=0.000 N cusum=2.25 rejected=3 dT_p=-0.125 u_dT_p=0.250 K T_s=47.500 C [-]"
        );
        assert_eq!(fixed(-0.0001, 3), "0.000");
        assert_eq!(fixed(-0.0006, 3), "-0.001");
        assert_eq!(humanize("INFO  checks: 15 passed"), "INFO  checks: 15 passed");
    }

    #[test]
    fn the_csv_has_the_header_and_reads_back_exactly() {
        let path = std::env::temp_dir().join(format!("xtask-telemetry-{}.csv", std::process::id()));
        let mut csv = CsvFile::create(&path).unwrap();
        let a = estimate(Flags::empty());
        let mut b = estimate(Flags::AT_STOP);
        b.flags.insert(Flags::SPIKE);
        csv.line(&line("INFO  ", 12999, &a)).unwrap();
        csv.line("INFO  not telemetry").unwrap();
        csv.line(&line("INFO  ", 13499, &b)).unwrap();
        assert_eq!(csv.rows, 2);
        drop(csv);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text.lines().next().unwrap(),
            "time_s,t_probe_c,t_oil_c,t_oil_sd_c,x_m,x_sd_m,v_m_s,p_a_pa,p_a_sd_pa,p_b_pa,p_b_sd_pa,q_a_m3s,q_b_m3s,q_throt_m3s,q_total_m3s,q_total_sd_m3s,compensation_error_m3s,compensation_error_sd_m3s,reseats,deadline_misses,lost_ticks,divider,divider_sd,spring,spring_sd,sensor_offset,sensor_offset_sd,friction_n,cusum,rejected,probe_bias_k,probe_bias_sd_k,t_monitor_c,flags"
        );
        assert!(
            text.lines()
                .nth(1)
                .unwrap()
                .starts_with("12.999,35.31,35.789177,0.31,0.000012860147,")
        );
        let back = read_csv(&path).unwrap();
        let sent = [
            parse(&line("", 12999, &a)).unwrap().unwrap(),
            parse(&line("", 13499, &b)).unwrap().unwrap(),
        ];
        assert_eq!(back.len(), 2);
        for (r, s) in back.iter().zip(&sent) {
            assert_eq!(r.time_s, s.time_s);
            assert_eq!(bits(&r.values), bits(&s.values));
        }
        // Without a monitor the health cells are NaN; with one, numbers.
        assert!(
            text.lines()
                .nth(1)
                .unwrap()
                .ends_with(",NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,")
        );
        let path_m = path.with_extension("monitor.csv");
        let mut csv = CsvFile::create(&path_m).unwrap();
        let m = monitored(estimate(Flags::CAPILLARY_RESTRICTED));
        csv.line(&monitor_line("INFO  ", 500, &m)).unwrap();
        drop(csv);
        let text = std::fs::read_to_string(&path_m).unwrap();
        assert!(
            text.lines()
                .nth(1)
                .unwrap()
                .ends_with(",1.0123,0.0456,1,0.05,-12.345678,250.5,0,2.25,3,-0.125,0.25,47.5,CAPILLARY_RESTRICTED"),
            "{text}"
        );
        let back = read_csv(&path_m).unwrap();
        assert_eq!(
            bits(&back[0].values),
            bits(&telemetry::Record::of_layout(&m, telemetry::Layout::Monitor))
        );
        let _ = std::fs::remove_file(&path_m);
        let _ = std::fs::remove_file(&path);
    }

    /// The column table in docs/firmware.md and the header the README and
    /// the docs print are the table's (`XTASK_WRITE_DOCS=1` rewrites the
    /// column table).
    #[test]
    fn the_docs_show_the_tables_columns() {
        let root = crate::root();
        let path = root.join("docs/firmware.md");
        let doc = std::fs::read_to_string(&path).unwrap();
        let (begin, end) = (
            "<!-- BEGIN GENERATED: telemetry-columns -->\n",
            "<!-- END GENERATED: telemetry-columns -->",
        );
        let (head, rest) = doc
            .split_once(begin)
            .expect("docs/firmware.md has the telemetry-columns markers");
        let (_, tail) = rest
            .split_once(end)
            .expect("docs/firmware.md has the telemetry-columns end marker");
        let current = format!("{head}{begin}{}{end}{tail}", columns_markdown());
        if std::env::var_os("XTASK_WRITE_DOCS").is_some() {
            std::fs::write(&path, &current).unwrap();
            return;
        }
        assert!(
            doc == current,
            "docs/firmware.md's telemetry columns are stale: run `XTASK_WRITE_DOCS=1 cargo test -p xtask the_docs`"
        );
        let csv_header = header().join(",");
        for file in ["README.md", "docs/firmware.md"] {
            let text = std::fs::read_to_string(root.join(file)).unwrap();
            assert!(text.contains(&csv_header), "{file} shows the CSV header {csv_header}");
        }
    }
}
