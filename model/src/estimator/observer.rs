//! The oil-temperature observer: a Kalman filter that reconstructs the oil
//! temperature from the readings of a probe that lags it.
//!
//! A probe in a thermowell answers an oil change as a first-order lag of
//! seconds (optionally a second, slower lag: the well). Its reading is the
//! probe's temperature, not the oil's: at a 0.5 C/s warm-up through an 8 s
//! probe it reads 4 C low. The observer's model (states in this order):
//!
//! ```text
//! d T_oil  = r dt                          (the oil temperature [C])
//! d r      = dw,  E[dw^2] = q dt           (its rate [C/s], a random walk)
//! d T_well = (T_oil - T_well) / tau_w dt   (only with a well lag)
//! d T_pr   = (T_in - T_pr) / tau_p dt      (T_in: T_well, or T_oil)
//! y        = T_pr + v,  E[v^2] = R         (one reading)
//! ```
//!
//! with `R = noise^2 + resolution^2 / 12` (the probe's noise and the
//! converter's quantization as a uniform error, GUM 4.3.7). A constant rate
//! is followed without bias in the steady state (the model holds a ramp
//! exactly), so a warm-up is tracked through the probe's lag; how fast a
//! change of rate is followed is the process noise `q`, traded against the
//! noise the estimate passes on. Two steady-state filters of the same model
//! do both jobs:
//!
//! * **fast mode**, `q_f = (a / 2)^2 T_s` with `a = max_oil_rate / (tau_p +
//!   tau_w)`: a change of the rate by the oil's largest plausible rate
//!   within the probe's response, the white-noise-acceleration rule of
//!   thumb (process noise of half the largest acceleration: Bar-Shalom, Li,
//!   Kirubarajan 2001, "Estimation with Applications to Tracking and
//!   Navigation", 6.3.3) at the sample period `T_s`;
//! * **hold mode**, `q_h = 1e-3 q_f`: the rate changes a thousand times
//!   less; the estimate then averages the noise over tens of seconds.
//!
//! A two-sided CUSUM of the normalised innovations `u = nu / sqrt(S)`
//! (drift 0.5, threshold 14: for white unit innovations a false alarm
//! every ~1e7 samples, two days at 50 Hz; Page 1954, Siegmund's
//! approximation of the run length) says when the innovations are no
//! longer zero-mean, the signature of a change the hold mode does not
//! follow. An alarm puts the filter back in the fast mode's steady state
//! (its covariance: the rate is uncertain again), and from there the gains
//! follow the **schedule**: the filter's own Riccati recursion under the
//! hold mode's process noise, started from the fast mode's covariance, so
//! that the gains fall as fast as the covariance does and no faster
//! ([`ObserverDesign::schedule`], [`SCHEDULE`] entries at readings `c j^2`
//! after the alarm, interpolated linearly on the square-root scale; one
//! `sqrt` per reading). A fixed blend of the two modes' steady states (a
//! weight decaying with the probe's time constant, the design before this
//! one) left the fast mode's rate error to the hold mode's slow dynamics:
//! at 0.05 C/s through an 8 s probe, 95 of 101 random designs within 0.15 %
//! of the stroke once two time constants had passed, against 101 of 101
//! with the schedule (`docs/firmware.md`). The estimate's variance follows
//! the schedule too: small in a hold, large in a fast change and for a
//! while after, and it grows between samples as the rate is extrapolated.
//!
//! The gains are designed once in `f64` ([`ObserverDesign::new`]: Van
//! Loan's discretisation and the Riccati equation's steady state by
//! doubling, [`crate::linalg::small`]); the firmware's build script runs
//! that on the host and compiles the result in. Per tick the observer
//! predicts (eight `f32` multiply-adds, compensated sums so that a slow
//! drift is not lost below half an ulp of the temperature: the finding F2
//! of the project's `docs/fuzzing.md`), and per sample it updates (four
//! more, one CUSUM step).

use super::spike::{SpikeGate, SpikeSettings, Verdict};
use crate::linalg::small::{Mat, dare_filter, mul, transpose, van_loan};
use crate::scalar::Real;

/// Drift of the CUSUM of normalised innovations (half a standard deviation:
/// it detects a shift of one standard deviation fastest, Page 1954).
pub const CUSUM_DRIFT: f32 = 0.5;

/// Threshold of the CUSUM: run length to a false alarm about 1e7 samples
/// for white unit-variance innovations (Siegmund: `(e^(2 k (h + 1.166)) -
/// 2 k (h + 1.166) - 1) / (2 k^2)` per side with `k = 0.5`, `h = 14`).
pub const CUSUM_THRESHOLD: f32 = 14.0;

/// The rate the estimate may hold, in units of the oil's largest plausible
/// rate (`estimator.max_oil_rate`): the state is projected onto
/// `|r| <= RATE_LIMIT max_oil_rate` after each update (a constrained
/// Kalman filter by projection, Simon 2010, "Kalman filtering with state
/// constraints: a survey of linear and nonlinear algorithms", IET Control
/// Theory & Applications 4(8)). A jump of the oil, beyond what the file
/// declares plausible, would otherwise make the rate overshoot and the
/// estimate ring: a 38 C step through a 6 s probe undershot by 16 C, with
/// the limit by 4 C.
pub const RATE_LIMIT: f64 = 2.0;

/// Ratio of the hold mode's process noise to the fast mode's.
pub const HOLD_RATIO: f64 = 1e-3;

/// Entries of the gain schedule from the fast mode to the hold mode
/// ([`ObserverDesign::schedule`]).
pub const SCHEDULE: usize = 24;

/// How close to the hold mode's the schedule's gains end, relative.
pub const SCHEDULE_CONVERGED: f64 = 1e-3;

/// The most readings the schedule is followed for (an hour at 50 Hz): a
/// filter slower than that ends on the hold mode at once.
pub const SCHEDULE_MAX_READINGS: u32 = 180_000;

/// Why an observer cannot be designed for the settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignError {
    /// A time constant, the noise, the rate, the tick or the sample period
    /// is not positive and finite.
    Settings,
    /// The discretisation or the Riccati equation has no usable solution
    /// (time constants or noise beyond what `f64` resolves).
    Numerics,
}

impl core::fmt::Display for DesignError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            DesignError::Settings => "the observer's settings must be positive and finite",
            DesignError::Numerics => "no steady-state Kalman filter for these settings",
        })
    }
}

