//! The cross toolchain for the Cortex-M targets, chosen fast and without
//! hanging:
//!
//! 1. rustup's own target, when `rustup target list --installed` (10 s
//!    deadline) lists every target needed;
//! 2. else Debian's `rustc-web` (with its standard library sources) unpacked
//!    under `target/cross-toolchain/` by an earlier run, used with
//!    `RUSTC_BOOTSTRAP=1 -Z build-std=core` and rustup's `rust-lld`;
//! 3. else that toolchain is provisioned: `apt-get download` of the
//!    packages (names read from `apt-cache`, `apt-get update` first if the
//!    lists lack them and we are root), unpacked with `dpkg -x`. Nothing is
//!    installed system-wide (`rustc-web` conflicts with rustup).
//!
//! `rustup target add` is never called: it cannot download here and would
//! hang.

use crate::process::{capture, is_root};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

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

fn rustup_has(targets: &[&str]) -> bool {
    let out = capture(
        Command::new("rustup").args(["target", "list", "--installed"]),
        Duration::from_secs(10),
    );
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

/// `Some(version)` when the unpacked Debian toolchain under `root` runs and
/// has its library sources.
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

/// `Depends:` of a package, or `None` when apt does not know it.
fn depends(pkg: &str) -> Option<String> {
    let out = capture(
        Command::new("apt-cache").args(["show", "--no-all-versions", pkg]),
        Duration::from_secs(60),
    );
    if !out.ok() || out.stdout.trim().is_empty() {
        return None;
    }
    Some(
        out.stdout
            .lines()
            .find_map(|l| l.strip_prefix("Depends:"))
            .unwrap_or("")
            .to_string(),
    )
}

/// The packages of Debian's web-browser Rust toolchain, read from apt's
/// metadata: `rustc-web`, `rust-web-src`, and, transitively, the
/// `libstd-rust-web-*` and `libllvm*` packages it depends on.
fn debian_packages() -> Result<Vec<String>, String> {
    if depends("rustc-web").is_none() {
        if !is_root() {
            return Err(
                "apt has no rustc-web; run `sudo apt-get update` (or install the rustup target thumbv7em-none-eabihf)"
                    .into(),
            );
        }
        eprintln!("xtask: apt-get update (rustc-web not in the package lists)");
        let upd = capture(Command::new("apt-get").arg("update"), Duration::from_secs(300));
        if !upd.ok() {
            return Err(format!("apt-get update failed: {}", upd.stderr.trim()));
        }
    }
    let mut pkgs: Vec<String> = vec!["rustc-web".into(), "rust-web-src".into()];
    let mut i = 0;
    while i < pkgs.len() {
        let deps = depends(&pkgs[i]).ok_or_else(|| format!("{} is not available from apt", pkgs[i]))?;
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
    Ok(pkgs)
}

fn provision_debian(dir: &Path) -> Result<(), String> {
    let debs = dir.join("debs");
    let root = dir.join("root");
    let _ = std::fs::remove_dir_all(&debs);
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&debs).map_err(|e| e.to_string())?;
    let pkgs = debian_packages()?;
    eprintln!("xtask: downloading {}", pkgs.join(" "));
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
    if rustup_has(targets) {
        return Ok(Toolchain {
            description: format!("rustup (targets {} installed)", targets.join(", ")),
            env: vec![],
            build_std: false,
        });
    }
    let dir = workspace.join("target/cross-toolchain");
    let root = dir.join("root");
    let version = match debian_works(&root) {
        Some(v) => v,
        None => {
            eprintln!(
                "xtask: rustup lacks {}; provisioning Debian's rustc-web under {}",
                targets.join(", "),
                dir.display()
            );
            provision_debian(&dir)?;
            debian_works(&root).ok_or("the unpacked Debian toolchain does not run")?
        }
    };
    Ok(Toolchain {
        description: format!("{version} from {} with -Z build-std=core", root.display()),
        env: debian_env(&root)?,
        build_std: true,
    })
}
