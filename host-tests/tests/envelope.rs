//! The linearisation over the parameter schema's whole plausible envelope:
//! finite eigenvalues, natural frequencies and damping ratios, or a typed
//! error, never `-inf` or a damping ratio outside [-1, 1].
//!
//! The fuzzers found `linearise` returning infinite eigenvalues as `Ok`
//! (F3), `Complex::abs` overflowing (F1) and the Routh-Hurwitz verdict
//! overflowing (F4) on designs with magnitudes no device has (a bulk
//! modulus of 4.7e174 Pa, a subnormal mass). The schema now bounds every
//! field's magnitude (params/src/schema.rs); this test draws designs at
//! the envelope's corners and inside it (seeded; each field at its minimum,
//! its maximum or log-uniform between, on top of a physical design) and
//! checks what the core promises on them. The functions themselves are
//! also fixed for any input (the model's unit tests of `Complex::abs` and
//! `hurwitz_stable`).

use compensator::dynamics::Model;
use compensator::dynamics::linear::{hurwitz_stable, jacobian_at_equilibrium, linearise};
use compensator::params::{CORE_FIELDS, RawParams};
use compensator::{Float, Params};
use host_tests::random::{Rng, physical_params};

/// A physical design with each core field, with probability 1/2, moved
/// to its plausible minimum, maximum or a log-uniform value between.
fn envelope_design(rng: &mut Rng) -> RawParams {
    let mut raw = physical_params(rng);
    raw.core = raw.core.map(|n| {
        let field = CORE_FIELDS.iter().find(|f| f.path == n.path).unwrap();
        let (lo, hi) = (field.min, field.max);
        match rng.next_u64() % 6 {
            0 => lo,
            1 => hi,
            2 if lo > 0.0 => rng.log_uniform(lo, hi),
            2 => rng.uniform(lo, hi),
            _ => n.value,
        }
    });
    raw
}

/// The linearisation's promises at `t` on `p`; `true` when it is `Ok`.
fn check<F: Float + std::fmt::Debug>(raw: &RawParams, p: &Params<F>, t: f64) -> bool {
    let Ok(l) = linearise(p, F::from_f64(t)) else {
        return false;
    };
    for (i, e) in l.eigenvalues.iter().enumerate() {
        assert!(e.re.is_finite() && e.im.is_finite(), "{raw:?} at {t} C: {l:?}");
        let (wn, zeta) = (l.natural_frequency[i], l.damping_ratio[i]);
        assert!(wn.is_finite() && wn >= F::ZERO, "{raw:?} at {t} C: {l:?}");
        assert!(zeta >= -F::ONE && zeta <= F::ONE, "{raw:?} at {t} C: {l:?}");
        // |lambda| >= |Re lambda| and |Im lambda|, within rounding.
        let slack = F::from_f64(1.0 + 1e-5);
        assert!(
            wn * slack >= e.re.abs() && wn * slack >= e.im.abs(),
            "{raw:?} at {t} C: {l:?}"
        );
    }
    assert!(l.plunger_damping_ratio.is_finite(), "{raw:?} at {t} C: {l:?}");
    assert_eq!(l.stable, l.eigenvalues.iter().all(|e| e.re < F::ZERO));
    // The Routh-Hurwitz verdict agrees wherever no eigenvalue lies within
    // 1e-6 |lambda|_max of the imaginary axis (where either may round
    // either way).
    let model = Model::new(p).unwrap();
    let jac = jacobian_at_equilibrium(&model, F::from_f64(t)).unwrap();
    let top = l.natural_frequency.iter().fold(F::ZERO, |a, &b| a.max(b));
    let margin = l
        .eigenvalues
        .iter()
        .fold(F::from_f64(f64::MAX), |a, e| a.min(e.re.abs()));
    if margin > F::from_f64(1e-6) * top {
        assert_eq!(hurwitz_stable(&jac), l.stable, "{raw:?} at {t} C: {l:?}");
    }
    true
}

#[test]
fn linearise_is_finite_or_refused_over_the_plausible_envelope() {
    let mut rng = Rng::new(0xE1F3_0F4A);
    let (mut designs, mut ok64, mut ok32) = (0, 0, 0);
    for _ in 0..8000 {
        let raw = envelope_design(&mut rng);
        if raw.validate().is_err() {
            continue;
        }
        designs += 1;
        let p64 = Params::<f64>::new(&raw).unwrap();
        let p32 = Params::<f32>::new(&raw);
        for t in [-40.0, 0.0, 26.0, 55.0, 78.0, 150.0, 250.0] {
            ok64 += usize::from(check(&raw, &p64, t));
            if let Ok(p32) = &p32 {
                ok32 += usize::from(check(&raw, p32, t));
            }
        }
    }
    // Enough of the envelope was accepted and linearised to mean something.
    eprintln!("{designs} designs; linearised {ok64} times in f64, {ok32} in f32");
    assert!(
        designs >= 500 && ok64 >= 2500 && ok32 >= 2500,
        "{designs} {ok64} {ok32}"
    );
}
