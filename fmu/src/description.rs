//! The `modelDescription.xml` of the FMU, for FMI 2.0 or 3.0, generated
//! from the variable table ([`crate::variables`], itself from the
//! parameter schema) and the packaged parameter file (start values, the
//! twin's tick). Also the Markdown table of the variables in
//! `docs/fmu.md` (a test keeps the two the same).

use crate::instance::{Instance, Setup};
use crate::variables::{
    FLAGS_OUTPUT, INPUTS, READING_UNIT, Unit, VR_FIRST_FIELD, VR_FIRST_OUTPUT, VR_MACHINE_PRESENT, VR_T_OIL, VR_TIME,
    field_min, fields, fmi_unit, outputs, resolve_unit, used_units,
};
use compensator::RawParams;
use compensator::dynamics::TwinConfig;
use core::fmt::Write;

/// The FMI version of a model description (and of the functions an
/// importer calls: the binary exports both sets). The binaries' folders
/// are [`crate::platforms::Platform::dir`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0 co-simulation (`binaries/linux64/`, `win64/`, `aarch64-linux/`).
    V2,
    /// FMI 3.0 co-simulation (`binaries/x86_64-linux/`, `x86_64-windows/`, `aarch64-linux/`).
    V3,
}

/// The model identifier: the name of the binary (`compensator.so`).
pub const MODEL_IDENTIFIER: &str = "compensator";

