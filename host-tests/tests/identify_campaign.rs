//! A bounded slice of the identification campaign
//! (`examples/identify_campaign.rs`, docs/calibration.md): seeded random
//! underdamped and overdamped designs, each a step recorded by the
//! independent reference solver with displacement noise only, fitted by
//! `identify`'s default (mass, damping, bulk modulus) from a base file
//! with the mass and friction off by up to a factor 2 and the bulk modulus
//! by up to 1.5.
//!
//! Asserted: every underdamped design's damping within 5 % of the truth;
//! every mass or damping whose 95 % interval is within +-5 % of its value
//! within 5 % of the truth; the 95 % intervals hold the truth at about
//! their rate (at most 2 misses in a slice of 7 or 12 intervals, where
//! 0.4 and 0.6 are expected; the campaign measures the rate); the residual
//! at the noise (the twin follows the reference, the fit found the
//! minimum).

use host_tests::identify_study::{Class, Outcome, Summary, run};

/// Campaign seed of the slice (the example's default is 1: the slice is
/// other designs than the documented campaign's first ones).
const SEED: u64 = 11;

fn slice(class: Class, count: u64) -> Vec<Outcome> {
    let out: Vec<Outcome> = (0..count).filter_map(|i| run(class, SEED, i)).collect();
    assert_eq!(out.len(), count as usize, "the reference records every design");
    for o in &out {
        eprintln!(
            "{:?} {} zeta {:.2}: {:?}",
            o.class,
            o.index,
            o.zeta,
            o.result.as_ref().map(|v| v
                .iter()
                .map(|s| (
                    s.path,
                    s.estimate.map(|e| (e.value / s.truth - 1.0, e.std_error / e.value))
                ))
                .collect::<Vec<_>>())
        );
        assert!(o.result.is_ok(), "{o:?}");
        assert!((0.8..1.2).contains(&o.rms_over_noise), "{o:?}");
    }
    out
}

fn check(out: &[Outcome]) -> Summary {
    let s = Summary::of(out);
    eprintln!("{s:?}");
    assert_eq!(s.failed, 0);
    assert_eq!(s.claimed_5, s.claimed_5_held, "{s:?}");
    assert!(s.intervals - s.covered <= 2, "{s:?}");
    s
}

#[test]
fn underdamped_designs_get_their_damping_within_five_percent() {
    let out = slice(Class::Underdamped, 6);
    let s = check(&out);
    assert_eq!(s.damping_within_5, out.len(), "{s:?}");
    assert!(
        s.by_parameter[0].0 == out.len() && s.by_parameter[1].0 == out.len(),
        "{s:?}"
    );
}

#[test]
fn overdamped_designs_report_what_they_determine_with_honest_intervals() {
    let out = slice(Class::Overdamped, 4);
    let s = check(&out);
    // The friction sets an overdamped creep's pace: always identified.
    assert_eq!(s.by_parameter[1].0, out.len(), "{s:?}");
}
