//! The cross toolchain for the Cortex-M targets, chosen fast, without
//! hanging, and never older than the workspace's `rust-version` (the
//! highest `rust-version` of the locked dependencies; [`MINIMUM`]):
//!
//! 1. rustup's own targets, when `rustup target list --installed` (10 s
//!    deadline) lists every target needed;
//! 2. else `rustup target add` of the missing targets (the ecosystem's
//!    standard route, also what `rust-toolchain.toml` asks for), with a
//!    [`RUSTUP_ADD_DEADLINE`]: a machine without access to rustup's
//!    servers fails or times out there and goes on to
//! 3. Debian's `rustc-web` (with its standard library sources) unpacked
//!    under `target/cross-toolchain/` by an earlier run, used with
//!    `RUSTC_BOOTSTRAP=1 -Z build-std=core` and rustup's `rust-lld`, when
//!    its version is at least [`MINIMUM`] (an older one is removed);
//! 4. else that toolchain is provisioned: `apt-get download` of the
//!    packages (names read from `apt-cache`), unpacked with `dpkg -x`.
//!    Nothing is installed system-wide (`rustc-web` conflicts with rustup).
//!    A candidate older than [`MINIMUM`] (package lists months old) makes
//!    xtask refresh the lists (`apt-get update`, as root) and look again;
//!    still too old, or not root, it stops and says what to run.
//!
//! The decisions ([`choose_debian`], [`cached_is_usable`]) take apt's
//! answers through the [`Apt`] trait, so that they are unit-tested with
//! fake `apt-cache` output.

use crate::process::{capture, is_root};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The oldest compiler the workspace builds with: its `rust-version`
/// (`Cargo.toml`, `[workspace.package]`), which `cargo xtask msrv` keeps at
/// or above every locked dependency's.
pub const MINIMUM: &str = env!("CARGO_PKG_RUST_VERSION");

/// How long `rustup target add` may try before the Debian route is taken.
pub const RUSTUP_ADD_DEADLINE: Duration = Duration::from_secs(120);

/// A toolchain able to build for the Cortex-M targets.
#[derive(Clone, Debug)]
pub struct Toolchain {
    /// How it was found (for the log).
    pub description: String,
    /// Environment for `cargo`.
    pub env: Vec<(String, String)>,
    /// `-Z build-std=core` is needed.
    pub build_std: bool,
}

impl Toolchain {
    /// A `cargo` command with this toolchain's environment.
    pub fn cargo(&self) -> Command {
        let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
        for (k, v) in &self.env {
            cmd.env(k, v);
        }
        if self.build_std {
            cmd.env("RUSTC_BOOTSTRAP", "1");
        }
        cmd
    }

    /// Arguments to append to a `cargo build/test --target` invocation.
    pub fn build_args(&self) -> Vec<String> {
        if self.build_std {
            vec!["-Z".into(), "build-std=core".into()]
        } else {
            vec![]
        }
    }
}

/// A Rust release, `major.minor.patch`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Version(pub u32, pub u32, pub u32);

impl Version {
    /// Reads the release from `1.93`, `1.93.1`, Debian's `1.85.0+dfsg1-1~deb12u2`
    /// (epoch and Debian revision ignored) or `rustc 1.85.0 (...)`.
    pub fn parse(text: &str) -> Option<Version> {
        let text = text.trim();
        let text = text.strip_prefix("rustc ").unwrap_or(text);
        // A Debian epoch ("1:1.85.0...").
        let text = match text.split_once(':') {
            Some((epoch, rest)) if epoch.chars().all(|c| c.is_ascii_digit()) => rest,
            _ => text,
        };
        let release: String = text.chars().take_while(|c| c.is_ascii_digit() || *c == '.').collect();
        let mut parts = release.split('.').filter(|p| !p.is_empty()).map(str::parse::<u32>);
        let major = parts.next()?.ok()?;
        let minor = parts.next()?.ok()?;
        let patch = match parts.next() {
            Some(p) => p.ok()?,
            None => 0,
        };
        Some(Version(major, minor, patch))
    }

    /// [`MINIMUM`], parsed.
    pub fn minimum() -> Version {
        Version::parse(MINIMUM).expect("the workspace's rust-version is a version")
    }
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}.{}", self.0, self.1, self.2)
    }
}

