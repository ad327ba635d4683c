//! Fixed point over the whole oil range, near zero flow included: every fixed-point quantity of the twin's tick path keeps its
//! range and its resolution from the oil range's bottom (-20 C) to its top
//! (150 C, or where a thin oil leaves Walther's range), on the presets and
//! on the survey's designs at the ends of every coefficient's range.
//!
//! * the regularised orifice law near zero flow in Q12.20 (its
//!   first failure: 2048 at `u = 5e-4`);
//! * the CLI's case of a cold hold: the paper preset held at -15 C;
//! * holds at both ends of the oil range, and steps into hot oil, against
//!   the closed form;
//! * the ranges: every coefficient and every arithmetic result of the tick
//!   path within half of Q12.20's range, every divisor of the stage
//!   solution resolved to 1e-3, and the Q12.20 twin on the `f64` one.
//!
//! `docs/dynamics.md` ("Fixed-point ranges") has the tables;
//! `cargo run --release -p host-tests --example fixed_ranges -- --designs 1000`
//! prints them.

use compensator::Params;
use compensator::RawParams;
use compensator::Real;
use compensator::dynamics::dirk::{Dirk, SDIRK3};
use compensator::dynamics::fsi::{Coefficients, Fsi};
use compensator::dynamics::schemes::OdeSystem;
use compensator::dynamics::{Contact, Model, TwinConfig};
use compensator::scalar::Fixed;
use compensator::throttle::regularised_root;
use compensator_cli::dynamics::{Precision, Response, simulate};
use compensator_reference::dynamics::Profile;
use host_tests::fixed_audit::{
    COEFFICIENTS, Measured, Q12_20_MAX, coefficient_table, extremes, oil_ends, probe_design,
};
use host_tests::probe::{Op, source_line};
use host_tests::survey::{Kind, Step, chosen, settle_time};
use host_tests::{reference, repo_root};
use std::sync::OnceLock;

/// Seed of the CI survey (`tests/survey.rs`).
const SEED: u64 = 0x5EED_2026;
/// Designs the extremes are picked from (those of `--designs 1000` of the
/// survey example).
const SURVEYED: usize = 1000;
/// What "within range" means: half of Q12.20's, so that a change that
/// creeps toward saturation fails here before it saturates.
const HEADROOM: f64 = 0.5 * Q12_20_MAX;

/// The presets and the survey designs at the ends of each coefficient's
/// range (and the slowest), each with the configuration the chooser picks.
fn audited() -> &'static [(RawParams, TwinConfig)] {
    static DESIGNS: OnceLock<Vec<(RawParams, TwinConfig)>> = OnceLock::new();
    DESIGNS.get_or_init(|| {
        extremes(SURVEYED, SEED)
            .into_iter()
            .map(|raw| {
                let config = chosen(&raw).expect("a configuration").config;
                (raw, config)
            })
            .collect()
    })
}

#[test]
fn regularised_root_keeps_its_resolution_near_zero_flow() {
    // Independent f64: r(u) = u / (u^2 + u_tr^2)^(1/4),
    // r'(u) = (u^2 / 2 + u_tr^2) / (u^2 + u_tr^2)^(5/4).
    let law = |u: f64, tr: f64| {
        let s = u * u + tr * tr;
        (u / s.powf(0.25), (0.5 * u * u + tr * tr) / s.powf(1.25))
    };
    let (value, slope) = law(5e-4, 1e-5);
    assert!((value - 0.02236).abs() < 1e-5 && (slope - 22.36).abs() < 0.01);
    let (v, d) = regularised_root(Fixed::from_f64(5e-4), Fixed::from_f64(1e-5));
    assert!(
        (v.to_f64() - value).abs() <= 1e-3 * value,
        "value {v:?} vs {value} (the unscaled law gave 2048)"
    );
    assert!((d.to_f64() - slope).abs() <= 1e-3 * slope, "slope {d:?} vs {slope}");
    // Across the transition and on both sides of zero: the value to the
    // resolution the inputs allow (one LSB of u moves it by at most
    // 1 / (2 sqrt(u_tr)) LSB ~ 160 LSB near zero), the slope to 2 %.
    for &u in &[
        -0.3, -7e-4, -1e-5, -2e-6, 0.0, 1e-6, 3e-6, 1e-5, 4e-5, 1e-4, 5e-4, 0.01, 0.5, 1.0, 4.0,
    ] {
        let (v, d) = regularised_root(Fixed::from_f64(u), Fixed::from_f64(1e-5));
        // The law at the inputs as Q12.20 holds them.
        let (uq, tq) = (Fixed::from_f64(u).to_f64(), Fixed::from_f64(1e-5).to_f64());
        let (value, slope) = law(uq, tq);
        assert!(
            (v.to_f64() - value).abs() <= 3e-6 + 1e-4 * value.abs(),
            "r({u}): {v:?} vs {value}"
        );
        assert!((d.to_f64() - slope).abs() <= 2e-2 * slope, "r'({u}): {d:?} vs {slope}");
    }
}

