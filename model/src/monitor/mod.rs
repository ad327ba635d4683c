//! Condition monitoring: a second sensor (a chamber pressure or the
//! plunger displacement) says what the oil's temperature is, faster and
//! finer than the probe; the probe, through its own lag, says whether the
//! device still reads as its health estimate says; sequential tests on
//! what the two cannot agree on name the device's fault.
//!
//! **Why the probe is the test, not the second sensor.** The
//! oil-temperature observer inverts the probe's lag: in a step of the oil
//! (1 C/s through an 8 s probe) its estimate is off by up to 1.3 K for a
//! few seconds, 20 to 50 times its own variance (`docs/monitoring.md`, the
//! observer's error over the campaign's histories). A reading of the
//! second sensor compared with the twin at the observer's temperature
//! carries that error: a chamber pressure moves 1-7 kPa per kelvin, 5-35
//! of its noise's standard deviations. The comparison made the other way
//! round carries none of it: the second sensor's reading gives the oil
//! temperature at which the device, as the health parameters say it is,
//! reads it; that temperature, sent through the probe's lag, predicts the
//! probe's reading, with nothing to invert. A change of the device (a
//! restricted capillary: the pressure says the oil warmed by kelvins, the
//! probe never follows) shows in the probe's innovation as the fault's
//! step through the lag; a true change of the oil shows in both and
//! cancels.
//!
//! Per reading of the second sensor, in this order:
//!
//! 1. **The sensor's temperature.** The twin (the nominal device of the
//!    parameter file, at the oil temperature of its Fluid job) gives its
//!    reading `y_twin` now; the health parameters `theta` move it by what
//!    they move the quasi-static reading at the twin's oil
//!    ([`signature`]: `y_pred = y_twin + h(theta) - h(0)`), and, for the
//!    displacement, a plunger held by friction stays in its play band
//!    ([`signature::play`]), then the stops clamp it. The reading `y` then
//!    says the oil is at `T_s = T_twin + (y - y_pred) / (dy/dT)`, `dy/dT` the
//!    reading's temperature sensitivity through the redistribution
//!    parameter (`dA/dT = A (nu'/nu + rho'/(2 rho))`). Where the reading
//!    hardly depends on the temperature (a plunger on a stop, held by
//!    friction, or reading less than [`MAX_TEMPERATURE_SD`] a kelvin per
//!    standard deviation of its noise) it says nothing: `T_s` is the
//!    twin's, and the reading counts as uninformed.
//! 2. **Through the probe's lag** ([`lag`]): `T_s`, its derivatives in the
//!    health parameters (the filter's Jacobian), each hypothesis'
//!    signature (step 4) and the uninformed indicator go through the
//!    probe's first-order lag (and the well's).
//! 3. **At a reading of the probe.** Its innovation is `nu = y_p -
//!    T_probe - beta (a + b |T|)` (`beta`: where the probe sits within
//!    its IEC 60751 tolerance, a health parameter), of variance `S = H P H'
//!    + R`: the probe's noise and quantization, the second sensor's noise
//!    through the lag, and the observer's error for the uninformed share of
//!    the lag's memory. A Kalman filter of the health parameters
//!    ([`filter`]: the divider `theta_A = ln(A / A_file)`, the spring
//!    `theta_k = ln(c / c_file)`, the reading's offset `delta`, the probe's
//!    `beta`, each a slow random walk, and the twin's error) updates with
//!    it; a change of the parameters moves the lagged temperature by the
//!    lagged Jacobian. The second sensor's noise through the lag is a state
//!    of the filter too, not a white noise: the lag remembers it for its
//!    time constant, and a probe whose time constant is comparable with the
//!    readings' period (a bare fast probe) passes as much of it as its own
//!    noise, correlated from one probe reading to the next ([`filter`],
//!    "The lag's noise"); taken as white it made the innovations of such a
//!    probe correlated (lag-1 0.17-0.30 at 0.01-0.05 s) and their variance
//!    wrong, and the CUSUM raised `DEVICE_CHANGED` on healthy devices. An
//!    innovation beyond [`GATE`] standard deviations is counted
//!    ([`HealthEstimate::rejected`]), not applied; with more than
//!    [`MAX_UNINFORMED`] of the lag's memory uninformed there is no test.
//! 4. **Detection.** A two-sided CUSUM of the standardised innovation
//!    `z = nu / sqrt(S)` ([`CUSUM_DRIFT`], [`CUSUM_THRESHOLD`]) says the
//!    device no longer behaves as the filter's device: `DEVICE_CHANGED`.
//! 5. **Isolation.** From the CUSUM run's start on (the change's onset), the
//!    innovations are fitted by each fault's signature alone, through the
//!    lag (a generalised likelihood ratio over the window, [`Hypothesis`]);
//!    the fault whose fit explains the innovations better than every
//!    other's by [`ISOLATION_MARGIN`] in log-likelihood, over at least
//!    [`ISOLATION_SPAN`] of oil temperature (sticking at any span: its
//!    signature is the probe less the lag of a held second sensor's
//!    temperature since its hold, through the play band, its amplitude
//!    bounded), is named (its flag latches), its parameter moves by the
//!    fitted size and its variance reopens, and watching resumes. While a
//!    change is detected and not yet isolated,
//!    or a CUSUM run is past a quarter of the threshold, the health
//!    parameters are held, so that the filter does not absorb the change it
//!    is trying to name; the lag's noise still follows the readings (a
//!    zero-mean state that forgets within the probe's time constant cannot
//!    absorb a change), or a held filter would make the innovations of a
//!    fast probe correlated just when a run has started. The model error
//!    decorrelates with the twin's oil temperature's travel.
//!
//! The second sensor's own faults (`crate::sensor::SensorFault`) skip its
//! reading and raise `SECOND_SENSOR_FAULT`; the lag then runs on the
//! twin's temperature (uninformed) and the tests pause.
//!
//! **Why not the twin's four states in the filter.** The twin's chamber
//! pressures and plunger settle within milliseconds
//! ([`crate::estimator::Plant::slowest_time_constant`]); the oil's
//! temperature, and with it every reading, moves over seconds. Over a
//! sensor period the fast states are slaved to the slow ones (singular
//! perturbation): an extended Kalman filter of `(x, v, p_a, p_b, theta)`
//! would carry a covariance of the fast states that is the quasi-static
//! image of `theta`'s, at four times the cost. The filter here keeps the
//! slow states; the twin supplies the fast ones' transient, the
//! quasi-static algebra the health parameters' effect on them, and the
//! second sensor the oil's temperature.
//!
//! What each sensor can tell apart, and the flags' confusions, are in the
//! project's `docs/monitoring.md`. Nothing here allocates or panics; a
//! non-finite input is a rejected reading.

pub mod filter;
pub mod lag;
pub mod signature;

pub use filter::HealthFilter;
pub use lag::ProbeModel;
pub use signature::{Design, Quantity, Reading};

use crate::equilibrium::a_parameter;
use crate::estimator::{Flags, clamp};
use crate::fluid::FluidPoint;
use crate::params::Params;
use crate::scalar::Real;
use filter::{Measured, NOISE, STATES};
use lag::{Decay, Lag};
use signature::{DIVIDER, MODEL, OFFSET, PARAMETERS, PROBE, SPRING, exp, play};

/// Standard deviations of the probe's innovation beyond which a reading is
/// not applied to the filter: `P(|z| > 6) = 2e-9` for a normal innovation,
/// below one a day at 50 readings a second.
pub const GATE: f32 = 6.0;

/// Drift `k` of the CUSUM, in innovation standard deviations: it detects
/// a shift of the innovation's mean by `2 k` fastest (Page 1954). The
/// innovations of healthy devices are close to white unit normal (over
/// the campaign's seeded histories: mean 0.00, variance 0.97, lag-1
/// correlation under 0.03 in magnitude, none beyond 5 standard deviations;
/// `cargo run --release -p host-tests --example monitor_innovations`; and
/// for probes from 0.01 s to 20 s, `tests/monitor_fast_probe.rs`), so
/// the drift need not cover a bias of the model.
pub const CUSUM_DRIFT: f32 = 1.0;

/// Threshold `h` of the CUSUM in innovation standard deviations. For a
/// white standardised innovation, Siegmund's approximation of the run
/// length to a false alarm, `exp(2 k (h + 1.166)) / (2 k^2)`, is 2e9
/// readings (a year and a half at 50 probe readings a second); the
/// largest value a healthy history reached is in `docs/monitoring.md`.
pub const CUSUM_THRESHOLD: f32 = 10.0;

/// Standardised innovations are clipped here in the CUSUM, so that one
/// reading alone (a spike the sensor's own checks let through) cannot
/// raise it: two such readings in a row are needed.
pub const CUSUM_CLIP: f32 = 8.0;

/// Margin in log-likelihood (`ln 10^3`) by which the named fault's fit must
/// beat every other fault's before its flag is raised.
pub const ISOLATION_MARGIN: f32 = 6.9;

