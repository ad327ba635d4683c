//! The FMU's variables: one flat scalar each, with its value reference,
//! causality, unit and description. The parameters are the parameter
//! file's fields, taken from the schema (`compensator_params::CORE_FIELDS`,
//! `MACHINE_FIELDS`, `ESTIMATOR_FIELDS`): names, units, descriptions and
//! plausible ranges are never restated here. The condition monitor's
//! outputs are the core's health table
//! (`compensator::estimator::health::HEALTH_FIELDS`), likewise.

use compensator::estimator::health::{HEALTH_FIELDS, HealthUnit};
use compensator_params::{CORE_FIELDS, ESTIMATOR_FIELDS, Field, Kind, MACHINE_FIELDS, PROBE_FIELDS};

/// Value reference of the independent variable `time` [s] (declared in
/// FMI 3.0 only, where it is required).
pub const VR_TIME: u32 = 0;
/// Value reference of the input `T_oil` [degC].
pub const VR_T_OIL: u32 = 1;
/// Value reference of the input `p_supply` [Pa].
pub const VR_P_SUPPLY: u32 = 2;
/// Value reference of the input `p_outlet` [Pa].
pub const VR_P_OUTLET: u32 = 3;
/// Value reference of the input `second_reading` [Pa or m].
pub const VR_SECOND_READING: u32 = 4;

/// The unit of a variable in the second sensor's unit: `Pa` for a
/// pressure, `m` for the displacement, as the packaged file's
/// `monitor.sensor` says ([`resolve_unit`]).
pub const READING_UNIT: &str = "Pa|m";

/// The FMI unit `unit` of a variable for a packaged file whose second
/// sensor measures a displacement (`displacement`) or not: the unit
/// itself, or for [`READING_UNIT`] `m` or `Pa`.
pub fn resolve_unit(unit: &'static str, displacement: bool) -> &'static str {
    match unit {
        READING_UNIT if displacement => "m",
        READING_UNIT => "Pa",
        u => u,
    }
}

/// The inputs (continuous Float64s, held over a communication step), in
/// value-reference order from [`VR_T_OIL`].
pub const INPUTS: [Variable; 4] = [
    Variable {
        name: "T_oil",
        unit: Some("degC"),
        doc: "Oil temperature. Outside estimator.oil_min..oil_max it is not used (the twin keeps the last one, flag \
              SENSOR_FAULT); its value at the end of initialisation is where the twin starts at rest. Start: the \
              middle of the validated range.",
    },
    Variable {
        name: "p_supply",
        unit: Some("Pa"),
        doc: "Supply (inlet) pressure p_p. Not finite: not used (the twin keeps the last pressures, flag SENSOR_FAULT); \
              at the end of initialisation it must exceed p_outlet. Start: operating.outlet_pressure + \
              operating.pressure_drop.",
    },
    Variable {
        name: "p_outlet",
        unit: Some("Pa"),
        doc: "Outlet pressure p_c (the circuit downstream). Not finite: not used (the twin keeps the last pressures, \
              flag SENSOR_FAULT). Start: operating.outlet_pressure.",
    },
    Variable {
        name: "second_reading",
        unit: Some(READING_UNIT),
        doc: "The condition monitor's second sensor's reading, of the quantity of the packaged file's monitor.sensor \
              (p_a, p_b or dp_ab in Pa, x in m): one reading per communication step, taken at the step's start \
              (NaN: no reading this step). Without a second sensor in the file only NaN is accepted. Start: NaN.",
    },
];

/// The input of value reference `vr`, with its index in [`INPUTS`].
pub fn input_of(vr: u32) -> Option<usize> {
    let i = vr.checked_sub(VR_T_OIL)? as usize;
    (i < INPUTS.len()).then_some(i)
}

/// Value reference of the first output (`x`); the outputs follow in
/// [`OUTPUTS`] order.
pub const VR_FIRST_OUTPUT: u32 = 10;
/// Value reference of the Boolean parameter `machine.present`.
pub const VR_MACHINE_PRESENT: u32 = 100;
/// Value reference of the first parameter-file field; the fields follow in
/// [`fields`] order (core, machine, estimator: file order).
pub const VR_FIRST_FIELD: u32 = 1000;

/// An input or an output of the twin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variable {
    /// Variable name.
    pub name: &'static str,
    /// FMI unit name (`None`: an integer, no unit).
    pub unit: Option<&'static str>,
    /// Description.
    pub doc: &'static str,
}

