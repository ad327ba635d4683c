//! Every field of the file lands in the struct field of its name.
//!
//! The schema macro declares each field once (`spring_rate: "plunger".
//! "spring_rate"`), and every other piece of code names fields rather than
//! counting them. What remains to check is the list itself: that each
//! `section.key` fills the struct field it should, for the reader, the
//! writer and the validation. [`EVERY_FIELD`] says so by hand, apart from
//! the macro: a field inserted, removed, moved or given another's key makes
//! these tests fail.

use crate::{
    CORE_FIELDS, ESTIMATOR_FIELDS, MACHINE_FIELDS, MONITOR_FIELDS, PROBE_FIELDS, ParamError, Problem, RawParams,
};

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
    ("estimator.max_oil_rate", 0.7, |r| r.estimator.max_oil_rate),
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
    ("estimator.sensor", 1.0, |r| r.estimator.sensor),
    ("estimator.ntc_r25", 10_100.0, |r| r.estimator.ntc_r25),
    ("estimator.ntc_beta", 3950.0, |r| r.estimator.ntc_beta),
    ("estimator.ntc_sh_a", 1.1292e-3, |r| r.estimator.ntc_sh_a),
    ("estimator.ntc_sh_b", 2.3411e-4, |r| r.estimator.ntc_sh_b),
    ("estimator.ntc_sh_c", 8.7755e-8, |r| r.estimator.ntc_sh_c),
    ("estimator.ntc_series", 12_000.0, |r| r.estimator.ntc_series),
    ("estimator.adc_bits", 10.0, |r| r.estimator.adc_bits),
    ("estimator.ntc_oversampling", 16.0, |r| r.estimator.ntc_oversampling),
    ("probe.time_constant", 6.5, |r| r.probe.time_constant),
    ("probe.well_time_constant", 21.0, |r| r.probe.well_time_constant),
    ("probe.noise", 0.015, |r| r.probe.noise),
    ("probe.tolerance_a", 0.15, |r| r.probe.tolerance_a),
    ("probe.tolerance_b", 0.002, |r| r.probe.tolerance_b),
    ("monitor.sensor", 2.0, |r| r.monitor.sensor),
    // The only value of `output` besides its default is 1, which
    // `estimator.sensor` has too; a swap of the two is still seen: the
    // file names them ("current", "ntc"), and each is refused under the
    // other's key.
    ("monitor.output", 1.0, |r| r.monitor.output),
    ("monitor.range_min", -20_000.0, |r| r.monitor.range_min),
    ("monitor.range_max", 1.2e6, |r| r.monitor.range_max),
    ("monitor.accuracy", 0.001, |r| r.monitor.accuracy),
    ("monitor.noise", 250.0, |r| r.monitor.noise),
    ("monitor.sample_hz", 200.0, |r| r.monitor.sample_hz),
    ("monitor.adc_bits", 8.0, |r| r.monitor.adc_bits),
    ("monitor.divider", 0.6, |r| r.monitor.divider),
    ("monitor.shunt", 120.0, |r| r.monitor.shunt),
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
    let tables = every_schema_field();
    assert_eq!(every_schema_field().count(), EVERY_FIELD.len());
    for (field, (path, v, _)) in tables.zip(EVERY_FIELD) {
        assert_eq!(field.path, *path);
        assert_eq!(field.path.split_once('.'), Some((field.section, field.key)));
        assert_ne!(field.default, Some(*v), "{path}: the test's value is the default");
    }
    for (i, (a, va, _)) in EVERY_FIELD.iter().enumerate() {
        for (b, vb, _) in &EVERY_FIELD[i + 1..] {
            assert_ne!(a, b);
            if (*a, *b) == ("estimator.sensor", "monitor.output") {
                continue;
            }
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
            // Steinhart-Hart's coefficients come together: one left out
            // (0) beside the others is refused under its own name.
            (Some(("estimator", "ntc_sh_a" | "ntc_sh_b" | "ntc_sh_c")), raw) => {
                let e = raw.expect_err(path);
                assert_eq!(e.field, *path);
                assert!(matches!(e.problem, Problem::Inconsistent(_)), "{path}: {e}");
            }
            // Estimator and probe keys have defaults, and so have the
            // monitor's but its range and noise (required with a sensor).
            (Some(("monitor", "range_min" | "range_max" | "noise")), Err(e)) => {
                assert_eq!((e.field, e.problem), (*path, Problem::Missing));
            }
            (Some(("estimator" | "probe" | "monitor", _)), raw) => assert!(raw.is_ok(), "{path}: {raw:?}"),
            (_, Err(e)) => assert_eq!((e.field, e.problem), (*path, Problem::Missing)),
            (_, Ok(_)) => panic!("{path}: accepted without it"),
        }
    }
}

