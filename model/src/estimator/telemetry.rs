//! The telemetry record, declared once: the table at the end of this file
//! lists every field the firmware sends, with its CSV column (SI unit in
//! the name), its SI unit, its wire encoding, how the log shows it and
//! what it is. Everything else comes from the table:
//!
//! * [`encode`]: the bytes the firmware packs ([`StateEstimate`]'s
//!   `defmt::Format` sends them as one byte string);
//! * [`Record`], one `f64` per field by column name, with
//!   [`Record::decode`] (the host's decoder of those bytes) and
//!   [`Record::of`] (an estimate as the wire carries it, computed without
//!   the byte layout: what a host replica compares decoded telemetry with);
//! * [`FIELDS`], each field's [`Field`] (column, unit, [`Encoding`],
//!   display key, unit, scale and decimals, description): the host's CSV
//!   header and reader, the rounded log line, the replica's tolerances
//!   ([`Field::tolerance`]) and the documentation's column table are
//!   generated from it.
//!
//! Adding a field is one line in the table (and the computation of its
//! value in the estimator). The layout tag [`LAYOUT`], a hash of the
//! table, travels in every record: a decoder built from another table
//! refuses the record ([`DecodeError::Layout`]) rather than misread it.
//!
//! # The condition monitor's rows
//!
//! The table has two parts: the rows every image sends, then, after
//! `@monitor:`, the condition monitor's health parameters
//! ([`crate::monitor::HealthEstimate`]), which only an image with a second
//! sensor sends ([`Layout::Monitor`]: the core's `monitor` feature, which
//! the firmware enables exactly when its device file names a sensor). An
//! image without one packs the same record as before the monitor existed
//! ([`Layout::Plain`]: its bytes, its tag [`LAYOUT`], its cost per
//! telemetry tick), so the health rows cost it nothing; each row would
//! have cost it about 15 instructions a record (`docs/bench.md`), and its
//! worst tick has no room for nine. The host decodes both layouts, by
//! their tags ([`Record::decode`]); a [`Record`] has every column, the
//! health ones NaN for a record without them ([`Record::layout`]).
//!
//! # Wire format
//!
//! Little-endian: the layout's tag ([`LAYOUT`] or [`LAYOUT_MONITOR`],
//! `u16`), then each field of the layout in table order in its
//! [`Encoding`], then the [`Flags`] bits (`u32`); [`SIZE`] or
//! [`SIZE_MONITOR`] bytes in all.
//! Packing costs a store per field (plus a scale and a saturation for the
//! 16-bit encodings), where defmt's per-argument formatting cost about 66
//! instructions per field; the figures per encoding are in the project's
//! `docs/bench.md` (`cargo xtask bench`).

use super::estimate::StateEstimate;
use super::flags::Flags;
use core::fmt;

/// How a field travels in the record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// IEEE 754 single precision, 4 bytes: every digit of the estimate,
    /// NaN and infinities kept.
    F32,
    /// A non-negative quantity in 2 bytes: `round(v / step)` (halves up) for codes
    /// `0 ..= 65533` (`0 ..= 65533 step`), [`U16_ABOVE`] for anything
    /// larger (decoded as `+inf`: "beyond the wire's range", never a
    /// silently clipped value), [`U16_NAN`] for NaN. A negative value is
    /// sent as 0. For standard deviations and other magnitudes whose
    /// resolution is known.
    U16 {
        /// Value of one code, in the field's SI unit.
        step: f64,
    },
    /// A signed quantity in 2 bytes: `round(v / step)` (halves up) for codes
    /// `-32766 ..= 32766`, [`I16_ABOVE`] / [`I16_BELOW`] beyond (decoded as
    /// `+inf` / `-inf`), [`I16_NAN`] for NaN.
    I16 {
        /// Value of one code, in the field's SI unit.
        step: f64,
    },
    /// A count, `u32`, 4 bytes, exact.
    U32,
}

/// [`Encoding::U16`]'s code for a value above its range (decoded `+inf`).
pub const U16_ABOVE: u16 = 0xFFFE;
/// [`Encoding::U16`]'s code for NaN.
pub const U16_NAN: u16 = 0xFFFF;
/// [`Encoding::I16`]'s code for a value above its range (decoded `+inf`).
pub const I16_ABOVE: i16 = i16::MAX;
/// [`Encoding::I16`]'s code for a value below its range (decoded `-inf`).
pub const I16_BELOW: i16 = i16::MIN + 1;
/// [`Encoding::I16`]'s code for NaN.
pub const I16_NAN: i16 = i16::MIN;

impl Encoding {
    /// Bytes the encoding takes in the record.
    pub const fn size(self) -> usize {
        match self {
            Encoding::F32 | Encoding::U32 => 4,
            Encoding::U16 { .. } | Encoding::I16 { .. } => 2,
        }
    }

    /// The value of one code in the field's SI unit (0 for the exact
    /// encodings, [`Encoding::F32`] and [`Encoding::U32`]).
    pub fn quantum(self) -> f64 {
        match self {
            Encoding::F32 | Encoding::U32 => 0.0,
            Encoding::U16 { step } | Encoding::I16 { step } => step,
        }
    }

