//! Reference solution of the FSI model (`docs/model.md` section 6) in SI units.
//!
//! ```text
//! C_a dp_a/dt = Q_t(p_p - p_a) - (p_a - p_c) / R_l + A_p v,  C_a = (V_a0 - A_p x) / beta
//! C_b dp_b/dt = (p_p - p_b) / R_l - Q_t(p_b - p_c) - A_p v,  C_b = (V_b0 + A_p x) / beta
//! m dv/dt     = A_p (p_b - p_a) - b v - c (x0 + x)
//! ```
//!
//! with the orifice law regularised as in the core (`regRoot`, transition at
//! `1e-5 dp`) and the oil's properties evaluated at the profile's
//! temperature at every time (a ramp is followed exactly, not per tick).
//!
//! The port pressures `p_p`, `p_c` are the parameter file's, or a given
//! history ([`Ports::Given`], piecewise linear: a changing pressure drop), or
//! the outlet is the node of a circuit ([`Ports::Circuit`]: a line volume
//! between the compensator and a load orifice to a tank),
//!
//! ```text
//! C_line dp_c/dt = Q0 - Q_load(p_c),  Q0 = (p_a - p_c) / R_l + Q_t(p_b - p_c) + Q_w(x, p_p - p_c)
//! Q_load(p) = K_load sign(p - p_tank) sqrt|p - p_tank|,  Q_w = eta pi d x sqrt(2 (p_p - p_c) / rho)
//! ```
//!
//! integrated with the compensator as one stiff system.
//!
//! With Coulomb friction ([`simulate_with_friction`]) the plunger's
//! equation gains `- F sign(v)`; a plunger at rest stays while `|force| <=
//! F` ([`Mode::Stuck`]), each reversal of its speed is an event.
//!
//! The end stops are events: in free motion the solver stops exactly where
//! `x` reaches a stop (inelastic: `v = 0`, then held if the static force
//! pushes into the stop); while held it stops where the force changes sign
//! (release). Each phase restarts a fresh solver. Event times are found by
//! the Illinois method on the solver's dense output ([`Phase`]), because the
//! library's own event search can lose its bracket (0.7.0).

use crate::statics;
use compensator_params::RawCore;
use differential_equations::ode::{OrdinaryNumericalMethod, solve_ode};
use differential_equations::prelude::*;
use std::f64::consts::PI;

/// Transition of the regularised orifice law, as a fraction of `dp` (the
/// core's value, restated).
pub const TRANSITION_FRACTION: f64 = 1.0e-5;

/// The temperature seen by the compensator over time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile {
    /// At equilibrium at `from` before `t = 0`, at `to` after.
    Step {
        /// Initial temperature [C].
        from: f64,
        /// Final temperature [C].
        to: f64,
    },
    /// From `from` to `to` at `rate` [C/s] starting at `t = 0`, then constant.
    Ramp {
        /// Initial temperature [C].
        from: f64,
        /// Final temperature [C].
        to: f64,
        /// Rate magnitude [C/s].
        rate: f64,
    },
}

impl Profile {
    /// Temperature at time `t` [s].
    pub fn temperature(&self, t: f64) -> f64 {
        match *self {
            Profile::Step { from, to } => {
                if t > 0.0 {
                    to
                } else {
                    from
                }
            }
            Profile::Ramp { from, to, rate } => {
                let span = (to - from).abs() / rate;
                if t >= span {
                    to
                } else {
                    from + (to - from) * (t.max(0.0) / span)
                }
            }
        }
    }

    /// Initial temperature [C].
    pub fn start(&self) -> f64 {
        match *self {
            Profile::Step { from, .. } | Profile::Ramp { from, .. } => from,
        }
    }

    /// Final temperature [C].
    pub fn end(&self) -> f64 {
        match *self {
            Profile::Step { to, .. } | Profile::Ramp { to, .. } => to,
        }
    }

    /// Times where the temperature's derivative jumps (phase boundaries).
    pub fn kinks(&self) -> Vec<f64> {
        match *self {
            Profile::Step { .. } => vec![],
            Profile::Ramp { from, to, rate } => vec![(to - from).abs() / rate],
        }
    }
}