impl core::error::Error for DesignError {}

/// What the observer is designed from (SI units; the device file's
/// `[probe]` section and `estimator.max_oil_rate`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverSettings {
    /// The probe's first-order time constant `tau_p` \[s\].
    pub time_constant: f64,
    /// A second lag in series, the well's `tau_w` \[s\] (0: none).
    pub well_time_constant: f64,
    /// Standard deviation of one reading's noise \[C\].
    pub noise: f64,
    /// The converter's resolution, one code \[C\] (quantization variance
    /// `resolution^2 / 12`).
    pub resolution: f64,
    /// The oil's largest plausible rate of change [C/s].
    pub max_rate: f64,
    /// The estimator's tick \[s\].
    pub tick: f64,
    /// The period of the readings \[s\] (the gains are per reading).
    pub sample_period: f64,
    /// Width of the oil's temperature range \[C\] (`oil_max - oil_min`): the
    /// largest change the oil can make, which bounds how far one reading
    /// can move ([`ObserverDesign::gate`]).
    pub span: f64,
}

/// Time constant of a probe read without lag \[s\]: well below a reading
/// period, so that the readings are the oil's temperature
/// ([`ObserverSettings::without_lag`]).
pub const NO_LAG: f64 = 0.01;

impl ObserverSettings {
    /// These settings for a probe that does not lag: `time_constant` of
    /// [`NO_LAG`], no well. For readings that are the oil's temperature
    /// itself (the soak's seeded walk, which tests the sensor's faults and
    /// the twin, not the probe).
    pub fn without_lag(self) -> Self {
        ObserverSettings {
            time_constant: NO_LAG,
            well_time_constant: 0.0,
            ..self
        }
    }
}

/// One mode's steady state ([`ObserverDesign`] holds the hold and fast
/// modes').
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeGains {
    /// Gains per reading on `[T_oil, r, T_well, T_probe]` (`T_well`'s is 0
    /// without a well).
    pub gain: [f32; 4],
    /// `1 / sqrt(S)`, the innovation's inverse standard deviation [1/C].
    pub inv_innovation_sd: f32,
    /// Variance of the oil temperature estimate after a reading [C^2].
    pub var_oil: f32,
    /// Its covariance with the rate [C^2/s].
    pub cov_oil_rate: f32,
    /// Variance of the rate [C^2/s^2].
    pub var_rate: f32,
    /// Process noise intensity `q` [C^2/s^3].
    pub q: f32,
}

/// The observer's design: constants computed once from
/// [`ObserverSettings`] ([`ObserverDesign::new`]), in `f32` for the tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverDesign {
    /// The tick \[s\].
    pub tick: f32,
    /// The period of the readings the gains are designed for \[s\].
    pub sample_period: f32,
    /// Whether the model has the well's lag.
    pub well: bool,
    /// Per-tick transition of `T_well`: `dT_well = well_oil (T_oil -
    /// T_well) + well_rate r` (rows of the transition sum to one over the
    /// temperatures: written as increments of differences).
    pub well_oil: f32,
    /// See `well_oil` \[s\].
    pub well_rate: f32,
    /// Per-tick transition of `T_probe`: `dT_probe = probe_oil (T_oil -
    /// T_probe) + probe_well (T_well - T_probe) + probe_rate r`.
    pub probe_oil: f32,
    /// See `probe_oil`.
    pub probe_well: f32,
    /// See `probe_oil` \[s\].
    pub probe_rate: f32,
    /// Hold mode.
    pub hold: ModeGains,
    /// Fast mode.
    pub fast: ModeGains,
    /// The filter's own time-varying gains after a change: the Riccati
    /// recursion of the hold mode's model started from the fast mode's
    /// covariance, entry `j` at `c j^2` readings after the change (`fast`
    /// at 0, `hold` at the last), so that the estimate leaves the fast
    /// mode as quickly as its covariance shrinks and no faster.
    pub schedule: [ModeGains; SCHEDULE],
    /// `1 / (c n_r)` with `n_r` ticks per reading: `n` ticks after a change
    /// the schedule's position is `sqrt(n schedule_rate)` (computed from
    /// the count, so that no rounding accumulates over millions of ticks).
    pub schedule_rate: f32,
    /// How far the probe can move per second [C/s]: the oil jumping across
    /// its whole range moves the probe by `span (1 - e^(-t / tau_p)) <=
    /// span t / tau_p` in `t` ([`ObserverDesign::gate`]).
    pub gate_rate: f32,
    /// The readings' own scatter the gate allows on top \[C\]: six standard
    /// deviations of the difference of two readings, `6 sqrt(2 R)`.
    pub gate_noise: f32,
    /// The largest rate the estimate may hold [C/s]: twice the oil's
    /// largest plausible rate (`estimator.max_oil_rate`); the state is
    /// projected onto `|r| <= rate_limit` after each update (a constrained
    /// Kalman filter by projection, Simon 2010).
    pub rate_limit: f32,
    /// Weight of a reading in the innovations' running mean square, `1 -
    /// e^(-T_s / (tau_p + tau_w))` ([`OilObserver::variance`]).
    pub innovation_weight: f32,
}

/// The design's continuous model: `(A, g)` with `N` states.
fn model<const N: usize>(s: &ObserverSettings) -> Mat<N> {
    let mut a = [[0.0; N]; N];
    a[0][1] = 1.0;
    if N == 4 {
        a[2][0] = 1.0 / s.well_time_constant;
        a[2][2] = -1.0 / s.well_time_constant;
        a[3][2] = 1.0 / s.time_constant;
        a[3][3] = -1.0 / s.time_constant;
    } else {
        a[N - 1][0] = 1.0 / s.time_constant;
        a[N - 1][N - 1] = -1.0 / s.time_constant;
    }
    a
}

/// Variance of one reading [C^2]: the probe's noise and the converter's
/// quantization (uniform over one step of `resolution`).
fn reading_variance(s: &ObserverSettings) -> f64 {
    s.noise * s.noise + s.resolution * s.resolution / 12.0
}

/// The `N`-state model (`M = 2 N`) over one reading period with the rate
/// driven by white noise of intensity `q`: `(Phi, Q_d)`.
fn discrete<const N: usize, const M: usize>(s: &ObserverSettings, q: f64) -> Result<(Mat<N>, Mat<N>), DesignError> {
    let mut g = [0.0; N];
    g[1] = 1.0;
    van_loan::<N, M>(&model::<N>(s), &g, q, s.sample_period).ok_or(DesignError::Numerics)
}

