//! The platforms an FMU's archive can carry a binary for, as data: the
//! FMI 3.0 platform tuple, the FMI 2.0 folder name, the Rust target and
//! what cross-building and running the binary there takes
//! (`cargo xtask fmu --platforms`, `cargo xtask fmu-check`).
//!
//! FMI 2.0 names x86 folders only (`win64`, `linux64`); for any other
//! platform FMI 2.0.4 and later say to use FMI 3.0's platform tuple, so
//! the aarch64 Linux binary is `binaries/aarch64-linux/` in both versions.

use crate::description::FmiVersion;

/// A platform of the FMU's binaries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Platform {
    /// FMI 3.0 platform tuple (`x86_64-linux`): the name
    /// `cargo xtask fmu --platforms` takes.
    pub tuple: &'static str,
    /// FMI 2.0 folder under `binaries/`.
    pub fmi2_dir: &'static str,
    /// Rust target triple.
    pub rust_target: &'static str,
    /// The shared library's name in cargo's output folder.
    pub cargo_file: &'static str,
    /// The binary's extension in the FMU (`so`, `dll`).
    pub extension: &'static str,
    /// The Debian packages that provide the cross compiler and its C library.
    pub compiler_package: &'static str,
    /// The C cross compiler that links the binary and the C driver (Debian
    /// package in [`Platform::compiler_package`]); `None`: the host's.
    pub cross_compiler: Option<&'static str>,
}

/// Every platform, the host's first.
pub const PLATFORMS: [Platform; 3] = [
    Platform {
        tuple: "x86_64-linux",
        fmi2_dir: "linux64",
        rust_target: "x86_64-unknown-linux-gnu",
        cargo_file: "libcompensator_fmu.so",
        extension: "so",
        compiler_package: "gcc",
        cross_compiler: None,
    },
    Platform {
        tuple: "x86_64-windows",
        fmi2_dir: "win64",
        rust_target: "x86_64-pc-windows-gnu",
        cargo_file: "compensator_fmu.dll",
        extension: "dll",
        compiler_package: "gcc-mingw-w64-x86-64",
        cross_compiler: Some("x86_64-w64-mingw32-gcc"),
    },
    Platform {
        tuple: "aarch64-linux",
        fmi2_dir: "aarch64-linux",
        rust_target: "aarch64-unknown-linux-gnu",
        cargo_file: "libcompensator_fmu.so",
        extension: "so",
        compiler_package: "gcc-aarch64-linux-gnu libc6-dev-arm64-cross",
        cross_compiler: Some("aarch64-linux-gnu-gcc"),
    },
];

impl Platform {
    /// The platform of `tuple` (`x86_64-linux`, `x86_64-windows`,
    /// `aarch64-linux`).
    pub fn named(tuple: &str) -> Option<Platform> {
        PLATFORMS.iter().copied().find(|p| p.tuple == tuple)
    }

    /// The platform this code was compiled for, if the FMU has one.
    pub fn host() -> Option<Platform> {
        let arch = std::env::consts::ARCH;
        let os = std::env::consts::OS;
        PLATFORMS.iter().copied().find(|p| p.tuple == format!("{arch}-{os}"))
    }

    /// The folder under `binaries/` for `version`.
    pub fn dir(self, version: FmiVersion) -> &'static str {
        match version {
            FmiVersion::V2 => self.fmi2_dir,
            FmiVersion::V3 => self.tuple,
        }
    }

    /// The binary's path in the archive (`binaries/linux64/compensator.so`).
    pub fn archive_path(self, version: FmiVersion) -> String {
        format!(
            "binaries/{}/{}.{}",
            self.dir(version),
            crate::description::MODEL_IDENTIFIER,
            self.extension
        )
    }

    /// `CARGO_TARGET_<TRIPLE>_LINKER` (the variable naming the linker of a
    /// cross build).
    pub fn linker_variable(self) -> String {
        format!(
            "CARGO_TARGET_{}_LINKER",
            self.rust_target.to_uppercase().replace('-', "_")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_follow_each_version() {
        let [linux, windows, arm] = PLATFORMS;
        assert_eq!(linux.archive_path(FmiVersion::V2), "binaries/linux64/compensator.so");
        assert_eq!(
            linux.archive_path(FmiVersion::V3),
            "binaries/x86_64-linux/compensator.so"
        );
        assert_eq!(windows.archive_path(FmiVersion::V2), "binaries/win64/compensator.dll");
        assert_eq!(
            windows.archive_path(FmiVersion::V3),
            "binaries/x86_64-windows/compensator.dll"
        );
        assert_eq!(
            arm.archive_path(FmiVersion::V2),
            "binaries/aarch64-linux/compensator.so"
        );
        assert_eq!(
            arm.archive_path(FmiVersion::V3),
            "binaries/aarch64-linux/compensator.so"
        );
        assert_eq!(arm.linker_variable(), "CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER");
        assert_eq!(Platform::named("x86_64-windows"), Some(windows));
        assert_eq!(Platform::named("win64"), None);
        if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
            assert_eq!(Platform::host(), Some(linux));
        }
    }
}