/// The instantiation token (FMI 3.0) or GUID (FMI 2.0): a fingerprint of
/// the crate's version and the variable table (names, value references,
/// units), which the binary checks at instantiation, so that a model
/// description and a binary of different builds are not combined.
pub fn token() -> String {
    let mut text = String::from(env!("CARGO_PKG_VERSION"));
    for (vr, name, unit) in variable_list() {
        let _ = write!(text, ";{vr}:{name}:{}", unit.unwrap_or("-"));
    }
    let a = fnv1a(text.as_bytes(), 0xcbf2_9ce4_8422_2325);
    let b = fnv1a(text.as_bytes(), 0x6c62_272e_07bb_0142);
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

fn fnv1a(bytes: &[u8], seed: u64) -> u64 {
    bytes
        .iter()
        .fold(seed, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// `(value reference, name, unit)` of every variable (FMI 3.0's `time`
/// included).
fn variable_list() -> Vec<(u32, String, Option<&'static str>)> {
    let mut v = vec![(VR_TIME, "time".to_string(), Some("s"))];
    v.extend(
        INPUTS
            .iter()
            .enumerate()
            .map(|(i, v)| (VR_T_OIL + i as u32, v.name.to_string(), v.unit)),
    );
    v.extend(
        outputs()
            .enumerate()
            .map(|(i, o)| (VR_FIRST_OUTPUT + i as u32, o.name.to_string(), o.unit)),
    );
    v.push((VR_MACHINE_PRESENT, "machine.present".into(), None));
    v.extend(
        fields()
            .enumerate()
            .map(|(i, f)| (VR_FIRST_FIELD + i as u32, f.path.to_string(), fmi_unit(f.unit))),
    );
    v
}

/// A number as an `xs:double`: integers plainly, others in the shortest
/// form that reads back to the same `f64`.
pub fn number(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e15 {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `s` escaped for an XML attribute value.
fn attr(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' | '\r' | '\t' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

fn base_unit(u: &Unit) -> String {
    const NAMES: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];
    let mut s = String::from("<BaseUnit");
    for (name, e) in NAMES.iter().zip(u.exponents) {
        if e != 0 {
            let _ = write!(s, " {name}=\"{e}\"");
        }
    }
    if u.factor != 1.0 {
        let _ = write!(s, " factor=\"{}\"", number(u.factor));
    }
    if u.offset != 0.0 {
        let _ = write!(s, " offset=\"{}\"", number(u.offset));
    }
    s.push_str("/>");
    s
}

/// What the description says about the twin as packaged.
fn summary(config: &TwinConfig) -> String {
    format!(
        "Passive throttle-based temperature flow compensator: the firmware's f32 twin ({}, {} substep{} per {} s tick, \
         as chosen for the packaged parameter file), driven by the oil temperature and the port pressures",
        config.scheme.name(),
        config.substeps,
        if config.substeps == 1 { "" } else { "s" },
        number(config.tick)
    )
}

/// The model description for `version`, with the start values of `raw`
/// (the packaged parameter file) and its twin configuration `config`.
pub fn model_description(version: FmiVersion, raw: &RawParams, config: &TwinConfig) -> String {
    let setup = Setup::from_raw(raw);
    let tick = number(config.tick);
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let generation = format!("compensator-fmu {} (cargo xtask fmu)", env!("CARGO_PKG_VERSION"));
    let token = token();
    // What the versions' headers differ in: the version, the name of the
    // fingerprint, the state capabilities' spelling, FMI 3.0's fixed
    // internal step and event mode, FMI 2.0's memory callbacks.
    let (fmi, token_name, state, extra) = match version {
        FmiVersion::V2 => (
            "2.0",
            "guid",
            "FMUstate",
            " canNotUseMemoryManagementFunctions=\"true\"".to_string(),
        ),
        FmiVersion::V3 => (
            "3.0",
            "instantiationToken",
            "FMUState",
            format!(" fixedInternalStepSize=\"{tick}\" hasEventMode=\"false\""),
        ),
    };
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"{fmi}\" modelName=\"{MODEL_IDENTIFIER}\" {token_name}=\"{token}\" \
         description=\"{}\" generationTool=\"{generation}\" variableNamingConvention=\"structured\">",
        attr(&summary(config))
    );
    let _ = writeln!(
        x,
        "  <CoSimulation modelIdentifier=\"{MODEL_IDENTIFIER}\" canHandleVariableCommunicationStepSize=\"true\" \
         canGetAndSet{state}=\"true\" canSerialize{state}=\"true\"{extra}/>"
    );
    x.push_str("  <UnitDefinitions>\n");
    for u in used_units() {
        let _ = writeln!(x, "    <Unit name=\"{}\">{}</Unit>", attr(u.name), base_unit(&u));
    }
    x.push_str("  </UnitDefinitions>\n");
    x.push_str("  <LogCategories>\n");
    x.push_str("    <Category name=\"logStatusError\" description=\"Refused calls: a parameter, a step, a state (the message names the field)\"/>\n");
    x.push_str("    <Category name=\"logStatusOk\" description=\"Information, with debug logging on (the twin's configuration)\"/>\n");
    x.push_str("  </LogCategories>\n");
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0\" stopTime=\"1\" stepSize=\"{tick}\"/>"
    );
    x.push_str("  <ModelVariables>\n");
    // (value reference, index in FMI 2.0's list) of each output.
    let mut listed = Vec::new();
    let mut index = 0u32;
    let mut var = |x: &mut String, v3: String, v2: String| {
        match version {
            FmiVersion::V2 => x.push_str(&v2),
            FmiVersion::V3 => x.push_str(&v3),
        }
        index += 1;
        index
    };
    if version == FmiVersion::V3 {
        var(
            &mut x,
            format!(
                "    <Float64 name=\"time\" valueReference=\"{VR_TIME}\" causality=\"independent\" variability=\"continuous\" unit=\"s\" description=\"Simulation time\"/>\n"
            ),
            String::new(),
        );
    }
    let inputs = Instance::new(raw).inputs();
    // The second sensor's unit: the packaged file's quantity's.
    let displacement = raw.monitor.sensor == 4.0;
    for (k, (input, start)) in INPUTS
        .iter()
        .zip([inputs.t_oil, inputs.p_supply, inputs.p_outlet, inputs.second])
        .enumerate()
    {
        let (name, vr, doc, start) = (input.name, VR_T_OIL + k as u32, attr(input.doc), number(start));
        let unit = resolve_unit(input.unit.unwrap_or_default(), displacement);
        var(
            &mut x,
            format!(
                "    <Float64 name=\"{name}\" valueReference=\"{vr}\" causality=\"input\" variability=\"continuous\" unit=\"{unit}\" start=\"{start}\" description=\"{doc}\"/>\n"
            ),
            format!(
                "    <ScalarVariable name=\"{name}\" valueReference=\"{vr}\" causality=\"input\" variability=\"continuous\" description=\"{doc}\">\n      <Real unit=\"{unit}\" start=\"{start}\"/>\n    </ScalarVariable>\n"
            ),
        );
    }
    for (i, o) in outputs().enumerate() {
        let vr = VR_FIRST_OUTPUT + i as u32;
        let doc = attr(o.doc);
        let k = if i == FLAGS_OUTPUT {
            var(
                &mut x,
                format!(
                    "    <Int32 name=\"{}\" valueReference=\"{vr}\" causality=\"output\" variability=\"discrete\" initial=\"calculated\" description=\"{doc}\"/>\n",
                    o.name
                ),
                format!(
                    "    <ScalarVariable name=\"{}\" valueReference=\"{vr}\" causality=\"output\" variability=\"discrete\" initial=\"calculated\" description=\"{doc}\">\n      <Integer/>\n    </ScalarVariable>\n",
                    o.name
                ),
            )
        } else {
            let unit = resolve_unit(o.unit.unwrap_or_default(), displacement);
            var(
                &mut x,
                format!(
                    "    <Float64 name=\"{}\" valueReference=\"{vr}\" causality=\"output\" variability=\"continuous\" initial=\"calculated\" unit=\"{unit}\" description=\"{doc}\"/>\n",
                    o.name
                ),
                format!(
                    "    <ScalarVariable name=\"{}\" valueReference=\"{vr}\" causality=\"output\" variability=\"continuous\" initial=\"calculated\" description=\"{doc}\">\n      <Real unit=\"{unit}\"/>\n    </ScalarVariable>\n",
                    o.name
                ),
            )
        };
        listed.push((vr, k));
    }
    let present = if setup.machine_present { "true" } else { "false" };
    let m_doc = attr("The driven machine ([machine] section) is used: compensation_error is defined.");
    var(
        &mut x,
        format!(
            "    <Boolean name=\"machine.present\" valueReference=\"{VR_MACHINE_PRESENT}\" causality=\"parameter\" variability=\"fixed\" start=\"{present}\" description=\"{m_doc}\"/>\n"
        ),
        format!(
            "    <ScalarVariable name=\"machine.present\" valueReference=\"{VR_MACHINE_PRESENT}\" causality=\"parameter\" variability=\"fixed\" initial=\"exact\" description=\"{m_doc}\">\n      <Boolean start=\"{present}\"/>\n    </ScalarVariable>\n"
        ),
    );
    for (i, f) in fields().enumerate() {
        let vr = VR_FIRST_FIELD + i as u32;
        let unit = fmi_unit(f.unit).map(|u| format!(" unit=\"{u}\"")).unwrap_or_default();
        let range = format!(
            " min=\"{}\" max=\"{}\" start=\"{}\"",
            number(field_min(f)),
            number(f.max),
            number(setup.values[i])
        );
        let doc = attr(f.doc);
        var(
            &mut x,
            format!(
                "    <Float64 name=\"{}\" valueReference=\"{vr}\" causality=\"parameter\" variability=\"fixed\"{unit}{range} description=\"{doc}\"/>\n",
                f.path
            ),
            format!(
                "    <ScalarVariable name=\"{}\" valueReference=\"{vr}\" causality=\"parameter\" variability=\"fixed\" initial=\"exact\" description=\"{doc}\">\n      <Real{unit}{range}/>\n    </ScalarVariable>\n",
                f.path
            ),
        );
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // Outputs depend on no input directly (they are the state at the end of
    // the last step): no algebraic loop through the FMU. At initialisation
    // they depend on everything known (T_oil and every parameter), which
    // an omitted `dependencies` attribute declares.
    match version {
        FmiVersion::V2 => {
            x.push_str("    <Outputs>\n");
            for (_, k) in &listed {
                let _ = writeln!(x, "      <Unknown index=\"{k}\" dependencies=\"\"/>");
            }
            x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
            for (_, k) in &listed {
                let _ = writeln!(x, "      <Unknown index=\"{k}\"/>");
            }
            x.push_str("    </InitialUnknowns>\n");
        }
        FmiVersion::V3 => {
            for (vr, _) in &listed {
                let _ = writeln!(x, "    <Output valueReference=\"{vr}\" dependencies=\"\"/>");
            }
            for (vr, _) in &listed {
                let _ = writeln!(x, "    <InitialUnknown valueReference=\"{vr}\"/>");
            }
        }
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

/// The variables as a Markdown table (name, causality, type, unit, value
/// reference, description), the one `docs/fmu.md` shows.
pub fn variables_markdown() -> String {
    let mut s = String::from(
        "| name | causality | type | unit | value reference | range | description |\n|---|---|---|---|---|---|---|\n",
    );
    let _ = writeln!(
        s,
        "| `time` | independent (FMI 3.0 only) | Float64 | s | {VR_TIME} | | Simulation time |"
    );
    let unit = |u: Option<&str>| match u {
        Some(READING_UNIT) => "Pa (m for x)".to_string(),
        u => u.unwrap_or_default().to_string(),
    };
    for (k, i) in INPUTS.iter().enumerate() {
        let _ = writeln!(
            s,
            "| `{}` | input | Float64 | {} | {} | | {} |",
            i.name,
            unit(i.unit),
            VR_T_OIL + k as u32,
            i.doc.replace('|', "\\|")
        );
    }
    for (i, o) in outputs().enumerate() {
        let ty = if i == FLAGS_OUTPUT {
            "Int32 (FMI 2.0: Integer)"
        } else {
            "Float64"
        };
        let _ = writeln!(
            s,
            "| `{}` | output | {ty} | {} | {} | | {} |",
            o.name,
            unit(o.unit),
            VR_FIRST_OUTPUT + i as u32,
            o.doc
        );
    }
    let _ = writeln!(
        s,
        "| `machine.present` | parameter | Boolean | | {VR_MACHINE_PRESENT} | | The `[machine]` section is used |"
    );
    for (i, f) in fields().enumerate() {
        let _ = writeln!(
            s,
            "| `{}` | parameter | Float64 | {} | {} | {} .. {} | {} |",
            f.path,
            fmi_unit(f.unit).unwrap_or(""),
            VR_FIRST_FIELD + i as u32,
            number(field_min(f)),
            number(f.max),
            f.doc.replace('|', "\\|")
        );
    }
    s
}
