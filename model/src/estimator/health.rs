//! The condition monitor's health estimate as host code and the FMU show
//! it: one table ([`HEALTH_FIELDS`]) of [`HealthEstimate`]'s values, each
//! with its name, unit and meaning, so that a new field of the estimate is
//! one line here and every consumer (the CLI's `estimate` and `monitor`
//! columns, the FMU's outputs) gains it.

use super::flags::Flags;
use crate::monitor::{HealthEstimate, LATCHED, PER_READING, Quantity};

/// The unit of a health value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HealthUnit {
    /// Dimensionless (a factor, a logarithm's standard deviation, a
    /// statistic in innovation standard deviations).
    One,
    /// The second sensor's reading's unit: Pa for a pressure, m for the
    /// displacement.
    Reading,
    /// Newton (a force).
    Newton,
    /// Kelvin (a temperature difference).
    Kelvin,
    /// Degree Celsius (a temperature).
    Celsius,
    /// A count.
    Count,
}

impl HealthUnit {
    /// The SI unit's symbol for a sensor measuring `quantity` (`"1"` for
    /// dimensionless values and counts).
    pub const fn symbol(self, quantity: Quantity) -> &'static str {
        match self {
            HealthUnit::One | HealthUnit::Count => "1",
            HealthUnit::Reading if quantity.is_pressure() => "Pa",
            HealthUnit::Reading => "m",
            HealthUnit::Newton => "N",
            HealthUnit::Kelvin => "K",
            HealthUnit::Celsius => "degC",
        }
    }

    /// The suffix a column's name carries for the unit (`"_pa"`, `"_m"`,
    /// `"_n"`, `"_k"`; none for dimensionless values and counts), as the
    /// telemetry's columns are named.
    pub const fn suffix(self, quantity: Quantity) -> &'static str {
        match self {
            HealthUnit::One | HealthUnit::Count => "",
            HealthUnit::Reading if quantity.is_pressure() => "_pa",
            HealthUnit::Reading => "_m",
            HealthUnit::Newton => "_n",
            HealthUnit::Kelvin => "_k",
            HealthUnit::Celsius => "_c",
        }
    }
}

/// One value of the health estimate.
#[derive(Clone, Copy, Debug)]
pub struct HealthField {
    /// Its name, [`HealthEstimate`]'s field's.
    pub name: &'static str,
    /// Its unit.
    pub unit: HealthUnit,
    /// What it is.
    pub doc: &'static str,
    /// Its value in `health` (NaN where the monitor has none: before its
    /// first reading, the innovation of a reading it did not apply).
    pub value: fn(&HealthEstimate) -> f64,
}

/// Every value of [`HealthEstimate`] but its flags, in the order host
/// tables list them.
pub const HEALTH_FIELDS: [HealthField; 14] = [
    HealthField {
        name: "divider",
        unit: HealthUnit::One,
        doc: "Divider factor A / A_file: above 1 a restricted capillary or a worn orifice, below 1 a clogged orifice.",
        value: |h| f64::from(h.divider),
    },
    HealthField {
        name: "sd_divider",
        unit: HealthUnit::One,
        doc: "Standard deviation of ln(divider).",
        value: |h| f64::from(h.sd_divider),
    },
    HealthField {
        name: "spring",
        unit: HealthUnit::One,
        doc: "Spring rate's factor c / c_file (1 for a pressure sensor, which does not see it).",
        value: |h| f64::from(h.spring),
    },
    HealthField {
        name: "sd_spring",
        unit: HealthUnit::One,
        doc: "Standard deviation of ln(spring).",
        value: |h| f64::from(h.sd_spring),
    },
    HealthField {
        name: "offset",
        unit: HealthUnit::Reading,
        doc: "The reading's offset (for the displacement: the preload lost, or the sensor's zero).",
        value: |h| f64::from(h.offset),
    },
    HealthField {
        name: "sd_offset",
        unit: HealthUnit::Reading,
        doc: "Standard deviation of the offset.",
        value: |h| f64::from(h.sd_offset),
    },
    HealthField {
        name: "probe_bias",
        unit: HealthUnit::Kelvin,
        doc: "The oil-temperature probe's error at the oil temperature (its place within its IEC 60751 tolerance times the tolerance).",
        value: |h| f64::from(h.probe_bias),
    },
    HealthField {
        name: "sd_probe_bias",
        unit: HealthUnit::Kelvin,
        doc: "Standard deviation of the probe's error.",
        value: |h| f64::from(h.sd_probe_bias),
    },
    HealthField {
        name: "oil",
        unit: HealthUnit::Celsius,
        doc: "The oil temperature the second sensor's reading gives through the health estimate (the twin's where it does not depend on it).",
        value: |h| f64::from(h.oil),
    },
    HealthField {
        name: "friction",
        unit: HealthUnit::Newton,
        doc: "Friction force holding the plunger (0 until sticking is isolated).",
        value: |h| f64::from(h.friction),
    },
    HealthField {
        name: "predicted",
        unit: HealthUnit::Reading,
        doc: "The reading the monitor predicted for the device it estimates.",
        value: |h| f64::from(h.predicted),
    },
    HealthField {
        name: "innovation",
        unit: HealthUnit::One,
        doc: "Standardised innovation of the last reading (reading - predicted, in its standard deviations).",
        value: |h| f64::from(h.innovation),
    },
    HealthField {
        name: "cusum",
        unit: HealthUnit::One,
        doc: "The larger CUSUM statistic, in innovation standard deviations (DEVICE_CHANGED above 10).",
        value: |h| f64::from(h.cusum),
    },
    HealthField {
        name: "rejected",
        unit: HealthUnit::Count,
        doc: "Readings not applied since start: beyond the gate, or not finite.",
        value: |h| f64::from(h.rejected),
    },
];

/// The monitor's flags: `DEVICE_CHANGED`, the isolated faults (latched) and
/// the per-reading `SECOND_SENSOR_FAULT` and `INNOVATION_REJECTED`.
pub const MONITOR_FLAGS: Flags = Flags(Flags::DEVICE_CHANGED.0 | LATCHED.0 | PER_READING.0);

/// The monitor's flags that say the device changed: `DEVICE_CHANGED` and
/// the isolated faults.
pub const FAULT_FLAGS: Flags = Flags(Flags::DEVICE_CHANGED.0 | LATCHED.0);
