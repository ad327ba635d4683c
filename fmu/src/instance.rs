//! One FMU instance in plain Rust: the parameter values, the input, the
//! phase of the FMI state machine and, once initialised, the twin. The C
//! interfaces (`fmi2`, `fmi3`) are thin wrappers around it; nothing here is
//! shared between instances (no statics).
//!
//! What runs is the firmware's own twin: `Twin<f32, f32>` with the
//! configuration the core's chooser picks for the parameter file
//! (`compensator::dynamics::config::choose` at the estimator's tick over
//! its validated range: what `build.rs` ships and `compensator step
//! --precision f32` runs), inside the estimator's own plant observer
//! (`compensator::estimator::Plant`: the twin, the jobs and the
//! publication of an estimate), driven with the input temperature and
//! port pressures directly. The estimator's sensor side is not used: its
//! temperature filter, spike rejection and slew limit would put the
//! sensor's dynamics between the oil temperature and the twin. Where the
//! estimator runs its jobs in rotation, an input change runs them all at
//! once (`Plant::refresh`); the flags, flows and compensation error are
//! the estimator's publication (`Plant::estimate`).
//!
//! With a second sensor in the packaged file (`[monitor]`), the core's
//! condition monitor (`compensator::monitor::Monitor`, its settings
//! `MonitorSettings::from_raw`) takes the input `second_reading` once per
//! communication step, at the step's start (after the inputs are applied,
//! before the ticks), against the twin's state and oil there, the oil's
//! temperature known exactly (the input, not a probe's estimate); its
//! health estimate is published with the step's outputs. The monitor's
//! state is not part of a serialised FMU state (the core does not expose
//! it): a state saved after the monitor took a reading is refused when set.

use crate::variables::{
    FIELD_COUNT, FIRST_HEALTH_OUTPUT, FLAGS_OUTPUT, INPUTS, OUTPUT_COUNT, VR_FIRST_OUTPUT, VR_MACHINE_PRESENT,
    VR_P_OUTLET, VR_P_SUPPLY, VR_SECOND_READING, VR_TIME, field_of, fields, input_of, output,
};
use compensator::dynamics::config::choose;
use compensator::dynamics::{Owed, TwinConfig, TwinMemory};
use compensator::estimator::health::HEALTH_FIELDS;
use compensator::estimator::{EstimatorConfig, Flags, NO_LAG, Plant};
use compensator::monitor::{HealthEstimate, Monitor, MonitorSettings, PER_READING, PlantView, ProbeModel, ProbeSample};
use compensator::{ModelError, Params, RawParams};
use compensator_params::{MACHINE_FIELDS, RawMonitor, RawTolerances};

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

/// The types of the FMU's variables, as each FMI version names them
/// (FMI 2.0 `Real`, `Integer`; FMI 3.0 `Float64`, `Int32`; both
/// `Boolean`, `String`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    /// A 64-bit float.
    Float,
    /// A 32-bit integer.
    Integer,
    /// A Boolean.
    Boolean,
    /// A string (the FMU has none).
    String,
}

/// Why a call failed: the message the logger gets (naming the field or
/// the quantity), and whether the instance can go on (`Discard`) or not.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// The call was refused and changed nothing; the instance goes on
    /// (FMI `Discard` for a step, `Error` for a set or get).
    Refused(String),
    /// A value reference read or written as a type it is not (or set
    /// though it is not settable): refused as [`Failure::Refused`].
    NotOfType {
        /// The value reference.
        vr: u32,
        /// The type the call reads or writes.
        ty: Type,
        /// The call writes.
        settable: bool,
    },
    /// The instance cannot go on without a reset or an earlier state.
    Broken(String),
}

impl Failure {
    /// The message, the types named by `type_name` (the FMI version's).
    pub fn message(&self, type_name: impl Fn(Type) -> &'static str) -> String {
        match self {
            Failure::Refused(m) | Failure::Broken(m) => m.clone(),
            Failure::NotOfType { ty: Type::String, .. } => "this FMU has no String variable".into(),
            Failure::NotOfType { vr, ty, settable } => {
                let name = type_name(*ty);
                let article = if !settable && name.starts_with(['A', 'E', 'I', 'O', 'U']) {
                    "an"
                } else {
                    "a"
                };
                format!(
                    "value reference {vr}: not {article}{} {name}",
                    if *settable { " settable" } else { "" }
                )
            }
        }
    }
}

