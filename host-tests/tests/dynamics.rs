//! The FSI twin against the independent adaptive reference: the accuracy
//! accuracy goals of `docs/dynamics.md`, the reference's own cross-check, the
//! linearisation against nalgebra, and the reduced model.

use compensator::Params;
use compensator::dynamics::linear::{eigenvalues, hurwitz_stable, jacobian_at_equilibrium, linearise};
use compensator::dynamics::{Model, Scheme, Twin, TwinConfig};
use compensator::equilibrium::equilibrium;
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::{self as reference, Method, Profile};
use host_tests::accuracy::{Case, paper_cases, random_cases};
use host_tests::random::{Rng, physical_params};
use host_tests::repo_root;
use std::sync::OnceLock;

fn paper() -> compensator::RawParams {
    compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap()
}

/// The accuracy cases, solved once for all tests of this file.
fn cases() -> &'static (Vec<Case>, Vec<Case>) {
    static CASES: OnceLock<(Vec<Case>, Vec<Case>)> = OnceLock::new();
    CASES.get_or_init(|| (paper_cases(&paper()), random_cases(50)))
}

/// The configuration `dynamics::config::choose` picks for `raw` at 1 ms
/// over its validated range.
fn chosen(raw: &compensator::RawParams) -> TwinConfig {
    host_tests::survey::chosen(raw).expect("a configuration").config
}

/// Trajectory goals, max |x - x_ref| in % of the step: f64, f32, Q12.20.
const GOALS: [f64; 3] = [0.1, 0.5, 1.0];

#[test]
fn the_chosen_twin_meets_every_goal_on_the_paper_preset() {
    let cfg = chosen(&paper());
    // What the firmware's build chooses for the paper preset: one SDIRK3
    // step per 1 ms tick (the cost budget of the paper preset rests on it).
    assert_eq!((cfg.scheme, cfg.substeps), (Scheme::Sdirk3, 1));
    for c in &cases().0 {
        let e64 = c.error_pct(&c.twin(Precision::F64, cfg));
        let x32 = c.twin(Precision::F32, cfg);
        let e32 = c.error_pct(&x32);
        let efx = c.error_pct(&c.twin(Precision::Fixed, cfg));
        eprintln!("{:?}: f64 {e64:.4} %, f32 {e32:.4} %, Q12.20 {efx:.4} %", c.profile);
        assert!(e64 <= GOALS[0], "{:?}: f64 {e64} %", c.profile);
        assert!(e32 <= GOALS[1], "{:?}: f32 {e32} %", c.profile);
        assert!(efx <= GOALS[2], "{:?}: fixed {efx} %", c.profile);
        let final_err = (x32[c.ticks] - c.x_ref[c.ticks]).abs() / c.raw.core.stroke;
        assert!(
            final_err <= 1e-4,
            "{:?}: final value off by {final_err:e} of the stroke",
            c.profile
        );
    }
}

#[test]
fn the_chosen_twin_meets_every_goal_on_50_random_designs() {
    // Designs sized as a designer would (`physical_params`), each with the
    // configuration chosen for it, each on a step of at least 5 % of the
    // stroke over 30-80 C (the envelope survey covers scattered designs).
    for (i, c) in cases().1.iter().enumerate() {
        let cfg = chosen(&c.raw);
        let e = [Precision::F64, Precision::F32, Precision::Fixed].map(|p| c.error_pct(&c.twin(p, cfg)));
        for (k, (e, goal)) in e.iter().zip(GOALS).enumerate() {
            assert!(
                *e <= goal,
                "design {i} {:?} with {} substeps: precision {k} off by {e} % (goal {goal} %)",
                c.profile,
                cfg.substeps
            );
        }
    }
}

