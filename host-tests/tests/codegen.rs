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
