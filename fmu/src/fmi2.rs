//! The FMI 2.0 co-simulation interface (`fmi2Functions.h`): each function
//! one call into [`crate::shell`] with FMI 2.0's arguments. What is FMI
//! 2.0's own: the callback struct and its variadic logger (given the
//! instance name), `fmi2SetupExperiment`'s start time, `fmi2Boolean` as an
//! `int`, the status queries, the types' names (`Real`, `Integer`).

#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::Status;
use crate::instance::{Instance, Type};
use crate::shell::{self, Callbacks, Names, Version, text};
use std::ffi::{CStr, c_char, c_int, c_uint, c_void};

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

/// FMI 2.0 for the shell.
pub(crate) struct Fmi2;

impl Version for Fmi2 {
    type Logger = Logger;
    const NAMES: Names = shell::NAMES[0];
    const FORMAT_STRING: bool = true;

    unsafe fn emit(log: Logger, env: Env, instance: &CStr, status: Status, category: &CStr, text: &CStr) {
        // SAFETY: the importer's logger with valid C strings, the message
        // as the format string (what FMI 2.0 loggers expect, and what a
        // logger that does not expand arguments prints).
        unsafe {
            log(
                env,
                instance.as_ptr(),
                status as c_int,
                category.as_ptr(),
                text.as_ptr(),
            )
        }
    }
}

const CO_SIMULATION: c_int = 1;
const LAST_SUCCESSFUL_TIME: c_int = 2;
const TERMINATED: c_int = 3;

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
            log: f.logger,
            env: f.component_environment,
        },
        None => Callbacks {
            log: None,
            env: std::ptr::null_mut(),
        },
    };
    if fmu_type != CO_SIMULATION {
        return shell::refuse_instance::<Fmi2>(
            callbacks,
            "this FMU is for co-simulation only (fmuType fmi2CoSimulation)",
        );
    }
    // SAFETY: C strings from the importer.
    let (name, guid, location) = unsafe { (text(instance_name), text(guid), text(resource_location)) };
    shell::instantiate::<Fmi2>(callbacks, name, guid, location, logging_on != 0)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    // SAFETY: the caller's contract.
    unsafe { shell::free::<Fmi2>(c) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::set_debug_logging::<Fmi2>(c, on != 0) }
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
    // SAFETY: the caller's contract.
    unsafe { shell::set_start_time::<Fmi2>(c, start_time) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::enter_initialization::<Fmi2>(c, None) }
}

shell::instance_calls! { Fmi2: fmi2ExitInitializationMode => exit_initialization; fmi2Terminate => terminate; }
shell::instance_calls! { Fmi2: fmi2Reset => reset; }

shell::value_calls! { Fmi2, one:
    get fmi2GetReal(*mut f64) => Instance::get_real;
    get fmi2GetInteger(*mut c_int) => Instance::get_integer;
    get fmi2GetBoolean(*mut c_int) => |i: &mut Instance, r| i.get_boolean(r).map(c_int::from);
    none fmi2GetString(*mut *const c_char) => Type::String;
    set fmi2SetReal(*const f64) => Instance::set_real;
    none fmi2SetInteger(*const c_int) => Type::Integer;
    set fmi2SetBoolean(*const c_int) => |i: &mut Instance, r, v: c_int| i.set_boolean(r, v != 0);
    none fmi2SetString(*const *const c_char) => Type::String;
}

shell::state_calls! { Fmi2, c_char:
    fmi2GetFMUstate,
    fmi2SetFMUstate,
    fmi2FreeFMUstate,
    fmi2SerializedFMUstateSize,
    fmi2SerializeFMUstate,
    fmi2DeSerializeFMUstate
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
    // SAFETY: the caller's contract.
    unsafe { shell::unsupported::<Fmi2>(c, "fmi2GetDirectionalDerivative") }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _v: *const f64,
) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::unsupported::<Fmi2>(c, "fmi2SetRealInputDerivatives") }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _v: *mut f64,
) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::unsupported::<Fmi2>(c, "fmi2GetRealOutputDerivatives") }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(c: Component, time: f64, h: f64, _no_set_prior: c_int) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::do_step::<Fmi2>(c, time, h) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: Component) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::unsupported::<Fmi2>(c, "fmi2CancelStep (steps are synchronous)") }
}

/// The status queries: `fmi2LastSuccessfulTime` and `fmi2Terminated`
/// answered, the others refused (`Discard`, as the standard asks).
unsafe fn status<T>(
    c: Component,
    kind: c_int,
    value: *mut T,
    answer: impl FnOnce(&mut Instance, c_int) -> Option<T>,
) -> c_int {
    // SAFETY: the caller's contract.
    unsafe {
        shell::with::<Fmi2>(c, Status::Discard, |i| {
            let v = answer(i, kind).ok_or_else(|| {
                crate::instance::Failure::Refused(format!("fmi2Get*Status of kind {kind}: not supported by this FMU"))
            })?;
            *value
                .as_mut()
                .ok_or_else(|| crate::instance::Failure::Refused("fmi2Get*Status: a null value".into()))? = v;
            Ok(())
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { status(c, kind, value, |_, _| None) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> c_int {
    // SAFETY: the caller's contract.
    unsafe {
        status(c, kind, value, |i, k| {
            (k == LAST_SUCCESSFUL_TIME)
                .then(|| i.get_real(crate::variables::VR_TIME).ok())
                .flatten()
        })
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { status(c, kind, value, |_, _| None) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: Component, kind: c_int, value: *mut c_int) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { status(c, kind, value, |_, k| (k == TERMINATED).then_some(0)) }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(c: Component, kind: c_int, value: *mut *const c_char) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { status(c, kind, value, |_, _| None) }
}
