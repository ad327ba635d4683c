//! The reference solution of the circuit demo (`docs/fmu.md`, "In a
//! circuit"): the compensator between a pressure source and a load
//! orifice, with the line between them, solved by the independent
//! reference solver (`compensator_reference::dynamics::Ports::Circuit`,
//! Radau5) as one stiff system. Writes the solution as CSV and the
//! circuit as JSON, which `fmu/python/circuit.py` reads to run the FMU in
//! the same circuit with a small co-simulation loop:
//!
//! ```sh
//! cargo run --release -p compensator-fmu --example circuit_reference -- target/fmu/circuit
//! ```
//!
//! writes `target/fmu/circuit/reference.csv` (`time_s,p_supply_pa,
//! p_outlet_pa,q0_m3s,x_m`, every 0.1 ms) and `circuit.json`.
//!
//! The circuit: the paper preset's compensator, its oil stepped from 30 to
//! 60 C at t = 0; the supply 5 bar, stepped to 7 bar at 0.25 s; a 2 l
//! line (capacitance V / beta with the preset's bulk modulus) drained to a
//! tank at 0 Pa through an orifice that passes 3 l/min at 1 bar.

use compensator_reference::dynamics::{Load, Method, Ports, Profile, simulate_with};
use std::fmt::Write;
use std::path::PathBuf;

fn main() -> Result<(), String> {
    let out = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "target/fmu/circuit".into()));
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let raw = compensator_params::file::load(&root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let (from, to) = (30.0, 60.0);
    let (t_end, dt) = (0.5, 1e-4);
    let supply = vec![(0.0, 5e5), (0.25, 5e5), (0.25, 7e5)];
    let line_volume = 2e-3;
    let load = Load {
        capacitance: line_volume / raw.core.bulk_modulus,
        coefficient: 5e-5 / 1e5f64.sqrt(),
        tank: 0.0,
    };
    let ports = Ports::Circuit {
        supply: supply.clone(),
        load,
    };
    let r = simulate_with(
        &raw.core,
        Profile::Step { from, to },
        &ports,
        t_end,
        dt,
        Method::Radau5,
        1e-10,
    )?;
    let mut csv = String::from("time_s,p_supply_pa,p_outlet_pa,q0_m3s,x_m\n");
    for k in 0..r.time.len() {
        let _ = writeln!(
            csv,
            "{:?},{:?},{:?},{:?},{:?}",
            r.time[k], r.ports[k].0, r.ports[k].1, r.outflow[k], r.state[k][0]
        );
    }
    let points: Vec<String> = supply.iter().map(|(t, p)| format!("[{t:?}, {p:?}]")).collect();
    let json = format!(
        "{{\"from_c\": {from:?}, \"to_c\": {to:?}, \"t_end_s\": {t_end:?}, \"supply\": [{}], \
         \"capacitance_m3_per_pa\": {:?}, \"load_coefficient\": {:?}, \"tank_pa\": {:?}}}\n",
        points.join(", "),
        load.capacitance,
        load.coefficient,
        load.tank
    );
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    for (name, text) in [("reference.csv", csv), ("circuit.json", json)] {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let q: Vec<f64> = r.outflow.clone();
    let (lo, hi) = q.iter().fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    println!(
        "circuit reference: {} samples to {}, Q0 {:.3} .. {:.3} l/min, p_outlet {:.3} .. {:.3} bar ({} solver steps)",
        r.time.len(),
        out.display(),
        lo * 6e4,
        hi * 6e4,
        r.ports.iter().map(|p| p.1).fold(f64::MAX, f64::min) / 1e5,
        r.ports.iter().map(|p| p.1).fold(f64::MIN, f64::max) / 1e5,
        r.steps
    );
    Ok(())
}
