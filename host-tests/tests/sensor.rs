//! The MAX31865 driver against the datasheet's register map (mock SPI
//! transactions), fault decoding, bus errors, and the simulated converter
//! the QEMU twin reads.

use compensator::sensor::max31865::{Mains, Max31865, Settings, Wires, classify, code_of, config, fault};
use compensator::sensor::simulated::SimulatedMax31865;
use compensator::sensor::{SensorFault, TemperatureSource, rtd};
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::spi::{Mock, Transaction as T};

const SETTINGS: Settings = Settings {
    r0: 100.0,
    reference: 430.0,
    wires: Wires::Three,
    mains: Mains::Hz50,
    fault_band: (-60.0, 250.0),
};

/// The RTD word (code << 1 | fault bit) as the two bytes of registers 1-2.
fn rtd_bytes(code: u16, fault: bool) -> Vec<u8> {
    let w = (code << 1) | u16::from(fault);
    vec![(w >> 8) as u8, w as u8]
}

#[test]
fn configure_writes_thresholds_then_starts_continuous_conversion() {
    // Thresholds, worked by hand from IEC 60751: R(250 C) = 194.0981 ohm,
    // code round(194.0981 / 430 * 2^15) = 14791, word 14791 << 1 = 0x738E;
    // R(-60 C) = 76.3278 ohm, code 5817, word 0x2D72.
    // Datasheet: write address = read address | 0x80; thresholds at 0x03-0x06
    // (high MSB, LSB, low MSB, LSB), auto-incrementing; configuration 0x00.
    let expectations = [
        T::transaction_start(),
        T::write_vec(vec![0x83, 0x73, 0x8E, 0x2D, 0x72]),
        T::transaction_end(),
        T::transaction_start(),
        // V_BIAS | auto | 3-wire | fault clear | 50 Hz
        T::write_vec(vec![0x80, 0x80 | 0x40 | 0x10 | 0x02 | 0x01]),
        T::transaction_end(),
    ];
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    drv.configure().unwrap();
    spi.done();
    assert_eq!(
        config::V_BIAS | config::AUTO | config::THREE_WIRE | config::FILTER_50HZ,
        0xD1
    );
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
        let expectations = [
            T::transaction_start(),
            T::write_vec(vec![0x01]),
            T::read_vec(rtd_bytes(code, false)),
            T::transaction_end(),
        ];
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
fn a_fault_bit_reads_the_status_clears_it_and_names_the_fault() {
    let code = code_of(&SETTINGS, rtd::resistance(100.0, 40.0));
    let expectations = [
        T::transaction_start(),
        T::write_vec(vec![0x01]),
        T::read_vec(rtd_bytes(code, true)),
        T::transaction_end(),
        T::transaction_start(),
        T::write_vec(vec![0x07]),
        T::read_vec(vec![fault::RTD_HIGH]),
        T::transaction_end(),
        T::transaction_start(),
        T::write_vec(vec![0x80, 0x80 | 0x40 | 0x10 | 0x01 | 0x02]),
        T::transaction_end(),
    ];
    let mut spi = Mock::new(&expectations);
    let mut drv = Max31865::new(spi.clone(), SETTINGS);
    assert_eq!(drv.read(), Err(SensorFault::RtdHigh));
    spi.done();
}

#[test]
fn status_bits_map_to_faults() {
    assert_eq!(classify(fault::RTD_HIGH), SensorFault::RtdHigh);
    assert_eq!(classify(fault::RTD_LOW), SensorFault::RtdLow);
    assert_eq!(classify(fault::REFIN_HIGH), SensorFault::Wiring);
    assert_eq!(classify(fault::REFIN_LOW | fault::RTD_HIGH), SensorFault::Wiring);
    assert_eq!(classify(fault::RTDIN_LOW), SensorFault::Wiring);
    assert_eq!(classify(fault::VOLTAGE), SensorFault::Voltage);
    assert_eq!(classify(0), SensorFault::Implausible);
}

#[test]
fn saturated_codes_are_implausible_not_temperatures() {
    for code in [0u16, 0x7FFF] {
        let expectations = [
            T::transaction_start(),
            T::write_vec(vec![0x01]),
            T::read_vec(rtd_bytes(code, false)),
            T::transaction_end(),
        ];
        let mut spi = Mock::new(&expectations);
        let mut drv = Max31865::new(spi.clone(), SETTINGS);
        assert_eq!(drv.read(), Err(SensorFault::Implausible));
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
    assert_eq!(drv.device_mut().config(), 0xD1, "fault-clear bit self-clears");
    assert!((drv.read().unwrap().unwrap() - 61.2).abs() < 0.02);
    drv.device_mut().fault = fault::RTD_LOW;
    assert_eq!(drv.read(), Err(SensorFault::RtdLow));
    // The cause persists: clearing the latch does not hide it.
    assert_eq!(drv.read(), Err(SensorFault::RtdLow));
    drv.device_mut().fault = 0;
    assert!(drv.read().unwrap().is_some());
    drv.device_mut().forced_code = Some(0x7FFF);
    assert_eq!(drv.read(), Err(SensorFault::Implausible));
    drv.device_mut().forced_code = None;
    drv.device_mut().bus_error = true;
    assert_eq!(drv.read(), Err(SensorFault::Bus));
}
