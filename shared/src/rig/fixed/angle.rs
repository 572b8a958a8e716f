//! The wrapping angle: one full turn is 2^32, so integer overflow *is* the wrap.
//!
//! ```text
//! bits b ∈ [−2^31, 2^31)  ↔  angle = b · 2π / 2^32 ∈ [−π, π)
//! ```
//! Sums and differences are modulo one turn by construction: no branch, no drift, and the same
//! resolution (1.46e-9 rad) at any number of turns.

use super::Rad;
use crate::math;
use core::ops::{Add, AddAssign, Neg, Sub, SubAssign};

/// An angle or phase, wrapping, one turn = 2^32.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Angle(i32);

/// 2^32 as f64.
const TURN: f64 = 4_294_967_296.0;
/// π/8 in Q32: bits · π/8 · 2^-32 · 2^28… see [`Angle::to_rad_q`].
const PI_OVER_8_Q32: i64 = 1_686_629_713; // round(π/8 · 2^32)

impl Angle {
    pub const ZERO: Self = Self(0);
    pub const QUARTER_TURN: Self = Self(1 << 30);
    pub const HALF_TURN: Self = Self(i32::MIN);

    #[inline]
    pub const fn from_bits(bits: i32) -> Self {
        Self(bits)
    }
    #[inline]
    pub const fn to_bits(self) -> i32 {
        self.0
    }
    /// The same bits read as an unsigned phase in [0, 1) turn.
    #[inline]
    pub const fn to_turns_u32(self) -> u32 {
        self.0 as u32
    }
    #[inline]
    pub const fn from_turns_u32(bits: u32) -> Self {
        Self(bits as i32)
    }

    /// From radians (any size), rounded to the nearest 2^-32 turn. Boundary conversion.
    pub fn from_rad(x: f64) -> Self {
        let turns = x / math::TAU;
        let frac = turns - libm::floor(turns); // [0, 1]
        Self(libm::round(frac * TURN) as i64 as u32 as i32)
    }
    pub fn from_deg(deg: f64) -> Self {
        let turns = deg / 360.0;
        let frac = turns - libm::floor(turns);
        Self(libm::round(frac * TURN) as i64 as u32 as i32)
    }
    /// In radians, in [−π, π). Exact (every i32 is an f64).
    pub fn to_rad(self) -> f64 {
        f64::from(self.0) * (math::TAU / TURN)
    }
    pub fn to_deg(self) -> f64 {
        f64::from(self.0) * (360.0 / TURN)
    }
    /// In radians as [`Rad`] (I4F28), in [−π, π); error ≤ 1 LSB (3.7e-9 rad).
    ///
    /// ```text
    /// rad·2^28 = b · 2π/2^32 · 2^28 = b · π/8
    /// ```
    #[inline]
    pub fn to_rad_q(self) -> Rad {
        let prod = i64::from(self.0) * PI_OVER_8_Q32;
        Rad::from_bits(((prod + (1 << 31)) >> 32) as i32)
    }
    /// From radians in [`Rad`], wrapping (any value maps to a valid angle).
    #[inline]
    pub fn from_rad_q(r: Rad) -> Self {
        // b = rad·2^28 · 8/π; 8/π in Q32 = round(8/π · 2^32).
        const EIGHT_OVER_PI_Q32: i64 = 10_937_044_409;
        let prod = i64::from(r.to_bits()) * EIGHT_OVER_PI_Q32;
        Self(((prod + (1 << 31)) >> 32) as i32)
    }
    /// Twice the angle, wrapping: 2(φ − θd) for the equilibrium condition.
    #[inline]
    pub fn double(self) -> Self {
        Self(self.0.wrapping_mul(2))
    }
    /// |angle| in [0, π] as unsigned bits (half a turn = 2^31).
    #[inline]
    pub fn abs_bits(self) -> u32 {
        self.0.unsigned_abs()
    }
}

impl Add for Angle {
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self(self.0.wrapping_add(rhs.0))
    }
}
impl Sub for Angle {
    type Output = Self;
    #[inline]
    fn sub(self, rhs: Self) -> Self {
        Self(self.0.wrapping_sub(rhs.0))
    }
}
impl Neg for Angle {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self(self.0.wrapping_neg())
    }
}
impl AddAssign for Angle {
    #[inline]
    fn add_assign(&mut self, rhs: Self) {
        *self = *self + rhs;
    }
}
impl SubAssign for Angle {
    #[inline]
    fn sub_assign(&mut self, rhs: Self) {
        *self = *self - rhs;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_by_construction() {
        // Half a turn plus half a turn is a full turn, i.e. zero; no panic in debug builds.
        assert_eq!(Angle::HALF_TURN + Angle::HALF_TURN, Angle::ZERO);
        assert_eq!(Angle::from_deg(270.0), Angle::from_deg(-90.0));
        assert_eq!(
            Angle::from_deg(-90.0) - Angle::from_deg(170.0),
            Angle::from_deg(100.0)
        );
        // 1e6 turns plus 30° is 30°, to the rounding of the f64 input (2^-32 turn).
        let a = Angle::from_rad(1e6 * math::TAU + math::to_rad(30.0));
        assert!((a.to_deg() - 30.0).abs() < 1e-6);
    }

    #[test]
    fn fixed_radians_within_one_lsb() {
        // to_rad_q against the exact f64 value; bound 1 LSB of I4F28 (3.7e-9 rad) + rounding.
        for deg in [-180.0, -179.9, -90.0, -1e-6, 0.0, 0.3, 45.0, 123.4, 179.99] {
            let a = Angle::from_deg(deg);
            let q: f64 = a.to_rad_q().to_num();
            assert!(
                (q - a.to_rad()).abs() <= 4e-9,
                "{deg}: {q} vs {}",
                a.to_rad()
            );
            let back = Angle::from_rad_q(a.to_rad_q());
            assert!((back - a).to_bits().abs() <= 2, "{deg}");
        }
    }
}
