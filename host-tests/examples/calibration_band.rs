//! What calibration buys: the paper preset's standard uncertainties of the
//! displacement, the chamber (a) pressure and the total flow before and
//! after `compensator calibrate` writes its fit into the file.
//!
//!     cargo run --release -p host-tests --example calibration_band
//!
//! The fit is `calibrate`'s own (`compensator_cli::calibration`): the paper's
//! Tables 1 and 2 on the model example, the file it writes
//! (`Calibration::written`). Both columns are the calibrated values with
//! the uncertainty table the estimator builds (`EstimatorConfig::new`,
//! `model/src/uncertainty.rs`); "prior" is with the model example's
//! tolerances (the drawing's and the oil grade's), "calibrated" with the
//! calibrated file's.
//!
//! Two tables: the fitted fields' contributions alone (every other
//! tolerance zero), with, beside the uncertainty table's figure (central
//! differences over one standard uncertainty of each field), the same
//! covariance propagated with steps of 1e-6 of each value (the linear
//! law, GUM 5.2.2) as a check; and the whole band the calibrated device
//! reports (every tolerance in the file and the probe's class and
//! resolution; the observer's own variance, the same before and after,
//! left out).

use compensator::Params;
use compensator::equilibrium::equilibrium;
use compensator::estimator::EstimatorConfig;
use compensator::params::{RawParams, RawTolerances};
use compensator::uncertainty::UncertaintyTable;
use compensator_cli::calibration;
use compensator_cli::{input, params_file};

/// Temperatures of the validated range (26-78 C) [C].
const TEMPS: [f64; 5] = [30.0, 40.0, 50.0, 60.0, 70.0];

/// The reported quantities, their index in the table and display scale.
const OUTPUTS: [(&str, usize, f64, &str); 3] = [
    ("x", 0, 1e6, "um"),
    ("p_a", 1, 1e-3, "kPa"),
    ("q_total", 3, 1e6 * 60.0, "cm^3/min"),
];