/// One piece of a port-pressure history: supply and outlet pressure [Pa]
/// linear in time from `t0` [s].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    t0: f64,
    supply: (f64, f64),
    outlet: (f64, f64),
}

impl Segment {
    fn at(&self, t: f64) -> (f64, f64) {
        let dt = t - self.t0;
        (self.supply.0 + self.supply.1 * dt, self.outlet.0 + self.outlet.1 * dt)
    }
}

/// A piecewise-linear history `(time [s], value)`, held before its first
/// and after its last point; two points at one time are a jump.
fn segment_of(points: &[(f64, f64)], t: f64) -> (f64, f64, f64) {
    let Some(&(t_first, v_first)) = points.first() else {
        return (t, 0.0, 0.0);
    };
    if t < t_first {
        return (t_first, v_first, 0.0);
    }
    for w in points.windows(2) {
        let ((ta, va), (tb, vb)) = (w[0], w[1]);
        if t >= ta && t < tb {
            return (ta, va, (vb - va) / (tb - ta));
        }
    }
    let &(tl, vl) = points.last().unwrap_or(&(t, 0.0));
    (tl, vl, 0.0)
}

/// The load of [`Ports::Circuit`]: a line volume after the compensator,
/// drained by an orifice to a tank.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Load {
    /// Hydraulic capacitance of the line `V / beta` [m^3/Pa].
    pub capacitance: f64,
    /// Orifice coefficient `K`: `Q = K sqrt(p - p_tank)` [m^3/s/sqrt(Pa)].
    pub coefficient: f64,
    /// Tank pressure [Pa].
    pub tank: f64,
}

impl Load {
    /// Flow through the load orifice at line pressure `p` [Pa] (signed,
    /// regularised below `transition` [Pa]).
    pub fn flow(&self, p: f64, transition: f64) -> f64 {
        let d = p - self.tank;
        self.coefficient * d / (d * d + transition * transition).powf(0.25)
    }
}

/// The pressures at the compensator's ports over time.
#[derive(Clone, Debug, PartialEq)]
pub enum Ports {
    /// The parameter file's: `p_c = operating.outlet_pressure`, `p_p = p_c
    /// + operating.pressure_drop`.
    Fixed,
    /// Supply and outlet pressure given as `(time [s], p_p [Pa], p_c [Pa])`,
    /// linear between the points, held outside them (two points at one
    /// time: a jump).
    Given(Vec<(f64, f64, f64)>),
    /// The supply given as `(time [s], p_p [Pa])`, the outlet the line of
    /// a [`Load`] (a state, starting where the circuit is at rest).
    Circuit {
        /// Supply pressure history.
        supply: Vec<(f64, f64)>,
        /// The line and its load orifice.
        load: Load,
    },
}

impl Ports {
    /// The piece of the history in force from `t` [s] (for a circuit, the
    /// outlet part is unused).
    fn segment(&self, p: &RawCore, t: f64) -> Segment {
        match self {
            Ports::Fixed => Segment {
                t0: t,
                supply: (p.outlet_pressure + p.pressure_drop, 0.0),
                outlet: (p.outlet_pressure, 0.0),
            },
            Ports::Given(points) => {
                let sp: Vec<(f64, f64)> = points.iter().map(|q| (q.0, q.1)).collect();
                let op: Vec<(f64, f64)> = points.iter().map(|q| (q.0, q.2)).collect();
                let (ts, s0, ss) = segment_of(&sp, t);
                let (to, o0, os) = segment_of(&op, t);
                Segment {
                    t0: t,
                    supply: (s0 + ss * (t - ts), ss),
                    outlet: (o0 + os * (t - to), os),
                }
            }
            Ports::Circuit { supply, .. } => {
                let (ts, s0, ss) = segment_of(supply, t);
                Segment {
                    t0: t,
                    supply: (s0 + ss * (t - ts), ss),
                    outlet: (0.0, 0.0),
                }
            }
        }
    }