/// The measurement update of the probe reading (the last state) with
/// variance `r`, from the prior covariance: the gain, the innovation's
/// variance and the posterior covariance `(I - k h) P`.
fn update<const N: usize>(prior: &Mat<N>, r: f64) -> ([f64; N], f64, Mat<N>) {
    let innovation = prior[N - 1][N - 1] + r;
    let mut k = [0.0; N];
    for i in 0..N {
        k[i] = prior[i][N - 1] / innovation;
    }
    let mut post = *prior;
    for i in 0..N {
        for j in 0..N {
            post[i][j] = prior[i][j] - k[i] * prior[N - 1][j];
        }
    }
    (k, innovation, post)
}

/// Steady state of one mode of the `N`-state model (`M = 2 N`).
fn mode<const N: usize, const M: usize>(s: &ObserverSettings, q: f64) -> Result<([f64; N], f64, Mat<N>), DesignError> {
    let (phi, qd) = discrete::<N, M>(s, q)?;
    let r = reading_variance(s);
    let mut h = [0.0; N];
    h[N - 1] = 1.0;
    let p = dare_filter(&phi, &qd, &h, r).ok_or(DesignError::Numerics)?;
    Ok(update(&p, r))
}

/// A mode's gains on the runtime's four slots.
fn gains<const N: usize>(k: [f64; N], innovation: f64, post: &Mat<N>, q: f64) -> ModeGains {
    let mut gain = [0.0f32; 4];
    gain[0] = k[0] as f32;
    gain[1] = k[1] as f32;
    if N == 4 {
        gain[2] = k[2] as f32;
    }
    gain[3] = k[N - 1] as f32;
    ModeGains {
        gain,
        inv_innovation_sd: (1.0 / libm::sqrt(innovation)) as f32,
        var_oil: post[0][0] as f32,
        cov_oil_rate: post[0][1] as f32,
        var_rate: post[1][1] as f32,
        q: q as f32,
    }
}

/// The gain schedule from the fast mode's posterior covariance `start`
/// under the hold mode's process noise `q_hold` (see
/// [`ObserverDesign::schedule`]) and its spacing `c` [readings]: the plain
/// Riccati recursion, run once to find where its gains come within
/// [`SCHEDULE_CONVERGED`] of the hold mode's (at most
/// [`SCHEDULE_MAX_READINGS`]), and again to take its entries.
fn schedule<const N: usize, const M: usize>(
    s: &ObserverSettings,
    q_hold: f64,
    start: &Mat<N>,
    hold: &ModeGains,
    fast: &ModeGains,
) -> Result<([ModeGains; SCHEDULE], f64), DesignError> {
    let (phi, qd) = discrete::<N, M>(s, q_hold)?;
    let phi_t = transpose(&phi);
    let r = reading_variance(s);
    // One reading: the prior from the last posterior, the gain, the
    // posterior.
    let step = |post: &Mat<N>| -> ([f64; N], f64, Mat<N>) {
        let mut prior = mul(&mul(&phi, post), &phi_t);
        for i in 0..N {
            for j in 0..N {
                prior[i][j] += qd[i][j];
            }
        }
        update(&prior, r)
    };
    let slots: &[(usize, usize)] = if N == 4 {
        &[(0, 0), (1, 1), (2, 2), (3, 3)]
    } else {
        &[(0, 0), (1, 1), (N - 1, 3)]
    };
    let converged = |k: &[f64; N]| {
        slots.iter().all(|&(i, slot)| {
            (k[i] - f64::from(hold.gain[slot])).abs() <= SCHEDULE_CONVERGED * f64::from(hold.gain[slot]).abs()
        })
    };
    let mut post = *start;
    let mut readings = SCHEDULE_MAX_READINGS;
    for n in 1..=SCHEDULE_MAX_READINGS {
        let (k, _, next) = step(&post);
        if !k.iter().all(|v| v.is_finite()) {
            return Err(DesignError::Numerics);
        }
        post = next;
        if converged(&k) {
            readings = n;
            break;
        }
    }
    let last = (SCHEDULE - 1) as u32;
    let c = readings.div_ceil(last * last).max(1);
    let mut out = [*hold; SCHEDULE];
    out[0] = *fast;
    let mut post = *start;
    let mut n = 0;
    for (j, entry) in out.iter_mut().enumerate().take(SCHEDULE - 1).skip(1) {
        let target = c * (j as u32) * (j as u32);
        let mut at = None;
        while n < target {
            at = Some(step(&post));
            post = at.map_or(post, |a| a.2);
            n += 1;
        }
        if let Some((k, innovation, p)) = at {
            *entry = gains(k, innovation, &p, q_hold);
        }
    }
    Ok((out, f64::from(c)))
}

