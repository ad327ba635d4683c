//! Every field of the file lands in the struct field of its name.
//!
//! The schema macro declares each field once (`spring_rate: "plunger".
//! "spring_rate"`), and every other piece of code names fields rather than
//! counting them. What remains to check is the list itself: that each
//! `section.key` fills the struct field it should, for the reader, the
//! writer and the validation. [`EVERY_FIELD`] says so by hand, apart from
//! the macro: a field inserted, removed, moved or given another's key makes
//! these tests fail.

use crate::{CORE_FIELDS, ESTIMATOR_FIELDS, MACHINE_FIELDS, ParamError, Problem, RawParams};

type Get = fn(&RawParams) -> f64;

fn machine(r: &RawParams) -> crate::RawMachine {
    r.machine.expect("the [machine] section was given")
}

/// Every field of the file in file order: its `section.key`, a value that
/// no other field has (none is its field's default either, so that the
/// writer keeps every key), and where the reader must put it. The values
/// form a valid parameter set.
const EVERY_FIELD: &[(&str, f64, Get)] = &[
    ("fluid.walther_a", 9.5, |r| r.core.walther_a),
    ("fluid.walther_b", 3.75, |r| r.core.walther_b),
    ("fluid.density_15", 871.0, |r| r.core.density_15),
    ("fluid.expansion", 6.5e-4, |r| r.core.expansion),
    ("fluid.bulk_modulus", 1.6e9, |r| r.core.bulk_modulus),
    ("laminar_throttle.diameter", 8.1e-4, |r| r.core.laminar_diameter),
    ("laminar_throttle.length", 0.0242, |r| r.core.laminar_length),
    ("turbulent_throttle.diameter", 7.2e-4, |r| r.core.turbulent_diameter),
    ("turbulent_throttle.discharge_coefficient", 0.61, |r| {
        r.core.turbulent_discharge
    }),
    ("plunger.diameter", 0.0101, |r| r.core.plunger_diameter),
    ("plunger.mass", 0.021, |r| r.core.mass),
    ("plunger.damping", 2.2, |r| r.core.damping),
    ("plunger.spring_rate", 25600.0, |r| r.core.spring_rate),
    ("plunger.preload", 1.1e-5, |r| r.core.preload),
    ("plunger.stroke", 0.0015, |r| r.core.stroke),
    ("slot.diameter", 0.0021, |r| r.core.slot_diameter),
    ("slot.discharge_coefficient", 0.63, |r| r.core.slot_discharge),
    ("chambers.volume_a", 2.1e-6, |r| r.core.volume_a),
    ("chambers.volume_b", 2.3e-6, |r| r.core.volume_b),
    ("operating.pressure_drop", 410_000.0, |r| r.core.pressure_drop),
    ("operating.outlet_pressure", 1500.0, |r| r.core.outlet_pressure),
    ("machine.working_flow", 3.6e-7, |r| machine(r).working_flow),
    ("machine.leakage_reference", 3.5e-5, |r| machine(r).leakage_reference),
    ("machine.leakage_temperature", 41.0, |r| machine(r).leakage_temperature),
    ("estimator.tick_hz", 800.0, |r| r.estimator.tick_hz),
    ("estimator.filter_time_constant", 0.25, |r| {
        r.estimator.filter_time_constant
    }),
    ("estimator.spike_threshold", 4.5, |r| r.estimator.spike_threshold),
    ("estimator.spike_limit", 7.0, |r| r.estimator.spike_limit),
    ("estimator.valid_min", 24.0, |r| r.estimator.valid_min),
    ("estimator.valid_max", 79.0, |r| r.estimator.valid_max),
    ("estimator.oil_min", -15.0, |r| r.estimator.oil_min),
    ("estimator.oil_max", 140.0, |r| r.estimator.oil_max),
    ("estimator.telemetry_hz", 3.0, |r| r.estimator.telemetry_hz),
    ("estimator.rtd_r0", 101.0, |r| r.estimator.rtd_r0),
    ("estimator.rtd_reference", 440.0, |r| r.estimator.rtd_reference),
    ("estimator.rtd_wires", 4.0, |r| r.estimator.rtd_wires),
    ("estimator.mains_hz", 60.0, |r| r.estimator.mains_hz),
    ("estimator.rtd_a", 3.95e-3, |r| r.estimator.rtd_a),
    ("estimator.rtd_b", -5.8e-7, |r| r.estimator.rtd_b),
    ("estimator.rtd_c", -4.2e-12, |r| r.estimator.rtd_c),
];

