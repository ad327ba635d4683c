//! The FMI 3.0 co-simulation interface (`fmi3Functions.h`): thin, checked
//! wrappers around [`Instance`], as `fmi2`. Model exchange, scheduled
//! execution, clocks, event mode and derivatives are not provided: their
//! functions exist (an importer may look them up) and refuse with a
//! logged message.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::description::token;
use crate::instance::{Failure, Instance};
use crate::{Shell, Status, guarded, load_resource_params, path_from_location};
use std::ffi::{CStr, CString, c_char, c_int, c_void};

type Inst = *mut c_void;
type Env = *mut c_void;
/// `fmi3LogMessageCallback`.
pub type LogMessage = unsafe extern "C" fn(Env, c_int, *const c_char, *const c_char);

/// What an instance keeps of the callbacks.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks {
    log: Option<LogMessage>,
    env: Env,
}

type Fmu = Shell<Callbacks>;

fn log_to(cb: &Callbacks, status: Status, message: &str) {
    let Some(log) = cb.log else { return };
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    let category = if status == Status::Ok {
        c"logStatusOk"
    } else {
        c"logStatusError"
    };
    // SAFETY: the importer's callback with valid C strings.
    unsafe { log(cb.env, status as c_int, category.as_ptr(), text.as_ptr()) };
}

unsafe fn fmu<'a>(c: Inst) -> Option<&'a mut Fmu> {
    // SAFETY: `c` is null or what fmi3InstantiateCoSimulation returned
    // (the caller's contract).
    unsafe { (c as *mut Fmu).as_mut() }
}

unsafe fn with(c: Inst, refused: Status, f: impl FnOnce(&mut Instance) -> Result<(), Failure>) -> c_int {
    // SAFETY: as `fmu`.
    let Some(fmu) = (unsafe { fmu(c) }) else {
        return Status::Error as c_int;
    };
    if fmu.broken {
        log_to(
            &fmu.logger,
            Status::Error,
            "the instance failed earlier: only fmi3Reset, fmi3SetFMUState or fmi3FreeInstance",
        );
        return Status::Error as c_int;
    }
    match guarded(|| f(&mut fmu.instance)) {
        Ok(()) => Status::Ok as c_int,
        Err(e) => {
            let status = match e {
                Failure::Refused(_) => refused,
                Failure::Broken(_) => {
                    fmu.broken = true;
                    Status::Error
                }
            };
            log_to(&fmu.logger, status, e.message());
            status as c_int
        }
    }
}

unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], Failure> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure::Refused("a null array with a nonzero length".into()));
    }
    // SAFETY: `n` elements at `p` (the caller's contract).
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], Failure> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(Failure::Refused("a null array with a nonzero length".into()));
    }
    // SAFETY: `n` writable elements at `p` (the caller's contract).
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// Every variable is a scalar: one value per value reference.
fn scalars(nvr: usize, nvalues: usize) -> Result<(), Failure> {
    if nvr == nvalues {
        Ok(())
    } else {
        Err(Failure::Refused(format!(
            "{nvalues} values for {nvr} value references (every variable is a scalar)"
        )))
    }
}

