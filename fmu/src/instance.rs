//! One FMU instance in plain Rust: the parameter values, the input, the
//! phase of the FMI state machine and, once initialised, the twin. The C
//! interfaces (`fmi2`, `fmi3`) are thin wrappers around it; nothing here is
//! shared between instances (no statics).
//!
//! What runs is the firmware's own twin: `Twin<f32, f32>` with the
//! configuration the core's chooser picks for the parameter file
//! (`compensator::dynamics::config::choose` at the estimator's tick over
//! its validated range: what `build.rs` ships and `compensator step
//! --precision f32` runs), driven with the input temperature directly. The
//! estimator itself is not ticked: its temperature filter, spike rejection
//! and slew limit would put the sensor's dynamics between the oil
//! temperature and the twin, and its API takes sensor samples only. Its
//! flags are computed with the same functions as its jobs (fluid point,
//! flow laws, closed-form equilibrium, Routh-Hurwitz stability of the
//! linearisation, machine losses: `compensator::estimator` module docs).

use crate::variables::{
    FIELD_COUNT, FLAGS_OUTPUT, OUTPUTS, VR_FIRST_OUTPUT, VR_MACHINE_PRESENT, VR_T_OIL, VR_TIME, field_of, fields,
};
use compensator::dynamics::config::choose;
use compensator::dynamics::fsi::{Contact, Fsi};
use compensator::dynamics::linear::characteristic_polynomial;
use compensator::dynamics::schemes::OdeSystem;
use compensator::dynamics::{Twin, TwinConfig, TwinMemory};
use compensator::equilibrium::{a_parameter, equilibrium_for};
use compensator::estimator::{EstimatorConfig, Flags, quartic_hurwitz};
use compensator::throttle::FlowLaws;
use compensator::{ModelError, Params, RawParams, asymptotic, compensation};
use compensator_params::MACHINE_FIELDS;

/// Where an instance is in the FMI state machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Instantiated: parameters and the input may be set.
    Instantiated,
    /// Initialization mode: parameters and the input may be set, outputs
    /// read (the twin at rest at the input's temperature).
    Initialization,
    /// Step mode (after exit-initialization): the input may be set, steps
    /// taken; parameters are fixed.
    Step,
    /// Terminated: values may be read; only reset and free remain.
    Terminated,
}

impl Phase {
    fn code(self) -> u8 {
        self as u8
    }
    fn from_code(c: u8) -> Option<Phase> {
        [
            Phase::Instantiated,
            Phase::Initialization,
            Phase::Step,
            Phase::Terminated,
        ]
        .get(c as usize)
        .copied()
    }
}

/// Why a call failed: the message the logger gets (naming the field or
/// the quantity), and whether the instance can go on (`Discard`) or not.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// The call was refused and changed nothing; the instance goes on
    /// (FMI `Discard` for a step, `Error` for a set or get).
    Refused(String),
    /// The instance cannot go on without a reset or an earlier state.
    Broken(String),
}

impl Failure {
    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Failure::Refused(m) | Failure::Broken(m) => m,
        }
    }
}

/// The values settable before initialisation: every parameter-file field
/// (in [`fields`] order) and whether the `[machine]` section is present.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// Field values, in [`fields`] order.
    pub values: [f64; FIELD_COUNT],
    /// The `[machine]` section is used (`machine.present`).
    pub machine_present: bool,
}

/// Start values of the `[machine]` fields for a file without that section
/// (not used while `machine.present` is false): no flow, no loss, the loss
/// referred to 40 C (the ISO 3448 viscosity-grade temperature).
const NO_MACHINE: [f64; 3] = [0.0, 0.0, 40.0];

impl Setup {
    /// The values of a parameter file.
    pub fn from_raw(raw: &RawParams) -> Setup {
        let machine = raw.machine.map(|m| m.named().into_array().map(|n| n.value));
        let values: Vec<f64> = raw
            .core
            .named()
            .into_array()
            .iter()
            .map(|n| n.value)
            .chain(machine.unwrap_or(NO_MACHINE))
            .chain(raw.estimator.named().into_array().iter().map(|n| n.value))
            .collect();
        Setup {
            values: values.try_into().expect("one value per field"),
            machine_present: raw.machine.is_some(),
        }
    }

