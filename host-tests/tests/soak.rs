//! The soak with faults, bounded for CI: the estimator on the
//! paper preset through the QEMU soak image's walk (same seed, same ticks:
//! the host twin of `cargo xtask test`'s QEMU soak step), and the `f32` twin
//! against the `f64` twin on the paper preset and random designs.
//! `COMPENSATOR_SOAK_TICKS` runs longer; the long run is
//! `cargo run --release -p host-tests --example soak -- --ticks 10000000`
//! (`docs/soak.md`).

use host_tests::soak::{Kind, SEED, drift, moving_designs, paper, run};

/// Ticks of the estimator soak: the QEMU image's 1e6, or
/// `COMPENSATOR_SOAK_TICKS`.
fn ticks() -> u32 {
    std::env::var("COMPENSATOR_SOAK_TICKS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000)
}

#[test]
fn the_estimator_survives_a_faulty_sensor_and_recovers() {
    let r = run(&paper(), ticks(), SEED).unwrap();
    eprintln!("{}", r.table());
    assert_eq!(r.violations(), 0, "\n{}", r.table());
    let st = &r.stats;
    assert_eq!(st.reseats, 0);
    // The walk did what it is for: every kind of fault, long ones, cold
    // excursions, real steps, settled holds.
    for kind in Kind::ALL {
        assert!(st.injected[kind.index()] > 0, "no {} injected", kind.name());
    }
    assert!(st.long.iter().sum::<u32>() >= 10, "{:?}", st.long);
    assert!(st.cold_excursions >= 3, "{} cold excursions", st.cold_excursions);
    assert!(st.span.0 <= r.limits.oil.0 + 3.0, "coldest {} C", st.span.0);
    assert!(st.holds_checked >= 30, "{} holds checked", st.holds_checked);
    assert!(st.spikes > 0 && st.unusable > 0);
    // The latencies were measured, not vacuous: a dropout raises DEGRADED
    // within the last sample period of its bound.
    let dropout = st.degraded[Kind::Dropout.index()];
    let lim = &r.limits;
    assert!(
        dropout + lim.sensor_every > lim.degraded_bound(),
        "dropout flagged after {dropout} ticks"
    );
}

#[test]
fn the_same_seed_gives_the_same_soak() {
    let a = run(&paper(), 100_000, 7).unwrap();
    let b = run(&paper(), 100_000, 7).unwrap();
    assert_eq!(a.stats, b.stats);
    let c = run(&paper(), 100_000, 8).unwrap();
    assert_ne!(a.stats.injected, c.stats.injected);
}

#[test]
fn the_f32_twin_stays_on_the_f64_twin() {
    let mut runs = vec![("paper preset".to_string(), paper(), ticks())];
    for (i, d) in moving_designs(3, SEED).into_iter().enumerate() {
        runs.push((format!("random design {i}"), d, ticks()));
    }
    for (name, raw, n) in &runs {
        let d = drift(raw, *n, SEED).unwrap();
        eprintln!("{name}: {}", d.line());
        let problems = d.problems();
        assert!(problems.is_empty(), "{name}: {problems:?}\n{}", d.line());
    }
}