impl ObserverDesign {
    /// Designs the observer (see the module docs).
    ///
    /// # Errors
    ///
    /// [`DesignError::Settings`] when a setting is not positive and finite
    /// (`well_time_constant` and `noise` may be 0; `noise` and `resolution`
    /// not both), [`DesignError::Numerics`] when no steady-state filter is
    /// found.
    pub fn new(s: &ObserverSettings) -> Result<Self, DesignError> {
        let positive = |v: f64| v > 0.0 && v.is_finite();
        let non_negative = |v: f64| v >= 0.0 && v.is_finite();
        if !(positive(s.time_constant)
            && non_negative(s.well_time_constant)
            && non_negative(s.noise)
            && non_negative(s.resolution)
            && (s.noise > 0.0 || s.resolution > 0.0)
            && positive(s.max_rate)
            && positive(s.tick)
            && positive(s.sample_period)
            && positive(s.span))
        {
            return Err(DesignError::Settings);
        }
        let well = s.well_time_constant > 0.0;
        let lag = s.time_constant + s.well_time_constant;
        let accel = s.max_rate / lag;
        let q_fast = (accel / 2.0) * (accel / 2.0) * s.sample_period;
        let q_hold = HOLD_RATIO * q_fast;
        // Each mode's steady state; the schedule starts from the fast
        // mode's posterior covariance.
        let (hold, fast, schedule, readings_per) = if well {
            let (k, i, p) = mode::<4, 8>(s, q_hold)?;
            let hold = gains(k, i, &p, q_hold);
            let (k, i, p) = mode::<4, 8>(s, q_fast)?;
            let fast = gains(k, i, &p, q_fast);
            let (schedule, c) = schedule::<4, 8>(s, q_hold, &p, &hold, &fast)?;
            (hold, fast, schedule, c)
        } else {
            let (k, i, p) = mode::<3, 6>(s, q_hold)?;
            let hold = gains(k, i, &p, q_hold);
            let (k, i, p) = mode::<3, 6>(s, q_fast)?;
            let fast = gains(k, i, &p, q_fast);
            let (schedule, c) = schedule::<3, 6>(s, q_hold, &p, &hold, &fast)?;
            (hold, fast, schedule, c)
        };
        // The per-tick transition (noise-free), as increments.
        let (well_oil, well_rate, probe_oil, probe_well, probe_rate) = if well {
            let (phi, _) = van_loan::<4, 8>(&model::<4>(s), &[0.0; 4], 0.0, s.tick).ok_or(DesignError::Numerics)?;
            (phi[2][0], phi[2][1], phi[3][0], phi[3][2], phi[3][1])
        } else {
            let (phi, _) = van_loan::<3, 6>(&model::<3>(s), &[0.0; 3], 0.0, s.tick).ok_or(DesignError::Numerics)?;
            (0.0, 0.0, phi[2][0], 0.0, phi[2][1])
        };
        let design = ObserverDesign {
            tick: s.tick as f32,
            sample_period: s.sample_period as f32,
            well,
            well_oil: well_oil as f32,
            well_rate: well_rate as f32,
            probe_oil: probe_oil as f32,
            probe_well: probe_well as f32,
            probe_rate: probe_rate as f32,
            hold,
            fast,
            schedule,
            schedule_rate: (s.tick / (readings_per * s.sample_period)) as f32,
            gate_rate: (s.span / s.time_constant) as f32,
            rate_limit: (RATE_LIMIT * s.max_rate) as f32,
            innovation_weight: -libm::expm1(-s.sample_period / lag) as f32,
            gate_noise: (6.0 * libm::sqrt(2.0 * reading_variance(s))) as f32,
        };
        let finite = [
            design.well_oil,
            design.well_rate,
            design.probe_oil,
            design.probe_well,
            design.probe_rate,
            design.schedule_rate,
            design.gate_rate,
            design.gate_noise,
            design.rate_limit,
            design.innovation_weight,
        ]
        .iter()
        .chain(hold.gain.iter())
        .chain(fast.gain.iter())
        .chain(
            [
                hold.inv_innovation_sd,
                fast.inv_innovation_sd,
                hold.var_oil,
                fast.var_oil,
            ]
            .iter(),
        )
        .all(|v| v.is_finite());
        let schedule_finite = schedule.iter().all(|g| {
            g.gain
                .into_iter()
                .chain([g.inv_innovation_sd, g.var_oil, g.cov_oil_rate, g.var_rate, g.q])
                .all(f32::is_finite)
        });
        if finite && schedule_finite {
            Ok(design)
        } else {
            Err(DesignError::Numerics)
        }
    }

    /// The largest change of the reading the oil can explain `ticks` after
    /// the last accepted one \[C\]: `gate_rate t + gate_noise`. A reading
    /// further from the last accepted one is out of band (a spike, or after
    /// enough agreeing ones a step of the reading itself, where the observer
    /// restarts), whatever the spike threshold: inverting the probe's lag,
    /// a jump of the reading the oil cannot have made would be amplified by
    /// up to `tau_p / T_s` in the oil's estimate (a 4 C jump through an
    /// 8 s probe: 17 C).
    pub fn gate(&self, ticks: u32) -> f32 {
        self.gate_rate * (ticks as f32 * self.tick) + self.gate_noise
    }

    /// How long the schedule lasts after a change \[s\]: from then on the
    /// gains are the hold mode's. At least `(SCHEDULE - 1)^2` readings
    /// (10.6 s at 50 Hz); 42 s (5.3 time constants) for an 8 s probe with
    /// 0.02 C of noise and `max_oil_rate` 1 C/s, longer for a noisier probe
    /// or a smaller plausible rate (85 s at 0.1 C/s), shorter for a larger
    /// one.
    pub fn schedule_time(&self) -> f32 {
        let last = (SCHEDULE - 1) as f32;
        last * last / self.schedule_rate * self.tick
    }

    /// Where `ticks` after a change sits on the schedule, in `[0, 1]` (0:
    /// the fast mode, 1: the hold mode).
    fn position(&self, ticks: u32) -> f32 {
        let last = (SCHEDULE - 1) as f32;
        let p = (ticks as f32 * self.schedule_rate).sqrt();
        if p < last { p / last } else { 1.0 }
    }

    /// The constants `pick` takes of the schedule's entries `ticks` after
    /// a change: the entries around `sqrt(ticks schedule_rate)`, each
    /// constant interpolated linearly. Only what the caller uses is
    /// interpolated (a reading's update needs five of the nine constants,
    /// the variance the other four: on a core without an FPU each is a
    /// software subtraction, product and sum).
    #[inline]
    fn at<const N: usize>(&self, ticks: u32, pick: impl Fn(&ModeGains) -> [f32; N]) -> [f32; N] {
        let last = SCHEDULE - 1;
        let p = (ticks as f32 * self.schedule_rate).sqrt();
        if !(p < last as f32) {
            return pick(&self.schedule[last]);
        }
        let j = (p as usize).min(last - 1);
        let m = p - j as f32;
        let (h, f) = (pick(&self.schedule[j]), pick(&self.schedule[j + 1]));
        let mut out = h;
        for (o, (a, b)) in out.iter_mut().zip(h.iter().zip(f.iter())) {
            *o = a + m * (b - a);
        }
        out
    }
}

/// The observer's state (the design and the spike settings come with each
/// call).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OilObserver {
    /// Estimated oil temperature [C] and its compensation carry.
    oil: f32,
    oil_carry: f32,
    /// Estimated rate [C/s] and its compensation carry.
    rate: f32,
    rate_carry: f32,
    /// Estimated well temperature [C] (the oil's without a well).
    well: f32,
    well_carry: f32,
    /// Estimated probe temperature [C].
    probe: f32,
    probe_carry: f32,
    /// Ticks since the last CUSUM alarm (saturating): where the gains are
    /// on the schedule.
    since_alarm: u32,
    /// Running mean square of the normalised innovations (1 when the model
    /// holds).
    innovations: f32,
    /// Two-sided CUSUM of the normalised innovations.
    cusum_up: f32,
    cusum_down: f32,
    /// Ticks since the last accepted reading (saturating).
    since_reading: u32,
    /// The last accepted reading [C].
    last_reading: f32,
    /// Spike rejection in front of the update.
    gate: SpikeGate,
}

