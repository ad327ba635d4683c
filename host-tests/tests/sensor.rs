//! The sensors. The MAX31865 driver against the datasheet's register map (mock SPI
//! transactions): configuration, conversion, the fault-detection cycle at
//! start-up and on its schedule, fault decoding (a status no chip can
//! answer is a bus fault), bus errors, and the simulated converter the QEMU
//! twin reads. The NTC on the STM32F4's ADC against independent f64
//! references of the beta and Steinhart-Hart equations and of the divider,
//! a round trip through the simulated ADC's registers, the fault codes, the
//! oversampling, and the parameter file's choice of the sensor.

use compensator::params::RawEstimator;
use compensator::sensor::max31865::{
    DIAGNOSIS_INTERVAL, Mains, Max31865, Phase, Settings, Wires, classify, code_of, config, fault, is_chip_answer,
};
use compensator::sensor::rtd::Cvd;
use compensator::sensor::simulated::SimulatedMax31865;
use compensator::sensor::{Detail, SensorFault, TemperatureSource, rtd};
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::spi::{Mock, Transaction as T};

/// The MAX31865's fault status byte as a fault's detail.
fn status(byte: u8) -> Detail {
    Detail::max31865_status(byte)
}

/// PT100, 430 ohm, 3 wires, 50 Hz, IEC 60751, fault band -60..250 C, a
/// detection cycle every 500 readings.
const SETTINGS: Settings = Settings::PT100_430;

/// The datasheet's configuration bytes for these settings (3-wire, 50 Hz):
/// bias on with the fault clear (D5, D3, D2 = 0), the automatic
/// fault-detection cycle `100X010Xb`, continuous conversion, continuous
/// conversion with the fault clear.
const CLEAR_BIAS_ON: u8 = 0x80 | 0x10 | 0x02 | 0x01;
const CYCLE_AUTO: u8 = 0x80 | 0x10 | 0x04 | 0x01;
const CONTINUOUS: u8 = 0x80 | 0x40 | 0x10 | 0x01;
const CONTINUOUS_CLEAR: u8 = CONTINUOUS | 0x02;
/// The configuration read back after a cycle: D3:D2 self-cleared.
const CYCLE_DONE: u8 = 0x80 | 0x10 | 0x01;

/// The RTD word (code << 1 | fault bit) as the two bytes of registers 1-2.
fn rtd_bytes(code: u16, fault: bool) -> Vec<u8> {
    let w = (code << 1) | u16::from(fault);
    vec![(w >> 8) as u8, w as u8]
}

/// One register read: address, then the value.
fn read_reg(addr: u8, value: u8) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write_vec(vec![addr]),
        T::read_vec(vec![value]),
        T::transaction_end(),
    ]
}

/// A configuration write.
fn write_config(value: u8) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write_vec(vec![0x80, value]),
        T::transaction_end(),
    ]
}

/// An RTD read returning `code` with the fault bit `fault`.
fn read_rtd(code: u16, fault: bool) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write_vec(vec![0x01]),
        T::read_vec(rtd_bytes(code, fault)),
        T::transaction_end(),
    ]
}

/// What `configure()` sends. Thresholds worked by hand from IEC 60751:
/// R(250 C) = 194.0981 ohm, code round(194.0981 / 430 * 2^15) = 14791,
/// word 14791 << 1 = 0x738E; R(-60 C) = 76.3278 ohm, code 5817, word
/// 0x2D72. Datasheet: write address = read address | 0x80; thresholds at
/// 0x03-0x06 (high MSB, LSB, low MSB, LSB), auto-incrementing;
/// configuration 0x00. The fault clear is written with D5, D3, D2 = 0, then
/// the cycle: "write 100X010Xb to the Configuration register".
fn configure_transactions() -> Vec<T<u8>> {
    let mut v = vec![
        T::transaction_start(),
        T::write_vec(vec![0x83, 0x73, 0x8E, 0x2D, 0x72]),
        T::transaction_end(),
    ];
    v.extend(write_config(CLEAR_BIAS_ON));
    v.extend(write_config(CYCLE_AUTO));
    v
}

/// The end of a cycle that found `status`: configuration read back, status
/// read, continuous conversion written back with the fault clear.
fn cycle_result(status: u8) -> Vec<T<u8>> {
    let mut v = read_reg(0x00, CYCLE_DONE);
    v.extend(read_reg(0x07, status));
    v.extend(write_config(CONTINUOUS_CLEAR));
    v
}

fn code_at(t: f32) -> u16 {
    code_of(&SETTINGS, rtd::resistance(100.0, t))
}

