//! Firmware for a real STM32F405 board: an RTD in the oil read by a
//! MAX31865 over SPI1 (or, with `estimator.sensor = "ntc"`, an NTC
//! thermistor in a divider on ADC1), the estimator every tick, telemetry
//! over RTT. `docs/firmware.md` walks from a blank board to live telemetry.
//!
//! Wiring (MAX31865 breakout; PT100 with a 430 ohm reference by default,
//! wire count, mains filter and the probe's Callendar-Van Dusen
//! coefficients from the parameter file's `[estimator]` section):
//!
//! | MAX31865 | STM32F405 |
//! |---|---|
//! | SCK  | PA5 (SPI1_SCK) |
//! | SDO  | PA6 (SPI1_MISO) |
//! | SDI  | PA7 (SPI1_MOSI) |
//! | CS   | PA4 (GPIO, active low) |
//! | VIN, GND | 3V3, GND |
//!
//! NTC (`estimator.sensor = "ntc"`: `build.rs` sets `cfg(sensor_ntc)`):
//! the series resistor `estimator.ntc_series` from VDDA (V_REF+) to PA1
//! (ADC1_IN1), the NTC from PA1 to GND, 100 nF from PA1 to GND beside the
//! pin. The HAL (`stm32f4xx_hal::adc::Adc`) enables, resets and calibrates
//! ADC1 (ADCCLK 21 MHz) and sets the channel's sampling time (84 cycles);
//! conversions are then
//! started and read through the register driver the simulator shares
//! (`compensator::sensor::ntc::RegisterAdc`: SWSTART, a bounded EOC poll,
//! DR), since the HAL's `convert` waits for EOC without a bound.
//!
//! The condition monitor's second sensor (feature `monitor`: the device
//! file's `[monitor]` names one; `build.rs` requires the feature then): a
//! pressure or displacement transducer into PA2 (ADC2_IN2; ratiometric
//! through its divider, or 4-20 mA across its shunt), read through the
//! transducer driver (`compensator::sensor::transducer`: NAMUR NE 43 fault
//! levels, stuck and noise checks) over the same register driver as the
//! NTC, on ADC2 (so that an NTC on ADC1 keeps its channel), every
//! `1 / monitor.sample_hz` and offered to the estimator, whose monitor
//! takes it in a job's place.
//!
//! Deadlines: a tick that starts after the next one was due is counted,
//! flagged `DEADLINE_MISSED` and caught up (`Estimator::tick_after`). The
//! independent watchdog (frozen under the debugger) resets a loop that
//! stops completing ticks; the first telemetry record after such a reset
//! carries `WATCHDOG_RESET`.
//!
//! Clocks: 8 MHz HSE -> 168 MHz SYSCLK; SysTick interrupts at the tick rate
//! of the parameter file (1 kHz by default); TIM5 provides the chip-select
//! delays. The converter runs in automatic conversion mode (a reading every
//! 20 ms at 50 Hz, 16.7 ms at 60 Hz), read once per conversion period; its
//! fault-detection cycle runs at start-up and every 10 s.
//!
//! Conventions: the stack sits alone in the core-coupled RAM
//! (the root's `memory.x`: an overflow faults instead of corrupting `.bss`); a
//! `HardFault` is logged with its registers, then halts at a breakpoint
//! under a debugger or resets the chip without one; debug builds keep the
//! debug port clocked in sleep (`wfi`) so that RTT and reflashing keep
//! working; defmt timestamps are real time (microseconds, from the SysTick
//! reload actually programmed); telemetry lines carry their time in ms,
//! the format `cargo xtask flash --csv` decodes.
//!
//! ```text
//! cargo xtask flash [--params device.toml] [--csv telemetry.csv]
//! ```
#![no_std]
#![no_main]

