//! The FMI 2.0 co-simulation interface (`fmi2Functions.h`): thin, checked
//! wrappers around [`Instance`]. Every refusal is logged through the
//! importer's logger (category `logStatusError`) with a message naming the
//! field or the call; no entry point unwinds into the importer.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::description::{MODEL_IDENTIFIER, token};
use crate::instance::{Failure, Instance};
use crate::{Shell, Status, guarded, load_resource_params, path_from_location};
use std::ffi::{CStr, CString, c_char, c_int, c_uint, c_void};

type Component = *mut c_void;
type Env = *mut c_void;
type ValueReference = c_uint;
/// `fmi2CallbackLogger`.
pub type Logger = unsafe extern "C" fn(Env, *const c_char, c_int, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions` (the memory functions are not used: the FMU
/// declares `canNotUseMemoryManagementFunctions`).
#[repr(C)]
pub struct CallbackFunctions {
    /// `fmi2CallbackLogger` (C-variadic; called with the message as the
    /// format string, `%` doubled, and no further arguments).
    pub logger: Option<Logger>,
    /// `fmi2CallbackAllocateMemory`.
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// `fmi2CallbackFreeMemory`.
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// `fmi2StepFinished`.
    pub step_finished: Option<unsafe extern "C" fn(Env, c_int)>,
    /// Passed back to the logger.
    pub component_environment: Env,
}

/// What an instance keeps of the callbacks.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks {
    logger: Option<Logger>,
    env: Env,
}

type Fmu = Shell<Callbacks>;

const CO_SIMULATION: c_int = 1;
const LAST_SUCCESSFUL_TIME: c_int = 2;
const TERMINATED: c_int = 3;

fn log_to(cb: &Callbacks, name: &CStr, status: Status, message: &str) {
    let Some(logger) = cb.logger else { return };
    // The message is the format string (what FMI 2.0 loggers expect, and
    // what a logger that does not expand arguments prints): `%` doubled.
    let text = CString::new(message.replace('%', "%%").replace('\0', " ")).unwrap_or_default();
    let category = match status {
        Status::Ok => c"logStatusOk",
        _ => c"logStatusError",
    };
    // SAFETY: the importer's logger with valid C strings.
    unsafe { logger(cb.env, name.as_ptr(), status as c_int, category.as_ptr(), text.as_ptr()) };
}

unsafe fn fmu<'a>(c: Component) -> Option<&'a mut Fmu> {
    // SAFETY: `c` is null or what fmi2Instantiate returned (the caller's
    // contract).
    unsafe { (c as *mut Fmu).as_mut() }
}

/// Runs `f` on the instance behind `c`; logs a refusal and maps it to a
/// status (`refused` for a refused call: Error, or Discard for a step).
unsafe fn with(c: Component, refused: Status, f: impl FnOnce(&mut Instance) -> Result<(), Failure>) -> c_int {
    // SAFETY: as `fmu`.
    let Some(fmu) = (unsafe { fmu(c) }) else {
        return Status::Error as c_int;
    };
    if fmu.broken {
        log_to(
            &fmu.logger,
            &fmu.name,
            Status::Error,
            "the instance failed earlier: only fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance",
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
            log_to(&fmu.logger, &fmu.name, status, e.message());
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

unsafe fn text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: a NUL-terminated string (the caller's contract).
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> Component {
    // SAFETY: the importer's callbacks (or null).
    let callbacks = match unsafe { functions.as_ref() } {
        Some(f) => Callbacks {
            logger: f.logger,
            env: f.component_environment,
        },
        None => Callbacks {
            logger: None,
            env: std::ptr::null_mut(),
        },
    };
    let result = std::panic::catch_unwind(|| {
        // SAFETY: C strings from the importer.
        let name = unsafe { text(instance_name) }.unwrap_or_else(|| MODEL_IDENTIFIER.into());
        let cname = CString::new(name.replace('\0', " ")).unwrap_or_default();
        let fail = |m: String| {
            log_to(&callbacks, &cname, Status::Error, &m);
            std::ptr::null_mut()
        };
        if fmu_type != CO_SIMULATION {
            return fail("fmi2Instantiate: this FMU is for co-simulation only (fmuType fmi2CoSimulation)".into());
        }
        // SAFETY: as above.
        let given = unsafe { text(guid) }.unwrap_or_default();
        if given != token() {
            return fail(format!(
                "fmi2Instantiate: GUID {given} is not this binary's {} (a model description of another build)",
                token()
            ));
        }
        // SAFETY: as above.
        let location = unsafe { text(resource_location) }.unwrap_or_default();
        let Some(dir) = path_from_location(&location) else {
            return fail(format!(
                "fmi2Instantiate: resource location '{location}' is not a file URI (the packaged {} is needed)",
                crate::PARAMS_RESOURCE
            ));
        };
        let raw = match load_resource_params(&dir) {
            Ok(r) => r,
            Err(e) => return fail(format!("fmi2Instantiate: {e}")),
        };
        let fmu = Box::new(Fmu {
            instance: Instance::new(&raw),
            name: cname,
            logger: callbacks,
            logging_on: logging_on != 0,
            broken: false,
            start_time: 0.0,
        });
        Box::into_raw(fmu) as Component
    });
    result.unwrap_or(std::ptr::null_mut())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    if !c.is_null() {
        // SAFETY: what fmi2Instantiate returned, freed once (the caller's
        // contract).
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Fmu) }));
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    // SAFETY: as `fmu`.
    match unsafe { fmu(c) } {
        Some(f) => {
            f.logging_on = on != 0;
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Component,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: c_int,
    _stop_time: f64,
) -> c_int {
    // SAFETY: as `fmu`.
    match unsafe { fmu(c) } {
        Some(f) => {
            f.start_time = start_time;
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> c_int {
    // SAFETY: as `fmu`.
    let start = match unsafe { fmu(c) } {
        Some(f) => f.start_time,
        None => return Status::Error as c_int,
    };
    // SAFETY: as `with`.
    unsafe { with(c, Status::Error, |i| i.enter_initialization(start)) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Component) -> c_int {
    // SAFETY: as `with`.
    let status = unsafe { with(c, Status::Error, Instance::exit_initialization) };
    // SAFETY: as `fmu`.
    if let Some(f) = unsafe { fmu(c) }
        && let Some(note) = f.initialised_note()
    {
        log_to(&f.logger, &f.name, Status::Ok, &note);
    }
    status
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: Component) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |i| {
            i.terminate();
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: Component) -> c_int {
    // SAFETY: as `fmu`.
    match unsafe { fmu(c) } {
        Some(f) => {
            f.instance.reset();
            f.broken = false;
            f.start_time = 0.0;
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(c: Component, vr: *const ValueReference, n: usize, value: *mut f64) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            let (vr, value) = (slice(vr, n)?, slice_mut(value, n)?);
            for (r, v) in vr.iter().zip(value) {
                *v = i.get_real(*r)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(c: Component, vr: *const ValueReference, n: usize, value: *mut c_int) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            let (vr, value) = (slice(vr, n)?, slice_mut(value, n)?);
            for (r, v) in vr.iter().zip(value) {
                *v = i.get_integer(*r)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(c: Component, vr: *const ValueReference, n: usize, value: *mut c_int) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            let (vr, value) = (slice(vr, n)?, slice_mut(value, n)?);
            for (r, v) in vr.iter().zip(value) {
                *v = i.get_boolean(*r)? as c_int;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _v: *mut *const c_char,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |_| match slice(vr, n)?.first() {
            Some(r) => Err(Failure::Refused(format!(
                "value reference {r}: this FMU has no String variable"
            ))),
            None => Ok(()),
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(c: Component, vr: *const ValueReference, n: usize, value: *const f64) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            for (r, v) in slice(vr, n)?.iter().zip(slice(value, n)?) {
                i.set_real(*r, *v)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(c: Component, vr: *const ValueReference, n: usize, _v: *const c_int) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |_| match slice(vr, n)?.first() {
            Some(r) => Err(Failure::Refused(format!("value reference {r}: not a settable Integer"))),
            None => Ok(()),
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    value: *const c_int,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            for (r, v) in slice(vr, n)?.iter().zip(slice(value, n)?) {
                i.set_boolean(*r, *v != 0)?;
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _v: *const *const c_char,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |_| match slice(vr, n)?.first() {
            Some(r) => Err(Failure::Refused(format!(
                "value reference {r}: this FMU has no String variable"
            ))),
            None => Ok(()),
        })
    }
}

/// A state as the importer holds it: the instance's serialisation.
type State = Vec<u8>;

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: Component, state: *mut *mut c_void) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |i| {
            let state = state
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi2GetFMUstate: null state pointer".into()))?;
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
pub unsafe extern "C" fn fmi2SetFMUstate(c: Component, state: *mut c_void) -> c_int {
    // SAFETY: as `fmu`.
    if let Some(f) = unsafe { fmu(c) } {
        f.broken = false;
    }
    // SAFETY: as `with`; `state` is one fmi2GetFMUstate made.
    unsafe {
        with(c, Status::Error, |i| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi2SetFMUstate: null state".into()))?;
            i.deserialize(s)
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(_c: Component, state: *mut *mut c_void) -> c_int {
    // SAFETY: a state fmi2GetFMUstate or fmi2DeSerializeFMUstate made,
    // freed once (the caller's contract); the pointer is then cleared.
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
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c: Component, state: *mut c_void, size: *mut usize) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |_| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi2SerializedFMUstateSize: null state".into()))?;
            *size
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi2SerializedFMUstateSize: null size".into()))? = s.len();
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: Component,
    state: *mut c_void,
    bytes: *mut c_char,
    size: usize,
) -> c_int {
    // SAFETY: as `with`, `slice_mut`.
    unsafe {
        with(c, Status::Error, |_| {
            let s = (state as *const State)
                .as_ref()
                .ok_or_else(|| Failure::Refused("fmi2SerializeFMUstate: null state".into()))?;
            if size < s.len() {
                return Err(Failure::Refused(format!(
                    "fmi2SerializeFMUstate: {size} bytes given, {} needed",
                    s.len()
                )));
            }
            let out = slice_mut(bytes as *mut u8, s.len())?;
            out.copy_from_slice(s);
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    bytes: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with(c, Status::Error, |i| {
            let given = slice(bytes as *const u8, size)?.to_vec();
            // Checked now, so that a state the instance cannot take is
            // refused here rather than at fmi2SetFMUstate.
            let mut probe = i.clone();
            probe.deserialize(&given)?;
            let state = state
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi2DeSerializeFMUstate: null state pointer".into()))?;
            match (*state as *mut State).as_mut() {
                Some(old) => *old = given,
                None => *state = Box::into_raw(Box::new(given)) as *mut c_void,
            }
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    _u: *const ValueReference,
    _nu: usize,
    _z: *const ValueReference,
    _nz: usize,
    _dv: *const f64,
    _dz: *mut f64,
) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Error, |_| Err(unsupported("fmi2GetDirectionalDerivative"))) }
}

fn unsupported(name: &str) -> Failure {
    Failure::Refused(format!("{name}: not supported by this FMU"))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _v: *const f64,
) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Error, |_| Err(unsupported("fmi2SetRealInputDerivatives"))) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _v: *mut f64,
) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Error, |_| Err(unsupported("fmi2GetRealOutputDerivatives"))) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(c: Component, time: f64, h: f64, _no_set_prior: c_int) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Discard, |i| i.do_step(time, h)) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: Component) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Error, |_| {
            Err(unsupported("fmi2CancelStep (steps are synchronous)"))
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, _kind: c_int, _value: *mut c_int) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Discard, |_| Err(unsupported("fmi2GetStatus"))) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Discard, |i| {
            if kind != LAST_SUCCESSFUL_TIME {
                return Err(unsupported("fmi2GetRealStatus of this kind"));
            }
            let t = i.get_real(crate::variables::VR_TIME)?;
            *value
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi2GetRealStatus: null value".into()))? = t;
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: Component, _kind: c_int, _value: *mut c_int) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Discard, |_| Err(unsupported("fmi2GetIntegerStatus"))) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with(c, Status::Discard, |_| {
            if kind != TERMINATED {
                return Err(unsupported("fmi2GetBooleanStatus of this kind"));
            }
            *value
                .as_mut()
                .ok_or_else(|| Failure::Refused("fmi2GetBooleanStatus: null value".into()))? = 0;
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(c: Component, _kind: c_int, _value: *mut *const c_char) -> c_int {
    // SAFETY: as `with`.
    unsafe { with(c, Status::Discard, |_| Err(unsupported("fmi2GetStringStatus"))) }
}