#[test]
fn configure_writes_thresholds_clears_and_starts_the_detection_cycle() {
    let expectations = configure_transactions();
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.phase(), Phase::Detecting { polls: 0 });
    spi.done();
    assert_eq!(
        (CONTINUOUS, CYCLE_AUTO),
        (
            config::V_BIAS | config::AUTO | config::THREE_WIRE | config::FILTER_50HZ,
            0b1001_0101
        )
    );
}

#[test]
fn a_passing_cycle_resumes_conversion_and_waits_for_a_fresh_reading() {
    // The RTD registers hold the pre-cycle reading until the first new
    // conversion (66 ms at most): four calls 20 ms apart return nothing
    // and touch no register, the fifth (100 ms) reads.
    assert_eq!(SETTINGS.restart_readings(), 5);
    let mut expectations = configure_transactions();
    expectations.extend(cycle_result(0));
    expectations.extend(read_rtd(code_at(45.0), false));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.read(), Ok(None), "a clean cycle");
    for _ in 0..4 {
        assert_eq!(drv.read(), Ok(None));
    }
    let t = drv.read().unwrap().unwrap();
    assert!((t - 45.0).abs() < 0.02, "{t}");
    assert_eq!(drv.phase(), Phase::Converting { until_cycle: 500 });
    spi.done();
}

#[test]
fn the_cycle_runs_again_at_its_interval_after_a_reading() {
    // Every `diagnosis_every` readings: the reading is returned, then the
    // cycle is started (conversion stops), its result read at the next call.
    let settings = Settings {
        diagnosis_every: 3,
        ..SETTINGS
    };
    let mut expectations = Vec::new();
    for t in [40.0, 41.0] {
        expectations.extend(read_rtd(code_at(t), false));
    }
    expectations.extend(read_rtd(code_at(42.0), false));
    expectations.extend(write_config(CYCLE_AUTO));
    expectations.extend(cycle_result(0));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), settings);
    for t in [40.0, 41.0, 42.0] {
        let read = drv.read().unwrap().unwrap();
        assert!((read - t).abs() < 0.02, "{read}");
    }
    assert_eq!(drv.phase(), Phase::Detecting { polls: 0 });
    assert_eq!(drv.read(), Ok(None));
    assert_eq!(drv.phase(), Phase::Restarting { stale: 5 });
    spi.done();
    // At the 10 s interval: 500 readings at 50 Hz, 600 at 60 Hz.
    let mut raw = RawEstimator::DEFAULT;
    assert_eq!(Settings::from_params(&raw).diagnosis_every, 500);
    raw.mains_hz = 60.0;
    let s60 = Settings::from_params(&raw);
    assert_eq!((s60.diagnosis_every, s60.mains), (600, Mains::Hz60));
    assert_eq!(DIAGNOSIS_INTERVAL, 10.0);
    // 66 ms over 16.7 ms periods: four, plus one.
    assert_eq!(s60.restart_readings(), 5);
}

#[test]
fn a_still_running_cycle_is_polled_then_restarted() {
    // D3:D2 still 01 when read: not done yet (nothing returned); after two
    // more polls the cycle is started again and the reading is implausible.
    let running = CYCLE_AUTO;
    let mut expectations = configure_transactions();
    for _ in 0..3 {
        expectations.extend(read_reg(0x00, running));
    }
    expectations.extend(write_config(CYCLE_AUTO));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.read(), Ok(None));
    assert_eq!(drv.read(), Ok(None));
    assert_eq!(drv.read(), Err(SensorFault::Stale));
    assert_eq!(drv.phase(), Phase::Detecting { polls: 0 });
    spi.done();
}

#[test]
fn a_wiring_fault_found_by_the_cycle_withholds_readings_until_a_cycle_passes() {
    // REFIN- < 0.85 V_BIAS with FORCE- open (D4): readings "appear valid"
    // (datasheet, Tables 10-12), so none is trusted: the fault is reported
    // for each, and a cycle is run after each fresh reading until one
    // passes.
    let mut expectations = configure_transactions();
    expectations.extend(cycle_result(fault::REFIN_LOW));
    expectations.extend(read_rtd(code_at(50.0), false));
    expectations.extend(write_config(CYCLE_AUTO));
    expectations.extend(cycle_result(0));
    expectations.extend(read_rtd(code_at(50.0), false));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.read(), Err(SensorFault::Wiring(status(fault::REFIN_LOW))));
    for _ in 0..4 {
        assert_eq!(drv.read(), Ok(None));
    }
    // A valid-looking code, withheld; the next cycle starts.
    assert_eq!(drv.read(), Err(SensorFault::Wiring(status(fault::REFIN_LOW))));
    assert_eq!(drv.phase(), Phase::Detecting { polls: 0 });
    // The fault is gone: the cycle passes, readings resume.
    assert_eq!(drv.read(), Ok(None));
    for _ in 0..4 {
        assert_eq!(drv.read(), Ok(None));
    }
    assert!((drv.read().unwrap().unwrap() - 50.0).abs() < 0.02);
    spi.done();
}