use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, MAX_CATCH_UP};
use compensator::sensor::TemperatureSource;
use compensator::sensor::device::sample_period;
#[cfg(not(sensor_ntc))]
use compensator::sensor::max31865::{Max31865, Settings};
#[cfg(sensor_ntc)]
use compensator::sensor::ntc::{self, Ntc};
#[cfg(any(sensor_ntc, feature = "monitor"))]
use compensator::sensor::ntc::{AdcRegisters, RegisterAdc, reg};
use compensator_firmware::clock::TickClock;
use compensator_firmware::deadline::TickPace;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{ExceptionFrame, entry, exception};
use defmt::{error, info, warn};
use defmt_rtt as _;
#[cfg(not(sensor_ntc))]
use embedded_hal::spi::MODE_1;
#[cfg(not(sensor_ntc))]
use embedded_hal_bus::spi::ExclusiveDevice;
use panic_probe as _;
#[cfg(not(sensor_ntc))]
use stm32f4xx_hal::gpio::{PinState, Speed};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;
#[cfg(not(sensor_ntc))]
use stm32f4xx_hal::spi::Spi;
use stm32f4xx_hal::watchdog::IndependentWatchdog;

include!(concat!(env!("OUT_DIR"), "/params.rs"));

/// The core clock [Hz] (8 MHz HSE through the PLL).
const SYSCLK_HZ: u32 = 168_000_000;

/// The independent watchdog's timeout in tick periods, at least
/// [`WATCHDOG_MIN_MS`]: fed once per tick that completes, it resets a loop
/// that hangs (a stuck bus, a tick that never returns). The IWDG counts
/// the LSI oscillator, 32 kHz nominal but 17 to 47 kHz over the STM32F405's
/// range (datasheet DS8626, table 38): the timeout is at least 32 / 47 of
/// the nominal one, so the loop may go up to 0.68 x `WATCHDOG_TICKS`
/// periods without a completed tick (34 ms at 1 kHz, where the worst tick
/// takes 20 us): far beyond the worst tick and the catch-up of a late one
/// (`MAX_CATCH_UP` twin ticks more), nothing a healthy loop reaches.
const WATCHDOG_TICKS: u32 = 50;
/// The watchdog's shortest nominal timeout [ms] (fast ticks).
const WATCHDOG_MIN_MS: u32 = 50;

/// Ticks elapsed (incremented by the SysTick interrupt).
static TICKS: AtomicU32 = AtomicU32::new(0);
/// Core cycles per tick, as programmed into SysTick (0 until it starts).
static CYCLES_PER_TICK: AtomicU32 = AtomicU32::new(0);

/// The real-time clock of the tick counter (`None` before SysTick starts).
fn clock() -> Option<TickClock> {
    TickClock::new(CYCLES_PER_TICK.load(Ordering::Relaxed), SYSCLK_HZ)
}

#[exception]
fn SysTick() {
    TICKS.fetch_add(1, Ordering::Relaxed);
}

