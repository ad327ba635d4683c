//! Build script of the firmware package: a thin driver over
//! `compensator-codegen`, whose functions host tests call too.
//!
//! 1. The memory layout: the workspace root's `memory.x` is the board's
//!    (STM32F405: the stack alone in the core-coupled RAM, so that an
//!    overflow faults instead of corrupting `.bss`), and the linker, which
//!    runs in the workspace root, reads it for every image. The QEMU
//!    images get their machine's differences as `--defsym` link arguments
//!    ([`QEMU_LAYOUTS`]): QEMU's STM32F405 and STM32F205 (`netduinoplus2`,
//!    `netduino2`) model no CCM, and the Cortex-M0 image runs on the
//!    nRF51 of `microbit`.
//! 2. For the firmware images (features `qemu`, `board`; host builds
//!    include no parameter file), reads the parameter file named by
//!    `COMPENSATOR_PARAMS` (default `presets/paper.toml`; a relative path
//!    is taken from the directory the command was run in, `$PWD`, as the
//!    CLI takes `--params`) with the same reader as the host tools, and
//!    writes `$OUT_DIR/params.rs` (`compensator_codegen::params_rs`: the
//!    constants and the twin's configuration chosen for the design). A
//!    refused file fails the build with one line naming the field
//!    (`cargo::error`, no backtrace). The firmware's `monitor` feature
//!    is required exactly when the file names the condition monitor's
//!    second sensor (`monitor.sensor`), and refused otherwise.
//! 3. For the QEMU images only (feature `qemu`): the twin's replay adapted
//!    to the device's ranges, with the bounds it checks itself against
//!    (`$OUT_DIR/replay.rs`, and its schedule as text in
//!    `$OUT_DIR/replay.txt` for the host-side replica of `cargo xtask
//!    test`), and the on-target tests' expectations
//!    (`$OUT_DIR/expectations.rs`), all from the independent reference
//!    (`compensator_codegen::replay`). The board image needs none of it,
//!    and its build compiles no reference.

use std::path::PathBuf;
use std::{env, fs};

/// The QEMU machines' layouts where they differ from the board's
/// `memory.x` (the symbols it reads): `stm32` for `netduinoplus2` and
/// `netduino2` (1 MiB flash at 0x0800_0000 as the board, 128 KiB of SRAM
/// used, the stack at its top: QEMU 7.2 maps no CCM at 0x1000_0000), and
/// `microbit` (nRF51822: 256 KiB flash at 0, 16 KiB SRAM).
const QEMU_LAYOUTS: [(&str, &[(&str, u32)]); 2] = [
    (
        "stm32",
        &[
            ("__qemu_flash_origin", 0x0800_0000),
            ("__qemu_flash_length", 1024 << 10),
            ("__qemu_ram_length", 128 << 10),
        ],
    ),
    (
        "microbit",
        &[
            ("__qemu_flash_origin", 0),
            ("__qemu_flash_length", 256 << 10),
            ("__qemu_ram_length", 16 << 10),
        ],
    ),
];

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let target = env::var("TARGET").unwrap_or_default();
    let board = env::var_os("CARGO_FEATURE_BOARD").is_some();
    let qemu = env::var_os("CARGO_FEATURE_QEMU").is_some();
    println!("cargo:rerun-if-changed=build.rs");
    // Set for an NTC device (`estimator.sensor = "ntc"`), below.
    println!("cargo::rustc-check-cfg=cfg(sensor_ntc)");

    println!("cargo:rerun-if-changed=memory.x");
    if target.starts_with("thumb") && !board {
        let machine = if target.starts_with("thumbv6m") {
            "microbit"
        } else {
            "stm32"
        };
        for (name, symbols) in QEMU_LAYOUTS {
            if name == machine {
                for (symbol, value) in symbols {
                    println!("cargo:rustc-link-arg=--defsym={symbol}={value:#x}");
                }
            }
        }
    }

    if !(board || qemu) {
        // Host builds (CLI, host tests, xtask) include no parameter file:
        // COMPENSATOR_PARAMS neither rebuilds nor breaks them.
        return;
    }
    println!("cargo:rerun-if-env-changed=COMPENSATOR_PARAMS");
    let params = match env::var_os("COMPENSATOR_PARAMS") {
        Some(p) => {
            let p = PathBuf::from(p);
            if p.is_absolute() {
                p
            } else {
                // Where the user ran cargo (cargo itself runs this script in
                // the package's directory).
                println!("cargo:rerun-if-env-changed=PWD");
                match env::var_os("PWD").map(PathBuf::from) {
                    Some(cwd) if cwd.is_absolute() => cwd.join(p),
                    _ => manifest.join(p),
                }
            }
        }
        None => manifest.join("presets/paper.toml"),
    };
    // `dir/../file` as `file`, in messages and for cargo (a missing file is
    // reported by the reader below).
    let params = fs::canonicalize(&params).unwrap_or(params);
    println!("cargo:rerun-if-changed={}", params.display());
    let raw = match compensator_params::file::load(&params) {
        Ok(raw) => raw,
        Err(e) => {
            // One line naming the field; cargo fails the build after it.
            println!("cargo::error=parameter file {}: {e}", params.display());
            return;
        }
    };
    let source = params
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let generated = match compensator_codegen::params_rs(&raw, &params.display().to_string(), &source) {
        Ok(g) => g,
        Err(e) => {
            println!("cargo::error=parameter file {}: {e}", params.display());
            return;
        }
    };
    for w in &generated.warnings {
        println!("cargo::warning=parameter file {}: {w}", params.display());
    }
    // The monitor is built in exactly when the file names its second
    // sensor: an image without one keeps its flash and its ticks, and an
    // image with one never ignores it.
    let monitor = env::var_os("CARGO_FEATURE_MONITOR").is_some();
    if raw.monitor.has_sensor() && !monitor {
        println!(
            "cargo::error=parameter file {}: monitor.sensor names a second sensor: build with the firmware's `monitor` feature (cargo xtask adds it; with cargo, --features {},monitor)",
            params.display(),
            if board { "board" } else { "qemu" }
        );
        return;
    }
    if monitor && !raw.monitor.has_sensor() {
        println!(
            "cargo::error=parameter file {}: the firmware's `monitor` feature needs a second sensor, and monitor.sensor is \"none\"",
            params.display()
        );
        return;
    }
    fs::write(out.join("params.rs"), generated.code).expect("write params.rs");
    // The sensor the file chose: the images compile its driver alone.
    if raw.estimator.is_ntc() {
        println!("cargo::rustc-cfg=sensor_ntc");
    }
    #[cfg(feature = "qemu")]
    {
        use compensator_codegen::replay;
        let r = replay::adapt(&raw);
        for note in &r.notes {
            println!("cargo::warning={note}");
        }
        fs::write(out.join("replay.rs"), r.rust(&raw)).expect("write replay.rs");
        fs::write(out.join("replay.txt"), r.schedule.text()).expect("write replay.txt");
        fs::write(out.join("expectations.rs"), replay::expectations(&raw.core)).expect("write expectations.rs");
    }
}
