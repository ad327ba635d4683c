//! The sizing fits are least-squares optima of the compensation error.

use compensator::Params;
use compensator::params::Machine;
use compensator_cli::sizing::{fit_machine, fit_slot};
use host_tests::random::{Rng, physical_params};

fn rms(p: &Params<f64>, temps: &[f64]) -> f64 {
    let s: f64 = temps
        .iter()
        .map(|&t| compensator::compensation::compensation(p, t).unwrap().error.powi(2))
        .sum();
    (s / temps.len() as f64).sqrt()
}

#[test]
fn fitted_machine_and_slot_are_least_squares_optima() {
    let temps: Vec<f64> = (30..=80).map(f64::from).collect();
    let mut rng = Rng::new(4242);
    let mut checked = 0;
    for _ in 0..20 {
        let raw = physical_params(&mut rng);
        let p = Params::<f64>::new(&raw).unwrap();
        let f = fit_machine(&p, &temps, 40.0).unwrap();
        if f.leakage_reference == 0.0 || f.working_flow == 0.0 {
            continue; // on a constraint: not an interior optimum
        }
        let with = |qw: f64, l: f64| Params {
            machine: Some(Machine {
                working_flow: qw,
                leakage_reference: l,
                leakage_temperature: 40.0,
            }),
            ..p
        };
        let best = rms(&with(f.working_flow, f.leakage_reference), &temps);
        assert!((best - f.rms_error).abs() <= 1e-12 * best.max(1e-20));
        for (dq, dl) in [(1.01, 1.0), (0.99, 1.0), (1.0, 1.01), (1.0, 0.99)] {
            assert!(rms(&with(f.working_flow * dq, f.leakage_reference * dl), &temps) > best);
        }
        // The slot that serves that machine best: at least as good as the
        // design's own window, and a minimum in the diameter.
        let pm = with(f.working_flow, f.leakage_reference);
        if let Ok(s) = fit_slot(&pm, &temps) {
            assert!(s.rms_error <= best * (1.0 + 1e-12));
            for k in [1.01, 0.99] {
                let mut q = pm;
                q.slot.diameter = s.slot_diameter * k;
                assert!(rms(&q, &temps) > s.rms_error);
            }
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} interior cases");
}