// Real time whatever `tick_hz` is (0 before SysTick starts).
defmt::timestamp!(
    "{=u64:us}",
    clock().map_or(0, |c| c.micros(TICKS.load(Ordering::Relaxed)))
);

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    // SAFETY: the System Control Block's fault status registers (CFSR,
    // HFSR, BFAR), always mapped on ARMv7-M, read-only here.
    let (cfsr, hfsr, bfar) = unsafe {
        (
            (0xE000_ED28 as *const u32).read_volatile(),
            (0xE000_ED2C as *const u32).read_volatile(),
            (0xE000_ED38 as *const u32).read_volatile(),
        )
    };
    error!(
        "HardFault: pc {=u32:#010x}, lr {=u32:#010x}, xpsr {=u32:#010x}, CFSR {=u32:#010x}, HFSR {=u32:#010x}, BFAR {=u32:#010x}",
        frame.pc(),
        frame.lr(),
        frame.xpsr(),
        cfsr,
        hfsr,
        bfar
    );
    if cortex_m::peripheral::DCB::is_debugger_attached() {
        // probe-rs stops here and prints the backtrace.
        cortex_m::asm::bkpt();
    }
    // In the field: start again rather than hang.
    cortex_m::peripheral::SCB::sys_reset()
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        defmt::panic!("peripherals already taken");
    };
    // The reset cause (RCC_CSR), then cleared (RMVF) so that the next
    // reset reads its own: an independent-watchdog reset is reported at
    // start and on the first telemetry record.
    let watchdog_reset = dp.RCC.csr().read().wdgrstf().bit_is_set();
    dp.RCC.csr().modify(|_, w| w.rmvf().set_bit());
    if watchdog_reset {
        warn!("restarted by the independent watchdog (RCC_CSR IWDGRSTF): the previous run hung");
    }
    // Debug builds: keep the debug port clocked while the core sleeps in
    // `wfi` (DBGMCU_CR DBG_SLEEP/STOP/STANDBY) and a bus master clocked
    // (DMA1), so that RTT and reflashing work between ticks. Release
    // builds save that power.
    #[cfg(debug_assertions)]
    {
        dp.DBGMCU
            .cr()
            .modify(|_, w| w.dbg_sleep().set_bit().dbg_stop().set_bit().dbg_standby().set_bit());
        dp.RCC.ahb1enr().modify(|_, w| w.dma1en().set_bit());
    }
    let params = match Params::<f32>::new(&RAW_PARAMS) {
        Ok(p) => p,
        Err(e) => defmt::panic!("parameters rejected: {=str}", e.field),
    };
    let mut config = match EstimatorConfig::from_parts(&RAW_PARAMS.estimator, &OBSERVER, &UNCERTAINTY) {
        Ok(c) => c,
        Err(e) => defmt::panic!("estimator settings rejected: {=str}", e.field),
    };
    if let Err(what) = compensator_firmware::use_built_twin(&mut config, TWIN_SCHEME, TWIN_SUBSTEPS) {
        defmt::panic!("twin configuration: {=str}", what);
    }

    let mut rcc = dp.RCC.freeze(Config::hse(8.MHz()).sysclk(SYSCLK_HZ.Hz()));
    let sysclk = rcc.clocks.sysclk().raw();

    let gpioa = dp.GPIOA.split(&mut rcc);
    #[cfg(not(sensor_ntc))]
    let mut sensor = {
        let sck = gpioa.pa5.into_alternate().speed(Speed::VeryHigh);
        let miso = gpioa.pa6.into_alternate();
        let mosi = gpioa.pa7.into_alternate().speed(Speed::VeryHigh);
        let spi = Spi::new(dp.SPI1, (Some(sck), Some(miso), Some(mosi)), MODE_1, 1.MHz(), &mut rcc);
        let cs = gpioa.pa4.into_push_pull_output_in_state(PinState::High);
        let delay = dp.TIM5.delay_us(&mut rcc);
        // The chip-select pin cannot fail (its error type is `Infallible`).
        let Ok(device) = ExclusiveDevice::new(spi, cs, delay);
        // Wire count, mains filter and the probe's curve from the parameter
        // file; the converter flags readings outside the oil's range.
        let settings = Settings::from_params(&RAW_PARAMS.estimator);
        let mut sensor = Max31865::new(device, settings);
        if sensor.configure().is_err() {
            error!("MAX31865 not configured (SPI error); it is retried at every reading, samples are flagged");
        }
        sensor
    };
    #[cfg(sensor_ntc)]
    let mut sensor = {
        use stm32f4xx_hal::adc::Adc;
        use stm32f4xx_hal::adc::config::{AdcConfig, Clock, SampleTime, Sequence};
        // The divider, the NTC's curve, the ADC's bits and oversampling
        // from the parameter file; readings outside the oil's range are
        // out of range.
        let settings = ntc::Settings::from_params(&RAW_PARAMS.estimator);
        let pa1 = gpioa.pa1.into_analog();
        // Clock, reset, calibration (VREFINT) and the channel's sampling
        // time by the HAL; the resolution and the conversions by the
        // register driver.
        // ADCCLK = PCLK2 / 4 = 21 MHz (at most 36 MHz, DS8626); 84 cycles
        // of sampling: the 100 nF at the pin charges the sampling capacitor.
        let config = AdcConfig::default().clock(Clock::Pclk2_div_4);
        let mut adc = Adc::new(dp.ADC1, true, config, &mut rcc);
        adc.configure_channel(&pa1, Sequence::One, SampleTime::Cycles_84);
        // ADC1 stays configured; its registers are driven from here on.
        core::mem::forget(adc);
        Ntc::new(RegisterAdc::new(Adc1, settings.bits), settings)
    };
    // The condition monitor's transducer on PA2, ADC2. The HAL's
    // `Adc::new` takes ADC1 only (its VREFINT calibration), and its reset
    // is every ADC's: ADC2 is clocked and set up here at register level
    // (RM0090 section 13.13), then driven by the register driver.
    #[cfg(feature = "monitor")]
    let mut second = {
        use compensator::sensor::transducer::Transducer;
        use stm32f4xx_hal::rcc::Enable;
        let Some(settings) = MONITOR_TRANSDUCER else {
            defmt::panic!("monitor.sensor: the monitor's image without a second sensor");
        };
        let _pa2 = gpioa.pa2.into_analog();
        pac::ADC2::enable(&mut rcc);
        // SAFETY: raw register values, each a valid setting: ADC_CCR
        // ADCPRE = 01 (ADCCLK = PCLK2 / 4 = 21 MHz, at most 36 MHz:
        // DS8626), the ADCs' common prescaler (ADC1's too, the same); SMPR2
        // SMP2 = 100 (84 cycles of sampling, 4 us at the pin: the
        // divider's or the shunt's source); SQR1 L = 0 (one conversion);
        // SQR3 SQ1 = 2 (channel 2, PA2).
        unsafe {
            dp.ADC_COMMON
                .ccr()
                .modify(|r, w| w.bits((r.bits() & !(0b11 << 16)) | (0b01 << 16)));
            dp.ADC2
                .smpr2()
                .modify(|r, w| w.bits((r.bits() & !(0b111 << 6)) | (0b100 << 6)));
            dp.ADC2.sqr1().write(|w| w.bits(0));
            dp.ADC2.sqr3().write(|w| w.bits(2));
        }
        Transducer::new(RegisterAdc::new(Adc2, settings.bits), settings)
    };

    // The start-up fault-detection cycle, then the first good sample starts
    // the estimator at its equilibrium (a reading every conversion period,
    // one second at most).
    let mut initial = None;
    let period = sample_period(&RAW_PARAMS.estimator);
    let period_cycles = (sysclk as f32 * period) as u32;
    for _ in 0..60 {
        cortex_m::asm::delay(period_cycles);
        match sensor.read() {
            Ok(Some(t)) => {
                initial = Some(t);
                break;
            }
            Ok(None) => {}
            Err(fault) => warn!("start-up reading: {}", fault),
        }
    }
    let start = match initial {
        Some(t) if config.oil.contains(t) => t,
        _ => {
            warn!("no valid first sample; starting at the validated range's lower end");
            config.valid.min
        }
    };
    #[cfg_attr(
        feature = "monitor",
        allow(unused_mut, reason = "the monitor's image moves it into its own")
    )]
    let mut estimator = match Estimator::new(&params, config, start) {
        Ok(e) => e,
        Err(e) => defmt::panic!("estimator: {}", e),
    };
    #[cfg(feature = "monitor")]
    let (mut estimator, second_every) = {
        let Some(settings) = MONITOR else {
            defmt::panic!("monitor.sensor: the monitor's image without a second sensor");
        };
        let estimator = match estimator.with_monitor(settings) {
            Ok(e) => e,
            Err(compensator::monitor::MonitorError::NotPositive(field)) => {
                defmt::panic!("{=str} must be finite and positive", field)
            }
        };
        let s = second.settings();
        info!(
            "second sensor: {=str} transducer on PA2 (ADC2_IN2), {=u8} bits, range {=f32}..{=f32}, read every {=f32} ms",
            s.quantity.name(),
            s.bits,
            s.range.0,
            s.range.1,
            s.period * 1e3
        );
        (estimator, config.ticks_per(s.period))
    };

    // SysTick counts 24 bits: at 168 MHz a tick of at most ~99.8 ms.
    let reload = (sysclk as f32 * config.tick()) as u32 - 1;
    if reload > 0x00FF_FFFF {
        defmt::panic!("estimator.tick_hz: below what SysTick can time at {=u32} Hz", sysclk);
    }
    CYCLES_PER_TICK.store(reload + 1, Ordering::Relaxed);
    #[cfg(sensor_ntc)]
    info!(
        "compensator estimator: parameters {=str}, start {=f32} C, tick {=u32} us, sensor NTC on PA1, {=u8} bits, {=u8} conversions every {=f32} ms",
        PARAMS_SOURCE,
        start,
        clock().map_or(0, |c| c.micros(1) as u32),
        sensor.settings().bits,
        sensor.settings().oversampling,
        period * 1e3
    );
    #[cfg(not(sensor_ntc))]
    info!(
        "compensator estimator: parameters {=str}, start {=f32} C, tick {=u32} us, sensor {}-wire {=u32} Hz",
        PARAMS_SOURCE,
        start,
        clock().map_or(0, |c| c.micros(1) as u32),
        RAW_PARAMS.estimator.rtd_wires as u32,
        RAW_PARAMS.estimator.mains_hz as u32
    );
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(reload);
    cp.SYST.clear_current();
    cp.SYST.enable_interrupt();
    cp.SYST.enable_counter();

    // The watchdog: frozen while a debugger halts the core, started last
    // (the start-up readings above may take a second), fed once per tick
    // that completes.
    let timeout_ms = WATCHDOG_MIN_MS.max(clock().map_or(0, |c| (c.micros(WATCHDOG_TICKS) / 1000) as u32));
    let mut watchdog = IndependentWatchdog::new(dp.IWDG);
    watchdog.stop_on_debug(&dp.DBGMCU, true);
    watchdog.start(timeout_ms.millis());
    info!(
        "independent watchdog: {=u32} ms nominal, at least {=u32} ms (LSI at 47 kHz); catch-up of a late tick: up to {=u32} ticks",
        timeout_ms,
        timeout_ms * 32 / 47,
        MAX_CATCH_UP
    );

    let sensor_every = config.ticks_per(period);
    let mut pace = TickPace::new(TICKS.load(Ordering::Relaxed));
    let mut first_record = true;
    loop {
        while !pace.due(TICKS.load(Ordering::Relaxed)) {
            cortex_m::asm::wfi();
        }
        let now = TICKS.load(Ordering::Relaxed);
        // More than one period since the last tick: this one starts late
        // (the estimator counts, flags and catches up).
        let elapsed = pace.take(now);
        let extra = if watchdog_reset && first_record {
            Flags::WATCHDOG_RESET
        } else {
            Flags::empty()
        };
        #[cfg(not(feature = "monitor"))]
        let published = tick_path(
            &mut sensor,
            &mut estimator,
            now,
            elapsed,
            now.is_multiple_of(sensor_every),
            extra,
        );
        #[cfg(feature = "monitor")]
        let published = tick_path(
            &mut sensor,
            &mut second,
            &mut estimator,
            now,
            elapsed,
            (now.is_multiple_of(sensor_every), now.is_multiple_of(second_every)),
            extra,
        );
        if published {
            first_record = false;
        }
        watchdog.feed();
    }
}