/// The value of the field `path` as the file writes it: a number, or the
/// name of a named field's value (`sensor = "ntc"`).
#[cfg(feature = "toml")]
fn file_value(path: &str, v: f64) -> String {
    match crate::field_by_path(path).map(|f| f.kind) {
        Some(crate::Kind::Named(names)) => format!("\"{}\"", names[v as usize]),
        _ => crate::file::fmt_float(v),
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
        let _ = writeln!(text, "{key} = {}", file_value(path, *v));
    }
    let raw = parse(&text).unwrap();
    assert_every_field_in_place(&raw);

    let written = to_toml(&raw);
    let back = parse(&written).unwrap();
    assert_eq!(back, raw, "{written}");
    assert_every_field_in_place(&back);
    for (path, v, _) in EVERY_FIELD {
        let (_, key) = path.split_once('.').unwrap();
        let line = match crate::field_by_path(path).map(|f| f.kind) {
            Some(crate::Kind::Named(_)) => format!("{key} = {}\n", file_value(path, *v)),
            _ => format!("{key} = {}    #", fmt_float(*v)),
        };
        assert!(written.contains(&line), "{path}: no `{line}` in\n{written}");
    }
}

/// Every field of the schema, in file order.
fn every_schema_field() -> impl Iterator<Item = &'static crate::Field> + Clone {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .chain(PROBE_FIELDS.iter())
        .chain(MONITOR_FIELDS.iter())
}

#[test]
fn every_plausible_range_holds_its_default_and_the_tests_value() {
    use crate::Kind;
    for f in every_schema_field() {
        assert!(f.min.is_finite() && f.max.is_finite() && f.min < f.max, "{}", f.path);
        if let Some(d) = f.default {
            assert_eq!(f.check(d), Ok(d), "{}: the default is refused", f.path);
        }
        let (_, v, _) = EVERY_FIELD.iter().find(|(p, _, _)| *p == f.path).unwrap();
        assert_eq!(f.check(*v), Ok(*v), "{}", f.path);
        if let Kind::OneOf(values) = f.kind {
            assert!(values.iter().all(|x| (f.min..=f.max).contains(x)), "{}", f.path);
        }
        // Outside the range, on either side, by a hair: refused by name.
        for out in [f.min - 1e-9 * f.min.abs().max(1e-300), f.max * (1.0 + 1e-9)] {
            let e = f.check(out).unwrap_err();
            assert_eq!(e.field, f.path);
            assert!(matches!(e.problem, Problem::Implausible(_)), "{}: {e}", f.path);
        }
    }
}

#[test]
fn the_walther_bounds_are_the_viscosity_bounds() {
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (lo, hi) = crate::VISCOSITY_40C_CST;
    assert_eq!(crate::schema::WALTHER_40C, (w(lo), w(hi)));
    assert_eq!(crate::schema::LOG10_T40, 313.15f64.log10());
}

#[test]
fn out_of_range_values_name_the_field_the_range_and_the_unit() {
    let e = read(Some(("plunger.mass", 1e-12))).unwrap_err();
    assert_eq!(
        e.to_string(),
        "plunger.mass = 1e-12: must lie in [1e-6, 1000] kg (plausible range)"
    );
    let e = read(Some(("fluid.bulk_modulus", 1e30))).unwrap_err();
    assert_eq!(
        e.to_string(),
        "fluid.bulk_modulus = 1e30: must lie in [1e7, 1e10] Pa (plausible range)"
    );
    // Dimensionless: no unit.
    let e = read(Some(("slot.discharge_coefficient", 1.5))).unwrap_err();
    assert_eq!(
        e.to_string(),
        "slot.discharge_coefficient = 1.5: must lie in [0.1, 1] (plausible range)"
    );
    let e = read(Some(("estimator.mains_hz", 55.0))).unwrap_err();
    assert_eq!(e.to_string(), "estimator.mains_hz = 55: must be 50 or 60");
}

