//! Condition monitoring: a second sensor (a chamber pressure or the
//! plunger displacement) corrects the twin's reading, and sequential tests
//! on what the twin cannot explain name the device's fault.
//!
//! Per reading of the second sensor, in this order:
//!
//! 1. **Prediction.** The twin (the nominal device of the parameter file)
//!    gives its reading `y_twin` now; the health parameters `theta` move it
//!    by what they move the quasi-static reading at the twin's oil
//!    ([`signature`]: `y = y_twin + h(theta) - h(0)`), and, for the
//!    displacement, a plunger held by friction stays in its play band
//!    ([`signature::play`]), then the stops clamp it.
//! 2. **Filter.** A Kalman filter of the health parameters ([`filter`]:
//!    the divider `theta_A = ln(A / A_file)`, the spring `theta_k =
//!    ln(c / c_file)`, the reading's offset `delta`), each a slow random
//!    walk, updates with the innovation `nu = y - y_pred`, whose variance is
//!    `S = H P H' + R`: the sensor's noise, the filter's own uncertainty,
//!    and the oil-temperature observer's variance through `dy/dT` (the
//!    probe's lag in a fast change). An innovation beyond [`GATE`]
//!    standard deviations is counted ([`HealthEstimate::rejected`]), not
//!    applied.
//! 3. **Detection.** A two-sided CUSUM of the standardised innovation
//!    `z = nu / sqrt(S)` ([`CUSUM_DRIFT`], [`CUSUM_THRESHOLD`]) says the
//!    device no longer behaves as the filter's device: `DEVICE_CHANGED`.
//! 4. **Isolation.** From the CUSUM run's start on (the change's onset), the
//!    innovations are fitted by each fault's signature alone (a generalised
//!    likelihood ratio over the window, [`Hypothesis`]); the fault whose
//!    fit explains the innovations better than every other's by
//!    [`ISOLATION_MARGIN`] in log-likelihood is named (its flag latches),
//!    the filter's variance of its parameter is reopened so that the
//!    parameter settles on the fault's size, and watching resumes. While a
//!    change is detected and not yet isolated the filter is frozen, so
//!    that it does not absorb the change it is trying to name.
//!
//! The second sensor's own faults (`crate::sensor::SensorFault`) skip the
//! update and raise `SECOND_SENSOR_FAULT`; the estimate then rests on the
//! temperature alone, as without a monitor.
//!
//! **Why not the twin's four states in the filter.** The twin's chamber
//! pressures and plunger settle within milliseconds
//! ([`crate::estimator::Plant::slowest_time_constant`]); the oil's
//! temperature, and with it every reading, moves over seconds. Over a
//! sensor period the fast states are slaved to the slow ones (singular
//! perturbation): an extended Kalman filter of `(x, v, p_a, p_b, theta)`
//! would carry a covariance of the fast states that is the quasi-static
//! image of `theta`'s, at four times the cost. The filter here keeps the
//! slow states; the twin supplies the fast ones' transient, and the
//! quasi-static algebra the health parameters' effect on them.
//!
//! What each sensor can tell apart, and the flags' confusions, are in the
//! project's `docs/monitoring.md`. Nothing here allocates or panics; a
//! non-finite input is a rejected reading.

pub mod filter;
pub mod signature;

pub use filter::HealthFilter;
pub use signature::{Design, Quantity, Reading};

use crate::equilibrium::a_parameter;
use crate::estimator::{Flags, clamp};
use crate::fluid::FluidPoint;
use crate::params::Params;
use crate::scalar::Real;
use signature::{DIVIDER, OFFSET, PARAMETERS, SPRING, exp, play};

/// Standard deviations of the innovation beyond which a reading is not
/// applied to the filter: `P(|z| > 6) = 2e-9` for a normal innovation,
/// below one a day at 100 readings a second.
pub const GATE: f32 = 6.0;

/// Drift `k` of the CUSUM, in innovation standard deviations: a bias of the
/// model below it (an unmodelled lag, a probe's tolerance the filter has
/// not yet learned) only drains the statistic.
pub const CUSUM_DRIFT: f32 = 3.0;

/// Threshold `h` of the CUSUM in innovation standard deviations. For a
/// white standardised innovation, Siegmund's approximation of the run
/// length to a false alarm, `exp(2 k h) / (2 k^2)`, is 6e24 readings.
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
/// with the temperature.
pub const ISOLATION_SPAN: f32 = 1.0;