/// Oil temperature span \[K\] the isolation window must cover before a
/// fault is named: at one temperature every fault's signature is one
/// number, and the faults are told apart by how their signatures change
/// with the temperature. A transducer's offset is constant in the
/// reading, a divider's change is not, and over the first kelvin the two
/// differ by less than the change's onset misfits them: at 1 K a 20 %
/// restriction was named an offset on one design of 41, 1 s into its
/// 5 C move (`cargo run --release -p host-tests --example monitor_campaign
/// -- 40 1 1.0 p_a 0.05 capillary:0.8`: 35 of 36 eligible designs within
/// 60 s at 1 K, 36 of 36 at 3 K, median 26 s after the onset either way).
/// 3 K leaves the 5 C move the 60 s goal allows its last 2 K for the
/// probe's lag. Over the campaign's 11 designs (`-- 10 1 1.5 p_a,dp_ab`,
/// `docs/monitoring.md`) 3 and 5 K name the same faults as 1 K but one on
/// `p_a` (an orifice clogged to 0.9, named an offset at 1 K, 11 s after
/// its onset and before the move), none other on `dp_ab`; 5 K waits for
/// the move's end (an orifice clogged to 0.8 named 442 s after its onset,
/// 295 s at 3 K).
pub const ISOLATION_SPAN: f32 = 3.0;

/// Relative error of a fault's signature, systematic over the isolation's
/// window (the nominal design's shape against the device's as built, the
/// linearisation, the onset's timing): a misfit this large does not
/// average down with more readings, so another fault is ruled out only
/// when its fit is worse than the named one's by more than this error of
/// the whole signal could make it, `MODEL_ERROR^2 sum(nu^2 / S) / 2` in
/// log-likelihood on top of [`ISOLATION_MARGIN`]. A large fault, far above
/// the noise, is named once the temperature has spread the signatures
/// apart by more than the model's error, not by chance of its misfit.
/// Measured over the campaign's seeded designs (`cargo run --release -p
/// host-tests --example monitor_campaign -- 10 1 1.5 p_a`, docs/monitoring.md):
/// at 1 % a divider's fault is named against the other divider fault
/// wrongly in 2 of 66 runs and a 20 % restriction within 60 s of a 5 C
/// move on every design; at 2 %, 1 wrong in 66 and 78 % within 60 s (the
/// rest need 20-40 C of travel). The as-built spreads of a capillary's or
/// an orifice's bore scale `A` alone, which the divider's parameter takes
/// whole: what is left is the linearisation and the onset's timing.
pub const MODEL_ERROR: f32 = 0.01;

/// Probe readings after a fault is named during which the filter takes
/// every reading (no gate, no test): it settles on the fault's size from
/// the tests' fit, whose linearisation at the old parameters is off by the
/// change's curvature.
pub const SETTLE_READINGS: u32 = 200;

/// The largest standard deviation \[K\] of the oil temperature one reading
/// of the second sensor may give for it to inform the probe's prediction
/// (its noise over its temperature sensitivity): a plunger near a stop
/// hardly moves with the oil.
pub const MAX_TEMPERATURE_SD: f32 = 2.0;

/// The farthest \[K\] the second sensor's temperature is taken from the
/// twin's: beyond the linearisation, a gross change of the device (a
/// capillary at half its conductance reads 14 K away).
pub const MAX_DEVIATION: f32 = 25.0;

/// The share of the probe lag's memory that may come from uninformed
/// readings (the twin's temperature) before the probe's readings are no
/// longer tested. The uninformed share stands for the oil with the twin's
/// temperature, which the observer takes from the probe itself: at a
/// quarter, the filter learned from the probe's own delayed readings (a
/// one-second open loop of the transducer on a healthy device at rest
/// shrank the divider's standard deviation by a third), and with the
/// learning held there the CUSUM took the share's error, a bias, for
/// evidence (2 false alarms in 16.5 h of `monitor_campaign -- 10 1 1.5
/// x`; `docs/monitoring.md`, "A plunger leaving its stop").
pub const MAX_UNINFORMED: f32 = 0.02;

/// The oil-temperature observer's largest error \[K\] behind a step of the
/// oil, which an uninformed share of the lag's memory carries into the
/// probe's prediction: 1.33 K over the campaign's histories (`cargo run
/// --release -p host-tests --example observer_error`).
pub const UNINFORMED_ERROR: f32 = 1.5;

/// Priors of the health parameters: standard deviations of a device as
/// built around its file (the divider's `A` goes with the capillary's bore
/// to the fourth power: 10 % is a 2.5 % bore; 5 % of a spring's rate).
pub const PRIOR_DIVIDER: f32 = 0.1;
/// Prior of `theta_k` (see [`PRIOR_DIVIDER`]).
pub const PRIOR_SPRING: f32 = 0.05;
/// Prior of the displacement's offset as a fraction of the stroke (the
/// preload's and the sensor's zero), on top of the sensor's accuracy.
pub const PRIOR_OFFSET_STROKES: f32 = 0.02;
/// Prior of the probe's place within its tolerance: uniform over `[-1,
/// 1]`, standard deviation `1 / sqrt(3)` (GUM 4.3.7).
pub const PRIOR_PROBE: f32 = 0.577_350_3;

/// Random-walk drift of the health parameters per square root of an hour:
/// the device's slow wear and the probe's ageing, which the filter follows
/// without a flag.
pub const DRIFT_PER_SQRT_HOUR: [f32; PARAMETERS] = [0.005, 0.002, 0.0, 0.01, 0.0];

/// The twin's own error in the second sensor's reading, a standard
/// deviation as a fraction of the stroke (displacement) or of `dp`
/// (pressures): the twin's accuracy goal at rest (`docs/dynamics.md`),
/// and the size of the slow device's lag behind its quasi-static
/// equilibrium in a warm-up (4-10 um of a 4.2 mm stroke on a seeded
/// design). A state (`MODEL`), not noise: it does not average down.
pub const MODEL_ACCURACY: f32 = 1e-3;

/// Oil temperature travel \[K\] over which the twin's error decorrelates
/// (the model-error state is Gauss-Markov in the temperature).
pub const MODEL_CORRELATION: f32 = 5.0;

/// The share of the probe lag's memory from its start at rest below which
/// the lag's noise is updated alone while the tests hold the parameters.
/// The start at rest puts the first reading's whole noise into the lag,
/// the filter takes it apart from the parameters only as they converge
/// from their priors, and an update of the noise alone while the two are
/// entangled moves the prediction along what the parameters would have
/// undone (a slow probe keeps that start for seconds).
pub const REST_FORGOTTEN: f32 = 0.01;

/// The friction the sticking test is designed for, as a fraction of the
/// spring's force at mid-stroke (`F = f c (x0 + x_max / 2)`): the play
/// band's half width of the fitted signature.
pub const STICKING_DESIGN: f32 = 0.05;

/// The stillness test's bound on a still reading's move, in standard
/// deviations of the difference of two readings (`sqrt 2` of the
/// sensor's noise): a held plunger's reading stays within it but once in
/// 1.7 million readings ([`Monitor::begin`]'s stillness test).
pub const STILL_READING: f32 = 5.0;

/// The free plunger's travel past a still reading that names sticking,
/// in half widths of the design's play band ([`STICKING_DESIGN`]): a
/// plunger held over that travel is held by at least the design's
/// friction, and one of the goal's (twice the design's) is named once it
/// lags half its band. A healthy reading follows the twin's travel within
/// its slope's as-built spread. At half of it the test named one more
/// design's sticking of 0.05 within 10 s of the hold (`monitor_campaign
/// -- 10 1 1.5 x`), and sticking on design 9's healthy device after a
/// step of its oil, where the probe and the observer's oil both still
/// had 0.55 K to catch up when the reading stopped
/// (`tests/monitor_seeded.rs`, `a_step_s_end_is_no_held_plunger`).
pub const STILL_TRAVEL: f32 = 1.0;

/// The largest friction the sticking test fits, in [`STICKING_DESIGN`]'s
/// play bands: the fitted width that `Monitor::confirm` enters, and the
/// bound of the test's amplitude (a held plunger's innovation is the
/// probe's travel through the true band, at most a few design bands).
const STICKING_MOST: f32 = 4.0;

/// What the monitor needs of its sensor (from the device file's
/// `[monitor]`) and of the oil-temperature probe (its `[probe]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MonitorSettings {
    /// What is measured.
    pub quantity: Quantity,
    /// Standard deviation of one reading's noise \[Pa or m\].
    pub sd_noise: f32,
    /// The sensor's accuracy as a standard uncertainty \[Pa or m\] (its class
    /// limit `a` of the span as `a / sqrt(3)`, GUM 4.3.7): the prior of the
    /// offset.
    pub sd_accuracy: f32,
    /// Time between readings \[s\].
    pub sample_period: f32,
    /// The oil-temperature probe ([`ProbeModel::new`] of the device file).
    pub probe: ProbeModel,
}

/// Why a monitor cannot be built: the setting named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MonitorError {
    /// The setting is not finite and positive (`monitor.noise`,
    /// `monitor.accuracy`, `monitor.sample_hz`, `probe.time_constant`,
    /// `probe.noise`).
    NotPositive(&'static str),
}

impl core::fmt::Display for MonitorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MonitorError::NotPositive(name) => write!(f, "{name} must be finite and positive"),
        }
    }
}

impl core::error::Error for MonitorError {}

/// A fault the isolation test fits: its flag, the parameter it moves (or
/// the play band) and the sign of the move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hypothesis {
    /// `theta_A` up: the capillary restricted, or the orifice worn.
    CapillaryRestricted,
    /// `theta_A` down: the orifice clogged, or the capillary eroded.
    OrificeClogged,
    /// `theta_k` down.
    SpringRelaxed,
    /// The offset up: for the displacement, the preload lost (or the
    /// sensor's zero moved up); for a pressure, the transducer's zero.
    OffsetUp,
    /// The offset down: the sensor's zero.
    OffsetDown,
    /// The plunger held by friction (the play band of [`STICKING_DESIGN`]).
    Sticking,
}

/// Hypotheses the isolation fits.
pub const HYPOTHESES: usize = 6;