unsafe fn text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: a NUL-terminated string (the caller's contract).
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(c: Inst, on: bool, _n: usize, _categories: *const *const c_char) -> c_int {
    // SAFETY: as `fmu`.
    match unsafe { fmu(c) } {
        Some(f) => {
            f.logging_on = on;
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    instantiation_token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    logging_on: bool,
    event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const u32,
    _n_required_intermediate: usize,
    instance_environment: Env,
    log_message: Option<LogMessage>,
    _intermediate_update: *const c_void,
) -> Inst {
    let callbacks = Callbacks {
        log: log_message,
        env: instance_environment,
    };
    let result = std::panic::catch_unwind(|| {
        // SAFETY: C strings from the importer.
        let name = unsafe { text(instance_name) }.unwrap_or_default();
        let fail = |m: String| {
            log_to(&callbacks, Status::Error, &m);
            std::ptr::null_mut()
        };
        if event_mode_used {
            return fail("fmi3InstantiateCoSimulation: this FMU has no event mode (hasEventMode false)".into());
        }
        // SAFETY: as above.
        let given = unsafe { text(instantiation_token) }.unwrap_or_default();
        if given != token() {
            return fail(format!(
                "fmi3InstantiateCoSimulation: instantiation token {given} is not this binary's {} (a model description of another build)",
                token()
            ));
        }
        // SAFETY: as above.
        let location = unsafe { text(resource_path) }.unwrap_or_default();
        let Some(dir) = path_from_location(&location) else {
            return fail(format!(
                "fmi3InstantiateCoSimulation: no resource path (the packaged {} is needed)",
                crate::PARAMS_RESOURCE
            ));
        };
        let raw = match load_resource_params(&dir) {
            Ok(r) => r,
            Err(e) => return fail(format!("fmi3InstantiateCoSimulation: {e}")),
        };
        let fmu = Box::new(Fmu {
            instance: Instance::new(&raw),
            name: CString::new(name.replace('\0', " ")).unwrap_or_default(),
            logger: callbacks,
            logging_on,
            broken: false,
            start_time: 0.0,
        });
        Box::into_raw(fmu) as Inst
    });
    result.unwrap_or(std::ptr::null_mut())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    instance_environment: Env,
    log_message: Option<LogMessage>,
) -> Inst {
    let cb = Callbacks {
        log: log_message,
        env: instance_environment,
    };
    log_to(&cb, Status::Error, "this FMU is for co-simulation only");
    std::ptr::null_mut()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    instance_environment: Env,
    log_message: Option<LogMessage>,
    _clock_update: *const c_void,
    _lock: *const c_void,
    _unlock: *const c_void,
) -> Inst {
    let cb = Callbacks {
        log: log_message,
        env: instance_environment,
    };
    log_to(&cb, Status::Error, "this FMU is for co-simulation only");
    std::ptr::null_mut()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(c: Inst) {
    if !c.is_null() {
        // SAFETY: what fmi3InstantiateCoSimulation returned, freed once.
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Fmu) }));
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    c: Inst,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: bool,
    _stop_time: f64,
) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Error, |i| i.enter_initialization(start_time)) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(c: Inst) -> c_int {
    // SAFETY: as `with`.
    let status = unsafe { with(c, Status::Error, Instance::exit_initialization) };
    // SAFETY: as `fmu`.
    if let Some(f) = unsafe { fmu(c) }
        && let Some(note) = f.initialised_note()
    {
        log_to(&f.logger, Status::Ok, &note);
    }
    status
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterStepMode(c: Inst) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |i| {
            if i.phase() == crate::instance::Phase::Step {
                Ok(())
            } else {
                Err(Failure::Refused("fmi3EnterStepMode: not initialised".into()))
            }
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(c: Inst) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |i| {
            i.terminate();
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(c: Inst) -> c_int {
    // SAFETY: as `fmu`.
    match unsafe { fmu(c) } {
        Some(f) => {
            f.instance.reset();
            f.broken = false;
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    c: Inst,
    vr: *const u32,
    nvr: usize,
    values: *mut f64,
    nvalues: usize,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            let (vr, values) = (slice(vr, nvr)?, slice_mut(values, nvalues)?);
            for (r, v) in vr.iter().zip(values) {
                *v = i.get_real(*r)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt32(c: Inst, vr: *const u32, nvr: usize, values: *mut i32, nvalues: usize) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            let (vr, values) = (slice(vr, nvr)?, slice_mut(values, nvalues)?);
            for (r, v) in vr.iter().zip(values) {
                *v = i.get_integer(*r)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBoolean(
    c: Inst,
    vr: *const u32,
    nvr: usize,
    values: *mut bool,
    nvalues: usize,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            let (vr, values) = (slice(vr, nvr)?, slice_mut(values, nvalues)?);
            for (r, v) in vr.iter().zip(values) {
                *v = i.get_boolean(*r)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    c: Inst,
    vr: *const u32,
    nvr: usize,
    values: *const f64,
    nvalues: usize,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            for (r, v) in slice(vr, nvr)?.iter().zip(slice(values, nvalues)?) {
                i.set_real(*r, *v)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBoolean(
    c: Inst,
    vr: *const u32,
    nvr: usize,
    values: *const bool,
    nvalues: usize,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            for (r, v) in slice(vr, nvr)?.iter().zip(slice(values, nvalues)?) {
                i.set_boolean(*r, *v)?;
            }
            Ok(())
        })
    }
}

/// A state as the importer holds it: the instance's serialisation.
type State = Vec<u8>;

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(c: Inst, state: *mut *mut c_void) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |i| {
            let state = state
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi3GetFMUState: null state pointer".into()))?;
            let bytes = i.serialize();
            match (*state as *mut State).as_mut() {
                Some(old) => *old = bytes,
                None => *state = Box::into_raw(Box::new(bytes)) as *mut c_void,
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(c: Inst, state: *mut c_void) -> c_int {
    // SAFETY: as `fmu`.
    if let Some(f) = unsafe { fmu(c) } {
        f.broken = false;
    }
    // SAFETY: as `with`; `state` is one fmi3GetFMUState made.
    unsafe {
        with(c, Status::Error, |i| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi3SetFMUState: null state".into()))?;
            i.deserialize(s)
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(_c: Inst, state: *mut *mut c_void) -> c_int {
    // SAFETY: a state this FMU made, freed once; the pointer is cleared.
    unsafe {
        if let Some(s) = state.as_mut()
            && !s.is_null()
        {
            drop(Box::from_raw(*s as *mut State));
            *s = std::ptr::null_mut();
        }
    }
    Status::Ok as c_int
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(c: Inst, state: *mut c_void, size: *mut usize) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |_| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi3SerializedFMUStateSize: null state".into()))?;
            *size
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi3SerializedFMUStateSize: null size".into()))? = s.len();
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(c: Inst, state: *mut c_void, bytes: *mut u8, size: usize) -> c_int {
    // SAFETY: as `with`, `slice_mut`.
    unsafe {
        with(c, Status::Error, |_| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi3SerializeFMUState: null state".into()))?;
            if size < s.len() {
                return Err(Failure::Refused(format!(
                    "fmi3SerializeFMUState: {size} bytes given, {} needed",
                    s.len()
                )));
            }
            slice_mut(bytes, s.len())?.copy_from_slice(s);
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    c: Inst,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            let given = slice(bytes, size)?.to_vec();
            let mut probe = i.clone();
            probe.deserialize(&given)?;
            let state = state
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi3DeserializeFMUState: null state pointer".into()))?;
            match (*state as *mut State).as_mut() {
                Some(old) => *old = given,
                None => *state = Box::into_raw(Box::new(given)) as *mut c_void,
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DoStep(
    c: Inst,
    time: f64,
    h: f64,
    _no_set_prior: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> c_int {
    // SAFETY: as `with`; the out-pointers are the importer's (or null).
    unsafe {
        let status = with(c, Status::Discard, |i| i.do_step(time, h));
        for flag in [event_handling_needed, terminate_simulation, early_return] {
            if let Some(f) = flag.as_mut() {
                *f = false;
            }
        }
        if let (Some(t), Some(f)) = (last_successful_time.as_mut(), fmu(c)) {
            *t = f.instance.get_real(crate::variables::VR_TIME).unwrap_or(time);
        }
        status
    }
}

/// Functions of FMI 3.0 this FMU does not provide: each refuses with a
/// logged message (`fmi3Error`).
macro_rules! unsupported {
    ($($name:ident($($t:ty),*);)*) => {
        $(
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(c: Inst $(, _: $t)*) -> c_int {
                // SAFETY: as `with`.
                unsafe {
                    with(c, Status::Error, |_| {
                        Err(Failure::Refused(concat!(stringify!($name), ": not supported by this FMU").into()))
                    })
                }
            }
        )*
    };
}

unsupported! {
    fmi3EnterEventMode();
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3EnterContinuousTimeMode();
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(*mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64);
    fmi3GetFloat32(*const u32, usize, *mut f32, usize);
    fmi3GetInt8(*const u32, usize, *mut i8, usize);
    fmi3GetUInt8(*const u32, usize, *mut u8, usize);
    fmi3GetInt16(*const u32, usize, *mut i16, usize);
    fmi3GetUInt16(*const u32, usize, *mut u16, usize);
    fmi3GetUInt32(*const u32, usize, *mut u32, usize);
    fmi3GetInt64(*const u32, usize, *mut i64, usize);
    fmi3GetUInt64(*const u32, usize, *mut u64, usize);
    fmi3GetString(*const u32, usize, *mut *const c_char, usize);
    fmi3GetBinary(*const u32, usize, *mut usize, *mut *const u8, usize);
    fmi3GetClock(*const u32, usize, *mut bool);
    fmi3SetFloat32(*const u32, usize, *const f32, usize);
    fmi3SetInt8(*const u32, usize, *const i8, usize);
    fmi3SetUInt8(*const u32, usize, *const u8, usize);
    fmi3SetInt16(*const u32, usize, *const i16, usize);
    fmi3SetUInt16(*const u32, usize, *const u16, usize);
    fmi3SetInt32(*const u32, usize, *const i32, usize);
    fmi3SetUInt32(*const u32, usize, *const u32, usize);
    fmi3SetInt64(*const u32, usize, *const i64, usize);
    fmi3SetUInt64(*const u32, usize, *const u64, usize);
    fmi3SetString(*const u32, usize, *const *const c_char, usize);
    fmi3SetBinary(*const u32, usize, *const usize, *const *const u8, usize);
    fmi3SetClock(*const u32, usize, *const bool);
    fmi3GetNumberOfVariableDependencies(u32, *mut usize);
    fmi3GetVariableDependencies(u32, *mut usize, *mut u32, *mut usize, *mut c_int, usize);
    fmi3GetDirectionalDerivative(*const u32, usize, *const u32, usize, *const f64, usize, *mut f64, usize);
    fmi3GetAdjointDerivative(*const u32, usize, *const u32, usize, *const f64, usize, *mut f64, usize);
    fmi3GetIntervalDecimal(*const u32, usize, *mut f64, *mut c_int);
    fmi3GetIntervalFraction(*const u32, usize, *mut u64, *mut u64, *mut c_int);
    fmi3GetShiftDecimal(*const u32, usize, *mut f64);
    fmi3GetShiftFraction(*const u32, usize, *mut u64, *mut u64);
    fmi3SetIntervalDecimal(*const u32, usize, *const f64);
    fmi3SetIntervalFraction(*const u32, usize, *const u64, *const u64);
    fmi3SetShiftDecimal(*const u32, usize, *const f64);
    fmi3SetShiftFraction(*const u32, usize, *const u64, *const u64);
    fmi3CompletedIntegratorStep(bool, *mut bool, *mut bool);
    fmi3SetTime(f64);
    fmi3SetContinuousStates(*const f64, usize);
    fmi3GetContinuousStateDerivatives(*mut f64, usize);
    fmi3GetEventIndicators(*mut f64, usize);
    fmi3GetContinuousStates(*mut f64, usize);
    fmi3GetNominalsOfContinuousStates(*mut f64, usize);
    fmi3GetNumberOfEventIndicators(*mut usize);
    fmi3GetNumberOfContinuousStates(*mut usize);
    fmi3GetOutputDerivatives(*const u32, usize, *const i32, *mut f64, usize);
    fmi3ActivateModelPartition(u32, f64);
}
