//! The non-trigonometric approximations: logarithm, square root, division.
//!
//! ```text
//! ln n, n ≥ 1 integer:  n = m·2^e with m ∈ [1/√2, √2) (e from the leading-zero count),
//!                       ln n = e·ln 2 + 2·atanh u,  u = (m − 1)/(m + 1), |u| ≤ 3 − 2√2 = 0.172
//!                       2·atanh u = 2(u + u³/3 + u⁵/5 + u⁷/7) + R,  |R| ≤ 2u⁹/(9(1 − u²)) = 3e-8
//!                       (Abramowitz & Stegun 4.1.27)
//! sqrt:                 `fixed`'s integer square root, rounded down: result ≤ √x < result + 1 LSB
//! division:             exact integer division rounded to nearest: |error| ≤ ½ LSB
//! ```
//! `micromath`'s f32 `sqrt` halves the exponent bits — √2 comes out as 1.5, 6 % high — so it is
//! offered only as [`sqrt_micromath`] for the cost table and never used by the rig.

use super::{RadPerSec, Unit};

/// ln 2 in Q30.
const LN2_Q30: i64 = 744_261_118;

/// ln of a positive integer in Q30 (i64); |error| ≤ 3.5e-8.
fn ln_q30(n: u64) -> i64 {
    debug_assert!(n > 0);
    let n = n.max(1);
    let mut e = 63 - n.leading_zeros() as i64; // floor(log2 n)
                                               // m in Q30: n / 2^e ∈ [1, 2)
    let mut m: i64 = if e >= 30 {
        (n >> (e - 30)) as i64
    } else {
        (n << (30 - e)) as i64
    };
    // √2 in Q30 = 1_518_500_250
    if m > 1_518_500_250 {
        m >>= 1;
        e += 1;
    }
    let one = 1i64 << 30;
    let u = ((m - one) << 30) / (m + one); // Q30, |u| ≤ 0.172
    let u2 = (u * u) >> 30;
    // 2(u + u³/3 + u⁵/5 + u⁷/7) by Horner: u(2 + u²(2/3 + u²(2/5 + u²·2/7)))
    const K7: i64 = 306_783_378; // round(2/7 · 2^30)
    const K5: i64 = 429_496_730; // round(2/5 · 2^30)
    const K3: i64 = 715_827_883; // round(2/3 · 2^30)
    let mut p = K7;
    p = K5 + ((u2 * p) >> 30);
    p = K3 + ((u2 * p) >> 30);
    p = 2 * one + ((u2 * p) >> 30);
    e * LN2_Q30 + ((u * p) >> 30)
}

/// ln(num/den) for positive integers, as I8F24; |error| ≤ 1e-7.
///
/// Used for the decay rate of the slow oscillation from two swing amplitudes.
pub fn ln_ratio(num: u64, den: u64) -> fixed::types::I8F24 {
    let d = ln_q30(num.max(1)) - ln_q30(den.max(1));
    let bits = (d + (1 << 5)) >> 6; // Q30 → Q24, rounded
    fixed::types::I8F24::from_bits(bits.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32)
}

/// √x for x ≥ 0 (negative → 0), rounded down: error < 1 LSB (1.5e-5).
pub fn sqrt(x: RadPerSec) -> RadPerSec {
    if x <= RadPerSec::ZERO {
        RadPerSec::ZERO
    } else {
        x.sqrt()
    }
}

/// √x of a [`Unit`] quantity, rounded down: error < 1 LSB (9.3e-10).
pub fn sqrt_unit(x: Unit) -> Unit {
    if x <= Unit::ZERO {
        Unit::ZERO
    } else {
        x.sqrt()
    }
}

/// `micromath`'s f32 square root, called explicitly (std's inherent `f32::sqrt` would shadow the
/// trait method in host builds). Crude: up to 6 % relative error. Cost table only.
pub fn sqrt_micromath(x: f32) -> f32 {
    micromath::F32(x).sqrt().0
}