/// What xtask asks of apt (real: [`SystemApt`]; tests: a fake).
pub trait Apt {
    /// `apt-cache show --no-all-versions PKG`: the candidate's record, or
    /// `None` when apt does not know the package.
    fn show(&mut self, pkg: &str) -> Option<String>;
    /// Whether `apt-get update` may be run (root).
    fn may_update(&self) -> bool;
    /// `apt-get update`.
    fn update(&mut self) -> Result<(), String>;
}

/// The machine's apt, with deadlines.
pub struct SystemApt;

impl Apt for SystemApt {
    fn show(&mut self, pkg: &str) -> Option<String> {
        let out = capture(
            Command::new("apt-cache").args(["show", "--no-all-versions", pkg]),
            Duration::from_secs(60),
        );
        (out.ok() && !out.stdout.trim().is_empty()).then_some(out.stdout)
    }

    fn may_update(&self) -> bool {
        is_root()
    }

    fn update(&mut self) -> Result<(), String> {
        let upd = capture(Command::new("apt-get").arg("update"), Duration::from_secs(300));
        if upd.ok() {
            Ok(())
        } else {
            Err(format!("apt-get update failed: {}", upd.stderr.trim()))
        }
    }
}

/// A field (`Version:`, `Depends:`) of an apt record.
fn field<'a>(record: &'a str, name: &str) -> Option<&'a str> {
    record
        .lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(':'))
        .map(str::trim)
}

/// The candidate version of `rustc-web`, if apt has one.
fn candidate(apt: &mut dyn Apt) -> Option<Version> {
    let record = apt.show("rustc-web")?;
    Version::parse(field(&record, "Version")?)
}

/// What to install instead when Debian cannot provide `minimum` (the
/// targets need no naming: rustup adds the ones `rust-toolchain.toml`
/// lists when it first builds in the workspace).
fn rustup_advice(minimum: Version) -> String {
    format!(
        "install Rust >= {minimum} with rustup: `rustup toolchain install stable` (rust-toolchain.toml names the Cortex-M targets, which rustup then adds)"
    )
}

/// The Debian packages to download: `rustc-web`, `rust-web-src`, and,
/// transitively, the `libstd-rust-web-*` and `libllvm*` packages they
/// depend on, with the compiler's version. A candidate missing from the
/// lists or older than `minimum` makes this refresh the lists (when
/// allowed) and look again; it is never accepted.
pub fn choose_debian(apt: &mut dyn Apt, minimum: Version) -> Result<(Vec<String>, Version), String> {
    let mut version = candidate(apt);
    if version.is_none_or(|v| v < minimum) {
        let offered = match version {
            Some(v) => format!("rustc-web {v}, older than the workspace's rust-version {minimum}"),
            None => "no rustc-web".to_string(),
        };
        if !apt.may_update() {
            return Err(format!(
                "apt offers {offered}: refresh the package lists (`sudo apt-get update`) and run again, or {}",
                rustup_advice(minimum)
            ));
        }
        eprintln!("xtask: apt offers {offered}; apt-get update");
        apt.update()?;
        version = candidate(apt);
        match version {
            Some(v) if v >= minimum => {}
            Some(v) => {
                return Err(format!(
                    "after apt-get update apt still offers rustc-web {v}, older than the workspace's rust-version {minimum}: {}",
                    rustup_advice(minimum)
                ));
            }
            None => {
                return Err(format!(
                    "after apt-get update apt has no rustc-web: {}",
                    rustup_advice(minimum)
                ));
            }
        }
    }
    let version = version.expect("checked above");
    let mut pkgs: Vec<String> = vec!["rustc-web".into(), "rust-web-src".into()];
    let mut i = 0;
    while i < pkgs.len() {
        let record = apt
            .show(&pkgs[i])
            .ok_or_else(|| format!("{} is not available from apt", pkgs[i]))?;
        let deps = field(&record, "Depends").unwrap_or("").to_string();
        for dep in deps.split([',', '|']) {
            let name = dep.trim().split([' ', '(']).next().unwrap_or("").to_string();
            if (name.starts_with("libstd-rust-web") || name.starts_with("libllvm")) && !pkgs.contains(&name) {
                pkgs.push(name);
            }
        }
        i += 1;
    }
    if !pkgs.iter().any(|p| p.starts_with("libstd-rust-web-1")) {
        return Err(format!("unexpected rustc-web dependencies: {}", pkgs.join(", ")));
    }
    Ok((pkgs, version))
}

/// Whether a toolchain unpacked by an earlier run, reporting `rustc -V`
/// output `reported`, may be used: only at or above `minimum`.
pub fn cached_is_usable(reported: &str, minimum: Version) -> bool {
    Version::parse(reported).is_some_and(|v| v >= minimum)
}