impl OilObserver {
    /// At rest at `initial` \[C\] (oil, well and probe), rate 0, at the
    /// start of the schedule (the fast mode): the first readings are followed quickly, and the estimate's
    /// variance starts at the fast mode's.
    pub const fn new(initial: f32) -> Self {
        OilObserver {
            oil: initial,
            oil_carry: 0.0,
            rate: 0.0,
            rate_carry: 0.0,
            well: initial,
            well_carry: 0.0,
            probe: initial,
            probe_carry: 0.0,
            since_alarm: 0,
            innovations: 1.0,
            cusum_up: 0.0,
            cusum_down: 0.0,
            since_reading: 0,
            last_reading: initial,
            gate: SpikeGate::new(initial),
        }
    }

    /// The estimated oil temperature \[C\].
    #[inline]
    pub fn oil(&self) -> f32 {
        self.oil
    }

    /// The estimated rate of the oil temperature [C/s].
    pub fn rate(&self) -> f32 {
        self.rate
    }

    /// The estimated well temperature \[C\] (the oil's without a well).
    pub fn well(&self) -> f32 {
        self.well
    }

    /// The estimated probe temperature \[C\] (what the next reading is
    /// expected to be, without noise).
    pub fn probe(&self) -> f32 {
        self.probe
    }

    /// The last accepted reading \[C\].
    pub fn last_reading(&self) -> f32 {
        self.last_reading
    }

    /// Where the gains are between the fast mode (0, right after a change)
    /// and the hold mode (1), on the schedule's square-root scale.
    pub fn settling(&self, design: &ObserverDesign) -> f32 {
        design.position(self.since_alarm)
    }

    /// Variance of the oil temperature estimate [C^2]: the schedule's
    /// after a reading, grown by extrapolating the rate over the time since
    /// the last accepted reading `t`: `P00 + 2 P01 t + P11 t^2 + q t^3 / 3`,
    /// scaled by the innovations' running mean square where it exceeds one
    /// (covariance matching, Mehra 1972: innovations larger than the model
    /// expects, as after a jump of the oil it does not describe, say that
    /// the estimate is worse than the steady state's variance).
    pub fn variance(&self, design: &ObserverDesign) -> f32 {
        let [var_oil, cov_oil_rate, var_rate, q] =
            design.at(self.since_alarm, |g| [g.var_oil, g.cov_oil_rate, g.var_rate, g.q]);
        let t = self.since_reading as f32 * design.tick;
        let steady = var_oil + t * (2.0 * cov_oil_rate + t * (var_rate + t * q * (1.0 / 3.0)));
        steady * self.innovations.max(1.0)
    }

    /// One tick: the prediction to this tick (see the module docs).
    #[inline]
    pub fn predict(&mut self, design: &ObserverDesign) {
        let (oil, well, probe, rate) = (self.oil, self.well, self.probe, self.rate);
        let input = if design.well { well } else { oil };
        let d_probe = design.probe_oil * (oil - probe) + design.probe_well * (input - probe) + design.probe_rate * rate;
        self.probe = probe.mul_add_compensated(1.0, d_probe, &mut self.probe_carry);
        if design.well {
            let d_well = design.well_oil * (oil - well) + design.well_rate * rate;
            self.well = well.mul_add_compensated(1.0, d_well, &mut self.well_carry);
        }
        self.oil = oil.mul_add_compensated(design.tick, rate, &mut self.oil_carry);
        if !design.well {
            self.well = self.oil;
        }
        self.since_alarm = self.since_alarm.saturating_add(1);
        self.since_reading = self.since_reading.saturating_add(1);
    }