/// The values settable before initialisation: every parameter-file field
/// (in [`fields`] order) and whether the `[machine]` section is present;
/// with the packaged file's `[tolerances]`, which are no variables (the
/// uncertainty table the estimator settings are built with needs them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// Field values, in [`fields`] order.
    pub values: [f64; FIELD_COUNT],
    /// The `[machine]` section is used (`machine.present`).
    pub machine_present: bool,
    /// The packaged file's standard uncertainties and correlations.
    pub tolerances: RawTolerances,
    /// The packaged file's second sensor (`[monitor]`; not variables
    /// either: the monitor's settings travel with the file).
    pub monitor: RawMonitor,
}

/// Start values of the `[machine]` fields for a file without that section
/// (not used while `machine.present` is false): no flow, no loss, the loss
/// referred to 40 C (the ISO 3448 viscosity-grade temperature).
const NO_MACHINE: [f64; 3] = [0.0, 0.0, 40.0];

impl Setup {
    /// The values of a parameter file.
    pub fn from_raw(raw: &RawParams) -> Setup {
        // In the variables' order ([`fields`]); a machine's fields at
        // their placeholders when the file has none.
        let values: Vec<f64> = fields()
            .map(|f| match raw.get(f.path) {
                Ok(v) => v,
                Err(_) => MACHINE_FIELDS
                    .iter()
                    .position(|m| m.path == f.path)
                    .map_or(f64::NAN, |i| NO_MACHINE[i]),
            })
            .collect();
        Setup {
            values: values.try_into().expect("one value per field"),
            machine_present: raw.machine.is_some(),
            tolerances: raw.tolerances,
            monitor: raw.monitor,
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
        .and_then(|raw| {
            let raw = RawParams {
                tolerances: self.tolerances,
                monitor: self.monitor,
                ..raw
            };
            // The second sensor's rules against the device.
            raw.validate().map(|()| raw)
        })
        .map_err(|e| e.to_string())
    }
}

/// The port pressures `(p_supply, p_outlet)` [Pa] of a parameter set: the
/// inputs' start values (`operating.outlet_pressure + pressure_drop`,
/// `operating.outlet_pressure`).
pub fn pressures_start(raw: &RawParams) -> (f64, f64) {
    let c = &raw.core;
    (c.outlet_pressure + c.pressure_drop, c.outlet_pressure)
}

/// What the twin's coefficients were last set from: the oil temperature
/// [C] and the port pressures `(p_supply, p_outlet)` [Pa].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Applied {
    t: f32,
    pressures: (f32, f32),
}

/// An initialised instance: the plant observer and what drives it.
#[derive(Clone, Copy, Debug)]
struct Sim {
    raw: RawParams,
    estimator: EstimatorConfig,
    /// The twin, its jobs and the publication of an estimate: the
    /// estimator's own ([`Plant`]), driven by the inputs.
    plant: Plant<f32>,
    /// The configured tick [s] (the chooser's; a communication step that
    /// is not whole ticks runs shorter ones, `Twin::set_tick`).
    tick: f64,
    /// Temperature the twin was built at [C].
    t_init: f32,
    /// Temperature and pressures of the twin's coefficients.
    applied: Applied,
    /// The last results could not be computed at `applied` (the previous
    /// ones stand, flagged `DEGRADED`, until they can).
    stale: bool,
    /// The instance's time [s]: the end of the last communication step.
    time: f64,
    flags: Flags,
    outputs: [f64; OUTPUT_COUNT],
    /// The condition monitor, with a second sensor in the file.
    monitor: Option<Monitor>,
    /// Its estimate at its last reading.
    health: HealthEstimate,
    /// Readings it has taken.
    readings: u64,
    /// The time of the monitor's last reading \[s\].
    monitor_time: Option<f64>,
}

fn model_error(what: &str, e: ModelError) -> String {
    format!("{what}: {e}")
}

/// The inputs of one communication step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// Oil temperature [C].
    pub t_oil: f64,
    /// Supply pressure [Pa].
    pub p_supply: f64,
    /// Outlet pressure [Pa].
    pub p_outlet: f64,
    /// The second sensor's reading this step [Pa or m] (NaN: none).
    pub second: f64,
}

