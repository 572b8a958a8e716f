//! The number formats the simulator runs in: f64 and f32, behind one small trait.
//!
//! Every transcendental goes through libm here, on the host as on the microcontroller, so an f32
//! run on the host computes exactly what the target would.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A floating-point format: f64 or f32.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Send
    + Sync
    + 'static
{
    const ZERO: Self;
    const ONE: Self;
    /// The format's name, for reports: "f64" or "f32".
    const NAME: &'static str;
    /// Machine epsilon.
    const EPSILON: Self;

    fn from_f64(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn sqrt(self) -> Self;
    fn exp(self) -> Self;
    fn abs(self) -> Self;
    fn is_finite(self) -> bool;

    /// (sin ϕ, cos ϕ) of a drive phase kept in f64. f64 evaluates it directly; f32 first
    /// reduces ϕ to (−π, π] in f64, since the phase grows without bound and f32 would lose it.
    fn sin_cos_phase(phase: f64) -> (Self, Self);
    /// cos ϕ alone, reduced the same way (cheaper than both when only it is needed).
    fn cos_phase(phase: f64) -> Self;

    fn max(self, other: Self) -> Self {
        if self > other {
            self
        } else {
            other
        }
    }
    fn min(self, other: Self) -> Self {
        if self < other {
            self
        } else {
            other
        }
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const NAME: &'static str = "f64";
    const EPSILON: Self = f64::EPSILON;

    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sin(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cos(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        libm::sincos(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    #[inline]
    fn exp(self) -> Self {
        libm::exp(self)
    }
    #[inline]
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline]
    fn sin_cos_phase(phase: f64) -> (Self, Self) {
        libm::sincos(phase)
    }
    #[inline]
    fn cos_phase(phase: f64) -> Self {
        libm::cos(phase)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const NAME: &'static str = "f32";
    const EPSILON: Self = f32::EPSILON;

    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sinf(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cosf(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        libm::sincosf(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        libm::sqrtf(self)
    }
    #[inline]
    fn exp(self) -> Self {
        libm::expf(self)
    }
    #[inline]
    fn abs(self) -> Self {
        libm::fabsf(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline]
    fn sin_cos_phase(phase: f64) -> (Self, Self) {
        libm::sincosf(crate::math::wrap_pi(phase) as f32)
    }
    #[inline]
    fn cos_phase(phase: f64) -> Self {
        libm::cosf(crate::math::wrap_pi(phase) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn generic_identity<R: Real>(x: f64) -> f64 {
        let (s, c) = R::from_f64(x).sin_cos();
        (s * s + c * c).to_f64()
    }

    #[test]
    fn both_formats_agree_with_closed_forms() {
        // sin² + cos² = 1 to a few ulp of each format.
        assert!((generic_identity::<f64>(1.3) - 1.0).abs() < 4.0 * f64::EPSILON);
        assert!((generic_identity::<f32>(1.3) - 1.0).abs() < 4.0 * f64::from(f32::EPSILON));
        assert_eq!(<f32 as Real>::NAME, "f32");
    }
}
