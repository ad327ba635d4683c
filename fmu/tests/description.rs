//! The model descriptions (FMI 2.0 and 3.0) read back with an XML parser:
//! well formed, every variable a scalar with its unit declared, start
//! values the instance's, a complete `ModelStructure`; and the variables
//! table of `docs/fmu.md` the generated one.

use compensator::RawParams;
use compensator_fmu::chosen_config;
use compensator_fmu::description::{FmiVersion, model_description, token, variables_markdown};
use compensator_fmu::instance::{Instance, Phase};
use compensator_fmu::variables::{
    FIELD_COUNT, OUTPUT_COUNT, VR_FIRST_FIELD, VR_FIRST_OUTPUT, fields, outputs as all_outputs, resolve_unit,
};
use std::collections::HashSet;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn params(name: &str) -> RawParams {
    compensator_params::file::load(&root().join("presets").join(name)).expect("preset loads")
}

/// A scalar variable read from either version's description.
#[derive(Debug)]
struct Var {
    name: String,
    vr: u32,
    causality: String,
    ty: String,
    unit: Option<String>,
    start: Option<String>,
    min: Option<f64>,
    max: Option<f64>,
}

fn variables(doc: &roxmltree::Document, version: FmiVersion) -> Vec<Var> {
    let mv = doc
        .descendants()
        .find(|n| n.has_tag_name("ModelVariables"))
        .expect("ModelVariables");
    mv.children()
        .filter(|n| n.is_element())
        .map(|n| {
            let (ty_node, ty) = match version {
                FmiVersion::V2 => {
                    assert!(n.has_tag_name("ScalarVariable"));
                    let t = n.children().find(|c| c.is_element()).expect("a type element");
                    (t, t.tag_name().name().to_string())
                }
                FmiVersion::V3 => (n, n.tag_name().name().to_string()),
            };
            let f = |a: &str| ty_node.attribute(a).map(|v| v.parse::<f64>().expect("a number"));
            Var {
                name: n.attribute("name").expect("name").into(),
                vr: n.attribute("valueReference").expect("vr").parse().expect("u32"),
                causality: n.attribute("causality").unwrap_or("local").into(),
                ty,
                unit: ty_node.attribute("unit").map(String::from),
                start: ty_node.attribute("start").map(String::from),
                min: f("min"),
                max: f("max"),
            }
        })
        .collect()
}