#[test]
fn a_fault_bit_reads_the_status_clears_it_and_names_the_fault() {
    let mut expectations = read_rtd(code_at(40.0), true);
    expectations.extend(read_reg(0x07, fault::RTD_HIGH));
    expectations.extend(write_config(CONTINUOUS_CLEAR));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    assert_eq!(drv.read(), Err(SensorFault::OpenCircuit(status(fault::RTD_HIGH))));
    spi.done();
}

#[test]
fn status_bits_map_to_faults_and_impossible_bytes_to_the_bus() {
    assert_eq!(
        classify(fault::RTD_HIGH),
        SensorFault::OpenCircuit(status(fault::RTD_HIGH))
    );
    assert_eq!(
        classify(fault::RTD_LOW),
        SensorFault::ShortCircuit(status(fault::RTD_LOW))
    );
    assert_eq!(
        classify(fault::REFIN_HIGH),
        SensorFault::Wiring(status(fault::REFIN_HIGH))
    );
    assert_eq!(
        classify(fault::REFIN_LOW | fault::RTD_HIGH),
        SensorFault::Wiring(status(fault::REFIN_LOW | fault::RTD_HIGH))
    );
    assert_eq!(
        classify(fault::RTDIN_LOW),
        SensorFault::Wiring(status(fault::RTDIN_LOW))
    );
    assert_eq!(classify(fault::VOLTAGE), SensorFault::Supply(status(fault::VOLTAGE)));
    assert_eq!(classify(0), SensorFault::OutOfRange(status(0)));
    // MISO stuck high: 0xFF sets the unused D1:D0 and RTD high and low at
    // once; no chip answers that.
    for status in [0xFF, 0x01, 0x02, fault::RTD_HIGH | fault::RTD_LOW] {
        assert!(!is_chip_answer(status), "{status:#04x}");
        assert_eq!(classify(status), SensorFault::Bus, "{status:#04x}");
    }
    assert!(is_chip_answer(fault::RTD_HIGH | fault::REFIN_HIGH | fault::VOLTAGE));
}

#[test]
fn miso_stuck_high_is_a_bus_fault_on_every_path() {
    // An RTD word 0xFFFF (its fault bit set) makes the driver read the
    // status: 0xFF, a bus fault, not "wiring".
    let mut expectations = vec![
        T::transaction_start(),
        T::write_vec(vec![0x01]),
        T::read_vec(vec![0xFF, 0xFF]),
        T::transaction_end(),
    ];
    expectations.extend(read_reg(0x07, 0xFF));
    expectations.extend(write_config(CONTINUOUS_CLEAR));
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    assert_eq!(drv.read(), Err(SensorFault::Bus));
    spi.done();
    // The cycle's configuration read answers 0xFF: not what was written.
    // The driver configures the chip again at the next call.
    let mut expectations = configure_transactions();
    expectations.extend(read_reg(0x00, 0xFF));
    expectations.extend(configure_transactions());
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.read(), Err(SensorFault::Bus));
    assert_eq!(drv.phase(), Phase::Idle);
    assert_eq!(drv.read(), Ok(None));
    assert_eq!(drv.phase(), Phase::Detecting { polls: 0 });
    spi.done();
}

#[test]
fn reading_converts_the_code_by_callendar_van_dusen() {
    // IEC 60751 table resistances of a PT100 (0.01 ohm, about 0.013 C) and
    // their codes round(R / 430 * 2^15), worked by hand.
    let table: [(f32, f32, u16); 7] = [
        (-40.0, 84.27, 6422),
        (0.0, 100.00, 7620),
        (25.0, 109.73, 8362),
        (50.0, 119.40, 9099),
        (80.0, 130.90, 9975),
        (100.0, 138.51, 10555),
        (150.0, 157.33, 11989),
    ];
    for (t, ohm, code) in table {
        // The driver's own code of the table resistance agrees.
        assert_eq!(code_of(&SETTINGS, ohm), code, "{ohm} ohm");
        let expectations = read_rtd(code, false);
        let mut spi = Mock::new(&expectations);
        let mut drv = Max31865::new(spi.clone(), SETTINGS);
        let read = drv.read().unwrap().unwrap();
        spi.done();
        // Table rounding (0.013 C) plus half a code (430 / 65536 ohm,
        // 0.017 C).
        assert!((read - t).abs() < 0.035, "{t} C read as {read}");
    }
}

