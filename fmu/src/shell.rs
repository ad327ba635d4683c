//! The FMI shell both C interfaces share: what an instance keeps besides
//! the [`Instance`], the checked entry points (null pointers, array
//! lengths, an instance broken by an earlier call, a panic caught at the
//! boundary, every refusal logged) and the FMU states, written once over a
//! small per-version trait, [`Version`]: the names of its calls and types,
//! its logger. `fmi2` and `fmi3` are the exported functions with their
//! standards' signatures, each one call into this module, and differ only
//! where the standards do (arguments, callbacks, what a version has that
//! the other has not).

use crate::description::{MODEL_IDENTIFIER, token};
use crate::instance::{Failure, Instance, Phase, Type};
use crate::{PARAMS_RESOURCE, Status, guarded, load_resource_params, path_from_location};
use std::ffi::{CStr, CString, c_char, c_int, c_void};

/// The names an FMI version gives its calls and types: its functions'
/// prefix, its spelling of an FMU state, its instantiation function, its
/// model description's fingerprint, its names of [`Type::Float`] and
/// [`Type::Integer`] (`Boolean` and `String` are both versions').
#[derive(Clone, Copy, Debug)]
pub(crate) struct Names {
    prefix: &'static str,
    state: &'static str,
    instantiate: &'static str,
    token: &'static str,
    numbers: [&'static str; 2],
}

impl Names {
    const fn new(
        prefix: &'static str,
        state: &'static str,
        instantiate: &'static str,
        token: &'static str,
        numbers: [&'static str; 2],
    ) -> Names {
        Names {
            prefix,
            state,
            instantiate,
            token,
            numbers,
        }
    }

    fn type_name(&self, t: Type) -> &'static str {
        match t {
            Type::Float => self.numbers[0],
            Type::Integer => self.numbers[1],
            Type::Boolean => "Boolean",
            Type::String => "String",
        }
    }
}

/// FMI 2.0's names ([`NAMES`]`[0]`) and FMI 3.0's (`[1]`).
pub(crate) const NAMES: [Names; 2] = [
    Names::new("fmi2", "FMUstate", "fmi2Instantiate", "GUID", ["Real", "Integer"]),
    Names::new(
        "fmi3",
        "FMUState",
        "fmi3InstantiateCoSimulation",
        "instantiation token",
        ["Float64", "Int32"],
    ),
];

/// What differs between the FMI versions at the C boundary besides the
/// functions' signatures: the names, and the logger's C signature.
pub(crate) trait Version {
    /// The importer's logging callback.
    type Logger: Copy;
    /// The version's names.
    const NAMES: Names;
    /// The logger takes the message as a format string (FMI 2.0): `%` is
    /// doubled.
    const FORMAT_STRING: bool = false;
    /// Calls the logger with a message (category `logStatusOk` for `Ok`,
    /// else `logStatusError`).
    ///
    /// # Safety
    ///
    /// `log` is the importer's callback for `env`.
    unsafe fn emit(log: Self::Logger, env: *mut c_void, instance: &CStr, status: Status, category: &CStr, text: &CStr);
}

/// What an instance keeps of the importer's callbacks: its logger and the
/// environment the logger gets back.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks<L> {
    pub(crate) log: Option<L>,
    pub(crate) env: *mut c_void,
}

/// Logs `message` through the importer's callback, if it gave one.
fn log<V: Version>(cb: &Callbacks<V::Logger>, instance: &CStr, status: Status, message: &str) {
    let Some(log) = cb.log else { return };
    let text = c_string(&if V::FORMAT_STRING {
        message.replace('%', "%%")
    } else {
        message.to_string()
    });
    let category = match status {
        Status::Ok => c"logStatusOk",
        _ => c"logStatusError",
    };
    // SAFETY: the importer's logger with valid C strings.
    unsafe { V::emit(log, cb.env, instance, status, category, &text) }
}