#[test]
fn more_substeps_converge_at_the_schemes_order() {
    // The random design the one-step-per-tick twin follows worst: its error
    // falls like h^3 (SDIRK3) as the substeps grow, to the reference.
    let cases = &cases().1;
    let one = TwinConfig {
        substeps: 1,
        ..TwinConfig::SHIPPED
    };
    let (_, c) = cases
        .iter()
        .map(|c| (c.error_pct(&c.twin(Precision::F64, one)), c))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    let err = |n: u8| c.error_pct(&c.twin(Precision::F64, TwinConfig { substeps: n, ..one }));
    let (e2, e4, e8) = (err(2), err(4), err(8));
    eprintln!("{:?}: {e2:.4} -> {e4:.4} -> {e8:.4} %", c.profile);
    assert!(e4 < e2 / 4.0 && e8 < e4 / 4.0 && e8 < 0.05, "{e2} -> {e4} -> {e8}");
}

#[test]
fn steady_state_is_the_closed_form_equilibrium_in_f32() {
    let raw = paper();
    let p = Params::<f32>::new(&raw).unwrap();
    for t in [35.0f32, 45.0, 55.0, 65.0, 75.0] {
        let mut twin = Twin::<f32, f32>::new(&p, TwinConfig::SHIPPED, t - 5.0).unwrap();
        twin.set_temperature(t).unwrap();
        for _ in 0..1000 {
            twin.tick().unwrap();
        }
        let x_closed = equilibrium(&p, t).unwrap().x;
        let d = (twin.state().x - x_closed).abs() / p.plunger.stroke;
        assert!(d <= 1e-6, "at {t} C: {d:e} of the stroke");
    }
}

#[test]
fn reference_solvers_agree_radau5_and_dop853() {
    let raw = paper();
    for (from, to) in [(30.0, 40.0), (80.0, 30.0)] {
        let prof = Profile::Step { from, to };
        let a = reference::simulate(&raw.core, prof, 0.1, 1e-4, Method::Radau5, 1e-11).unwrap();
        let b = reference::simulate(&raw.core, prof, 0.1, 1e-4, Method::Dop853, 1e-11).unwrap();
        let dx = a
            .state
            .iter()
            .zip(&b.state)
            .map(|(p, q)| (p[0] - q[0]).abs())
            .fold(0.0, f64::max);
        assert!(dx <= 1e-8 * raw.core.stroke, "{from}->{to}: {dx:e} m");
        assert_eq!(a.events.len(), b.events.len());
        for (ea, eb) in a.events.iter().zip(&b.events) {
            assert_eq!(ea.1, eb.1);
            assert!((ea.0 - eb.0).abs() < 1e-7, "event times {} vs {}", ea.0, eb.0);
        }
    }
}

#[test]
fn reference_crate_solves_a_stiff_linear_system_exactly() {
    // Guards the pinned differential-equations 0.7.0 (array tolerances):
    // y' = A y, A = V diag(-1, -50, -2e3, -2e4) V^-1, exact solution known.
    use differential_equations::prelude::*;
    use nalgebra::{Matrix4, Vector4};
    let v = Matrix4::new(
        1.0, 0.5, 0.0, 0.2, 0.0, 1.0, 0.3, 0.0, 0.1, 0.0, 1.0, 0.4, 0.0, 0.2, 0.0, 1.0,
    );
    let d = Vector4::new(-1.0, -50.0, -2e3, -2e4);
    let v_inv = v.try_inverse().unwrap();
    let a = v * Matrix4::from_diagonal(&d) * v_inv;
    struct Lin(Matrix4<f64>);
    impl ODE<f64, [f64; 4]> for Lin {
        fn diff(&self, _t: f64, y: &[f64; 4], dy: &mut [f64; 4]) {
            dy.copy_from_slice((self.0 * Vector4::from(*y)).as_slice());
        }
    }
    let y0 = [1.0, 2.0, -1.0, 0.5];
    let sol = IVP::ode(&Lin(a), 0.0, 0.5, y0)
        .method(ImplicitRungeKutta::radau5().rtol([1e-12; 4]).atol([1e-14; 4]))
        .solve()
        .unwrap();
    let (t, y) = sol.last().unwrap();
    let c = v_inv * Vector4::from(y0);
    let exact = v * Vector4::from_fn(|i, _| c[i] * (d[i] * t).exp());
    for i in 0..4 {
        assert!(
            (y[i] - exact[i]).abs() <= 1e-9 * (1.0 + exact[i].abs()),
            "component {i}: {} vs {}",
            y[i],
            exact[i]
        );
    }
}

