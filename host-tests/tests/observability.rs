//! What a second sensor can and cannot see of the device's faults at
//! steady state (`docs/monitoring.md`), on the two presets over their
//! validated range, from the independent reference equilibrium.

use host_tests::observability::{FAULTS, Finding, SENSORS, analyse};
use host_tests::repo_root;

const CAPILLARY: usize = 0;
const ORIFICE: usize = 1;
const OIL: usize = 2;
const SPRING: usize = 3;
const WINDOW: usize = 5;
const P_A: usize = 0;
const X: usize = 3;

fn findings(preset: &str, sensor: usize) -> Vec<Finding> {
    let raw = compensator_cli::load(&repo_root().join(preset)).unwrap();
    analyse(
        &raw.core,
        raw.estimator.valid_min,
        raw.estimator.valid_max,
        &SENSORS[sensor],
    )
}

#[test]
fn a_pressure_sensor_sees_the_hydraulics_and_not_the_plunger() {
    for preset in ["presets/paper.toml", "presets/model-example.toml"] {
        let f = findings(preset, P_A);
        for fault in [CAPILLARY, ORIFICE, OIL] {
            assert!(f[fault].0 > 20.0, "{preset}: {}: snr {}", FAULTS[fault].0, f[fault].0);
        }
        // The chamber pressures do not depend on where the plunger sits.
        for fault in [SPRING, 4, WINDOW] {
            assert!(f[fault].0 < 1e-6, "{preset}: {}: snr {}", FAULTS[fault].0, f[fault].0);
        }
        // A restricted capillary and a worn orifice look alike at every
        // temperature; a thicker oil does not look like either.
        let (_, twin, cos, perp) = f[CAPILLARY];
        assert_eq!(twin, ORIFICE, "{preset}");
        assert!(cos > 0.999 && perp < 3.0, "{preset}: |cos| {cos}, snr_perp {perp}");
        assert!(f[OIL].3 > 10.0, "{preset}: thicker oil: snr_perp {}", f[OIL].3);
    }
}

#[test]
fn a_displacement_sensor_separates_the_throttles_and_sees_the_spring() {
    for preset in ["presets/paper.toml", "presets/model-example.toml"] {
        let f = findings(preset, X);
        assert!(f[CAPILLARY].3 > 5.0, "{preset}: capillary: snr_perp {}", f[CAPILLARY].3);
        assert!(
            f[SPRING].0 > 20.0 && f[SPRING].3 > 5.0,
            "{preset}: spring: {:?}",
            f[SPRING]
        );
        // The window's erosion changes only the total flow.
        assert!(f[WINDOW].0 < 1e-6, "{preset}: window: snr {}", f[WINDOW].0);
    }
}