    /// A reading `y` \[C\] (finite: the caller rejects the rest): gated
    /// against the last accepted reading by the spike settings, the
    /// threshold no wider than [`ObserverDesign::gate`] (a spike is
    /// rejected; the `limit + 1`-th agreeing out-of-band reading is a real
    /// step, where the observer restarts at rest at it, in the fast mode),
    /// else the update.
    pub fn offer(&mut self, design: &ObserverDesign, spikes: &SpikeSettings, y: f32) -> Verdict {
        let band = SpikeSettings {
            threshold: spikes.threshold.min(design.gate(self.since_reading)),
            limit: spikes.limit,
        };
        let verdict = self.gate.offer(&band, self.last_reading, y);
        match verdict {
            Verdict::Spike => return verdict,
            Verdict::Step => {
                *self = OilObserver {
                    gate: self.gate,
                    ..OilObserver::new(y)
                };
                return verdict;
            }
            Verdict::Accepted => {}
        }
        let [g0, g1, g2, g3, inv_innovation_sd] = design.at(self.since_alarm, |g| {
            let [g0, g1, g2, g3] = g.gain;
            [g0, g1, g2, g3, g.inv_innovation_sd]
        });
        let nu = y - self.probe;
        self.oil = self.oil.mul_add_compensated(g0, nu, &mut self.oil_carry);
        self.rate = self.rate.mul_add_compensated(g1, nu, &mut self.rate_carry);
        let limit = design.rate_limit;
        if !(libm::fabsf(self.rate) <= limit) {
            self.rate = if self.rate > 0.0 { limit } else { -limit };
            self.rate_carry = 0.0;
        }
        if design.well {
            self.well = self.well.mul_add_compensated(g2, nu, &mut self.well_carry);
        } else {
            self.well = self.oil;
        }
        self.probe = self.probe.mul_add_compensated(g3, nu, &mut self.probe_carry);
        // The innovations' CUSUM: a shift in their mean is a change the
        // current mode does not follow.
        let u = nu * inv_innovation_sd;
        self.innovations += (u * u - self.innovations) * design.innovation_weight;
        self.cusum_up = (self.cusum_up + u - CUSUM_DRIFT).max(0.0);
        self.cusum_down = (self.cusum_down - u - CUSUM_DRIFT).max(0.0);
        if self.cusum_up > CUSUM_THRESHOLD || self.cusum_down > CUSUM_THRESHOLD {
            self.since_alarm = 0;
            self.cusum_up = 0.0;
            self.cusum_down = 0.0;
        }
        self.since_reading = 0;
        self.last_reading = y;
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic normal generator (xorshift64 and Box-Muller).
    struct Noise(u64);

    impl Noise {
        fn unit(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn normal(&mut self) -> f64 {
            let (u, v) = (self.unit(), self.unit());
            (-2.0 * u.ln()).sqrt() * (2.0 * core::f64::consts::PI * v).cos()
        }
    }

    const CODE: f64 = 0.033;

    fn settings(time_constant: f64, well: f64, noise: f64) -> ObserverSettings {
        ObserverSettings {
            time_constant,
            well_time_constant: well,
            noise,
            resolution: CODE,
            max_rate: 1.0,
            tick: 1e-3,
            sample_period: 0.02,
            span: 170.0,
        }
    }

    /// The probe (and well) exactly over `dt` for an oil ramp of `rate`
    /// from `oil` (closed form of the first-order lags).
    struct Probe {
        oil: f64,
        well: f64,
        probe: f64,
        tau: f64,
        tau_w: f64,
    }

    impl Probe {
        fn advance(&mut self, rate: f64, dt: f64) {
            // Substeps of 1 ms: the lags' exact response to a linear input.
            let n = (dt / 1e-3).round().max(1.0) as usize;
            let h = dt / n as f64;
            for _ in 0..n {
                let lag = |y: f64, u0: f64, slope: f64, tau: f64| {
                    let e = (-h / tau).exp();
                    // y' = (u - y) / tau with u = u0 + slope s.
                    u0 + slope * h - slope * tau + (y - u0 + slope * tau) * e
                };
                let w_slope = if self.tau_w > 0.0 { 0.0 } else { rate };
                if self.tau_w > 0.0 {
                    let w0 = self.well;
                    self.well = lag(self.well, self.oil, rate, self.tau_w);
                    // The probe follows the well, taken linear over h.
                    let ws = (self.well - w0) / h;
                    self.probe = lag(self.probe, w0, ws, self.tau);
                } else {
                    self.probe = lag(self.probe, self.oil, w_slope, self.tau);
                }
                self.oil += rate * h;
            }
        }
    }

    /// Runs the observer through `seconds` of an oil held at 40 C until
    /// `start` and rising at `rate` after, through a probe of `tau` (and
    /// `tau_w`), with `noise` and quantization; returns, per reading, the
    /// time, the estimate's error and its standard deviation.
    fn run(tau: f64, tau_w: f64, noise: f64, rate: f64, start: f64, seconds: f64, seed: u64) -> Vec<(f64, f64, f64)> {
        let s = settings(tau, tau_w, noise);
        let d = ObserverDesign::new(&s).unwrap();
        let spikes = SpikeSettings {
            threshold: 5.0,
            limit: 5,
        };
        let mut o = OilObserver::new(40.0);
        let mut p = Probe {
            oil: 40.0,
            well: 40.0,
            probe: 40.0,
            tau,
            tau_w,
        };
        let mut n = Noise(2 * seed + 1);
        let mut out = Vec::new();
        let readings = (seconds / s.sample_period) as usize;
        for k in 0..readings {
            let t = k as f64 * s.sample_period;
            p.advance(if t >= start { rate } else { 0.0 }, s.sample_period);
            for _ in 0..20 {
                o.predict(&d);
            }
            let y = ((p.probe + noise * n.normal()) / CODE).round() * CODE;
            assert_eq!(o.offer(&d, &spikes, y as f32), Verdict::Accepted);
            out.push((
                t + s.sample_period,
                f64::from(o.oil()) - p.oil,
                f64::from(o.variance(&d)).sqrt(),
            ));
        }
        out
    }

    /// The standard deviation of a first-order low-pass of 0.2 s over the
    /// same noisy readings of a held oil (the estimator's filter before the
    /// observer).
    fn low_pass_sd(noise: f64, seed: u64) -> f64 {
        let mut n = Noise(seed | 1);
        let g = 1.0 - (-0.02f64 / 0.2).exp();
        let mut y = 40.0;
        let mut sum2 = 0.0;
        let count = 20_000;
        for k in 0..count + 500 {
            let r = ((40.0 + noise * n.normal()) / CODE).round() * CODE;
            y += g * (r - y);
            if k >= 500 {
                sum2 += (y - 40.0) * (y - 40.0);
            }
        }
        (sum2 / count as f64).sqrt()
    }

    /// The steady state of the plain Riccati recursion, iterated to
    /// convergence: an independent check of the doubling's.
    fn riccati_iterated(s: &ObserverSettings, q: f64) -> [f64; 3] {
        let a = model::<3>(s);
        let (phi, qd) = van_loan::<3, 6>(&a, &[0.0, 1.0, 0.0], q, s.sample_period).unwrap();
        let r = s.noise * s.noise + s.resolution * s.resolution / 12.0;
        let mut p = qd;
        let mut k = [0.0; 3];
        for _ in 0..2_000_000 {
            let sv = p[2][2] + r;
            k = [p[0][2] / sv, p[1][2] / sv, p[2][2] / sv];
            let mut post = p;
            for i in 0..3 {
                for j in 0..3 {
                    post[i][j] = p[i][j] - k[i] * p[2][j];
                }
            }
            let mut next = qd;
            for i in 0..3 {
                for j in 0..3 {
                    for l in 0..3 {
                        for m in 0..3 {
                            next[i][j] += phi[i][l] * post[l][m] * phi[j][m];
                        }
                    }
                }
            }
            let change = (0..3)
                .map(|i| (next[i][i] - p[i][i]).abs() / p[i][i])
                .fold(0.0, f64::max);
            p = next;
            if change < 1e-15 {
                break;
            }
        }
        k
    }

    /// The time-varying filter after a change, run reading by reading: the
    /// plain recursion under `q_fast` to its steady state, then under
    /// `q_hold`; the gains at each reading after the switch.
    fn recursion_after_a_change<const N: usize, const M: usize>(
        s: &ObserverSettings,
        q_fast: f64,
        readings: usize,
    ) -> Vec<[f64; N]> {
        let mut g = [0.0; N];
        g[1] = 1.0;
        let r = s.noise * s.noise + s.resolution * s.resolution / 12.0;
        let step = |p: &Mat<N>, phi: &Mat<N>, qd: &Mat<N>| -> ([f64; N], Mat<N>) {
            // p is the prior: the gain, the posterior, the next prior.
            let sv = p[N - 1][N - 1] + r;
            let k: [f64; N] = core::array::from_fn(|i| p[i][N - 1] / sv);
            let post: Mat<N> = core::array::from_fn(|i| core::array::from_fn(|j| p[i][j] - k[i] * p[N - 1][j]));
            let next: Mat<N> = core::array::from_fn(|i| {
                core::array::from_fn(|j| {
                    qd[i][j]
                        + (0..N)
                            .map(|l| (0..N).map(|m| phi[i][l] * post[l][m] * phi[j][m]).sum::<f64>())
                            .sum::<f64>()
                })
            });
            (k, next)
        };
        let (phi, qd) = van_loan::<N, M>(&model::<N>(s), &g, q_fast, s.sample_period).unwrap();
        let mut p = qd;
        for _ in 0..400_000 {
            p = step(&p, &phi, &qd).1;
        }
        let (_, qd_hold) = van_loan::<N, M>(&model::<N>(s), &g, HOLD_RATIO * q_fast, s.sample_period).unwrap();
        // The change's reading is the fast mode's; the hold's noise from it on.
        let (_, post_fast) = {
            let sv = p[N - 1][N - 1] + r;
            let k: [f64; N] = core::array::from_fn(|i| p[i][N - 1] / sv);
            (
                k,
                core::array::from_fn::<[f64; N], N, _>(|i| core::array::from_fn(|j| p[i][j] - k[i] * p[N - 1][j])),
            )
        };
        let mut p: Mat<N> = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                qd_hold[i][j]
                    + (0..N)
                        .map(|l| (0..N).map(|m| phi[i][l] * post_fast[l][m] * phi[j][m]).sum::<f64>())
                        .sum::<f64>()
            })
        });
        let mut out = Vec::with_capacity(readings);
        for _ in 0..readings {
            let (k, next) = step(&p, &phi, &qd_hold);
            out.push(k);
            p = next;
        }
        out
    }

    #[test]
    fn the_schedule_is_the_filters_own_recursion_from_the_fast_mode_to_the_hold_mode() {
        for (tau, well) in [(2.0, 0.0), (8.0, 0.0), (30.0, 0.0), (4.0, 12.0)] {
            let s = settings(tau, well, 0.02);
            let d = ObserverDesign::new(&s).unwrap();
            let accel = s.max_rate / (tau + well);
            let q_fast = (accel / 2.0) * (accel / 2.0) * s.sample_period;
            let c = (s.tick / (f64::from(d.schedule_rate) * s.sample_period)).round() as usize;
            let last = SCHEDULE - 1;
            let ks: Vec<[f64; 4]> = if well > 0.0 {
                recursion_after_a_change::<4, 8>(&s, q_fast, c * last * last)
            } else {
                recursion_after_a_change::<3, 6>(&s, q_fast, c * last * last)
                    .into_iter()
                    .map(|k| [k[0], k[1], 0.0, k[2]])
                    .collect()
            };
            assert_eq!(d.schedule[0], d.fast, "tau {tau}");
            assert_eq!(d.schedule[last], d.hold, "tau {tau}");
            for j in 1..last {
                let k = ks[c * j * j - 1];
                for slot in [0, 1, 3] {
                    let rel = (f64::from(d.schedule[j].gain[slot]) / k[slot] - 1.0).abs();
                    assert!(
                        rel < 1e-5,
                        "tau {tau}, entry {j}, gain {slot}: {} vs {}",
                        d.schedule[j].gain[slot],
                        k[slot]
                    );
                }
            }
            // By its last entry the recursion has come to the hold mode.
            let k = ks[c * last * last - 1];
            for slot in [0, 1, 3] {
                let rel = (f64::from(d.hold.gain[slot]) / k[slot] - 1.0).abs();
                assert!(rel <= 1.01 * SCHEDULE_CONVERGED, "tau {tau}, gain {slot}: {rel}");
            }
            // And not long before: the fast mode's gains are well above.
            assert!(d.fast.gain[0] > 3.0 * d.hold.gain[0], "tau {tau}");
        }
    }

    #[test]
    fn the_gains_are_the_riccati_equations_steady_state() {
        for tau in [2.0, 8.0, 30.0] {
            let s = settings(tau, 0.0, 0.02);
            let d = ObserverDesign::new(&s).unwrap();
            let accel = s.max_rate / tau;
            let q_fast = (accel / 2.0) * (accel / 2.0) * s.sample_period;
            for (mode, q) in [(d.hold, HOLD_RATIO * q_fast), (d.fast, q_fast)] {
                let k = riccati_iterated(&s, q);
                for (i, slot) in [(0usize, 0usize), (1, 1), (2, 3)] {
                    let rel = (f64::from(mode.gain[slot]) / k[i] - 1.0).abs();
                    assert!(
                        rel < 1e-5,
                        "tau {tau}, q {q:e}: gain {i} {} vs {}",
                        mode.gain[slot],
                        k[i]
                    );
                }
            }
        }
    }

    #[test]
    fn a_hold_is_estimated_without_bias_and_with_less_noise_than_the_low_pass() {
        for tau in [2.0, 8.0, 30.0] {
            let out = run(tau, 0.0, 0.02, 0.0, f64::INFINITY, 400.0, 7);
            // After the start-up (the fast mode decays with the probe).
            let tail = &out[out.len() / 4..];
            let n = tail.len() as f64;
            let mean = tail.iter().map(|r| r.1).sum::<f64>() / n;
            let sd = (tail.iter().map(|r| (r.1 - mean) * (r.1 - mean)).sum::<f64>() / n).sqrt();
            let lp = low_pass_sd(0.02, 7);
            assert!(mean.abs() < 0.005, "tau {tau}: bias {mean} C");
            assert!(sd < lp, "tau {tau}: noise {sd} C, the 0.2 s low-pass's {lp} C");
            // The variance it reports is the hold mode's, the same order
            // as the noise it passes.
            let reported = tail.last().unwrap().2;
            assert!(
                reported > 0.5 * sd && reported < 3.0 * sd,
                "tau {tau}: reports {reported}, passes {sd}"
            );
        }
    }

    #[test]
    fn a_warm_up_is_followed_through_the_probes_lag() {
        // (probe, well, rate, bound after two probe time constants [C]).
        for (tau, well, rate, bound) in [
            (8.0, 0.0, 0.5, 0.06),
            (8.0, 0.0, 0.05, 0.05),
            (2.0, 0.0, 0.5, 0.06),
            (30.0, 0.0, 0.5, 0.06),
            (4.0, 12.0, 0.5, 0.1),
        ] {
            for seed in [1, 2, 4] {
                let start = 60.0;
                let out = run(tau, well, 0.02, rate, start, start + 2.0 * (tau + well) + 60.0, seed);
                let after = start + 2.0 * (tau + well);
                let worst = out
                    .iter()
                    .filter(|r| r.0 >= after)
                    .map(|r| r.1.abs())
                    .fold(0.0, f64::max);
                // The reading itself lags by rate * lag.
                assert!(
                    worst < bound,
                    "tau {tau}, well {well}, {rate} C/s, seed {seed}: {worst} C off (the reading lags {} C)",
                    rate * (tau + well)
                );
            }
        }
    }

    #[test]
    fn the_variance_grows_in_a_fast_change_and_falls_in_a_hold() {
        let out = run(8.0, 0.0, 0.02, 0.5, 100.0, 200.0, 3);
        let at = |t: f64| out.iter().find(|r| r.0 >= t).unwrap().2;
        let hold = at(99.0);
        let change = (100..130).map(|t| at(t as f64)).fold(0.0, f64::max);
        assert!(change > 2.0 * hold, "hold {hold} C, in the change {change} C");
        // Back to a steady ramp: the rate is learnt, the variance falls.
        assert!(at(199.0) < 0.6 * change, "{} vs {change}", at(199.0));
    }

    /// A jump of the oil (38 C at once, beyond the declared 1 C/s) through
    /// a 6 s probe: the rate limit keeps the estimate from ringing far past
    /// the new level (16 C without it), it settles within 0.1 C in 15 s,
    /// and its variance says it is unsure meanwhile.
    #[test]
    fn a_jump_of_the_oil_is_followed_without_ringing_and_its_variance_grows() {
        let s = settings(6.0, 0.0, 0.02);
        let d = ObserverDesign::new(&s).unwrap();
        let spikes = SpikeSettings {
            threshold: 5.0,
            limit: 5,
        };
        let mut o = OilObserver::new(78.0);
        let reading = |o: &mut OilObserver, y: f64| {
            for _ in 0..20 {
                o.predict(&d);
            }
            assert_eq!(o.offer(&d, &spikes, y as f32), Verdict::Accepted, "{y}");
        };
        for _ in 0..3000 {
            reading(&mut o, 78.0);
        }
        let hold = o.variance(&d);
        let mut probe = 78.0f64;
        let (mut low, mut late, mut worst_sd) = (f32::INFINITY, 0.0f32, 0.0f32);
        for k in 0..2000 {
            probe += (40.0 - probe) * -(-0.02f64 / 6.0).exp_m1();
            reading(&mut o, probe);
            low = low.min(o.oil());
            if k >= 750 {
                late = late.max((o.oil() - 40.0).abs());
            }
            worst_sd = worst_sd.max(o.variance(&d).sqrt());
        }
        assert!(low > 35.0, "undershoot to {low} C");
        assert!(late < 0.1, "{late} C off after 15 s");
        assert!(
            worst_sd > 20.0 * hold.sqrt() && worst_sd > 0.5,
            "sd {worst_sd} C (hold {} C)",
            hold.sqrt()
        );
        assert!(o.rate().abs() <= d.rate_limit);
    }

    #[test]
    fn a_real_step_restarts_the_observer_at_it() {
        let s = settings(8.0, 0.0, 0.02);
        let d = ObserverDesign::new(&s).unwrap();
        let spikes = SpikeSettings {
            threshold: 5.0,
            limit: 2,
        };
        let mut o = OilObserver::new(40.0);
        let reading = |o: &mut OilObserver, y: f32| {
            for _ in 0..20 {
                o.predict(&d);
            }
            o.offer(&d, &spikes, y)
        };
        assert_eq!(reading(&mut o, 60.0), Verdict::Spike);
        assert_eq!(reading(&mut o, 60.5), Verdict::Spike);
        assert!((o.oil() - 40.0).abs() < 1e-6);
        assert_eq!(reading(&mut o, 61.0), Verdict::Step);
        assert_eq!((o.oil(), o.probe(), o.rate(), o.settling(&d)), (61.0, 61.0, 0.0, 0.0));
        for _ in 0..20 {
            o.predict(&d);
        }
        assert_eq!(o.offer(&d, &spikes, 61.2), Verdict::Accepted);
        // Within the spike threshold but beyond what the oil can move an
        // 8 s probe in one reading (170 C over 20 ms: 0.42 C, and the
        // noise): out of band too, and after the limit a step, not a
        // 17 C overshoot of the oil's estimate.
        assert!(d.gate(20) > 0.4 && d.gate(20) < 0.7, "{}", d.gate(20));
        let mut o = OilObserver::new(50.0);
        for _ in 0..20 {
            o.predict(&d);
        }
        assert_eq!(o.offer(&d, &spikes, 54.0), Verdict::Spike);
        assert_eq!(o.offer(&d, &spikes, 54.0), Verdict::Spike);
        assert_eq!(o.offer(&d, &spikes, 54.0), Verdict::Step);
        assert_eq!(o.oil(), 54.0);
        // The oil crossing its range through the probe: every reading in
        // band.
        let mut o = OilObserver::new(-20.0);
        let mut probe = -20.0f64;
        for _ in 0..3000 {
            probe += (150.0 - probe) * -(-0.02f64 / 8.0).exp_m1();
            for _ in 0..20 {
                o.predict(&d);
            }
            assert_eq!(o.offer(&d, &spikes, probe as f32), Verdict::Accepted, "{probe}");
        }
    }

    #[test]
    fn designs_refuse_what_is_not_a_probe() {
        let ok = settings(8.0, 0.0, 0.02);
        for bad in [
            ObserverSettings {
                time_constant: 0.0,
                ..ok
            },
            ObserverSettings {
                time_constant: f64::NAN,
                ..ok
            },
            ObserverSettings {
                well_time_constant: -1.0,
                ..ok
            },
            ObserverSettings {
                noise: 0.0,
                resolution: 0.0,
                ..ok
            },
            ObserverSettings { max_rate: 0.0, ..ok },
            ObserverSettings {
                sample_period: f64::INFINITY,
                ..ok
            },
            ObserverSettings { span: 0.0, ..ok },
        ] {
            assert_eq!(ObserverDesign::new(&bad), Err(DesignError::Settings), "{bad:?}");
        }
    }
}
