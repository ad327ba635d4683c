//! Closed-form derivatives against finite differences, and the asymptotic
//! series' error shrinking at the expected order as t -> t0.

use compensator::Params;
use compensator::asymptotic::{Expansion, Reading, monotonicity, phi, phi_derivatives, sensitivity};
use compensator::equilibrium::{Stop, a_derivatives, equilibrium};
use host_tests::random::{Rng, physical_params};
use host_tests::{isclose, reference, repo_root};
use std::f64::consts::PI;

fn paper() -> Params<f64> {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    Params::new(&raw).unwrap()
}

/// `A(t)` from the independent reference oil: `R_l / sqrt(R_t)`.
fn a_reference(p: &compensator::params::RawCore, t: f64) -> f64 {
    let (nu, rho) = reference::oil(p, t);
    let r_l = 128.0 * nu * rho * p.laminar_length / (PI * p.laminar_diameter.powi(4));
    let f = PI * p.turbulent_diameter.powi(2) / 4.0;
    let r_t = rho / (2.0 * (p.turbulent_discharge * f).powi(2));
    r_l / r_t.sqrt()
}

#[test]
fn phi_derivatives_match_finite_differences() {
    let mut rng = Rng::new(11);
    for _ in 0..200 {
        let raw = physical_params(&mut rng);
        let p = Params::<f64>::new(&raw).unwrap();
        let sqrt_dp = raw.core.pressure_drop.sqrt();
        for a_hat in [0.05, 0.3, std::f64::consts::FRAC_1_SQRT_2, 1.5, 4.0, 20.0] {
            let a = a_hat * sqrt_dp;
            let h = 1e-4 * a;
            let d = phi_derivatives(&p, a);
            let fd1 = (phi(&p, a + h) - phi(&p, a - h)) / (2.0 * h);
            let fd2 = (phi_derivatives(&p, a + h).d1 - phi_derivatives(&p, a - h).d1) / (2.0 * h);
            assert!(isclose(d.d1, fd1, 1e-7, 0.0), "Phi' {} vs {fd1} at a_hat {a_hat}", d.d1);
            assert!(
                isclose(d.d2, fd2, 1e-7, 0.0),
                "Phi'' {} vs {fd2} at a_hat {a_hat}",
                d.d2
            );
            // The printed form of Eq. (16), for large a_hat only where it
            // does not cancel catastrophically.
            if a_hat < 2.0 {
                let dp = raw.core.pressure_drop;
                let printed = (dp + a * a - a * (4.0 * dp + a * a).sqrt()) * p.plunger.compliance();
                assert!(isclose(d.value, printed, 1e-9, 1e-12 * raw.core.stroke));
            }
        }
    }
}

#[test]
fn a_derivatives_match_the_reference_oil() {
    let mut rng = Rng::new(12);
    for _ in 0..200 {
        let raw = physical_params(&mut rng);
        let p = Params::<f64>::new(&raw).unwrap();
        for t in [26.0, 40.0, 55.5, 78.0] {
            let d = a_derivatives(&p, t).unwrap();
            let h = 1e-2;
            let (am, a0, ap) = (
                a_reference(&raw.core, t - h),
                a_reference(&raw.core, t),
                a_reference(&raw.core, t + h),
            );
            assert!(isclose(d.value, a0, 1e-12, 0.0), "A {} vs {a0}", d.value);
            assert!(isclose(d.d1, (ap - am) / (2.0 * h), 1e-6, 0.0), "A' {} vs fd", d.d1);
            assert!(
                isclose(d.d2, (ap - 2.0 * a0 + am) / (h * h), 1e-4, 0.0),
                "A'' {} vs fd",
                d.d2
            );
        }
    }
}

/// log2 of the error ratio when the distance to t0 halves.
fn observed_orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

#[test]
fn series_error_shrinks_at_the_expected_order() {
    let p = paper();
    let t0 = 55.0;
    let x_free = |t: f64| equilibrium(&p, t).unwrap().x_free;
    let q_total = |t: f64| equilibrium(&p, t).unwrap().q_total;
    assert_eq!(equilibrium(&p, t0).unwrap().stop, Stop::Free);
    for reading in [Reading::Temperature, Reading::Property] {
        let e = Expansion::new(&p, t0, reading).unwrap();
        for order in 0..=2usize {
            let steps = [4.0, 2.0, 1.0, 0.5];
            let x_err: Vec<f64> = steps
                .iter()
                .map(|dt| (e.at(t0 + dt).unwrap().x_series(order) - x_free(t0 + dt)).abs())
                .collect();
            let orders = observed_orders(&x_err);
            for o in &orders {
                assert!(
                    (o - (order as f64 + 1.0)).abs() < 0.25,
                    "{reading:?} x order {order}: observed {orders:?}"
                );
            }
            if reading == Reading::Temperature {
                let q_err: Vec<f64> = steps
                    .iter()
                    .map(|dt| (e.at(t0 + dt).unwrap().q_total_series(order) - q_total(t0 + dt)).abs())
                    .collect();
                for o in observed_orders(&q_err) {
                    assert!(
                        (o - (order as f64 + 1.0)).abs() < 0.25,
                        "Q0 order {order}: observed {o}"
                    );
                }
            }
        }
        // At t0 the series is the quasi-static point itself.
        let at0 = e.at(t0).unwrap();
        let qs = equilibrium(&p, t0).unwrap();
        assert!(isclose(at0.x_series(2), qs.x_free, 1e-14, 1e-18));
        assert!(isclose(at0.q_total_series(2), qs.q_total, 1e-13, 0.0));
        assert!(isclose(at0.q_branch_series(2), qs.q_branch, 1e-13, 0.0));
    }
}

#[test]
fn sensitivities_match_finite_differences() {
    let p = paper();
    for t in [36.0, 45.0, 60.0, 75.0] {
        let s = sensitivity(&p, t).unwrap();
        let h = 1e-3;
        let (em, ep) = (equilibrium(&p, t - h).unwrap(), equilibrium(&p, t + h).unwrap());
        assert_eq!(s.stop, Stop::Free);
        assert!(isclose(s.dx_dt, (ep.x - em.x) / (2.0 * h), 1e-6, 0.0), "dx/dt at {t}");
        assert!(
            isclose(s.dq_throt_dt, (ep.q_throt - em.q_throt) / (2.0 * h), 1e-6, 0.0),
            "dQ_throt/dt at {t}"
        );
    }
    // On the closed stop the plunger does not move, the branch still does.
    let cold = sensitivity(&p, 28.0).unwrap();
    assert_eq!((cold.stop, cold.dx_dt), (Stop::Closed, 0.0));
    assert!(cold.dx_dt_branch > 0.0);
}

#[test]
fn equation_32_holds_on_the_paper_preset_and_finds_the_flattest_point() {
    let p = paper();
    let m = monotonicity(&p, 26.0, 78.0, 53).unwrap();
    assert!(m.monotonic);
    assert_eq!(m.sign, 1);
    // Phi' A' flattens as the oil thins: the worst point is the hot end.
    assert_eq!(m.worst_temperature, 78.0);
    let s = sensitivity(&p, 78.0).unwrap();
    assert_eq!(m.worst_dx_dt, s.dx_dt_branch);
    assert!(monotonicity(&p, 50.0, 40.0, 10).is_err());
}