/// One tick: the sensor read when due (`read`), the estimator, the
/// telemetry record when due. Not inlined, so that `cargo xtask test` can
/// check that nothing reachable from it panics (the HAL's SPI or the ADC's
/// registers, and the RTT logger included).
/// `elapsed`: the tick periods since the last tick (more than one: this
/// tick is late); `extra`: flags the firmware adds to the record published
/// (the watchdog's reset on the first). Returns whether a record went out.
#[cfg(not(feature = "monitor"))]
#[inline(never)]
fn tick_path<S: TemperatureSource>(
    sensor: &mut S,
    estimator: &mut compensator_firmware::BuiltEstimator,
    now: u32,
    elapsed: u32,
    read: bool,
    extra: Flags,
) -> bool {
    let sample = if read { sensor.read() } else { Ok(None) };
    let mut estimate = estimator.tick_after(sample, elapsed);
    if estimator.telemetry_due() {
        estimate.flags.insert(extra);
        // The same line as the QEMU twin's: `cargo xtask` decodes it.
        let ms = clock().map_or(0, |c| c.millis(now));
        info!("{=u32} ms {}", ms, estimate);
        return true;
    }
    false
}

/// [`tick_path`] with the condition monitor: the second sensor read when
/// due (`read.1`, the temperature's `read.0`) and offered to the
/// estimator, whose monitor takes it in a job's place.
#[cfg(feature = "monitor")]
#[inline(never)]
fn tick_path<S: TemperatureSource>(
    sensor: &mut S,
    second: &mut compensator::sensor::transducer::Transducer<RegisterAdc<Adc2>>,
    estimator: &mut compensator_firmware::BuiltEstimator,
    now: u32,
    elapsed: u32,
    read: (bool, bool),
    extra: Flags,
) -> bool {
    let sample = if read.0 { sensor.read() } else { Ok(None) };
    if read.1 {
        estimator.offer_second(second.read());
    }
    let mut estimate = estimator.tick_after(sample, elapsed);
    if estimator.telemetry_due() {
        estimate.flags.insert(extra);
        // The same line as the QEMU twin's: `cargo xtask` decodes it.
        let ms = clock().map_or(0, |c| c.millis(now));
        info!("{=u32} ms {}", ms, estimate);
        return true;
    }
    false
}

