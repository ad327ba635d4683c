//! The FMI 3.0 co-simulation interface (`fmi3Functions.h`): each function
//! one call into [`crate::shell`] with FMI 3.0's arguments, as `fmi2`.
//! What is FMI 3.0's own: the log callback (no instance name), the start
//! time given to enter-initialization, step mode, `bool`, the value
//! counts beside the value references, `doStep`'s out-flags and last
//! successful time, the types' names (`Float64`, `Int32`). Model exchange,
//! scheduled execution, clocks, event mode and derivatives are not
//! provided: their functions exist (an importer may look them up) and
//! refuse with a logged message.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::Status;
use crate::instance::Instance;
use crate::shell::{self, Callbacks, Names, Version, text};
use std::ffi::{CStr, c_char, c_int, c_void};

type Inst = *mut c_void;
type Env = *mut c_void;
/// `fmi3LogMessageCallback`.
pub type LogMessage = unsafe extern "C" fn(Env, c_int, *const c_char, *const c_char);

/// FMI 3.0 for the shell.
pub(crate) struct Fmi3;

impl Version for Fmi3 {
    type Logger = LogMessage;
    const NAMES: Names = shell::NAMES[1];

    unsafe fn emit(log: LogMessage, env: Env, _instance: &CStr, status: Status, category: &CStr, text: &CStr) {
        // SAFETY: the importer's callback with valid C strings.
        unsafe { log(env, status as c_int, category.as_ptr(), text.as_ptr()) }
    }
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(c: Inst, on: bool, _n: usize, _categories: *const *const c_char) -> c_int {
    // SAFETY: the caller's contract.
    unsafe { shell::set_debug_logging::<Fmi3>(c, on) }
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
    if event_mode_used {
        return shell::refuse_instance::<Fmi3>(callbacks, "this FMU has no event mode (hasEventMode false)");
    }
    // SAFETY: C strings from the importer.
    let (name, token, path) = unsafe { (text(instance_name), text(instantiation_token), text(resource_path)) };
    shell::instantiate::<Fmi3>(callbacks, name, token, path, logging_on)
}

/// Exports the instantiations of the interface types this FMU does not
/// have (their arguments after the six all share): each refuses, logged.
macro_rules! co_simulation_only {
    ($($name:ident($($arg:ident: $t:ty),*);)*) => {$(
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(
            _name: *const c_char,
            _token: *const c_char,
            _resource_path: *const c_char,
            _visible: bool,
            _logging_on: bool,
            instance_environment: Env,
            log_message: Option<LogMessage>,
            $($arg: $t),*
        ) -> Inst {
            let callbacks = Callbacks { log: log_message, env: instance_environment };
            shell::refuse_instance::<Fmi3>(callbacks, "this FMU is for co-simulation only")
        }
    )*};
}

co_simulation_only! {
    fmi3InstantiateModelExchange();
    fmi3InstantiateScheduledExecution(_clock_update: *const c_void, _lock: *const c_void, _unlock: *const c_void);
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(c: Inst) {
    // SAFETY: the caller's contract.
    unsafe { shell::free::<Fmi3>(c) }
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
    // SAFETY: the caller's contract.
    unsafe { shell::enter_initialization::<Fmi3>(c, Some(start_time)) }
}

shell::instance_calls! { Fmi3: fmi3ExitInitializationMode => exit_initialization; fmi3EnterStepMode => enter_step_mode; }
shell::instance_calls! { Fmi3: fmi3Terminate => terminate; fmi3Reset => reset; }

shell::value_calls! { Fmi3, two:
    get fmi3GetFloat64(*mut f64) => Instance::get_real;
    get fmi3GetInt32(*mut i32) => Instance::get_integer;
    get fmi3GetBoolean(*mut bool) => |i: &mut Instance, r| i.get_boolean(r);
    set fmi3SetFloat64(*const f64) => Instance::set_real;
    set fmi3SetBoolean(*const bool) => Instance::set_boolean;
}

shell::state_calls! { Fmi3, u8:
    fmi3GetFMUState,
    fmi3SetFMUState,
    fmi3FreeFMUState,
    fmi3SerializedFMUStateSize,
    fmi3SerializeFMUState,
    fmi3DeserializeFMUState
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
    // SAFETY: the caller's contract; the out-pointers are the importer's
    // (or null).
    unsafe {
        let status = shell::do_step::<Fmi3>(c, time, h);
        for flag in [event_handling_needed, terminate_simulation, early_return] {
            if let Some(f) = flag.as_mut() {
                *f = false;
            }
        }
        if let Some(t) = last_successful_time.as_mut() {
            *t = shell::time::<Fmi3>(c, time);
        }
        status
    }
}

// Functions of FMI 3.0 this FMU does not provide: each refuses with a
// logged message (`fmi3Error`).
shell::unsupported_calls! { Fmi3:
    fmi3EnterEventMode();
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3EnterContinuousTimeMode();
    fmi3EvaluateDiscreteStates();
    fmi3UpdateDiscreteStates(*mut bool, *mut bool, *mut bool, *mut bool, *mut bool, *mut f64);
    fmi3SetInt32(*const u32, usize, *const i32, usize);
    fmi3GetString(*const u32, usize, *mut *const c_char, usize);
    fmi3GetBinary(*const u32, usize, *mut usize, *mut *const u8, usize);
    fmi3GetClock(*const u32, usize, *mut bool);
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

// The getters and setters of the types this FMU has no variable of.
shell::unsupported_calls! { Fmi3, values:
    fmi3GetFloat32, fmi3SetFloat32(f32);
    fmi3GetInt8, fmi3SetInt8(i8);
    fmi3GetUInt8, fmi3SetUInt8(u8);
    fmi3GetInt16, fmi3SetInt16(i16);
    fmi3GetUInt16, fmi3SetUInt16(u16);
    fmi3GetUInt32, fmi3SetUInt32(u32);
    fmi3GetInt64, fmi3SetInt64(i64);
    fmi3GetUInt64, fmi3SetUInt64(u64);
}