    /// Times in `(0, t_end)` where the history's slope changes (phase
    /// boundaries).
    fn kinks(&self, t_end: f64) -> Vec<f64> {
        let times: Vec<f64> = match self {
            Ports::Fixed => vec![],
            Ports::Given(points) => points.iter().map(|q| q.0).collect(),
            Ports::Circuit { supply, .. } => supply.iter().map(|q| q.0).collect(),
        };
        times.into_iter().filter(|k| *k > 0.0 && *k < t_end).collect()
    }

    fn load(&self) -> Option<Load> {
        match self {
            Ports::Circuit { load, .. } => Some(*load),
            _ => None,
        }
    }
}

/// Motion state of the plunger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Free motion.
    Free,
    /// Held at `x = 0`.
    Closed,
    /// Held at `x = x_max`.
    Open,
    /// Held where it is by Coulomb friction (only with friction,
    /// [`simulate_with_friction`]).
    Stuck,
}

/// The model at a fixed mode, over one piece of the port pressures. The
/// state is `(x, v, p_a, p_b, p_c)`: the outlet pressure is a state in a
/// circuit and follows the given history otherwise (its derivative zero,
/// the history read instead).
#[derive(Clone, Copy, Debug)]
pub struct Fsi {
    p: RawCore,
    profile: Profile,
    mode: Mode,
    segment: Segment,
    load: Option<Load>,
    /// Coulomb friction on the plunger [N] (0: none).
    friction: f64,
    /// The direction of sliding in free motion with friction (+1 towards
    /// `x_max`, -1 back; the friction force is `-friction slide`).
    slide: f64,
}

/// State `(x [m], v [m/s], p_a [Pa], p_b [Pa])`, and `p_c` [Pa] fifth in
/// a circuit (`N = 5`; otherwise `N = 4`, so that the solver's error norm
/// and steps are those of the compensator alone).
type State<const N: usize> = [f64; N];

impl Fsi {
    fn area(&self) -> f64 {
        PI * self.p.plunger_diameter.powi(2) / 4.0
    }

    /// Orifice flow for drop `dp` [Pa] at density `rho`, regularised near zero.
    fn orifice(&self, dp: f64, rho: f64) -> f64 {
        let f = PI * self.p.turbulent_diameter.powi(2) / 4.0;
        let tr = TRANSITION_FRACTION * self.p.pressure_drop;
        self.p.turbulent_discharge * f * (2.0 / rho).sqrt() * dp / (dp * dp + tr * tr).powf(0.25)
    }

    /// Net static force on the plunger, positive towards `x_max` [N].
    pub fn force(&self, y: &[f64]) -> f64 {
        self.area() * (y[3] - y[2]) - self.p.spring_rate * (self.p.preload + y[0])
    }

    /// Supply and outlet pressure [Pa] at `t` [s] in state `y`.
    fn ports(&self, t: f64, y: &[f64]) -> (f64, f64) {
        let (pp, pc) = self.segment.at(t);
        match (self.load, y.get(4)) {
            (Some(_), Some(&line)) => (pp, line),
            _ => (pp, pc),
        }
    }

    /// The flow leaving the compensator [m^3/s] (capillary of (a), orifice
    /// of (b), window) at `t` [s] in state `y`.
    pub fn outflow(&self, t: f64, y: &[f64]) -> f64 {
        if y.len() < 4 {
            return f64::NAN;
        }
        let p = &self.p;
        let (nu, rho) = statics::oil(p, self.profile.temperature(t));
        let r_l = 128.0 * nu * rho * p.laminar_length / (PI * p.laminar_diameter.powi(4));
        let (pp, pc) = self.ports(t, y);
        let window = p.slot_discharge * PI * p.slot_diameter * y[0].max(0.0) * (2.0 * (pp - pc).max(0.0) / rho).sqrt();
        (y[2] - pc) / r_l + self.orifice(y[3] - pc, rho) + window
    }
}

