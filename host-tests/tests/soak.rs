//! The soak with faults, bounded for CI: the estimator on the
//! paper preset through the QEMU soak image's walk (same seed, same ticks:
//! the host twin of `cargo xtask test`'s QEMU soak step), and the `f32` twin
//! against the `f64` twin on the paper preset and random designs; the same
//! soak with the NTC preset's sensor (`presets/paper-ntc.toml`).
//! `COMPENSATOR_SOAK_TICKS` runs longer; the long run is
//! `cargo run --release -p host-tests --example soak -- --ticks 10000000`
//! (`docs/soak.md`).

use compensator::sensor::device::SensorKind;
use host_tests::soak::{Kind, Run, SEED, drift, moving_designs, paper, paper_ntc, run};

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
    assert_eq!(r.sensor, SensorKind::Rtd);
    survives(&r);
}

/// The same soak through the NTC on the STM32F4's ADC (no diagnosis
/// cycle: no read after a fault's start hides it).
#[test]
fn the_estimator_survives_a_faulty_ntc_and_recovers() {
    let r = run(&paper_ntc(), ticks(), SEED).unwrap();
    assert_eq!(r.sensor, SensorKind::Ntc);
    assert_eq!(r.limits.restart, 0);
    survives(&r);
    // Every fault of a kind that must be flagged was read, and flagged
    // within one sample period.
    assert_eq!(r.stats.unread, [0; 11]);
    for kind in Kind::ALL {
        assert!(r.stats.detection[kind.index()] < r.limits.sensor_every, "{}", r.table());
    }
}

/// The checks of a soak run, whatever its sensor.
fn survives(r: &Run) {
    eprintln!("{:?} sensor\n{}", r.sensor, r.table());
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
    for raw in [paper(), paper_ntc()] {
        let a = run(&raw, 100_000, 7).unwrap();
        let b = run(&raw, 100_000, 7).unwrap();
        assert_eq!(a.stats, b.stats);
        let c = run(&raw, 100_000, 8).unwrap();
        assert_ne!(a.stats.injected, c.stats.injected);
    }
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