/// What both C interfaces keep per instance besides the [`Instance`].
pub(crate) struct Shell<V: Version> {
    pub(crate) instance: Instance,
    pub(crate) name: CString,
    pub(crate) callbacks: Callbacks<V::Logger>,
    pub(crate) logging_on: bool,
    /// An earlier call broke the instance: only reset, a state or free.
    pub(crate) broken: bool,
    /// Start time from `fmi2SetupExperiment` [s] (FMI 3.0 passes it to
    /// enter-initialization directly).
    pub(crate) start_time: f64,
}

impl<V: Version> Shell<V> {
    fn log(&self, status: Status, message: &str) {
        log::<V>(&self.callbacks, &self.name, status, message);
    }

    /// What a log with debug logging on says after initialisation.
    fn initialised_note(&self) -> Option<String> {
        if !self.logging_on {
            return None;
        }
        let c = self.instance.twin_config()?;
        Some(format!(
            "initialised: the twin runs {}, {} substep(s) per {} s tick (the core's chooser for these parameters)",
            c.scheme.name(),
            c.substeps,
            c.tick
        ))
    }
}

/// `s` as a C string (a NUL replaced by a space).
pub(crate) fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

unsafe fn shell<'a, V: Version>(c: *mut c_void) -> Option<&'a mut Shell<V>> {
    // SAFETY: `c` is null or what `instantiate` returned (the caller's
    // contract).
    unsafe { (c as *mut Shell<V>).as_mut() }
}

/// Runs `f` on the instance behind `c`; logs a refusal and maps it to a
/// status (`refused` for a refused call: Error, or Discard for a step).
///
/// # Safety
///
/// `c` is null or a live instance of version `V`.
pub(crate) unsafe fn with<V: Version>(
    c: *mut c_void,
    refused: Status,
    f: impl FnOnce(&mut Instance) -> Result<(), Failure>,
) -> c_int {
    // SAFETY: as `shell`.
    let Some(fmu) = (unsafe { shell::<V>(c) }) else {
        return Status::Error as c_int;
    };
    if fmu.broken {
        let Names { prefix: p, state, .. } = V::NAMES;
        fmu.log(
            Status::Error,
            &format!("the instance failed earlier: only {p}Reset, {p}Set{state} or {p}FreeInstance"),
        );
        return Status::Error as c_int;
    }
    match guarded(|| f(&mut fmu.instance)) {
        Ok(()) => Status::Ok as c_int,
        Err(e) => {
            let status = match e {
                Failure::Broken(_) => {
                    fmu.broken = true;
                    Status::Error
                }
                _ => refused,
            };
            fmu.log(status, &e.message(|t| V::NAMES.type_name(t)));
            status as c_int
        }
    }
}

/// Runs `f` on the shell behind `c` (calls a broken instance still takes).
///
/// # Safety
///
/// As [`with`].
unsafe fn on_shell<V: Version>(c: *mut c_void, f: impl FnOnce(&mut Shell<V>)) -> c_int {
    // SAFETY: as `shell`.
    match unsafe { shell::<V>(c) } {
        Some(s) => {
            f(s);
            Status::Ok as c_int
        }
        None => Status::Error as c_int,
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

/// A C string from the importer, or `None` for a null pointer.
///
/// # Safety
///
/// `p` is null or a NUL-terminated string.
pub(crate) unsafe fn text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: a NUL-terminated string (the caller's contract).
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
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

/// A new instance, or null with the reason logged: the model description's
/// fingerprint checked, the packaged parameters read from `location`.
pub(crate) fn instantiate<V: Version>(
    callbacks: Callbacks<V::Logger>,
    name: Option<String>,
    given_token: Option<String>,
    location: Option<String>,
    logging_on: bool,
) -> *mut c_void {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let name = c_string(&name.unwrap_or_else(|| MODEL_IDENTIFIER.into()));
        let fail = |m: String| {
            log::<V>(
                &callbacks,
                &name,
                Status::Error,
                &format!("{}: {m}", V::NAMES.instantiate),
            );
            std::ptr::null_mut()
        };
        let given = given_token.unwrap_or_default();
        if given != token() {
            return fail(format!(
                "{} {given} is not this binary's {} (a model description of another build)",
                V::NAMES.token,
                token()
            ));
        }
        let location = location.unwrap_or_default();
        let Some(dir) = path_from_location(&location) else {
            return fail(format!(
                "resource location '{location}' is not a path or a file URI (the packaged {PARAMS_RESOURCE} is needed)"
            ));
        };
        let raw = match load_resource_params(&dir) {
            Ok(r) => r,
            Err(e) => return fail(e),
        };
        let fmu = Box::new(Shell::<V> {
            instance: Instance::new(&raw),
            name,
            callbacks,
            logging_on,
            broken: false,
            start_time: 0.0,
        });
        Box::into_raw(fmu) as *mut c_void
    }));
    result.unwrap_or(std::ptr::null_mut())
}