/// num/den rounded to nearest (ties away from zero); den ≠ 0. Saturates to i64 on the one
/// overflowing case (i64::MIN / −1).
#[inline]
pub fn div_round(num: i64, den: i64) -> i64 {
    debug_assert!(den != 0);
    if den == 0 {
        return if num >= 0 { i64::MAX } else { i64::MIN };
    }
    let half = den.unsigned_abs() / 2;
    let q = num.unsigned_abs().saturating_add(half) / den.unsigned_abs();
    let q = q.min(i64::MAX as u64) as i64;
    if (num < 0) != (den < 0) {
        -q
    } else {
        q
    }
}

/// Saturates an i64 into i32.
#[inline]
pub fn sat_i32(x: i64) -> i32 {
    x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_bound() {
        // Against f64 libm::log; bound 3.5e-8 per ln (series remainder 3e-8 + Q30 rounding).
        let mut worst: f64 = 0.0;
        let mut n: u64 = 1;
        while n < (1u64 << 62) {
            for k in [n, n + 1, n + n / 3, n + n / 2 + 7] {
                let got = ln_q30(k) as f64 / (1u64 << 30) as f64;
                worst = worst.max((got - libm::log(k as f64)).abs());
            }
            n = n * 3 / 2 + 1;
        }
        assert!(worst <= 3.5e-8, "ln error {worst:e}");
        // Ratios, as used for the decay rate: bound 1e-7 (two ln plus the Q24 rounding).
        for (a, b) in [
            (1000u64, 999u64),
            (7, 3),
            (1 << 30, 12345),
            (5, 5),
            (2, 1_000_000),
        ] {
            let got: f64 = ln_ratio(a, b).to_num();
            let want = libm::log(a as f64 / b as f64);
            assert!((got - want).abs() <= 1e-7, "{a}/{b}: {got} vs {want}");
        }
    }

    #[test]
    fn sqrt_rounds_down_within_one_lsb() {
        // fixed's documented contract: result ≤ √x < result + DELTA.
        for x in [0.0, 1e-4, 0.5, 2.0, 59.0, 1234.5, 32000.0] {
            let q = RadPerSec::from_num(x);
            let r = sqrt(q);
            let exact = libm::sqrt(q.to_num::<f64>());
            let got: f64 = r.to_num();
            assert!(
                got <= exact && exact < got + RadPerSec::DELTA.to_num::<f64>(),
                "{x}"
            );
        }
        assert_eq!(sqrt(RadPerSec::from_num(-1)), RadPerSec::ZERO);
        let u: f64 = sqrt_unit(Unit::from_num(0.5)).to_num();
        assert!((u - libm::sqrt(0.5)).abs() < 1e-9);
    }

    #[test]
    fn micromath_sqrt_is_crude() {
        // micromath's sqrt gives 1.5 for √2 (6 % high). Relative error stays within 6.1 %
        // over many decades (measured bound), which is why the rig never uses it.
        assert_eq!(sqrt_micromath(2.0), 1.5);
        let mut worst: f64 = 0.0;
        let mut x = 1e-6f32;
        while x < 1e6 {
            let rel = (f64::from(sqrt_micromath(x)) / libm::sqrt(f64::from(x)) - 1.0).abs();
            worst = worst.max(rel);
            x *= 1.37;
        }
        assert!(worst < 0.061 && worst > 0.05, "{worst}");
    }

    #[test]
    fn division_rounds_to_nearest() {
        assert_eq!(div_round(7, 2), 4);
        assert_eq!(div_round(-7, 2), -4);
        assert_eq!(div_round(5, -3), -2);
        assert_eq!(div_round(i64::MIN, -1), i64::MAX);
        assert_eq!(sat_i32(1 << 40), i32::MAX);
        // Against f64 (exact for |num| < 2^52): within ½ LSB, for pseudo-random operands.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..100_000 {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let num = (x >> 12) as i64 - (1 << 51);
            let den = ((x & 0x0FFF_FFFF) as i64 - (1 << 27)) | 1;
            let err = (div_round(num, den) as f64 - num as f64 / den as f64).abs();
            assert!(err <= 0.5 + 1e-6, "{num}/{den}: {err}");
        }
    }
}