    /// The parameter set, validated (each field's own range, then the rules
    /// between fields).
    ///
    /// # Errors
    ///
    /// The validation's message, naming the field (`plunger.stroke: ...`).
    pub fn to_raw(&self) -> Result<RawParams, String> {
        RawParams::from_lookup(|section, key| {
            let (i, _) = fields()
                .enumerate()
                .find(|(_, f)| f.section == section && f.key == key)?;
            if section == MACHINE_FIELDS[0].section && !self.machine_present {
                return None;
            }
            Some(self.values[i])
        })
        .map_err(|e| e.to_string())
    }
}

/// Results that depend on the temperature only (what the estimator's jobs
/// keep).
#[derive(Clone, Copy, Debug)]
struct Statics {
    flows: FlowLaws<f32>,
    stable: bool,
    /// The machine's losses [m^3/s] (NaN without a machine).
    losses: f32,
}

/// An initialised instance: the twin and what it needs.
#[derive(Clone, Copy, Debug)]
struct Sim {
    raw: RawParams,
    params: Params<f32>,
    estimator: EstimatorConfig,
    twin: Twin<f32, f32>,
    monotonic: bool,
    slot_window_factor: f32,
    machine_mu_ref: f32,
    /// Temperature the twin was built at [C].
    t_init: f32,
    /// Temperature of the twin's coefficients [C].
    applied: f32,
    statics: Statics,
    /// The last temperature-only results could not be computed at
    /// `applied` (the previous ones stand, flagged `DEGRADED`, until they
    /// can).
    stale: bool,
    ticks: u64,
    start_time: f64,
    flags: Flags,
    outputs: [f64; 10],
}

fn model_error(what: &str, e: ModelError) -> String {
    format!("{what}: {e}")
}

impl Sim {
    fn new(
        setup: &Setup,
        t_oil: f64,
        start_time: f64,
        chosen: Option<(&RawParams, TwinConfig)>,
    ) -> Result<Sim, String> {
        let raw = setup.to_raw()?;
        let params = Params::<f32>::new(&raw).map_err(|e| e.to_string())?;
        let estimator = EstimatorConfig::new(&raw.estimator).map_err(|e| e.to_string())?;
        let config = match chosen {
            Some((r, c)) if *r == raw => c,
            _ => {
                let p64 = Params::<f64>::new(&raw).map_err(|e| e.to_string())?;
                let valid = (raw.estimator.valid_min, raw.estimator.valid_max);
                let tick = 1.0 / raw.estimator.tick_hz;
                choose(&p64, tick, valid)
                    .map_err(|e| {
                        model_error(
                            &format!(
                                "choosing the twin's substeps over {}-{} C at a {tick} s tick",
                                valid.0, valid.1
                            ),
                            e,
                        )
                    })?
                    .config
            }
        };
        let t = t_oil as f32;
        if !(t.is_finite() && estimator.oil.contains(t)) {
            return Err(format!(
                "T_oil: {t_oil} degC is outside the oil model's range {}..{} degC (estimator.oil_min, estimator.oil_max)",
                estimator.oil.min, estimator.oil.max
            ));
        }
        let twin = Twin::new(&params, config, t).map_err(|e| model_error(&format!("T_oil = {t_oil} degC"), e))?;
        let monotonic = asymptotic::monotonicity(&params, estimator.valid.min, estimator.valid.max, 201)
            .map(|m| m.monotonic)
            .unwrap_or(false);
        let machine_mu_ref = match &params.machine {
            Some(m) => {
                params
                    .oil
                    .state(m.leakage_temperature)
                    .map_err(|e| model_error("machine.leakage_temperature", e))?
                    .dynamic_viscosity
            }
            None => f32::NAN,
        };
        let slot_window_factor = params.slot.window_factor(params.pressure_drop);
        let mut sim = Sim {
            raw,
            params,
            estimator,
            twin,
            monotonic,
            slot_window_factor,
            machine_mu_ref,
            t_init: t,
            applied: t,
            statics: Statics {
                flows: FlowLaws {
                    capillary_conductance: 0.0,
                    orifice_factor: 0.0,
                    window_factor: 0.0,
                },
                stable: true,
                losses: f32::NAN,
            },
            stale: false,
            ticks: 0,
            start_time,
            flags: Flags::empty(),
            outputs: [f64::NAN; 10],
        };
        sim.statics = sim
            .statics_at(t)
            .map_err(|e| model_error(&format!("T_oil = {t_oil} degC"), e))?;
        let flags = sim.base_flags();
        sim.publish(flags);
        Ok(sim)
    }

