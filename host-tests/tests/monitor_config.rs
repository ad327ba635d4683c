//! The condition monitor's settings from a device file's `[monitor]`
//! section (`MonitorSettings::from_raw`), against the same figures worked
//! out here from the file's fields: the reading's noise with the ADC's
//! quantisation `lsb^2 / 12` (one code over the sensor's span through its
//! divider or shunt), the class as `accuracy * span / sqrt(3)` (GUM 4.3.7)
//! and the period `1 / sample_hz`.

use compensator::monitor::{MonitorSettings, Quantity};
use compensator::params::RawParams;
use host_tests::repo_root;

fn preset(name: &str) -> RawParams {
    compensator_cli::load(&repo_root().join("presets").join(name)).unwrap()
}

/// `|got - want| <= rel |want|`.
fn close(got: f32, want: f64, rel: f64, what: &str) {
    assert!(
        (f64::from(got) - want).abs() <= rel * want.abs(),
        "{what}: {got} against {want}"
    );
}

/// One ADC code in the reading's unit, from the file's fields: the signal
/// band (0.5-4.5 V through the divider, or 4-20 mA through the shunt) at
/// the ADC covers `band / 3.3 V * 2^bits` codes of the span.
fn lsb(raw: &RawParams) -> f64 {
    let m = &raw.monitor;
    let volts = if m.is_current() {
        16e-3 * m.shunt
    } else {
        4.0 * m.divider
    };
    let codes = volts / 3.3 * 2f64.powf(m.adc_bits);
    (m.range_max - m.range_min) / codes
}

fn expected(raw: &RawParams) -> (f64, f64, f64) {
    let m = &raw.monitor;
    let q = lsb(raw);
    (
        (m.noise * m.noise + q * q / 12.0).sqrt(),
        m.accuracy * (m.range_max - m.range_min) / 3f64.sqrt(),
        1.0 / m.sample_hz,
    )
}

#[test]
fn paper_monitor_preset_gives_the_files_sensor() {
    let raw = preset("paper-monitor.toml");
    let s = MonitorSettings::from_raw(&raw)
        .unwrap()
        .expect("the preset has a sensor");
    assert_eq!(s.quantity, Quantity::ChamberA);
    // The preset's comment: 152 Pa a code, a standard uncertainty of 289 Pa.
    assert!((lsb(&raw) - 152.6).abs() < 0.1, "{}", lsb(&raw));
    let (noise, accuracy, period) = expected(&raw);
    close(s.sd_noise, noise, 1e-6, "sd_noise");
    close(s.sd_accuracy, accuracy, 1e-6, "sd_accuracy");
    close(s.sample_period, period, 1e-6, "sample_period");
    assert!((noise - 109.3).abs() < 0.1 && (accuracy - 288.7).abs() < 0.1);
}

#[test]
fn every_sensor_and_output_is_worked_out_from_the_file() {
    let base = preset("paper-monitor.toml");
    // (case, monitor.sensor, range, noise, current output, adc_bits, quantity)
    type Case = (&'static str, f64, (f64, f64), f64, bool, f64, Quantity);
    let cases: [Case; 4] = [
        ("p_b, 10 bits", 2.0, (0.0, 6e5), 50.0, false, 10.0, Quantity::ChamberB),
        (
            "dp_ab, 4-20 mA",
            3.0,
            (-5e5, 5e5),
            200.0,
            true,
            12.0,
            Quantity::Difference,
        ),
        (
            "x, no noise",
            4.0,
            (0.0, 1.8e-3),
            0.0,
            false,
            12.0,
            Quantity::Displacement,
        ),
        (
            "x, 8 bits, 4-20 mA",
            4.0,
            (-1e-4, 2e-3),
            1e-6,
            true,
            8.0,
            Quantity::Displacement,
        ),
    ];
    for (what, sensor, range, noise, current, bits, quantity) in cases {
        let mut raw = base;
        raw.monitor.sensor = sensor;
        raw.monitor.output = if current { 1.0 } else { 0.0 };
        (raw.monitor.range_min, raw.monitor.range_max) = range;
        raw.monitor.noise = noise;
        raw.monitor.adc_bits = bits;
        raw.monitor.sample_hz = 250.0;
        raw.monitor.accuracy = 0.0025;
        let s = MonitorSettings::from_raw(&raw)
            .unwrap_or_else(|e| panic!("{what}: {e}"))
            .unwrap();
        assert_eq!(s.quantity, quantity, "{what}");
        let (noise, accuracy, period) = expected(&raw);
        close(s.sd_noise, noise, 1e-6, what);
        close(s.sd_accuracy, accuracy, 1e-6, what);
        close(s.sample_period, period, 1e-6, what);
        // Without noise the quantisation alone remains: lsb / sqrt(12).
        if raw.monitor.noise == 0.0 {
            close(s.sd_noise, lsb(&raw) / 12f64.sqrt(), 1e-6, what);
        }
    }
}

#[test]
fn no_sensor_is_none_and_a_bad_field_is_named() {
    assert_eq!(MonitorSettings::from_raw(&preset("paper.toml")).unwrap(), None);
    let mut raw = preset("paper-monitor.toml");
    raw.monitor.sensor = 0.0;
    assert_eq!(MonitorSettings::from_raw(&raw).unwrap(), None);
    let mut raw = preset("paper-monitor.toml");
    raw.monitor.noise = 6e5;
    let e = MonitorSettings::from_raw(&raw).unwrap_err();
    assert_eq!(e.field(), "monitor.noise", "{e}");
    // A range in bar is refused by the device's rules, naming the field.
    let mut raw = preset("paper-monitor.toml");
    raw.monitor.range_max = 5.0;
    let e = MonitorSettings::from_raw(&raw).unwrap_err();
    assert!(e.field().starts_with("monitor.range"), "{e}");
    assert!(e.to_string().contains("bar"), "{e}");
}

#[test]
fn the_settings_build_a_monitor_in_the_estimator() {
    use compensator::Params;
    use compensator::estimator::{Estimator, EstimatorConfig};
    let raw = preset("paper-monitor.toml");
    let s = MonitorSettings::from_raw(&raw).unwrap().unwrap();
    let est = Estimator::new(
        &Params::<f32>::new(&raw).unwrap(),
        EstimatorConfig::new(&raw).unwrap(),
        40.0,
    )
    .unwrap()
    .with_monitor(s)
    .unwrap();
    assert_eq!(est.monitor().map(|m| *m.settings()), Some(s));
}
