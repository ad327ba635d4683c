//! Firmware for a real STM32F405 board: a PT100 in the oil read by a
//! MAX31865 over SPI1, the estimator every 1 ms tick, telemetry over RTT.
//!
//! Wiring (MAX31865 breakout, 3-wire PT100, 430 ohm reference):
//!
//! | MAX31865 | STM32F405 |
//! |---|---|
//! | SCK  | PA5 (SPI1_SCK) |
//! | SDO  | PA6 (SPI1_MISO) |
//! | SDI  | PA7 (SPI1_MOSI) |
//! | CS   | PA4 (GPIO, active low) |
//! | VIN, GND | 3V3, GND |
//!
//! Clocks: 8 MHz HSE -> 168 MHz SYSCLK; SysTick interrupts at the tick rate
//! of the parameter file (1 kHz by default); TIM5 provides the chip-select
//! delays. The converter runs in automatic conversion mode (50 Hz filter,
//! a new reading every 20 ms) and is read every 20 ticks.
//!
//! Build and flash (probe-rs):
//!
//! ```text
//! cargo xtask build                 # builds target/firmware/thumbv7em-none-eabihf/release/board
//! probe-rs run --chip STM32F405RGTx target/firmware/thumbv7em-none-eabihf/release/board
//! ```
//!
//! With your own device: `COMPENSATOR_PARAMS=path/to/device.toml cargo xtask build`
//! (the file is validated at build time; a bad field fails the build).
#![no_std]
#![no_main]

use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::sensor::TemperatureSource;
use compensator::sensor::max31865::{Mains, Max31865, Settings, Wires};
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use defmt::{error, info, warn};
use defmt_rtt as _;
use embedded_hal::spi::MODE_1;
use embedded_hal_bus::spi::ExclusiveDevice;
use panic_probe as _;
use stm32f4xx_hal::gpio::{PinState, Speed};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::spi::Spi;

include!(concat!(env!("OUT_DIR"), "/params.rs"));

/// Ticks elapsed (incremented by the SysTick interrupt).
static TICKS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    TICKS.fetch_add(1, Ordering::Relaxed);
}

defmt::timestamp!("{=u32:ms}", TICKS.load(Ordering::Relaxed));

#[entry]
fn main() -> ! {
    let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        defmt::panic!("peripherals already taken");
    };
    let params = match Params::<f32>::new(&RAW_PARAMS) {
        Ok(p) => p,
        Err(e) => defmt::panic!("parameters rejected: {=str}", e.field),
    };
    let config = match EstimatorConfig::new(&RAW_PARAMS.estimator) {
        Ok(c) => c,
        Err(e) => defmt::panic!("estimator settings rejected: {=str}", e.field),
    };

    let mut rcc = dp.RCC.freeze(Config::hse(8.MHz()).sysclk(168.MHz()));
    let sysclk = rcc.clocks.sysclk().raw();

    let gpioa = dp.GPIOA.split(&mut rcc);
    let sck = gpioa.pa5.into_alternate().speed(Speed::VeryHigh);
    let miso = gpioa.pa6.into_alternate();
    let mosi = gpioa.pa7.into_alternate().speed(Speed::VeryHigh);
    let spi = Spi::new(dp.SPI1, (Some(sck), Some(miso), Some(mosi)), MODE_1, 1.MHz(), &mut rcc);
    let cs = gpioa.pa4.into_push_pull_output_in_state(PinState::High);
    let delay = dp.TIM5.delay_us(&mut rcc);
    // The chip-select pin cannot fail (its error type is `Infallible`).
    let Ok(device) = ExclusiveDevice::new(spi, cs, delay);
    let settings = Settings {
        r0: RAW_PARAMS.estimator.rtd_r0 as f32,
        reference: RAW_PARAMS.estimator.rtd_reference as f32,
        wires: Wires::Three,
        mains: Mains::Hz50,
        fault_band: (RAW_PARAMS.estimator.oil_min as f32, RAW_PARAMS.estimator.oil_max as f32),
    };
    let mut sensor = Max31865::new(device, settings);
    if sensor.configure().is_err() {
        error!("MAX31865 not configured (SPI error); continuing, samples will be flagged");
    }

    // The first good sample starts the estimator at its equilibrium.
    let mut initial = None;
    for _ in 0..50 {
        cortex_m::asm::delay(sysclk / 50);
        if let Ok(Some(t)) = sensor.read() {
            initial = Some(t);
            break;
        }
    }
    let start = match initial {
        Some(t) if t >= config.oil.0 && t <= config.oil.1 => t,
        _ => {
            warn!("no valid first sample; starting at the validated range's lower end");
            config.valid.0
        }
    };
    let mut estimator = match Estimator::new(&params, config, start) {
        Ok(e) => e,
        Err(e) => defmt::panic!("estimator: {}", e),
    };
    info!(
        "compensator estimator: parameters {=str}, start {=f32} C, tick {=f32} ms",
        PARAMS_SOURCE,
        start,
        config.tick() * 1e3
    );

    // SysTick counts 24 bits: at 168 MHz a tick of at most ~99.8 ms.
    let reload = (sysclk as f32 * config.tick()) as u32 - 1;
    if reload > 0x00FF_FFFF {
        defmt::panic!("estimator.tick_hz: below what SysTick can time at {=u32} Hz", sysclk);
    }
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(reload);
    cp.SYST.clear_current();
    cp.SYST.enable_interrupt();
    cp.SYST.enable_counter();

    let sensor_every = config.ticks_per(settings.mains.conversion_period());
    let mut done = TICKS.load(Ordering::Relaxed);
    loop {
        while TICKS.load(Ordering::Relaxed) == done {
            cortex_m::asm::wfi();
        }
        let now = TICKS.load(Ordering::Relaxed);
        if now.wrapping_sub(done) > 1 {
            warn!("{=u32} ticks overran", now.wrapping_sub(done) - 1);
        }
        done = now;
        let sample = if now % sensor_every == 0 {
            sensor.read()
        } else {
            Ok(None)
        };
        let estimate = estimator.tick(sample);
        if estimator.telemetry_due() {
            info!("{}", estimate);
        }
    }
}