    /// The estimator's temperature-only jobs at `t` [C] (Fluid, Equilibrium,
    /// Stability, Losses: `compensator::estimator`), with the twin's
    /// current coefficients.
    fn statics_at(&self, t: f32) -> Result<Statics, ModelError> {
        let p = &self.params;
        let point = p.oil.point(t)?;
        let flows = FlowLaws::new(
            &p.capillary,
            &p.orifice,
            self.slot_window_factor,
            point.state.density,
            point.state.dynamic_viscosity,
        );
        let eq = equilibrium_for(p, point.state, a_parameter(p, &point.state))?;
        let y_equilibrium: [f32; 4] = self.twin.model().equilibrium_state(&eq);
        let sys = Fsi {
            coefficients: self.twin.coefficients(),
            contact: Contact::Free,
        };
        let stable = quartic_hurwitz(&characteristic_polynomial(&sys.jacobian(&y_equilibrium)));
        let losses = match &p.machine {
            Some(m) => compensation::losses_for(m, self.machine_mu_ref, point.state.dynamic_viscosity)?,
            None => f32::NAN,
        };
        Ok(Statics { flows, stable, losses })
    }

    /// Flags that follow from the design and the applied temperature.
    fn base_flags(&self) -> Flags {
        let mut flags = Flags::empty();
        if !self.monotonic {
            flags.insert(Flags::NOT_UNIQUE);
        }
        if !self.estimator.valid.contains(self.applied) {
            flags.insert(Flags::OUT_OF_RANGE);
        }
        if !self.statics.stable {
            flags.insert(Flags::UNSTABLE);
        }
        flags
    }

    /// Computes the outputs from the twin's state (as the estimator's step 5).
    fn publish(&mut self, mut flags: Flags) {
        let [xi, ..] = self.twin.raw_state();
        if xi <= 0.0 || xi >= 1.0 {
            flags.insert(Flags::AT_STOP);
        }
        let p = &self.params;
        let st = &self.statics;
        let s = self.twin.state();
        let q_a = st.flows.capillary_flow(s.p_a - p.outlet_pressure);
        let q_b = st.flows.orifice_flow(s.p_b - p.outlet_pressure);
        let q_throt = st.flows.window_flow(s.x);
        let q_total = q_a + q_b + q_throt;
        let error = match &p.machine {
            Some(m) => q_total - (m.working_flow + st.losses),
            None => f32::NAN,
        };
        self.flags = flags;
        self.outputs = [
            s.x as f64,
            s.v as f64,
            s.p_a as f64,
            s.p_b as f64,
            q_a as f64,
            q_b as f64,
            q_throt as f64,
            q_total as f64,
            error as f64,
            flags.0 as f64,
        ];
    }

    fn tick(&self) -> f64 {
        self.twin.config().tick
    }

    fn time(&self) -> f64 {
        self.start_time + self.ticks as f64 * self.tick()
    }

    /// `n` ticks with the oil at `t_oil` [C].
    fn step(&mut self, t_oil: f64, n: u64) -> Result<(), String> {
        let mut flags = Flags::empty();
        let t = t_oil as f32;
        if t.is_finite() && self.estimator.oil.contains(t) {
            // As `compensator step`: the temperature set before each tick
            // (held over this communication step, so once).
            match self.twin.set_temperature(t) {
                Ok(()) => {
                    if t != self.applied || self.stale {
                        match self.statics_at(t) {
                            Ok(s) => {
                                self.statics = s;
                                self.stale = false;
                            }
                            Err(_) => self.stale = true,
                        }
                        self.applied = t;
                    }
                }
                Err(_) => flags.insert(Flags::DEGRADED),
            }
        } else {
            // Not an oil temperature: the twin keeps the last one, flagged
            // as the estimator flags an unusable sample.
            flags.insert(Flags::SENSOR_FAULT);
        }
        for _ in 0..n {
            if self.twin.tick().is_err() {
                // As the estimator: a failed tick (never seen with valid
                // parameters) restarts the twin at rest in the equilibrium.
                self.twin = Twin::new(&self.params, self.twin.config(), self.applied)
                    .map_err(|e| model_error(&format!("restarting the twin at {} degC", self.applied), e))?;
                flags.insert(Flags::DEGRADED);
            }
            self.ticks += 1;
        }
        if self.stale {
            flags.insert(Flags::DEGRADED);
        }
        let mut all = self.base_flags();
        all.insert(flags);
        self.publish(all);
        Ok(())
    }
}