/// Every tick of `r` within `1e-3` of `dp` (pressures) and of the stroke
/// (displacement) of the closed-form equilibrium at `t`, and the pressures
/// within `[p_c - dp, p_p + dp]`.
fn assert_held(raw: &RawParams, t: f64, r: &Response, what: &str) {
    let core = &raw.core;
    let eq = reference::equilibrium(core, t);
    let (dp, pc) = (core.pressure_drop, core.outlet_pressure);
    for (k, s) in r.state.iter().enumerate() {
        for (name, p, p_eq) in [("p_a", s.p_a, eq.p_a), ("p_b", s.p_b, eq.p_b)] {
            assert!(
                (p - p_eq).abs() <= 1e-3 * dp,
                "{what}, tick {k}: {name} = {p} Pa, closed form {p_eq} Pa (dp {dp} Pa)"
            );
            assert!(
                p >= pc - dp && p <= pc + 2.0 * dp,
                "{what}, tick {k}: {name} = {p} Pa outside [p_c - dp, p_p + dp]"
            );
        }
        assert!(
            (s.x - eq.x).abs() <= 1e-3 * core.stroke,
            "{what}, tick {k}: x = {} m, closed form {} m",
            s.x,
            eq.x
        );
    }
}

#[test]
fn paper_preset_held_at_minus_15_c_stays_at_its_equilibrium() {
    // A cold hold through the CLI: `compensator step --params presets/paper.toml
    // --from -15 --to -15 --precision fixed` (the CLI's default
    // configuration), which jumped to 88 MPa after one tick.
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let prof = Profile::Step { from: -15.0, to: -15.0 };
    let r = simulate(&raw, Precision::Fixed, TwinConfig::SHIPPED, &prof, 1000).unwrap();
    assert_eq!(r.state.len(), 1001);
    assert_held(&raw, -15.0, &r, "paper preset at -15 C");
}

#[test]
fn held_at_either_end_of_the_oil_range_every_design_stays_at_its_equilibrium() {
    for (i, (raw, config)) in audited().iter().enumerate() {
        let (cold, hot) = oil_ends(raw);
        for t in [cold, hot] {
            let prof = Profile::Step { from: t, to: t };
            let r = simulate(raw, Precision::Fixed, *config, &prof, 1000)
                .unwrap_or_else(|e| panic!("design {i} held at {t} C: {e}"));
            assert_held(raw, t, &r, &format!("design {i} held at {t} C"));
        }
    }
}

#[test]
fn steps_into_hot_oil_end_at_the_closed_form() {
    // The survey steps into cold oil and back; these are the steps to the
    // top of the oil range, where the flow unit changes on thin oils.
    for (i, (raw, config)) in audited().iter().enumerate() {
        let (cold, hot) = oil_ends(raw);
        let mid = 0.5 * (raw.estimator.valid_min + raw.estimator.valid_max);
        for (from, to) in [(mid, hot), (hot, mid), (cold, hot)] {
            let step = Step {
                kind: Kind::Partial,
                from,
                to,
            };
            let eq = reference::equilibrium(&raw.core, to);
            let prof = Profile::Step { from, to };
            let (stroke, dp) = (raw.core.stroke, raw.core.pressure_drop);
            let off = |r: &Response| {
                let e = r.state.last().unwrap();
                ((e.x - eq.x).abs() / stroke).max((e.p_a - eq.p_a).abs().max((e.p_b - eq.p_b).abs()) / dp)
            };
            // Long enough for the f64 twin to settle within 1e-4 (doubled
            // up to 20 s).
            let mut time = settle_time(raw, &step);
            let ticks = loop {
                let n = (time / config.tick).round() as usize;
                let r = simulate(raw, Precision::F64, *config, &prof, n).unwrap();
                if off(&r) <= 1e-4 || time >= 20.0 {
                    break n;
                }
                time = (2.0 * time).min(20.0);
            };
            let r = simulate(raw, Precision::Fixed, *config, &prof, ticks)
                .unwrap_or_else(|e| panic!("design {i} {from} -> {to} C: {e}"));
            assert!(
                off(&r) <= 1e-3,
                "design {i} {from} -> {to} C: Q12.20 ends {:.2e} away from the closed form",
                off(&r)
            );
        }
    }
}

