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
            self.name, self.value, self.allowed
        )
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ParamError {}

/// Accepts a finite number > 0.
pub fn positive(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            allowed: "a finite number > 0",
        })
    }
}

/// Accepts a finite number ≥ 0.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            allowed: "a finite number >= 0",
        })
    }
}

/// Accepts any finite number.
pub fn finite(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError {
            name,
            value,
            allowed: "a finite number",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