/// One FMU instance.
#[derive(Clone, Debug)]
pub struct Instance {
    /// The values of the packaged parameter file (what a reset returns to).
    start: Setup,
    setup: Setup,
    t_oil_start: f64,
    t_oil: f64,
    start_time: f64,
    phase: Phase,
    sim: Option<Sim>,
}

/// Tolerance on a communication step's length, as a fraction of the tick.
const STEP_TOLERANCE: f64 = 1e-6;

/// Most ticks one communication step may take (10,000 s at 1 kHz, a few
/// seconds of computing): a larger step is refused rather than left to
/// run for hours.
pub const MAX_TICKS_PER_STEP: f64 = 1e7;

impl Instance {
    /// An instance with the values of `raw` (the packaged parameter file),
    /// the input at its start value.
    pub fn new(raw: &RawParams) -> Instance {
        let setup = Setup::from_raw(raw);
        let t = t_oil_start(raw);
        Instance {
            start: setup,
            setup,
            t_oil_start: t,
            t_oil: t,
            start_time: 0.0,
            phase: Phase::Instantiated,
            sim: None,
        }
    }

    /// The phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The current parameter values.
    pub fn setup(&self) -> &Setup {
        &self.setup
    }

    /// The twin's configuration (once initialised).
    pub fn twin_config(&self) -> Option<TwinConfig> {
        self.sim.as_ref().map(|s| s.twin.config())
    }

    fn settable(&self, name: &str) -> Result<(), Failure> {
        match self.phase {
            Phase::Instantiated | Phase::Initialization => Ok(()),
            _ => Err(Failure::Refused(format!(
                "{name}: a parameter can be set only before initialisation ends"
            ))),
        }
    }

