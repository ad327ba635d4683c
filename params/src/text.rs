//! How messages show numbers and echo the user's input: compactly, on one
//! line, with a bounded length, so that an error is always one short line
//! whatever the file held (a value of `1e300` is not 301 digits, a 100 MB
//! key is not echoed whole, a key with a newline does not break the line).

use core::fmt::{self, Write as _};

/// An `f64` in a short form: plain decimal (`0.0015`, `1000`, `25000.5`)
/// unless the exponent form is shorter by two characters or more (`1e300`,
/// `5e-324`, `1e-5`, `4e5`): short numbers stay as people write them, long
/// runs of zeros go. Both forms are Rust's shortest round-trip digits, so
/// the text reads back as the same value; it is at most 24 characters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compact(pub f64);

/// Counts the bytes written, writes nothing.
struct Count(usize);

impl fmt::Write for Count {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let (mut plain, mut exp) = (Count(0), Count(0));
        write!(plain, "{v}")?;
        write!(exp, "{v:e}")?;
        if exp.0 + 2 <= plain.0 {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

/// How many characters of the user's input a message echoes at most.
pub const ECHO_MAX: usize = 64;

/// Text from the user's input (a key, a path, a parser's message) as a
/// message shows it: control characters escaped (`\n`, `\u{1b}`), so it
/// stays on one line, and at most `max` characters of it, the cut marked
/// with an ellipsis (`…`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Echo<'a> {
    text: &'a str,
    max: usize,
    keep_end: bool,
}

impl<'a> Echo<'a> {
    /// The beginning of `text` (keys, messages): at most [`ECHO_MAX`]
    /// characters.
    pub fn head(text: &'a str) -> Self {
        Echo {
            text,
            max: ECHO_MAX,
            keep_end: false,
        }
    }

    /// The end of `text` (file paths, whose last part names the file): at
    /// most [`ECHO_MAX`] characters.
    pub fn tail(text: &'a str) -> Self {
        Echo {
            text,
            max: ECHO_MAX,
            keep_end: true,
        }
    }

    /// The same with at most `max` characters.
    pub fn max(self, max: usize) -> Self {
        Echo { max, ..self }
    }
}

fn write_escaped(f: &mut fmt::Formatter<'_>, text: &str) -> fmt::Result {
    for c in text.chars() {
        if c.is_control() {
            write!(f, "{}", c.escape_default())?;
        } else {
            f.write_char(c)?;
        }
    }
    Ok(())
}

impl fmt::Display for Echo<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.text.chars().count();
        if n <= self.max {
            return write_escaped(f, self.text);
        }
        let keep = self.max.saturating_sub(1);
        if self.keep_end {
            let (at, _) = self.text.char_indices().nth(n - keep).unwrap_or((0, ' '));
            f.write_char('…')?;
            write_escaped(f, &self.text[at..])
        } else {
            let at = self.text.char_indices().nth(keep).map_or(self.text.len(), |(i, _)| i);
            write_escaped(f, &self.text[..at])?;
            f.write_char('…')
        }
    }
}
