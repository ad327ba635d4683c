//! The host benchmark's workloads, shared by `benches/host.rs` (which runs
//! them) and `cargo xtask callgrind` (which counts their instructions).

/// Operations per workload.
pub const COUNT: u32 = 20_000;

/// Workload names, in report order (`setup`, reading the preset, is run
/// separately and subtracted by the callgrind check).
pub const WORKLOADS: [&str; 7] = [
    "twin-f32",
    "twin-f64",
    "twin-q12.20",
    "twin-ros2-f32",
    "equilibrium-f32",
    "fluid-f32",
    "estimator-f32",
];
