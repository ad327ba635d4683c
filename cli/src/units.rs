//! `--units si|eng`: the unit system of every table and figure.
//!
//! The commands compute and print in SI (m, Pa, m^3/s, m^2/s, C); with
//! `--units eng` a table's columns are converted by the unit suffix of
//! their name, which changes with them: `x_m` -> `x_mm`, `dp_ab_pa` ->
//! `dp_ab_bar`, `q_total_m3s` -> `q_total_lpm`, `nu_m2s` -> `nu_cst`. A
//! column without a unit suffix (temperatures in C, eigenvalues in 1/s,
//! percentages, text) is left as it is. Figures draw their axes in the same
//! system ([`Units::length`], [`Units::pressure`], [`Units::flow`]).

/// A unit system.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Units {
    /// SI: m, Pa, m^3/s, m^2/s, C.
    #[default]
    Si,
    /// Engineering: mm, bar, L/min, cSt, C.
    Eng,
}

/// An SI value `v` in a display unit: `v * mul / div` (one of the two is 1,
/// so that e.g. pascals divide by 1e5 exactly rounded rather than multiply
/// by an inexact 1e-5), with the unit's name.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Scale {
    /// Multiplier.
    pub mul: f64,
    /// Divisor.
    pub div: f64,
    /// Unit name for an axis, e.g. `mm`.
    pub unit: &'static str,
}

impl Scale {
    const fn si(unit: &'static str) -> Self {
        Scale {
            mul: 1.0,
            div: 1.0,
            unit,
        }
    }

    /// `v` [SI] in this unit.
    pub fn apply(&self, v: f64) -> f64 {
        if self.div == 1.0 { v * self.mul } else { v / self.div }
    }
}

/// Column-name suffixes of SI quantities, their engineering suffix and the
/// conversion; the longest matching suffix applies (`_m3s_k` before `_m3s`,
/// `_m_s` before `_m`).
const COLUMN_SUFFIXES: [(&str, &str, Scale); 9] = [
    // sqrt(Pa) -> sqrt(bar): divide by sqrt(1e5).
    (
        "_sqrt_pa",
        "_sqrt_bar",
        Scale {
            mul: 1.0,
            div: 316.227_766_016_837_94,
            unit: "sqrt(bar)",
        },
    ),
    (
        "_m3s_k",
        "_lpm_k",
        Scale {
            mul: 6.0e4,
            div: 1.0,
            unit: "L/(min K)",
        },
    ),
    (
        "_m3s",
        "_lpm",
        Scale {
            mul: 6.0e4,
            div: 1.0,
            unit: "L/min",
        },
    ),
    (
        "_m2s",
        "_cst",
        Scale {
            mul: 1.0e6,
            div: 1.0,
            unit: "cSt",
        },
    ),
    (
        "_m2",
        "_mm2",
        Scale {
            mul: 1.0e6,
            div: 1.0,
            unit: "mm^2",
        },
    ),
    (
        "_m_s",
        "_mm_s",
        Scale {
            mul: 1.0e3,
            div: 1.0,
            unit: "mm/s",
        },
    ),
    (
        "_m_k",
        "_mm_k",
        Scale {
            mul: 1.0e3,
            div: 1.0,
            unit: "mm/K",
        },
    ),
    (
        "_pa",
        "_bar",
        Scale {
            mul: 1.0,
            div: 1.0e5,
            unit: "bar",
        },
    ),
    (
        "_m",
        "_mm",
        Scale {
            mul: 1.0e3,
            div: 1.0,
            unit: "mm",
        },
    ),
];

/// The engineering name and scale of an SI column, if it has a unit suffix.
pub fn eng_column(name: &str) -> Option<(String, Scale)> {
    COLUMN_SUFFIXES
        .iter()
        .filter(|(si, _, _)| name.len() > si.len() && name.ends_with(si))
        .max_by_key(|(si, _, _)| si.len())
        .map(|(si, eng, scale)| (format!("{}{eng}", &name[..name.len() - si.len()]), *scale))
}

