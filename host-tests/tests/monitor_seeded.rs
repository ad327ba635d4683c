//! The condition monitor on seeded designs with their own slow probes
//! (`host_tests::campaign::design`, the campaign's healthy baseline): an
//! hour and a half of ordinary operation (a warm-up, holds, ramps that end
//! in a knee) raises no alarm on the designs where a knee once did. At a
//! ramp's end the observer's oil temperature overshoots the true one by a
//! few tenths of a kelvin for a few seconds; a twin's-error state held
//! correlated through a play of the twin's travel as wide as that (0.25 K,
//! and still at 0.02 K on the pressure difference) took the twin's
//! transient there for a device change (`monitor_campaign -- 10 1 1.5
//! p_a`: 29 alarms in 16.5 h on two of eleven designs).

use host_tests::campaign::{Fault, Injection, Quantity, Scenario, catalogue_before_move, design};
use host_tests::monitor_campaign::run;

/// The campaign's healthy run of design `n` of seed 1 (the seeded design
/// `1000 + n - 1`, its history from seed `1 + n`), `hours` long.
fn healthy(n: u64, q: Quantity, hours: f64) -> Scenario {
    Scenario::ordinary(&design(1000 + n - 1), q, Injection::HEALTHY, hours * 3600.0, 1 + n)
}

#[test]
fn seeded_designs_raise_nothing_through_their_ramps_knees() {
    for n in [4, 8] {
        for q in [Quantity::PA, Quantity::DPAB] {
            let s = healthy(n, q, 1.5);
            let out = run(&s).unwrap();
            assert_eq!(
                out.false_alarms,
                0,
                "design {n}, {}: first alarm at {:?} s",
                q.name(),
                out.false_alarm
            );
            assert!(out.healthy_time >= 5400.0, "design {n}: {} s", out.healthy_time);
        }
    }
}

/// Design 4's simulated day with the displacement sensor, through its
/// first two hours: as built, its plunger reaches the upper stop at a
/// lower oil temperature than the file's (at 73.6 C, 7,226 s into the
/// day), where the filter had learned an offset of +4.8e-5 m (1.1 % of
/// the stroke) that is the device's, not the sensor's zero. Less that
/// offset, the reading at the stop looked 4.8e-5 m short of it, so it
/// went on informing the probe's prediction while the plunger rested,
/// and the CUSUM fired. The stop is now taken to read anywhere between
/// the reading as read and the reading less the offset.
#[test]
fn a_plunger_at_its_stop_as_built_raises_nothing() {
    use compensator::estimator::Flags;
    use host_tests::monitor_campaign::{ALARMS, Replay};
    let s = healthy(4, Quantity::X, 24.0);
    let mut replay = Replay::new(&s).unwrap();
    let mut at_stop = 0u32;
    while let Some((r, e)) = replay.next_fed().filter(|(r, _)| r.t < 7_400.0) {
        let alarm = Flags(e.flags.0 & ALARMS.0);
        assert!(alarm.is_empty(), "{alarm:?} at {} s, oil {:.2} C", r.t, r.t_true);
        if r.truth.x >= s.device.stroke - 1e-9 {
            at_stop += 1;
        }
    }
    // The history does take the plunger to its stop.
    assert!(at_stop > 100, "{at_stop} records at the upper stop");
}

/// The campaign's run of `fault` on seeded design `n` of seed 1 (`cargo
/// run --release -p host-tests --example monitor_campaign -- 10 1 1.5`):
/// its catalogue's scenario, the onset shortly before the history's first
/// 5 C move.
fn campaign_run(n: u64, q: Quantity, fault: Fault) -> Scenario {
    let lead = ((7 + n) % 21) as f64;
    let runs = catalogue_before_move(&design(1000 + n - 1), q, 1.5 * 3600.0, 1 + n, lead);
    let i = Fault::CATALOGUE.iter().position(|f| *f == fault).unwrap();
    runs[i].clone()
}

