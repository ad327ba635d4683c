//! The oil's Walther evaluation in two halves (`Oil::walther_log`, then
//! `Oil::point_from_log`: what a core without an FPU spreads over two job
//! ticks) against the whole (`Oil::point`, bit for bit) and against an
//! independent `f64` evaluation of ASTM D341 and the density law.

use compensator::fluid::{KELVIN_OFFSET, Oil};

/// `(walther_a, walther_b)`: the paper preset's oil and two ISO grades'
/// (VG 10 and VG 100, from their 40 and 100 C viscosities).
const OILS: [(f64, f64); 3] = [
    (13.406399536848388, 5.340508448321484),
    (10.182421501506951, 3.937623044584095),
    (7.165868034959745, 2.7615560760237954),
];

const DENSITY_15: f64 = 870.0;
const EXPANSION: f64 = 0.00065;

/// ASTM D341 in `f64`: kinematic viscosity [cSt] and its first derivative
/// [cSt/K] at `t` [C], `log10(log10(nu + 0.7)) = a - b log10(T_K)`.
fn astm_d341(a: f64, b: f64, t: f64) -> (f64, f64) {
    let tk = t + KELVIN_OFFSET;
    let w = 10f64.powf(a - b * tk.log10());
    let z = 10f64.powf(w);
    // dz/dT = z ln10 dw/dT, dw/dT = -b w / T_K.
    (z - 0.7, -z * core::f64::consts::LN_10 * b * w / tk)
}

#[test]
fn two_halves_are_the_whole_and_agree_with_astm_d341() {
    let mut compared = 0;
    for (a, b) in OILS {
        let oil = Oil::<f32>::new(a, b, DENSITY_15, EXPANSION, 1.5e9);
        for k in 0..=400 {
            let t = -20.0 + 0.5 * k as f32;
            let whole = oil.point(t);
            let halves = oil.walther_log(t).and_then(|log| oil.point_from_log(log));
            match (whole, halves) {
                (Ok(w), Ok(h)) => {
                    // Bit for bit: the same operations in the same order.
                    let bits = |p: &compensator::fluid::FluidPoint<f32>| {
                        [
                            p.state.temperature,
                            p.state.kinematic_viscosity,
                            p.state.density,
                            p.state.dynamic_viscosity,
                            p.viscosity.value,
                            p.viscosity.d1,
                            p.viscosity.d2,
                            p.density.value,
                            p.density.d1,
                            p.density.d2,
                        ]
                        .map(f32::to_bits)
                    };
                    assert_eq!(bits(&w), bits(&h), "oil ({a}, {b}) at {t} C");
                    let (nu, dnu) = astm_d341(a, b, f64::from(t));
                    let rel = |x: f32, exact: f64| ((f64::from(x) - exact) / exact).abs();
                    assert!(
                        rel(h.viscosity.value * 1e6, nu) < 2e-5,
                        "nu at {t} C: {} cSt, D341 {nu}",
                        h.viscosity.value * 1e6
                    );
                    assert!(
                        rel(h.viscosity.d1 * 1e6, dnu) < 1e-4,
                        "nu' at {t} C: {}, D341 {dnu}",
                        h.viscosity.d1 * 1e6
                    );
                    let rho = DENSITY_15 / (1.0 + EXPANSION * (f64::from(t) - 15.0));
                    assert!(rel(h.density.value, rho) < 1e-6, "rho at {t} C");
                    compared += 1;
                }
                // Outside Walther's range both refuse, with the same reason.
                (Err(w), Err(h)) => assert_eq!(w, h, "oil ({a}, {b}) at {t} C"),
                (w, h) => panic!("oil ({a}, {b}) at {t} C: whole {w:?}, halves {h:?}"),
            }
        }
    }
    assert!(compared > 600, "{compared} temperatures inside Walther's range");
}

#[test]
fn the_first_half_refuses_what_the_whole_refuses_first() {
    let oil = Oil::<f32>::new(OILS[0].0, OILS[0].1, DENSITY_15, EXPANSION, 1.5e9);
    for t in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -300.0] {
        assert_eq!(oil.walther_log(t).map(|_| ()), oil.point(t).map(|_| ()), "{t}");
        assert!(oil.walther_log(t).is_err());
    }
}