impl<const N: usize> ODE<f64, State<N>> for Fsi {
    fn diff(&self, t: f64, y: &State<N>, d: &mut State<N>) {
        let p = &self.p;
        let (nu, rho) = statics::oil(p, self.profile.temperature(t));
        let r_l = 128.0 * nu * rho * p.laminar_length / (PI * p.laminar_diameter.powi(4));
        let (pp, pc) = self.ports(t, y);
        let area = self.area();
        let (x, v) = match self.mode {
            Mode::Free => (y[0], y[1]),
            Mode::Closed => (0.0, 0.0),
            Mode::Open => (p.stroke, 0.0),
            Mode::Stuck => (y[0], 0.0),
        };
        let c_a = (p.volume_a - area * x) / p.bulk_modulus;
        let c_b = (p.volume_b + area * x) / p.bulk_modulus;
        d[2] = (self.orifice(pp - y[2], rho) - (y[2] - pc) / r_l + area * v) / c_a;
        d[3] = ((pp - y[3]) / r_l - self.orifice(y[3] - pc, rho) - area * v) / c_b;
        if self.mode == Mode::Free {
            d[0] = v;
            d[1] = (self.force(y) - p.damping * v - self.friction * self.slide) / p.mass;
        } else {
            d[0] = 0.0;
            d[1] = 0.0;
        }
        if let (Some(load), Some(&line)) = (self.load, y.get(4)) {
            let q_load = load.flow(line, TRANSITION_FRACTION * p.pressure_drop);
            let mut held = *y;
            held[0] = x;
            d[4] = (self.outflow(t, &held) - q_load) / load.capacitance;
        }
    }
}

/// Time that turns the plunger's speed into a length for the event
/// function of free motion with friction (its reversal, beside the stops)
/// [s]: only the sign matters.
const SPEED_SCALE: f64 = 1e-3;

/// Hysteresis of the friction law, relative to the friction: a plunger at
/// rest is released when the force exceeds the friction by twice this,
/// one whose speed reverses sticks when the force is within once this.
/// A plunger that slid to rest sits exactly at the threshold; without the
/// margin a rounding of the force releases it and it sticks again at
/// once, over and over.
const STICTION_MARGIN: f64 = 1e-6;

/// Output handler of one phase: records samples on the output grid from
/// the dense output, and stops exactly at the phase's event.
struct Phase<'a, const N: usize> {
    sys: &'a Fsi,
    grid: &'a [f64],
    next: usize,
    samples: Vec<(f64, State<N>)>,
    g_prev: Option<f64>,
    event: Option<(f64, State<N>)>,
    phase_end: f64,
    end_state: Option<State<N>>,
}

impl<const N: usize> Phase<'_, N> {
    /// Event function and the crossing direction that ends the phase.
    fn g(&self, y: &State<N>) -> (f64, f64) {
        let f = self.sys.friction * (1.0 + 2.0 * STICTION_MARGIN);
        match self.sys.mode {
            Mode::Free if f > 0.0 => (
                y[0].min(self.sys.p.stroke - y[0])
                    .min(self.sys.slide * y[1] * SPEED_SCALE),
                -1.0,
            ),
            Mode::Free => (y[0].min(self.sys.p.stroke - y[0]), -1.0),
            Mode::Closed => (self.sys.force(y) - f, 1.0),
            Mode::Open => (self.sys.force(y) + f, -1.0),
            Mode::Stuck => (self.sys.force(y).abs() - f, 1.0),
        }
    }
}