#[test]
fn a_field_out_of_its_range_is_blamed_before_any_rule_between_fields() {
    // A plunger of 1e160 m would make chamber (a) too small: the diameter
    // is named, not the chamber.
    let e = read(Some(("plunger.diameter", 1e160))).unwrap_err();
    assert_eq!(e.field, "plunger.diameter");
    // An estimator field out of range comes before a core rule that fails.
    let e = RawParams::from_lookup(|s, k| match (s, k) {
        ("plunger", "preload") => Some(1.0),
        ("estimator", "rtd_r0") => Some(1e-300),
        _ => lookup(s, k, None),
    })
    .unwrap_err();
    assert_eq!(e.field, "estimator.rtd_r0");
    // Walther constants each in range but no oil together: blamed on a.
    let e = read(Some(("fluid.walther_a", 20.0))).unwrap_err();
    assert_eq!(
        e.to_string(),
        "fluid.walther_a = 20: the oil's viscosity at 40 C (fluid.walther_a, fluid.walther_b) must lie in [2, 1e5] cSt (plausible range)"
    );
}

#[test]
fn numbers_are_printed_in_their_shortest_form() {
    use crate::Compact;
    for (v, text) in [
        (1e300, "1e300"),
        (5e-324, "5e-324"),
        (0.0015, "0.0015"),
        (1000.0, "1000"),
        (10000.0, "1e4"),
        (0.002, "0.002"),
        (0.0001, "1e-4"),
        (4e5, "4e5"),
        (65534.0, "65534"),
        (25000.5, "25000.5"),
        (-1e-5, "-1e-5"),
        (0.0, "0"),
        (0.5, "0.5"),
        (1.0344023879631311e-5, "1.0344023879631311e-5"),
        (f64::NAN, "NaN"),
        (f64::NEG_INFINITY, "-inf"),
    ] {
        assert_eq!(Compact(v).to_string(), text);
    }
    // Any bit pattern: at most 24 characters, read back exactly.
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    for _ in 0..100_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let v = f64::from_bits(x);
        let s = Compact(v).to_string();
        assert!(s.len() <= 24, "{s}");
        if v.is_finite() {
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
        }
    }
}

#[test]
fn echoed_input_stays_on_one_short_line() {
    use crate::{ECHO_MAX, Echo};
    let long = "k".repeat(1_000_000);
    let s = Echo::head(&long).to_string();
    assert_eq!(s.chars().count(), ECHO_MAX);
    assert!(s.ends_with('…'));
    let s = Echo::tail(&format!("{long}/paper.toml")).to_string();
    assert!(s.starts_with('…') && s.ends_with("/paper.toml"), "{s}");
    assert_eq!(Echo::head("ma\nss").to_string(), "ma\\nss");
    assert_eq!(Echo::head("plunger.mass").to_string(), "plunger.mass");
}

#[cfg(feature = "toml")]
#[test]
fn file_errors_are_one_bounded_line_naming_the_key() {
    use crate::file::{LoadError, parse};
    let one_line = |text: &str| {
        let e = parse(text).unwrap_err().to_string();
        assert_eq!(e.lines().count(), 1, "{e:?}");
        assert!(e.len() <= 300, "{} bytes", e.len());
        e
    };
    assert_eq!(
        one_line("[plunger]\nmass = 0.01\nmass = 0.02\n"),
        "line 3: duplicate key plunger.mass"
    );
    assert_eq!(
        one_line("[plunger]\nmass = 0.01\n[plunger]\n"),
        "line 3: duplicate table [plunger]"
    );
    let huge = format!("[plunger]\n{} = 1\n", "k".repeat(10_000_000));
    assert!(one_line(&huge).ends_with("…: unknown key"));
    assert_eq!(
        one_line("[plunger]\n\"ma\\nss\" = 1\n"),
        "plunger.ma\\nss: unknown key; did you mean plunger.mass?"
    );
    assert_eq!(
        one_line("plunger = 1\n"),
        "plunger: expected a section [plunger], not a value"
    );
    let e = parse("[plunger]\nmass = [1.0]\n").unwrap_err();
    assert_eq!(e.field(), Some("plunger.mass"));
    assert_eq!(e.to_string(), "plunger.mass: expected a number, found a TOML array");
    assert!(matches!(e, LoadError::NotANumber { found: "array", .. }));
}