#[test]
fn a_calibrated_probe_is_read_with_its_own_coefficients() {
    // A calibrated PT100 whose certificate gives A = 3.9122e-3,
    // B = -5.781e-7: at 100 C it reads 100 (1 + 0.39122 - 0.005781) =
    // 138.5439 ohm, code round(138.5439 / 430 * 2^15) = 10558 (by hand).
    let settings = Settings {
        cvd: Cvd {
            a: 3.9122e-3,
            b: -5.781e-7,
            c: -4.187e-12,
        },
        ..SETTINGS
    };
    assert_eq!(code_of(&settings, 138.5439), 10558);
    let expectations = read_rtd(10558, false);
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), settings);
    let read = drv.read().unwrap().unwrap();
    spi.done();
    assert!((read - 100.0).abs() < 0.02, "{read}");
    // The standard curve would have read the same code 0.1 C high.
    let standard = rtd::temperature(100.0, 10558.0 * 430.0 / 32768.0).unwrap();
    assert!((standard - read - 0.1).abs() < 0.02, "{standard} vs {read}");
}

#[test]
fn two_and_four_wire_and_60_hz_configure_their_bits() {
    // D4 clear for 2- and 4-wire, D0 clear for the 60 Hz notch.
    let mut raw = RawEstimator::DEFAULT;
    raw.rtd_wires = 4.0;
    raw.mains_hz = 60.0;
    let settings = Settings::from_params(&raw);
    assert_eq!((settings.wires, settings.mains), (Wires::TwoOrFour, Mains::Hz60));
    let drv = Max31865::new(Broken, settings);
    assert_eq!(drv.config_byte(), 0x80 | 0x40);
    raw.rtd_wires = 2.0;
    assert_eq!(Settings::from_params(&raw).wires, Wires::TwoOrFour);
    // The defaults are the usual breakout, with the oil's range as the
    // converter's fault band.
    let defaults = Settings::from_params(&RawEstimator::DEFAULT);
    assert_eq!(
        defaults,
        Settings {
            fault_band: (-20.0, 150.0),
            ..SETTINGS
        }
    );
}

#[test]
fn saturated_codes_are_out_of_range_not_temperatures() {
    for code in [0u16, 0x7FFF] {
        let expectations = read_rtd(code, false);
        let mut spi = Mock::new(&expectations);
        let mut drv = Max31865::new(spi.clone(), SETTINGS);
        assert_eq!(drv.read(), Err(SensorFault::OutOfRange(Detail::code(code))));
        spi.done();
    }
}

/// A bus that always fails.
struct Broken;
impl ErrorType for Broken {
    type Error = ErrorKind;
}
impl SpiDevice for Broken {
    fn transaction(&mut self, _: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        Err(ErrorKind::Other)
    }
}

#[test]
fn bus_errors_are_faults_not_panics() {
    let mut drv = Max31865::new(Broken, SETTINGS);
    assert!(drv.configure().is_err());
    assert_eq!(drv.read(), Err(SensorFault::Bus));
}

#[test]
fn the_simulated_converter_speaks_the_same_register_map() {
    let mut drv = Max31865::new(SimulatedMax31865::new(SETTINGS, 61.2), SETTINGS);
    drv.configure().unwrap();
    assert_eq!(drv.device_mut().detection_cycles, 1);
    assert_eq!(drv.read(), Ok(None), "the start-up cycle passes");
    assert_eq!(drv.device_mut().config(), 0xD1, "fault-clear bit self-clears");
    let first = (0..5).map(|_| drv.read()).find(|r| r != &Ok(None));
    assert!((first.unwrap().unwrap().unwrap() - 61.2).abs() < 0.02);
    drv.device_mut().fault = fault::RTD_LOW;
    assert_eq!(drv.read(), Err(SensorFault::ShortCircuit(status(fault::RTD_LOW))));
    // The cause persists: clearing the latch does not hide it.
    assert_eq!(drv.read(), Err(SensorFault::ShortCircuit(status(fault::RTD_LOW))));
    drv.device_mut().fault = 0;
    assert!(drv.read().unwrap().is_some());
    drv.device_mut().forced_code = Some(0x7FFF);
    assert_eq!(drv.read(), Err(SensorFault::OutOfRange(Detail::code(0x7FFF))));
    drv.device_mut().forced_code = None;
    drv.device_mut().bus_error = true;
    assert_eq!(drv.read(), Err(SensorFault::Bus));
    drv.device_mut().bus_error = false;
    drv.device_mut().miso_stuck_high = true;
    assert_eq!(drv.read(), Err(SensorFault::Bus));
}