    /// The encoding's name as the documentation shows it (`f32`,
    /// `u16 x 1e-8`).
    pub fn describe(self) -> impl fmt::Display {
        struct Describe(Encoding);
        impl fmt::Display for Describe {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                match self.0 {
                    Encoding::F32 => f.write_str("f32"),
                    Encoding::U32 => f.write_str("u32"),
                    Encoding::U16 { step } => write!(f, "u16 x {step:e}"),
                    Encoding::I16 { step } => write!(f, "i16 x {step:e}"),
                }
            }
        }
        Describe(self)
    }

    /// A code for the layout hash.
    const fn tag(self) -> u32 {
        match self {
            Encoding::F32 => 1,
            Encoding::U32 => 2,
            Encoding::U16 { step } => 3 ^ fold(step.to_bits()),
            Encoding::I16 { step } => 4 ^ fold(step.to_bits()).rotate_left(7),
        }
    }
}

/// [`Encoding::U16`]'s code for `v`, with `per_step = 1 / step` (the
/// firmware multiplies: a division costs 14 cycles on a Cortex-M4F):
/// `round(v / step)`, halves up. The usual value takes two comparisons, an
/// add and a conversion; NaN, negative and out-of-range values the slow
/// path.
#[inline(always)]
pub fn u16_code(v: f32, per_step: f32) -> u16 {
    let s = v * per_step;
    if (0.0..65533.5).contains(&s) {
        // In range for `i32`: one conversion (the `u16` cast's saturation
        // would add compares).
        (s + 0.5) as i32 as u16
    } else if s >= 65533.5 {
        U16_ABOVE
    } else if s < 0.0 {
        0
    } else {
        U16_NAN
    }
}

/// The value [`u16_code`]'s `code` stands for [SI unit of the field]
/// (`step` the one the code was made with, in `f64`).
pub fn u16_value(code: u16, step: f64) -> f64 {
    match code {
        U16_NAN => f64::NAN,
        U16_ABOVE => f64::INFINITY,
        c => f64::from(c) * step,
    }
}

/// [`Encoding::I16`]'s code for `v`, with `per_step = 1 / step`:
/// `round(v / step)`, halves up (rounded in the positive range, shifted by
/// 32768: one conversion, no `roundf`, which is software on the
/// Cortex-M4F).
#[inline(always)]
pub fn i16_code(v: f32, per_step: f32) -> i16 {
    let s = v * per_step;
    if s > -32766.5 && s < 32766.5 {
        ((s + 32768.5) as i32 - 32768) as i16
    } else if s >= 32766.5 {
        I16_ABOVE
    } else if s <= -32766.5 {
        I16_BELOW
    } else {
        I16_NAN
    }
}

/// The value [`i16_code`]'s `code` stands for [SI unit of the field].
pub fn i16_value(code: i16, step: f64) -> f64 {
    match code {
        I16_NAN => f64::NAN,
        I16_ABOVE => f64::INFINITY,
        I16_BELOW => f64::NEG_INFINITY,
        c => f64::from(c) * step,
    }
}

/// One field of the telemetry record (a row of the table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Field {
    /// CSV column, SI unit in the name (`x_m`); the [`Record`] field.
    pub column: &'static str,
    /// SI unit (`"-"`: a count or a ratio).
    pub unit: &'static str,
    /// How it travels.
    pub encoding: Encoding,
    /// Key in the log line (`x` in `x=12.9 um`).
    pub key: &'static str,
    /// Unit the log line shows (`"um"`; empty: none).
    pub shown_unit: &'static str,
    /// Shown value per SI value (`1e6` for um).
    pub scale: f64,
    /// Decimals the log line shows: what the sensor and the model resolve.
    pub decimals: usize,
    /// Description.
    pub doc: &'static str,
}

/// Relative part of the agreement [`Field::tolerance`] allows between two
/// runs of the same estimator on different machines (the firmware and a
/// host replica: `f32` code generation differs in the last bits, and the
/// differences grow through the twin's steps).
pub const AGREEMENT: f64 = 1e-5;

impl Field {
    /// Resolution of the log line, in the field's SI unit.
    pub fn resolution(&self) -> f64 {
        let mut r = 1.0;
        for _ in 0..self.decimals {
            r *= 0.1;
        }
        r / self.scale
    }

    /// How far two runs of the estimator may put this field apart with
    /// `reference` as one of them: [`AGREEMENT`] of `|reference|` plus a
    /// tenth of the log line's [`Field::resolution`], at least one code of a
    /// quantised [`Encoding`] (the same value a hair either side of a
    /// rounding boundary).
    pub fn tolerance(&self, reference: f64) -> f64 {
        let abs = (0.1 * self.resolution()).max(self.encoding.quantum());
        AGREEMENT * reference.abs() + abs
    }
}

/// Why a byte string is not a telemetry record of this table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// The record has `got` bytes, this table's `expected`.
    Length {
        /// [`SIZE`].
        expected: usize,
        /// Bytes received.
        got: usize,
    },
    /// The record was packed by another table (another firmware version).
    Layout {
        /// [`LAYOUT`].
        expected: u16,
        /// The tag received.
        got: u16,
    },
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::Length { expected, got } => {
                write!(
                    f,
                    "telemetry record of {got} bytes, this decoder's table packs {expected}"
                )
            }
            DecodeError::Layout { expected, got } => write!(
                f,
                "telemetry record of layout {got:#06x}, this decoder's table is {expected:#06x} (firmware and host built from different tables)"
            ),
        }
    }
}

impl core::error::Error for DecodeError {}

/// Which rows a record carries: the table's first part alone, or the
/// condition monitor's health rows too (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// The rows every image sends ([`encode`], [`LAYOUT`], [`SIZE`]).
    Plain,
    /// Those and the monitor's health rows ([`encode_monitor`],
    /// [`LAYOUT_MONITOR`], [`SIZE_MONITOR`]): an image with a second sensor.
    Monitor,
}