impl<const N: usize> Solout<f64, State<N>> for Phase<'_, N> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &State<N>,
        _y_prev: &State<N>,
        interp: &mut I,
        _sol: &mut Solution<f64, State<N>>,
    ) -> ControlFlag<f64, State<N>>
    where
        I: Interpolation<f64, State<N>> + ?Sized,
    {
        let (gc, dir) = self.g(y_curr);
        // Seeded from the phase's initial state: a crossing within the
        // solver's first step is caught whether or not the solver reports
        // the start point first.
        let gp = self.g_prev.replace(gc).unwrap_or(gc);
        let mut t_stop = t_curr;
        let mut terminate = false;
        // An event is a step that ends strictly beyond the surface from a
        // point not beyond it: a phase that starts on the surface (free
        // motion from a stop, a release at zero force) still sees the
        // crossing that follows.
        if dir * gp <= 0.0 && dir * gc > 0.0 {
            // Illinois regula falsi on the dense output, to adjacent doubles.
            let (mut a, mut fa, mut b, mut fb) = (t_prev, gp, t_curr, gc);
            let mut side = 0;
            for it in 0..300 {
                if b - a <= 4.0 * f64::EPSILON * b.abs().max(1e-300) || fb == 0.0 {
                    break;
                }
                let mut c = if it < 100 {
                    (a * fb - b * fa) / (fb - fa)
                } else {
                    0.5 * (a + b)
                };
                if !(c > a && c < b) {
                    c = 0.5 * (a + b);
                }
                let Ok(yc) = interp.interpolate(c) else { break };
                let fc = self.g(&yc).0;
                if dir * fc > 0.0 {
                    (b, fb) = (c, fc);
                    if side == -1 {
                        fa *= 0.5;
                    }
                    side = -1;
                } else {
                    (a, fa) = (c, fc);
                    if side == 1 {
                        fb *= 0.5;
                    }
                    side = 1;
                }
            }
            let yb = interp.interpolate(b).unwrap_or(*y_curr);
            self.event = Some((b, yb));
            t_stop = b;
            terminate = true;
        }
        while self.next < self.grid.len() && self.grid[self.next] <= t_stop {
            let ts = self.grid[self.next];
            let y = if ts == t_curr {
                *y_curr
            } else {
                interp.interpolate(ts).unwrap_or(*y_curr)
            };
            self.samples.push((ts, y));
            self.next += 1;
        }
        if terminate {
            return ControlFlag::Terminate;
        }
        if t_curr >= self.phase_end {
            self.end_state = Some(*y_curr);
        }
        ControlFlag::Continue
    }
}

/// Which integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Radau IIA of order 5 (stiff, implicit).
    Radau5,
    /// Dormand-Prince 8(5,3) (explicit), the cross-check.
    Dop853,
}

/// Most output samples (`t_end / dt`) a run may ask for. The solver's step
/// is capped at `dt` (so that no sample interval hides a transient), so a
/// run takes at least one Radau step per sample: about 4 us a sample with
/// the solver optimised (the paper preset's 500 s ramp at `dt` = 1 ms,
/// 500,000 samples: 2 s), plus 40 bytes a sample for the trajectory and
/// about 100 for the CLI's CSV. 5,000,000 samples are then about 20 s and
/// 0.7 GB; beyond that a run is refused up front instead of failing or
/// exhausting memory half-way.
pub const MAX_SAMPLES: usize = 5_000_000;

/// Steps one phase of `span` [s] may take with steps capped at `h_max`:
/// four times the least number, for rejected steps and the short steps
/// around transients and events, plus a fixed reserve for the stiff start
/// of a phase (a step or a release).
pub fn step_budget(span: f64, h_max: f64) -> usize {
    4 * (span / h_max).ceil() as usize + 100_000
}

/// Least step budget of DOP853 per phase: explicit, its steps are bounded
/// by the pressures' stiffness (eigenvalues up to ~1e8 1/s), not by `dt`.
const DOP853_FLOOR: usize = 100_000_000;

/// A reference trajectory sampled on a uniform grid.
#[derive(Clone, Debug)]
pub struct Trajectory {
    /// Sample times [s], `0, dt, 2 dt, ...`.
    pub time: Vec<f64>,
    /// States `(x [m], v [m/s], p_a [Pa], p_b [Pa])` at the sample times.
    pub state: Vec<[f64; 4]>,
    /// Supply and outlet pressure `(p_p, p_c)` [Pa] at the sample times.
    pub ports: Vec<(f64, f64)>,
    /// The flow leaving the compensator `Q0` [m^3/s] at the sample times
    /// (capillary of (a), orifice of (b), window).
    pub outflow: Vec<f64>,
    /// Mode changes `(time [s], new mode)`.
    pub events: Vec<(f64, Mode)>,
    /// Accepted steps of the integrator.
    pub steps: usize,
}

/// The equilibrium state `(x, 0, p_a, p_b)` at temperature `t` [C] and its mode.
pub fn equilibrium(p: &RawCore, t: f64) -> ([f64; 4], Mode) {
    let (y, mode) = equilibrium_at(p, t, p.outlet_pressure + p.pressure_drop, p.outlet_pressure, 0.0);
    ([y[0], y[1], y[2], y[3]], mode)
}