/// Logs `message` for an instance that is not made (a refused
/// instantiation).
pub(crate) fn refuse_instance<V: Version>(callbacks: Callbacks<V::Logger>, message: &str) -> *mut c_void {
    let text = format!("{}: {message}", V::NAMES.instantiate);
    log::<V>(&callbacks, c"", Status::Error, &text);
    std::ptr::null_mut()
}

/// Frees an instance.
///
/// # Safety
///
/// `c` is null or a live instance of version `V`, freed once.
pub(crate) unsafe fn free<V: Version>(c: *mut c_void) {
    if !c.is_null() {
        // SAFETY: what `instantiate` returned, freed once (the caller's
        // contract).
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Shell<V>) }));
    }
}

/// Sets debug logging.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn set_debug_logging<V: Version>(c: *mut c_void, on: bool) -> c_int {
    // SAFETY: as `on_shell`.
    unsafe { on_shell::<V>(c, |s| s.logging_on = on) }
}

/// Keeps the start time for the next enter-initialization (FMI 2.0's setup).
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn set_start_time<V: Version>(c: *mut c_void, start_time: f64) -> c_int {
    // SAFETY: as `on_shell`.
    unsafe { on_shell::<V>(c, |s| s.start_time = start_time) }
}

/// Enters initialization mode at `start_time` (`None`: the one kept by
/// [`set_start_time`]).
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn enter_initialization<V: Version>(c: *mut c_void, start_time: Option<f64>) -> c_int {
    // SAFETY: as `shell`.
    let Some(start) = start_time.or_else(|| unsafe { shell::<V>(c) }.map(|s| s.start_time)) else {
        return Status::Error as c_int;
    };
    // SAFETY: as `with`.
    unsafe { with::<V>(c, Status::Error, |i| i.enter_initialization(start)) }
}

/// Leaves initialization mode; with debug logging on, logs the twin's
/// configuration.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn exit_initialization<V: Version>(c: *mut c_void) -> c_int {
    // SAFETY: as `with`.
    let status = unsafe { with::<V>(c, Status::Error, Instance::exit_initialization) };
    // SAFETY: as `shell`.
    if let Some(f) = unsafe { shell::<V>(c) }
        && let Some(note) = f.initialised_note()
    {
        f.log(Status::Ok, &note);
    }
    status
}

/// Enters step mode (FMI 3.0; FMI 2.0 is in it after initialisation).
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn enter_step_mode<V: Version>(c: *mut c_void) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with::<V>(c, Status::Error, |i| {
            if i.phase() == Phase::Step {
                Ok(())
            } else {
                Err(Failure::Refused(format!(
                    "{}EnterStepMode: not initialised",
                    V::NAMES.prefix
                )))
            }
        })
    }
}

/// Terminates.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn terminate<V: Version>(c: *mut c_void) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with::<V>(c, Status::Error, |i| {
            i.terminate();
            Ok(())
        })
    }
}

/// Back to the packaged values (also after an instance broke).
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn reset<V: Version>(c: *mut c_void) -> c_int {
    // SAFETY: as `on_shell`.
    unsafe {
        on_shell::<V>(c, |s| {
            s.instance.reset();
            s.broken = false;
            s.start_time = 0.0;
        })
    }
}

