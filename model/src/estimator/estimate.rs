//! The estimator's output for one tick, and the telemetry record it packs
//! into (with the `defmt` feature).

use super::flags::Flags;

/// The estimator's output for one tick (SI units, `f32`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateEstimate {
    /// Tick counter.
    pub tick: u32,
    /// Filtered oil temperature [C].
    pub temperature: f32,
    /// Plunger displacement [m].
    pub x: f32,
    /// Plunger velocity [m/s].
    pub v: f32,
    /// Chamber (a) pressure [Pa].
    pub p_a: f32,
    /// Chamber (b) pressure [Pa].
    pub p_b: f32,
    /// Flow leaving chamber (a) through its capillary [m^3/s].
    pub q_a: f32,
    /// Flow leaving chamber (b) through its orifice [m^3/s].
    pub q_b: f32,
    /// Flow through the window [m^3/s].
    pub q_throt: f32,
    /// Total flow `Q0 = Q_a + Q_b + Q_throt` [m^3/s].
    pub q_total: f32,
    /// `Q0 - (Q_work + dQ_lost(t))` [m^3/s]; NaN without a `[machine]`.
    pub compensation_error: f32,
    /// Quasi-static equilibrium displacement at this temperature [m].
    pub x_equilibrium: f32,
    /// `dx/dt` of the equilibrium branch (Eq. 31) [m/K].
    pub dx_dt: f32,
    /// Times the consistency check has re-seated the twin on the
    /// closed-form equilibrium since start (saturating; 0 for a twin that
    /// never settled at a false state).
    pub reseats: u32,
    /// Conditions.
    pub flags: Flags,
}

impl StateEstimate {
    /// An estimate at `temperature` [C] without physics: every state, flow
    /// and equilibrium field NaN (what the estimator reports, flagged, when
    /// the model refuses a temperature before it has had an estimate).
    pub(super) const fn without_physics(tick: u32, temperature: f32, reseats: u32, flags: Flags) -> Self {
        StateEstimate {
            tick,
            temperature,
            x: f32::NAN,
            v: f32::NAN,
            p_a: f32::NAN,
            p_b: f32::NAN,
            q_a: f32::NAN,
            q_b: f32::NAN,
            q_throt: f32::NAN,
            q_total: f32::NAN,
            compensation_error: f32::NAN,
            x_equilibrium: f32::NAN,
            dx_dt: f32::NAN,
            reseats,
            flags,
        }
    }

    /// Whether every state, flow and equilibrium field is finite (the
    /// estimator's promise on any input). `compensation_error` is left out:
    /// it is NaN by design without a `[machine]`.
    pub fn is_finite(&self) -> bool {
        [
            self.temperature,
            self.x,
            self.v,
            self.p_a,
            self.p_b,
            self.q_a,
            self.q_b,
            self.q_throt,
            self.q_total,
            self.x_equilibrium,
            self.dx_dt,
        ]
        .iter()
        .all(|v| v.is_finite())
    }
}

/// The telemetry record: the state estimate in engineering units. The
/// equilibrium `x*` and `dx/dt` stay out of it (each float costs ~80
/// instructions to pack); they are in the struct for whoever needs them.
#[cfg(feature = "defmt")]
impl defmt::Format for StateEstimate {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "t={=f32} C x={=f32} um v={=f32} mm/s p_a={=f32} p_b={=f32} kPa Q_a={=f32} Q_b={=f32} Q_throt={=f32} Q0={=f32} err={=f32} l/min reseats={=u32} [{}]",
            self.temperature,
            self.x * 1e6,
            self.v * 1e3,
            self.p_a * 1e-3,
            self.p_b * 1e-3,
            self.q_a * 6e4,
            self.q_b * 6e4,
            self.q_throt * 6e4,
            self.q_total * 6e4,
            self.compensation_error * 6e4,
            self.reseats,
            self.flags
        )
    }
}