/// [`EVERY_FIELD`]'s value for `section.key`, with `replaced` (a path and
/// a value) put in place of one.
fn lookup(section: &str, key: &str, replaced: Option<(&str, f64)>) -> Option<f64> {
    let (_, v, _) = EVERY_FIELD
        .iter()
        .find(|(path, _, _)| path.split_once('.') == Some((section, key)))?;
    match replaced {
        Some((path, r)) if path.split_once('.') == Some((section, key)) => Some(r),
        _ => Some(*v),
    }
}

fn read(replaced: Option<(&str, f64)>) -> Result<RawParams, ParamError> {
    RawParams::from_lookup(|section, key| lookup(section, key, replaced))
}

/// Every field `raw` has lands where [`EVERY_FIELD`] says, with its value.
fn assert_every_field_in_place(raw: &RawParams) {
    for (path, v, get) in EVERY_FIELD {
        assert_eq!(get(raw), *v, "{path} is not in its own struct field");
    }
}

#[test]
fn the_schema_lists_the_fields_of_the_hand_written_table_in_its_order() {
    let tables = CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter());
    assert_eq!(tables.clone().count(), EVERY_FIELD.len());
    for (field, (path, v, _)) in tables.zip(EVERY_FIELD) {
        assert_eq!(field.path, *path);
        assert_eq!(field.path.split_once('.'), Some((field.section, field.key)));
        assert_ne!(field.default, Some(*v), "{path}: the test's value is the default");
    }
    for (i, (a, va, _)) in EVERY_FIELD.iter().enumerate() {
        for (b, vb, _) in &EVERY_FIELD[i + 1..] {
            assert_ne!(a, b);
            assert_ne!(va, vb, "{a} and {b} have the same test value: a swap would go unseen");
        }
    }
}

#[test]
fn every_field_is_read_into_the_struct_field_of_its_name() {
    let raw = read(None).expect("the test's values are valid");
    assert_every_field_in_place(&raw);
}

#[test]
fn every_field_is_validated_under_its_own_name() {
    for (path, _, _) in EVERY_FIELD {
        for (bad, problem) in [(f64::NAN, Problem::NotANumber), (f64::INFINITY, Problem::Infinite)] {
            let e = read(Some((path, bad))).expect_err(path);
            assert_eq!((e.field, e.problem), (*path, problem));
        }
    }
}

#[test]
fn every_missing_field_is_named() {
    for (path, _, _) in EVERY_FIELD {
        let raw = RawParams::from_lookup(|section, key| {
            if path.split_once('.') == Some((section, key)) {
                None
            } else {
                lookup(section, key, None)
            }
        });
        match (path.split_once('.'), raw) {
            // Estimator keys have defaults.
            (Some(("estimator", _)), raw) => assert!(raw.is_ok(), "{path}: {raw:?}"),
            (_, Err(e)) => assert_eq!((e.field, e.problem), (*path, Problem::Missing)),
            (_, Ok(_)) => panic!("{path}: accepted without it"),
        }
    }
}

/// The file format by name: a file with every key is read into the struct
/// fields of their names, and the writer writes each field under its own
/// key (read back, every value is again where it belongs).
#[cfg(feature = "toml")]
#[test]
fn every_field_round_trips_through_the_file_by_name() {
    use crate::file::{fmt_float, parse, to_toml};
    use std::fmt::Write as _;

    let mut text = String::new();
    let mut section = "";
    for (path, v, _) in EVERY_FIELD {
        let (s, key) = path.split_once('.').unwrap();
        if s != section {
            let _ = writeln!(text, "[{s}]");
            section = s;
        }
        let _ = writeln!(text, "{key} = {}", fmt_float(*v));
    }
    let raw = parse(&text).unwrap();
    assert_every_field_in_place(&raw);

    let written = to_toml(&raw);
    let back = parse(&written).unwrap();
    assert_eq!(back, raw, "{written}");
    assert_every_field_in_place(&back);
    for (path, v, _) in EVERY_FIELD {
        let (_, key) = path.split_once('.').unwrap();
        let line = format!("{key} = {}    #", fmt_float(*v));
        assert!(written.contains(&line), "{path}: no `{line}` in\n{written}");
    }
}