#[test]
fn eigenvalues_match_nalgebra() {
    let mut rng = Rng::new(99);
    let check = |m: [[f64; 4]; 4]| {
        let ours = eigenvalues(&m).unwrap();
        let na = nalgebra::Matrix4::from_fn(|i, j| m[i][j]).complex_eigenvalues();
        let mut theirs: Vec<(f64, f64)> = na.iter().map(|c| (c.re, c.im)).collect();
        theirs.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.total_cmp(&a.1)));
        let scale = theirs.iter().map(|c| c.0.hypot(c.1)).fold(0.0, f64::max);
        for (o, t) in ours.iter().zip(&theirs) {
            assert!(
                (o.re - t.0).abs() + (o.im - t.1).abs() <= 1e-9 * scale,
                "{ours:?} vs {theirs:?}"
            );
        }
    };
    for _ in 0..500 {
        let mut m = [[0.0; 4]; 4];
        for row in m.iter_mut() {
            for v in row.iter_mut() {
                *v = rng.uniform(-10.0, 10.0);
            }
        }
        check(m);
    }
    // The FSI Jacobians at the equilibria of the paper preset and random designs.
    let mut designs = vec![paper()];
    for _ in 0..50 {
        designs.push(physical_params(&mut rng));
    }
    for raw in designs {
        let p = Params::<f64>::new(&raw).unwrap();
        let model = Model::new(&p).unwrap();
        for t in [30.0, 55.0, 80.0] {
            let j = jacobian_at_equilibrium(&model, t).unwrap();
            check(j);
            let l = linearise(&p, t).unwrap();
            assert_eq!(l.stable, hurwitz_stable(&j));
        }
    }
}

#[test]
fn dominant_eigenvalue_predicts_the_final_decay() {
    // Near the end of a step the error decays as exp(lambda t).
    let raw = paper();
    let p = Params::<f64>::new(&raw).unwrap();
    for (from, to) in [(45.0, 50.0), (65.0, 70.0)] {
        let lam = linearise(&p, to).unwrap().dominant.re;
        let tr = reference::simulate(&raw.core, Profile::Step { from, to }, 0.1, 1e-3, Method::Radau5, 1e-12).unwrap();
        let x_star = equilibrium(&p, to).unwrap().x;
        let (k1, k2) = (40, 60);
        let e = |k: usize| (tr.state[k][0] - x_star).abs();
        let rate = (e(k2) / e(k1)).ln() / ((k2 - k1) as f64 * 1e-3);
        assert!(
            (rate - lam).abs() <= 1e-3 * lam.abs(),
            "{from}->{to}: decay {rate} vs eigenvalue {lam}"
        );
    }
}

#[test]
fn reduced_model_tracks_the_full_one_within_its_documented_error() {
    // Pressures quasi-steady: the singular-perturbation limit. Its error
    // against the full model (docs/dynamics.md) stays below 0.5 % of a step.
    let raw = paper();
    for (from, to) in [(30.0, 40.0), (40.0, 50.0), (60.0, 70.0), (80.0, 30.0)] {
        let prof = Profile::Step { from, to };
        let cfg = TwinConfig {
            substeps: 8,
            ..TwinConfig::SHIPPED
        };
        let full = simulate(&raw, Precision::F64, cfg, &prof, 300).unwrap();
        let red = simulate(&raw, Precision::Reduced, cfg, &prof, 300).unwrap();
        let step = (full.state[300].x - full.state[0].x).abs();
        let err = full
            .state
            .iter()
            .zip(&red.state)
            .map(|(a, b)| (a.x - b.x).abs())
            .fold(0.0, f64::max)
            / step;
        eprintln!("{from}->{to}: reduced model within {:.3} % of the step", err * 100.0);
        assert!(err <= 0.005, "{from}->{to}: {:.3} %", err * 100.0);
        // Both settle on the same equilibrium.
        assert!((full.state[300].x - red.state[300].x).abs() <= 1e-9 * raw.core.stroke);
    }
}