/// The equilibrium state `(x, 0, p_a, p_b, p_c)` at temperature `t` [C]
/// with supply and outlet pressures `pp`, `pc` [Pa] (`pp > pc`), and its mode.
/// With Coulomb friction `friction` [N] a plunger at rest inside the stroke
/// is [`Mode::Stuck`].
fn equilibrium_at(p: &RawCore, t: f64, pp: f64, pc: f64, friction: f64) -> ([f64; 5], Mode) {
    let at = RawCore {
        pressure_drop: pp - pc,
        outlet_pressure: pc,
        ..*p
    };
    let e = statics::equilibrium(&at, t);
    let y = [e.x, 0.0, e.p_a, e.p_b, pc];
    let sys = Fsi {
        p: *p,
        profile: Profile::Step { from: t, to: t },
        mode: Mode::Free,
        segment: Ports::Fixed.segment(p, 0.0),
        load: None,
        friction: 0.0,
        slide: 0.0,
    };
    let f = sys.force(&y);
    let mode = if e.x <= 0.0 && f <= 0.0 {
        Mode::Closed
    } else if e.x >= p.stroke && f >= 0.0 {
        Mode::Open
    } else if friction > 0.0 {
        Mode::Stuck
    } else {
        Mode::Free
    };
    (y, mode)
}

/// Integrates from the equilibrium at the profile's start, sampling every
/// `dt` [s] up to `round(t_end / dt) dt` (the last sample, where the
/// integration ends), with relative tolerance `rtol` (absolute tolerances
/// scaled to the stroke, its speed over a millisecond, and `dp`).
pub fn simulate(
    p: &RawCore,
    profile: Profile,
    t_end: f64,
    dt: f64,
    method: Method,
    rtol: f64,
) -> Result<Trajectory, String> {
    simulate_with(p, profile, &Ports::Fixed, t_end, dt, method, rtol)
}

/// The outlet pressure [Pa] where a circuit ([`Ports::Circuit`]) with
/// supply `pp` [Pa] is at rest at `t` [C]: the compensator's equilibrium
/// flow equals the load's (bisection on the line pressure between the
/// tank and the supply).
///
/// # Errors
///
/// A supply not above the tank, or a flow balance without a root there.
pub fn circuit_rest(p: &RawCore, t: f64, pp: f64, load: &Load) -> Result<f64, String> {
    if !(pp > load.tank) {
        return Err(format!("supply {pp} Pa is not above the tank's {} Pa", load.tank));
    }
    let balance = |pc: f64| {
        let at = RawCore {
            pressure_drop: pp - pc,
            outlet_pressure: pc,
            ..*p
        };
        statics::equilibrium(&at, t).q_total - load.flow(pc, TRANSITION_FRACTION * p.pressure_drop)
    };
    let (lo, hi) = (load.tank, load.tank + 0.999 * (pp - load.tank));
    if !(balance(lo) >= 0.0 && balance(hi) <= 0.0) {
        return Err("the circuit's flow balance has no root between the tank and the supply".into());
    }
    Ok(statics::bisect_decreasing(balance, lo, hi))
}

/// As [`simulate`], with the port pressures of `ports`: from the
/// equilibrium at the profile's start temperature and the ports' pressures
/// at `t = 0` (a circuit: where it is at rest, [`circuit_rest`]).
///
/// # Errors
///
/// As [`simulate`], and a start where the supply is not above the outlet.
pub fn simulate_with(
    p: &RawCore,
    profile: Profile,
    ports: &Ports,
    t_end: f64,
    dt: f64,
    method: Method,
    rtol: f64,
) -> Result<Trajectory, String> {
    if ports.load().is_some() {
        run::<5>(p, profile, ports, 0.0, t_end, dt, method, rtol)
    } else {
        run::<4>(p, profile, ports, 0.0, t_end, dt, method, rtol)
    }
}