#[test]
fn every_fixed_point_quantity_keeps_its_range_and_resolution() {
    let designs: Vec<RawParams> = audited().iter().map(|(raw, _)| *raw).collect();
    // The coefficients, by name, over the oil range (not omega_a0,
    // omega_b0: only the explicit schemes read them, and they may saturate).
    let table = coefficient_table(&designs, true);
    for (name, (_, max)) in COEFFICIENTS.iter().zip(table) {
        assert!(max <= HEADROOM, "{name} reaches {max}");
    }
    // Every arithmetic result of the tick path, through holds and steps
    // at both ends of the oil range.
    let mut total = Measured::default();
    for (i, (raw, config)) in audited().iter().enumerate() {
        let mut m = probe_design(raw, Some(*config), 500);
        for f in &mut m.failures {
            *f = format!("design {i}: {f}");
        }
        total.merge(&m);
    }
    assert!(total.failures.is_empty(), "{}", total.failures.join("\n"));
    let tick_path = |file: &str| {
        ["dirk.rs", "twin.rs", "fsi.rs", "coefficients.rs", "stops.rs"]
            .iter()
            .any(|f| file.ends_with(&format!("dynamics/{f}")))
    };
    let mut sites = 0;
    for (precision, ranges) in [("f64", &total.exact), ("Q12.20", &total.fixed)] {
        for (site, r) in ranges.iter().filter(|(s, _)| tick_path(s.file)) {
            sites += 1;
            assert!(
                r.max_abs <= HEADROOM,
                "{precision}: {}:{}:{} ({:?}) reaches {:.3e}: `{}`",
                site.file,
                site.line,
                site.column,
                site.op,
                r.max_abs,
                source_line(site)
            );
        }
    }
    assert!(sites > 100, "only {sites} sites recorded");
    // Every divisor of the stage solution resolved to better than 1e-3,
    // but the step length `h gamma` (of the step's `1 / hg`, and of `tau /
    // hg` where that is not resolved): a release or an impact located in
    // a step's first microseconds makes it a few LSB, whose rounding moves
    // the located time by less than a nanosecond (the step is taken
    // consistently with the rounded length).
    for (site, r) in total.fixed.iter() {
        if site.op == Op::Divisor && site.file.ends_with("dynamics/dirk.rs") {
            let line = source_line(site);
            if line.contains("ONE / hg") || line.contains("tau / self.hg") {
                continue;
            }
            assert!(
                r.min_nonzero >= 1e-3,
                "divisor at {}:{}:{} down to {:.3e}: `{line}`",
                site.file,
                site.line,
                site.column,
                r.min_nonzero
            );
        }
    }
    // And what it all amounts to: the Q12.20 twin on the f64 one.
    eprintln!(
        "{} designs: Q12.20 against f64, xi within {:.1e}, pressures within {:.1e}, end states within {:.1e}",
        designs.len(),
        total.worst_xi,
        total.worst_pi,
        total.worst_end
    );
    assert!(total.worst_xi <= 2e-4, "xi off by {:.2e} of the stroke", total.worst_xi);
    assert!(total.worst_end <= 1e-4, "end states off by {:.2e}", total.worst_end);
    assert!(total.worst_pi <= 1e-2, "pressures off by {:.2e} of dp", total.worst_pi);
}

