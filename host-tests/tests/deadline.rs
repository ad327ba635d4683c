//! Ticks that start late (`Estimator::tick_after`): the missed deadlines
//! are counted and flagged, and the twin catches up in simulated time, so
//! that after the same real time a late controller's twin is the punctual
//! one's; in `f32` and in Q12.20.

use compensator::Params;
use compensator::Real;
use compensator::dynamics::DynamicState;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, MAX_CATCH_UP, MAX_DEFERRED};
use compensator::scalar::Fixed;
use host_tests::repo_root;

fn setup<T: Real>(t: f32) -> (Params<f32>, Estimator<T>) {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    (p, Estimator::<T>::with_scalar(&p, cfg, t).unwrap())
}

/// The twin off its equilibrium (the plunger half-way, the chamber
/// pressures swapped), at a steady temperature: it relaxes by its own
/// dynamics, which the late estimator must follow in real time.
fn displaced<T: Real>(p: &Params<f32>, est: &mut Estimator<T>) {
    let s = est.twin().state();
    est.twin_mut().set_state(&DynamicState {
        x: 0.5 * p.plunger.stroke,
        v: 0.0,
        p_a: s.p_b,
        p_b: s.p_a,
    });
}

fn late_twin_follows_real_time<T: Real>() {
    let t = 55.0;
    let (p, mut punctual) = setup::<T>(t);
    let (_, mut late) = setup::<T>(t);
    displaced(&p, &mut punctual);
    displaced(&p, &mut late);
    // 90 ms of real time (inside the consistency check's settling window,
    // so that neither estimator re-seats its relaxing twin): the late
    // controller ticks every 3 periods, then every 7.
    let sample = |tick: u32| if tick.is_multiple_of(20) { Ok(Some(t)) } else { Ok(None) };
    let (mut real, mut misses) = (0u32, 0u32);
    let mut last = None;
    for elapsed in std::iter::repeat_n(3u32, 15).chain(std::iter::repeat_n(7, 6)) {
        for _ in 0..elapsed {
            real += 1;
            punctual.tick(sample(real));
        }
        let e = late.tick_after(sample(real), elapsed);
        misses += elapsed - 1;
        assert!(e.flags.contains(Flags::DEADLINE_MISSED), "{:?}", e.flags);
        assert_eq!((e.tick, e.deadline_misses), (real, misses));
        last = Some(e);
    }
    assert_eq!(real, 87);
    assert_eq!((late.deadline_misses(), late.lost_ticks()), (misses, 0));
    // The plunger moved (the twin relaxed), and the late twin is where the
    // punctual one is: the same ticks of the same twin, bunched.
    let (a, b) = (punctual.twin().raw_state(), late.twin().raw_state());
    assert!(
        (a[0].to_f64() - 0.5).abs() > 0.01,
        "the displaced twin did not move: {a:?}"
    );
    for i in 0..4 {
        assert!(
            (a[i].to_f64() - b[i].to_f64()).abs() <= 1e-5,
            "{}: late {b:?} vs punctual {a:?}",
            T::NAME
        );
    }
    // A tick on time again clears the flag, keeps the count.
    let e = late.tick_after(sample(real + 1), 1);
    assert!(!e.flags.contains(Flags::DEADLINE_MISSED));
    assert_eq!(e.deadline_misses, last.unwrap().deadline_misses);
}

#[test]
fn a_late_twin_follows_real_time_in_f32() {
    late_twin_follows_real_time::<f32>();
}

#[test]
fn a_late_twin_follows_real_time_in_q12_20() {
    late_twin_follows_real_time::<Fixed>();
}

#[test]
fn a_tick_later_than_the_catch_up_loses_the_rest_counted() {
    let (_, mut est) = setup::<f32>(40.0);
    let gap = MAX_CATCH_UP + 1 + 5;
    let e = est.tick_after(Ok(None), gap);
    assert_eq!(e.deadline_misses, gap - 1);
    assert_eq!(est.lost_ticks(), 5);
    // The estimate (and so its telemetry record) carries the count.
    assert_eq!(e.lost_ticks, 5);
    assert_eq!(e.tick, gap);
    assert!(e.flags.contains(Flags::DEADLINE_MISSED));
    // No elapsed time at all is taken as one tick.
    let e = est.tick_after(Ok(None), 0);
    assert_eq!((e.tick, e.deadline_misses, e.lost_ticks), (gap + 1, gap - 1, 5));
}