/// An ADC's registers (RM0090 section 13.13), as the register driver
/// drives them after the HAL set the ADC up: a unit struct per ADC
/// (`Adc1` for the NTC, `Adc2` for the monitor's transducer).
#[cfg(any(sensor_ntc, feature = "monitor"))]
macro_rules! adc_registers {
    ($name:ident, $adc:ident) => {
        #[doc = concat!(stringify!($adc), "'s registers.")]
        struct $name;

        impl AdcRegisters for $name {
            fn read(&mut self, offset: u32) -> u32 {
                // SAFETY: the ADC's register block, always mapped; the HAL's
                // driver was forgotten after the set-up, this is its only user.
                let adc = unsafe { &*pac::$adc::ptr() };
                match offset {
                    reg::SR => adc.sr().read().bits(),
                    reg::CR1 => adc.cr1().read().bits(),
                    reg::CR2 => adc.cr2().read().bits(),
                    reg::DR => adc.dr().read().bits(),
                    _ => 0,
                }
            }

            fn write(&mut self, offset: u32, value: u32) {
                // SAFETY: as in `read`; every value the driver writes is a valid
                // setting of these registers (RES, ADON, SWSTART; SR's rc_w0 bits).
                let adc = unsafe { &*pac::$adc::ptr() };
                #[allow(
                    unused_unsafe,
                    reason = "bits() is unsafe on some registers of the PAC, safe on others"
                )]
                match offset {
                    reg::SR => adc.sr().write(|w| unsafe { w.bits(value) }),
                    reg::CR1 => adc.cr1().write(|w| unsafe { w.bits(value) }),
                    reg::CR2 => adc.cr2().write(|w| unsafe { w.bits(value) }),
                    _ => return,
                };
            }
        }
    };
}

#[cfg(sensor_ntc)]
adc_registers!(Adc1, ADC1);
#[cfg(feature = "monitor")]
adc_registers!(Adc2, ADC2);
