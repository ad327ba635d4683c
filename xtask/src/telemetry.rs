//! The firmware's telemetry lines, decoded on the host: CSV for plotting
//! beside `compensator step`, and the human-readable log with its numbers
//! rounded to what the sensor and the model resolve.
//!
//! A telemetry line (QEMU twin and board alike, `StateEstimate`'s defmt
//! format after a time in ms):
//!
//! ```text
//! 499 ms t=26.004648 C x=0.0 um v=0.0 mm/s p_a=273.9017 p_b=126.09832 kPa Q_a=0.24067159 Q_b=0.24067156 Q_throt=0.0 Q0=0.48134312 err=-0.5017106 l/min [AT_STOP]
//! ```
//!
//! The firmware sends full `f32`s (packing them costs what it costs; defmt
//! prints them in their shortest round-trip form), so the CSV gets every
//! digit and only the display is rounded: temperature to 0.01 C (one
//! MAX31865 code is 0.033 C with a PT100 and 430 ohm), displacement to
//! 0.1 um, pressures to 0.1 kPa, flows to 0.001 l/min, velocity to
//! 0.001 mm/s: below what one code moves them at the paper preset (up to
//! 1.3 um, 0.3 kPa and 0.009 l/min per code, from the 4 C steps of the
//! twin's static table, `cargo xtask run`).

use std::path::Path;

/// The CSV header, SI units (as `compensator step`'s columns).
pub const HEADER: [&str; 12] = [
    "time_s",
    "t_c",
    "x_m",
    "v_m_s",
    "p_a_pa",
    "p_b_pa",
    "q_a_m3s",
    "q_b_m3s",
    "q_throt_m3s",
    "q_total_m3s",
    "compensation_error_m3s",
    "flags",
];

/// One telemetry record, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Time since start [s].
    pub time_s: f64,
    /// Filtered oil temperature [C].
    pub t_c: f64,
    /// Plunger displacement [m].
    pub x_m: f64,
    /// Plunger velocity [m/s].
    pub v_m_s: f64,
    /// Chamber (a) pressure [Pa].
    pub p_a_pa: f64,
    /// Chamber (b) pressure [Pa].
    pub p_b_pa: f64,
    /// Capillary flow [m^3/s].
    pub q_a_m3s: f64,
    /// Orifice flow [m^3/s].
    pub q_b_m3s: f64,
    /// Window flow [m^3/s].
    pub q_throt_m3s: f64,
    /// Total flow [m^3/s].
    pub q_total_m3s: f64,
    /// Compensation error [m^3/s] (NaN without a `[machine]`).
    pub compensation_error_m3s: f64,
    /// Flag names joined by `|` (empty: none).
    pub flags: String,
}

/// l/min per m^3/s.
const LPM: f64 = 6.0e4;

impl Record {
    /// The values of the numeric columns, in [`HEADER`] order.
    pub fn numbers(&self) -> [f64; 11] {
        [
            self.time_s,
            self.t_c,
            self.x_m,
            self.v_m_s,
            self.p_a_pa,
            self.p_b_pa,
            self.q_a_m3s,
            self.q_b_m3s,
            self.q_throt_m3s,
            self.q_total_m3s,
            self.compensation_error_m3s,
        ]
    }

    /// The human-readable line, rounded (see the module docs).
    pub fn display(&self) -> String {
        let flags = if self.flags.is_empty() { "-" } else { &self.flags };
        format!(
            "{} ms t={} C x={} um v={} mm/s p_a={} p_b={} kPa Q_a={} Q_b={} Q_throt={} Q0={} err={} l/min [{flags}]",
            (self.time_s * 1e3).round(),
            fixed(self.t_c, 2),
            fixed(self.x_m * 1e6, 1),
            fixed(self.v_m_s * 1e3, 3),
            fixed(self.p_a_pa * 1e-3, 1),
            fixed(self.p_b_pa * 1e-3, 1),
            fixed(self.q_a_m3s * LPM, 3),
            fixed(self.q_b_m3s * LPM, 3),
            fixed(self.q_throt_m3s * LPM, 3),
            fixed(self.q_total_m3s * LPM, 3),
            fixed(self.compensation_error_m3s * LPM, 3),
        )
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

/// Where the telemetry message starts in a log line (after a level or
/// timestamp prefix): the digits before `" ms t="`.
fn message_start(line: &str) -> Option<usize> {
    let at = line.find(" ms t=")?;
    let digits = line[..at].bytes().rev().take_while(u8::is_ascii_digit).count();
    (digits > 0).then_some(at - digits)
}

/// The record of a telemetry line, or `None` for any other line.
pub fn parse(line: &str) -> Option<Record> {
    let msg = &line[message_start(line)?..];
    let mut words = msg.split_whitespace();
    let ms: f64 = words.next()?.parse().ok()?;
    let get = |key: &str| -> Option<f64> {
        let w = msg
            .split_whitespace()
            .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))?;
        w.parse::<f64>().ok()
    };
    let (t, x, v, pa, pb) = (get("t")?, get("x")?, get("v")?, get("p_a")?, get("p_b")?);
    let (qa, qb, qt, q0, err) = (get("Q_a")?, get("Q_b")?, get("Q_throt")?, get("Q0")?, get("err")?);
    let flags = msg.rsplit_once('[')?.1.strip_suffix(']')?.trim();
    Some(Record {
        time_s: ms * 1e-3,
        t_c: t,
        x_m: x * 1e-6,
        v_m_s: v * 1e-3,
        p_a_pa: pa * 1e3,
        p_b_pa: pb * 1e3,
        q_a_m3s: qa / LPM,
        q_b_m3s: qb / LPM,
        q_throt_m3s: qt / LPM,
        q_total_m3s: q0 / LPM,
        compensation_error_m3s: err / LPM,
        flags: if flags == "-" { String::new() } else { flags.to_string() },
    })
}