/// Relative model error of a fault's signature in the isolation's fit: the
/// variance of each reading there is `S + (MODEL_ERROR nu)^2`, so that a
/// signal far above the noise does not make the small misfits of the
/// linearisation and of the temperature estimate decisive.
pub const MODEL_ERROR: f32 = 0.02;

/// Readings after a fault is named during which the filter takes every
/// reading (no gate, no test): it settles on the fault's size from the
/// tests' fit, whose linearisation at the old parameters is off by the
/// change's curvature.
pub const SETTLE_READINGS: u32 = 200;

/// Priors of the health parameters: standard deviations of a device as
/// built around its file (the divider's `A` goes with the capillary's bore
/// to the fourth power: 10 % is a 2.5 % bore; 5 % of a spring's rate).
pub const PRIOR_DIVIDER: f32 = 0.1;
/// Prior of `theta_k` (see [`PRIOR_DIVIDER`]).
pub const PRIOR_SPRING: f32 = 0.05;
/// Prior of the displacement's offset as a fraction of the stroke (the
/// preload's and the sensor's zero), on top of the sensor's accuracy.
pub const PRIOR_OFFSET_STROKES: f32 = 0.02;

/// Random-walk drift of the health parameters per square root of an hour:
/// the device's slow wear the filter follows without a flag.
pub const DRIFT_PER_SQRT_HOUR: [f32; PARAMETERS] = [0.005, 0.002, 0.0];

/// The friction the sticking test is designed for, as a fraction of the
/// spring's force at mid-stroke (`F = f c (x0 + x_max / 2)`): the play
/// band's half width of the fitted signature.
pub const STICKING_DESIGN: f32 = 0.05;

/// What the monitor needs of its sensor (from the device file's
/// `[monitor]`).
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
}

/// Why a monitor cannot be built: the setting named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MonitorError {
    /// The setting is not finite and positive (`monitor.noise`,
    /// `monitor.accuracy`, `monitor.sample_hz`).
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

impl Hypothesis {
    /// Every hypothesis, in the accumulators' order.
    pub const ALL: [Hypothesis; 6] = [
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
}

/// What the monitor reads of the plant at a reading: the twin's oil and
/// state, and the oil-temperature observer's variance.
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
    /// Variance of the oil-temperature estimate \[K^2\].
    pub var_t: f32,
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
    /// The friction force holding the plunger \[N\] (0 until sticking is
    /// isolated).
    pub friction: f32,
    /// The corrected reading the monitor predicted \[Pa or m\].
    pub predicted: f32,
    /// The standardised innovation of the last reading.
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
        friction: f32::NAN,
        predicted: f32::NAN,
        innovation: f32::NAN,
        cusum: f32::NAN,
        rejected: 0,
        flags: Flags::empty(),
    };
}

