//! The committed seed corpus (`fuzz/corpus/<target>/seed-*`), written by
//! `cargo run --manifest-path fuzz/Cargo.toml --example write_seeds`:
//! the presets as TOML, the presets' values with a few edits, and
//! temperature sequences (holds, steps both ways, a ramp, cold and hot
//! oil, sensor faults) in the byte formats of the targets' modules.

use crate::input::{MODEL_EXAMPLE, PAPER, code_of};

/// `(target, name, bytes)` of every seed.
pub fn all() -> Vec<(&'static str, String, Vec<u8>)> {
    let mut out = Vec::new();
    for (name, text) in params_files() {
        out.push(("params_file", name.to_string(), text.into_bytes()));
    }
    for (name, bytes) in raw_params() {
        out.push(("raw_params", name.to_string(), bytes));
    }
    for (name, bytes) in twins() {
        out.push(("twin", name, bytes));
    }
    for (name, bytes) in estimators() {
        out.push(("estimator", name.to_string(), bytes));
    }
    out
}

fn params_files() -> Vec<(&'static str, String)> {
    let paper = PAPER.to_string();
    let without_machine = paper.split("[machine]").next().unwrap_or("").to_string();
    vec![
        ("paper", paper.clone()),
        ("model-example", MODEL_EXAMPLE.to_string()),
        (
            "paper-estimator",
            format!(
                "{paper}\n[estimator]\ntick_hz = 500\nmax_oil_rate = 0.5\nspike_limit = 3\n\
                 valid_min = 20\nvalid_max = 95\ntelemetry_hz = 0\nrtd_wires = 4\nmains_hz = 60\n"
            ),
        ),
        ("paper-without-machine", without_machine.clone()),
        (
            "paper-written",
            compensator_params::file::to_toml(&crate::input::presets()[0]),
        ),
        ("nan", without_machine.replace("mass = 0.02", "mass = nan")),
        ("inf", without_machine.replace("stroke = 0.0015", "stroke = inf")),
        ("unknown-key", format!("{without_machine}\n[plunger2]\nmass = 1\n")),
        (
            "not-a-number",
            without_machine.replace("mass = 0.02", "mass = \"0.02\""),
        ),
        (
            "preload-beyond-stroke",
            without_machine.replace("stroke = 0.0015", "stroke = 1e-6"),
        ),
    ]
}

