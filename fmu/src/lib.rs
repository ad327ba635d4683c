//! The compensator twin as a co-simulation FMU (FMI 2.0 and 3.0), for
//! software in the loop: Modelica tools, Simulink, Hopsan, Python.
//!
//! The shared library exports both the FMI 2.0 (`fmi2*`) and the FMI 3.0
//! (`fmi3*`) co-simulation functions; `cargo xtask fmu --fmi-version 2|3`
//! packages it with the model description of one version
//! ([`description::model_description`]) and the parameter file
//! (`resources/params.toml`, read at instantiation). `docs/fmu.md` is the
//! user's guide.
//!
//! * [`variables`]: the variables (flat scalars, units declared), the
//!   parameters taken from the parameter schema;
//! * [`instance`]: one instance in plain Rust (the FMI state machine, the
//!   twin, the state's serialisation), no statics: instances never share
//!   state;
//! * [`description`]: `modelDescription.xml` for either version;
//! * `shell`: the FMI shell both versions share (checked entry points,
//!   refusals logged through the importer's logger, FMU states) over a
//!   small per-version trait (names, logger, type names); `fmi2`, `fmi3`:
//!   the exported C functions, one call into the shell each, differing
//!   only where the standards do. No entry point unwinds into the importer
//!   (each runs under `catch_unwind` as a last guard; nothing in the
//!   instance panics by design);
//! * [`platforms`]: the platforms an archive can carry a binary for.
//!
//! The C interface is written here by hand against the standard's headers
//! (`fmi2Functions.h`, `fmi3Functions.h`): `fmi-export` exports FMI 3.0
//! only and generates its own model description from a derive macro (not
//! from the parameter schema), and `fmi-sys` generates import bindings
//! with bindgen at build time (libclang in CI) for loading FMUs, not for
//! exporting one.

pub mod description;
pub mod fmi2;
pub mod fmi3;
pub mod instance;
pub mod platforms;
mod shell;
pub mod variables;

use compensator::RawParams;
use instance::Failure;
use std::path::{Path, PathBuf};

/// The parameter file inside an FMU's `resources/` folder.
pub const PARAMS_RESOURCE: &str = "params.toml";

/// Status of a call, as both FMI versions number it (`OK`, `Warning`,
/// `Discard`, `Error`, `Fatal`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Status {
    Ok = 0,
    Discard = 2,
    Error = 3,
}

/// A path from a resource location: a `file:` URI (FMI 2.0:
/// `file:///tmp/x/resources`, `file:/tmp/x/resources`, on Windows
/// `file:///C:/x/resources`; percent-escapes decoded) or a plain path
/// (FMI 3.0's `resourcePath`).
pub fn path_from_location(location: &str) -> Option<PathBuf> {
    location_path(location, cfg!(windows))
}

/// [`path_from_location`] for a Windows host (`windows`: a URI's
/// `/C:/...` is the drive path `C:/...`) or another.
fn location_path(location: &str, windows: bool) -> Option<PathBuf> {
    let uri = location.starts_with("file:");
    let rest = match location.strip_prefix("file://") {
        Some(r) => r.strip_prefix("localhost").unwrap_or(r),
        None => location.strip_prefix("file:").unwrap_or(location),
    };
    if rest.is_empty() {
        return None;
    }
    let mut bytes = Vec::with_capacity(rest.len());
    let raw = rest.as_bytes();
    let mut i = 0;
    while i < raw.len() {
        if raw[i] == b'%' && i + 2 < raw.len() {
            let hex = std::str::from_utf8(&raw[i + 1..i + 3]).ok()?;
            bytes.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            bytes.push(raw[i]);
            i += 1;
        }
    }
    let path = String::from_utf8(bytes).ok()?;
    let drive = |p: &str| {
        let b = p.as_bytes();
        b.len() >= 3 && b[0] == b'/' && b[1].is_ascii_alphabetic() && b[2] == b':'
    };
    if windows && uri && drive(&path) {
        return Some(PathBuf::from(&path[1..]));
    }
    Some(PathBuf::from(path))
}

/// The packaged parameter file of the FMU whose resources are in `dir`.
///
/// # Errors
///
/// A file that cannot be read or that the validation refuses (the message
/// names the field).
pub fn load_resource_params(dir: &Path) -> Result<RawParams, String> {
    let path = dir.join(PARAMS_RESOURCE);
    compensator_params::file::load(&path).map_err(|e| format!("{}: {e}", path.display()))
}

/// The twin's configuration for a parameter file: the core's chooser at the
/// estimator's tick over the validated range (what `build.rs` ships and
/// `compensator step` runs).
///
/// # Errors
///
/// Parameters the model refuses, or a chooser failure, in one line.
pub fn chosen_config(raw: &RawParams) -> Result<compensator::dynamics::TwinConfig, String> {
    let p = compensator::Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let valid = (raw.estimator.valid_min, raw.estimator.valid_max);
    compensator::dynamics::config::choose(&p, 1.0 / raw.estimator.tick_hz, valid)
        .map(|c| c.config)
        .map_err(|e| format!("choosing the twin's substeps: {e}"))
}

/// Runs `f` and turns a panic (never expected: a last guard at the C
/// boundary) into a broken call.
pub(crate) fn guarded<T>(f: impl FnOnce() -> Result<T, Failure>) -> Result<T, Failure> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(_) => Err(Failure::Broken(
            "internal error (a panic was caught at the FMI boundary)".into(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_locations_become_paths() {
        assert_eq!(
            path_from_location("file:///tmp/a%20b/resources"),
            Some("/tmp/a b/resources".into())
        );
        assert_eq!(path_from_location("file:/tmp/x"), Some("/tmp/x".into()));
        assert_eq!(path_from_location("file://localhost/tmp/x"), Some("/tmp/x".into()));
        assert_eq!(path_from_location("/tmp/x/"), Some("/tmp/x/".into()));
        assert_eq!(path_from_location(""), None);
        assert_eq!(path_from_location("file:///tmp/%zz"), None);
        assert_eq!(
            location_path("file:///C:/Users/a%20b/resources", true),
            Some("C:/Users/a b/resources".into())
        );
        assert_eq!(location_path("file:///C:/x", false), Some("/C:/x".into()));
        assert_eq!(location_path("file:///tmp/x", true), Some("/tmp/x".into()));
        assert_eq!(location_path("Z:\\tmp\\x", true), Some("Z:\\tmp\\x".into()));
    }
}
