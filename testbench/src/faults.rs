//! The sensor faults the QEMU twin's replay injects, as typed data shared
//! by the twin image (`src/bin/twin.rs`), the build's replay generator
//! (`compensator-codegen`, which places the spike) and `cargo xtask`'s
//! host-side replica of the replay (`xtask/src/replica.rs`): renaming a
//! fault or its flag fails to compile where the rename is made, in all.

/// What the replay does to the simulated sensor (either kind: each maps
/// to a [`compensator::sensor::simulated::Injection`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Injected {
    /// [`Fault::spike`]'s delta added to one sample.
    Spike,
    /// The bus fails (MAX31865: every SPI transaction; NTC: no ADC
    /// conversion ends).
    BusError,
    /// The element open (MAX31865: its RTD-high fault; NTC: the divider's
    /// input at full scale).
    Open,
    /// A full-scale code.
    SaturatedCode,
}

impl Injected {
    /// What the simulated sensor is given (`None` for the spike, which is
    /// a temperature, not a fault of the sensor).
    pub fn injection(self) -> Option<compensator::sensor::simulated::Injection> {
        use compensator::sensor::simulated::Injection;
        match self {
            Injected::Spike => None,
            Injected::BusError => Some(Injection::Bus),
            Injected::Open => Some(Injection::Open),
            Injected::SaturatedCode => Some(Injection::Saturated),
        }
    }
}

/// The estimator flag an injected fault must raise (the twin maps each to
/// its `Flags` constant with a `match`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expected {
    /// `Flags::SPIKE`: the sample is rejected as a spike.
    Spike,
    /// `Flags::SENSOR_FAULT`: the tick's sample is missing or unusable.
    SensorFault,
    /// `Flags::DEGRADED`: no usable sample for half a second.
    Degraded,
}

/// One injected fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fault {
    /// Start of the injection [s of replay time].
    pub start: f32,
    /// End of the injection [s], exclusive.
    pub end: f32,
    /// What is injected.
    pub injected: Injected,
    /// The flag the estimate must show during the injection.
    pub expected: Expected,
}

/// The faults, in time order (the replay's temperature pieces are adapted
/// to the device's ranges by `build.rs`; the faults' times are not).
pub const FAULTS: [Fault; 5] = [
    Fault {
        start: 10.0,
        end: 10.02,
        injected: Injected::Spike,
        expected: Expected::Spike,
    },
    Fault {
        start: 20.0,
        end: 20.3,
        injected: Injected::BusError,
        expected: Expected::SensorFault,
    },
    Fault {
        start: 30.0,
        end: 30.1,
        injected: Injected::Open,
        expected: Expected::SensorFault,
    },
    Fault {
        start: 40.0,
        end: 40.05,
        injected: Injected::SaturatedCode,
        expected: Expected::SensorFault,
    },
    // Half a second without samples.
    Fault {
        start: 69.0,
        end: 70.0,
        injected: Injected::BusError,
        expected: Expected::Degraded,
    },
];

/// The index into [`FAULTS`] of the fault injected at `time` [s], if any.
pub fn fault_at(time: f32) -> Option<usize> {
    FAULTS.iter().position(|f| time >= f.start && time < f.end)
}