impl Sim {
    /// The twin at rest at `inputs` (the equilibrium of the oil
    /// temperature at the port pressures). `chosen`: a configuration
    /// already chosen for these parameters.
    fn new(
        setup: &Setup,
        inputs: Inputs,
        start_time: f64,
        chosen: Option<(&RawParams, TwinConfig)>,
    ) -> Result<Sim, String> {
        let raw = setup.to_raw()?;
        let params = Params::<f32>::new(&raw).map_err(|e| e.to_string())?;
        let estimator = EstimatorConfig::new(&raw).map_err(|e| e.to_string())?;
        let monitor = match MonitorSettings::from_raw(&raw).map_err(|e| e.to_string())? {
            // The oil's temperature is the input itself: a probe that
            // neither lags nor errs, read to the file's converter's
            // resolution.
            Some(m) => {
                let probe = ProbeModel {
                    time_constant: NO_LAG as f32,
                    well_time_constant: 0.0,
                    tolerance_a: 0.0,
                    tolerance_b: 0.0,
                    ..m.probe
                };
                Some(Monitor::new(&params, MonitorSettings { probe, ..m }).map_err(|e| e.to_string())?)
            }
            None => None,
        };
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
        let t_oil = inputs.t_oil;
        let t = t_oil as f32;
        if !(t.is_finite() && estimator.oil.contains(t)) {
            return Err(format!(
                "T_oil: {t_oil} degC is outside the oil model's range {}..{} degC (estimator.oil_min, estimator.oil_max)",
                estimator.oil.min, estimator.oil.max
            ));
        }
        let pressures = (inputs.p_supply as f32, inputs.p_outlet as f32);
        if !(pressures.0.is_finite() && pressures.1.is_finite() && pressures.0 > pressures.1) {
            return Err(format!(
                "p_supply = {} Pa, p_outlet = {} Pa: at the end of initialisation the supply must exceed the outlet \
                 (the twin starts at rest in the equilibrium there)",
                inputs.p_supply, inputs.p_outlet
            ));
        }
        let at_t = |e| model_error(&format!("T_oil = {t_oil} degC"), e);
        // The twin at rest at the oil temperature, the input's uncertainty
        // none (the temperature is given, not measured).
        let mut plant = Plant::new(
            &params,
            &EstimatorConfig {
                twin: config,
                ..estimator
            },
            t,
            0.0,
        )
        .map_err(at_t)?;
        let designed = (params.pressure_drop + params.outlet_pressure, params.outlet_pressure);
        if pressures != designed {
            plant
                .set_ports(pressures.0, pressures.1)
                .map_err(|e| model_error("p_supply, p_outlet", e))?;
            plant
                .rest()
                .map_err(|e| model_error("the equilibrium at p_supply, p_outlet", e))?;
            plant.refresh(&estimator, t, 0.0).map_err(at_t)?;
        }
        let applied = Applied { t, pressures };
        let mut sim = Sim {
            raw,
            estimator,
            plant,
            tick: config.tick,
            t_init: t,
            applied,
            stale: false,
            time: start_time,
            flags: Flags::empty(),
            outputs: [f64::NAN; OUTPUT_COUNT],
            monitor,
            health: HealthEstimate::NONE,
            readings: 0,
            monitor_time: None,
        };
        sim.publish(Flags::empty());
        Ok(sim)
    }

    /// Computes the outputs from the plant's estimate (the estimator's
    /// publication) with `flags` and the design's and inputs' own.
    fn publish(&mut self, mut flags: Flags) {
        flags.insert(self.plant.flags_at(&self.estimator, self.applied.t));
        // The monitor's standing flags (the named faults, a change not yet
        // named); its per-reading ones come with the step's reading.
        flags.insert(Flags(self.health.flags.0 & !PER_READING.0));
        let e = self.plant.estimate(self.applied.t, flags);
        self.flags = e.flags;
        let state = [
            e.x as f64,
            e.v as f64,
            e.p_a as f64,
            e.p_b as f64,
            e.q_a as f64,
            e.q_b as f64,
            e.q_throt as f64,
            e.q_total as f64,
            e.compensation_error as f64,
            e.flags.0 as f64,
        ];
        self.outputs[..FIRST_HEALTH_OUTPUT].copy_from_slice(&state);
        for (out, f) in self.outputs[FIRST_HEALTH_OUTPUT..].iter_mut().zip(&HEALTH_FIELDS) {
            *out = (f.value)(&self.health);
        }
    }

