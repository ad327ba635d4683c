//! The sweep's settling time from the `f64` twin against the independent
//! reference solver (Radau5) on many variants (`host_tests::sweep_twin`;
//! the survey `examples/sweep_twin.rs` runs more): the twin's response,
//! as the sweep samples it (tick ends and their Hermite interpolant), is
//! within 0.1 % of the step of the reference at every sample, and the
//! settling times agree (equal, or within the shift an error of 0.1 % of
//! the step makes at the crossing; both infinite when the response has
//! not settled by the end); some runs meet a stop and are taken at the
//! sample interval.

use compensator_cli::params_file;
use host_tests::sweep_twin::{compare_first, variant};

#[test]
fn the_twin_s_settling_times_are_the_reference_s() {
    let paper = params_file::parse(compensator_cli::input::PAPER_PRESET).unwrap();
    let (mut compared, mut equal, mut fine, mut worst) = (0, 0, 0, 0.0f64);
    for i in 0..60 {
        let raw = variant(7, i, &paper);
        let Ok((step, c)) = compare_first(&raw, 1e-4, 0.2) else {
            continue;
        };
        compared += 1;
        worst = worst.max(c.max_error_pct);
        assert!(
            c.max_error_pct <= 0.1,
            "variant {i} {step:?}: {:.4} % of the step at {} s, plan {:?}",
            c.max_error_pct,
            c.max_error_at,
            c.plan
        );
        assert!(
            c.settling_agrees(),
            "variant {i} {step:?}: settling {} s (twin) vs {} s (reference), allowed {} s",
            c.settling_twin,
            c.settling_reference,
            c.allowed
        );
        equal += usize::from(c.settling_twin == c.settling_reference);
        fine += usize::from(c.fine);
    }
    let _ = fine;
    // The paper design onto its closed stop (at 30 C and below): an impact.
    let mut onto_stops = 0;
    for (from, to) in [(50.0, 20.0), (60.0, 25.0)] {
        let c = host_tests::sweep_twin::compare(&paper, from, to, 1e-4, 0.2).unwrap();
        eprintln!("paper {from} -> {to} C: {c:?}");
        assert!(c.max_error_pct <= 0.1, "{from} -> {to}: {c:?}");
        assert!(c.settling_agrees(), "{from} -> {to}: {c:?}");
        onto_stops += usize::from(c.fine);
    }
    assert_eq!(onto_stops, 2, "the impacts run at the sample interval");
    eprintln!("{compared} variants: worst {worst:.4} % of the step; settling equal in {equal}; {fine} met a stop");
    assert!(compared >= 40, "{compared}");
    assert!(equal * 10 >= compared * 9, "{equal} of {compared}");
}
