//! Simulated sensors behind their real drivers, as the replays (the QEMU
//! twin, the soak, `cargo xtask`'s host replica, the fuzzer) drive them:
//! the temperature at the element and an injected fault, whatever the
//! chip. The register-level simulators are the chips' own
//! ([`SimulatedMax31865`], [`SimulatedStm32Adc`]); this module gives them
//! one interface, [`SimulatedSource`], implemented for each driver over
//! its simulator ([`SimulatedRtd`], [`SimulatedNtc`]).

pub use super::max31865::SimulatedMax31865;
use super::max31865::{self, Max31865};
pub use super::ntc::SimulatedStm32Adc;
use super::ntc::{self, Ntc, RegisterAdc};
use super::{SensorFault, TemperatureSource};

/// The MAX31865 driver over its simulator.
pub type SimulatedRtd = Max31865<SimulatedMax31865>;
/// The NTC driver over the simulated STM32F4 ADC's registers.
pub type SimulatedNtc = Ntc<RegisterAdc<SimulatedStm32Adc>>;

/// A fault injected into a simulated sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Injection {
    /// The element open (MAX31865: its RTD-high fault; NTC: the input at
    /// `V_REF+`).
    Open,
    /// The element shorted (MAX31865: RTD-low; NTC: the input at ground).
    Short,
    /// The bus fails (MAX31865: every SPI transaction; NTC: no conversion
    /// ends).
    Bus,
    /// A full-scale code (a broken converter).
    Saturated,
    /// The converter stuck (MAX31865: MISO stuck high, every byte 0xFF;
    /// NTC: no conversion ends).
    Stuck,
    /// The converter reports this raw code whatever the element reads (a
    /// frozen or broken converter; the codes of
    /// [`SimulatedSource::code_of`]).
    Code(u16),
}

/// A driver over its simulator, as a replay drives it.
pub trait SimulatedSource: TemperatureSource {
    /// The driver and its simulator at `temperature` \[C\], from the file's
    /// `[estimator]` section with the element's fault band `band` \[C\]
    /// (the replays widen it, so that the estimator's oil range is what
    /// rejects samples).
    fn simulated(raw: &crate::params::RawEstimator, band: (f32, f32), temperature: f32) -> Self
    where
        Self: Sized;

    /// Brings the converter up (the MAX31865's thresholds and start-up
    /// diagnosis; nothing for the ADC, set up by the driver's creation).
    ///
    /// # Errors
    ///
    /// [`SensorFault::Bus`] when the converter cannot be configured.
    fn start(&mut self) -> Result<(), SensorFault>;

    /// Time between two readings \[s\].
    fn sample_period(&self) -> f32;

    /// The temperature at the element \[C\].
    fn set_temperature(&mut self, temperature: f32);

    /// The fault present from now on (`None`: healthy).
    fn inject(&mut self, fault: Option<Injection>);

    /// Readings after a diagnosis cycle that return no sample (the
    /// MAX31865's stale registers after its fault-detection cycle,
    /// [`max31865::Settings::restart_readings`]; 0 for the NTC, which has
    /// no such cycle).
    fn restart_readings(&self) -> u32;

    /// The converter's raw code at `temperature` \[C\], as its simulator
    /// converts it (for [`Injection::Code`]).
    fn code_of(&self, temperature: f32) -> u16;
}

impl SimulatedSource for SimulatedRtd {
    fn simulated(raw: &crate::params::RawEstimator, band: (f32, f32), temperature: f32) -> Self {
        let settings = max31865::Settings {
            fault_band: band,
            ..max31865::Settings::from_params(raw)
        };
        Max31865::new(SimulatedMax31865::new(settings, temperature), settings)
    }

    fn start(&mut self) -> Result<(), SensorFault> {
        self.configure().map_err(|_| SensorFault::Bus)
    }

    fn sample_period(&self) -> f32 {
        self.settings().mains.conversion_period()
    }

    fn set_temperature(&mut self, temperature: f32) {
        self.device_mut().temperature = temperature;
    }

    fn inject(&mut self, fault: Option<Injection>) {
        let sim = self.device_mut();
        sim.bus_error = false;
        sim.fault = 0;
        sim.forced_code = None;
        sim.miso_stuck_high = false;
        match fault {
            None => {}
            Some(Injection::Open) => sim.fault = max31865::fault::RTD_HIGH,
            Some(Injection::Short) => sim.fault = max31865::fault::RTD_LOW,
            Some(Injection::Bus) => sim.bus_error = true,
            Some(Injection::Saturated) => sim.forced_code = Some(0x7FFF),
            Some(Injection::Stuck) => sim.miso_stuck_high = true,
            Some(Injection::Code(code)) => sim.forced_code = Some(code),
        }
    }

    fn restart_readings(&self) -> u32 {
        self.settings().restart_readings()
    }

    fn code_of(&self, temperature: f32) -> u16 {
        let s = self.settings();
        max31865::code_of(s, s.cvd.resistance(s.r0, temperature))
    }
}

impl SimulatedSource for SimulatedNtc {
    fn simulated(raw: &crate::params::RawEstimator, band: (f32, f32), temperature: f32) -> Self {
        let settings = ntc::Settings {
            band,
            ..ntc::Settings::from_params(raw)
        };
        let adc = RegisterAdc::new(SimulatedStm32Adc::new(settings, temperature), settings.bits);
        Ntc::new(adc, settings)
    }

    fn start(&mut self) -> Result<(), SensorFault> {
        Ok(())
    }

    fn sample_period(&self) -> f32 {
        self.settings().period
    }

    fn set_temperature(&mut self, temperature: f32) {
        self.device_mut().registers_mut().temperature = temperature;
    }

    fn inject(&mut self, fault: Option<Injection>) {
        let sim = self.device_mut().registers_mut();
        sim.open = false;
        sim.short = false;
        sim.forced_code = None;
        sim.stuck = false;
        match fault {
            None => {}
            Some(Injection::Open) => sim.open = true,
            Some(Injection::Short) => sim.short = true,
            Some(Injection::Bus | Injection::Stuck) => sim.stuck = true,
            Some(Injection::Saturated) => sim.forced_code = Some(u16::MAX),
            Some(Injection::Code(code)) => sim.forced_code = Some(code),
        }
    }

    fn restart_readings(&self) -> u32 {
        0
    }

    fn code_of(&self, temperature: f32) -> u16 {
        self.settings().code_of(temperature)
    }
}
