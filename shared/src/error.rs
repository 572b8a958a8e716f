//! Errors raised where parameters enter the core API.
//!
//! Every constructor that takes a physical number checks it once, here at the boundary, so that no
//! integrator or root finder ever sees a NaN, an infinity or a non-positive length.

use core::fmt;

/// A parameter outside its allowed range: which one, its value, and what is allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamError {
    pub name: &'static str,
    pub value: f64,
    pub allowed: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {} is out of range: allowed {}",
            self.name,
            Compact(self.value),
            self.allowed
        )
    }
}

/// A number as an error message shows it: plainly at ordinary magnitudes, in exponent form
/// beyond them, so that 1e300 reads as `1e300` and not as 301 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compact(pub f64);

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a.is_finite() && a != 0.0 && !(1e-6..1e15).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ParamError {}

/// The ranges numbers are checked against, each with the words its error messages use: the one
/// definition behind the core's checks and the command line's and scene files' messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Range {
    /// A finite number > 0.
    Positive,
    /// A finite number ≥ 0.
    NonNegative,
    /// Any finite number.
    Finite,
}

impl Range {
    pub fn admits(self, value: f64) -> bool {
        value.is_finite()
            && match self {
                Range::Positive => value > 0.0,
                Range::NonNegative => value >= 0.0,
                Range::Finite => true,
            }
    }

    /// What is allowed, as messages say it.
    pub fn allowed(self) -> &'static str {
        match self {
            Range::Positive => "a finite number > 0",
            Range::NonNegative => "a finite number >= 0",
            Range::Finite => "a finite number",
        }
    }

    /// `value` if the range admits it, else the error naming the parameter.
    pub fn check(self, name: &'static str, value: f64) -> Result<f64, ParamError> {
        if self.admits(value) {
            Ok(value)
        } else {
            Err(ParamError {
                name,
                value,
                allowed: self.allowed(),
            })
        }
    }
}

/// Accepts a finite number > 0.
pub fn positive(name: &'static str, value: f64) -> Result<f64, ParamError> {
    Range::Positive.check(name, value)
}

/// Accepts a finite number ≥ 0.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    Range::NonNegative.check(name, value)
}

/// Accepts any finite number.
pub fn finite(name: &'static str, value: f64) -> Result<f64, ParamError> {
    Range::Finite.check(name, value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_and_tiny_numbers_are_shown_in_exponent_form() {
        assert_eq!(format!("{}", Compact(1e300)), "1e300");
        assert_eq!(format!("{}", Compact(-2.5e-9)), "-2.5e-9");
        assert_eq!(format!("{}", Compact(330.0)), "330");
        assert_eq!(format!("{}", Compact(0.0)), "0");
        assert_eq!(format!("{}", Compact(f64::INFINITY)), "inf");
    }

    #[test]
    fn rejects_nan_inf_and_sign() {
        assert!(positive("x", f64::NAN).is_err());
        assert!(positive("x", f64::INFINITY).is_err());
        assert!(positive("x", 0.0).is_err());
        assert!(non_negative("x", -1e-300).is_err());
        assert_eq!(non_negative("x", 0.0), Ok(0.0));
        assert!(finite("x", f64::NEG_INFINITY).is_err());
    }
}
