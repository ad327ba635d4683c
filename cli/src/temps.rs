//! Temperature lists: `a:b:step` (inclusive of `b` when it falls on the
//! grid) or a comma-separated list.

use std::fmt;

/// Why a temperature list was rejected (one line).
#[derive(Debug, Clone, PartialEq)]
pub struct TempsError(pub String);

impl fmt::Display for TempsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "--temps: {}", self.0)
    }
}

impl std::error::Error for TempsError {}

/// At most this many temperatures in one list.
pub const MAX_TEMPS: usize = 1_000_000;

fn number(s: &str) -> Result<f64, TempsError> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| TempsError(format!("'{s}' is not a number")))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(TempsError(format!("'{s}' is not finite")))
    }
}

/// Parses `a:b:step` or `t1,t2,...` into temperatures [C].
pub fn parse(spec: &str) -> Result<Vec<f64>, TempsError> {
    let spec = spec.trim();
    if spec.is_empty() {
        return Err(TempsError("empty".into()));
    }
    if spec.contains(':') {
        let parts: Vec<&str> = spec.split(':').collect();
        if parts.len() != 3 {
            return Err(TempsError(format!("'{spec}' is not of the form start:end:step")));
        }
        let (a, b, step) = (number(parts[0])?, number(parts[1])?, number(parts[2])?);
        if !(step > 0.0) {
            return Err(TempsError(format!("step {step} must be positive")));
        }
        if b < a {
            return Err(TempsError(format!("end {b} is below start {a}")));
        }
        let n = ((b - a) / step + 1e-9).floor();
        if n + 1.0 > MAX_TEMPS as f64 {
            return Err(TempsError(format!("more than {MAX_TEMPS} temperatures")));
        }
        Ok((0..=n as usize).map(|i| a + step * i as f64).collect())
    } else {
        let v: Vec<f64> = spec.split(',').map(number).collect::<Result<_, _>>()?;
        if v.len() > MAX_TEMPS {
            return Err(TempsError(format!("more than {MAX_TEMPS} temperatures")));
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_lists() {
        assert_eq!(parse("30:80:10").unwrap(), vec![30.0, 40.0, 50.0, 60.0, 70.0, 80.0]);
        assert_eq!(parse("30:35:10").unwrap(), vec![30.0]);
        assert_eq!(parse("26.5, 30").unwrap(), vec![26.5, 30.0]);
        assert!(parse("30:80:0").is_err());
        assert!(parse("80:30:10").is_err());
        assert!(parse("30,x").is_err());
        assert!(parse("nan").is_err());
        assert!(parse("0:1e12:1e-6").is_err());
    }
}