/// On designs 4 and 8 the divider's signature and an offset's hardly
/// differ over the first 5 C; during the move the twin's transient, a
/// bias of the probe's prediction the lag passes whole, makes the fits'
/// gap in either direction (an orifice clogged to 0.9 was named a
/// transducer's offset 20-24 s after its onset, 3-4 K into its move, a
/// transducer's offset of 0.002 or 0.005 of its span a divider change).
/// The isolation's margin counts that bias's energy: these are named
/// right, after the move (the orifice in 80 s at most). Design 8's
/// clogged orifice is still named an offset (`docs/monitoring.md`).
#[test]
fn a_clogged_orifice_and_an_offset_are_told_apart_after_the_move() {
    use compensator::estimator::Flags;
    for (n, fault, flag) in [
        (4, Fault::OrificeClogged(0.9), Flags::ORIFICE_CLOGGED),
        (4, Fault::SensorOffset(0.002), Flags::SENSOR_OFFSET),
        (4, Fault::SensorOffset(0.005), Flags::SENSOR_OFFSET),
        (8, Fault::SensorOffset(0.002), Flags::SENSOR_OFFSET),
        (8, Fault::SensorOffset(0.005), Flags::SENSOR_OFFSET),
    ] {
        let out = run(&campaign_run(n, Quantity::PA, fault)).unwrap();
        assert_eq!(out.false_alarm, None, "design {n}, {fault}");
        let (after, named) = out
            .named
            .unwrap_or_else(|| panic!("design {n}, {fault}: nothing named"));
        assert_eq!(
            named, flag,
            "design {n}, {fault}: named {named:?} {after:.1} s after the onset"
        );
        if flag == Flags::ORIFICE_CLOGGED {
            assert!(after < 80.0, "design {n}, {fault}: named {after:.1} s after the onset");
        }
    }
}

/// Design 5 of the campaign (`monitor_campaign -- 10 1 1.5 x`), its
/// plunger held by a friction of 0.1 of the mid-stroke spring force from
/// the onset, 0.35 mm above its lower stop in a 0.016 C/s cooling. The
/// held plunger's innovation grows with the oil's travel from zero, under
/// the CUSUM's drift: the filter learned it, along what one temperature
/// cannot tell apart (the divider, the probe's error and the offset), into
/// an offset of 3.3e-4 m within 20 s, 70 times the sensor's class. The
/// stop rule took that offset for the sensor's zero, the held reading then
/// sat at the lower stop, and the tests never resumed: sticking was not
/// detected at any friction. The sensor's zero is now bounded by its
/// class. Named 64 s after the onset, 20 s after the plunger is held back
/// by half its band: the filter still learns the first of it.
#[test]
fn a_plunger_held_near_its_stop_in_a_slow_cooling_is_named_sticking() {
    use compensator::estimator::Flags;
    let s = campaign_run(5, Quantity::X, Fault::Sticking(0.1));
    let out = run(&s).unwrap();
    assert_eq!(out.false_alarms, 0, "false alarm at {:?} s", out.false_alarm);
    let held = out.held.expect("the plunger is held back by half its band");
    assert!(held > 30.0, "held {held:.1} s after the onset");
    let (named, flags) = out.named.expect("a fault named");
    assert_eq!(
        flags,
        Flags::PLUNGER_STICKING,
        "named {flags:?} {named:.1} s after the onset"
    );
    assert!(
        named <= held + 30.0,
        "named {named:.1} s after the onset, held at {held:.1} s"
    );
}

/// A plunger held by a friction of 0.1 of the mid-stroke spring force
/// (`monitor_campaign -- 10 1 1.5 x`), in a ramp on designs 2, 5 and 9:
/// the displacement reading stands still while the twin's plunger and the
/// probe move. Through the probe's lag alone the held plunger was named a
/// clogged orifice 618 s after the onset (design 2), sticking 20 s after
/// being held back by half its band (design 5) and a relaxed spring 307 s
/// after (design 9): the filter learned its first readings as an offset
/// before the CUSUM ran. The stillness test reads the displacement itself
/// and names each sticking within 10 s of being held.
#[test]
fn a_plunger_held_in_a_ramp_is_named_sticking_within_10_s_of_being_held() {
    use compensator::estimator::Flags;
    for n in [2, 5, 9] {
        let out = run(&campaign_run(n, Quantity::X, Fault::Sticking(0.1))).unwrap();
        assert_eq!(
            out.false_alarms, 0,
            "design {n}: false alarm at {:?} s",
            out.false_alarm
        );
        let held = out.held.expect("the plunger is held back by half its band");
        let (named, flags) = out.named.unwrap_or_else(|| panic!("design {n}: nothing named"));
        assert_eq!(
            flags,
            Flags::PLUNGER_STICKING,
            "design {n}: named {flags:?} {named:.1} s after the onset"
        );
        assert!(
            named <= held + 10.0,
            "design {n}: named {named:.1} s after the onset, held at {held:.1} s"
        );
    }
}