/// Reads `nvr` values through `get` into `values` (`nvalues` of them).
///
/// # Safety
///
/// As [`with`]; `vr` and `values` hold `nvr` and `nvalues` elements.
pub(crate) unsafe fn get<V: Version, T>(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *mut T,
    nvalues: usize,
    get: impl Fn(&mut Instance, u32) -> Result<T, Failure>,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with::<V>(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            let (vr, values) = (slice(vr, nvr)?, slice_mut(values, nvalues)?);
            for (r, v) in vr.iter().zip(values) {
                *v = get(i, *r)?;
            }
            Ok(())
        })
    }
}

/// Writes `nvr` values from `values` through `set`.
///
/// # Safety
///
/// As [`get`].
pub(crate) unsafe fn set<V: Version, T: Copy>(
    c: *mut c_void,
    vr: *const u32,
    nvr: usize,
    values: *const T,
    nvalues: usize,
    set: impl Fn(&mut Instance, u32, T) -> Result<(), Failure>,
) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with::<V>(c, Status::Error, |i| {
            scalars(nvr, nvalues)?;
            for (r, v) in slice(vr, nvr)?.iter().zip(slice(values, nvalues)?) {
                set(i, *r, *v)?;
            }
            Ok(())
        })
    }
}

/// A get or set of a type this FMU has no variable of (or none settable):
/// refused naming the first value reference.
///
/// # Safety
///
/// As [`with`]; `vr` holds `n` elements.
pub(crate) unsafe fn no_variable<V: Version>(c: *mut c_void, vr: *const u32, n: usize, ty: Type) -> c_int {
    // SAFETY: as `with`, `slice`.
    unsafe {
        with::<V>(c, Status::Error, |_| match slice(vr, n)?.first() {
            Some(&vr) => Err(Failure::NotOfType { vr, ty, settable: true }),
            None => Ok(()),
        })
    }
}

/// A communication step; `Discard` (nothing done) when refused.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn do_step<V: Version>(c: *mut c_void, time: f64, h: f64) -> c_int {
    // SAFETY: as `with`.
    unsafe { with::<V>(c, Status::Discard, |i| i.do_step(time, h)) }
}

/// The instance's time [s] (its last successful communication point), or
/// `fallback` before it has one.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn time<V: Version>(c: *mut c_void, fallback: f64) -> f64 {
    // SAFETY: as `shell`.
    unsafe { shell::<V>(c) }
        .and_then(|s| s.instance.get_real(crate::variables::VR_TIME).ok())
        .unwrap_or(fallback)
}

/// A function this FMU does not provide: refused, logged.
///
/// # Safety
///
/// As [`with`].
pub(crate) unsafe fn unsupported<V: Version>(c: *mut c_void, name: &str) -> c_int {
    // SAFETY: as `with`.
    unsafe {
        with::<V>(c, Status::Error, |_| {
            Err(Failure::Refused(format!("{name}: not supported by this FMU")))
        })
    }
}

/// A state as the importer holds it: the instance's serialisation.
type State = Vec<u8>;

/// Writes `value` through an out-pointer, refusing a null one.
///
/// # Safety
///
/// `p` is null or valid for a write.
unsafe fn out<T>(p: *mut T, value: T, what: &str) -> Result<(), Failure> {
    // SAFETY: as stated.
    let slot = unsafe { p.as_mut() }.ok_or_else(|| Failure::Refused(format!("{what}: a null pointer")))?;
    *slot = value;
    Ok(())
}

/// The state behind an importer's handle.
///
/// # Safety
///
/// `state` is null or a state this module made.
unsafe fn state_of<'a>(state: *mut c_void, what: &str) -> Result<&'a State, Failure> {
    // SAFETY: as stated.
    unsafe { (state as *const State).as_ref() }.ok_or_else(|| Failure::Refused(format!("{what}: a null state")))
}