fn check(version: FmiVersion, raw: &RawParams) {
    let config = chosen_config(raw).expect("chosen");
    let xml = model_description(version, raw, &config);
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
    let root = doc.root_element();
    let (v, token_attr) = match version {
        FmiVersion::V2 => ("2.0", "guid"),
        FmiVersion::V3 => ("3.0", "instantiationToken"),
    };
    assert_eq!(root.attribute("fmiVersion"), Some(v));
    assert_eq!(root.attribute(token_attr), Some(token().as_str()));
    let vars = variables(&doc, version);
    let units: HashSet<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("Unit"))
        .map(|n| n.attribute("name").expect("unit name"))
        .collect();
    // Names and value references unique; every unit declared.
    assert_eq!(vars.iter().map(|v| &v.name).collect::<HashSet<_>>().len(), vars.len());
    assert_eq!(vars.iter().map(|v| v.vr).collect::<HashSet<_>>().len(), vars.len());
    for var in &vars {
        if let Some(u) = &var.unit {
            assert!(units.contains(u.as_str()), "{}: unit {u} not declared", var.name);
        }
    }
    // Every parameter-file field, with its schema unit, range and the
    // file's value; an instance reads the same value back.
    let mut inst = Instance::new(raw);
    let params: Vec<&Var> = vars.iter().filter(|v| v.vr >= VR_FIRST_FIELD).collect();
    assert_eq!(params.len(), FIELD_COUNT);
    for (var, field) in params.iter().zip(fields()) {
        assert_eq!(var.name, field.path);
        assert_eq!(var.causality, "parameter");
        let start: f64 = var.start.as_deref().expect("start").parse().expect("number");
        assert_eq!(start, inst.get_real(var.vr).expect("readable"), "{}", var.name);
        assert!(
            var.min.expect("min") <= start && start <= var.max.expect("max"),
            "{}",
            var.name
        );
        assert_eq!(var.max, Some(field.max));
        assert_eq!(var.unit.is_none(), field.unit == "-", "{}", var.name);
    }
    // The input's start value is the instance's.
    let t = vars.iter().find(|v| v.causality == "input").expect("one input");
    assert_eq!(t.name, "T_oil");
    assert_eq!(t.unit.as_deref(), Some("degC"));
    let t_start: f64 = t.start.as_deref().expect("start").parse().expect("number");
    assert_eq!(t_start, inst.get_real(t.vr).expect("readable"));
    // Outputs: every one, flat scalars with units (flags an integer).
    let outputs: Vec<&Var> = vars.iter().filter(|v| v.causality == "output").collect();
    assert_eq!(outputs.len(), OUTPUT_COUNT);
    let displacement = raw.monitor.sensor == 4.0;
    for (k, (var, o)) in outputs.iter().zip(all_outputs()).enumerate() {
        assert_eq!((var.name.as_str(), var.vr), (o.name, VR_FIRST_OUTPUT + k as u32));
        assert_eq!(var.unit.as_deref(), o.unit.map(|u| resolve_unit(u, displacement)));
        let integer = if version == FmiVersion::V2 { "Integer" } else { "Int32" };
        assert_eq!(var.ty == integer, o.unit.is_none());
    }
    // ModelStructure: each output once in Outputs and in InitialUnknowns,
    // depending on no input.
    let structure = doc
        .descendants()
        .find(|n| n.has_tag_name("ModelStructure"))
        .expect("ModelStructure");
    let listed = |tag: &str| -> Vec<u32> {
        structure
            .descendants()
            .filter(|n| n.has_tag_name(tag))
            .map(|n| match version {
                FmiVersion::V2 => {
                    let i: usize = n.attribute("index").expect("index").parse().expect("index");
                    vars[i - 1].vr
                }
                FmiVersion::V3 => n.attribute("valueReference").expect("vr").parse().expect("vr"),
            })
            .collect()
    };
    let out_vrs: Vec<u32> = outputs.iter().map(|v| v.vr).collect();
    match version {
        FmiVersion::V2 => {
            let outs = structure
                .children()
                .find(|n| n.has_tag_name("Outputs"))
                .expect("Outputs");
            let init = structure
                .children()
                .find(|n| n.has_tag_name("InitialUnknowns"))
                .expect("InitialUnknowns");
            for n in outs.children().filter(|n| n.is_element()) {
                assert_eq!(n.attribute("dependencies"), Some(""));
            }
            assert_eq!(outs.children().filter(|n| n.is_element()).count(), outputs.len());
            assert_eq!(init.children().filter(|n| n.is_element()).count(), outputs.len());
            assert_eq!(listed("Unknown"), [out_vrs.clone(), out_vrs.clone()].concat());
        }
        FmiVersion::V3 => {
            assert_eq!(listed("Output"), out_vrs);
            assert_eq!(listed("InitialUnknown"), out_vrs);
            let time = vars.iter().find(|v| v.causality == "independent").expect("time");
            assert_eq!((time.name.as_str(), time.unit.as_deref()), ("time", Some("s")));
        }
    }
    // The default experiment steps by the twin's tick.
    let step: f64 = doc
        .descendants()
        .find(|n| n.has_tag_name("DefaultExperiment"))
        .and_then(|n| n.attribute("stepSize"))
        .expect("stepSize")
        .parse()
        .expect("number");
    assert_eq!(step, config.tick);
    assert_eq!(inst.phase(), Phase::Instantiated);
}

#[test]
fn both_versions_describe_every_variable_for_every_preset() {
    for entry in std::fs::read_dir(root().join("presets")).expect("presets") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let name = path.file_name().expect("name").to_string_lossy().into_owned();
            let raw = params(&name);
            check(FmiVersion::V2, &raw);
            check(FmiVersion::V3, &raw);
        }
    }
}

#[test]
fn a_file_without_a_machine_starts_with_it_absent() {
    let mut raw = params("paper.toml");
    raw.machine = None;
    let xml = model_description(FmiVersion::V3, &raw, &chosen_config(&raw).expect("chosen"));
    assert!(xml.contains(
        "name=\"machine.present\" valueReference=\"100\" causality=\"parameter\" variability=\"fixed\" start=\"false\""
    ));
    check(FmiVersion::V2, &raw);
    check(FmiVersion::V3, &raw);
}

#[test]
fn the_docs_show_the_generated_variables_table() {
    let path = root().join("docs/fmu.md");
    let text = std::fs::read_to_string(&path).expect("docs/fmu.md");
    let (begin, end) = ("<!-- variables:begin -->\n", "<!-- variables:end -->");
    let a = text.find(begin).expect("begin marker") + begin.len();
    let b = text.find(end).expect("end marker");
    let table = variables_markdown();
    if std::env::var_os("FMU_DOCS_BLESS").is_some() {
        std::fs::write(&path, format!("{}{table}{}", &text[..a], &text[b..])).expect("written");
        return;
    }
    assert_eq!(
        &text[a..b],
        table,
        "docs/fmu.md's variables table is stale: FMU_DOCS_BLESS=1 cargo test -p compensator-fmu --test description"
    );
}