/// As [`simulate`], with Coulomb friction `friction` [N] on the plunger
/// (equal static and kinetic): at rest it stays ([`Mode::Stuck`]) while the
/// net static force's magnitude is at most `friction`; sliding, the
/// friction opposes the motion, and each reversal of the speed is an event
/// (a phase ends there, the plunger sticks or slides back). A stop holds
/// it until the force away from the stop exceeds the friction. From the
/// equilibrium at the profile's start (stuck where it is, inside the
/// stroke).
///
/// # Errors
///
/// As [`simulate`]; a negative or non-finite friction.
pub fn simulate_with_friction(
    p: &RawCore,
    profile: Profile,
    friction: f64,
    t_end: f64,
    dt: f64,
    method: Method,
    rtol: f64,
) -> Result<Trajectory, String> {
    if !(friction >= 0.0 && friction.is_finite()) {
        return Err(format!("friction {friction} N: not a force"));
    }
    run::<4>(p, profile, &Ports::Fixed, friction, t_end, dt, method, rtol)
}

#[allow(clippy::too_many_arguments, reason = "the public entry points fix the arguments")]
fn run<const N: usize>(
    p: &RawCore,
    profile: Profile,
    ports: &Ports,
    friction: f64,
    t_end: f64,
    dt: f64,
    method: Method,
    rtol: f64,
) -> Result<Trajectory, String> {
    if !(t_end > 0.0 && dt > 0.0 && rtol > 0.0) {
        return Err("t_end, dt and rtol must be positive".into());
    }
    let samples = (t_end / dt).round();
    if samples > MAX_SAMPLES as f64 {
        return Err(format!(
            "t_end / dt = {t_end} s / {dt} s: {samples} output samples exceed the reference solver's \
             limit of {MAX_SAMPLES} (at least one step each); use a larger dt"
        ));
    }
    let n = samples as usize;
    if n == 0 {
        return Err(format!("dt = {dt} s is more than twice t_end = {t_end} s"));
    }
    let t_end = n as f64 * dt;
    let grid: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let start = ports.segment(p, 0.0).at(0.0);
    let outlet0 = match ports.load() {
        Some(load) => circuit_rest(p, profile.start(), start.0, &load)?,
        None => start.1,
    };
    if !(start.0 > outlet0) {
        return Err(format!(
            "at t = 0 the supply {} Pa is not above the outlet {outlet0} Pa",
            start.0
        ));
    }
    let (y5, mut mode) = equilibrium_at(p, profile.start(), start.0, outlet0, friction);
    let mut slide = 0.0;
    let mut y: State<N> = [0.0; N];
    for (a, b) in y.iter_mut().zip(y5) {
        *a = b;
    }
    let sample = |sys: &Fsi, t: f64, y: &[f64]| -> ((f64, f64), f64) { (sys.ports(t, y), sys.outflow(t, y)) };
    let first = Fsi {
        p: *p,
        profile,
        mode,
        segment: ports.segment(p, 0.0),
        load: ports.load(),
        friction,
        slide,
    };
    let (ports0, q0) = sample(&first, 0.0, &y);
    let mut out = Trajectory {
        time: vec![0.0],
        state: vec![[y[0], y[1], y[2], y[3]]],
        ports: vec![ports0],
        outflow: vec![q0],
        events: vec![],
        steps: 0,
    };
    let mut next = 1;
    let mut t = 0.0;
    let mut atol = [rtol * p.pressure_drop; N];
    atol[0] = rtol * p.stroke;
    atol[1] = rtol * p.stroke * 1e3;
    // Phases end at events and at the profile's and the ports' kinks.
    let mut boundaries: Vec<f64> = profile.kinks().into_iter().filter(|k| *k > 0.0 && *k < t_end).collect();
    boundaries.extend(ports.kinks(t_end));
    boundaries.sort_by(f64::total_cmp);
    boundaries.push(t_end);
    let mut guard = 0;
    while t < t_end {
        guard += 1;
        if guard > 100_000 {
            return Err("too many phases (chattering at a stop?)".into());
        }
        let phase_end = boundaries.iter().copied().find(|b| *b > t).unwrap_or(t_end);
        let sys = Fsi {
            p: *p,
            profile,
            mode,
            segment: ports.segment(p, t),
            load: ports.load(),
            friction,
            slide,
        };
        let mut phase = Phase {
            sys: &sys,
            grid: &grid,
            next,
            samples: vec![],
            g_prev: None,
            event: None,
            phase_end,
            end_state: None,
        };
        phase.g_prev = Some(phase.g(&y).0);
        let h_max = dt.min(phase_end - t);
        // The steps are capped at `dt`: a long run needs at least
        // `(phase_end - t) / dt` of them, more than the library's default
        // budget (100,000 for Radau5), so the budget follows the run.
        let budget = step_budget(phase_end - t, h_max);
        let steps = match method {
            Method::Radau5 => solve(
                &sys,
                t,
                phase_end,
                y,
                &mut phase,
                ImplicitRungeKutta::radau5()
                    .rtol([rtol; N])
                    .atol(atol)
                    .h_max(h_max)
                    .max_steps(budget),
                budget,
            )?,
            Method::Dop853 => solve(
                &sys,
                t,
                phase_end,
                y,
                &mut phase,
                ExplicitRungeKutta::dop853()
                    .rtol(rtol)
                    .atol(atol)
                    .h_max(h_max)
                    .max_steps(budget.max(DOP853_FLOOR)),
                budget.max(DOP853_FLOOR),
            )?,
        };
        out.steps += steps;
        for (ts, ys) in phase.samples.drain(..) {
            let (pts, q) = sample(&sys, ts, &ys);
            out.time.push(ts);
            out.state.push([ys[0], ys[1], ys[2], ys[3]]);
            out.ports.push(pts);
            out.outflow.push(q);
        }
        next = phase.next;
        if let Some((te, mut ye)) = phase.event {
            t = te;
            mode = match mode {
                // With friction: the speed reversed inside the stroke
                // (nearer its zero than either stop).
                Mode::Free if friction > 0.0 && (ye[1] * SPEED_SCALE).abs() <= ye[0].min(p.stroke - ye[0]).abs() => {
                    ye[1] = 0.0;
                    let f = sys.force(&ye);
                    if f.abs() <= friction * (1.0 + STICTION_MARGIN) {
                        Mode::Stuck
                    } else {
                        slide = f.signum();
                        Mode::Free
                    }
                }
                Mode::Free => {
                    let low = ye[0] < 0.5 * p.stroke;
                    ye[0] = if low { 0.0 } else { p.stroke };
                    ye[1] = 0.0;
                    let f = sys.force(&ye);
                    if low && f <= friction {
                        Mode::Closed
                    } else if !low && f >= -friction {
                        Mode::Open
                    } else {
                        slide = if low { 1.0 } else { -1.0 };
                        Mode::Free
                    }
                }
                Mode::Closed => {
                    slide = 1.0;
                    Mode::Free
                }
                Mode::Open => {
                    slide = -1.0;
                    Mode::Free
                }
                Mode::Stuck => {
                    slide = sys.force(&ye).signum();
                    Mode::Free
                }
            };
            y = ye;
            out.events.push((t, mode));
        } else {
            y = phase.end_state.ok_or("integrator ended before the phase end")?;
            t = phase_end;
        }
    }
    if out.time.len() != grid.len() {
        return Err(format!("sampled {} of {} output times", out.time.len(), grid.len()));
    }
    Ok(out)
}

fn solve<M, const N: usize>(
    sys: &Fsi,
    t0: f64,
    t1: f64,
    y0: State<N>,
    phase: &mut Phase<'_, N>,
    mut method: M,
    budget: usize,
) -> Result<usize, String>
where
    M: OrdinaryNumericalMethod<f64, State<N>> + Interpolation<f64, State<N>>,
{
    let sol = solve_ode(&mut method, sys, t0, t1, &y0, phase).map_err(|e| match e {
        Error::MaxSteps { t, .. } => format!(
            "the solver used its budget of {budget} steps between t = {t0} s and t = {t1} s \
             (stopped at t = {t} s)"
        ),
        e => format!("{e:?}"),
    })?;
    Ok(sol.steps.accepted)
}
