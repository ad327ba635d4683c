//! The firmware build script's generator (`compensator-codegen`), called
//! here as `build.rs` calls it: the constants of every design of the
//! survey, and the QEMU replay's checkpoints against the independent
//! reference.

use compensator_codegen::replay;
use compensator_codegen::{params_rs, twin_configuration};
use host_tests::{repo_root, survey};

#[test]
fn the_constants_of_every_survey_design_name_the_chosen_twin() {
    for raw in survey::designs(12, 7) {
        let choice = twin_configuration(&raw).unwrap();
        let g = params_rs(&raw, "design.toml", "design.toml").unwrap();
        assert!(
            g.code
                .contains(&format!("TWIN_SCHEME: &str = {:?};", choice.config.scheme.name()))
        );
        assert!(
            g.code
                .contains(&format!("TWIN_SUBSTEPS: u8 = {};", choice.config.substeps))
        );
        assert!(g.code.contains(&format!("stroke: {:?}", raw.core.stroke)));
        assert_eq!(g.warnings.is_empty(), choice.goal_met);
    }
}

#[test]
fn the_replays_checkpoints_are_the_reference_at_the_oils_temperature() {
    let raw = compensator_params::file::load(&repo_root().join("presets/paper.toml")).unwrap();
    let r = replay::adapt(&raw);
    let code = r.rust(&raw);
    let checkpoints = r.checkpoints();
    let holds = r.schedule.pieces.iter().filter(|p| p.2 == p.3).count();
    assert!(checkpoints.len() > holds + 5, "{} checkpoints", checkpoints.len());
    assert!(code.contains(&format!(
        "CHECKPOINTS: [(f32, f32, f32, f32, f32, Option<bool>); {}]",
        checkpoints.len()
    )));
    // The first hold's end, 26 C: the window closed, p_a the reference's.
    let cold = compensator_reference::statics::equilibrium(&raw.core, 26.0);
    let first = code.lines().find(|l| l.trim_start().starts_with("(23.999")).unwrap();
    assert!(first.contains(&format!("{:?}", cold.p_a as f32)), "{first}");
    // 26 C is the validated range's lower bound: half a code either side
    // straddles it, so the flag is not checked there; inside the range a
    // hold's end must not raise OUT_OF_RANGE, beyond it it must.
    assert!(first.ends_with("None),"), "{first}");
    assert!(code.lines().any(|l| l.trim_end().ends_with("Some(false)),")));
    assert!(code.lines().any(|l| l.trim_end().ends_with("Some(true)),")));
    // Along the warm-up: the reference at the oil's temperature then.
    let (t, oil) = checkpoints.iter().find(|c| c.0 > 60.0 && c.0 < 100.0).copied().unwrap();
    assert_eq!(oil, 26.0 + 0.5 * (t - 24.0));
    let e = compensator_reference::statics::equilibrium(&raw.core, oil);
    assert!(code.contains(&format!("{:?}", e.x as f32)));
    assert!(code.contains("const OUT_OF_RANGE_REACHABLE: bool = true;"));
    assert!(replay::expectations(&raw.core).contains("pub const EXPECTED: [(f32, f64, f64, f64, f64, f64, f64); 8]"));
}

#[test]
fn the_monitors_replay_reads_the_reference_device_healthy_then_restricted() {
    let raw = compensator_params::file::load(&repo_root().join("presets/paper-monitor.toml")).unwrap();
    let r = replay::adapt(&raw);
    let m = r.schedule.monitor.as_ref().expect("a second sensor's track");
    // The template's levels, then the tail's holds at 40 and 50 C.
    let holds: Vec<_> = r.schedule.pieces.iter().filter(|p| p.2 == p.3).collect();
    assert_eq!(holds.len(), 9 + replay::MONITOR_TAIL.len());
    let tail = holds[9];
    assert_eq!(tail.2, 40.0);
    assert_eq!(m.restricted_from, 0.5 * (tail.0 + tail.1));
    let open = holds[replay::OPEN_LOOP_HOLD];
    assert_eq!(open.2, 60.0);
    assert_eq!(m.open_loop, (0.5 * (open.0 + open.1), 0.5 * (open.0 + open.1) + 1.0));
    // The truth table spans the replay's temperatures and interpolates the
    // reference's p_a within 5 % of the sensor's 100 Pa of noise, healthy
    // and with the capillary's bore at 0.8^(1/4) (its conductance x 0.8),
    // at temperatures between its rows.
    let truth = &m.truth;
    assert_eq!((truth[0].0, truth[truth.len() - 1].0), (10.0, 90.0));
    let mut restricted = raw.core;
    restricted.laminar_diameter *= 0.8f64.powf(0.25);
    let table: Vec<(f32, f32, f32)> = truth.iter().map(|&(t, a, b)| (t as f32, a as f32, b as f32)).collect();
    let mut rng = host_tests::random::Rng::new(5);
    for _ in 0..200 {
        let t = 10.0 + 80.0 * rng.unit();
        let (a, b) = compensator_testbench::monitor::truth_at(&table, t as f32);
        let healthy = compensator_reference::statics::equilibrium(&raw.core, t).p_a;
        let restricted = compensator_reference::statics::equilibrium(&restricted, t).p_a;
        assert!(
            (f64::from(a) - healthy).abs() < 5.0 + 1e-6 * healthy,
            "{t} C: {a} against {healthy}"
        );
        assert!(
            (f64::from(b) - restricted).abs() < 5.0 + 1e-6 * restricted,
            "{t} C: {b} against {restricted}"
        );
        // The restriction raises A by 1/0.8, and p_a = p_p - q^2 dp with
        // q = 2 / (a + sqrt(a^2 + 4)) falling in a: p_a rises.
        assert!(restricted > healthy, "{t} C");
    }
    // The twin's constants and the replica's text carry the same track.
    let code = r.rust(&raw);
    assert!(code.contains(&format!("const MONITOR_TRUTH: [(f32, f32, f32); {}]", truth.len())));
    assert!(code.contains(&format!(
        "const MONITOR_RESTRICTED_FROM: f32 = {:?};",
        m.restricted_from
    )));
    let back = replay::Schedule::<f64>::parse(&r.schedule.text()).unwrap();
    assert_eq!(back, r.schedule);
    // A file without the sensor: no track, the template alone.
    let plain = compensator_params::file::load(&repo_root().join("presets/paper.toml")).unwrap();
    let p = replay::adapt(&plain);
    assert!(p.schedule.monitor.is_none());
    assert!(!p.rust(&plain).contains("MONITOR"));
    assert!(!p.schedule.text().contains("monitor"));
}