/// Stores `bytes` in the importer's handle `*state` (reusing a state it
/// passes, else a new one).
///
/// # Safety
///
/// `state` is null or valid for reads and writes; `*state` null or a state
/// this module made.
unsafe fn keep(state: *mut *mut c_void, bytes: State, what: &str) -> Result<(), Failure> {
    // SAFETY: as stated.
    unsafe {
        let state = state
            .as_mut()
            .ok_or_else(|| Failure::Refused(format!("{what}: a null state pointer")))?;
        match (*state as *mut State).as_mut() {
            Some(old) => *old = bytes,
            None => *state = Box::into_raw(Box::new(bytes)) as *mut c_void,
        }
    }
    Ok(())
}

/// Saves the instance's state in `*state`.
///
/// # Safety
///
/// As [`with`] and [`keep`].
pub(crate) unsafe fn get_state<V: Version>(c: *mut c_void, state: *mut *mut c_void, what: &str) -> c_int {
    // SAFETY: as stated.
    unsafe { with::<V>(c, Status::Error, |i| keep(state, i.serialize(), what)) }
}

/// Restores a state (also on an instance that broke).
///
/// # Safety
///
/// As [`with`]; `state` null or a state this module made.
pub(crate) unsafe fn set_state<V: Version>(c: *mut c_void, state: *mut c_void, what: &str) -> c_int {
    // SAFETY: as `shell`.
    if let Some(f) = unsafe { shell::<V>(c) } {
        f.broken = false;
    }
    // SAFETY: as stated.
    unsafe { with::<V>(c, Status::Error, |i| i.deserialize(state_of(state, what)?)) }
}

/// Frees a state and clears the importer's handle.
///
/// # Safety
///
/// `state` is null or valid; `*state` null or a state this module made,
/// freed once.
pub(crate) unsafe fn free_state(state: *mut *mut c_void) -> c_int {
    // SAFETY: as stated.
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

/// The size of a state's serialisation.
///
/// # Safety
///
/// As [`set_state`]; `size` null or valid for a write.
pub(crate) unsafe fn serialized_size<V: Version>(
    c: *mut c_void,
    state: *mut c_void,
    size: *mut usize,
    what: &str,
) -> c_int {
    // SAFETY: as stated.
    unsafe { with::<V>(c, Status::Error, |_| out(size, state_of(state, what)?.len(), what)) }
}

/// Writes a state's serialisation into `bytes` (`size` of them).
///
/// # Safety
///
/// As [`set_state`]; `bytes` holds `size` writable bytes.
pub(crate) unsafe fn serialize<V: Version>(
    c: *mut c_void,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
    what: &str,
) -> c_int {
    // SAFETY: as stated.
    unsafe {
        with::<V>(c, Status::Error, |_| {
            let s = state_of(state, what)?;
            if size < s.len() {
                return Err(Failure::Refused(format!(
                    "{what}: {size} bytes given, {} needed",
                    s.len()
                )));
            }
            slice_mut(bytes, s.len())?.copy_from_slice(s);
            Ok(())
        })
    }
}

/// A state from its serialisation, checked now (so that a state the
/// instance cannot take is refused here rather than when it is set).
///
/// # Safety
///
/// As [`keep`]; `bytes` holds `size` bytes.
pub(crate) unsafe fn deserialize<V: Version>(
    c: *mut c_void,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
    what: &str,
) -> c_int {
    // SAFETY: as stated.
    unsafe {
        with::<V>(c, Status::Error, |i| {
            let given = slice(bytes, size)?.to_vec();
            i.clone().deserialize(&given)?;
            keep(state, given, what)
        })
    }
}

/// Exports the calls that take the instance alone: `$name(c) -> status`,
/// each calling `shell::$call::<$version>(c)`.
macro_rules! instance_calls {
    ($version:ty: $($name:ident => $call:ident;)*) => {$(
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut std::ffi::c_void) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::$call::<$version>(c) }
        }
    )*};
}

