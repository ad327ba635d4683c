//! The columns of measured data files (`calibrate --pressure-data`,
//! `--displacement-data`, `identify --data`, `estimate --sensor-data`),
//! declared once: name, unit,
//! plausible range and the units a value in the wrong one is likely in.
//! Every cell of a known column is checked when the file is read
//! ([`crate::csv::read_columns`]): a pressure log in bar, a displacement
//! in mm or a temperature in K is refused naming row, column and the
//! likely unit, before any fit can fit it silently. Ranges that depend on
//! the parameter file (the plunger's travel, the oil model's
//! temperatures: [`crate::envelope`]) are checked by the commands.

use crate::display::sig;

/// A unit a value may have been written in: its name and how to convert
/// it to the column's SI unit (`si = value * factor + offset`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OtherUnit {
    /// `bar`.
    pub name: &'static str,
    /// Multiplier to SI.
    pub factor: f64,
    /// Offset to SI (temperatures).
    pub offset: f64,
}

const fn unit(name: &'static str, factor: f64) -> OtherUnit {
    OtherUnit {
        name,
        factor,
        offset: 0.0,
    }
}

/// One column of a data file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DataColumn {
    /// Header name (`dp_pa`).
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// Lowest plausible value.
    pub min: f64,
    /// Highest plausible value.
    pub max: f64,
    /// What it is.
    pub doc: &'static str,
    /// Units a wrong value is likely in, most likely first.
    pub likely: &'static [OtherUnit],
}

const PRESSURE_UNITS: &[OtherUnit] = &[
    unit("bar", 1e5),
    unit("kPa", 1e3),
    unit("MPa", 1e6),
    unit("psi", 6894.757),
];
const LENGTH_UNITS: &[OtherUnit] = &[unit("mm", 1e-3), unit("um", 1e-6)];
const TEMPERATURE_UNITS: &[OtherUnit] = &[
    OtherUnit {
        name: "K",
        factor: 1.0,
        offset: -273.15,
    },
    OtherUnit {
        name: "F",
        factor: 5.0 / 9.0,
        offset: -160.0 / 9.0,
    },
];

/// Every data column the commands read. The ranges are those of the
/// parameter file's fields for the same quantity (`operating.pressure_drop`
/// 1e3..1e8 Pa, a stroke of at most 1 m, temperatures -60..300 C; a probe's
/// resistance that of a PT100 to a PT1000 over IEC 60751's -200..850 C,
/// 18.5 to 3,910 ohm, with room for other elements; the MAX31865's code
/// its 15 bits).
pub const DATA_COLUMNS: &[DataColumn] = &[
    DataColumn {
        name: "t_c",
        unit: "C",
        min: -60.0,
        max: 300.0,
        doc: "oil temperature",
        likely: TEMPERATURE_UNITS,
    },
    DataColumn {
        name: "t_probe_c",
        unit: "C",
        min: -60.0,
        max: 300.0,
        doc: "probe temperature",
        likely: TEMPERATURE_UNITS,
    },
    DataColumn {
        name: "rtd_ohm",
        unit: "ohm",
        min: 1.0,
        max: 1e5,
        doc: "RTD resistance",
        likely: &[unit("kohm", 1e3), unit("mohm", 1e-3)],
    },
    DataColumn {
        name: "code",
        unit: "LSB",
        min: 0.0,
        max: 32767.0,
        doc: "MAX31865 15-bit RTD code",
        // The RTD registers read as one 16-bit word: the code shifted left
        // by one, the fault bit in bit 0.
        likely: &[unit("register word (code x 2 + fault bit)", 0.5)],
    },
    DataColumn {
        name: "dp_pa",
        unit: "Pa",
        min: 1e3,
        max: 1e8,
        doc: "inlet-outlet pressure drop p_p - p_c",
        likely: PRESSURE_UNITS,
    },
    DataColumn {
        name: "dp_ab_pa",
        unit: "Pa",
        min: -1e8,
        max: 1e8,
        doc: "chamber pressure difference p_b - p_a",
        likely: PRESSURE_UNITS,
    },
    DataColumn {
        name: "p_a_pa",
        unit: "Pa",
        min: 0.0,
        max: 1e8,
        doc: "pressure in chamber (a)",
        likely: PRESSURE_UNITS,
    },
    DataColumn {
        name: "p_b_pa",
        unit: "Pa",
        min: 0.0,
        max: 1e8,
        doc: "pressure in chamber (b)",
        likely: PRESSURE_UNITS,
    },
    DataColumn {
        name: "x_m",
        unit: "m",
        min: -1.0,
        max: 1.0,
        doc: "plunger displacement",
        likely: LENGTH_UNITS,
    },
    DataColumn {
        name: "time_s",
        unit: "s",
        min: 0.0,
        max: 1e7,
        doc: "sample time",
        likely: &[unit("ms", 1e-3)],
    },
];

