//! Decoding the targets' bytes: temperatures, designs, the presets.

use arbitrary::Unstructured;
use compensator::RawParams;
use compensator::params::CORE_FIELDS;
use std::sync::OnceLock;

/// `presets/paper.toml`, the firmware's default device.
pub const PAPER: &str = include_str!("../../presets/paper.toml");
/// `presets/model-example.toml`.
pub const MODEL_EXAMPLE: &str = include_str!("../../presets/model-example.toml");

/// The presets, parsed once: `[paper, model-example]`.
pub fn presets() -> &'static [RawParams; 2] {
    static PRESETS: OnceLock<[RawParams; 2]> = OnceLock::new();
    PRESETS.get_or_init(|| {
        let read = |text: &str| compensator_params::file::parse(text).expect("a preset parses");
        [read(PAPER), read(MODEL_EXAMPLE)]
    })
}

/// A byte, 0 once the input is exhausted.
pub fn byte(u: &mut Unstructured) -> u8 {
    u.arbitrary().unwrap_or(0)
}

/// A little-endian `u16`, 0 once the input is exhausted.
pub fn word(u: &mut Unstructured) -> u16 {
    u.arbitrary().unwrap_or(0)
}

/// An `f64` from 8 little-endian bytes of its bits (any value: NaN,
/// infinities, subnormals), 0 once the input is exhausted.
pub fn float(u: &mut Unstructured) -> f64 {
    u.arbitrary().unwrap_or(0.0)
}

/// Values that break naive code, as temperatures (codes `0xFFF0..`).
pub const SPECIAL_TEMPERATURES: [f64; 16] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    -273.15,
    -273.16,
    1e30,
    -1e30,
    0.0,
    -0.0,
    f64::MIN_POSITIVE,
    5e-324,
    f32::MAX as f64,
    -60.0,
    300.0,
    150.0,
    -20.0,
];

/// Lowest temperature of the linear codes [C].
pub const T_LOW: f64 = -80.0;
/// Span of the linear codes [C]: `-80..320 C` in steps of 0.006 C.
pub const T_SPAN: f64 = 400.0;
/// First code of [`SPECIAL_TEMPERATURES`].
pub const SPECIAL_CODES: u16 = 0xFFF0;

/// A temperature [C] from a 16-bit code: `-80..320 C` linearly below
/// `0xFFF0` (where the oil models live, their refusals on either side),
/// then the 16 special values.
pub fn temperature(code: u16) -> f64 {
    if code >= SPECIAL_CODES {
        SPECIAL_TEMPERATURES[usize::from(code - SPECIAL_CODES)]
    } else {
        T_LOW + f64::from(code) * (T_SPAN / f64::from(SPECIAL_CODES))
    }
}

/// The code of the linear temperature nearest `t` [C] (for seeds).
pub fn code_of(t: f64) -> u16 {
    let c = ((t - T_LOW) / T_SPAN * f64::from(SPECIAL_CODES)).round();
    c.clamp(0.0, f64::from(SPECIAL_CODES - 1)) as u16
}

/// Which design a target runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Design {
    /// A preset as shipped (`0`: paper, `1`: model-example): the twin's
    /// promises (no failed tick, the closed form at rest) hold without
    /// exception.
    Preset(usize),
    /// The paper preset with every core field scaled by `2^(i / 64)`, `i`
    /// a byte read as `i8` (a factor in `[1/4, 4)`; `0`, or a missing
    /// byte, leaves the field unchanged): valid or not, stiff or soft.
    Perturbed,
}

/// A design: selector byte `s` (`s % 4`: 0, 1 the presets, 2 and 3
/// perturbed), and for a perturbed one 21 factor bytes, one per core field
/// in file order.
pub fn design(u: &mut Unstructured) -> (Design, RawParams) {
    let s = byte(u) % 4;
    let presets = presets();
    match s {
        0 | 1 => (Design::Preset(usize::from(s)), presets[usize::from(s)]),
        _ => {
            let mut raw = presets[0];
            let mut factors = [1.0f64; CORE_FIELDS.len()];
            for f in factors.iter_mut() {
                *f = (f64::from(byte(u) as i8) / 64.0).exp2();
            }
            let mut i = 0;
            raw.core = raw.core.map(|n| {
                let v = n.value * factors[i];
                i += 1;
                v
            });
            (Design::Perturbed, raw)
        }
    }
}