fn rustup(root: &Path, args: &[&str], timeout: Duration) -> crate::process::Output {
    // In the workspace, so that rustup acts on rust-toolchain.toml's toolchain.
    capture(Command::new("rustup").args(args).current_dir(root), timeout)
}

fn rustup_has(root: &Path, targets: &[&str]) -> bool {
    let out = rustup(root, &["target", "list", "--installed"], Duration::from_secs(10));
    out.ok() && targets.iter().all(|t| out.stdout.lines().any(|l| l.trim() == *t))
}

/// rustup's host `rust-lld` (Debian's rustc-web does not ship one).
fn rust_lld_dir() -> Result<PathBuf, String> {
    let out = capture(
        Command::new("rustc").args(["--print", "sysroot"]),
        Duration::from_secs(20),
    );
    if !out.ok() {
        return Err(format!("`rustc --print sysroot` failed: {}", out.stderr.trim()));
    }
    let host = capture(Command::new("rustc").args(["-vV"]), Duration::from_secs(20));
    let triple = host
        .stdout
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .unwrap_or("x86_64-unknown-linux-gnu")
        .trim()
        .to_string();
    let dir = PathBuf::from(out.stdout.trim())
        .join("lib/rustlib")
        .join(triple)
        .join("bin");
    if dir.join("rust-lld").exists() {
        Ok(dir)
    } else {
        Err(format!(
            "rust-lld not found in {} (install rustup's default profile)",
            dir.display()
        ))
    }
}

fn debian_env(root: &Path) -> Result<Vec<(String, String)>, String> {
    let lib = root.join("usr/lib/x86_64-linux-gnu");
    let rustc = root.join("usr/bin/rustc");
    let lld = rust_lld_dir()?;
    let path = format!("{}:{}", lld.display(), std::env::var("PATH").unwrap_or_default());
    let ld = match std::env::var("LD_LIBRARY_PATH") {
        Ok(old) if !old.is_empty() => format!("{}:{old}", lib.display()),
        _ => lib.display().to_string(),
    };
    Ok(vec![
        ("RUSTC".into(), rustc.display().to_string()),
        ("LD_LIBRARY_PATH".into(), ld),
        ("PATH".into(), path),
        // A wrapper from the environment would not know this rustc.
        ("RUSTC_WRAPPER".into(), String::new()),
    ])
}

/// `Some(rustc -V output)` when the unpacked Debian toolchain under `root`
/// runs and has its library sources.
fn debian_works(root: &Path) -> Option<String> {
    let rustc = root.join("usr/bin/rustc");
    let src = root.join("usr/lib/rustlib/src/rust/library/core");
    if !rustc.exists() || !src.exists() {
        return None;
    }
    let out = capture(
        Command::new(&rustc)
            .arg("--version")
            .env("LD_LIBRARY_PATH", root.join("usr/lib/x86_64-linux-gnu")),
        Duration::from_secs(20),
    );
    out.ok().then(|| out.stdout.trim().to_string())
}

fn provision_debian(dir: &Path, minimum: Version) -> Result<(), String> {
    let debs = dir.join("debs");
    let root = dir.join("root");
    let _ = std::fs::remove_dir_all(&debs);
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&debs).map_err(|e| e.to_string())?;
    let (pkgs, version) = choose_debian(&mut SystemApt, minimum)?;
    eprintln!("xtask: downloading rustc-web {version}: {}", pkgs.join(" "));
    let dl = capture(
        Command::new("apt-get").arg("download").args(&pkgs).current_dir(&debs),
        Duration::from_secs(900),
    );
    if !dl.ok() {
        return Err(format!("apt-get download failed: {}", dl.stderr.trim()));
    }
    for entry in std::fs::read_dir(&debs).map_err(|e| e.to_string())? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.extension().is_some_and(|e| e == "deb") {
            let x = capture(
                Command::new("dpkg").arg("-x").arg(&path).arg(&root),
                Duration::from_secs(300),
            );
            if !x.ok() {
                return Err(format!("dpkg -x {} failed: {}", path.display(), x.stderr.trim()));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&debs);
    Ok(())
}