    /// Gives the second sensor's `reading` [Pa or m] (NaN: none) to the
    /// monitor, against the twin as it stands; the reading's own flags.
    fn monitor_reading(&mut self, reading: f64) -> Flags {
        let Some(monitor) = self.monitor.as_mut() else {
            return Flags::empty();
        };
        if reading.is_nan() {
            return Flags::empty();
        }
        let s = self.plant.twin().state();
        let view = PlantView {
            oil: *self.plant.oil(),
            x: s.x,
            p_a: s.p_a,
            p_b: s.p_b,
            dt: self.monitor_time.map_or(0.0, |t| (self.time - t) as f32),
            probe: Some(ProbeSample {
                value: self.applied.t,
                age: 0.0,
            }),
        };
        self.monitor_time = Some(self.time);
        self.health = monitor.update(self.plant.params(), &view, Ok::<f32, ()>(reading as f32));
        self.readings += 1;
        Flags(self.health.flags.0 & PER_READING.0)
    }

    /// Sets the twin's coefficients for `inputs` where they are usable
    /// (as `compensator step`: before the ticks; held over the
    /// communication step); the flags of what was not.
    fn apply(&mut self, inputs: Inputs) -> Flags {
        let mut flags = Flags::empty();
        let mut next = self.applied;
        let t = inputs.t_oil as f32;
        if t.is_finite() && self.estimator.oil.contains(t) {
            next.t = t;
        } else {
            // Not an oil temperature: the twin keeps the last one, flagged
            // as the estimator flags an unusable sample.
            flags.insert(Flags::SENSOR_FAULT);
        }
        let pressures = (inputs.p_supply as f32, inputs.p_outlet as f32);
        if pressures.0.is_finite() && pressures.1.is_finite() {
            if pressures != self.applied.pressures {
                match self.plant.set_ports(pressures.0, pressures.1) {
                    Ok(()) => next.pressures = pressures,
                    Err(_) => flags.insert(Flags::DEGRADED),
                }
            }
        } else {
            flags.insert(Flags::SENSOR_FAULT);
        }
        if next != self.applied || self.stale {
            // Every job at once at the inputs (the estimator runs them in
            // rotation); a refusal leaves the twin's last oil and the last
            // results, flagged, until the inputs are usable.
            self.stale = self.plant.refresh(&self.estimator, next.t, 0.0).is_err();
            self.applied = next;
        }
        flags
    }