/// The isolation's state ([`Monitor::isolation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isolation {
    /// Log-likelihood gain of each hypothesis' single-fault fit, in
    /// [`Hypothesis::ALL`]'s order (0 for an amplitude of the wrong sign).
    pub gain: [f32; HYPOTHESES],
    /// What the best gain must beat the next by to name its fault.
    pub margin: f32,
    /// The oil's span \[K\] over the run's tested readings.
    pub span: f32,
}

impl Hypothesis {
    /// Every hypothesis, in the accumulators' order.
    pub const ALL: [Hypothesis; HYPOTHESES] = [
        Hypothesis::CapillaryRestricted,
        Hypothesis::OrificeClogged,
        Hypothesis::SpringRelaxed,
        Hypothesis::OffsetUp,
        Hypothesis::OffsetDown,
        Hypothesis::Sticking,
    ];

    /// Its flag, for a sensor measuring `quantity`.
    pub fn flag(self, quantity: Quantity) -> Flags {
        match self {
            Hypothesis::CapillaryRestricted => Flags::CAPILLARY_RESTRICTED,
            Hypothesis::OrificeClogged => Flags::ORIFICE_CLOGGED,
            Hypothesis::SpringRelaxed => Flags::SPRING_RELAXED,
            Hypothesis::OffsetUp if quantity == Quantity::Displacement => Flags::PRELOAD_LOST,
            Hypothesis::OffsetUp | Hypothesis::OffsetDown => Flags::SENSOR_OFFSET,
            Hypothesis::Sticking => Flags::PLUNGER_STICKING,
        }
    }

    /// The sign of its signature's amplitude (its regressor is `sign *
    /// dy/dtheta`).
    fn sign(self) -> f32 {
        match self {
            Hypothesis::OrificeClogged | Hypothesis::SpringRelaxed | Hypothesis::OffsetDown => -1.0,
            _ => 1.0,
        }
    }

    /// Its signature's derivative in the reading: `sign * dy/dtheta` from
    /// the reading's Jacobian, or the sticking test's signature.
    fn derivative(self, jacobian: &[f32; PARAMETERS], sticking: f32) -> f32 {
        match self.parameter() {
            PARAMETERS => sticking,
            k => jacobian[k] * self.sign(),
        }
    }

    /// The health parameter it moves ([`PARAMETERS`] for the play band).
    fn parameter(self) -> usize {
        match self {
            Hypothesis::CapillaryRestricted | Hypothesis::OrificeClogged => DIVIDER,
            Hypothesis::SpringRelaxed => SPRING,
            Hypothesis::OffsetUp | Hypothesis::OffsetDown => OFFSET,
            Hypothesis::Sticking => PARAMETERS,
        }
    }
}

/// A reading of the oil-temperature probe the monitor has not yet seen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The reading \[C\], as the observer accepted it.
    pub value: f32,
    /// How long before the monitor's reading it was taken \[s\].
    pub age: f32,
}

/// What the monitor reads of the plant at a reading: the twin's oil and
/// state, the time since its last reading, and the probe's new reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantView {
    /// The twin's oil (its temperature and the temperature derivatives of
    /// viscosity and density).
    pub oil: FluidPoint<f32>,
    /// The twin's displacement \[m\].
    pub x: f32,
    /// The twin's chamber (a) pressure \[Pa\].
    pub p_a: f32,
    /// The twin's chamber (b) pressure \[Pa\].
    pub p_b: f32,
    /// Time since the monitor's previous reading \[s\] (ignored at the first).
    pub dt: f32,
    /// The probe's reading since the monitor's previous one, if any.
    pub probe: Option<ProbeSample>,
}

/// The monitor's estimate after a reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HealthEstimate {
    /// The divider factor `A / A_file = e^theta_A` (a restricted capillary
    /// or a worn orifice above 1).
    pub divider: f32,
    /// Standard deviation of `theta_A` (of the factor's logarithm).
    pub sd_divider: f32,
    /// The spring rate's factor `c / c_file` (1 for a pressure sensor,
    /// which does not see it).
    pub spring: f32,
    /// Standard deviation of `theta_k`.
    pub sd_spring: f32,
    /// The reading's offset \[Pa or m\].
    pub offset: f32,
    /// Its standard deviation \[Pa or m\].
    pub sd_offset: f32,
    /// The probe's error at the twin's oil temperature \[K\]: where it sits
    /// within its tolerance times the tolerance there.
    pub probe_bias: f32,
    /// Its standard deviation \[K\].
    pub sd_probe_bias: f32,
    /// The oil temperature the second sensor's reading gives through the
    /// health estimate \[C\] (the twin's where the reading does not depend
    /// on it).
    pub oil: f32,
    /// The friction force holding the plunger \[N\] (0 until sticking is
    /// isolated).
    pub friction: f32,
    /// The corrected reading the monitor predicted at the twin's oil
    /// temperature \[Pa or m\].
    pub predicted: f32,
    /// The standardised innovation of the probe's last reading tested.
    pub innovation: f32,
    /// The larger of the two CUSUM statistics (in innovation standard
    /// deviations).
    pub cusum: f32,
    /// Readings not applied: beyond the gate, not finite (saturating).
    pub rejected: u32,
    /// The monitor's flags: `DEVICE_CHANGED`, the faults isolated so far
    /// (latched), `SECOND_SENSOR_FAULT` for this reading,
    /// `INNOVATION_REJECTED`.
    pub flags: Flags,
}

impl HealthEstimate {
    /// No monitor, or no reading yet: every value NaN, nothing rejected, no flag.
    pub const NONE: HealthEstimate = HealthEstimate {
        divider: f32::NAN,
        sd_divider: f32::NAN,
        spring: f32::NAN,
        sd_spring: f32::NAN,
        offset: f32::NAN,
        sd_offset: f32::NAN,
        probe_bias: f32::NAN,
        sd_probe_bias: f32::NAN,
        oil: f32::NAN,
        friction: f32::NAN,
        predicted: f32::NAN,
        innovation: f32::NAN,
        cusum: f32::NAN,
        rejected: 0,
        flags: Flags::empty(),
    };
}

/// The lag's signals: the second sensor's temperature, its derivatives in
/// the first three health parameters, each hypothesis' signature, the
/// uninformed indicator.
const OIL: usize = 0;
const D_THETA: usize = 1;
const SIGNATURE: usize = D_THETA + OFFSET + 1;
const UNINFORMED: usize = SIGNATURE + HYPOTHESES;
/// The sticking test's signature (the last hypothesis): it runs through
/// the lag at every reading, not from a run's start (`Monitor::predict`).
const HELD: usize = UNINFORMED - 1;
const _: () = assert!(matches!(Hypothesis::ALL[HYPOTHESES - 1], Hypothesis::Sticking));
const SIGNALS: usize = UNINFORMED + 1;

/// The condition monitor (see the module docs). `f32`; one reading costs
/// two exponentials and a square root (three more of each while a change
/// is being isolated), the lag of 11 signals, the lag's noise state's
/// step, and at a probe reading a 6-state filter update.
#[derive(Clone, Copy, Debug)]
pub struct Monitor {
    design: Design,
    settings: MonitorSettings,
    /// The file's spring rate `c` \[N/m\].
    spring_rate: f32,
    filter: HealthFilter,
    /// The probe's lag of the signals, and its decay for the last step.
    lag: Lag<SIGNALS>,
    decay: Decay,
    /// The variance of the second sensor's temperature's noise at the
    /// last reading \[K^2\] (0: uninformed), which drives the lag's noise
    /// at the next step ([`filter`]).
    last_fresh: f32,
    /// The last update, if at the last reading: its Jacobian, measurement
    /// noise variance, residual after the update, and the share `c` of the
    /// reading's noise in it; its measurement noise drives the lag's noise
    /// at the next step.
    correlated: Option<(Measured, f32)>,
    /// The share of the probe lag's memory still from its start at rest
    /// (`p^k` after `k` steps).
    rest_share: f32,
    /// The first reading has set the lag at rest.
    started: bool,
    /// The play band's half width of an isolated sticking fault \[m\].
    friction_width: f32,
    /// Where the monitor's plunger is held by that friction \[m\].
    held: f32,
    /// Half width of the sticking test's play band \[m\].
    design_width: f32,
    /// The sticking test's own held plunger \[m\]: where the free plunger
    /// stood when the oil last rested, played through the design band
    /// since.
    test_held: f32,
    /// The free plunger's position at the last reading \[m\], and its
    /// change per reading averaged over the probe lag's memory \[m\]: the
    /// oil rests while that change over the memory stays within the
    /// reading's noise and the twin's accuracy.
    last_free: f32,
    free_change: f32,
    /// The oil rested at the last reading (see `last_free`).
    resting: bool,
    /// The stillness test's anchor: the reading \[m\] and the twin's
    /// plunger \[m\] when the reading last moved (NaN: none).
    still_reading: f32,
    still_twin: f32,
    /// The probe's reading at the anchor \[C\], and its last \[C\].
    still_probe: f32,
    probe_now: f32,
    /// How far the observer's oil stood from the probe at the anchor \[K\].
    still_gap: f32,
    /// The design band's half width in oil temperature at the last
    /// informed reading \[K\] (`design_width / |dy/dT|`).
    width_oil: f32,
    /// The sticking test in the probe's terms: the probe's corrected
    /// reading before this one \[C\], and the probe's reading predicted
    /// then for a held second sensor \[C\].
    last_probe: f32,
    last_held: f32,
    /// The temperature a held second sensor gives \[C\] (NaN: no hold),
    /// played through the design band on the twin's oil moved to where
    /// the second sensor's temperature stood at the hold (`held_shift`,
    /// \[K\]).
    held_oil: f32,
    held_shift: f32,
    /// The lag of the temperature the held second sensor gives, from the
    /// lagged temperature's at the hold.
    held_lag: Lag<1>,
    /// The sticking test's evidence since its hold, `sum g nu / S` (its
    /// sign renews the hold).
    held_fit: f32,
    /// CUSUM statistics for innovations up and down.
    cusum: [f32; 2],
    /// The change is detected (`DEVICE_CHANGED`) and not yet isolated.
    detected: bool,
    /// Isolation sums over the CUSUM's run: per hypothesis `sum g nu / S`
    /// and `sum g^2 / S`.
    fit_b: [f32; HYPOTHESES],
    fit_c: [f32; HYPOTHESES],
    /// `sum nu^2 / S` over the run: the signal's energy.
    energy: f32,
    /// `sum b^2 / S` over the run, `b` the twin's transient through the
    /// probe's lag (`twin_bias`): a bias of the probe's prediction that
    /// does not average down, whose share of the fits' gap the margin
    /// counts ([`Monitor::isolated`]).
    bias_energy: f32,
    /// The standardised innovation of the probe's last reading tested.
    innovation: f32,
    latched: Flags,
    rejected: u32,
    /// Readings left of the settling after a named fault.
    settling: u32,
    /// The oil temperatures the isolation window spans \[C\].
    window: (f32, f32),
    /// The parameters whose temperature sensitivity turns a reading into
    /// the second sensor's temperature: the file's device, then each named
    /// fault's.
    reference: [f32; PARAMETERS],
    /// The model-error state's stationary standard deviation \[Pa or m\].
    sd_model: f32,
    /// The farthest the sensor's zero may sit from the file's \[Pa or m\]:
    /// its class limit (`sqrt 3` of its standard uncertainty), and each
    /// offset named since ([`Monitor::at_stop`]).
    zero_limit: f32,
    /// The twin's oil temperature at the last reading \[C\].
    last_oil: f32,
    /// The twin's transient in the second sensor's temperature \[K\]
    /// (`|y_twin - y_eq| / |dy/dT|`), through the probe's lag: a standard
    /// deviation of the probe's prediction that does not average down
    /// ([`Monitor::begin`]).
    twin_bias: f32,
    /// The reading's stages not yet run ([`Monitor::begin`]).
    pending: Pending,
}

