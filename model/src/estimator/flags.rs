//! The condition flags of an estimate and their names.
//!
//! The flags are listed once, in the table at the end of this file: each
//! flag's bit, constant, name and meaning. The table makes the constants,
//! [`Flags::NAMES`] (what host code prints: the QEMU twin's host replica,
//! the tests) and, with the `defmt` feature, the interned names the
//! telemetry record packs. A name is its constant's, spelt out because
//! `defmt::intern!` takes a string literal only; the build fails when the
//! two differ or a flag's bit is not its place in the table.

/// Condition flags of an estimate (a bit set).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags(pub u32);

impl Flags {
    /// No flag set.
    pub const fn empty() -> Self {
        Flags(0)
    }
    /// All of `other`'s flags are set.
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }
    /// Sets `other`'s flags.
    pub fn insert(&mut self, other: Flags) {
        self.0 |= other.0;
    }
    /// Clears `other`'s flags.
    pub fn remove(&mut self, other: Flags) {
        self.0 &= !other.0;
    }
    /// No flag set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// The names of the flags set, in bit order.
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        Flags::NAMES
            .iter()
            .enumerate()
            .filter(move |(i, _)| self.0 & (1 << i) != 0)
            .map(|(_, name)| *name)
    }
}

/// `a == b`, in a constant expression.
const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// Makes the flags from the table: rows `BIT NAME "NAME";`, each with its
/// docs.
macro_rules! flag_table {
    ($($(#[$meta:meta])* $bit:literal $flag:ident $name:literal;)*) => {
        impl Flags {
            $(
                $(#[$meta])*
                pub const $flag: Flags = Flags(1 << $bit);
            )*

            /// Names of the flags, in bit order (each its constant's name).
            pub const NAMES: [&'static str; [$($name),*].len()] = [$($name),*];
        }

        // Each name is its constant's, and each bit its place in the table.
        const _: () = {
            $(
                assert!(same_str(stringify!($flag), $name), "a flag's name is its constant's");
                assert!(same_str(Flags::NAMES[$bit], $name), "a flag's bit is its place in the table");
            )*
        };

        #[cfg(feature = "defmt")]
        impl defmt::Format for Flags {
            /// Names as interned strings: two bytes each in the log stream,
            /// not the name's bytes (what keeps a telemetry record cheap to
            /// pack).
            fn format(&self, f: defmt::Formatter) {
                if self.is_empty() {
                    defmt::write!(f, "-");
                    return;
                }
                let names = [$(defmt::intern!($name)),*];
                let mut first = true;
                for (i, name) in names.iter().enumerate() {
                    if self.0 & (1 << i) != 0 {
                        if first {
                            defmt::write!(f, "{=istr}", *name);
                        } else {
                            defmt::write!(f, "|{=istr}", *name);
                        }
                        first = false;
                    }
                }
            }
        }
    };
}

flag_table! {
    /// The plunger rests on a stop (window closed or fully open).
    0 AT_STOP "AT_STOP";
    /// The filtered temperature is outside the validated range.
    1 OUT_OF_RANGE "OUT_OF_RANGE";
    /// Eq. (32) does not hold over the validated range: the equilibrium
    /// branch may not be unique.
    2 NOT_UNIQUE "NOT_UNIQUE";
    /// The linearisation at the equilibrium is not Hurwitz-stable.
    3 UNSTABLE "UNSTABLE";
    /// This tick's sample was missing or unusable (a sensor fault).
    4 SENSOR_FAULT "SENSOR_FAULT";
    /// This tick's sample was rejected as a spike.
    5 SPIKE "SPIKE";
    /// The estimate is not trustworthy: no usable sample for a while, the
    /// oil model refused the temperature, or the twin had to be reset.
    6 DEGRADED "DEGRADED";
    /// The twin disagreed with the closed-form equilibrium although the
    /// temperature had been steady for several of its slowest time
    /// constants (a false equilibrium, or a state corrupted otherwise): it
    /// was re-seated on the equilibrium. Raised from the re-seat until a
    /// later check (one settling window on) finds the twin in agreement.
    7 TWIN_RESEATED "TWIN_RESEATED";
    /// The tick started after the next one was due (the controller missed
    /// a deadline): the twin advanced by the ticks that elapsed
    /// ([`Estimator::tick_after`](super::Estimator::tick_after)), counted in
    /// [`StateEstimate::deadline_misses`](super::StateEstimate::deadline_misses).
    8 DEADLINE_MISSED "DEADLINE_MISSED";
    /// The controller restarted because its watchdog reset it (the
    /// reset-cause register read at start): raised by the firmware on the
    /// first telemetry record after the restart, never by the estimator.
    9 WATCHDOG_RESET "WATCHDOG_RESET";
    /// The condition monitor's CUSUM found the device behaving unlike the
    /// device its health parameters describe, and no single fault explains
    /// the change yet (`crate::monitor`).
    10 DEVICE_CHANGED "DEVICE_CHANGED";
    /// The monitor isolated a rise of the divider parameter `A`: the
    /// capillary restricted (silting) or the orifice worn; no steady
    /// reading tells the two apart (latched).
    11 CAPILLARY_RESTRICTED "CAPILLARY_RESTRICTED";
    /// The monitor isolated a fall of `A`: the orifice clogged, or the
    /// capillary eroded (latched).
    12 ORIFICE_CLOGGED "ORIFICE_CLOGGED";
    /// The monitor isolated a loss of spring rate (a displacement sensor
    /// only; latched).
    13 SPRING_RELAXED "SPRING_RELAXED";
    /// The monitor isolated a displacement offset upwards: the spring's
    /// preload lost, or the displacement sensor's zero moved (latched).
    14 PRELOAD_LOST "PRELOAD_LOST";
    /// The monitor isolated a plunger held by friction: it lags the
    /// temperature's changes (a displacement sensor only; latched).
    15 PLUNGER_STICKING "PLUNGER_STICKING";
    /// The monitor isolated an offset of the second sensor's reading that
    /// no device fault explains (latched).
    16 SENSOR_OFFSET "SENSOR_OFFSET";
    /// The reading of the second sensor this tick took (or, on a published
    /// estimate, one since the last published) was refused by its own
    /// checks (open loop, out of range, stuck, noisy): the monitor skipped it.
    17 SECOND_SENSOR_FAULT "SECOND_SENSOR_FAULT";
    /// The reading of the second sensor this tick took (or, on a published
    /// estimate, one since the last published) lay beyond the monitor's
    /// gate, or was not finite: counted, not applied.
    18 INNOVATION_REJECTED "INNOVATION_REJECTED";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_bits() {
        assert_eq!(Flags::NAMES.len(), 19);
        let mut all = Flags::empty();
        for (i, name) in Flags::NAMES.iter().enumerate() {
            all.insert(Flags(1 << i));
            assert_eq!(Flags(1 << i).names().collect::<Vec<_>>(), [*name]);
        }
        assert_eq!(all.names().count(), Flags::NAMES.len());
        let mut f = Flags::SPIKE;
        f.insert(Flags::AT_STOP);
        assert_eq!(f.names().collect::<Vec<_>>(), ["AT_STOP", "SPIKE"]);
        assert_eq!(Flags::empty().names().count(), 0);
    }
}
