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

use host_tests::band::{CalibratedPaper, calibrated_paper, linear, only, params_part, table};

/// Temperatures of the validated range (26-78 C) [C].
const TEMPS: [f64; 5] = [30.0, 40.0, 50.0, 60.0, 70.0];

/// The reported quantities, their index in the table and display scale.
const OUTPUTS: [(&str, usize, f64, &str); 3] = [
    ("x", 0, 1e6, "um"),
    ("p_a", 1, 1e-3, "kPa"),
    ("q_total", 3, 1e6 * 60.0, "cm^3/min"),
];

fn main() {
    let CalibratedPaper {
        base,
        cal,
        written,
        fitted,
        prior,
        after,
    } = calibrated_paper();

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