/// What a reading begun by [`Monitor::begin`] has left to run, and what it
/// carries to those stages.
#[derive(Clone, Copy, Debug)]
struct Pending {
    /// The hypotheses' signatures, and their signals' step through the lag.
    signatures: Option<SignatureInputs>,
    /// The signatures' signals step through the lag (the step's other
    /// signals have).
    step: bool,
    /// The probe's reading to test, and the twin's oil temperature \[C\].
    test: Option<(ProbeSample, f32)>,
    /// The sticking test's signature of this reading (zero for a reading
    /// that does not inform), which steps through the lag whether a
    /// change is watched or not.
    held: f32,
    /// The hypotheses' signatures of this reading at the filter's
    /// parameters (their derivatives, `inv dy/dtheta`), zero for a reading
    /// that does not inform: what a change's test seeds the signatures'
    /// lag with when it starts at this reading.
    onset: [f32; HYPOTHESES],
    /// The reading's prediction, the second sensor's temperature \[C\],
    /// its flags so far and the twin's oil temperature \[C\]; `None`:
    /// nothing pending.
    estimate: Option<(f32, f32, Flags, f32)>,
}

/// What [`Monitor::signatures`] takes: `-1 / (dy/dT)`, the
/// redistribution parameter, the filter's parameters and the reading
/// there, the reading's Jacobian, the sticking test's signature.
#[derive(Clone, Copy, Debug)]
struct SignatureInputs {
    inv: f32,
    a: f32,
    theta: [f32; PARAMETERS],
    value: f32,
    jacobian: [f32; PARAMETERS],
    sticking: f32,
}

impl Pending {
    const NONE: Pending = Pending {
        signatures: None,
        step: false,
        test: None,
        held: 0.0,
        onset: [0.0; HYPOTHESES],
        estimate: None,
    };
}