/// The outputs, in value-reference order from [`VR_FIRST_OUTPUT`]; the last
/// (`flags`) is an integer, the others are Float64.
pub const OUTPUTS: [Variable; 10] = [
    Variable {
        name: "x",
        unit: Some("m"),
        doc: "Plunger displacement (0: window closed).",
    },
    Variable {
        name: "v",
        unit: Some("m/s"),
        doc: "Plunger velocity.",
    },
    Variable {
        name: "p_a",
        unit: Some("Pa"),
        doc: "Chamber (a) pressure.",
    },
    Variable {
        name: "p_b",
        unit: Some("Pa"),
        doc: "Chamber (b) pressure.",
    },
    Variable {
        name: "Q_a",
        unit: Some("m3/s"),
        doc: "Flow leaving chamber (a) through its capillary.",
    },
    Variable {
        name: "Q_b",
        unit: Some("m3/s"),
        doc: "Flow leaving chamber (b) through its orifice.",
    },
    Variable {
        name: "Q_throt",
        unit: Some("m3/s"),
        doc: "Flow through the window opened by the plunger.",
    },
    Variable {
        name: "Q0",
        unit: Some("m3/s"),
        doc: "Total flow Q0 = Q_a + Q_b + Q_throt.",
    },
    Variable {
        name: "compensation_error",
        unit: Some("m3/s"),
        doc: "Q0 - (Q_work + dQ_lost(T)) of the driven machine; NaN when machine.present is false.",
    },
    Variable {
        name: "flags",
        unit: None,
        doc: "Estimator flags, a bit set: 1 AT_STOP, 2 OUT_OF_RANGE, 4 NOT_UNIQUE, 8 UNSTABLE, 16 SENSOR_FAULT, 64 DEGRADED; the condition monitor's 1024 DEVICE_CHANGED, 2048 CAPILLARY_RESTRICTED, 4096 ORIFICE_CLOGGED, 8192 SPRING_RELAXED, 16384 PRELOAD_LOST, 32768 PLUNGER_STICKING, 65536 SENSOR_OFFSET, 262144 INNOVATION_REJECTED (docs/fmu.md).",
    },
];

/// Index of `flags` in [`OUTPUTS`].
pub const FLAGS_OUTPUT: usize = 9;

/// Every output: [`OUTPUTS`], then the condition monitor's health
/// estimate, one Float64 per field of the core's `HEALTH_FIELDS` (its
/// name, unit and description), in value-reference order from
/// [`VR_FIRST_OUTPUT`].
pub fn outputs() -> impl Iterator<Item = Variable> {
    OUTPUTS.into_iter().chain(HEALTH_FIELDS.iter().map(|f| Variable {
        name: f.name,
        unit: Some(match f.unit {
            HealthUnit::One | HealthUnit::Count => "1",
            HealthUnit::Reading => READING_UNIT,
            HealthUnit::Newton => "N",
            HealthUnit::Kelvin => "K",
            HealthUnit::Celsius => "degC",
        }),
        doc: f.doc,
    }))
}

/// Number of outputs ([`outputs`]).
pub const OUTPUT_COUNT: usize = OUTPUTS.len() + HEALTH_FIELDS.len();

/// Index in [`outputs`] of the first health value.
pub const FIRST_HEALTH_OUTPUT: usize = OUTPUTS.len();

/// The output of index `i` in [`outputs`].
pub fn output(i: usize) -> Option<Variable> {
    outputs().nth(i)
}

/// The parameter file's fields in the variables' order: core, machine,
/// estimator, probe in file order, then the estimator's sensor-kind fields
/// (its `[tolerances]` are not variables: they travel with the packaged
/// file, [`crate::instance::Setup`]).
pub fn fields() -> impl Iterator<Item = &'static Field> {
    let (estimator, sensor) = ESTIMATOR_FIELDS.split_at(first_sensor_kind_field());
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(estimator.iter())
        .chain(PROBE_FIELDS.iter())
        .chain(sensor.iter())
}

/// Where `[estimator]`'s sensor-kind fields start (`estimator.sensor`, the
/// NTC's): they came after the `[probe]` fields, and take the value
/// references after theirs, so that every earlier variable keeps its
/// reference.
fn first_sensor_kind_field() -> usize {
    ESTIMATOR_FIELDS
        .iter()
        .position(|f| f.path == "estimator.sensor")
        .unwrap_or(ESTIMATOR_FIELDS.len())
}