/// The `[tolerances]` section and `[[correlation]]` tables: read under the
/// fields' names, written back, and refused by name when wrong.
#[cfg(feature = "toml")]
#[test]
fn tolerances_and_correlations_round_trip_and_are_checked_by_name() {
    use crate::file::{parse, to_toml};
    use std::fmt::Write as _;

    let mut base = String::new();
    let mut section = "";
    for (path, v, _) in EVERY_FIELD {
        let (s, key) = path.split_once('.').unwrap();
        if s != section {
            let _ = writeln!(base, "[{s}]");
            section = s;
        }
        let _ = writeln!(base, "{key} = {}", file_value(path, *v));
    }
    let with = |extra: &str| format!("{base}\n{extra}");
    let text = with(
        "[tolerances]\nlaminar_throttle.diameter = 5.8e-6\nplunger.spring_rate = 700.0\n\
         [tolerances.machine]\nleakage_reference = 1e-6\n\
         [[correlation]]\nfields = [\"plunger.spring_rate\", \"laminar_throttle.diameter\"]\ncoefficient = -0.25\n",
    );
    let raw = parse(&text).unwrap();
    assert_eq!(raw.tolerances.core.laminar_diameter, 5.8e-6);
    assert_eq!(raw.tolerances.core.spring_rate, 700.0);
    assert_eq!(raw.tolerances.machine.leakage_reference, 1e-6);
    assert_eq!(raw.tolerances.core.mass, 0.0);
    assert_eq!(
        raw.tolerances
            .correlation("laminar_throttle.diameter", "plunger.spring_rate"),
        -0.25
    );
    assert_eq!(raw.tolerances.correlation("plunger.mass", "plunger.spring_rate"), 0.0);
    let back = parse(&to_toml(&raw)).unwrap();
    assert_eq!(back, raw, "{}", to_toml(&raw));

    let refused = |extra: &str| parse(&with(extra)).unwrap_err().to_string();
    assert_eq!(
        refused("[tolerances]\nplunger.sping_rate = 1.0\n"),
        "tolerances.plunger.sping_rate: unknown key; did you mean tolerances.plunger.spring_rate?"
    );
    assert_eq!(
        refused("[tolerances]\nestimator.tick_hz = 1.0\n"),
        "tolerances.estimator.tick_hz: unknown key"
    );
    assert_eq!(
        refused("[tolerances]\nplunger.mass = -1e-3\n"),
        "tolerances.plunger.mass = -0.001: must be positive"
    );
    assert_eq!(
        refused("[tolerances]\nplunger.mass = 0.5\n"),
        "tolerances.plunger.mass = 0.5: must lie in [0, 0.007] (at most a third of the field's value)"
    );
    assert_eq!(
        refused("[tolerances]\nplunger.mass = \"big\"\n"),
        "tolerances.plunger.mass: expected a number, found a TOML string"
    );
    let two = "[tolerances]\nplunger.mass = 1e-3\nplunger.spring_rate = 700.0\nplunger.damping = 0.1\n";
    assert_eq!(
        refused(&format!(
            "{two}[[correlation]]\nfields = [\"plunger.mass\", \"plunger.spring_rate\"]\ncoefficient = 1.5\n"
        )),
        "correlation of plunger.mass and plunger.spring_rate = 1.5: a correlation coefficient must lie in [-1, 1]"
    );
    assert_eq!(
        refused(&format!(
            "{two}[[correlation]]\nfields = [\"plunger.mass\", \"plunger.stroke\"]\ncoefficient = 0.5\n"
        )),
        "correlation of plunger.mass and plunger.stroke = 0.5: both fields need a tolerance in [tolerances]"
    );
    assert_eq!(
        refused(&format!(
            "{two}[[correlation]]\nfields = [\"plunger.mass\"]\ncoefficient = 0.5\n"
        )),
        "correlation 1: fields must name two fields, fields = [\"section.key\", \"section.key\"]"
    );
    // Three fields each correlated 0.9 with one and -0.9 with another:
    // no population has that matrix.
    let psd = format!(
        "{two}[[correlation]]\nfields = [\"plunger.mass\", \"plunger.spring_rate\"]\ncoefficient = 0.9\n\
         [[correlation]]\nfields = [\"plunger.mass\", \"plunger.damping\"]\ncoefficient = 0.9\n\
         [[correlation]]\nfields = [\"plunger.spring_rate\", \"plunger.damping\"]\ncoefficient = -0.9\n"
    );
    assert!(
        refused(&psd).contains("not a valid correlation matrix"),
        "{}",
        refused(&psd)
    );
    // A machine tolerance without a [machine] section is named.
    let no_machine: String = base.split("[machine]").next().unwrap().to_string()
        + &base
            .split("[estimator]")
            .nth(1)
            .map(|r| format!("[estimator]{r}"))
            .unwrap();
    let e = parse(&format!("{no_machine}\n[tolerances]\nmachine.working_flow = 1e-9\n")).unwrap_err();
    assert_eq!(e.field(), Some("tolerances.machine.working_flow"), "{e}");
}

