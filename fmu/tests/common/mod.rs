//! An FMI 3.0 instance as the integration tests drive it (no logger): made
//! from a resources folder, its Float64s set and read, freed on drop.

#![allow(dead_code)] // each test crate uses part of it

use compensator_fmu::description::token;
use compensator_fmu::fmi3;
use std::ffi::{CString, c_void};
use std::path::Path;

/// A live FMI 3.0 instance.
pub struct Inst(pub *mut c_void);

/// `fmi3InstantiateCoSimulation` of the FMU whose resources folder is
/// `dir`, with `token`, the logger `log` and its environment `env`.
pub fn instantiate(dir: &Path, token: &str, env: *mut c_void, log: Option<fmi3::LogMessage>) -> *mut c_void {
    let token = CString::new(token).expect("token");
    let path = CString::new(dir.to_str().expect("utf-8")).expect("path");
    // SAFETY: valid strings; the caller keeps `env` alive for the instance.
    unsafe {
        fmi3::fmi3InstantiateCoSimulation(
            c"test".as_ptr(),
            token.as_ptr(),
            path.as_ptr(),
            false,
            false,
            false,
            false,
            std::ptr::null(),
            0,
            env,
            log,
            std::ptr::null(),
        )
    }
}

impl Inst {
    /// Instantiates the FMU whose resources folder is `dir` (no logger).
    pub fn new(dir: &Path) -> Inst {
        let i = Inst(instantiate(dir, &token(), std::ptr::null_mut(), None));
        assert!(!i.0.is_null(), "the FMU instantiates");
        i
    }

    /// Sets one Float64.
    pub fn set(&self, vr: u32, v: f64) {
        // SAFETY: a live instance, one value.
        assert_eq!(unsafe { fmi3::fmi3SetFloat64(self.0, &vr, 1, &v, 1) }, 0);
    }

    /// Reads one Float64.
    pub fn get(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: as `set`.
        assert_eq!(unsafe { fmi3::fmi3GetFloat64(self.0, &vr, 1, &mut v, 1) }, 0);
        v
    }

    /// Enters and exits initialization mode at t = 0.
    pub fn initialise(&self) {
        // SAFETY: a live instance.
        unsafe {
            assert_eq!(
                fmi3::fmi3EnterInitializationMode(self.0, false, 0.0, 0.0, false, 0.0),
                0
            );
            assert_eq!(fmi3::fmi3ExitInitializationMode(self.0), 0);
        }
    }

    /// One communication step of `h` from `t` [s].
    pub fn step(&self, t: f64, h: f64) {
        let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
        // SAFETY: a live instance, valid out-pointers.
        assert_eq!(
            unsafe { fmi3::fmi3DoStep(self.0, t, h, false, &mut a, &mut b, &mut c, &mut last) },
            0
        );
    }
}

impl Drop for Inst {
    fn drop(&mut self) {
        // SAFETY: freed once.
        unsafe { fmi3::fmi3FreeInstance(self.0) }
    }
}