/// `choose` answers for every positive tick, however coarse: a tick
/// beyond MAX_PROBE / 20 (25 ms) once crossed the bounds of a `clamp` and
/// panicked (the CLI's `step --dt 10`, an FMU at `tick_hz` below 40).
#[test]
fn the_chooser_answers_for_any_tick_without_panicking() {
    use compensator::dynamics::config::choose;
    use compensator::dynamics::twin::MAX_SUBSTEPS;
    let mut rng = Rng::new(0x7eed);
    let designs: Vec<compensator::RawParams> = std::iter::once(paper())
        .chain((0..5).map(|_| physical_params(&mut rng)))
        .collect();
    for raw in &designs {
        let p = Params::<f64>::new(raw).unwrap();
        for tick in [1e-6, 1e-3, 0.025, 0.026, 0.1, 1.0, 10.0, 1e6] {
            let r = std::panic::catch_unwind(|| choose(&p, tick, (30.0, 70.0)));
            let choice = r.unwrap_or_else(|_| panic!("choose panicked at tick {tick} s"));
            if let Ok(c) = choice {
                assert_eq!(c.config.tick, tick);
                assert!((1..=MAX_SUBSTEPS).contains(&c.config.substeps), "tick {tick}: {c:?}");
                assert!(c.estimated_error_pct.is_finite(), "tick {tick}: {c:?}");
            }
        }
        for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            assert!(choose(&p, bad, (30.0, 70.0)).is_err(), "tick {bad}");
        }
    }
}

/// In fixed point an event's rest is left to the next substep (`Owed`):
/// over the bench's ramps across the opening (26 -> 46 -> 26 C at 4 C/s,
/// the plunger released from the closed stop and back onto it, the
/// impact's force at the stop pulling by rounding's worth), with one
/// substep per tick every event tick of the Q12.20 twin ends at its event
/// and leaves its rest to the next tick (none is stepped at once: a rest
/// taken as the contact test at the event found it kept a bounce going
/// until it was), and the trajectory stays on the `f64` twin's (which
/// steps every rest at once); with four substeps per tick too.
#[test]
fn a_fixed_point_events_rest_is_taken_by_the_next_substep() {
    use compensator::Real;
    use compensator::dynamics::Owed;
    use compensator::scalar::Fixed;
    let raw = paper();
    let (p32, p64) = (Params::<f32>::new(&raw).unwrap(), Params::<f64>::new(&raw).unwrap());
    for substeps in [1u8, 4] {
        let config = TwinConfig {
            substeps,
            ..TwinConfig::SHIPPED
        };
        let mut fixed = Twin::<f32, Fixed>::new(&p32, config, 26.0).unwrap();
        let mut float = Twin::<f64, f64>::new(&p64, config, 26.0).unwrap();
        let (mut events, mut deferred, mut worst) = (0u32, 0u32, 0.0f64);
        for k in 0..10_000u32 {
            let s = (k as f64 + 0.5) * 1e-3;
            let t = 26.0 + 4.0 * if s < 5.0 { s } else { 10.0 - s };
            fixed.set_temperature(t as f32).unwrap();
            float.set_temperature(t).unwrap();
            let report = fixed.tick().unwrap();
            float.tick().unwrap();
            let frac = fixed.memory().owed.frac.to_f64();
            if report.impact || report.release {
                events += 1;
                deferred += u32::from(frac > 0.0);
            } else {
                assert!(
                    frac == 0.0,
                    "{substeps} substeps, tick {k}: {frac} substeps owed without an event"
                );
            }
            let d = (f64::from(fixed.state().x) - float.state().x).abs() / raw.core.stroke;
            worst = worst.max(d);
        }
        assert_eq!(float.memory().owed, Owed::NONE);
        eprintln!("{substeps} substeps: {events} event ticks, {deferred} deferred, worst {worst:e} of the stroke");
        assert!(events >= 2, "{substeps} substeps: {events} event ticks");
        // With one substep a tick that had an event owes its rest to the
        // next; with more, the tick's next substep took it.
        if substeps == 1 {
            assert_eq!(deferred, events, "a rest was stepped at once");
        }
        assert!(
            worst <= 1e-4,
            "{substeps} substeps: Q12.20 off the f64 twin by {worst:e} of the stroke"
        );
    }
}