/// `raw` with only the fields `fitted` keeping their tolerances and the
/// correlations among them.
fn only(raw: &RawParams, fitted: &[&'static str]) -> RawParams {
    let mut out = *raw;
    out.tolerances = RawTolerances::NONE;
    for f in fitted {
        *out.tolerances.get_mut(f).expect("a field with a tolerance") = raw.tolerances.get(f).unwrap_or(0.0);
    }
    for c in raw.tolerances.correlations() {
        if fitted.contains(&c.a) && fitted.contains(&c.b) {
            out.tolerances
                .push_correlation(c.a, c.b, c.coefficient)
                .expect("fewer than a file holds");
        }
    }
    out
}

fn table(raw: &RawParams) -> UncertaintyTable {
    *EstimatorConfig::new(raw)
        .expect("the estimator's configuration")
        .table()
}

/// x_free, p_a and the total flow (the window extended past the stops, as
/// the uncertainty table takes it) of `raw` at `t`.
fn outputs(raw: &RawParams, t: f64) -> [f64; 4] {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let e = equilibrium(&p, t).expect("the equilibrium");
    let velocity = (2.0 * p.pressure_drop / e.fluid.density).sqrt();
    let per_x = p.slot.discharge_coefficient * std::f64::consts::PI * p.slot.diameter * velocity;
    [e.x_free, e.p_a, e.p_b, e.q_total + per_x * (e.x_free - e.x)]
}

/// `sqrt(g' V g)` of each output at `t` with the gradient by central
/// differences of 1e-6 of each uncertain field's value.
fn linear(raw: &RawParams, t: f64) -> [f64; 4] {
    let fields: Vec<(&'static str, f64)> = compensator::params::CORE_FIELDS
        .iter()
        .filter_map(|f| raw.tolerances.get(f.path).filter(|s| *s > 0.0).map(|s| (f.path, s)))
        .collect();
    let grads: Vec<[f64; 4]> = fields
        .iter()
        .map(|(path, _)| {
            let v = raw.core.value(path).expect("a core field");
            let h = 1e-6 * v.abs();
            let (mut up, mut down) = (*raw, *raw);
            *up.core.value_mut(path).expect("a core field") += h;
            *down.core.value_mut(path).expect("a core field") -= h;
            let (u, d) = (outputs(&up, t), outputs(&down, t));
            std::array::from_fn(|o| (u[o] - d[o]) / (2.0 * h))
        })
        .collect();
    std::array::from_fn(|o| {
        let mut var = 0.0;
        for (i, (a, sa)) in fields.iter().enumerate() {
            for (j, (b, sb)) in fields.iter().enumerate() {
                var += grads[i][o] * raw.tolerances.correlation(a, b) * sa * sb * grads[j][o];
            }
        }
        var.sqrt()
    })
}

fn main() {
    let base = params_file::parse(input::MODEL_EXAMPLE).expect("the model example");
    let pressure = calibration::read_pressure(input::PAPER_PRESSURE_CSV).expect("Table 1");
    let displacement = calibration::read_displacement(input::PAPER_DISPLACEMENT_CSV).expect("Table 2");
    let cal = calibration::fit(&base, &pressure, Some(&displacement)).expect("the paper fit");
    let written = cal.written(&base).expect("the calibrated tolerances");
    let fitted: Vec<&'static str> = cal.estimates.iter().map(|e| e.path).collect();
    let (mut prior, mut after) = (cal.params, cal.params);
    prior.tolerances = base.tolerances;
    after.tolerances = written.tolerances;

    println!("Fitted fields, standard uncertainty (k = 1), prior -> calibrated:");
    for (i, e) in cal.estimates.iter().enumerate() {
        let held = written.held.iter().any(|h| h.path == e.path);
        println!(
            "  {:<24} {:.3e} -> {:.3e} {}{}",
            e.path,
            base.tolerances.get(e.path).unwrap_or(0.0),
            written.covariance[(i, i)].sqrt(),
            e.unit,
            if held {
                "  (not determined by the data: the base file's, the others conditioned on it)"
            } else {
                ""
            }
        );
    }

    let (tb, ta) = (table(&only(&prior, &fitted)), table(&only(&after, &fitted)));
    println!(
        "\nThe fitted fields' contributions (other tolerances zero): prior | calibrated | calibrated, linear check\n"
    );
    print!("| T [C] |");
    for (name, _, _, unit) in OUTPUTS {
        print!(" u({name}) [{unit}] |");
    }
    println!("\n|---|{}", "---|".repeat(OUTPUTS.len()));
    let after_fitted = only(&after, &fitted);
    for t in TEMPS {
        let lin = linear(&after_fitted, t);
        print!("| {t:.0} |");
        for (_, o, scale, _) in OUTPUTS {
            print!(
                " {:.3} \\| {:.3} \\| {:.3} |",
                params_part(&tb, t, o) * scale,
                params_part(&ta, t, o) * scale,
                lin[o] * scale
            );
        }
        println!();
    }

    let (tb, ta) = (table(&prior), table(&after));
    println!("\nThe whole band (every tolerance of the file, the probe's class and resolution): prior | calibrated\n");
    print!("| T [C] |");
    for (name, _, _, unit) in OUTPUTS {
        print!(" u({name}) [{unit}] |");
    }
    println!("\n|---|{}", "---|".repeat(OUTPUTS.len()));
    for t in TEMPS {
        let (b, a) = (tb.at(t as f32, 0.0), ta.at(t as f32, 0.0));
        print!("| {t:.0} |");
        for (o, (_, _, scale, _)) in [b.x, b.p_a, b.q_total]
            .into_iter()
            .zip([a.x, a.p_a, a.q_total])
            .zip(OUTPUTS)
        {
            print!(" {:.3} \\| {:.3} |", f64::from(o.0) * scale, f64::from(o.1) * scale);
        }
        println!();
    }
}

/// The parameters' part of output `o`'s standard uncertainty at `t` in
/// `tab` (its `sd_params`, interpolated as [`UncertaintyTable::at`] does).
fn params_part(tab: &UncertaintyTable, t: f64, o: usize) -> f64 {
    let last = tab.sd_params.len() - 1;
    let pos = ((t as f32 - tab.t0) / tab.step).clamp(0.0, last as f32);
    let k = (pos as usize).min(last - 1);
    let w = pos - k as f32;
    f64::from(tab.sd_params[k][o] + w * (tab.sd_params[k + 1][o] - tab.sd_params[k][o]))
}