/// Exports the getters and setters of one version's value types: FMI 2.0
/// passes one count (`n` references, `n` values), FMI 3.0 two; each calls
/// [`get`] or [`set`] (`$call`) with the instance's accessor, or, for a
/// type the FMU has no variable of, [`no_variable`] (`none`).
macro_rules! value_calls {
    ($version:ty, $counts:tt: $($call:ident $name:ident($t:ty) => $f:expr;)*) => {$(
        $crate::shell::value_calls!(@one $version, $counts, $call, $name, $t, $f);
    )*};
    (@one $version:ty, one, none, $name:ident, $t:ty, $f:expr) => {
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut std::ffi::c_void, vr: *const u32, n: usize, _values: $t) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::no_variable::<$version>(c, vr, n, $f) }
        }
    };
    (@one $version:ty, one, $call:ident, $name:ident, $t:ty, $f:expr) => {
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut std::ffi::c_void, vr: *const u32, n: usize, values: $t) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::$call::<$version, _>(c, vr, n, values, n, $f) }
        }
    };
    (@one $version:ty, two, $call:ident, $name:ident, $t:ty, $f:expr) => {
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(
            c: *mut std::ffi::c_void,
            vr: *const u32,
            nvr: usize,
            values: $t,
            nvalues: usize,
        ) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::$call::<$version, _>(c, vr, nvr, values, nvalues, $f) }
        }
    };
}

/// Exports the functions of one version this FMU does not provide: each
/// refuses with a logged message (`Error`).
macro_rules! unsupported_calls {
    ($version:ty: $($name:ident($($t:ty),*);)*) => {$(
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut std::ffi::c_void $(, _: $t)*) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::unsupported::<$version>(c, stringify!($name)) }
        }
    )*};
    ($version:ty, values: $($get:ident, $set:ident($t:ty);)*) => {$(
        $crate::shell::unsupported_calls! { $version:
            $get(*const u32, usize, *mut $t, usize);
            $set(*const u32, usize, *const $t, usize);
        }
    )*};
}

/// Exports one version's FMU-state functions under its names (`$byte`:
/// its type of a serialised byte).
macro_rules! state_calls {
    ($version:ty, $byte:ty: $get:ident, $set:ident, $free:ident, $size:ident, $serialize:ident, $deserialize:ident) => {
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(c: *mut std::ffi::c_void, state: *mut *mut std::ffi::c_void) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::get_state::<$version>(c, state, stringify!($get)) }
        }

        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(c: *mut std::ffi::c_void, state: *mut std::ffi::c_void) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::set_state::<$version>(c, state, stringify!($set)) }
        }

        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $free(
            _c: *mut std::ffi::c_void,
            state: *mut *mut std::ffi::c_void,
        ) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::free_state(state) }
        }

        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $size(
            c: *mut std::ffi::c_void,
            state: *mut std::ffi::c_void,
            size: *mut usize,
        ) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::serialized_size::<$version>(c, state, size, stringify!($size)) }
        }

        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $serialize(
            c: *mut std::ffi::c_void,
            state: *mut std::ffi::c_void,
            bytes: *mut $byte,
            size: usize,
        ) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe { $crate::shell::serialize::<$version>(c, state, bytes as *mut u8, size, stringify!($serialize)) }
        }

        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $deserialize(
            c: *mut std::ffi::c_void,
            bytes: *const $byte,
            size: usize,
            state: *mut *mut std::ffi::c_void,
        ) -> std::ffi::c_int {
            // SAFETY: the caller's contract.
            unsafe {
                $crate::shell::deserialize::<$version>(c, bytes as *const u8, size, state, stringify!($deserialize))
            }
        }
    };
}

pub(crate) use {instance_calls, state_calls, unsupported_calls, value_calls};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_version_names_the_types_its_own_way() {
        let cases = [
            (
                Type::Float,
                false,
                ["value reference 10: not a Real", "value reference 10: not a Float64"],
            ),
            (
                Type::Integer,
                false,
                ["value reference 10: not an Integer", "value reference 10: not an Int32"],
            ),
            (Type::Boolean, true, ["value reference 10: not a settable Boolean"; 2]),
            (Type::String, true, ["this FMU has no String variable"; 2]),
        ];
        for (ty, settable, want) in cases {
            let failure = Failure::NotOfType { vr: 10, ty, settable };
            for (names, want) in NAMES.iter().zip(want) {
                assert_eq!(failure.message(|t| names.type_name(t)), want);
            }
        }
    }
}
