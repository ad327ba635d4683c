//! `cargo xtask msrv`: the workspace's `rust-version` is the real minimum
//! of what it builds, at least the highest `rust-version` declared by any
//! locked dependency (host and firmware alike: `cargo metadata` lists every
//! platform's packages). Part of `cargo xtask test`, so that a dependency
//! bump that raises the minimum cannot leave the claim behind (`fixed` 1.31
//! needs 1.93 while the workspace claimed 1.85: Debian's 1.85 was taken and
//! failed).

use crate::process::capture;
use crate::toolchain::Version;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// A locked package: name, version, declared `rust-version`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Package {
    /// Crate name.
    pub name: String,
    /// Its locked version.
    pub version: String,
    /// Its `rust-version`, when declared.
    pub rust_version: Option<String>,
    /// A member of this workspace.
    pub workspace: bool,
}

/// The dependency that needs the newest compiler, with that compiler.
pub fn highest(packages: &[Package]) -> Option<(Version, &Package)> {
    packages
        .iter()
        .filter(|p| !p.workspace)
        .filter_map(|p| Some((Version::parse(p.rust_version.as_deref()?)?, p)))
        .max_by_key(|(v, _)| *v)
}

/// `Ok(summary)` when `declared` covers every dependency, else which one
/// needs more.
pub fn verdict(declared: Version, packages: &[Package]) -> Result<String, String> {
    match highest(packages) {
        Some((v, p)) if v > declared => Err(format!(
            "the workspace's rust-version {declared} is below what {} {} needs ({v}): raise \
             [workspace.package] rust-version in Cargo.toml",
            p.name, p.version
        )),
        Some((v, p)) => Ok(format!(
            "rust-version {declared} covers every locked dependency (highest: {} {} needs {v})",
            p.name, p.version
        )),
        None => Ok(format!("rust-version {declared}: no dependency declares one")),
    }
}

/// Reads the locked packages with `cargo metadata --locked`.
pub fn packages(root: &Path) -> Result<Vec<Package>, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = capture(
        Command::new(cargo)
            .args(["metadata", "--format-version", "1", "--locked"])
            .current_dir(root),
        Duration::from_secs(300),
    );
    if !out.ok() {
        return Err(format!("cargo metadata failed: {}", out.stderr.trim()));
    }
    let json: serde_json::Value = serde_json::from_str(&out.stdout).map_err(|e| format!("cargo metadata: {e}"))?;
    let members: Vec<&str> = json["workspace_members"]
        .as_array()
        .ok_or("cargo metadata: no workspace_members")?
        .iter()
        .filter_map(|m| m.as_str())
        .collect();
    let list = json["packages"].as_array().ok_or("cargo metadata: no packages")?;
    Ok(list
        .iter()
        .map(|p| Package {
            name: p["name"].as_str().unwrap_or_default().to_string(),
            version: p["version"].as_str().unwrap_or_default().to_string(),
            rust_version: p["rust_version"].as_str().map(str::to_string),
            workspace: p["id"].as_str().is_some_and(|id| members.contains(&id)),
        })
        .collect())
}

/// `cargo xtask msrv`.
pub fn check(root: &Path) -> Result<(), String> {
    let line = verdict(Version::minimum(), &packages(root)?)?;
    eprintln!("xtask: {line}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pkg(name: &str, rv: Option<&str>, workspace: bool) -> Package {
        Package {
            name: name.into(),
            version: "1.0.0".into(),
            rust_version: rv.map(str::to_string),
            workspace,
        }
    }

    #[test]
    fn the_declared_version_must_cover_the_highest_dependency() {
        let locked = [
            pkg("compensator", Some("1.85"), true),
            pkg("az", Some("1.85.0"), false),
            pkg("nalgebra", Some("1.89.0"), false),
            pkg("fixed", Some("1.93"), false),
            pkg("libm", None, false),
        ];
        // The reported claim: 1.85 against fixed's 1.93.
        let e = verdict(Version(1, 85, 0), &locked).unwrap_err();
        assert!(e.contains("fixed") && e.contains("1.93.0"), "{e}");
        assert!(verdict(Version(1, 93, 0), &locked).unwrap().contains("fixed"));
        assert!(verdict(Version(1, 95, 0), &locked).is_ok());
        // Workspace members do not count (their rust-version is the claim).
        let only_members = [pkg("compensator", Some("1.99"), true)];
        assert!(verdict(Version(1, 85, 0), &only_members).is_ok());
    }
}