    /// Sets a Float64 variable: the input `T_oil` (any time before
    /// termination) or a parameter (before exit-initialization, checked
    /// against the field's own rule at once; the rules between fields are
    /// checked when initialisation ends).
    ///
    /// # Errors
    ///
    /// An unknown or read-only value reference, a parameter set too late,
    /// or a value the field refuses (the message names the field).
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), Failure> {
        if vr == VR_T_OIL {
            if self.phase == Phase::Terminated {
                return Err(Failure::Refused("T_oil: the instance is terminated".into()));
            }
            self.t_oil = value;
            if self.phase == Phase::Initialization {
                self.sim = None;
            }
            return Ok(());
        }
        let Some((i, field)) = field_of(vr) else {
            return Err(Failure::Refused(format!(
                "value reference {vr}: not a settable Float64"
            )));
        };
        self.settable(field.path)?;
        let v = field.check(value).map_err(|e| Failure::Refused(e.to_string()))?;
        self.setup.values[i] = v;
        self.sim = None;
        Ok(())
    }

    /// Sets the Boolean `machine.present`.
    ///
    /// # Errors
    ///
    /// Another value reference, or a set after initialisation.
    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<(), Failure> {
        if vr != VR_MACHINE_PRESENT {
            return Err(Failure::Refused(format!(
                "value reference {vr}: not a settable Boolean"
            )));
        }
        self.settable("machine.present")?;
        self.setup.machine_present = value;
        self.sim = None;
        Ok(())
    }

    /// Builds the twin from the current values when it is not built.
    fn ensure_sim(&mut self) -> Result<&mut Sim, Failure> {
        if self.sim.is_none() {
            self.sim = Some(Sim::new(&self.setup, self.t_oil, self.start_time, None).map_err(Failure::Refused)?);
        }
        Ok(self.sim.as_mut().expect("built above"))
    }

    /// Reads a Float64: time, the input, an output (from initialization
    /// mode on: the twin at rest at `T_oil` until the first step) or a
    /// parameter.
    ///
    /// # Errors
    ///
    /// An unknown value reference, an output read before initialization
    /// mode, or (in initialization mode) values that do not initialise.
    pub fn get_real(&mut self, vr: u32) -> Result<f64, Failure> {
        if vr == VR_T_OIL {
            return Ok(self.t_oil);
        }
        if let Some((i, _)) = field_of(vr) {
            return Ok(self.setup.values[i]);
        }
        let out = vr.wrapping_sub(VR_FIRST_OUTPUT) as usize;
        if vr == VR_TIME || (out < OUTPUTS.len() && out != FLAGS_OUTPUT) {
            let sim = self.initialised_sim(vr)?;
            return Ok(if vr == VR_TIME { sim.time() } else { sim.outputs[out] });
        }
        Err(Failure::Refused(format!("value reference {vr}: not a Float64")))
    }

    fn initialised_sim(&mut self, vr: u32) -> Result<&mut Sim, Failure> {
        if self.phase == Phase::Instantiated {
            if vr == VR_TIME {
                return Err(Failure::Refused("time: not defined before initialization mode".into()));
            }
            return Err(Failure::Refused(format!(
                "{}: outputs are defined from initialization mode on",
                OUTPUTS[(vr - VR_FIRST_OUTPUT) as usize].name
            )));
        }
        self.ensure_sim()
    }

    /// Reads the integer output `flags`.
    ///
    /// # Errors
    ///
    /// Another value reference, or as [`Instance::get_real`].
    pub fn get_integer(&mut self, vr: u32) -> Result<i32, Failure> {
        if vr != VR_FIRST_OUTPUT + FLAGS_OUTPUT as u32 {
            return Err(Failure::Refused(format!("value reference {vr}: not an integer")));
        }
        Ok(self.initialised_sim(vr)?.flags.0 as i32)
    }

    /// Reads the Boolean `machine.present`.
    ///
    /// # Errors
    ///
    /// Another value reference.
    pub fn get_boolean(&self, vr: u32) -> Result<bool, Failure> {
        if vr != VR_MACHINE_PRESENT {
            return Err(Failure::Refused(format!("value reference {vr}: not a Boolean")));
        }
        Ok(self.setup.machine_present)
    }

    /// Enters initialization mode at `start_time` [s].
    ///
    /// # Errors
    ///
    /// Not in the instantiated phase.
    pub fn enter_initialization(&mut self, start_time: f64) -> Result<(), Failure> {
        if self.phase != Phase::Instantiated {
            return Err(Failure::Refused(
                "enter initialization mode: only from the instantiated state".into(),
            ));
        }
        if !start_time.is_finite() {
            return Err(Failure::Refused(format!("start time {start_time} s is not finite")));
        }
        self.start_time = start_time;
        self.sim = None;
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// Leaves initialization mode: validates the parameters, chooses the
    /// twin's configuration and puts the twin at rest at `T_oil`.
    ///
    /// # Errors
    ///
    /// A parameter the validation refuses (the message names the field), a
    /// `T_oil` outside the oil model's range, or not in initialization mode.
    pub fn exit_initialization(&mut self) -> Result<(), Failure> {
        if self.phase != Phase::Initialization {
            return Err(Failure::Refused(
                "exit initialization mode: not in initialization mode".into(),
            ));
        }
        self.ensure_sim()?;
        self.phase = Phase::Step;
        Ok(())
    }

    /// Advances from `time` [s] by `h` [s]: `h / tick` ticks of the twin
    /// with the oil at `T_oil` throughout.
    ///
    /// # Errors
    ///
    /// `Refused` (nothing done: FMI `Discard`) for a step that is not a
    /// whole, positive number of ticks (at most [`MAX_TICKS_PER_STEP`]) or
    /// does not start at the instance's time; `Broken` for a twin that cannot be restarted.
    pub fn do_step(&mut self, time: f64, h: f64) -> Result<(), Failure> {
        if self.phase != Phase::Step {
            return Err(Failure::Broken(
                "do step: only in step mode (after exit initialization)".into(),
            ));
        }
        let t_oil = self.t_oil;
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| Failure::Broken("do step: not initialised".into()))?;
        let tick = sim.tick();
        let n = (h / tick).round();
        if !(h.is_finite() && n >= 1.0 && (h - n * tick).abs() <= STEP_TOLERANCE * tick) {
            return Err(Failure::Refused(format!(
                "communication step {h} s is not a whole multiple of the twin's tick {tick} s (estimator.tick_hz)"
            )));
        }
        if n > MAX_TICKS_PER_STEP {
            return Err(Failure::Refused(format!(
                "communication step {h:e} s is more than {MAX_TICKS_PER_STEP} ticks of {tick} s: take shorter steps"
            )));
        }
        let now = sim.time();
        if !((time - now).abs() <= 0.25 * tick) {
            return Err(Failure::Refused(format!(
                "communication point {time} s is not the instance's time {now} s"
            )));
        }
        sim.step(t_oil, n as u64).map_err(Failure::Broken)
    }

    /// The twin's tick [s] once initialised.
    pub fn tick(&self) -> Option<f64> {
        self.sim.as_ref().map(Sim::tick)
    }

    /// Terminates.
    pub fn terminate(&mut self) {
        self.phase = Phase::Terminated;
    }

    /// Back to the freshly instantiated state (the packaged parameters,
    /// the input's start value).
    pub fn reset(&mut self) {
        self.setup = self.start;
        self.t_oil = self.t_oil_start;
        self.start_time = 0.0;
        self.sim = None;
        self.phase = Phase::Instantiated;
    }

    /// The instance's state as bytes: phase, parameters, input and (once
    /// initialised) the twin's memory and outputs. [`Instance::deserialize`]
    /// restores it exactly.
    pub fn serialize(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(64 + 8 * FIELD_COUNT + 128);
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT.to_le_bytes());
        b.push(self.phase.code());
        b.push(self.setup.machine_present as u8);
        for v in self.setup.values {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&self.t_oil.to_le_bytes());
        b.extend_from_slice(&self.start_time.to_le_bytes());
        match &self.sim {
            None => b.push(0),
            Some(s) => {
                b.push(1);
                b.extend_from_slice(&s.t_init.to_le_bytes());
                b.extend_from_slice(&s.applied.to_le_bytes());
                b.extend_from_slice(&s.ticks.to_le_bytes());
                let m = s.twin.memory();
                for v in m.state {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                b.extend_from_slice(&m.xi_carry.to_le_bytes());
                b.push(m.abrupt as u8);
                b.extend_from_slice(&s.flags.0.to_le_bytes());
                for v in s.outputs {
                    b.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        b
    }

    /// Restores a state written by [`Instance::serialize`] (of this or
    /// another instance of this FMU).
    ///
    /// # Errors
    ///
    /// Bytes that are not such a state (nothing changes then), or
    /// parameters in it that no longer initialise.
    pub fn deserialize(&mut self, bytes: &[u8]) -> Result<(), Failure> {
        let bad = || Failure::Refused("FMU state: not a state of this FMU (wrong size or version)".to_string());
        let mut r = Reader { bytes, at: 0 };
        if r.take(4).ok_or_else(bad)? != MAGIC || r.u32().ok_or_else(bad)? != FORMAT {
            return Err(bad());
        }
        let phase = Phase::from_code(r.u8().ok_or_else(bad)?).ok_or_else(bad)?;
        let machine_present = r.u8().ok_or_else(bad)? != 0;
        let mut values = [0.0; FIELD_COUNT];
        for v in &mut values {
            *v = r.f64().ok_or_else(bad)?;
        }
        let setup = Setup {
            values,
            machine_present,
        };
        let t_oil = r.f64().ok_or_else(bad)?;
        let start_time = r.f64().ok_or_else(bad)?;
        let sim = match r.u8().ok_or_else(bad)? {
            0 => None,
            1 => {
                let t_init = r.f32().ok_or_else(bad)?;
                let applied = r.f32().ok_or_else(bad)?;
                let ticks = r.u64().ok_or_else(bad)?;
                let mut state = [0.0f32; 4];
                for v in &mut state {
                    *v = r.f32().ok_or_else(bad)?;
                }
                let xi_carry = r.f32().ok_or_else(bad)?;
                let abrupt = r.u8().ok_or_else(bad)? != 0;
                let flags = Flags(r.u16().ok_or_else(bad)?);
                let mut outputs = [0.0; 10];
                for v in &mut outputs {
                    *v = r.f64().ok_or_else(bad)?;
                }
                // The twin rebuilt along the same path (built at t_init,
                // then given the last temperature), then its memory.
                let chosen = self.sim.as_ref().map(|s| (&s.raw, s.twin.config()));
                let mut sim = Sim::new(&setup, t_init as f64, start_time, chosen).map_err(Failure::Refused)?;
                if applied != t_init {
                    sim.twin
                        .set_temperature(applied)
                        .map_err(|e| Failure::Refused(model_error("FMU state: temperature", e)))?;
                    match sim.statics_at(applied) {
                        Ok(st) => sim.statics = st,
                        Err(_) => sim.stale = true,
                    }
                    sim.applied = applied;
                }
                sim.twin.restore(&TwinMemory {
                    state,
                    xi_carry,
                    abrupt,
                });
                sim.ticks = ticks;
                sim.flags = flags;
                sim.outputs = outputs;
                Some(sim)
            }
            _ => return Err(bad()),
        };
        if r.at != bytes.len() {
            return Err(bad());
        }
        self.phase = phase;
        self.setup = setup;
        self.t_oil = t_oil;
        self.start_time = start_time;
        self.sim = sim;
        Ok(())
    }
}

/// The input's start value for a parameter file: the middle of its
/// validated range [C].
pub fn t_oil_start(raw: &RawParams) -> f64 {
    0.5 * (raw.estimator.valid_min + raw.estimator.valid_max)
}

const MAGIC: &[u8; 4] = b"CFMU";
/// Version of the state's byte layout.
const FORMAT: u32 = 1;

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let s = self.bytes.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }
    fn u8(&mut self) -> Option<u8> {
        Some(self.take(1)?[0])
    }
    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.take(2)?.try_into().ok()?))
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f32(&mut self) -> Option<f32> {
        Some(f32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn f64(&mut self) -> Option<f64> {
        Some(f64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn preset(name: &str) -> RawParams {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../presets")
            .join(name);
        compensator_params::file::load(&path).expect("preset loads")
    }

    #[test]
    fn the_values_of_a_file_give_the_file_back() {
        for name in ["paper.toml", "model-example.toml"] {
            let mut raw = preset(name);
            assert_eq!(Setup::from_raw(&raw).to_raw(), Ok(raw));
            raw.machine = None;
            let setup = Setup::from_raw(&raw);
            assert!(!setup.machine_present);
            assert_eq!(setup.to_raw(), Ok(raw));
        }
    }

    #[test]
    fn every_damaged_state_is_refused_and_changes_nothing() {
        let raw = preset("paper.toml");
        let mut inst = Instance::new(&raw);
        inst.set_real(VR_T_OIL, 35.0).expect("input");
        inst.enter_initialization(0.0).expect("init");
        inst.exit_initialization().expect("initialised");
        inst.set_real(VR_T_OIL, 75.0).expect("input");
        inst.do_step(0.0, 0.01).expect("steps");
        let bytes = inst.serialize();
        let x = inst.get_real(VR_FIRST_OUTPUT).expect("x");
        for len in 0..bytes.len() {
            assert!(inst.deserialize(&bytes[..len]).is_err(), "a state cut at {len} bytes");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(inst.deserialize(&longer).is_err());
        let mut other = bytes.clone();
        other[4] ^= 1;
        assert!(inst.deserialize(&other).is_err(), "another format version");
        assert_eq!(inst.get_real(VR_FIRST_OUTPUT), Ok(x));
        assert_eq!(inst.phase(), Phase::Step);
        assert!(inst.deserialize(&bytes).is_ok());
        assert_eq!(inst.serialize(), bytes);
    }

    #[test]
    fn a_slow_tick_the_schema_allows_initialises() {
        // 10 Hz is within the schema's range; the core's chooser once
        // panicked on ticks beyond 25 ms (its clamp's bounds crossed).
        let mut raw = preset("paper.toml");
        raw.estimator.tick_hz = 10.0;
        raw.estimator.telemetry_hz = 2.0;
        let mut inst = Instance::new(&raw);
        inst.enter_initialization(0.0).expect("init");
        inst.exit_initialization().expect("a 0.1 s tick initialises");
        assert_eq!(crate::chosen_config(&raw).expect("chosen").tick, 0.1);
    }

    #[test]
    fn outputs_are_refused_before_initialization_mode() {
        let mut inst = Instance::new(&preset("paper.toml"));
        assert!(matches!(inst.get_real(VR_FIRST_OUTPUT), Err(Failure::Refused(m)) if m.starts_with("x:")));
        assert!(inst.get_integer(VR_FIRST_OUTPUT + FLAGS_OUTPUT as u32).is_err());
        assert!(inst.get_real(VR_MACHINE_PRESENT).is_err());
        assert!(inst.do_step(0.0, 0.001).is_err());
        inst.enter_initialization(0.0).expect("init");
        // The twin at rest: no velocity.
        assert_eq!(inst.get_real(VR_FIRST_OUTPUT + 1), Ok(0.0));
    }
}