#[test]
fn the_simulated_converter_shows_wiring_faults_only_to_the_detection_cycle() {
    // FORCE- open: readings stay plausible; only the cycle sees it.
    let settings = Settings {
        diagnosis_every: 10,
        ..SETTINGS
    };
    let mut drv = Max31865::new(SimulatedMax31865::new(settings, 30.0), settings);
    drv.device_mut().fault = fault::RTDIN_LOW;
    drv.configure().unwrap();
    assert_eq!(
        drv.read(),
        Err(SensorFault::Wiring(status(fault::RTDIN_LOW))),
        "the start-up cycle"
    );
    let readings: Vec<_> = (0..40).map(|_| drv.read()).collect();
    assert!(
        readings
            .iter()
            .all(|r| matches!(r, Ok(None) | Err(SensorFault::Wiring(_))))
    );
    assert!(
        readings
            .iter()
            .any(|r| r == &Err(SensorFault::Wiring(status(fault::RTDIN_LOW))))
    );
    assert!(drv.device_mut().detection_cycles > 3, "rechecked while faulted");
    // Repaired: the next cycle passes and readings come back.
    drv.device_mut().fault = 0;
    let after: Vec<_> = (0..20).map(|_| drv.read()).collect();
    assert!(
        after
            .iter()
            .any(|r| matches!(r, Ok(Some(t)) if (t - 30.0).abs() < 0.02)),
        "{after:?}"
    );
}

/// The simulated converter, counting the bytes clocked over SPI.
struct Counting {
    sim: SimulatedMax31865,
    bytes: usize,
}
impl ErrorType for Counting {
    type Error = <SimulatedMax31865 as ErrorType>::Error;
}
impl SpiDevice for Counting {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        for op in operations.iter() {
            self.bytes += match op {
                Operation::Write(b) => b.len(),
                Operation::Read(b) => b.len(),
                Operation::Transfer(r, _) => r.len(),
                Operation::TransferInPlace(b) => b.len(),
                Operation::DelayNs(_) => 0,
            };
        }
        self.sim.transaction(operations)
    }
}

#[test]
fn no_reading_call_clocks_more_than_nine_bytes() {
    // The tick budget: every read() is a few short transactions, whatever
    // the diagnosis is doing. Over a minute of readings with a wiring
    // fault, an open RTD and a repair, the worst call moves 9 bytes (an
    // RTD read with its fault path and a cycle start), 72 us at the
    // board's 1 MHz SPI clock, of a 1 ms tick.
    let settings = Settings {
        diagnosis_every: 50,
        ..SETTINGS
    };
    let dev = Counting {
        sim: SimulatedMax31865::new(settings, 40.0),
        bytes: 0,
    };
    let mut drv = Max31865::new(dev, settings);
    drv.configure().unwrap();
    let mut worst = 0;
    for k in 0..3000 {
        let sim = &mut drv.device_mut().sim;
        sim.fault = match k {
            500..800 => fault::RTDIN_LOW,
            1200..1300 => fault::RTD_HIGH,
            1500..1520 => fault::RTD_HIGH | fault::REFIN_HIGH,
            _ => 0,
        };
        drv.device_mut().bytes = 0;
        let _ = drv.read();
        worst = worst.max(drv.device_mut().bytes);
    }
    assert_eq!(worst, 9);
}

// ---------------------------------------------------------------------------
// The NTC thermistor on the STM32F4's ADC.
// ---------------------------------------------------------------------------

use compensator::sensor::ntc::{self, AdcChannel, AdcRegisters, Curve, Ntc, RegisterAdc, SimulatedStm32Adc, reg};
use compensator::sensor::simulated::{Injection, SimulatedNtc, SimulatedSource};

/// The default NTC channel: 10 kohm NTCLE100E3103 (B25/85 = 3977 K), 10
/// kohm series resistor, 12 bits, 4 conversions a reading, -40..125 C.
const NTC: ntc::Settings = ntc::Settings::NTC10K;

/// Steinhart-Hart coefficients of a 10 kohm NTC (1/K; R in ohm).
const SH: (f64, f64, f64) = (1.1292e-3, 2.3411e-4, 8.7755e-8);

/// Beta equation in f64, written again from the datasheet form: the
/// temperature [C] of an NTC of `r25` ohm at 25 C and beta `b` K reading
/// `r` ohm.
fn beta_reference(r25: f64, b: f64, r: f64) -> f64 {
    1.0 / (1.0 / 298.15 + (r / r25).ln() / b) - 273.15
}

/// Its inverse: the resistance [ohm] at `t` [C].
fn beta_resistance(r25: f64, b: f64, t: f64) -> f64 {
    r25 * (b * (1.0 / (t + 273.15) - 1.0 / 298.15)).exp()
}

/// Steinhart-Hart in f64: the temperature [C] at `r` ohm.
fn sh_reference(r: f64) -> f64 {
    let l = r.ln();
    1.0 / (SH.0 + SH.1 * l + SH.2 * l * l * l) - 273.15
}

/// Steinhart-Hart inverted by bisection on ln R (monotonic): the
/// resistance [ohm] at `t` [C].
fn sh_resistance(t: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 20.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        // Higher resistance, colder.
        if sh_reference(mid.exp()) > t {
            lo = mid
        } else {
            hi = mid
        }
    }
    (0.5 * (lo + hi)).exp()
}

