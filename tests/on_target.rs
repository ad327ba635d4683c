//! The core's `f32` results on the emulated Cortex-M4F (real FPU model),
//! checked against expectations computed on the host in `f64` by the
//! independent reference (written by `build.rs` into `expectations.rs`).
//!
//! Run by `cargo xtask test` (defmt-test harness, xtask as cargo runner).
#![no_std]
#![no_main]

use cortex_m as _; // critical-section implementation
use cortex_m_rt as _; // vector table; defmt-test generates `main`

include!(concat!(env!("OUT_DIR"), "/params.rs"));
include!(concat!(env!("OUT_DIR"), "/expectations.rs"));

compensator_firmware::qemu_hard_fault_handler!();

/// `|actual - expected| <= atol + rtol |expected|`, in f64.
fn close(actual: f32, expected: f64, rtol: f64, atol: f64) -> bool {
    let a = actual as f64;
    let d = if a > expected { a - expected } else { expected - a };
    let e = if expected < 0.0 { -expected } else { expected };
    d <= atol + rtol * e
}

#[defmt_test::tests]
mod tests {
    use super::{EXPECTED, OBSERVER, RAW_PARAMS, TWIN_SCHEME, TWIN_SUBSTEPS, UNCERTAINTY, close};
    use compensator::dynamics::fsi::DynamicState;
    use compensator::dynamics::linear::{hurwitz_stable, linearise};
    use compensator::dynamics::{Twin, TwinConfig};
    use compensator::equilibrium::equilibrium;
    use compensator::estimator::{Estimator, EstimatorConfig, Flags};
    use compensator::sensor::max31865::{Max31865, Settings};
    use compensator::sensor::simulated::SimulatedMax31865;
    use compensator::sensor::{SensorFault, TemperatureSource, rtd};
    use compensator::{Params, Real};
    use defmt::assert;

    #[init]
    fn init() -> Params<f32> {
        match Params::new(&RAW_PARAMS) {
            Ok(p) => p,
            Err(e) => defmt::panic!("parameters rejected: {=str}", e.field),
        }
    }

    #[test]
    fn fpu_square_root_is_correctly_rounded() {
        let mut x = 1.0e-6f32;
        while x < 1.0e6 {
            let hw = Real::sqrt(core::hint::black_box(x));
            assert!(hw == libm::sqrt(x as f64) as f32, "sqrt({=f32}) = {=f32}", x, hw);
            x *= 1.37;
        }
    }

    #[test]
    fn oil_properties_match_the_host_reference(p: &mut Params<f32>) {
        for &(t, nu, rho, ..) in EXPECTED.iter() {
            let s = p.oil.state(t).unwrap();
            assert!(
                close(s.kinematic_viscosity, nu, 2e-6, 0.0),
                "nu at {=f32}: {=f32} vs {=f64}",
                t,
                s.kinematic_viscosity,
                nu
            );
            assert!(close(s.density, rho, 1e-6, 0.0), "rho at {=f32}", t);
        }
    }

    #[test]
    fn equilibrium_matches_the_host_reference(p: &mut Params<f32>) {
        let stroke = p.plunger.stroke as f64;
        let dp = p.pressure_drop as f64;
        for &(t, _, _, pa, pb, x, q0) in EXPECTED.iter() {
            let e = equilibrium(p, t).unwrap();
            assert!(
                close(e.x, x, 0.0, 1e-5 * stroke),
                "x at {=f32}: {=f32} vs {=f64}",
                t,
                e.x,
                x
            );
            assert!(close(e.p_a, pa, 0.0, 1e-5 * dp), "p_a at {=f32}", t);
            assert!(close(e.p_b, pb, 0.0, 1e-5 * dp), "p_b at {=f32}", t);
            assert!(close(e.q_total, q0, 1e-5, 0.0), "Q0 at {=f32}", t);
        }
    }

    #[test]
    fn twin_settles_on_the_reference_equilibrium(p: &mut Params<f32>) {
        let stroke = p.plunger.stroke as f64;
        for &(t, _, _, _, _, x, _) in EXPECTED.iter().filter(|e| e.0 >= 40.0) {
            let mut twin = Twin::<f32, f32>::new(p, TwinConfig::SHIPPED, 30.0).unwrap();
            twin.set_temperature(t).unwrap();
            for _ in 0..500 {
                twin.tick().unwrap();
            }
            let s = twin.state();
            assert!(
                close(s.x, x, 0.0, 1e-6 * stroke),
                "twin x at {=f32}: {=f32} vs {=f64}",
                t,
                s.x,
                x
            );
        }
    }

    #[test]
    fn linearisation_is_stable_and_agrees_with_hurwitz(p: &mut Params<f32>) {
        for t in [30.0f32, 45.0, 60.0, 80.0] {
            let l = linearise(p, t).unwrap();
            assert!(l.stable, "unstable at {=f32}", t);
            assert!(l.dominant.re < 0.0);
            let model = compensator::dynamics::Model::new(p).unwrap();
            let jac = compensator::dynamics::linear::jacobian_at_equilibrium(&model, t).unwrap();
            assert!(hurwitz_stable(&jac) == l.stable);
        }
    }