    /// `n` ticks of `tick` [s] with the inputs held.
    fn step(&mut self, inputs: Inputs, n: u64, tick: f64) -> Result<(), String> {
        let mut flags = self.apply(inputs);
        flags.insert(self.monitor_reading(inputs.second));
        let twin = self.plant.twin_mut();
        if twin.config().tick != tick {
            twin.set_tick(tick)
                .map_err(|e| model_error(&format!("a tick of {tick} s"), e))?;
        }
        for _ in 0..n {
            // As the estimator: a failed tick (never seen with valid
            // parameters) restarts the twin at rest in the equilibrium.
            self.plant
                .advance(&mut flags)
                .map_err(|e| model_error(&format!("restarting the twin at {} degC", self.applied.t), e))?;
        }
        self.publish(flags);
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
    /// The pressure inputs as set (`None`: never set since instantiation or
    /// reset, so at their start values: the operating point of the current
    /// parameters).
    p_supply: Option<f64>,
    p_outlet: Option<f64>,
    /// The second sensor's reading as set (NaN: none).
    second: f64,
    start_time: f64,
    phase: Phase,
    sim: Option<Sim>,
}

/// Tolerance on a communication step's length, as a fraction of the tick:
/// a step within it of a whole number of ticks is that many ticks.
const STEP_TOLERANCE: f64 = 1e-6;

/// Most ticks one communication step may take (10,000 s at 1 kHz, a few
/// seconds of computing): a larger step is refused rather than left to
/// run for hours.
pub const MAX_TICKS_PER_STEP: f64 = 1e7;

/// How the twin takes a communication step of `h` [s] with configured
/// tick `tick` [s]: `(n, tick')`, `n` ticks of `tick'`. A whole number of
/// ticks (within [`STEP_TOLERANCE`] of a tick) is that many configured
/// ticks; any other step is `ceil(h / tick)` equal ticks of `h / n`, each
/// shorter than the configured one (the same substeps, so at least as
/// accurate): the step ends exactly at `t + h`. `None` for a step that is
/// not positive and finite.
pub fn ticks_for(h: f64, tick: f64) -> Option<(f64, f64)> {
    if !(h.is_finite() && h > 0.0) {
        return None;
    }
    let whole = (h / tick).round();
    if whole >= 1.0 && (h - whole * tick).abs() <= STEP_TOLERANCE * tick {
        return Some((whole, tick));
    }
    let n = (h / tick).ceil().max(1.0);
    Some((n, h / n))
}

impl Instance {
    /// An instance with the values of `raw` (the packaged parameter file),
    /// the inputs at their start values.
    pub fn new(raw: &RawParams) -> Instance {
        let setup = Setup::from_raw(raw);
        let t = t_oil_start(raw);
        Instance {
            start: setup,
            setup,
            t_oil_start: t,
            t_oil: t,
            p_supply: None,
            p_outlet: None,
            second: f64::NAN,
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
        self.sim.as_ref().map(|s| s.plant.twin().config())
    }

    /// The inputs as they stand: `p_supply`, `p_outlet` at their start
    /// values (the current parameters' operating point) until set.
    pub fn inputs(&self) -> Inputs {
        let value = |path: &str| {
            fields()
                .position(|f| f.path == path)
                .map_or(f64::NAN, |i| self.setup.values[i])
        };
        let outlet = value("operating.outlet_pressure");
        let p_outlet = self.p_outlet.unwrap_or(outlet);
        Inputs {
            t_oil: self.t_oil,
            p_supply: self.p_supply.unwrap_or(outlet + value("operating.pressure_drop")),
            p_outlet,
            second: self.second,
        }
    }

    fn settable(&self, name: &str) -> Result<(), Failure> {
        match self.phase {
            Phase::Instantiated | Phase::Initialization => Ok(()),
            _ => Err(Failure::Refused(format!(
                "{name}: a parameter can be set only before initialisation ends"
            ))),
        }
    }

    /// Sets a Float64 variable: an input (any time before termination) or
    /// a parameter (before exit-initialization, checked against the
    /// field's own rule at once; the rules between fields are checked when
    /// initialisation ends).
    ///
    /// # Errors
    ///
    /// An unknown or read-only value reference, a parameter set too late,
    /// or a value the field refuses (the message names the field).
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), Failure> {
        if let Some(k) = input_of(vr) {
            if self.phase == Phase::Terminated {
                return Err(Failure::Refused(format!(
                    "{}: the instance is terminated",
                    INPUTS[k].name
                )));
            }
            match vr {
                VR_P_SUPPLY => self.p_supply = Some(value),
                VR_P_OUTLET => self.p_outlet = Some(value),
                VR_SECOND_READING => {
                    if !value.is_nan() && !self.setup.monitor.has_sensor() {
                        return Err(Failure::Refused(format!(
                            "second_reading: {value}: the packaged parameter file has no second sensor \
                             (monitor.sensor = \"none\"); leave it NaN"
                        )));
                    }
                    // A reading for the monitor, not a change of the twin's
                    // inputs: the initialised twin stands.
                    self.second = value;
                    return Ok(());
                }
                _ => self.t_oil = value,
            }
            if self.phase == Phase::Initialization {
                self.sim = None;
            }
            return Ok(());
        }
        let Some((i, field)) = field_of(vr) else {
            return Err(Failure::NotOfType {
                vr,
                ty: Type::Float,
                settable: true,
            });
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
            return Err(Failure::NotOfType {
                vr,
                ty: Type::Boolean,
                settable: true,
            });
        }
        self.settable("machine.present")?;
        self.setup.machine_present = value;
        self.sim = None;
        Ok(())
    }

    /// Builds the twin from the current values when it is not built.
    fn ensure_sim(&mut self) -> Result<&mut Sim, Failure> {
        if self.sim.is_none() {
            let inputs = self.inputs();
            self.sim = Some(Sim::new(&self.setup, inputs, self.start_time, None).map_err(Failure::Refused)?);
        }
        Ok(self.sim.as_mut().expect("built above"))
    }