/// The column named `name`, if it is one of [`DATA_COLUMNS`].
pub fn column(name: &str) -> Option<&'static DataColumn> {
    DATA_COLUMNS.iter().find(|c| c.name == name)
}

/// `; written in another unit? (4 bar = 400000 Pa)`: the most likely unit
/// (the first of the column's list) in which `v` lands in `lo..=hi` (the
/// column's range or one from the file), or nothing.
pub fn unit_hint(col: &DataColumn, v: f64, lo: f64, hi: f64) -> String {
    col.likely
        .iter()
        .find(|u| (lo..=hi).contains(&(v * u.factor + u.offset)))
        .map_or(String::new(), |u| {
            format!(
                "; written in another unit? ({} {} = {} {})",
                sig(v, 6),
                u.name,
                sig(v * u.factor + u.offset, 4),
                col.unit
            )
        })
}

/// Checks one cell of column `col` against its plausible range.
///
/// # Errors
///
/// The value, the range and the likely unit (`at` names row and column).
pub fn check(col: &DataColumn, v: f64, at: &str) -> Result<(), String> {
    if (col.min..=col.max).contains(&v) {
        return Ok(());
    }
    Err(format!(
        "{at}: {} {} is not a plausible {} [{}, {}] {}{}{}",
        sig(v, 6),
        col.unit,
        col.doc,
        sig(col.min, 6),
        sig(col.max, 6),
        col.unit,
        unit_hint(col, v, col.min, col.max),
        epoch_hint(col, v)
    ))
}

/// A sample time of 1e8 to 1e10 s is likely a Unix time (1973 to 2286):
/// the hint to count from the log's start.
fn epoch_hint(col: &DataColumn, v: f64) -> &'static str {
    if col.name == "time_s" && (1e8..1e10).contains(&v) {
        "; or a Unix time (s since 1970)? time_s counts from the log's start: subtract the first row's time"
    } else {
        ""
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrong_units_are_named() {
        let dp = column("dp_pa").unwrap();
        let e = check(dp, 4.0, "row 1, column dp_pa").unwrap_err();
        assert!(
            e.contains("4 Pa is not a plausible") && e.contains("(4 bar = 400000 Pa)"),
            "{e}"
        );
        let t = column("t_c").unwrap();
        let e = check(t, 300_000.0, "row 2, column t_c").unwrap_err();
        assert!(
            e.contains("300000 C is not a plausible oil temperature [-60, 300] C"),
            "{e}"
        );
        let e = check(t, 320.0, "row 2, column t_c").unwrap_err();
        assert!(e.contains("320 K = 46.85 C"), "{e}");
        let x = column("x_m").unwrap();
        let e = check(x, 2.0, "row 3, column x_m").unwrap_err();
        assert!(e.contains("2 mm = 0.002 m"), "{e}");
        assert!(check(dp, 4e5, "").is_ok());
    }
}
