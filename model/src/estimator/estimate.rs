//! The estimator's output for one tick, and (with the `defmt` feature) its
//! telemetry record's `defmt` format.

use super::flags::Flags;
use crate::monitor::HealthEstimate;
use crate::uncertainty::Uncertainty;

/// The estimator's output for one tick (SI units, `f32`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateEstimate {
    /// Tick counter.
    pub tick: u32,
    /// Estimated oil temperature \[C\] (the observer's, inside the oil range).
    pub temperature: f32,
    /// The probe's last accepted reading \[C\].
    pub t_probe: f32,
    /// Plunger displacement \[m\].
    pub x: f32,
    /// Plunger velocity [m/s].
    pub v: f32,
    /// Chamber (a) pressure \[Pa\].
    pub p_a: f32,
    /// Chamber (b) pressure \[Pa\].
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
    /// Quasi-static equilibrium displacement at this temperature \[m\].
    pub x_equilibrium: f32,
    /// `dx/dt` of the equilibrium branch (Eq. 31) [m/K].
    pub dx_dt: f32,
    /// Times the consistency check has re-seated the twin on the
    /// closed-form equilibrium since start (saturating; 0 for a twin that
    /// never settled at a false state).
    pub reseats: u32,
    /// Tick deadlines missed since start (saturating): the ticks that
    /// elapsed while the controller was still busy with an earlier one
    /// ([`Estimator::tick_after`](super::Estimator::tick_after)).
    pub deadline_misses: u32,
    /// Ticks of real time the twin did not advance through since start
    /// (saturating): late ticks beyond the catch-up bound
    /// ([`MAX_CATCH_UP`](super::MAX_CATCH_UP)) each; 0 while the twin's
    /// simulated time is the real time.
    pub lost_ticks: u32,
    /// Standard uncertainties of the estimate (`k = 1`), refreshed in the
    /// job rotation.
    pub uncertainty: Uncertainty,
    /// The condition monitor's health parameters at its last reading
    /// ([`HealthEstimate::NONE`] without a second sensor).
    pub health: HealthEstimate,
    /// Conditions.
    pub flags: Flags,
}

impl StateEstimate {
    /// An estimate at `temperature` [C] without physics: every state, flow
    /// and equilibrium field NaN (the telemetry's tests start from it).
    #[cfg(test)]
    pub(super) const fn without_physics(tick: u32, temperature: f32, t_probe: f32, reseats: u32, flags: Flags) -> Self {
        StateEstimate {
            tick,
            temperature,
            t_probe,
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
            deadline_misses: 0,
            lost_ticks: 0,
            uncertainty: Uncertainty::UNKNOWN,
            health: HealthEstimate::NONE,
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

/// The telemetry record: the estimate's fields as the table in
/// [`telemetry`](super::telemetry) lists them, packed by
/// [`telemetry::encode`](super::telemetry::encode) (with the `monitor`
/// feature, the condition monitor's health rows too:
/// [`telemetry::encode_monitor`](super::telemetry::encode_monitor)) and
/// sent as one byte string (the host decodes either with
/// [`telemetry::Record::decode`](super::telemetry::Record::decode)). One
/// argument instead of one per field: defmt's per-argument cost was about
/// 66 instructions.
#[cfg(feature = "defmt")]
impl defmt::Format for StateEstimate {
    fn format(&self, f: defmt::Formatter) {
        #[cfg(not(feature = "monitor"))]
        let record = super::telemetry::encode(self);
        #[cfg(feature = "monitor")]
        let record = super::telemetry::encode_monitor(self);
        defmt::write!(f, "telemetry {=[u8]}", &record[..]);
    }
}