    /// Reads a Float64: time, an input, an output (from initialization
    /// mode on: the twin at rest at the inputs until the first step) or a
    /// parameter.
    ///
    /// # Errors
    ///
    /// An unknown value reference, an output read before initialization
    /// mode, or (in initialization mode) values that do not initialise.
    pub fn get_real(&mut self, vr: u32) -> Result<f64, Failure> {
        if input_of(vr).is_some() {
            let i = self.inputs();
            return Ok(match vr {
                VR_P_SUPPLY => i.p_supply,
                VR_P_OUTLET => i.p_outlet,
                VR_SECOND_READING => i.second,
                _ => i.t_oil,
            });
        }
        if let Some((i, _)) = field_of(vr) {
            return Ok(self.setup.values[i]);
        }
        let out = vr.wrapping_sub(VR_FIRST_OUTPUT) as usize;
        if vr == VR_TIME || (out < OUTPUT_COUNT && out != FLAGS_OUTPUT) {
            let sim = self.initialised_sim(vr)?;
            return Ok(if vr == VR_TIME { sim.time } else { sim.outputs[out] });
        }
        Err(Failure::NotOfType {
            vr,
            ty: Type::Float,
            settable: false,
        })
    }

    fn initialised_sim(&mut self, vr: u32) -> Result<&mut Sim, Failure> {
        if self.phase == Phase::Instantiated {
            if vr == VR_TIME {
                return Err(Failure::Refused("time: not defined before initialization mode".into()));
            }
            return Err(Failure::Refused(format!(
                "{}: outputs are defined from initialization mode on",
                output((vr - VR_FIRST_OUTPUT) as usize).map_or("an output", |o| o.name)
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
            return Err(Failure::NotOfType {
                vr,
                ty: Type::Integer,
                settable: false,
            });
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
            return Err(Failure::NotOfType {
                vr,
                ty: Type::Boolean,
                settable: false,
            });
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
    /// twin's configuration and puts the twin at rest at the inputs.
    ///
    /// # Errors
    ///
    /// A parameter the validation refuses (the message names the field), a
    /// `T_oil` outside the oil model's range, a supply pressure not above
    /// the outlet's, or not in initialization mode.
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

    /// Advances from `time` [s] by `h` [s] with the inputs held: whole
    /// ticks of the twin, or, for a step that is not whole ticks (shorter
    /// than one, or between two counts), equal shorter ticks that end
    /// exactly at `time + h` ([`ticks_for`]).
    ///
    /// # Errors
    ///
    /// `Refused` (nothing done: FMI `Discard`) for a step that is not
    /// positive and finite, takes more than [`MAX_TICKS_PER_STEP`] ticks or
    /// does not start at the instance's time; `Broken` for a twin that
    /// cannot be restarted.
    pub fn do_step(&mut self, time: f64, h: f64) -> Result<(), Failure> {
        if self.phase != Phase::Step {
            return Err(Failure::Broken(
                "do step: only in step mode (after exit initialization)".into(),
            ));
        }
        let inputs = self.inputs();
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| Failure::Broken("do step: not initialised".into()))?;
        let Some((n, tick)) = ticks_for(h, sim.tick) else {
            return Err(Failure::Refused(format!(
                "communication step {h} s: must be positive and finite"
            )));
        };
        if n > MAX_TICKS_PER_STEP {
            return Err(Failure::Refused(format!(
                "communication step {h:e} s is more than {MAX_TICKS_PER_STEP} ticks of {} s: take shorter steps",
                sim.tick
            )));
        }
        let now = sim.time;
        if !((time - now).abs() <= STEP_TOLERANCE * sim.tick + 1e-12 * now.abs()) {
            return Err(Failure::Refused(format!(
                "communication point {time} s is not the instance's time {now} s"
            )));
        }
        sim.step(inputs, n as u64, tick).map_err(Failure::Broken)?;
        sim.time = time + h;
        Ok(())
    }

    /// The twin's configured tick [s] once initialised.
    pub fn tick(&self) -> Option<f64> {
        self.sim.as_ref().map(|s| s.tick)
    }

    /// Terminates.
    pub fn terminate(&mut self) {
        self.phase = Phase::Terminated;
    }

    /// Back to the freshly instantiated state (the packaged parameters,
    /// the inputs' start values).
    pub fn reset(&mut self) {
        self.setup = self.start;
        self.t_oil = self.t_oil_start;
        self.p_supply = None;
        self.p_outlet = None;
        self.second = f64::NAN;
        self.start_time = 0.0;
        self.sim = None;
        self.phase = Phase::Instantiated;
    }

    /// The instance's state as bytes: phase, parameters, inputs and (once
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
        for p in [self.p_supply, self.p_outlet] {
            b.push(p.is_some() as u8);
            b.extend_from_slice(&p.unwrap_or(0.0).to_le_bytes());
        }
        b.extend_from_slice(&self.second.to_le_bytes());
        b.extend_from_slice(&self.start_time.to_le_bytes());
        match &self.sim {
            None => b.push(0),
            Some(s) => {
                b.push(1);
                b.extend_from_slice(&s.t_init.to_le_bytes());
                b.extend_from_slice(&s.applied.t.to_le_bytes());
                b.extend_from_slice(&s.applied.pressures.0.to_le_bytes());
                b.extend_from_slice(&s.applied.pressures.1.to_le_bytes());
                b.extend_from_slice(&s.time.to_le_bytes());
                b.extend_from_slice(&s.plant.twin().config().tick.to_le_bytes());
                let m = s.plant.twin().memory();
                for v in m.state {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                b.extend_from_slice(&m.xi_carry.to_le_bytes());
                b.push(m.abrupt as u8);
                b.extend_from_slice(&s.flags.0.to_le_bytes());
                for v in s.outputs {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                b.extend_from_slice(&s.readings.to_le_bytes());
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
            // Not variables: the packaged file's, as at instantiation.
            tolerances: self.start.tolerances,
            monitor: self.start.monitor,
        };
        let t_oil = r.f64().ok_or_else(bad)?;
        let mut set = [None; 2];
        for p in &mut set {
            let given = r.u8().ok_or_else(bad)? != 0;
            let v = r.f64().ok_or_else(bad)?;
            *p = given.then_some(v);
        }
        let second = r.f64().ok_or_else(bad)?;
        let start_time = r.f64().ok_or_else(bad)?;
        let sim = match r.u8().ok_or_else(bad)? {
            0 => None,
            1 => {
                let t_init = r.f32().ok_or_else(bad)?;
                let applied = Applied {
                    t: r.f32().ok_or_else(bad)?,
                    pressures: (r.f32().ok_or_else(bad)?, r.f32().ok_or_else(bad)?),
                };
                let time = r.f64().ok_or_else(bad)?;
                let tick = r.f64().ok_or_else(bad)?;
                let mut state = [0.0f32; 4];
                for v in &mut state {
                    *v = r.f32().ok_or_else(bad)?;
                }
                let xi_carry = r.f32().ok_or_else(bad)?;
                let abrupt = r.u8().ok_or_else(bad)? != 0;
                let flags = Flags(r.u32().ok_or_else(bad)?);
                let mut outputs = [0.0; OUTPUT_COUNT];
                for v in &mut outputs {
                    *v = r.f64().ok_or_else(bad)?;
                }
                let readings = u64::from_le_bytes(r.take(8).ok_or_else(bad)?.try_into().map_err(|_| bad())?);
                if readings > 0 {
                    return Err(Failure::Refused(format!(
                        "FMU state: saved after the condition monitor took {readings} readings, whose state cannot \
                         be restored (the core does not expose it); restart from the initialisation instead"
                    )));
                }
                // The twin rebuilt along the same path (built at t_init at
                // the design's pressures, then given the last temperature
                // and pressures and the last tick), then its memory.
                let chosen = self.sim.as_ref().map(|s| (&s.raw, s.plant.twin().config()));
                let raw = setup.to_raw().map_err(Failure::Refused)?;
                let (ps, po) = pressures_start(&raw);
                let designed = Inputs {
                    t_oil: t_init as f64,
                    p_supply: ps,
                    p_outlet: po,
                    second: f64::NAN,
                };
                let mut sim = Sim::new(&setup, designed, start_time, chosen).map_err(Failure::Refused)?;
                let restored = sim.apply(Inputs {
                    t_oil: applied.t as f64,
                    p_supply: applied.pressures.0 as f64,
                    p_outlet: applied.pressures.1 as f64,
                    second: f64::NAN,
                });
                if sim.applied != applied || !restored.is_empty() {
                    return Err(Failure::Refused(
                        "FMU state: its temperature or pressures no longer apply".into(),
                    ));
                }
                sim.plant
                    .twin_mut()
                    .set_tick(tick)
                    .map_err(|e| Failure::Refused(model_error("FMU state: tick", e)))?;
                sim.plant.twin_mut().restore(&TwinMemory {
                    state,
                    xi_carry,
                    abrupt,
                    // A floating-point twin never leaves an event's rest
                    // to the next tick.
                    owed: Owed::NONE,
                });
                sim.time = time;
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
        [self.p_supply, self.p_outlet] = set;
        self.second = second;
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
const FORMAT: u32 = 3;

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
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
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
    use crate::variables::VR_T_OIL;

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