#[test]
fn a_record_due_inside_the_gap_goes_out_with_the_late_tick() {
    let (_, mut est) = setup::<f32>(40.0);
    let every = est.config().telemetry_every;
    assert!(every > 10, "the preset publishes every {every} ticks");
    for _ in 0..every - 2 {
        est.tick(Ok(None));
        assert!(!est.telemetry_due());
    }
    // Ticks every - 1 .. every + 1 elapse at once: the record due at
    // `every` is published now.
    est.tick_after(Ok(None), 3);
    assert!(est.telemetry_due());
}

/// A probe read on every tick: without an FPU a tick that took a reading's
/// update gives up its job, but never two in a row, so the jobs still run
/// and the fixed-point twin's oil follows a step as the `f32` one's does.
#[test]
fn readings_on_every_tick_do_not_starve_the_jobs() {
    let (_, mut float) = setup::<f32>(40.0);
    let (_, mut fixed) = setup::<Fixed>(40.0);
    for _ in 0..20_000 {
        float.tick(Ok(Some(50.0)));
        fixed.tick(Ok(Some(50.0)));
    }
    let (a, b) = (
        float.plant().oil().state.temperature,
        fixed.plant().oil().state.temperature,
    );
    assert!(a > 49.0, "the f32 twin's oil stayed at {a} C");
    assert!(
        (a - b).abs() < 0.5,
        "the Q12.20 twin's oil at {b} C, the f32 one's at {a} C"
    );
}

/// The bench's ramps across the opening (4 C/s), a reading every fifth
/// tick, in five runs of each phase (so that every event tick has a
/// reading in one of the runs, and a held reading has room to wait):
/// without an FPU a reading that
/// arrives on a tick the twin spends on an event (an impact, a release) is
/// held back and offered on the first tick without one (at most
/// `MAX_DEFERRED` ticks later), unless a newer reading came first; with
/// one, every reading is taken on its own tick.
#[test]
fn a_reading_on_an_event_tick_waits_for_a_tick_without_one_without_an_fpu() {
    /// (readings held back, of which superseded by a newer one).
    fn run<T: Real>(phase: u32) -> (u32, u32) {
        let (_, mut est) = setup::<T>(26.0);
        let (mut held, mut superseded) = (0u32, 0u32);
        // The reading held back and the ticks it has waited.
        let mut waiting: Option<(f32, u32)> = None;
        for k in 0..10_000u32 {
            let s = k as f32 * 1e-3;
            let t = 26.0 + 4.0 * if s < 5.0 { s } else { 10.0 - s };
            let sample = (k % 5 == phase).then_some(t);
            let e = est.tick(Ok(sample));
            if let Some((w, ticks)) = waiting.take() {
                if e.t_probe == w {
                    // Offered, and it was the observer's latest reading.
                } else if sample.is_some() {
                    superseded += 1;
                } else {
                    assert!(
                        ticks < MAX_DEFERRED,
                        "tick {k}: a reading held back for {} ticks",
                        ticks + 1
                    );
                    waiting = Some((w, ticks + 1));
                }
            }
            if let Some(t) = sample
                && e.t_probe != t
            {
                held += 1;
                waiting = Some((t, 1));
            }
        }
        (held, superseded)
    }
    for phase in 0..5 {
        assert_eq!(run::<f32>(phase), (0, 0), "f32 held readings back");
    }
    let runs: Vec<(u32, u32)> = (0..5).map(run::<Fixed>).collect();
    let held: u32 = runs.iter().map(|r| r.0).sum();
    let superseded: u32 = runs.iter().map(|r| r.1).sum();
    assert!(
        (1..=20).contains(&held),
        "Q12.20: {held} readings held back (the ramps have a few event ticks)"
    );
    assert!(
        superseded < held,
        "Q12.20: every held reading was superseded ({runs:?})"
    );
}