impl Units {
    /// Displacement: m or mm.
    pub fn length(self) -> Scale {
        match self {
            Units::Si => Scale::si("m"),
            Units::Eng => Scale {
                mul: 1.0e3,
                div: 1.0,
                unit: "mm",
            },
        }
    }

    /// Small displacement (an error): m or um.
    pub fn small_length(self) -> Scale {
        match self {
            Units::Si => Scale::si("m"),
            Units::Eng => Scale {
                mul: 1.0e6,
                div: 1.0,
                unit: "um",
            },
        }
    }

    /// Velocity: m/s or mm/s.
    pub fn velocity(self) -> Scale {
        match self {
            Units::Si => Scale::si("m/s"),
            Units::Eng => Scale {
                mul: 1.0e3,
                div: 1.0,
                unit: "mm/s",
            },
        }
    }

    /// Pressure: Pa or bar.
    pub fn pressure(self) -> Scale {
        match self {
            Units::Si => Scale::si("Pa"),
            Units::Eng => Scale {
                mul: 1.0,
                div: 1.0e5,
                unit: "bar",
            },
        }
    }

    /// Volume flow: m^3/s or L/min.
    pub fn flow(self) -> Scale {
        match self {
            Units::Si => Scale::si("m^3/s"),
            Units::Eng => Scale {
                mul: 6.0e4,
                div: 1.0,
                unit: "L/min",
            },
        }
    }

    /// CSV text (header row, SI columns as the commands write them) in this
    /// unit system: unchanged in SI; in engineering units each column with
    /// a unit suffix renamed and its numeric cells converted (empty and
    /// text cells stay as they are).
    pub fn convert_csv(self, text: &str) -> String {
        if self == Units::Si {
            return text.to_string();
        }
        let mut lines = text.lines();
        let Some(header) = lines.next() else {
            return String::new();
        };
        let columns: Vec<(String, Option<Scale>)> = header
            .split(',')
            .map(|h| match eng_column(h) {
                Some((name, scale)) => (name, Some(scale)),
                None => (h.to_string(), None),
            })
            .collect();
        let mut out = String::with_capacity(text.len() + 64);
        out.push_str(&columns.iter().map(|c| c.0.as_str()).collect::<Vec<_>>().join(","));
        out.push('\n');
        for line in lines {
            let cells: Vec<String> = line
                .split(',')
                .enumerate()
                .map(
                    |(i, cell)| match (columns.get(i).and_then(|c| c.1), cell.parse::<f64>()) {
                        (Some(scale), Ok(v)) => format!("{}", scale.apply(v)),
                        _ => cell.to_string(),
                    },
                )
                .collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suffixes_rename_and_scale() {
        let csv = "t_c,a_sqrt_pa,dp_ab_pa,x_m,v_m_s,q_total_m3s,dq_throt_dt_m3s_k,required_area_m2,dx_dt_m_k,nu_m2s,re_1,scheme,error\n\
                   40,1e5,250000,0.0005,0.02,1e-4,1e-6,3e-6,2e-5,4.6e-5,-90,sdirk3,\n\
                   90,,,,,,,,,,,,out of range\n";
        let eng = Units::Eng.convert_csv(csv);
        let mut lines = eng.lines();
        assert_eq!(
            lines.next().unwrap(),
            "t_c,a_sqrt_bar,dp_ab_bar,x_mm,v_mm_s,q_total_lpm,dq_throt_dt_lpm_k,required_area_mm2,dx_dt_mm_k,nu_cst,re_1,scheme,error"
        );
        let row: Vec<f64> = lines
            .next()
            .unwrap()
            .split(',')
            .take(11)
            .map(|c| c.parse().unwrap())
            .collect();
        let want = [
            40.0,
            1e5 / 1e5f64.sqrt(),
            2.5,
            0.5,
            20.0,
            6.0,
            0.06,
            3.0,
            0.02,
            46.0,
            -90.0,
        ];
        for (got, want) in row.iter().zip(want) {
            assert!((got - want).abs() <= 1e-12 * want.abs(), "{got} != {want}");
        }
        assert_eq!(lines.next().unwrap(), "90,,,,,,,,,,,,out of range");
        assert_eq!(Units::Si.convert_csv(csv), csv);
    }
}