    #[test]
    fn a_forced_wrong_state_is_reseated_on_the_reference(p: &mut Params<f32>) {
        // Steady at each expectation's temperature for the settling window,
        // then the twin forced to the far stop with its pressures swapped:
        // the next round of jobs puts it back on the host's equilibrium.
        let (stroke, dp) = (p.plunger.stroke as f64, p.pressure_drop as f64);
        let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY).unwrap();
        compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS).unwrap();
        for &(t, _, _, pa, pb, x, _) in EXPECTED.iter().filter(|e| e.0 == 30.0 || e.0 == 60.0) {
            let mut est = Estimator::new(p, config, t).unwrap();
            let window = est.settle_ticks();
            assert!(window < 20_000, "settling window {=u32} ticks at {=f32}", window, t);
            for k in 0..window + 100 {
                est.tick(if k % 20 == 0 { Ok(Some(t)) } else { Ok(None) });
            }
            let far = if x > 0.5 * stroke { 0.0 } else { p.plunger.stroke };
            est.twin_mut().set_state(&DynamicState {
                x: far,
                v: 0.0,
                p_a: pb as f32,
                p_b: pa as f32,
            });
            let mut e = est.tick(Ok(None));
            for _ in 0..4 {
                if e.reseats > 0 {
                    break;
                }
                e = est.tick(Ok(None));
            }
            assert!(e.reseats == 1, "not re-seated at {=f32}", t);
            assert!(e.flags.contains(Flags::TWIN_RESEATED));
            assert!(
                close(e.x, x, 0.0, 1e-3 * stroke),
                "x at {=f32}: {=f32} vs {=f64}",
                t,
                e.x,
                x
            );
            assert!(close(e.p_a, pa, 0.0, 1e-3 * dp), "p_a at {=f32}", t);
            assert!(close(e.p_b, pb, 0.0, 1e-3 * dp), "p_b at {=f32}", t);
        }
    }

    #[test]
    fn rtd_conversion_round_trips() {
        let mut t = -50.0f32;
        while t <= 200.0 {
            let back = rtd::temperature(100.0, rtd::resistance(100.0, t)).unwrap();
            assert!((back - t).abs() < 2e-3, "{=f32} -> {=f32}", t, back);
            t += 2.5;
        }
    }

    #[test]
    fn ntc_conversion_round_trips_through_the_adc_registers() {
        // The beta curve's f32 logf/expf on the M4F, through the simulated
        // STM32F4 ADC's registers and the real driver: within half a code
        // of the temperature (the widest, 0.26 C a code, at 120 C for the
        // 10 kohm NTC and resistor).
        use compensator::sensor::ntc::{self, Ntc, RegisterAdc};
        use compensator::sensor::simulated::SimulatedStm32Adc;
        let s = ntc::Settings::NTC10K;
        let mut sensor = Ntc::new(RegisterAdc::new(SimulatedStm32Adc::new(s, 25.0), s.bits), s);
        let mut t = -30.0f32;
        while t <= 120.0 {
            sensor.device_mut().registers_mut().temperature = t;
            let back = sensor.read().unwrap().unwrap();
            assert!((back - t).abs() < 0.2, "{=f32} -> {=f32}", t, back);
            t += 2.5;
        }
        sensor.device_mut().registers_mut().open = true;
        assert!(matches!(sensor.read(), Err(SensorFault::OpenCircuit(_))));
    }

    #[test]
    fn sensor_faults_become_flags_not_numbers(p: &mut Params<f32>) {
        let settings = Settings::PT100_430;
        let mut sensor = Max31865::new(SimulatedMax31865::new(settings, 45.0), settings);
        sensor.configure().unwrap();
        // The start-up fault-detection cycle, then the first conversion.
        let mut first = None;
        for _ in 0..8 {
            if let Some(t) = sensor.read().unwrap() {
                first = Some(t);
                break;
            }
        }
        let t = first.unwrap();
        assert!((t - 45.0).abs() < 0.05, "read {=f32}", t);
        sensor.device_mut().bus_error = true;
        assert!(sensor.read() == Err(SensorFault::Bus));
        let mut config = EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY).unwrap();
        compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS).unwrap();
        let mut est = Estimator::new(p, config, 45.0).unwrap();
        for sample in [
            Err(SensorFault::Bus),
            Ok(Some(f32::NAN)),
            Ok(Some(1.0e9)),
            Ok(Some(f32::NEG_INFINITY)),
        ] {
            let e = est.tick(sample);
            assert!(e.flags.contains(Flags::SENSOR_FAULT));
            assert!(e.x.is_finite() && e.p_a.is_finite() && e.q_total.is_finite());
        }
    }
}