fn le16(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn raw_params() -> Vec<(&'static str, Vec<u8>)> {
    let temps = |out: &mut Vec<u8>| {
        for t in [-20.0, 0.0, 26.0, 40.0, 52.0, 78.0, 120.0, 150.0] {
            le16(out, code_of(t));
        }
    };
    let mut seeds = Vec::new();
    for (name, base) in [("paper", 0u8), ("model-example", 1)] {
        let mut b = vec![base, 0];
        temps(&mut b);
        seeds.push((name, b));
    }
    // Edits: spring rate scaled by 2 (field 12, op 1, i = 2048), damping
    // set to 1e5 (field 11, op 0), tick rate halved (field 24, op 1,
    // i = -2048), [machine] dropped (field 41).
    let mut b = vec![0, 4];
    b.extend_from_slice(&[12, 1]);
    b.extend_from_slice(&f64::from_bits(2048).to_le_bytes());
    b.extend_from_slice(&[11, 0]);
    b.extend_from_slice(&1e5f64.to_le_bytes());
    b.extend_from_slice(&[24, 1]);
    b.extend_from_slice(&f64::from_bits(u64::from((-2048i16) as u16)).to_le_bytes());
    b.extend_from_slice(&[41, 0]);
    b.extend_from_slice(&0f64.to_le_bytes());
    temps(&mut b);
    seeds.push(("edits", b));
    seeds
}

/// A named temperature sequence: start [C], `(temperature [C], ticks)`.
type Sequence = (&'static str, f64, Vec<(f64, u8)>);

/// The twin's temperature sequences.
fn sequences() -> Vec<Sequence> {
    let ramp: Vec<(f64, u8)> = (0..52).map(|i| (26.0 + f64::from(i), 40)).collect();
    vec![
        ("hold-40", 40.0, vec![(40.0, 255), (40.0, 255)]),
        ("step-40-0", 40.0, vec![(0.0, 255); 4]),
        ("step-26-78", 26.0, vec![(78.0, 255); 4]),
        ("step-78-26", 78.0, vec![(26.0, 255); 4]),
        ("ramp-26-78", 26.0, ramp),
        ("cold-minus-15", -15.0, vec![(-15.0, 255)]),
        ("hot-150", 60.0, vec![(150.0, 255), (150.0, 255)]),
    ]
}

fn twins() -> Vec<(String, Vec<u8>)> {
    let mut seeds = Vec::new();
    for (scalar, ty) in [(0u8, "f32"), (1, "f64"), (2, "fixed")] {
        for (name, start, segments) in sequences() {
            let mut b = vec![scalar, 0, 0];
            le16(&mut b, code_of(start));
            for (t, n) in segments {
                le16(&mut b, code_of(t));
                b.push(n);
            }
            seeds.push((format!("{ty}-{name}"), b));
        }
    }
    // A perturbed design (stiffer spring, lighter plunger, smaller
    // chambers) and the Rosenbrock ROS3 scheme, two substeps.
    let mut b = vec![1, 2];
    let mut factors = [0u8; 21];
    factors[10] = 0xC0; // mass / 2
    factors[12] = 64; // spring rate * 2
    factors[17] = 0xC0; // volume_a / 2
    factors[18] = 0xC0; // volume_b / 2
    b.extend_from_slice(&factors);
    b.push(0);
    le16(&mut b, code_of(40.0));
    for t in [0.0, 80.0] {
        le16(&mut b, code_of(t));
        b.push(255);
    }
    seeds.push(("f64-perturbed-steps".into(), b));
    let mut b = vec![1, 0, 0xC0 | 3 | (1 << 3)];
    le16(&mut b, code_of(40.0));
    le16(&mut b, code_of(70.0));
    b.push(255);
    seeds.push(("f64-ros3-step".into(), b));
    seeds
}

fn estimators() -> Vec<(&'static str, Vec<u8>)> {
    let head = |driver: u8, start: f64| {
        let mut b = vec![0, 0, 0, 0, 0, 0, 0, driver];
        le16(&mut b, code_of(start));
        b
    };
    let step = |b: &mut Vec<u8>, kind: u8, code: u16, gap: u8| {
        b.push(kind);
        le16(b, code);
        b.push(gap);
    };
    let mut seeds = Vec::new();
    // Directly: samples every 20 ticks.
    let mut b = head(0, 55.0);
    for _ in 0..20 {
        step(&mut b, 0, code_of(55.0), 19);
    }
    seeds.push(("direct-hold-55", b));
    let mut b = head(0, 50.0);
    for _ in 0..10 {
        step(&mut b, 0, code_of(70.0), 19);
    }
    seeds.push(("direct-step-50-70", b));
    let mut b = head(0, 45.0);
    for (kind, code) in [
        (0, code_of(45.0)),
        (0, code_of(90.0)),
        (6, 0),
        (6, 1),
        (7, 0x7FC0),
        (5, 0),
    ] {
        step(&mut b, kind, code, 19);
    }
    step(&mut b, 0, code_of(400.0), 19);
    seeds.push(("direct-spikes-faults", b));
    // Through the driver: healthy, then faults one after another.
    let mut b = head(1, 45.0);
    for _ in 0..8 {
        step(&mut b, 0, code_of(45.0), 63);
    }
    seeds.push(("driver-hold-45", b));
    let mut b = head(1, 45.0);
    for kind in [0u8, 4, 5, 6, 7, 0x08, 0x10, 0x20, 0x80, 0xC0, 0] {
        step(&mut b, kind, code_of(60.0), 63);
    }
    seeds.push(("driver-faults", b));
    seeds
}