/// Design 3's history ends a 0.9 C/s warming at 74.5 C, 679 s in: the
/// plunger stops with the oil, while the observer's oil overshoots by 0.9
/// K and the probe, 6 K behind, catches up. Either alone moves the free
/// plunger past the still reading by more than the design band's half
/// width: a stillness test on the twin's travel alone named sticking
/// there on the healthy device. The probe's travel counts only past what
/// it still had to catch up at the reading's last move: nothing is
/// raised.
#[test]
fn a_ramp_s_end_is_no_held_plunger() {
    use compensator::estimator::Flags;
    use host_tests::monitor_campaign::{ALARMS, Replay};
    let s = healthy(3, Quantity::X, 0.25);
    let mut replay = Replay::new(&s).unwrap();
    let (mut before, mut after) = (f64::NAN, f64::NAN);
    while let Some((r, e)) = replay.next_fed().filter(|(r, _)| r.t < 700.0) {
        let alarm = Flags(e.flags.0 & ALARMS.0);
        assert!(alarm.is_empty(), "{alarm:?} at {} s, oil {:.2} C", r.t, r.t_true);
        if r.t <= 670.0 {
            before = r.t_true;
        }
        after = r.t_true;
    }
    // The history's ramp: about 8 K in the 30 s before its end at 679 s.
    assert!(
        after - before > 7.0,
        "oil {before:.2} C at 670 s, {after:.2} C at 700 s"
    );
}

/// Design 9's simulated day with the displacement sensor, through the
/// step of its oil by 0.8 K in 2 s at 15,222 s: the reading stops with
/// the oil while the probe and the observer's oil are both still short
/// of it (the observer's estimate of what the probe had left to catch up,
/// 0.19 K, fell 0.4 K short), and both then travel 0.55 K past the still
/// reading. A stillness test naming at half the design band's half width
/// (0.33 K of this design's oil) named sticking 15 s after the step; at
/// the whole half width (the design friction's) nothing is raised.
#[test]
fn a_step_s_end_is_no_held_plunger() {
    use compensator::estimator::Flags;
    use host_tests::monitor_campaign::{ALARMS, Replay};
    let s = healthy(9, Quantity::X, 24.0);
    let mut replay = Replay::new(&s).unwrap();
    let (mut last, mut low, mut high) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
    while let Some((r, e)) = replay.next_fed().filter(|(r, _)| r.t < 15_300.0) {
        let alarm = Flags(e.flags.0 & ALARMS.0);
        assert!(alarm.is_empty(), "{alarm:?} at {} s, oil {:.2} C", r.t, r.t_true);
        last = r.t;
        if (15_200.0..=15_215.0).contains(&r.t) {
            low = low.min(r.t_true);
        }
        if (15_225.0..=15_230.0).contains(&r.t) {
            high = high.max(r.t_true);
        }
    }
    assert!(last > 15_290.0, "the day ran to {last} s");
    // The history's step: 0.8 K between 15,215 and 15,225 s.
    assert!(high - low > 0.7, "oil {low:.2} C before the step, {high:.2} C after");
}

/// Once the stillness test names sticking, the monitor's plunger is held
/// where the reading stands: design 2's held plunger (friction 0.1), whose
/// free plunger has then travelled the design band's half width past it
/// (the free prediction 4.9e-5 m off), is predicted within a fifth of
/// that over the next 5 s. Released to the free plunger at the naming,
/// the prediction stood the whole travel off the reading; held at the
/// band's edge behind the free one, the as-built offset between the twin
/// and the device left it 2.8e-5 m off.
#[test]
fn a_plunger_named_sticking_is_predicted_where_it_is_held() {
    use compensator::estimator::Flags;
    use host_tests::monitor_campaign::Replay;
    let s = campaign_run(2, Quantity::X, Fault::Sticking(0.1));
    let mut replay = Replay::new(&s).unwrap();
    let mut named_at = None;
    let mut before = f64::NAN;
    let mut after = 0.0f64;
    while let Some((r, e)) = replay.next_fed() {
        let error = (f64::from(replay.estimator.health().predicted) - r.truth.x).abs();
        match named_at {
            None if e.flags.contains(Flags::PLUNGER_STICKING) => named_at = Some(r.t),
            None if r.second.is_some() => before = error,
            Some(t) if r.t > t + 5.0 => break,
            Some(_) if r.second.is_some() => after = after.max(error),
            _ => {}
        }
    }
    let t = named_at.expect("sticking named");
    assert!(t > s.injection.onset, "named at {t} s, before the onset");
    assert!(
        before > 3e-5,
        "the free prediction stood {before:.2e} m off the reading"
    );
    assert!(
        after < 0.2 * before,
        "predicted up to {after:.2e} m off the held plunger after the naming ({before:.2e} m before)"
    );
}
