//! # compensator-testbench
//!
//! What the firmware's emulated test runs share with their host
//! counterparts, `no_std` and allocation-free, so that the QEMU images and
//! the host compile the same code (no file is included by path):
//!
//! * [`faults`]: the sensor faults the QEMU twin's replay injects (the twin
//!   image, the build's replay generator `compensator-codegen` and the
//!   host-side replica of `cargo xtask test` read the one table);
//! * [`soak`]: the soak's seeded temperature walk, its injected sensor
//!   faults and the checks run on every tick (the QEMU soak image and the
//!   host soak of `host-tests`);
//! * [`probe`]: the probe the replay reads its oil through (a lag and
//!   noise);
//! * [`temperature_at`]: the replay's piecewise-linear profile;
//! * [`monitor`]: the condition monitor's second sensor in the replay (the
//!   true device's reading, its restriction, the transducer's open loop).
#![no_std]
#![deny(missing_docs)]
#![forbid(unsafe_code)]

pub mod faults;
pub mod monitor;
pub mod probe;
pub mod soak;

/// Temperature [C] of a piecewise-linear profile at `time` [s]: `pieces`
/// are (start s, end s, from C, to C) in time order; after the last piece,
/// its end value.
pub fn temperature_at(pieces: &[(f32, f32, f32, f32)], time: f32) -> f32 {
    for &(t0, t1, a, b) in pieces {
        if time >= t0 && time < t1 {
            return a + (b - a) * (time - t0) / (t1 - t0);
        }
    }
    pieces.last().map_or(0.0, |p| p.3)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_profile_interpolates_and_holds_its_last_value() {
        let pieces = [(0.0, 3.0, 26.0, 26.0), (3.0, 55.0, 26.0, 78.0)];
        assert_eq!(super::temperature_at(&pieces, 1.0), 26.0);
        assert_eq!(super::temperature_at(&pieces, 29.0), 52.0);
        assert_eq!(super::temperature_at(&pieces, 100.0), 78.0);
        assert_eq!(super::temperature_at(&[], 1.0), 0.0);
        assert_eq!(
            crate::faults::fault_at(10.01).map(|i| crate::faults::FAULTS[i].injected),
            Some(crate::faults::Injected::Spike)
        );
        assert_eq!(crate::faults::fault_at(10.02), None);
    }
}
