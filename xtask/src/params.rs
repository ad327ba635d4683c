//! The parameter file of a firmware build: `--params FILE` or
//! `COMPENSATOR_PARAMS`, resolved against the directory the command was run
//! in (as the CLI resolves `--params`) and checked before any build, so
//! that a refused file costs one line naming the field (exit 2), like the
//! CLI, and not a build.

use std::path::{Path, PathBuf};

/// The parameter file to build with: `flag` (`--params`), else the
/// environment's `COMPENSATOR_PARAMS`, else `None` (the default preset).
/// Relative paths are taken from `cwd`. `Err` is the one-line input error.
pub fn resolve(flag: Option<&str>, env: Option<&str>, cwd: &Path) -> Result<Option<PathBuf>, String> {
    let (given, origin) = match (flag, env) {
        (Some(f), _) => (f, "--params"),
        (None, Some(e)) if !e.is_empty() => (e, "COMPENSATOR_PARAMS"),
        _ => return Ok(None),
    };
    let path = cwd.join(given);
    let path = std::fs::canonicalize(&path).map_err(|e| format!("{origin} {given}: {} ({e})", path.display()))?;
    compensator_params::file::load(&path).map_err(|e| format!("parameter file {}: {e}", path.display()))?;
    Ok(Some(path))
}

/// [`resolve`] with the process's directory and environment.
pub fn from_args(flag: Option<&str>) -> Result<Option<PathBuf>, String> {
    let cwd = std::env::current_dir().map_err(|e| format!("the current directory: {e}"))?;
    let env = std::env::var("COMPENSATOR_PARAMS").ok();
    resolve(flag, env.as_deref(), &cwd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_are_taken_from_the_users_directory_and_checked() {
        let root = crate::root();
        // From the presets directory, as a user standing there would type it.
        let presets = root.join("presets");
        let p = resolve(Some("paper.toml"), None, &presets).unwrap().unwrap();
        assert_eq!(p, root.join("presets/paper.toml").canonicalize().unwrap());
        // The environment's COMPENSATOR_PARAMS the same way; --params wins.
        let p = resolve(None, Some("presets/paper.toml"), &root).unwrap().unwrap();
        assert!(p.ends_with("presets/paper.toml"));
        let p = resolve(Some("model-example.toml"), Some("nope.toml"), &presets)
            .unwrap()
            .unwrap();
        assert!(p.ends_with("presets/model-example.toml"));
        assert_eq!(resolve(None, None, &root).unwrap(), None);
        // Not there: says which name and where it was looked for.
        let e = resolve(None, Some("paper.toml"), &root).unwrap_err();
        assert!(
            e.starts_with("COMPENSATOR_PARAMS paper.toml:") && e.contains(&root.display().to_string()),
            "{e}"
        );
        // Refused: one line naming the field.
        let dir = std::env::temp_dir().join(format!("xtask-params-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = std::fs::read_to_string(root.join("presets/paper.toml")).unwrap();
        std::fs::write(dir.join("pt1000.toml"), format!("{text}\n[estimator]\nrtd_r0 = 1000\n")).unwrap();
        let e = resolve(Some("pt1000.toml"), None, &dir).unwrap_err();
        assert!(e.contains("estimator.rtd_reference = 430: must exceed"), "{e}");
        assert_eq!(e.lines().count(), 1);
    }
}