impl Monitor {
    /// A monitor of the device `params` with its sensor `settings`, its
    /// health parameters at their priors around the file's device.
    ///
    /// # Errors
    ///
    /// [`MonitorError::NotPositive`] naming the device file's field of a
    /// setting that is not finite and positive.
    pub fn new(params: &Params<f32>, settings: MonitorSettings) -> Result<Self, MonitorError> {
        let positive = |v: f32, name| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(MonitorError::NotPositive(name))
            }
        };
        positive(settings.sd_noise, "monitor.noise")?;
        positive(settings.sd_accuracy, "monitor.accuracy")?;
        positive(settings.sample_period, "monitor.sample_hz")?;
        positive(settings.probe.time_constant, "probe.time_constant")?;
        positive(settings.probe.reading_sd, "probe.noise")?;
        if !(settings.probe.well_time_constant >= 0.0 && settings.probe.well_time_constant.is_finite()) {
            return Err(MonitorError::NotPositive("probe.well_time_constant"));
        }
        let plunger = &params.plunger;
        let design = Design {
            quantity: settings.quantity,
            dp: params.pressure_drop,
            sqrt_dp: <f32 as Real>::sqrt(params.pressure_drop),
            p_c: params.outlet_pressure,
            compliance: plunger.compliance(),
            preload: plunger.preload,
            stroke: plunger.stroke,
        };
        let sd_offset = match settings.quantity {
            Quantity::Displacement => <f32 as Real>::sqrt(
                settings.sd_accuracy * settings.sd_accuracy
                    + (PRIOR_OFFSET_STROKES * plunger.stroke) * (PRIOR_OFFSET_STROKES * plunger.stroke),
            ),
            _ => settings.sd_accuracy,
        };
        let mut drift = [0.0; PARAMETERS];
        for (d, per) in drift.iter_mut().zip(DRIFT_PER_SQRT_HOUR) {
            *d = per * per;
        }
        let sd_model = MODEL_ACCURACY
            * match settings.quantity {
                Quantity::Displacement => plunger.stroke,
                _ => params.pressure_drop,
            };
        let filter = HealthFilter::new([PRIOR_DIVIDER, PRIOR_SPRING, sd_offset, PRIOR_PROBE, sd_model], drift);
        Ok(Monitor {
            design,
            settings,
            spring_rate: plunger.spring_rate,
            filter,
            lag: Lag::at_rest([0.0; SIGNALS]),
            decay: Decay::new(&settings.probe, settings.sample_period),
            last_fresh: 0.0,
            correlated: None,
            rest_share: 1.0,
            started: false,
            friction_width: 0.0,
            held: f32::NAN,
            design_width: STICKING_DESIGN * (plunger.preload + 0.5 * plunger.stroke),
            test_held: f32::NAN,
            last_free: f32::NAN,
            free_change: 0.0,
            resting: false,
            still_reading: f32::NAN,
            still_twin: f32::NAN,
            still_probe: f32::NAN,
            probe_now: f32::NAN,
            still_gap: 0.0,
            width_oil: 0.0,
            last_probe: f32::NAN,
            last_held: f32::NAN,
            held_oil: f32::NAN,
            held_shift: 0.0,
            held_lag: Lag::at_rest([f32::NAN]),
            held_fit: 0.0,
            cusum: [0.0; 2],
            detected: false,
            fit_b: [0.0; HYPOTHESES],
            fit_c: [0.0; HYPOTHESES],
            energy: 0.0,
            bias_energy: 0.0,
            innovation: f32::NAN,
            latched: Flags::empty(),
            rejected: 0,
            settling: 0,
            window: (f32::NAN, f32::NAN),
            reference: [0.0; PARAMETERS],
            sd_model,
            zero_limit: 1.732_050_8 * settings.sd_accuracy,
            last_oil: f32::NAN,
            twin_bias: 0.0,
            pending: Pending::NONE,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &MonitorSettings {
        &self.settings
    }

    /// The health filter.
    pub fn filter(&self) -> &HealthFilter {
        &self.filter
    }

    /// Clears the latched faults and restarts the health parameters at
    /// their priors (after the device's maintenance, or an inspection that
    /// found the device healthy).
    ///
    /// The probe's lag is kept: it holds the oil's recent past, which a
    /// reset does not change, with the parameters' change taken back
    /// through the lagged Jacobians (as the filter's updates move it), and
    /// the lag's noise. A lag restarted at rest on the current reading
    /// predicts a probe at the oil's temperature; in a ramp the probe
    /// trails it by the rate times its time constant (0.3 C/s through an
    /// 8 s probe: 2.4 K), which the restarted filter took for a fault and
    /// alarmed on again within a second, reset after reset.
    pub fn reset(&mut self, params: &Params<f32>) {
        let Ok(mut m) = Monitor::new(params, self.settings) else {
            return;
        };
        if self.started {
            let theta = self.filter.theta();
            let mut lag = self.lag;
            for (k, t) in theta.iter().enumerate().take(OFFSET + 1) {
                lag.add_scaled(OIL, D_THETA + k, -t);
            }
            lag.add_scaled(OIL, D_THETA + OFFSET, -theta[MODEL]);
            for i in SIGNATURE..UNINFORMED {
                lag.clear(i);
            }
            m.lag = lag;
            m.decay = self.decay;
            m.started = true;
            m.filter.restart_noise(self.filter.covariance()[NOISE][NOISE]);
            m.filter.shift(NOISE, self.filter.noise());
            m.last_fresh = self.last_fresh;
            m.rest_share = self.rest_share;
            m.twin_bias = self.twin_bias;
            m.last_oil = self.last_oil;
        }
        *self = m;
    }

    /// The twin's reading of the measured quantity (`x` for the
    /// displacement).
    fn twin_reading(&self, view: &PlantView) -> f32 {
        match self.design.quantity {
            Quantity::ChamberA => view.p_a,
            Quantity::ChamberB => view.p_b,
            Quantity::Difference => view.p_b - view.p_a,
            Quantity::Displacement => view.x,
        }
    }

    /// The stillness test (a displacement sensor's, until a friction is
    /// named): a plunger held by friction reads still while the free
    /// plunger travels. Its anchor is where reading `y` \[m\] last moved
    /// (by more than [`STILL_READING`] standard deviations of the
    /// difference of two readings), stood at a stop, or had no finite
    /// probe reading or observer's oil beside it: the reading there, the
    /// twin's plunger (`twin` \[m\]) and the probe's reading. The free
    /// plunger's travel since is the smaller of two that agree in sign:
    /// the twin's, whose oil is the observer's (`oil` \[C\]), which
    /// overshoots a ramp's end by up to a kelvin (on design 3 of the
    /// campaign, at the end of a 0.9 C/s warming, it moved the twin 2.2e-5
    /// m, more than the design band's half width, past a reading that had
    /// stopped with the oil); and the probe's, through `dy_dt` \[m/K\],
    /// less what the probe still had to catch up with the observer's oil
    /// at the anchor (after a ramp's end the probe goes on by the ramp's
    /// rate times its time constant). Once that travel reaches
    /// [`STILL_TRAVEL`] of the design band's half width (and 4 still
    /// bounds, for a sensor whose noise is that wide), sticking is named:
    /// the play band's half width, the travel, enters the prediction, the
    /// monitor's plunger held where the reading stands. The
    /// band's half width is at least the travel if the plunger stood at
    /// its middle at the anchor (at rest), at least half of it if at its
    /// edge (dragged, then reversed): `HealthEstimate::friction` may be up
    /// to twice the friction. `offset` \[m\]: the filter's, for the stops
    /// ([`Monitor::at_stop`]). Returns whether it named sticking.
    ///
    /// The probe-lag sticking test of the isolation sees a held plunger
    /// only through the probe's lag and once the CUSUM runs, while the
    /// filter learns its first readings as an offset; this one reads the
    /// displacement itself (`docs/monitoring.md`, "The stillness test").
    fn held_still(&mut self, y: f32, twin: f32, offset: f32, dy_dt: f32, oil: f32) -> bool {
        if self.design.quantity != Quantity::Displacement || self.friction_width > 0.0 || !twin.is_finite() {
            return false;
        }
        let moved = STILL_READING * core::f32::consts::SQRT_2 * self.settings.sd_noise;
        if !self.still_reading.is_finite()
            || !self.still_probe.is_finite()
            || !self.still_gap.is_finite()
            || libm::fabsf(y - self.still_reading) > moved
            || self.at_stop(y, offset)
        {
            self.still_reading = y;
            self.still_twin = twin;
            self.still_probe = self.probe_now;
            self.still_gap = libm::fabsf(oil - self.probe_now);
            return false;
        }
        // The free plunger's travel since: the twin's (its oil the
        // observer's, which overshoots a ramp's end by up to a kelvin) and
        // the probe's (which trails the oil), the smaller when they agree.
        let by_twin = twin - self.still_twin;
        let dp = self.probe_now - self.still_probe;
        let by_probe = dy_dt * libm::copysignf(libm::fmaxf(libm::fabsf(dp) - self.still_gap, 0.0), dp);
        let travel = if by_twin * by_probe > 0.0 {
            libm::fminf(libm::fabsf(by_twin), libm::fabsf(by_probe))
        } else {
            0.0
        };
        if !(travel >= STILL_TRAVEL * self.design_width) || travel < 4.0 * moved {
            return false;
        }
        // The monitor's plunger is held where the reading stands (its
        // prediction is the reading's); released to the free plunger, it
        // stood the whole travel off the held reading.
        self.friction_width = travel;
        self.held = y;
        self.restart_tests();
        true
    }

    /// A displacement reading `y` within three standard deviations (its
    /// noise and the twin's accuracy) of a stop, or beyond it: the plunger
    /// may rest there whatever the oil does. Where the stop reads is
    /// known only between the reading as read and the reading less the
    /// estimated `offset`: the offset is the sensor's zero and the
    /// device's own (a preload or a spring built off the file's) alike,
    /// and only the sensor's zero moves where a stop reads. Taken as the
    /// sensor's zero alone, an offset learned on a device that leaves its
    /// stop late made the readings at the stop look informed, which
    /// taught the filter more of the same offset.
    ///
    /// The sensor's zero is within its class (`sqrt 3` of its standard
    /// uncertainty, the uniform limit), and an offset named since: what
    /// the filter holds beyond it is the device's. Taken whole, an offset
    /// the filter learned while the plunger was held (along what one
    /// temperature cannot tell apart: the divider, the probe's error and
    /// the offset, 70 times the sensor's class in 20 s of a slow cooling)
    /// put a held plunger's reading at the stop, and the tests never
    /// resumed.
    fn at_stop(&self, y: f32, offset: f32) -> bool {
        if self.design.quantity != Quantity::Displacement {
            return false;
        }
        let sd = self.settings.sd_noise + self.sd_model;
        let zero = clamp(offset, -self.zero_limit, self.zero_limit);
        let (low, high) = if zero > 0.0 { (zero, 0.0) } else { (0.0, zero) };
        !(y - low > 3.0 * sd && y - high < self.design.stroke - 3.0 * sd)
    }

    /// A change is being watched or isolated: the hypotheses' signatures
    /// run through the lag.
    fn running(&self) -> bool {
        self.detected || self.cusum[0] > 0.0 || self.cusum[1] > 0.0
    }

    /// One reading `measured` (`Err`: the sensor's own checks refused it)
    /// of the second sensor, with the plant as it is now and the probe's
    /// reading since the last (see the module docs): [`Monitor::begin`],
    /// then [`Monitor::advance`] until the reading is done.
    pub fn update<E>(&mut self, params: &Params<f32>, view: &PlantView, measured: Result<f32, E>) -> HealthEstimate {
        self.begin(params, view, measured);
        // Two stages at most after the beginning (the signatures, the test).
        let mut done = None;
        for _ in 0..2 {
            done = self.advance();
            if done.is_some() {
                break;
            }
        }
        done.unwrap_or(HealthEstimate::NONE)
    }

    /// Whether a reading begun by [`Monitor::begin`] has stages left.
    pub fn pending(&self) -> bool {
        self.pending.estimate.is_some()
    }

    /// The next stage of the reading begun by [`Monitor::begin`]: the
    /// hypotheses' signatures through the lag (while a change is watched),
    /// then the probe's test and the filter; `Some` with the reading's
    /// health estimate once done (then and without a reading pending:
    /// [`Monitor::update`]'s estimate). The stages split a reading's cost
    /// over ticks (the worst about 900 instructions on the Cortex-M4F,
    /// `cargo xtask bench`); run one after the other, they are
    /// [`Monitor::update`], bit for bit.
    pub fn advance(&mut self) -> Option<HealthEstimate> {
        let (predicted, oil, mut flags, t_twin) = self.pending.estimate?;
        let mut estimate = HealthEstimate {
            predicted,
            innovation: self.innovation,
            oil,
            ..HealthEstimate::NONE
        };
        if let Some(g) = self.pending.signatures.take() {
            let mut u = [0.0f32; SIGNALS];
            self.signatures(&mut u, g.inv, (g.a, &g.theta, g.value), &g.jacobian, g.sticking);
            if self.pending.step {
                self.lag.step_signals(&u, &self.decay, SIGNATURE..UNINFORMED);
            }
            self.pending.step = false;
            return None;
        }
        if self.pending.step {
            // No signature this reading: their signals step with zero but
            // the sticking test's.
            let mut u = [0.0f32; SIGNALS];
            u[HELD] = self.pending.held;
            self.lag.step_signals(&u, &self.decay, SIGNATURE..UNINFORMED);
            self.pending.step = false;
        }
        if let Some((sample, t)) = self.pending.test.take() {
            let onset = self.pending.onset;
            self.test(sample, t, &onset, &mut estimate, &mut flags);
        }
        self.pending = Pending::NONE;
        Some(self.publish(estimate, flags, t_twin))
    }

    /// Begins one reading (see [`Monitor::update`]): the prediction, the
    /// second sensor's temperature and the lag's step of its signals but
    /// the signatures'; the rest waits for [`Monitor::advance`]. A reading
    /// still pending is finished first.
    pub fn begin<E>(&mut self, params: &Params<f32>, view: &PlantView, measured: Result<f32, E>) {
        for _ in 0..2 {
            if self.advance().is_some() {
                break;
            }
        }
        let mut flags = self.latched;
        let a = a_parameter(params, &view.oil.state);
        let theta = self.filter.theta();
        let now = self.design.reading(a, &theta);
        let nominal = self.design.reading(a, &[0.0; PARAMETERS]);
        let twin = self.twin_reading(view);
        // The twin's transient (its distance from its own equilibrium) on
        // the device's equilibrium.
        let (predicted, jacobian, sticking) = self.predict(twin, &now, &nominal);
        // dy/dT through A: dA/dT = A (nu'/nu + rho'/(2 rho)).
        let point = &view.oil;
        let dln_a = point.viscosity.d1 / point.viscosity.value + 0.5 * point.density.d1 / point.density.value;
        // The temperature sensitivity at the reference parameters, not the
        // filter's: `T_s` must be linear in the parameters the filter
        // moves, or a move along what one temperature cannot tell apart
        // (the divider against the probe's error) changes `T_s` through
        // the slope and the filter runs away along it. For the same reason
        // no Jacobian here may carry this reading's noise.
        let slope = if self.reference == [0.0; PARAMETERS] {
            nominal.jacobian[DIVIDER]
        } else {
            self.design.reading(a, &self.reference).jacobian[DIVIDER]
        };
        let dy_dt = if jacobian[DIVIDER] == 0.0 { 0.0 } else { slope * dln_a };
        let t_twin = point.state.temperature;
        let mut estimate = HealthEstimate {
            predicted,
            innovation: self.innovation,
            ..HealthEstimate::NONE
        };
        let reading = match measured {
            Ok(y) if y.is_finite() => Some(y),
            Ok(_) => {
                self.rejected = self.rejected.saturating_add(1);
                flags.insert(Flags::INNOVATION_REJECTED);
                None
            }
            Err(_) => {
                flags.insert(Flags::SECOND_SENSOR_FAULT);
                None
            }
        };
        if let Some(p) = view.probe.filter(|p| p.value.is_finite()) {
            self.probe_now = p.value;
        }
        if let Some(y) = reading
            && self.held_still(y, twin, theta[OFFSET], dy_dt, view.oil.state.temperature)
        {
            flags.insert(Hypothesis::Sticking.flag(self.design.quantity));
        }
        // The second sensor's temperature and the signals the lag carries.
        // The twin's transient (its distance from its own equilibrium) is
        // the device's only as far as the twin's dynamics are the device's:
        // it counts as the reading's error too, so that a twin settling
        // slowly (near a stop, after a step) does not move the parameters.
        let transient = match self.design.quantity {
            Quantity::Displacement => twin - clamp(nominal.value, 0.0, self.design.stroke),
            _ => twin - nominal.value,
        };
        let noise = self.settings.sd_noise;
        let spread = noise * noise + transient * transient;
        let sd_t = <f32 as Real>::sqrt(spread) / libm::fabsf(dy_dt);
        let mut u = [0.0f32; SIGNALS];
        u[OIL] = t_twin;
        let mut signatures = None;
        let mut onset = [0.0f32; HYPOTHESES];
        let mut held_signature = 0.0f32;
        let informed = match reading {
            Some(y)
                if sd_t < MAX_TEMPERATURE_SD
                    && predicted.is_finite()
                    && t_twin.is_finite()
                    && !self.at_stop(y, theta[OFFSET]) =>
            {
                let inv = -1.0 / dy_dt;
                // The twin's transient is the device's only as far as the
                // twin's drive (the observer's oil temperature, whose rate is
                // off by tenths of a kelvin a second at a ramp's knee) is the
                // oil's: through a plunger as slow as a second (the seeded
                // designs' slowest time constants reach 1.4 s) it moves the
                // second sensor's temperature by tenths of a kelvin for
                // seconds, a bias the probe's lag passes whole, not a noise
                // it averages down. Its size through the lag is a standard
                // deviation of the probe's prediction (`test`).
                let bias = libm::fabsf(transient * inv);
                if bias.is_finite() {
                    let p = self.decay.probe;
                    self.twin_bias = p * self.twin_bias + (1.0 - p) * bias;
                }
                let d = clamp((y - predicted) * -inv, -MAX_DEVIATION, MAX_DEVIATION);
                u[OIL] = t_twin + d;
                for k in 0..=OFFSET {
                    u[D_THETA + k] = jacobian[k] * inv;
                }
                for (o, h) in onset.iter_mut().zip(Hypothesis::ALL) {
                    *o = h.derivative(&jacobian, sticking) * inv;
                }
                held_signature = sticking * inv;
                let width = self.design_width * libm::fabsf(inv);
                if width.is_finite() {
                    self.width_oil = width;
                }
                if self.running() {
                    signatures = Some(SignatureInputs {
                        inv,
                        a,
                        theta,
                        value: now.value,
                        jacobian,
                        sticking,
                    });
                }
                true
            }
            _ => {
                u[UNINFORMED] = 1.0;
                self.twin_bias *= self.decay.probe;
                false
            }
        };
        estimate.oil = u[OIL];
        let mut step = false;
        if !self.started {
            if !u[OIL].is_finite() {
                self.pending = Pending {
                    estimate: Some((estimate.predicted, estimate.oil, flags, t_twin)),
                    ..Pending::NONE
                };
                return;
            }
            if let Some(g) = signatures.take() {
                self.signatures(&mut u, g.inv, (g.a, &g.theta, g.value), &g.jacobian, g.sticking);
            }
            // The lag at rest holds all of this reading's noise, `x_0 = n_0`:
            // its Markov part is `e_0 = (1 - c) n_0` ([`filter`]).
            let fresh = if informed { sd_t * sd_t } else { 0.0 };
            let c = 0.5 * (1.0 - self.decay.probe);
            self.filter.restart_noise((1.0 - c) * (1.0 - c) * fresh);
            self.last_fresh = fresh;
            self.lag = Lag::at_rest(u);
            self.started = true;
        } else if view.dt > 0.0 && view.dt.is_finite() {
            if view.dt != self.decay.h {
                self.decay = Decay::new(&self.settings.probe, view.dt);
            }
            self.lag.step_signals(&u, &self.decay, OIL..SIGNATURE);
            self.lag.step_signals(&u, &self.decay, UNINFORMED..SIGNALS);
            step = true;
            if self.held_oil.is_finite() && t_twin.is_finite() {
                self.held_oil = play(self.held_oil, t_twin + self.held_shift, self.width_oil);
                self.held_lag.step(&[self.held_oil], &self.decay);
            }
            // The lag's noise: `e_k = p e_(k-1) + c (1 + p) n_(k-1)`.
            let p = self.decay.probe;
            let drive = 0.5 * (1.0 - p) * (1.0 + p);
            let q = drive * drive * self.last_fresh;
            self.rest_share *= p;
            match self.correlated.take() {
                // The last update's measurement noise held `-c n_(k-1)`.
                Some((last, c)) => {
                    let m = -drive * c * self.last_fresh;
                    self.filter.fade_correlated(NOISE, p, q, m, &last);
                }
                None => self.filter.fade(NOISE, p, q),
            }
            self.last_fresh = if informed { sd_t * sd_t } else { 0.0 };
            self.filter.predict(view.dt * (1.0 / 3600.0));
        }
        // The model error decorrelates with the oil's travel, the
        // observer's included: a play that held it correlated through the
        // observer's overshoot at a ramp's knee (a few tenths of a kelvin
        // for a few seconds) took the twin's transient there for a device
        // change (`tests/monitor_seeded.rs`).
        let held = t_twin;
        let travel = libm::fabsf(held - self.last_oil);
        if travel > 0.0 && self.started {
            let phi = exp(-travel * (1.0 / MODEL_CORRELATION));
            self.filter.decay(MODEL, phi, self.sd_model * self.sd_model);
        }
        if held.is_finite() {
            self.last_oil = held;
        }
        self.pending = Pending {
            signatures: if step { signatures } else { None },
            step,
            test: view.probe.map(|sample| (sample, t_twin)),
            held: held_signature,
            onset,
            estimate: Some((estimate.predicted, estimate.oil, flags, t_twin)),
        };
    }

    /// The hypotheses' signatures on the second sensor's temperature
    /// (`inv = -1 / (dy/dT)`) into `u`. A fault's signature is the secant
    /// of the reading over the fault's size fitted so far (`(h(theta +
    /// delta e_k) - h(theta)) / delta`, the derivative while the size is not
    /// yet known): the reading is not linear in the divider or the spring
    /// over a fault's size, and the derivative's shape at the old
    /// parameters would favour the wrong fault. `at` is the redistribution
    /// parameter, the filter's parameters and the reading there.
    fn signatures(
        &self,
        u: &mut [f32; SIGNALS],
        inv: f32,
        at: (f32, &[f32; PARAMETERS], f32),
        jacobian: &[f32; PARAMETERS],
        sticking: f32,
    ) {
        let (a, theta, value) = at;
        for (i, h) in Hypothesis::ALL.iter().enumerate() {
            let k = h.parameter();
            let g = if k == PARAMETERS || k == OFFSET || jacobian[k] == 0.0 || !(self.fit_c[i] > 0.0) {
                h.derivative(jacobian, sticking)
            } else {
                // The size fitted so far, by the fault's sign (at least a
                // hundredth, where the secant is the derivative).
                let size = clamp(self.fit_b[i] / self.fit_c[i], 0.01, 2.0);
                let mut moved = *theta;
                moved[k] += h.sign() * size;
                (self.design.reading(a, &moved).value - value) / size
            };
            u[SIGNATURE + i] = g * inv;
        }
    }

    /// The probe's reading `sample` against the lagged temperature: the
    /// tests, then the filter (see the module docs, steps 3-5). `t_oil` is
    /// the twin's oil temperature \[C\].
    fn test(
        &mut self,
        sample: ProbeSample,
        t_oil: f32,
        onset: &[f32; HYPOTHESES],
        estimate: &mut HealthEstimate,
        flags: &mut Flags,
    ) {
        let probe = self.settings.probe;
        let uninformed = self.lag.probe(UNINFORMED);
        if !(uninformed <= MAX_UNINFORMED) || !sample.value.is_finite() {
            return;
        }
        // The lagged temperature when the reading was taken.
        let age = clamp(sample.age, 0.0, 1.0);
        let t_probe = self.lag.probe(OIL) - age * self.lag.probe_rate(OIL, &probe);
        // The tolerance at the twin's smooth temperature, not at the lagged
        // one, which carries the second sensor's noise: a Jacobian that
        // moves with the innovation's own noise biases the filter along
        // what one temperature cannot tell apart (the divider against the
        // probe's error), by far more than the tolerance's slope suggests.
        let tolerance = probe.tolerance_at(t_oil);
        let theta = self.filter.theta();
        // The lag's noise estimated so far enters as `-e` ([`filter`]).
        let nu = sample.value - t_probe - theta[PROBE] * tolerance + self.filter.noise();
        let mut h = [tolerance; STATES];
        for (k, h) in h.iter_mut().enumerate().take(OFFSET + 1) {
            *h = self.lag.probe(D_THETA + k);
        }
        // The model error moves the reading as the offset does.
        h[MODEL] = h[OFFSET];
        h[NOISE] = -1.0;
        // The probe's noise, this reading's share of the lag's noise
        // (`c n_k`), the uninformed share's error.
        let spread = uninformed * UNINFORMED_ERROR;
        let c = 0.5 * (1.0 - self.decay.probe);
        let r = probe.reading_sd * probe.reading_sd
            + c * c * self.last_fresh
            + spread * spread
            + self.twin_bias * self.twin_bias;
        let s = self.filter.innovation_variance(&h) + r;
        self.correlated = None;
        let z = nu / <f32 as Real>::sqrt(s);
        if !z.is_finite() {
            return;
        }
        estimate.innovation = z;
        self.innovation = z;
        // The sticking test's signature in the probe's terms: a held
        // plunger's reading stays, so the second sensor's temperature stays
        // where the oil was when it was held, and the probe's innovation is
        // the probe's reading less the lag of that held temperature (from
        // the lagged temperature's stages at the hold; dragged through the
        // design band by the twin's oil's travel since). The probe reads
        // the oil through its lag as the innovation does; the twin's oil
        // (the observer's, off by up to a kelvin and more for seconds at a
        // ramp's start, `UNINFORMED_ERROR`) enters only the drag. The
        // probe's own travel since the hold is not it: that carries the
        // probe's catching up with the oil's travel before the hold (20 s
        // into a ramp through an 8 s lag, the lagged travel is 0.63 of the
        // probe's), and the fit's amplitude fell short of the held
        // plunger's by as much. The hold is renewed (a plunger that starts
        // to stick does so where it stands) while the oil rests or the
        // test's evidence since the hold is not positive, Page's estimate
        // of the onset as the CUSUM's, and kept through a run. The
        // reading before this one, so that the regressor does not share
        // this reading's noise with the innovation.
        // A pressure sensor has no sticking test: none of it is kept.
        let mut held_gap = 0.0;
        if self.design.quantity == Quantity::Displacement {
            if self.last_probe.is_finite() && self.last_held.is_finite() {
                held_gap = self.last_probe - self.last_held;
            }
            let corrected = sample.value - theta[PROBE] * tolerance;
            let renew = self.resting || !(self.held_fit > 0.0);
            if !self.held_oil.is_finite() || (renew && !self.running()) {
                self.held_fit = 0.0;
                self.held_lag = self.lag.signal(OIL);
                self.held_oil = self.lag.input(OIL);
                self.held_shift = self.held_oil - t_oil;
            }
            self.last_probe = corrected;
            self.last_held = self.held_lag.probe(0) - age * self.held_lag.probe_rate(0, &probe);
        }
        if self.settling > 0 {
            self.settling -= 1;
            self.learn(&h, nu, s, r);
            return;
        }
        // Detection: the two-sided CUSUM; a run starting from zero starts
        // the isolation sums and the signatures (the change's onset).
        if !self.running() {
            self.fit_b = [0.0; HYPOTHESES];
            self.fit_c = [0.0; HYPOTHESES];
            self.energy = 0.0;
            self.bias_energy = 0.0;
            self.window = (t_oil, t_oil);
            // The change's onset is taken between the last reading and this
            // one (where the CUSUM last stood at zero, Page's estimate):
            // the innovation holds one step of the lag's response to it, and
            // so must the signatures, or the first readings' fit, far above
            // the noise for a large change, favours whichever hypothesis'
            // shape the missing step happens to resemble. The sticking
            // test's signature has run through the lag all along, from the
            // oil's last rest (`predict`), and keeps its memory.
            let mut u = [0.0f32; SIGNALS];
            for i in 0..HYPOTHESES - 1 {
                self.lag.clear(SIGNATURE + i);
                u[SIGNATURE + i] = onset[i];
            }
            self.lag.step_signals(&u, &self.decay, SIGNATURE..HELD);
        }
        let zc = clamp(z, -CUSUM_CLIP, CUSUM_CLIP);
        self.cusum[0] = clamp(self.cusum[0] + zc - CUSUM_DRIFT, 0.0, f32::MAX);
        self.cusum[1] = clamp(self.cusum[1] - zc - CUSUM_DRIFT, 0.0, f32::MAX);
        if self.running() {
            self.window = (
                clamp(self.window.0, f32::MIN, t_oil),
                clamp(self.window.1, t_oil, f32::MAX),
            );
            self.energy += nu * nu / s;
            self.bias_energy += self.twin_bias * self.twin_bias / s;
            for i in 0..HYPOTHESES {
                let g = if SIGNATURE + i == HELD {
                    held_gap
                } else {
                    self.lag.probe(SIGNATURE + i)
                };
                self.fit_b[i] += g * nu / s;
                self.fit_c[i] += g * g / s;
            }
        }
        if self.cusum[0] > CUSUM_THRESHOLD || self.cusum[1] > CUSUM_THRESHOLD {
            self.detected = true;
        }
        // The sticking test's evidence since its hold (its renewal).
        self.held_fit += held_gap * nu / s;
        let suspicious = self.cusum[0] > 0.25 * CUSUM_THRESHOLD || self.cusum[1] > 0.25 * CUSUM_THRESHOLD;
        if z * z <= GATE * GATE && (self.detected || suspicious) && self.rest_share < REST_FORGOTTEN {
            // The parameters are held; the lag's noise follows the reading.
            let residual = self.filter.update_noise(&h, nu, s);
            let c = 0.5 * (1.0 - self.decay.probe);
            self.correlated = Some((Measured { h, r, residual }, c));
        }
        if self.detected {
            flags.insert(Flags::DEVICE_CHANGED);
            if let Some(h) = self.isolated() {
                self.confirm(h);
                flags.insert(h.flag(self.design.quantity));
                flags.remove(Flags::DEVICE_CHANGED);
            }
        } else if z * z > GATE * GATE {
            self.rejected = self.rejected.saturating_add(1);
            flags.insert(Flags::INNOVATION_REJECTED);
        } else if !suspicious {
            // A suspicious run holds the filter: it must not learn the
            // change before the tests have named it.
            self.learn(&h, nu, s, r);
        }
    }

    /// The filter's update; the lagged temperature follows the parameters'
    /// change through the lagged Jacobian (as if the new parameters had
    /// read every past reading).
    fn learn(&mut self, h: &[f32; STATES], nu: f32, s: f32, r: f32) {
        let mut change = self.filter.update(h, nu, s);
        // The probe sits within its tolerance (IEC 60751: `beta` in
        // `[-1, 1]`); along the direction a reading cannot tell from the
        // divider (at one temperature the two move the prediction alike)
        // the estimate must not leave it.
        let back = self.filter.project(PROBE, -1.0, 1.0);
        for (c, b) in change.iter_mut().zip(back) {
            *c += b;
        }
        let c = 0.5 * (1.0 - self.decay.probe);
        let residual = nu * r / s;
        self.correlated = Some((Measured { h: *h, r, residual }, c));
        for (k, c) in change.iter().enumerate().take(OFFSET + 1) {
            self.lag.add_scaled(OIL, D_THETA + k, *c);
        }
        self.lag.add_scaled(OIL, D_THETA + OFFSET, change[MODEL]);
    }

    /// `estimate` with the filter's parameters now (the probe's error at
    /// the oil temperature `t_oil` \[C\]), the tests' state and `flags`.
    fn publish(&mut self, mut estimate: HealthEstimate, mut flags: Flags, t_oil: f32) -> HealthEstimate {
        self.latched = Flags(flags.0 & LATCHED.0);
        // A detected change stays raised until it is named, on readings
        // that carry no probe reading (no test) as well: the test alone
        // raised it, and the estimates between the probe's readings, the
        // telemetry's among them, went without it.
        if self.detected {
            flags.insert(Flags::DEVICE_CHANGED);
        }
        let theta = self.filter.theta();
        estimate.divider = exp(theta[DIVIDER]);
        estimate.sd_divider = self.filter.sd(DIVIDER);
        estimate.spring = exp(theta[SPRING]);
        estimate.sd_spring = self.filter.sd(SPRING);
        estimate.offset = theta[OFFSET];
        estimate.sd_offset = self.filter.sd(OFFSET);
        let tolerance = self.settings.probe.tolerance_at(t_oil);
        estimate.probe_bias = theta[PROBE] * tolerance;
        estimate.sd_probe_bias = self.filter.sd(PROBE) * tolerance;
        estimate.friction = self.friction_width * self.spring_rate;
        estimate.cusum = if self.cusum[0] > self.cusum[1] {
            self.cusum[0]
        } else {
            self.cusum[1]
        };
        estimate.rejected = self.rejected;
        estimate.flags = flags;
        estimate
    }

    /// The reading predicted for the device, its Jacobian, and the sticking
    /// test's signature (the design play band's deviation).
    fn predict(&mut self, twin: f32, now: &Reading, nominal: &Reading) -> (f32, [f32; PARAMETERS], f32) {
        let d = &self.design;
        if d.quantity.is_pressure() {
            let (lo, hi) = match d.quantity {
                Quantity::Difference => (-d.dp, d.dp),
                _ => (d.p_c, d.p_c + d.dp),
            };
            return (clamp(twin + now.value - nominal.value, lo, hi), now.jacobian, 0.0);
        }
        // The displacement: the twin's transient on the device's free
        // equilibrium, held by friction, then clamped by the stops.
        let free = twin + now.value - clamp(nominal.value, 0.0, d.stroke);
        let mut jacobian = now.jacobian;
        let held = if self.held.is_finite() { self.held } else { free };
        self.held = play(held, free, self.friction_width);
        if self.friction_width > 0.0
            && self.held != free - self.friction_width
            && self.held != free + self.friction_width
        {
            // Inside the band the plunger does not move: no parameter moves the reading.
            jacobian = [0.0; PARAMETERS];
        }
        let x = clamp(self.held, 0.0, d.stroke);
        if x != self.held {
            jacobian = [0.0; PARAMETERS];
        }
        // The sticking test's plunger is held from where the free one stood
        // when the oil last rested (a plunger that starts to stick does so
        // where it stands): a held plunger's reading stays from the oil's
        // first move on, long before the CUSUM's run starts (the innovation
        // grows with the travel through the probe's lag), and a hold taken
        // from the run's start misses the travel before it, a constant
        // that the step faults fit. The oil rests while the free plunger's
        // travel over the lag's memory stays within the reading's noise and
        // the twin's accuracy (what the reading cannot resolve); a run
        // under way keeps its hold (a plunger dragged, then at rest, stays
        // off its free position).
        let p = self.decay.probe;
        if self.last_free.is_finite() && free.is_finite() {
            self.free_change = p * self.free_change + (1.0 - p) * (free - self.last_free);
        }
        self.last_free = free;
        let resolved = self.settings.sd_noise + self.sd_model;
        let resting = libm::fabsf(self.free_change) < resolved * (1.0 - p);
        self.resting = resting;
        let rehold = resting && !self.running();
        let test = if self.test_held.is_finite() && !rehold {
            self.test_held
        } else {
            free
        };
        self.test_held = play(test, free, self.design_width);
        (x, jacobian, self.test_held - free)
    }

    /// The hypothesis whose fit beats every other's by the margin (the
    /// noise's, the model error's, [`MODEL_ERROR`], and the twin's
    /// transient's), if any.
    ///
    /// The twin's transient (`twin_bias`, through the probe's lag) is a
    /// bias of the probe's prediction, not a noise: counted in `S` as a
    /// variance, it is taken for independent from reading to reading,
    /// and a fit may gain on it from every reading of a move. The margin
    /// adds the bias's own energy, `sum b_k^2 / S_k / 2`: the most a fit of
    /// the bias alone gains. It is large only while the oil moves (a
    /// tenth of a kelvin and more in a 0.3 C/s ramp through an 8 s probe,
    /// where `S` grows tenfold); with it an orifice clogged to 0.9 on
    /// designs 4 and 8 of the campaign is no longer named a transducer's
    /// offset 3-4 K into its move (`docs/monitoring.md`). It does not
    /// bound the bias's cross term with a large fault's signal; margins
    /// that did (twice the bias's length on the fits' amplitudes, or
    /// waiting until the divider's and the offset's signatures stand
    /// apart by the margin) delayed the paper preset's replay past its
    /// ramp, where a transducer's offset fitted its restricted capillary
    /// better and was named.
    fn isolated(&self) -> Option<Hypothesis> {
        let iso = self.isolation();
        let gain = iso.gain;
        let mut best = 0;
        for i in 1..HYPOTHESES {
            if gain[i] > gain[best] {
                best = i;
            }
        }
        let mut second = 0.0f32;
        for (i, g) in gain.iter().enumerate() {
            if i != best && *g > second {
                second = *g;
            }
        }
        let spanned = iso.span >= ISOLATION_SPAN || Hypothesis::ALL[best] == Hypothesis::Sticking;
        if gain[best] - second >= iso.margin && spanned {
            Some(Hypothesis::ALL[best])
        } else {
            None
        }
    }

    /// The isolation's state over the current CUSUM run, or the last one
    /// (its sums restart with the next run and when a fault is named): each
    /// hypothesis' log-likelihood gain, in [`Hypothesis::ALL`]'s order, the
    /// margin the best must beat the next by (at least
    /// [`ISOLATION_MARGIN`]), and the oil's span \[K\] of the run's tested
    /// readings (NaN before the first run): what names a fault, for
    /// diagnostics (`host-tests/examples/monitor_trace.rs`, `TRACE_GAINS`).
    pub fn isolation(&self) -> Isolation {
        // Log-likelihood gain of each single-fault fit, `b^2 / (2 c)`, with
        // the fault's sign (an amplitude of the wrong sign gains nothing).
        // The sticking test's amplitude is bounded by `STICKING_MOST`: its
        // regressor is the oil's lagged travel since the hold, which
        // barely differs from zero while the oil has hardly moved, and an
        // unbounded amplitude then fits a step fault's first readings
        // whole (a capillary's restriction named sticking 0.02 s after its
        // onset, 2 mK into a cooling).
        let mut gain = [0.0f32; HYPOTHESES];
        for (i, ((g, b), c)) in gain.iter_mut().zip(&self.fit_b).zip(&self.fit_c).enumerate() {
            if *c > 0.0 && *b > 0.0 {
                *g = if Hypothesis::ALL[i] == Hypothesis::Sticking {
                    sticking_gain(*b, *c)
                } else {
                    0.5 * b * b / c
                };
            }
        }
        Isolation {
            gain,
            margin: ISOLATION_MARGIN + 0.5 * MODEL_ERROR * MODEL_ERROR * self.energy + 0.5 * self.bias_energy,
            span: self.window.1 - self.window.0,
        }
    }

    /// Accepts hypothesis `h`: its parameter moves by the fitted size and
    /// its variance reopens (the filter then settles on the fault's size),
    /// or the friction's fitted width enters the prediction; the lagged
    /// temperature takes the fitted change since the onset; the tests
    /// restart.
    fn confirm(&mut self, h: Hypothesis) {
        let i = Hypothesis::ALL.iter().position(|&x| x == h).unwrap_or(0);
        // The fit's amplitude (the change in the parameter, by the
        // signature's sign) and its standard deviation.
        let (amplitude, sd) = if self.fit_c[i] > 0.0 {
            (self.fit_b[i] / self.fit_c[i], 1.0 / <f32 as Real>::sqrt(self.fit_c[i]))
        } else {
            (0.0, 0.0)
        };
        self.lag.add_scaled(OIL, SIGNATURE + i, amplitude);
        let k = h.parameter();
        if k < PARAMETERS {
            let by = h.sign() * amplitude;
            self.filter.shift(k, by);
            if k == OFFSET {
                self.zero_limit += libm::fabsf(by);
            }
            // Room for the linearisation's error (a tenth of the change).
            let room = 0.1 * libm::fabsf(by);
            self.filter.reopen(k, <f32 as Real>::sqrt(sd * sd + room * room));
        } else {
            self.friction_width += clamp(amplitude, 0.0, STICKING_MOST) * self.design_width;
            self.held = f32::NAN;
        }
        self.reference = self.filter.theta();
        self.reference[PROBE] = 0.0;
        self.reference[MODEL] = 0.0;
        self.settling = SETTLE_READINGS;
        self.restart_tests();
    }

    /// The tests start afresh once a fault is named: no change detected,
    /// the CUSUM, the isolation's sums and the sticking test's evidence
    /// at zero.
    fn restart_tests(&mut self) {
        self.detected = false;
        self.cusum = [0.0; 2];
        self.fit_b = [0.0; HYPOTHESES];
        self.fit_c = [0.0; HYPOTHESES];
        self.held_fit = 0.0;
        self.energy = 0.0;
        self.bias_energy = 0.0;
    }
}

/// The log-likelihood gain of the sticking test's fit from its sums `b =
/// sum g nu / S` and `c = sum g^2 / S`: a positive amplitude, at most
/// [`STICKING_MOST`] design bands.
fn sticking_gain(b: f32, c: f32) -> f32 {
    if !(c > 0.0 && b > 0.0) {
        0.0
    } else if b > STICKING_MOST * c {
        STICKING_MOST * b - 0.5 * STICKING_MOST * STICKING_MOST * c
    } else {
        0.5 * b * b / c
    }
}

/// The flags of one reading only: the estimator's estimate of the tick
/// that took the reading carries them, and so does the next published one
/// (the telemetry's). The others stay raised: `DEVICE_CHANGED` until the
/// change is named, the named faults for good.
pub const PER_READING: Flags = Flags(Flags::SECOND_SENSOR_FAULT.0 | Flags::INNOVATION_REJECTED.0);

/// The flags that stay raised once set (the isolated faults).
pub const LATCHED: Flags = Flags(
    Flags::CAPILLARY_RESTRICTED.0
        | Flags::ORIFICE_CLOGGED.0
        | Flags::SPRING_RELAXED.0
        | Flags::PRELOAD_LOST.0
        | Flags::PLUNGER_STICKING.0
        | Flags::SENSOR_OFFSET.0,
);