#[test]
fn the_flow_unit_of_thin_hot_oils_changes_no_state() {
    // A design whose capillary conducts more than FLOW_SCALE_LIMIT times
    // the orifice in hot oil gets a flow unit of 2^n Q*: the right-hand
    // side and an SDIRK step are those of the unscaled coefficients.
    let mut checked = 0;
    for (raw, config) in audited() {
        let p = Params::<f64>::new(raw).unwrap();
        let model = Model::new(&p).unwrap();
        let c: Coefficients<f64> = model.coefficients(&p.oil.state(oil_ends(raw).1).unwrap()).unwrap();
        if c.flow_shift == 0 {
            continue;
        }
        checked += 1;
        assert!(
            c.g_l <= compensator::dynamics::fsi::FLOW_SCALE_LIMIT
                && c.g_l > 0.5 * compensator::dynamics::fsi::FLOW_SCALE_LIMIT
        );
        let s = f64::from(1u32 << c.flow_shift);
        let u = Coefficients {
            q_t: c.q_t * s,
            g_l: c.g_l * s,
            sigma: c.sigma * s,
            omega_a0: c.omega_a0 / s,
            omega_b0: c.omega_b0 / s,
            inv_omega_a0: c.inv_omega_a0 * s,
            inv_omega_b0: c.inv_omega_b0 * s,
            flow_shift: 0,
            ..c
        };
        let h = config.step(model.scales.time);
        let dirk = Dirk::<f64>::new(&SDIRK3, h, &c);
        for y in [[0.3, 0.02, 0.4, 0.7], [0.0, 0.0, 0.9, 0.05], [0.95, -0.3, 0.1, 0.99]] {
            let (a, b) = (
                Fsi {
                    coefficients: &c,
                    contact: Contact::Free,
                }
                .rhs(&y),
                Fsi {
                    coefficients: &u,
                    contact: Contact::Free,
                }
                .rhs(&y),
            );
            for i in 0..4 {
                assert!(
                    (a[i] - b[i]).abs() <= 1e-9 * (1.0 + b[i].abs()),
                    "rhs {y:?}: {a:?} vs {b:?}"
                );
            }
            let (a, b) = (
                dirk.step(&c, &y, 1.0, Contact::Free, &mut 0.0),
                dirk.step(&u, &y, 1.0, Contact::Free, &mut 0.0),
            );
            for i in 0..4 {
                assert!(
                    (a[i] - b[i]).abs() <= 1e-12 * (1.0 + b[i].abs()),
                    "step {y:?}: {a:?} vs {b:?}"
                );
            }
        }
    }
    assert!(checked > 0, "no audited design changes its flow unit");
}

#[test]
fn a_coefficient_beyond_q12_20_is_refused_by_name() {
    // A plunger damped 2,000 times more than the paper's: 2 zeta = 4,400,
    // beyond Q12.20's 2,048. The fixed-point twin refuses it with the
    // coefficient's name instead of saturating; the floats take it.
    let mut raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    raw.core.damping = 1.0e5;
    let prof = Profile::Step { from: 40.0, to: 40.0 };
    let e = simulate(&raw, Precision::Fixed, TwinConfig::SHIPPED, &prof, 1).unwrap_err();
    assert!(e.to_string().contains("zeta does not fit the scalar type"), "{e}");
    let p = Params::<f32>::new(&raw).unwrap();
    let err = compensator::dynamics::Twin::<f32, Fixed>::new(&p, TwinConfig::SHIPPED, 40.0).unwrap_err();
    assert_eq!(err, compensator::ModelError::NotRepresentable("zeta"));
    assert!(simulate(&raw, Precision::F32, TwinConfig::SHIPPED, &prof, 1).is_ok());
}

#[test]
fn a_plunger_creeping_over_short_steps_arrives() {
    // Survey design 259 of 1,000 (32 substeps per tick, h = 0.035): after
    // heating 26 -> 78 C its plunger creeps at ~30 LSB of velocity, and
    // each product h b_j w_j of the displacement update is below half an
    // LSB. Rounded one by one they stopped Q12.20 4.2e-4 of the stroke
    // short, for good; summed exactly (`Real::dot_add_compensated`) it
    // arrives with the f64 twin, but for what Q12.20 resolves of the
    // pressures of its slow chambers (`tau / h gamma = 30`): a substep
    // moves them by 1/30 of their way to equilibrium, and a move below
    // half an LSB rounds away, so they rest up to ~10 LSB (1e-5 of dp)
    // from it; at phi / a_x = 14.3 that holds the plunger up to 3e-5 of
    // the stroke off (`docs/dynamics.md`, "Fixed point").
    let raw = host_tests::survey::designs(1000, SEED)[259];
    let config = chosen(&raw).unwrap().config;
    assert_eq!(config.substeps, 32, "the design this test was written for");
    let prof = Profile::Step { from: 26.0, to: 78.0 };
    let a = simulate(&raw, Precision::F64, config, &prof, 3000).unwrap();
    let b = simulate(&raw, Precision::Fixed, config, &prof, 3000).unwrap();
    let (x, y) = (a.state[3000].x, b.state[3000].x);
    let off = (x - y).abs() / raw.core.stroke;
    assert!(off <= 4e-5, "Q12.20 ends {off:.2e} of the stroke from f64");
}