/// Number of parameter-file fields.
pub const FIELD_COUNT: usize = CORE_FIELDS.len() + MACHINE_FIELDS.len() + ESTIMATOR_FIELDS.len() + PROBE_FIELDS.len();

/// The field of value reference `vr`, with its index in [`fields`] order.
pub fn field_of(vr: u32) -> Option<(usize, &'static Field)> {
    let i = vr.checked_sub(VR_FIRST_FIELD)? as usize;
    fields().nth(i).map(|f| (i, f))
}

/// The lowest value a field accepts (zero for a field that may be zero).
pub fn field_min(f: &Field) -> f64 {
    if f.kind == Kind::OrZero { 0.0 } else { f.min }
}

/// An FMI unit: its name and its SI base-unit exponents (`kg, m, s, A, K,
/// mol, cd, rad`) with `factor` and `offset` (`value_SI = factor * value +
/// offset`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    /// Name (Modelica spelling: `m3/s`, `degC`, `N.s/m`).
    pub name: &'static str,
    /// Exponents of kg, m, s, A, K, mol, cd, rad.
    pub exponents: [i8; 8],
    /// Factor to SI.
    pub factor: f64,
    /// Offset to SI.
    pub offset: f64,
}

const fn unit(name: &'static str, exponents: [i8; 8]) -> Unit {
    Unit {
        name,
        exponents,
        factor: 1.0,
        offset: 0.0,
    }
}

/// Every unit the FMU declares: the schema's units and the outputs'.
pub const UNITS: [Unit; 20] = [
    unit("1", [0, 0, 0, 0, 0, 0, 0, 0]),
    unit("m", [0, 1, 0, 0, 0, 0, 0, 0]),
    unit("m/s", [0, 1, -1, 0, 0, 0, 0, 0]),
    unit("Pa", [1, -1, -2, 0, 0, 0, 0, 0]),
    unit("m3/s", [0, 3, -1, 0, 0, 0, 0, 0]),
    unit("m3", [0, 3, 0, 0, 0, 0, 0, 0]),
    unit("kg", [1, 0, 0, 0, 0, 0, 0, 0]),
    unit("kg/m3", [1, -3, 0, 0, 0, 0, 0, 0]),
    unit("K", [0, 0, 0, 0, 1, 0, 0, 0]),
    unit("1/K", [0, 0, 0, 0, -1, 0, 0, 0]),
    unit("1/K2", [0, 0, 0, 0, -2, 0, 0, 0]),
    unit("1/K4", [0, 0, 0, 0, -4, 0, 0, 0]),
    unit("N.s/m", [1, 0, -1, 0, 0, 0, 0, 0]),
    unit("N/m", [1, 0, -2, 0, 0, 0, 0, 0]),
    unit("N", [1, 1, -2, 0, 0, 0, 0, 0]),
    unit("s", [0, 0, 1, 0, 0, 0, 0, 0]),
    unit("Hz", [0, 0, -1, 0, 0, 0, 0, 0]),
    unit("K/s", [0, 0, -1, 0, 1, 0, 0, 0]),
    unit("Ohm", [1, 2, -3, -2, 0, 0, 0, 0]),
    Unit {
        name: "degC",
        exponents: [0, 0, 0, 0, 1, 0, 0, 0],
        factor: 1.0,
        offset: 273.15,
    },
];

/// The FMI unit of a schema unit (`"m^3/s"` -> `m3/s`, `"C"` -> `degC`,
/// `"1/C"` -> `1/K`: a coefficient per degree is per kelvin); `None` for
/// a dimensionless field (`"-"`) or a unit this table does not know (a
/// unit test checks every schema field has one).
pub fn fmi_unit(schema_unit: &str) -> Option<&'static str> {
    Some(match schema_unit {
        "m" => "m",
        "m^3" => "m3",
        "m^3/s" => "m3/s",
        "kg" => "kg",
        "kg/m^3" => "kg/m3",
        "K" => "K",
        "1/K" | "1/C" => "1/K",
        "1/C^2" => "1/K2",
        "1/C^4" => "1/K4",
        "N s/m" => "N.s/m",
        "N/m" => "N/m",
        "Pa" => "Pa",
        "s" => "s",
        "Hz" => "Hz",
        "C/s" => "K/s",
        "ohm" => "Ohm",
        "C" => "degC",
        _ => return None,
    })
}

