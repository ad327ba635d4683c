//! Placeholder, replaced below.
use std::path::{Path, PathBuf};
pub fn cmd(_root: &Path, _args: &[String]) -> Result<i32, String> {
    Ok(0)
}
pub fn check(
    _tc: &crate::toolchain::Toolchain,
    _root: &Path,
    _elfs: &[(crate::firmware::Image, PathBuf)],
) -> Result<(), String> {
    Ok(())
}