impl Layout {
    /// The layout a firmware image packs: [`Layout::Monitor`] with the
    /// core's `monitor` feature (the images built for a device file that
    /// names a second sensor), else [`Layout::Plain`]. On the host the
    /// feature says nothing of a log: a decoder takes the record's own tag.
    pub const BUILT: Layout = if cfg!(feature = "monitor") {
        Layout::Monitor
    } else {
        Layout::Plain
    };

    /// The fields the layout carries, in wire order.
    pub fn fields(self) -> &'static [Field] {
        match self {
            Layout::Plain => FIELDS.split_at(HEALTH_FROM).0,
            Layout::Monitor => &FIELDS,
        }
    }

    /// The layout's tag, sent first in its records.
    pub const fn tag(self) -> u16 {
        match self {
            Layout::Plain => LAYOUT,
            Layout::Monitor => LAYOUT_MONITOR,
        }
    }

    /// Bytes in a record of the layout.
    pub const fn size(self) -> usize {
        match self {
            Layout::Plain => SIZE,
            Layout::Monitor => SIZE_MONITOR,
        }
    }
}

/// Packs values into a record of `N` bytes, in order; never panics (a
/// full buffer, impossible with the table's [`SIZE`], would drop the
/// bytes).
struct Writer<const N: usize> {
    bytes: [u8; N],
    at: usize,
}

impl<const N: usize> Writer<N> {
    #[inline(always)]
    fn put<const K: usize>(&mut self, v: [u8; K]) {
        if let Some(slot) = self.bytes.get_mut(self.at..).and_then(|s| s.first_chunk_mut::<K>()) {
            *slot = v;
        }
        self.at += K;
    }
}

/// Reads values from a record, in order (zeros past its end, impossible
/// once its length is checked).
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const K: usize>(&mut self) -> [u8; K] {
        let v = self
            .bytes
            .get(self.at..)
            .and_then(|s| s.first_chunk::<K>())
            .copied()
            .unwrap_or([0; K]);
        self.at += K;
        v
    }
}

/// A 64-bit word folded to 32 bits.
const fn fold(w: u64) -> u32 {
    (w >> 32) as u32 ^ w as u32
}

/// FNV-1a over `bytes`, continuing from `h`.
const fn fnv(mut h: u32, bytes: &[u8]) -> u32 {
    let mut i = 0;
    while i < bytes.len() {
        h ^= bytes[i] as u32;
        h = h.wrapping_mul(0x0100_0193);
        i += 1;
    }
    h
}

/// The layout tag of a table: FNV-1a over each field's column and
/// encoding, folded to 16 bits.
const fn layout_of(fields: &[Field]) -> u16 {
    let mut h = 0x811C_9DC5;
    let mut i = 0;
    while i < fields.len() {
        h = fnv(h, fields[i].column.as_bytes());
        h = fnv(h, &fields[i].encoding.tag().to_le_bytes());
        i += 1;
    }
    ((h >> 16) ^ (h & 0xFFFF)) as u16
}

/// The Rust type a field's accessor returns, by encoding.
macro_rules! wire_type {
    (f32) => {
        f32
    };
    (u16) => {
        f32
    };
    (i16) => {
        f32
    };
    (u32) => {
        u32
    };
}

/// A field's [`Encoding`].
macro_rules! encoding {
    (f32) => {
        Encoding::F32
    };
    (u32) => {
        Encoding::U32
    };
    (u16 $step:literal) => {
        Encoding::U16 { step: $step }
    };
    (i16 $step:literal) => {
        Encoding::I16 { step: $step }
    };
}

/// Packs one value.
macro_rules! put {
    ($w:ident, $v:expr, f32) => {
        $w.put($v.to_bits().to_le_bytes())
    };
    ($w:ident, $v:expr, u32) => {
        $w.put($v.to_le_bytes())
    };
    ($w:ident, $v:expr, u16 $step:literal) => {
        $w.put(u16_code($v, const { 1.0f32 / $step }).to_le_bytes())
    };
    ($w:ident, $v:expr, i16 $step:literal) => {
        $w.put(i16_code($v, const { 1.0f32 / $step }).to_le_bytes())
    };
}

/// Reads one value back as `f64`.
macro_rules! get {
    ($r:ident, f32) => {
        f64::from(f32::from_bits(u32::from_le_bytes($r.take())))
    };
    ($r:ident, u32) => {
        f64::from(u32::from_le_bytes($r.take()))
    };
    ($r:ident, u16 $step:literal) => {
        u16_value(u16::from_le_bytes($r.take()), $step)
    };
    ($r:ident, i16 $step:literal) => {
        i16_value(i16::from_le_bytes($r.take()), $step)
    };
}

/// A value as the wire carries it, without the byte layout.
macro_rules! carried {
    ($v:expr, f32) => {
        f64::from($v)
    };
    ($v:expr, u32) => {
        f64::from($v)
    };
    ($v:expr, u16 $step:literal) => {
        u16_value(u16_code($v, const { 1.0f32 / $step }), $step)
    };
    ($v:expr, i16 $step:literal) => {
        i16_value(i16_code($v, const { 1.0f32 / $step }), $step)
    };
}