/// The units the model description declares: those some variable uses, in
/// [`UNITS`] order.
pub fn used_units() -> Vec<Unit> {
    let mut names: Vec<&str> = fields().filter_map(|f| fmi_unit(f.unit)).collect();
    // The second sensor's unit is Pa or m, both declared for other variables.
    names.extend(outputs().filter_map(|o| o.unit));
    names.extend(["Pa", "m"]);
    names.push("degC");
    names.push("s");
    UNITS.iter().copied().filter(|u| names.contains(&u.name)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_schema_unit_is_declared() {
        for f in fields() {
            if f.unit == "-" {
                continue;
            }
            let name = fmi_unit(f.unit).unwrap_or_else(|| panic!("{}: unit {} has no FMI unit", f.path, f.unit));
            assert!(UNITS.iter().any(|u| u.name == name), "{}: {name} not in UNITS", f.path);
        }
        for o in outputs().chain(INPUTS).filter_map(|o| o.unit) {
            for d in [false, true] {
                assert!(UNITS.iter().any(|u| u.name == resolve_unit(o, d)), "{o}");
            }
        }
    }

    #[test]
    fn value_references_are_unique_and_resolve() {
        assert_eq!(fields().count(), FIELD_COUNT);
        let mut vrs: Vec<u32> = vec![VR_TIME, VR_MACHINE_PRESENT];
        vrs.extend((0..INPUTS.len() as u32).map(|i| VR_T_OIL + i));
        vrs.extend((0..OUTPUT_COUNT as u32).map(|i| VR_FIRST_OUTPUT + i));
        vrs.extend((0..FIELD_COUNT as u32).map(|i| VR_FIRST_FIELD + i));
        let n = vrs.len();
        vrs.sort_unstable();
        vrs.dedup();
        assert_eq!(vrs.len(), n);
        assert!(VR_FIRST_OUTPUT + OUTPUT_COUNT as u32 <= VR_MACHINE_PRESENT);
        assert_eq!(outputs().count(), OUTPUT_COUNT);
        assert!(VR_T_OIL + INPUTS.len() as u32 <= VR_FIRST_OUTPUT);
        for (i, f) in fields().enumerate() {
            assert_eq!(field_of(VR_FIRST_FIELD + i as u32), Some((i, f)));
        }
        assert_eq!(field_of(VR_FIRST_FIELD + FIELD_COUNT as u32), None);
        assert_eq!(field_of(VR_T_OIL), None);
        for (k, vr) in [VR_T_OIL, VR_P_SUPPLY, VR_P_OUTLET, VR_SECOND_READING]
            .into_iter()
            .enumerate()
        {
            assert_eq!(input_of(vr), Some(k));
            assert!(vr < VR_FIRST_OUTPUT);
        }
        assert_eq!(input_of(VR_SECOND_READING + 1), None);
        assert_eq!(input_of(VR_TIME), None);
        assert_eq!(OUTPUTS[FLAGS_OUTPUT].name, "flags");
    }

    #[test]
    fn the_flags_doc_gives_each_flags_bit() {
        use compensator::estimator::Flags;
        let doc = OUTPUTS[FLAGS_OUTPUT].doc;
        let mut named = Flags(Flags::AT_STOP.0 | Flags::OUT_OF_RANGE.0 | Flags::NOT_UNIQUE.0);
        named.insert(Flags(Flags::UNSTABLE.0 | Flags::SENSOR_FAULT.0 | Flags::DEGRADED.0));
        // The FMU's readings are values, never the sensor's own faults.
        named.insert(Flags(
            compensator::estimator::health::MONITOR_FLAGS.0 & !Flags::SECOND_SENSOR_FAULT.0,
        ));
        for (bit, name) in Flags::NAMES.iter().enumerate() {
            if named.0 & (1 << bit) != 0 {
                assert!(doc.contains(&format!("{} {name}", 1u32 << bit)), "{name}");
            }
        }
    }

    #[test]
    fn temperatures_are_offset_from_kelvin() {
        let c = UNITS.iter().find(|u| u.name == "degC").expect("degC");
        assert_eq!((c.factor, c.offset), (1.0, 273.15));
        assert_eq!(fmi_unit("C"), Some("degC"));
        assert_eq!(fmi_unit("-"), None);
    }
}