/// The divider's ideal code (not rounded) at `r` ohm with `series` ohm and
/// `bits`: 2^bits R / (R + R_series).
fn code_reference(r: f64, series: f64, bits: u32) -> f64 {
    f64::from(1u32 << bits) * r / (r + series)
}

#[test]
fn the_beta_equation_matches_an_independent_f64_reference() {
    let curve = Curve::NTCLE100E3103;
    // R25 at 25 C exactly; the datasheet's B25/85 through 85 C.
    assert!((curve.temperature(10_000.0).unwrap() - 25.0).abs() < 1e-4);
    let r85 = beta_resistance(10_000.0, 3977.0, 85.0);
    assert!((r85 - 1070.0).abs() < 1.0, "{r85}");
    let mut t = -40.0;
    while t <= 125.0 {
        let r = beta_resistance(10_000.0, 3977.0, t);
        let got = f64::from(curve.temperature(r as f32).unwrap());
        assert!((got - t).abs() < 2e-3, "{t} C: {got}");
        let back = f64::from(curve.resistance(t as f32));
        assert!((back / r - 1.0).abs() < 1e-5, "{t} C: {back} ohm against {r}");
        assert!((beta_reference(10_000.0, 3977.0, r) - t).abs() < 1e-9);
        t += 2.5;
    }
    // No temperature for no resistance.
    for r in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert_eq!(curve.temperature(r), None, "{r}");
    }
}

#[test]
fn steinhart_hart_matches_an_independent_f64_reference_and_inverts() {
    let curve = Curve::SteinhartHart {
        a: SH.0 as f32,
        b: SH.1 as f32,
        c: SH.2 as f32,
    };
    let mut t = -40.0;
    while t <= 150.0 {
        let r = sh_resistance(t);
        let got = f64::from(curve.temperature(r as f32).unwrap());
        assert!((got - t).abs() < 2e-3, "{t} C: {got}");
        // Cardano's root, in f32, against the bisection.
        let back = f64::from(curve.resistance(t as f32));
        assert!((back / r - 1.0).abs() < 2e-5, "{t} C: {back} ohm against {r}");
        t += 2.5;
    }
}

#[test]
fn the_divider_reads_back_every_temperature_within_half_a_code() {
    // Through the simulated ADC's registers and the real driver, over the
    // element's range, beta and Steinhart-Hart: the reading is the
    // temperature within half a code's worth (the reference's slope) plus
    // the curve's f32 error.
    let sh = ntc::Settings {
        curve: Curve::SteinhartHart {
            a: SH.0 as f32,
            b: SH.1 as f32,
            c: SH.2 as f32,
        },
        ..NTC
    };
    for (settings, resistance) in [
        (NTC, (|t| beta_resistance(10_000.0, 3977.0, t)) as fn(f64) -> f64),
        (sh, sh_resistance as fn(f64) -> f64),
    ] {
        let mut drv: SimulatedNtc = Ntc::new(
            RegisterAdc::new(SimulatedStm32Adc::new(settings, 25.0), settings.bits),
            settings,
        );
        let mut t = -35.0f64;
        while t <= 120.0 {
            drv.set_temperature(t as f32);
            let read = f64::from(drv.read().unwrap().unwrap());
            let h = 0.01;
            let per_code = 2.0 * h
                / (code_reference(resistance(t - h), 10_000.0, 12) - code_reference(resistance(t + h), 10_000.0, 12));
            assert!(
                (read - t).abs() <= 0.5 * per_code + 2e-3,
                "{t} C read as {read} ({per_code} C a code)"
            );
            t += 0.7;
        }
        assert_eq!(
            drv.device_mut().registers_mut().conversions % 4,
            0,
            "4 conversions a reading"
        );
    }
    // Mid-range resolution of the default divider (docs/firmware.md's
    // error budget): 0.035 C a code at 52 C.
    let mut raw = RawEstimator::DEFAULT;
    raw.sensor = 1.0;
    let res = raw.resolution(52.0);
    assert!((res - 0.0348).abs() < 5e-4, "{res}");
}