/// Makes the record from the table: rows
/// `column [SI unit, encoding] shown [key, unit, scale, decimals] = |e| value;`,
/// each with its doc comment (one line: it is the documentation's
/// description of the column); then `@monitor:` and the rows only an image
/// with the condition monitor sends ([`Layout::Monitor`]).
macro_rules! telemetry_table {
    ($(
        $(#[doc = $doc:literal])*
        $column:ident [$unit:literal, $wire:ident $($step:literal)?]
            shown [$key:literal, $shown:literal, $scale:literal, $decimals:literal]
            = $value:expr;
    )*
    @monitor:
    $(
        $(#[doc = $mdoc:literal])*
        $mcolumn:ident [$munit:literal, $mwire:ident $($mstep:literal)?]
            shown [$mkey:literal, $mshown:literal, $mscale:literal, $mdecimals:literal]
            = $mvalue:expr;
    )*) => {
        /// One telemetry record in SI units, a field per column of the
        /// table (`f64`: a decoded record, or an estimate as the wire
        /// carries it; the monitor's columns NaN in a record without them),
        /// and the flags.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Record {
            $(
                $(#[doc = $doc])*
                #[doc = concat!("Unit: ", $unit, "; sent as ", stringify!($wire $($step)?), ".")]
                pub $column: f64,
            )*
            $(
                $(#[doc = $mdoc])*
                #[doc = concat!("Unit: ", $munit, "; sent as ", stringify!($mwire $($mstep)?), ", by an image with the condition monitor only (NaN in a record without it).")]
                pub $mcolumn: f64,
            )*
            /// Conditions.
            pub flags: Flags,
        }

        /// The fields of the record, in wire order: the plain layout's,
        /// then from [`HEALTH_FROM`] on the monitor's.
        pub const FIELDS: [Field; [$(stringify!($column),)* $(stringify!($mcolumn)),*].len()] = [$(
            Field {
                column: stringify!($column),
                unit: $unit,
                encoding: encoding!($wire $($step)?),
                key: $key,
                shown_unit: $shown,
                scale: $scale,
                decimals: $decimals,
                doc: concat!($($doc),*),
            },
        )* $(
            Field {
                column: stringify!($mcolumn),
                unit: $munit,
                encoding: encoding!($mwire $($mstep)?),
                key: $mkey,
                shown_unit: $mshown,
                scale: $mscale,
                decimals: $mdecimals,
                doc: concat!($($mdoc),*),
            },
        )*];

        /// Index in [`FIELDS`] of the first of the monitor's fields (the
        /// plain layout's count).
        pub const HEALTH_FROM: usize = [$(stringify!($column)),*].len();

        /// The plain layout's tag ([`Layout::Plain`]): sent first in every
        /// record of an image without the monitor.
        pub const LAYOUT: u16 = layout_of(FIELDS.split_at(HEALTH_FROM).0);

        /// The monitor layout's tag ([`Layout::Monitor`]).
        pub const LAYOUT_MONITOR: u16 = layout_of(&FIELDS);

        /// Bytes in a plain record: the layout tag, the fields, the flags.
        pub const SIZE: usize = 2 $(+ encoding!($wire $($step)?).size())* + 4;

        /// Bytes in a record with the monitor's fields.
        pub const SIZE_MONITOR: usize = SIZE $(+ encoding!($mwire $($mstep)?).size())*;

        /// The bytes of `e`'s plain telemetry record (see the module docs).
        /// A store per field, no branch but the 16-bit encodings'
        /// saturation: the firmware calls it on a telemetry tick.
        #[inline]
        pub fn encode(e: &StateEstimate) -> [u8; SIZE] {
            let mut w = Writer { bytes: [0; SIZE], at: 0 };
            w.put(LAYOUT.to_le_bytes());
            $(
                let get: fn(&StateEstimate) -> wire_type!($wire) = $value;
                put!(w, get(e), $wire $($step)?);
            )*
            w.put(e.flags.0.to_le_bytes());
            w.bytes
        }

        /// The bytes of `e`'s record with the monitor's fields (an image
        /// with a second sensor), as [`encode`].
        #[inline]
        pub fn encode_monitor(e: &StateEstimate) -> [u8; SIZE_MONITOR] {
            let mut w = Writer { bytes: [0; SIZE_MONITOR], at: 0 };
            w.put(LAYOUT_MONITOR.to_le_bytes());
            $(
                let get: fn(&StateEstimate) -> wire_type!($wire) = $value;
                put!(w, get(e), $wire $($step)?);
            )*
            $(
                let get: fn(&StateEstimate) -> wire_type!($mwire) = $mvalue;
                put!(w, get(e), $mwire $($mstep)?);
            )*
            w.put(e.flags.0.to_le_bytes());
            w.bytes
        }

        impl Record {
            /// The record of `bytes`, packed by [`encode`] or
            /// [`encode_monitor`] (told apart by their tags).
            ///
            /// # Errors
            ///
            /// [`DecodeError::Layout`] for a record of another table,
            /// [`DecodeError::Length`] for a byte string of another length
            /// than its tag's layout packs ([`SIZE`], [`SIZE_MONITOR`]).
            pub fn decode(bytes: &[u8]) -> Result<Record, DecodeError> {
                let mut r = Reader { bytes, at: 0 };
                let layout = u16::from_le_bytes(r.take());
                let (monitored, expected) = if bytes.len() < 2 {
                    (false, SIZE)
                } else if layout == LAYOUT {
                    (false, SIZE)
                } else if layout == LAYOUT_MONITOR {
                    (true, SIZE_MONITOR)
                } else {
                    return Err(DecodeError::Layout { expected: LAYOUT, got: layout });
                };
                if bytes.len() != expected {
                    return Err(DecodeError::Length { expected, got: bytes.len() });
                }
                // Struct fields are evaluated in the order written: wire order.
                Ok(Record {
                    $( $column: get!(r, $wire $($step)?), )*
                    $( $mcolumn: if monitored { get!(r, $mwire $($mstep)?) } else { f64::NAN }, )*
                    flags: Flags(u32::from_le_bytes(r.take())),
                })
            }

            /// `e` as a record of an image without the monitor carries it
            /// ([`Record::of_layout`] with [`Layout::Plain`]: the monitor's
            /// columns NaN).
            pub fn of(e: &StateEstimate) -> Record {
                Record::of_layout(e, Layout::Plain)
            }

            /// `e` as its record of `layout` carries it (quantised as the
            /// wire quantises), computed from the estimate without the byte
            /// layout; the monitor's columns NaN in [`Layout::Plain`].
            pub fn of_layout(e: &StateEstimate, layout: Layout) -> Record {
                let monitored = layout == Layout::Monitor;
                Record {
                    $( $column: {
                        let get: fn(&StateEstimate) -> wire_type!($wire) = $value;
                        carried!(get(e), $wire $($step)?)
                    }, )*
                    $( $mcolumn: if monitored {
                        let get: fn(&StateEstimate) -> wire_type!($mwire) = $mvalue;
                        carried!(get(e), $mwire $($mstep)?)
                    } else {
                        f64::NAN
                    }, )*
                    flags: e.flags,
                }
            }

            /// The layout the record came in: [`Layout::Monitor`] when any
            /// of the monitor's columns holds a number (its `u32` count
            /// always does), else [`Layout::Plain`].
            pub fn layout(&self) -> Layout {
                if false $(|| !self.$mcolumn.is_nan())* {
                    Layout::Monitor
                } else {
                    Layout::Plain
                }
            }

            /// The values, in the order of [`FIELDS`].
            pub fn values(&self) -> [f64; FIELDS.len()] {
                [$(self.$column,)* $(self.$mcolumn),*]
            }

            /// The record of `values` (in the order of [`FIELDS`]) and
            /// `flags`.
            pub fn from_values(values: [f64; FIELDS.len()], flags: Flags) -> Record {
                let [$($column,)* $($mcolumn),*] = values;
                Record { $($column,)* $($mcolumn,)* flags }
            }
        }
    };
}

// The record. Units: the column's suffix and the SI unit agree; the log
// line shows engineering units rounded to what the sensor and the model
// resolve (0.01 C: one MAX31865 code is 0.033 C with a PT100 and 430 ohm,
// and moves x by up to 1.3 um, the pressures by 0.3 kPa and the flows by
// 0.009 l/min at the paper preset, from the 4 C steps of the QEMU twin's
// static table). `x*` and `dx/dt` stay out: they are in `StateEstimate`
// for whoever needs them.
telemetry_table! {
    /// The probe's last accepted reading.
    t_probe_c ["C", f32] shown ["t_probe", "C", 1.0, 2] = |e| e.t_probe;
    /// Estimated oil temperature (the observer's: the probe's lag undone).
    t_oil_c ["C", f32] shown ["t", "C", 1.0, 2] = |e| e.temperature;
    /// Standard uncertainty (k = 1) of the oil temperature.
    t_oil_sd_c ["C", f32] shown ["u_t", "C", 1.0, 3] = |e| e.uncertainty.t_oil;
    /// Plunger displacement.
    x_m ["m", f32] shown ["x", "um", 1e6, 1] = |e| e.x;
    /// Standard uncertainty of the displacement (of the free displacement at a stop).
    x_sd_m ["m", f32] shown ["u_x", "um", 1e6, 2] = |e| e.uncertainty.x;
    /// Plunger velocity.
    v_m_s ["m/s", f32] shown ["v", "mm/s", 1e3, 3] = |e| e.v;
    /// Chamber (a) pressure.
    p_a_pa ["Pa", f32] shown ["p_a", "kPa", 1e-3, 1] = |e| e.p_a;
    /// Standard uncertainty of the chamber (a) pressure.
    p_a_sd_pa ["Pa", f32] shown ["u_p_a", "kPa", 1e-3, 2] = |e| e.uncertainty.p_a;
    /// Chamber (b) pressure.
    p_b_pa ["Pa", f32] shown ["p_b", "kPa", 1e-3, 1] = |e| e.p_b;
    /// Standard uncertainty of the chamber (b) pressure.
    p_b_sd_pa ["Pa", f32] shown ["u_p_b", "kPa", 1e-3, 2] = |e| e.uncertainty.p_b;
    /// Flow leaving chamber (a) through its capillary.
    q_a_m3s ["m^3/s", f32] shown ["Q_a", "l/min", 6e4, 3] = |e| e.q_a;
    /// Flow leaving chamber (b) through its orifice.
    q_b_m3s ["m^3/s", f32] shown ["Q_b", "l/min", 6e4, 3] = |e| e.q_b;
    /// Flow through the window.
    q_throt_m3s ["m^3/s", f32] shown ["Q_throt", "l/min", 6e4, 3] = |e| e.q_throt;
    /// Total flow Q0 = Q_a + Q_b + Q_throt.
    q_total_m3s ["m^3/s", f32] shown ["Q0", "l/min", 6e4, 3] = |e| e.q_total;
    /// Standard uncertainty of the total flow.
    q_total_sd_m3s ["m^3/s", f32] shown ["u_Q0", "l/min", 6e4, 4] = |e| e.uncertainty.q_total;
    /// Q0 - (Q_work + dQ_lost(t)); NaN without a `[machine]` section.
    compensation_error_m3s ["m^3/s", f32] shown ["err", "l/min", 6e4, 3] = |e| e.compensation_error;
    /// Standard uncertainty of the compensation error; NaN without a `[machine]` section.
    compensation_error_sd_m3s ["m^3/s", f32] shown ["u_err", "l/min", 6e4, 4] = |e| e.uncertainty.compensation_error;
    /// Times the consistency check re-seated the twin since start.
    reseats ["-", u32] shown ["reseats", "", 1.0, 0] = |e| e.reseats;
    /// Tick deadlines the controller missed since start.
    deadline_misses ["-", u32] shown ["missed", "", 1.0, 0] = |e| e.deadline_misses;
    /// Ticks of real time the twin did not advance through since start.
    lost_ticks ["-", u32] shown ["lost", "", 1.0, 0] = |e| e.lost_ticks;
@monitor:
    // The condition monitor's health parameters at its last reading
    // (`crate::monitor::HealthEstimate`; NaN until its first). The offset
    // is in the second sensor's unit, Pa or m: seven decimals show 0.1 um
    // of a displacement sensor's zero.
    /// The divider factor A / A_file the monitor estimates (above 1: a restricted capillary or a worn orifice).
    divider ["-", f32] shown ["A", "", 1.0, 4] = |e| e.health.divider;
    /// Standard deviation of ln(divider): the divider factor's relative standard uncertainty.
    divider_sd ["-", f32] shown ["u_A", "", 1.0, 4] = |e| e.health.sd_divider;
    /// The spring rate's factor c / c_file (1 from a pressure sensor, which does not see the spring).
    spring ["-", f32] shown ["k", "", 1.0, 4] = |e| e.health.spring;
    /// Standard deviation of ln(spring): the spring factor's relative standard uncertainty.
    spring_sd ["-", f32] shown ["u_k", "", 1.0, 4] = |e| e.health.sd_spring;
    /// The second sensor's reading offset, in its unit (Pa for a pressure, m for x).
    sensor_offset ["Pa or m", f32] shown ["off", "", 1.0, 7] = |e| e.health.offset;
    /// Standard deviation of the offset, in the second sensor's unit.
    sensor_offset_sd ["Pa or m", f32] shown ["u_off", "", 1.0, 7] = |e| e.health.sd_offset;
    /// The friction force holding the plunger (0 until sticking is named).
    friction_n ["N", f32] shown ["F", "N", 1.0, 3] = |e| e.health.friction;
    /// The larger of the monitor's two CUSUM statistics, in innovation standard deviations.
    cusum ["-", f32] shown ["cusum", "", 1.0, 2] = |e| e.health.cusum;
    /// Second-sensor readings the monitor did not apply since start (beyond its gate, or not finite).
    rejected ["-", u32] shown ["rejected", "", 1.0, 0] = |e| e.health.rejected;
    /// The oil-temperature probe's error at the oil temperature, its place within its IEC 60751 tolerance times the tolerance.
    probe_bias_k ["K", f32] shown ["dT_p", "K", 1.0, 3] = |e| e.health.probe_bias;
    /// Standard deviation of the probe's error.
    probe_bias_sd_k ["K", f32] shown ["u_dT_p", "K", 1.0, 3] = |e| e.health.sd_probe_bias;
    /// The oil temperature the second sensor's reading gives through the health estimate (the twin's where it does not depend on it).
    t_monitor_c ["C", f32] shown ["T_s", "C", 1.0, 3] = |e| e.health.oil;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate() -> StateEstimate {
        let mut e = StateEstimate::without_physics(7, 35.789177, 35.5, 3, Flags::AT_STOP);
        e.x = 12.860147e-6;
        e.v = 0.03813392e-3;
        e.p_a = 196205.72;
        e.p_b = 203794.24;
        e.q_a = 5.1e-6;
        e.q_b = 5.2e-6;
        e.q_throt = 1.5e-6;
        e.q_total = 1.18e-5;
        e
    }

    fn bits(r: &Record) -> [u64; FIELDS.len()] {
        r.values().map(f64::to_bits)
    }

    #[test]
    fn a_record_decodes_to_what_the_estimate_carries() {
        let e = estimate();
        let bytes = encode(&e);
        assert_eq!(bytes.len(), SIZE);
        let r = Record::decode(&bytes).unwrap();
        assert_eq!(bits(&r), bits(&Record::of(&e)));
        assert_eq!(r.x_m, f64::from(12.860147e-6f32));
        assert_eq!(r.reseats, 3.0);
        assert!(r.compensation_error_m3s.is_nan());
        assert_eq!(r.flags, Flags::AT_STOP);
        assert_eq!(
            Record::from_values(r.values(), r.flags).values().map(f64::to_bits),
            bits(&r)
        );
    }

    #[test]
    fn a_record_of_another_length_or_table_is_refused() {
        let mut bytes = encode(&estimate());
        assert_eq!(
            Record::decode(&bytes[..SIZE - 1]),
            Err(DecodeError::Length {
                expected: SIZE,
                got: SIZE - 1
            })
        );
        bytes[0] ^= 1;
        assert!(matches!(Record::decode(&bytes), Err(DecodeError::Layout { .. })));
    }

    #[test]
    fn the_layout_follows_the_table() {
        let plain = &FIELDS[..HEALTH_FROM];
        assert_eq!(layout_of(plain), LAYOUT);
        assert_eq!(layout_of(&FIELDS), LAYOUT_MONITOR);
        assert_ne!(LAYOUT, LAYOUT_MONITOR);
        let mut other = FIELDS;
        other.swap(1, 2);
        assert_ne!(layout_of(&other[..HEALTH_FROM]), LAYOUT, "a reordered table");
        let mut other = FIELDS;
        other[0].encoding = Encoding::U16 { step: 1e-3 };
        assert_ne!(layout_of(&other[..HEALTH_FROM]), LAYOUT, "another encoding");
        assert_ne!(layout_of(&plain[..plain.len() - 1]), LAYOUT, "a field less");
        assert_ne!(
            layout_of(&FIELDS[..FIELDS.len() - 1]),
            LAYOUT_MONITOR,
            "a health field less"
        );
    }

    #[test]
    fn the_table_is_consistent() {
        // The layout tag (2 bytes), the fields, the flags (4 bytes).
        let mut size = 6;
        for (i, f) in FIELDS.iter().enumerate() {
            if i == HEALTH_FROM {
                assert_eq!(size, SIZE, "the plain layout's size");
            }
            size += f.encoding.size();
            assert!(!f.doc.trim().is_empty(), "{}: a description", f.column);
            assert!(f.scale > 0.0 && !f.unit.is_empty(), "{}", f.column);
            assert!(
                FIELDS[..i].iter().all(|g| g.column != f.column && g.key != f.key),
                "{}: columns and keys are unique",
                f.column
            );
        }
        assert_eq!(size, SIZE_MONITOR);
        assert_eq!(Layout::Plain.fields().len(), HEALTH_FROM);
        assert_eq!(Layout::Monitor.fields().len(), FIELDS.len());
        assert_eq!((Layout::Plain.size(), Layout::Monitor.size()), (SIZE, SIZE_MONITOR));
        // The health columns begin with these nine, each its
        // `HealthEstimate` field: divider, spring and offset with their
        // standard deviations, the friction, the CUSUM, the rejected
        // readings (a parameter added later goes after them).
        let health: [&str; 9] = core::array::from_fn(|i| FIELDS[HEALTH_FROM + i].column);
        assert_eq!(
            health,
            [
                "divider",
                "divider_sd",
                "spring",
                "spring_sd",
                "sensor_offset",
                "sensor_offset_sd",
                "friction_n",
                "cusum",
                "rejected"
            ]
        );
    }

    /// An estimate with a health estimate of distinct values.
    fn monitored() -> StateEstimate {
        let mut e = estimate();
        // Field by field: a parameter the monitor adds keeps its NONE.
        let h = &mut e.health;
        h.divider = 1.25;
        h.sd_divider = 0.012;
        h.spring = 0.97;
        h.sd_spring = 0.05;
        h.offset = -123.5;
        h.sd_offset = 288.7;
        h.friction = 0.75;
        h.cusum = 4.5;
        h.rejected = 17;
        h.probe_bias = -0.25;
        h.sd_probe_bias = 0.18;
        h.oil = 47.5;
        h.flags = Flags::CAPILLARY_RESTRICTED;
        e.flags.insert(Flags::CAPILLARY_RESTRICTED);
        e
    }

    #[test]
    fn a_record_with_the_monitor_carries_the_health_estimate() {
        let e = monitored();
        let bytes = encode_monitor(&e);
        assert_eq!(bytes.len(), SIZE_MONITOR);
        assert_eq!(&bytes[..2], &LAYOUT_MONITOR.to_le_bytes());
        let r = Record::decode(&bytes).unwrap();
        assert_eq!(bits(&r), bits(&Record::of_layout(&e, Layout::Monitor)));
        assert_eq!(r.layout(), Layout::Monitor);
        assert_eq!(r.divider, 1.25);
        assert_eq!(r.divider_sd, f64::from(0.012f32));
        assert_eq!(r.spring, f64::from(0.97f32));
        assert_eq!(r.sensor_offset, -123.5);
        assert_eq!(r.sensor_offset_sd, f64::from(288.7f32));
        assert_eq!(r.friction_n, 0.75);
        assert_eq!(r.cusum, 4.5);
        assert_eq!(r.rejected, 17.0);
        assert_eq!(r.probe_bias_k, -0.25);
        assert_eq!(r.probe_bias_sd_k, f64::from(0.18f32));
        assert_eq!(r.t_monitor_c, 47.5);
        assert_eq!(r.flags, e.flags);
        // The plain part is the plain record's, byte for byte.
        let plain = encode(&e);
        assert_eq!(&bytes[2..SIZE - 4], &plain[2..SIZE - 4]);
        assert_eq!(&bytes[SIZE_MONITOR - 4..], &plain[SIZE - 4..]);
    }

    #[test]
    fn a_record_without_the_monitor_has_nan_health_columns() {
        // The same estimate, packed by an image without the monitor: the
        // health columns are not sent, and read as NaN.
        let e = monitored();
        let r = Record::decode(&encode(&e)).unwrap();
        assert_eq!(r.layout(), Layout::Plain);
        assert_eq!(bits(&r), bits(&Record::of(&e)));
        let values = r.values();
        assert!(values[HEALTH_FROM..].iter().all(|v| v.is_nan()));
        assert_eq!(r.x_m, f64::from(e.x));
        // A monitor record cut to the plain size is refused by its tag's length.
        let bytes = encode_monitor(&e);
        assert_eq!(
            Record::decode(&bytes[..SIZE]),
            Err(DecodeError::Length {
                expected: SIZE_MONITOR,
                got: SIZE
            })
        );
        assert_eq!(Record::decode(&[]), Err(DecodeError::Length { expected: SIZE, got: 0 }));
    }

    /// A table with a field of every encoding, through the same macro.
    mod every_encoding {
        use super::super::*;
        telemetry_table! {
            /// Displacement, 0.1 um codes.
            x_m ["m", u16 1e-7] shown ["x", "um", 1e6, 1] = |e| e.x;
            /// Pressure, 10 Pa codes.
            p_a_pa ["Pa", i16 10.0] shown ["p_a", "kPa", 1e-3, 2] = |e| e.p_a;
            /// Velocity.
            v_m_s ["m/s", f32] shown ["v", "mm/s", 1e3, 3] = |e| e.v;
            /// Count.
            reseats ["-", u32] shown ["reseats", "", 1.0, 0] = |e| e.reseats;
        @monitor:
            /// A health parameter, 1e-4 codes.
            divider ["-", u16 1e-4] shown ["A", "", 1.0, 4] = |e| e.health.divider;
            /// A count.
            rejected ["-", u32] shown ["rejected", "", 1.0, 0] = |e| e.health.rejected;
        }
    }

    #[test]
    fn every_encoding_packs_and_decodes_as_the_estimate_carries_it() {
        use every_encoding::{FIELDS, Record, SIZE, SIZE_MONITOR, encode, encode_monitor};
        assert_eq!(SIZE, 2 + 2 + 2 + 4 + 4 + 4);
        assert_eq!(SIZE_MONITOR, SIZE + 2 + 4);
        let mut e = estimate();
        for (x, p_a) in [
            (12.86e-6, 196205.72),
            (-1.0, -1e9),
            (f32::NAN, f32::INFINITY),
            (1.0, f32::NAN),
        ] {
            e.x = x;
            e.p_a = p_a;
            let r = Record::decode(&encode(&e)).unwrap();
            assert_eq!(r.values().map(f64::to_bits), Record::of(&e).values().map(f64::to_bits));
            assert_eq!(r.v_m_s, f64::from(e.v));
            assert_eq!(r.reseats, 3.0);
            assert_eq!(
                Record::from_values(r.values(), r.flags).values().map(f64::to_bits),
                r.values().map(f64::to_bits)
            );
        }
        let r = Record::of(&estimate());
        assert_eq!(r.x_m, 129.0 * 1e-7);
        assert_eq!(r.p_a_pa, 19621.0 * 10.0);
        // The monitor's part: a 16-bit health field and a count.
        e.health.divider = 1.23456;
        e.health.rejected = 9;
        let r = Record::decode(&encode_monitor(&e)).unwrap();
        assert_eq!(r.layout(), Layout::Monitor);
        assert_eq!(r.divider, 12346.0 * 1e-4);
        assert_eq!(r.rejected, 9.0);
        assert_eq!(
            r.values().map(f64::to_bits),
            Record::of_layout(&e, Layout::Monitor).values().map(f64::to_bits)
        );
        assert!(Record::decode(&encode(&e)).unwrap().divider.is_nan());
        // Two tables, two layouts: neither decodes the other's records.
        assert_ne!(every_encoding::LAYOUT, LAYOUT);
        assert_ne!(every_encoding::LAYOUT_MONITOR, LAYOUT_MONITOR);
        assert!(super::Record::decode(&encode(&e)).is_err());
        assert!(super::Record::decode(&encode_monitor(&e)).is_err());
        assert_eq!(FIELDS[0].encoding, Encoding::U16 { step: 1e-7 });
        assert_eq!(FIELDS[0].encoding.describe().to_string(), "u16 x 1e-7");
    }

    #[test]
    fn sixteen_bit_codes_saturate_and_keep_nan() {
        let per = 1.0 / 1e-3f32;
        assert_eq!(u16_code(0.0123, per), 12);
        assert_eq!(u16_code(0.0126, per), 13);
        assert_eq!(u16_code(-1.0, per), 0);
        assert_eq!(u16_code(65.5334, per), 65533);
        assert_eq!(u16_code(65.534, per), U16_ABOVE);
        assert_eq!(u16_code(f32::INFINITY, per), U16_ABOVE);
        assert_eq!(u16_code(f32::NAN, per), U16_NAN);
        assert_eq!(u16_value(12, 1e-3), 0.012);
        assert_eq!(u16_value(U16_ABOVE, 1e-3), f64::INFINITY);
        assert!(u16_value(U16_NAN, 1e-3).is_nan());

        assert_eq!(i16_code(-0.0123, per), -12);
        assert_eq!(i16_code(-0.0126, per), -13);
        assert_eq!(i16_code(0.0126, per), 13);
        assert_eq!(i16_code(0.0, per), 0);
        assert_eq!(i16_code(-32.766, per), -32766);
        assert_eq!(i16_code(32.766, per), 32766);
        assert_eq!(i16_code(32.767, per), I16_ABOVE);
        assert_eq!(i16_code(-32.767, per), I16_BELOW);
        assert_eq!(i16_code(f32::NEG_INFINITY, per), I16_BELOW);
        assert_eq!(i16_code(f32::NAN, per), I16_NAN);
        assert_eq!(i16_value(I16_BELOW, 1e-3), f64::NEG_INFINITY);
        assert_eq!(i16_value(I16_ABOVE, 1e-3), f64::INFINITY);
        assert!(i16_value(I16_NAN, 1e-3).is_nan());
    }

    #[test]
    fn tolerances_are_a_tenth_of_the_display_or_one_code() {
        let x = FIELDS.iter().find(|f| f.column == "x_m").unwrap();
        assert!((x.resolution() - 1e-7).abs() < 1e-20);
        assert!((x.tolerance(0.0) - 1e-8).abs() < 1e-20);
        let sd = Field {
            encoding: Encoding::U16 { step: 1e-6 },
            ..*x
        };
        assert_eq!(sd.tolerance(0.0), 1e-6);
    }
}