/// The condition monitor (see the module docs). `f32`; one reading costs
/// two exponentials, two square roots and a 3-state filter update.
#[derive(Clone, Copy, Debug)]
pub struct Monitor {
    design: Design,
    settings: MonitorSettings,
    /// The file's spring rate `c` [N/m].
    spring_rate: f32,
    filter: HealthFilter,
    /// The play band's half width of an isolated sticking fault \[m\].
    friction_width: f32,
    /// Where the monitor's plunger is held by that friction \[m\].
    held: f32,
    /// Half width of the sticking test's play band \[m\].
    design_width: f32,
    /// The sticking test's own held plunger \[m\].
    test_held: f32,
    /// CUSUM statistics for innovations up and down.
    cusum: [f32; 2],
    /// The change is detected (`DEVICE_CHANGED`) and not yet isolated.
    detected: bool,
    /// Isolation sums over the CUSUM's run: per hypothesis `sum g nu / S`
    /// and `sum g^2 / S`.
    fit_b: [f32; 6],
    fit_c: [f32; 6],
    latched: Flags,
    rejected: u32,
    /// Readings left of the settling after a named fault.
    settling: u32,
    /// The oil temperatures the isolation window spans \[C\].
    window: (f32, f32),
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
        let hours = settings.sample_period / 3600.0;
        let mut drift = [0.0; PARAMETERS];
        for (d, per) in drift.iter_mut().zip(DRIFT_PER_SQRT_HOUR) {
            *d = per * per * hours;
        }
        let filter = HealthFilter::new([PRIOR_DIVIDER, PRIOR_SPRING, sd_offset], drift);
        Ok(Monitor {
            design,
            settings,
            spring_rate: plunger.spring_rate,
            filter,
            friction_width: 0.0,
            held: f32::NAN,
            design_width: STICKING_DESIGN * (plunger.preload + 0.5 * plunger.stroke),
            test_held: f32::NAN,
            cusum: [0.0; 2],
            detected: false,
            fit_b: [0.0; 6],
            fit_c: [0.0; 6],
            latched: Flags::empty(),
            rejected: 0,
            settling: 0,
            window: (f32::NAN, f32::NAN),
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
    /// their priors (after the device's maintenance).
    pub fn reset(&mut self, params: &Params<f32>) {
        if let Ok(m) = Monitor::new(params, self.settings) {
            *self = m;
        }
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

    /// One reading `measured` (`Err`: the sensor's own checks refused it)
    /// of the second sensor, with the plant as it is now (see the module
    /// docs).
    pub fn update<E>(&mut self, params: &Params<f32>, view: &PlantView, measured: Result<f32, E>) -> HealthEstimate {
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
        let dy_dt = now.jacobian[DIVIDER] * dln_a;
        let r = self.settings.sd_noise * self.settings.sd_noise + dy_dt * dy_dt * view.var_t;
        // The parameters, the tests' state and the flags are filled in by
        // `publish`, on every path.
        let mut estimate = HealthEstimate {
            predicted,
            ..HealthEstimate::NONE
        };
        let y = match measured {
            Ok(y) if y.is_finite() && r.is_finite() && predicted.is_finite() => y,
            Ok(_) => {
                self.rejected = self.rejected.saturating_add(1);
                flags.insert(Flags::INNOVATION_REJECTED);
                return self.publish(estimate, flags);
            }
            Err(_) => {
                flags.insert(Flags::SECOND_SENSOR_FAULT);
                return self.publish(estimate, flags);
            }
        };
        let nu = y - predicted;
        let s = self.filter.innovation_variance(&jacobian) + r;
        let z = nu / <f32 as Real>::sqrt(s);
        estimate.innovation = z;
        if self.settling > 0 {
            self.settling -= 1;
            self.filter.update(&jacobian, nu, s);
            self.filter.predict();
            return self.publish(estimate, flags);
        }
        // Detection: the two-sided CUSUM; a run starting from zero starts
        // the isolation sums (the change's onset).
        let zc = clamp(z, -CUSUM_CLIP, CUSUM_CLIP);
        if self.cusum == [0.0, 0.0] && !self.detected {
            self.fit_b = [0.0; 6];
            self.fit_c = [0.0; 6];
            self.test_held = f32::NAN;
            self.window = (view.oil.state.temperature, view.oil.state.temperature);
        }
        self.cusum[0] = clamp(self.cusum[0] + zc - CUSUM_DRIFT, 0.0, f32::MAX);
        self.cusum[1] = clamp(self.cusum[1] - zc - CUSUM_DRIFT, 0.0, f32::MAX);
        let running = self.detected || self.cusum[0] > 0.0 || self.cusum[1] > 0.0;
        if running {
            let t = view.oil.state.temperature;
            self.window = (clamp(self.window.0, f32::MIN, t), clamp(self.window.1, t, f32::MAX));
            let s = s + MODEL_ERROR * MODEL_ERROR * nu * nu;
            self.accumulate(nu, s, (a, &theta, now.value), &jacobian, sticking);
        }
        if self.cusum[0] > CUSUM_THRESHOLD || self.cusum[1] > CUSUM_THRESHOLD {
            self.detected = true;
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
        } else if !(self.cusum[0] > 0.25 * CUSUM_THRESHOLD || self.cusum[1] > 0.25 * CUSUM_THRESHOLD) {
            // A suspicious run holds the filter: it must not learn the
            // change before the tests have named it.
            self.filter.update(&jacobian, nu, s);
        }
        self.filter.predict();
        self.publish(estimate, flags)
    }

    /// `estimate` with the filter's parameters now, the tests' state and
    /// `flags`.
    fn publish(&mut self, mut estimate: HealthEstimate, flags: Flags) -> HealthEstimate {
        self.latched = Flags(flags.0 & LATCHED.0);
        let theta = self.filter.theta();
        estimate.divider = exp(theta[DIVIDER]);
        estimate.sd_divider = self.filter.sd(DIVIDER);
        estimate.spring = exp(theta[SPRING]);
        estimate.sd_spring = self.filter.sd(SPRING);
        estimate.offset = theta[OFFSET];
        estimate.sd_offset = self.filter.sd(OFFSET);
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
        let test = if self.test_held.is_finite() {
            self.test_held
        } else {
            free
        };
        self.test_held = play(test, free, self.design_width);
        (x, jacobian, self.test_held - free)
    }

    /// Adds a reading to the isolation sums. A fault's signature is the
    /// secant of the reading over the fault's size fitted so far
    /// (`(h(theta + delta e_k) - h(theta)) / delta`, the derivative while the size is
    /// not yet known): the reading is not linear in the divider or the
    /// spring over a fault's size, and the derivative's shape at the old
    /// parameters would favour the wrong fault. `at` is the redistribution
    /// parameter, the filter's parameters and the reading there.
    fn accumulate(
        &mut self,
        nu: f32,
        s: f32,
        at: (f32, &[f32; PARAMETERS], f32),
        jacobian: &[f32; PARAMETERS],
        sticking: f32,
    ) {
        let (a, theta, value) = at;
        for (i, h) in Hypothesis::ALL.iter().enumerate() {
            let k = match h {
                Hypothesis::CapillaryRestricted | Hypothesis::OrificeClogged => DIVIDER,
                Hypothesis::SpringRelaxed => SPRING,
                Hypothesis::OffsetUp | Hypothesis::OffsetDown => OFFSET,
                Hypothesis::Sticking => PARAMETERS,
            };
            let g = if k == PARAMETERS {
                sticking
            } else if k == OFFSET || jacobian[k] == 0.0 || !(self.fit_c[i] > 0.0) {
                jacobian[k] * h.sign()
            } else {
                // The size fitted so far, by the fault's sign (at least a
                // hundredth, where the secant is the derivative).
                let size = clamp(self.fit_b[i] / self.fit_c[i], 0.01, 2.0);
                let mut moved = *theta;
                moved[k] += h.sign() * size;
                (self.design.reading(a, &moved).value - value) / size
            };
            self.fit_b[i] += g * nu / s;
            self.fit_c[i] += g * g / s;
        }
    }

    /// The hypothesis whose fit beats every other's by the margin, if any.
    fn isolated(&self) -> Option<Hypothesis> {
        // Log-likelihood gain of each single-fault fit, `b^2 / (2 c)`, with
        // the fault's sign (an amplitude of the wrong sign gains nothing).
        let mut gain = [0.0f32; 6];
        for ((g, b), c) in gain.iter_mut().zip(&self.fit_b).zip(&self.fit_c) {
            if *c > 0.0 && *b > 0.0 {
                *g = 0.5 * b * b / c;
            }
        }
        let mut best = 0;
        for i in 1..6 {
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
        let span = self.window.1 - self.window.0;
        if gain[best] - second >= ISOLATION_MARGIN && span >= ISOLATION_SPAN {
            Some(Hypothesis::ALL[best])
        } else {
            None
        }
    }

    /// Accepts hypothesis `h`: its parameter's variance reopens (the
    /// filter then settles on the fault's size), or the friction's fitted
    /// width enters the prediction; the tests restart.
    fn confirm(&mut self, h: Hypothesis) {
        let i = Hypothesis::ALL.iter().position(|&x| x == h).unwrap_or(0);
        // The fit's amplitude (the change in the parameter, by the
        // signature's sign) and its standard deviation.
        let (amplitude, sd) = if self.fit_c[i] > 0.0 {
            (self.fit_b[i] / self.fit_c[i], 1.0 / <f32 as Real>::sqrt(self.fit_c[i]))
        } else {
            (0.0, 0.0)
        };
        let mut size = |k: usize| {
            let by = h.sign() * amplitude;
            self.filter.shift(k, by);
            // Room for the linearisation's error (a tenth of the change).
            let room = 0.1 * libm::fabsf(by);
            self.filter.reopen(k, <f32 as Real>::sqrt(sd * sd + room * room));
        };
        match h {
            Hypothesis::CapillaryRestricted | Hypothesis::OrificeClogged => size(DIVIDER),
            Hypothesis::SpringRelaxed => size(SPRING),
            Hypothesis::OffsetUp | Hypothesis::OffsetDown => size(OFFSET),
            Hypothesis::Sticking => {
                self.friction_width += clamp(amplitude, 0.0, 4.0) * self.design_width;
                self.held = f32::NAN;
            }
        }
        self.settling = SETTLE_READINGS;
        self.detected = false;
        self.cusum = [0.0; 2];
        self.fit_b = [0.0; 6];
        self.fit_c = [0.0; 6];
    }
}

/// The flags of one reading only (the estimate of the tick that took it
/// carries them); the others stay raised: `DEVICE_CHANGED` until the change
/// is named, the named faults for good.
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