#[test]
fn open_short_and_out_of_range_codes_are_faults_with_their_code() {
    let mut drv = SimulatedNtc::simulated(&RawEstimator::DEFAULT, NTC.band, 40.0);
    assert!(drv.start().is_ok());
    assert!((drv.read().unwrap().unwrap() - 40.0).abs() < 0.05);
    drv.inject(Some(Injection::Open));
    assert_eq!(drv.read(), Err(SensorFault::OpenCircuit(Detail::code(4095))));
    drv.inject(Some(Injection::Short));
    assert_eq!(drv.read(), Err(SensorFault::ShortCircuit(Detail::code(0))));
    drv.inject(Some(Injection::Saturated));
    assert_eq!(drv.read(), Err(SensorFault::OpenCircuit(Detail::code(4095))));
    drv.inject(Some(Injection::Stuck));
    assert_eq!(drv.read(), Err(SensorFault::Stale));
    drv.inject(Some(Injection::Bus));
    assert_eq!(drv.read(), Err(SensorFault::Stale));
    drv.inject(None);
    // Hotter than the element's band (-20..150 C from the defaults) but a
    // code off the short band: out of range, with its code.
    drv.set_temperature(170.0);
    let code = NTC.code_of(170.0);
    assert!(code > 8, "{code}");
    assert_eq!(drv.read(), Err(SensorFault::OutOfRange(Detail::code(code))));
    // Just inside the bands: 9 and 4086 are temperatures (if in the band)
    // or out of range, never open or short.
    let mut mock = Codes(vec![]);
    for (code, open_or_short) in [(8u16, true), (9, false), (4086, false), (4087, true)] {
        mock.0 = vec![code; 4];
        let mut drv = Ntc::new(&mut mock, NTC);
        let r = drv.read();
        assert_eq!(
            matches!(r, Err(SensorFault::OpenCircuit(_) | SensorFault::ShortCircuit(_))),
            open_or_short,
            "{code}: {r:?}"
        );
    }
}

/// An ADC that returns these codes, last first; an error when none is
/// left.
struct Codes(Vec<u16>);
impl AdcChannel for Codes {
    type Error = ();
    fn read_code(&mut self) -> Result<u16, ()> {
        self.0.pop().ok_or(())
    }
}

/// The first sample a simulated source returns (the MAX31865's start-up
/// diagnosis leaves a few reads without one).
fn first_sample<S: SimulatedSource>(s: &mut S) -> Result<f32, SensorFault> {
    for _ in 0..50 {
        if let Some(t) = s.read()? {
            return Ok(t);
        }
    }
    panic!("no sample in 50 reads");
}

#[test]
fn a_forced_code_reads_as_its_temperature_on_either_sensor() {
    use compensator::sensor::simulated::SimulatedRtd;
    let band = (-60.0, 250.0);
    // The NTC: no diagnosis cycle, the divider's code.
    let mut ntc = SimulatedNtc::simulated(&RawEstimator::DEFAULT, band, 40.0);
    assert!(ntc.start().is_ok());
    assert_eq!(ntc.restart_readings(), 0);
    assert_eq!(ntc.code_of(60.0), NTC.code_of(60.0));
    ntc.inject(Some(Injection::Code(ntc.code_of(60.0))));
    assert!((first_sample(&mut ntc).unwrap() - 60.0).abs() < 0.05);
    ntc.inject(Some(Injection::Code(0)));
    assert_eq!(ntc.read(), Err(SensorFault::ShortCircuit(Detail::code(0))));
    // The MAX31865: its stale reads after a diagnosis cycle, the RTD's code.
    let mut rtd = SimulatedRtd::simulated(&RawEstimator::DEFAULT, band, 40.0);
    assert!(rtd.start().is_ok());
    let settings = Settings::from_params(&RawEstimator::DEFAULT);
    assert_eq!(rtd.restart_readings(), settings.restart_readings());
    assert!(rtd.restart_readings() > 0);
    assert_eq!(
        rtd.code_of(60.0),
        code_of(&settings, settings.cvd.resistance(settings.r0, 60.0))
    );
    rtd.inject(Some(Injection::Code(rtd.code_of(60.0))));
    assert!((first_sample(&mut rtd).unwrap() - 60.0).abs() < 0.05);
    rtd.inject(Some(Injection::Code(0)));
    assert!(first_sample(&mut rtd).is_err());
}

#[test]
fn oversampling_averages_the_codes_and_an_adc_error_is_a_bus_fault() {
    let mut adc = Codes(vec![2003, 2002, 2001, 2000]);
    let mut drv = Ntc::new(&mut adc, NTC);
    let t = f64::from(drv.read().unwrap().unwrap());
    let r = 10_000.0 * 2001.5 / (4096.0 - 2001.5);
    assert!((t - beta_reference(10_000.0, 3977.0, r)).abs() < 2e-3, "{t}");
    // Three codes left of four: the reading fails as a whole.
    let mut adc = Codes(vec![2000, 2000, 2000]);
    let mut drv = Ntc::new(&mut adc, NTC);
    assert_eq!(drv.read(), Err(SensorFault::Bus));
}

