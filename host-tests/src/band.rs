//! The uncertainty table against the law of propagation it approximates,
//! on the calibrated paper preset (`compensator calibrate`'s own fit of
//! the paper's Tables 1 and 2 on the model example).
//!
//! The table ([`compensator::uncertainty::UncertaintyTable`]) takes each
//! sensitivity as a difference across one standard deviation of the
//! device population; [`linear`] propagates the same covariance with
//! gradients from steps of 1e-6 of each value (GUM 5.1.2, the linear law).
//! Both evaluate the same equilibrium (the core's): what is compared is
//! the propagation, not the model.

use compensator::Params;
use compensator::estimator::EstimatorConfig;
use compensator::params::{RawParams, RawTolerances};
use compensator::uncertainty::UncertaintyTable;
use compensator_cli::calibration::{self, Calibration, Written};
use compensator_cli::{input, params_file};

/// The paper preset before and after calibration.
pub struct CalibratedPaper {
    /// The model example: the fit's starting point and prior tolerances.
    pub base: RawParams,
    /// The fit.
    pub cal: Calibration,
    /// What `calibrate` writes (tolerances and correlations).
    pub written: Written,
    /// The fitted fields' paths.
    pub fitted: Vec<&'static str>,
    /// The calibrated values with the model example's tolerances.
    pub prior: RawParams,
    /// The calibrated values with the calibrated tolerances.
    pub after: RawParams,
}

/// `calibrate`'s fit of the paper's tables on the model example.
pub fn calibrated_paper() -> CalibratedPaper {
    let base = params_file::parse(input::MODEL_EXAMPLE).expect("the model example");
    let pressure = calibration::read_pressure(input::PAPER_PRESSURE_CSV).expect("Table 1");
    let displacement = calibration::read_displacement(input::PAPER_DISPLACEMENT_CSV).expect("Table 2");
    let cal = calibration::fit(&base, &pressure, Some(&displacement)).expect("the paper fit");
    let written = cal.written(&base).expect("the calibrated tolerances");
    let fitted: Vec<&'static str> = cal.estimates.iter().map(|e| e.path).collect();
    let (mut prior, mut after) = (cal.params, cal.params);
    prior.tolerances = base.tolerances;
    after.tolerances = written.tolerances;
    CalibratedPaper {
        base,
        cal,
        written,
        fitted,
        prior,
        after,
    }
}

/// `raw` with only the fields `fitted` keeping their tolerances and the
/// correlations among them.
pub fn only(raw: &RawParams, fitted: &[&'static str]) -> RawParams {
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

/// The estimator's uncertainty table of `raw`.
pub fn table(raw: &RawParams) -> UncertaintyTable {
    *EstimatorConfig::new(raw)
        .expect("the estimator's configuration")
        .table()
}

/// x_free, p_a, p_b and the total flow (the window extended past the
/// stops) of `raw` at `t`: the table's own outputs
/// ([`compensator::uncertainty::outputs`]), so that only the propagation
/// differs.
pub fn outputs(raw: &RawParams, t: f64) -> [f64; 4] {
    let p = Params::<f64>::new(raw).expect("valid parameters");
    let y = compensator::uncertainty::outputs(&p, t).expect("the equilibrium");
    [y[0], y[1], y[2], y[3]]
}

/// `sqrt(g' V g)` of each output at `t` with the gradient by central
/// differences of 1e-6 of each uncertain field's value.
pub fn linear(raw: &RawParams, t: f64) -> [f64; 4] {
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

/// The parameters' part of output `o`'s standard uncertainty at `t` in
/// `tab` (its `sd_params`, interpolated as [`UncertaintyTable::at`] does).
pub fn params_part(tab: &UncertaintyTable, t: f64, o: usize) -> f64 {
    let last = tab.sd_params.len() - 1;
    let pos = ((t as f32 - tab.t0) / tab.step).clamp(0.0, last as f32);
    let k = (pos as usize).min(last - 1);
    let w = pos - k as f32;
    f64::from(tab.sd_params[k][o] + w * (tab.sd_params[k + 1][o] - tab.sd_params[k][o]))
}