/// Finds (or provisions) a toolchain for `targets`.
pub fn get(workspace: &Path, targets: &[&str]) -> Result<Toolchain, String> {
    let rustup_toolchain = |how: &str| Toolchain {
        description: format!("rustup (targets {} {how})", targets.join(", ")),
        env: vec![],
        build_std: false,
    };
    if rustup_has(workspace, targets) {
        return Ok(rustup_toolchain("installed"));
    }
    // The standard route: rustup downloads the targets (a short deadline:
    // without access to its servers this fails or times out).
    if rustup(workspace, &["--version"], Duration::from_secs(10)).ok() {
        eprintln!(
            "xtask: rustup target add {} (deadline {} s)",
            targets.join(" "),
            RUSTUP_ADD_DEADLINE.as_secs()
        );
        let mut args = vec!["target", "add"];
        args.extend_from_slice(targets);
        let add = rustup(workspace, &args, RUSTUP_ADD_DEADLINE);
        if add.ok() && rustup_has(workspace, targets) {
            return Ok(rustup_toolchain("added by rustup"));
        }
        eprintln!(
            "xtask: rustup could not add the targets ({}); taking Debian's rustc-web",
            if add.timed_out {
                "deadline passed".to_string()
            } else {
                // rustup's first error line says what failed (the last one
                // is often a bare curl code).
                add.stderr
                    .lines()
                    .find(|l| l.trim_start().starts_with("error"))
                    .or_else(|| add.stderr.lines().last())
                    .unwrap_or("failed")
                    .trim()
                    .to_string()
            }
        );
    }
    let minimum = Version::minimum();
    let dir = workspace.join("target/cross-toolchain");
    let root = dir.join("root");
    let cached = debian_works(&root);
    let version = match cached {
        Some(v) if cached_is_usable(&v, minimum) => v,
        other => {
            if let Some(old) = other {
                eprintln!(
                    "xtask: {old} under {} is older than the workspace's rust-version {minimum}; replacing it",
                    root.display()
                );
            }
            eprintln!(
                "xtask: provisioning Debian's rustc-web (>= {minimum}) for {} under {}",
                targets.join(", "),
                dir.display()
            );
            provision_debian(&dir, minimum)?;
            let v = debian_works(&root).ok_or("the unpacked Debian toolchain does not run")?;
            if !cached_is_usable(&v, minimum) {
                return Err(format!(
                    "the unpacked toolchain reports {v}, older than {minimum}: {}",
                    rustup_advice(minimum)
                ));
            }
            v
        }
    };
    Ok(Toolchain {
        description: format!("{version} from {} with -Z build-std=core", root.display()),
        env: debian_env(&root)?,
        build_std: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// apt with package lists that `apt-get update` replaces.
    struct FakeApt {
        lists: HashMap<&'static str, String>,
        fresh: HashMap<&'static str, String>,
        root: bool,
        updates: u32,
    }

    /// The record `apt-cache show` prints (the fields xtask reads).
    fn record(pkg: &str, version: &str, depends: &str) -> String {
        format!("Package: {pkg}\nVersion: {version}\nArchitecture: amd64\nDepends: {depends}\nDescription: x\n")
    }

    /// Debian 12's web toolchain at `upstream` (e.g. "1.85.0", "1.96.0"),
    /// with the dependency chain of bookworm's 1.96 records: rustc-web ->
    /// libstd-rust-web-dev -> libstd-rust-web-1.96 -> libllvm22.
    fn bookworm(upstream: &str) -> HashMap<&'static str, String> {
        let mm: String = upstream
            .rsplit_once('.')
            .map(|(a, _)| a.to_string())
            .unwrap_or_default();
        let v = format!("{upstream}+dfsg1-1~deb12u2");
        let mut m = HashMap::new();
        m.insert(
            "rustc-web",
            record(
                "rustc-web",
                &v,
                &format!("libc6 (>= 2.34), libgcc-s1 (>= 3.0), libstd-rust-web-dev (= {v}), gcc, libc-dev, binutils (>= 2.26)"),
            ),
        );
        m.insert("rust-web-src", record("rust-web-src", &v, ""));
        m.insert(
            "libstd-rust-web-dev",
            record("libstd-rust-web-dev", &v, &format!("libstd-rust-web-{mm} (= {v})")),
        );
        m.insert(
            "libstd-rust-web-1.",
            record(
                "libstd-rust-web",
                &v,
                "libc6 (>= 2.34), libgcc-s1 (>= 4.2), libllvm22, libstdc++6 (>= 11)",
            ),
        );
        m.insert("libllvm22", record("libllvm22", "1:22.1.0-1", "libc6, libffi8"));
        m
    }

    impl Apt for FakeApt {
        fn show(&mut self, pkg: &str) -> Option<String> {
            let key = if pkg.starts_with("libstd-rust-web-1.") {
                "libstd-rust-web-1."
            } else {
                self.lists.keys().find(|k| **k == pkg).copied()?
            };
            self.lists.get(key).cloned()
        }
        fn may_update(&self) -> bool {
            self.root
        }
        fn update(&mut self) -> Result<(), String> {
            self.updates += 1;
            self.lists = self.fresh.clone();
            Ok(())
        }
    }

    fn min() -> Version {
        Version(1, 93, 0)
    }

    #[test]
    fn versions_parse_from_debian_rustc_and_cargo_forms() {
        assert_eq!(Version::parse("1.85.0+dfsg1-1~deb12u2"), Some(Version(1, 85, 0)));
        assert_eq!(Version::parse("1:19.1.7-3"), Some(Version(19, 1, 7)));
        assert_eq!(
            Version::parse("rustc 1.96.0 (abc 2026-05-01) (built from a source tarball)"),
            Some(Version(1, 96, 0))
        );
        assert_eq!(Version::parse("1.93"), Some(Version(1, 93, 0)));
        assert_eq!(Version::parse("stable"), None);
        assert!(Version(1, 85, 0) < Version(1, 93, 0) && Version(1, 93, 0) < Version(1, 96, 0));
        // The workspace's own minimum is what `fixed` 1.31 needs.
        assert!(Version::minimum() >= Version(1, 93, 0), "{MINIMUM}");
    }

    #[test]
    fn stale_lists_are_refreshed_and_the_fresh_candidate_taken() {
        // The reported machine: months-old lists offer 1.85; after an update, 1.96.
        let mut apt = FakeApt {
            lists: bookworm("1.85.0"),
            fresh: bookworm("1.96.0"),
            root: true,
            updates: 0,
        };
        let (pkgs, v) = choose_debian(&mut apt, min()).unwrap();
        assert_eq!(v, Version(1, 96, 0));
        assert_eq!(apt.updates, 1);
        assert_eq!(
            pkgs,
            [
                "rustc-web",
                "rust-web-src",
                "libstd-rust-web-dev",
                "libstd-rust-web-1.96",
                "libllvm22"
            ]
        );
    }

    #[test]
    fn a_fresh_enough_candidate_needs_no_update() {
        let mut apt = FakeApt {
            lists: bookworm("1.93.1"),
            fresh: HashMap::new(),
            root: true,
            updates: 0,
        };
        let (_, v) = choose_debian(&mut apt, min()).unwrap();
        assert_eq!((v, apt.updates), (Version(1, 93, 1), 0));
    }

    #[test]
    fn a_too_old_candidate_is_never_accepted() {
        // Still 1.85 after the update: refused, with what to install.
        let mut apt = FakeApt {
            lists: bookworm("1.85.0"),
            fresh: bookworm("1.85.0"),
            root: true,
            updates: 0,
        };
        let e = choose_debian(&mut apt, min()).unwrap_err();
        assert_eq!(apt.updates, 1);
        assert!(
            e.contains("1.85.0") && e.contains("1.93.0") && e.contains("rustup toolchain install"),
            "{e}"
        );
        // Not root: no update, the command to run instead.
        let mut apt = FakeApt {
            lists: bookworm("1.85.0"),
            fresh: bookworm("1.96.0"),
            root: false,
            updates: 0,
        };
        let e = choose_debian(&mut apt, min()).unwrap_err();
        assert_eq!(apt.updates, 0);
        assert!(e.contains("sudo apt-get update") && e.contains("1.85.0"), "{e}");
        // No rustc-web at all, even after the update.
        let mut apt = FakeApt {
            lists: HashMap::new(),
            fresh: HashMap::new(),
            root: true,
            updates: 0,
        };
        let e = choose_debian(&mut apt, min()).unwrap_err();
        assert!(e.contains("no rustc-web"), "{e}");
    }

    #[test]
    fn a_cached_toolchain_older_than_the_minimum_is_replaced() {
        assert!(!cached_is_usable(
            "rustc 1.85.0 (4d215e2de 2025-02-17) (built from a source tarball)",
            min()
        ));
        assert!(cached_is_usable(
            "rustc 1.96.0 (0b1d3e6c1 2026-05-25) (built from a source tarball)",
            min()
        ));
        assert!(!cached_is_usable("garbage", min()));
    }
}