#[test]
fn the_register_adc_starts_polls_and_reads_as_the_reference_manual_says() {
    let mut sim = SimulatedStm32Adc::new(NTC, 25.0);
    let mut adc = RegisterAdc::new(&mut sim, 10);
    // 10 bits: half scale at 25 C, R = R_series.
    assert_eq!(adc.read_code(), Ok(512));
    let regs = adc.registers_mut();
    assert_eq!(regs.read(reg::CR1), 1 << 24, "RES = 01: 10 bits");
    assert_eq!(regs.read(reg::CR2) & reg::CR2_SWSTART, 0, "SWSTART cleared by hardware");
    assert_eq!(regs.read(reg::SR) & reg::SR_EOC, 0, "reading DR cleared EOC");
    assert_eq!(regs.read(reg::SR) & reg::SR_OVR, 0, "no overrun");
    // A conversion whose code is not read, then another: overrun.
    regs.write(reg::CR2, reg::CR2_ADON | reg::CR2_SWSTART);
    regs.write(reg::CR2, reg::CR2_ADON | reg::CR2_SWSTART);
    assert_ne!(regs.read(reg::SR) & reg::SR_OVR, 0);
    // Off: SWSTART converts nothing.
    let before = sim.conversions;
    sim.write(reg::CR2, reg::CR2_SWSTART);
    assert_eq!(sim.conversions, before);
}

#[test]
fn the_parameter_file_chooses_and_checks_the_ntc() {
    use compensator::sensor::device::{SensorKind, sample_period};
    use compensator_params::file::parse;
    let base = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../presets/paper.toml")).unwrap();
    let rtd = parse(&base).unwrap();
    assert_eq!(SensorKind::of(&rtd.estimator), SensorKind::Rtd);
    let with = |extra: &str| parse(&format!("{base}\n[estimator]\n{extra}"));
    let raw = with("sensor = \"ntc\"\nntc_series = 4700.0\nadc_bits = 10\n").unwrap();
    assert_eq!(SensorKind::of(&raw.estimator), SensorKind::Ntc);
    let s = ntc::Settings::from_params(&raw.estimator);
    assert_eq!((s.series, s.bits, s.oversampling), (4700.0, 10, 4));
    assert_eq!(s.band, (-20.0, 150.0));
    assert_eq!(s.curve, Curve::NTCLE100E3103);
    assert_eq!(s.period, sample_period(&raw.estimator));
    // Steinhart-Hart when its three coefficients are given.
    let raw = with("sensor = \"ntc\"\nntc_sh_a = 1.1292e-3\nntc_sh_b = 2.3411e-4\nntc_sh_c = 8.7755e-8\n").unwrap();
    assert!(matches!(
        ntc::Settings::from_params(&raw.estimator).curve,
        Curve::SteinhartHart { .. }
    ));
    // Refused by name: one coefficient missing; a divider whose codes reach
    // the short band at oil_max (a 1 Mohm series resistor); a kind that is
    // not one.
    let e = with("sensor = \"ntc\"\nntc_sh_a = 1.1292e-3\nntc_sh_c = 8.7755e-8\n").unwrap_err();
    assert_eq!(e.field(), Some("estimator.ntc_sh_b"), "{e}");
    let e = with("sensor = \"ntc\"\nntc_series = 1e6\n").unwrap_err();
    assert_eq!(e.field(), Some("estimator.ntc_series"), "{e}");
    assert!(e.to_string().contains("saturates the ADC"), "{e}");
    // The same divider does not matter to an RTD device.
    assert!(with("ntc_series = 1e6\n").is_ok());
    let e = with("sensor = \"pt1000\"\n").unwrap_err();
    assert_eq!(e.to_string(), "estimator.sensor: expected \"rtd\" or \"ntc\"");
    let e = with("sensor = 1\n").unwrap_err();
    assert_eq!(e.field(), Some("estimator.sensor"));
}

#[test]
fn a_fault_carries_the_chips_word_and_a_reading_stays_eight_bytes() {
    use compensator::sensor::Word;
    assert_eq!(Detail::NONE.word(), Word::None);
    assert_eq!(Detail::max31865_status(0x84).word(), Word::Max31865Status(0x84));
    assert_eq!(Detail::max31865_status(0).word(), Word::Max31865Status(0));
    for code in [0u16, 1, 4095, 0x7FFF] {
        assert_eq!(Detail::code(code).word(), Word::Code(code));
    }
    assert_eq!(
        SensorFault::OpenCircuit(Detail::code(4095)).detail(),
        Detail::code(4095)
    );
    assert_eq!(SensorFault::Stale.detail(), Detail::NONE);
    assert_eq!(
        SensorFault::Wiring(Detail::max31865_status(fault::REFIN_LOW)).to_string(),
        "a force or reference line of the element is open or shorted (MAX31865 fault status 0x10)"
    );
    // The estimator's tick takes the reading by value: as small as it was
    // with fieldless faults.
    assert_eq!(core::mem::size_of::<Result<Option<f32>, SensorFault>>(), 8);
}
