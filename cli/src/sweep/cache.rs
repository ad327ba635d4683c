//! Work a sweep's variants share, done once per sweep.
//!
//! The Eq. (32) verdict evaluates the oil at every 0.1 C of the validated
//! range (521 Walther evaluations, each a `log10`, a `powf` and two
//! `exp10`, for 26-78 C): most of a variant's static metrics. The oil's
//! viscosity and density derivatives at those temperatures depend on the
//! `[fluid]` law and the range alone, which a sweep of the plunger, the
//! throttles or the spring leaves unchanged: [`Shared`] evaluates them
//! once for the base file's oil and range, and a variant with the same
//! oil (compared bit for bit) and range reuses them. What it computes is
//! [`compensator::asymptotic::monotonicity`]'s result exactly, by the same
//! steps ([`Shared::monotonicity`]; `tests` compare the two).

use compensator::asymptotic::{MAX_MONOTONICITY_SAMPLES, Monotonicity, monotonicity, monotonicity_of, sensitivity_at};
use compensator::fluid::{FluidPoint, Oil};
use compensator::{ModelError, Params, RawParams};

/// The oil with the bulk modulus (which no fluid point depends on) zeroed:
/// the key of the cached points.
fn key(oil: &Oil<f64>) -> Oil<f64> {
    let mut k = *oil;
    k.bulk_modulus = 0.0;
    k
}

/// The fluid points of one oil at the samples of one range.
#[derive(Clone, Debug)]
struct Points {
    oil: Oil<f64>,
    lo: f64,
    hi: f64,
    n: u32,
    points: Vec<Result<FluidPoint<f64>, ModelError>>,
}

/// What the variants of one sweep share ([module docs](self)).
#[derive(Clone, Debug, Default)]
pub struct Shared {
    points: Option<Points>,
}

/// The sample temperatures of [`monotonicity`] over `[lo, hi]` in `n`
/// samples, as it computes them.
fn sample(lo: f64, hi: f64, n: u32, i: u32) -> f64 {
    let frac = i as f64 / (n - 1) as f64;
    lo + (hi - lo) * frac
}

impl Shared {
    /// Nothing shared: every variant computes everything.
    pub fn none() -> Shared {
        Shared::default()
    }

    /// The work shared by the variants of `base` whose Eq. (32) check runs
    /// over `[lo, hi]` in `samples` samples. A base file the model refuses
    /// shares nothing.
    pub fn new(base: &RawParams, lo: f64, hi: f64, samples: u32) -> Shared {
        let Ok(p) = Params::<f64>::new(base) else {
            return Shared::none();
        };
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Shared::none();
        }
        let n = samples.clamp(2, MAX_MONOTONICITY_SAMPLES);
        Shared {
            points: Some(Points {
                oil: key(&p.oil),
                lo,
                hi,
                n,
                points: (0..n).map(|i| p.oil.point(sample(lo, hi, n, i))).collect(),
            }),
        }
    }

    /// [`monotonicity`]`(params, lo, hi, samples)`, from the shared fluid
    /// points when `params`' oil and the range are the shared ones.
    ///
    /// # Errors
    ///
    /// As [`monotonicity`].
    pub fn monotonicity(
        &self,
        params: &Params<f64>,
        lo: f64,
        hi: f64,
        samples: u32,
    ) -> Result<Monotonicity<f64>, ModelError> {
        let n = samples.clamp(2, MAX_MONOTONICITY_SAMPLES);
        let Some(c) = self
            .points
            .as_ref()
            .filter(|c| c.lo == lo && c.hi == hi && c.n == n && c.oil == key(&params.oil))
        else {
            return monotonicity(params, lo, hi, samples);
        };
        // The steps of `monotonicity`, each sample's oil point cached.
        monotonicity_of(c.points.iter().enumerate().map(|(i, point)| {
            let d = sensitivity_at(params, point.as_ref().map_err(|e| *e)?)?.dx_dt_branch;
            Ok((sample(lo, hi, n, i as u32), d))
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached verdict is the library's, bit for bit, for variants that
    /// share the oil (the plunger, throttles and drop varied) and for those
    /// that do not (computed afresh), including a range the oil refuses.
    #[test]
    fn the_shared_verdict_is_the_library_s() {
        let base = crate::params_file::parse(crate::input::PAPER_PRESET).unwrap();
        let (lo, hi) = (base.estimator.valid_min, base.estimator.valid_max);
        let shared = Shared::new(&base, lo, hi, 521);
        // A range the oil model refuses part of: the error is the library's.
        let hot = Shared::new(&base, lo, 400.0, 521);
        assert!(monotonicity(&Params::<f64>::new(&base).unwrap(), lo, 400.0, 521).is_err());
        let mut checked = 0;
        for k in 0..40u32 {
            let f = 1.0 + 0.02 * (f64::from(k) - 20.0);
            let mut raw = base;
            raw.core.plunger_diameter *= f;
            raw.core.spring_rate /= f;
            raw.core.laminar_length *= f * f;
            raw.core.pressure_drop *= 2.0 - f;
            if k % 5 == 0 {
                raw.core.walther_b *= f; // another oil: not shared
            }
            let Ok(p) = Params::<f64>::new(&raw) else { continue };
            for (lo, hi, n) in [(lo, hi, 521), (lo, hi, 100), (-60.0, hi, 521)] {
                assert_eq!(
                    shared.monotonicity(&p, lo, hi, n),
                    monotonicity(&p, lo, hi, n),
                    "variant {k}, {lo}..{hi} in {n}"
                );
            }
            assert_eq!(hot.monotonicity(&p, lo, 400.0, 521), monotonicity(&p, lo, 400.0, 521));
            checked += 1;
        }
        assert!(checked >= 30, "{checked}");
        assert!(Shared::none().points.is_none());
    }
}