#[test]
fn every_field_is_reached_by_its_path_for_reading_and_writing() {
    let raw = read(None).expect("the test's values are valid");
    for (path, v, get) in EVERY_FIELD {
        assert_eq!(raw.get(path), Ok(*v), "{path}");
        let mut changed = raw;
        changed.set(path, 0.5).unwrap();
        assert_eq!(get(&changed), 0.5, "{path}: set wrote another field");
        // Every other field is untouched.
        for (other, w, get_other) in EVERY_FIELD {
            if other != path {
                assert_eq!(get_other(&changed), *w, "setting {path} changed {other}");
            }
        }
    }
    let mut no_machine = raw;
    no_machine.machine = None;
    let e = no_machine.get("machine.working_flow").unwrap_err();
    assert_eq!(e.problem, crate::PathProblem::NoMachineSection);
    assert!(no_machine.set("machine.working_flow", 1.0).is_err());
    let e = raw.get("plunger.sping_rate").unwrap_err();
    assert_eq!(e.problem, crate::PathProblem::Unknown);
    // The nearest valid name is the TOML reader's (feature `toml`).
    #[cfg(feature = "toml")]
    assert_eq!(
        e.to_string(),
        "unknown parameter 'plunger.sping_rate' (a section.key of docs/parameters.md); did you mean plunger.spring_rate?"
    );
}

#[cfg(feature = "toml")]
#[test]
fn misspelt_keys_and_sections_get_the_nearest_valid_name() {
    use crate::file::{nearest_path, parse};
    assert_eq!(nearest_path("plunger.sping_rate"), Some("plunger.spring_rate"));
    assert_eq!(nearest_path("plungr.mass"), Some("plunger.mass"));
    assert_eq!(nearest_path("plunger.bulk_modulus"), Some("fluid.bulk_modulus"));
    assert_eq!(nearest_path("estimator.oil_mx"), Some("estimator.oil_max"));
    assert_eq!(nearest_path("something.else"), None);
    let preset = include_str!("../presets/paper.toml");
    let typo = preset.replace("spring_rate", "sping_rate");
    assert_eq!(
        parse(&typo).unwrap_err().to_string(),
        "plunger.sping_rate: unknown key; did you mean plunger.spring_rate?"
    );
    let typo = preset.replace("[plunger]", "[plungr]");
    let e = parse(&typo).unwrap_err().to_string();
    assert!(e.ends_with("unknown key; did you mean [plunger]?"), "{e}");
    // A section named otherwise: its keys are found where they belong.
    let typo = preset.replace("[fluid]", "[oil]");
    let e = parse(&typo).unwrap_err().to_string();
    assert!(e.ends_with("; did you mean fluid.bulk_modulus?"), "{e}");
    let e = parse("[plunger]\ncolour = 1\n").unwrap_err().to_string();
    assert_eq!(e, "plunger.colour: unknown key");
}