/// `line` with a telemetry message rounded for reading; other lines as
/// they are.
pub fn humanize(line: &str) -> String {
    match (message_start(line), parse(line)) {
        (Some(start), Some(r)) => format!("{}{}", &line[..start], r.display()),
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
            .write_record(HEADER)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(CsvFile { writer, rows: 0 })
    }

    /// Appends the record of `line` if it is a telemetry line.
    pub fn line(&mut self, line: &str) -> Result<(), String> {
        match parse(line) {
            Some(r) => self.record(&r),
            None => Ok(()),
        }
    }

    /// Appends one record (numbers in their shortest round-trip form).
    pub fn record(&mut self, r: &Record) -> Result<(), String> {
        let mut row: Vec<String> = r.numbers().iter().map(|v| v.to_string()).collect();
        row.push(r.flags.clone());
        self.writer.write_record(&row).map_err(|e| e.to_string())?;
        self.writer.flush().map_err(|e| e.to_string())?;
        self.rows += 1;
        Ok(())
    }
}

/// Reads a telemetry CSV written by [`CsvFile`] back into records.
pub fn read_csv(path: &Path) -> Result<Vec<Record>, String> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| e.to_string())?
        .iter()
        .map(str::to_string)
        .collect();
    if header != HEADER {
        return Err(format!("{}: header {header:?}", path.display()));
    }
    let mut out = Vec::new();
    for row in reader.records() {
        let row = row.map_err(|e| e.to_string())?;
        let n: Vec<f64> = (0..11)
            .map(|i| row.get(i).and_then(|v| v.parse().ok()).ok_or(format!("row {row:?}")))
            .collect::<Result<_, _>>()?;
        out.push(Record {
            time_s: n[0],
            t_c: n[1],
            x_m: n[2],
            v_m_s: n[3],
            p_a_pa: n[4],
            p_b_pa: n[5],
            q_a_m3s: n[6],
            q_b_m3s: n[7],
            q_throt_m3s: n[8],
            q_total_m3s: n[9],
            compensation_error_m3s: n[10],
            flags: row.get(11).unwrap_or_default().to_string(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line of the twin's log (tests/snapshots/twin.log before rounding).
    const LINE: &str = "INFO  12999 ms t=35.789177 C x=12.860147 um v=0.03813392 mm/s p_a=196.20572 p_b=203.79424 kPa Q_a=0.30710542 Q_b=0.3069253 Q_throt=0.0917632 Q0=0.7057939 err=-1.0280564 l/min [-]";

    #[test]
    fn a_telemetry_line_decodes_to_si_units() {
        let r = parse(LINE).unwrap();
        assert_eq!(r.time_s, 12.999);
        assert_eq!(r.t_c, 35.789177);
        assert!((r.x_m - 12.860147e-6).abs() < 1e-18);
        assert!((r.v_m_s - 0.03813392e-3).abs() < 1e-18);
        assert_eq!((r.p_a_pa, r.p_b_pa), (196205.72, 203794.24));
        // 0.7057939 l/min = 1.17632317e-5 m^3/s.
        assert!((r.q_total_m3s - 1.176_323_166_666_666_7e-5).abs() < 1e-18);
        assert!(r.flags.is_empty());
        let flagged = LINE
            .replace("[-]", "[AT_STOP|SPIKE]")
            .replace("err=-1.0280564", "err=NaN");
        let r = parse(&flagged).unwrap();
        assert_eq!(r.flags, "AT_STOP|SPIKE");
        assert!(r.compensation_error_m3s.is_nan());
        // A probe-rs line (timestamp and level first) decodes the same.
        let board = format!("0.500000 INFO {}", &LINE[6..]);
        assert_eq!(parse(&board).unwrap().p_a_pa, 196205.72);
        assert!(parse("INFO  checkpoint 26.0 C: x 0.0 um").is_none());
        assert!(parse("INFO  replaying 74.0 s: ticks of 1.0 ms").is_none());
    }

    #[test]
    fn the_readable_line_is_rounded_to_what_the_sensor_resolves() {
        assert_eq!(
            humanize(LINE),
            "INFO  12999 ms t=35.79 C x=12.9 um v=0.038 mm/s p_a=196.2 p_b=203.8 kPa Q_a=0.307 Q_b=0.307 Q_throt=0.092 Q0=0.706 err=-1.028 l/min [-]"
        );
        assert_eq!(fixed(-0.0001, 3), "0.000");
        assert_eq!(fixed(-0.0006, 3), "-0.001");
        assert_eq!(humanize("INFO  checks: 15 passed"), "INFO  checks: 15 passed");
    }

    #[test]
    fn the_csv_has_the_header_and_reads_back_exactly() {
        let path = std::env::temp_dir().join(format!("xtask-telemetry-{}.csv", std::process::id()));
        let mut csv = CsvFile::create(&path).unwrap();
        csv.line(LINE).unwrap();
        csv.line("INFO  not telemetry").unwrap();
        csv.line(&LINE.replace("[-]", "[AT_STOP]")).unwrap();
        assert_eq!(csv.rows, 2);
        drop(csv);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text.lines().next().unwrap(),
            "time_s,t_c,x_m,v_m_s,p_a_pa,p_b_pa,q_a_m3s,q_b_m3s,q_throt_m3s,q_total_m3s,compensation_error_m3s,flags"
        );
        let back = read_csv(&path).unwrap();
        assert_eq!(
            back,
            vec![parse(LINE).unwrap(), parse(&LINE.replace("[-]", "[AT_STOP]")).unwrap()]
        );
        let _ = std::fs::remove_file(&path);
    }
}
