//! sin and cos of an [`Angle`], four ways, so that their accuracy and cost can be compared
//! (`docs/accuracy-mcu.md`). The rig uses [`sin_cos`]; the others exist for that comparison.
//!
//! All four share the exact integer range reduction, which is what a turn-based angle buys:
//!
//! ```text
//! q = round(b / 2^30) mod 4            quadrant (b: Angle bits, 2^30 = a quarter turn)
//! r = b − q·2^30 ∈ [−2^29, 2^29)       |r| ≤ 1/8 turn, x = r·2π/2^32 ∈ [−π/4, π/4)
//! (sin, cos)(b) = (s, c), (c, −s), (−s, −c), (−c, s)   for q = 0, 1, 2, 3
//! ```
//! On |x| ≤ π/4 the Taylor series converge fast; the Lagrange remainders bound the truncation
//! (Abramowitz & Stegun 4.3.65–66):
//!
//! ```text
//! sin to x⁹:  |R| ≤ (π/4)^11/11! = 1.8e-9      cos to x^10: |R| ≤ (π/4)^12/12! = 1.2e-10
//! sin to x⁷:  |R| ≤ (π/4)^9/9!   = 3.1e-7      cos to x⁸:   |R| ≤ (π/4)^10/10! = 2.5e-8
//! ```
//! Rounding adds a few units of 2^-31 (Q30 Horner) or of f32's 2^-24.

use super::{Angle, Unit};

/// A Q30 sin/cos, chosen at compile time (so a kernel generic over it pays no indirection):
/// the rig uses [`Poly`]; [`Table`] exists for the cost comparison.
pub trait SinCos {
    fn sin_cos(a: Angle) -> (Unit, Unit);
}

/// [`sin_cos`]: the Taylor polynomial.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Poly;
/// [`sin_cos_table`]: the quarter-wave table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Table;

impl SinCos for Poly {
    #[inline]
    fn sin_cos(a: Angle) -> (Unit, Unit) {
        sin_cos(a)
    }
}
impl SinCos for Table {
    #[inline]
    fn sin_cos(a: Angle) -> (Unit, Unit) {
        sin_cos_table(a)
    }
}

/// An f32 sin/cos of an [`Angle`], for the f32 variants of the cost comparison.
pub trait SinCosF32 {
    fn sin_cos(a: Angle) -> (f32, f32);
}
/// [`sin_cos_f32_poly`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PolyF32;
/// [`sin_cos_f32_micromath`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Micromath;

impl SinCosF32 for PolyF32 {
    #[inline]
    fn sin_cos(a: Angle) -> (f32, f32) {
        sin_cos_f32_poly(a)
    }
}
impl SinCosF32 for Micromath {
    #[inline]
    fn sin_cos(a: Angle) -> (f32, f32) {
        sin_cos_f32_micromath(a)
    }
}

/// π/2 in Q32: x·2^30 = r·(π/2)·2^30/2^30… i.e. x_Q30 = r·π/2 for r in 2^-32 turns.
const HALF_PI_Q32: i64 = 6_746_518_852; // round(π/2 · 2^32)

/// Splits an angle into quadrant q ∈ 0..4 and remainder r ∈ [−2^29, 2^29) (2^-32 turns).
#[inline]
fn reduce(a: Angle) -> (u32, i32) {
    let b = a.to_turns_u32();
    let q = b.wrapping_add(1 << 29) >> 30;
    let r = b.wrapping_sub(q << 30) as i32;
    (q, r)
}

#[inline]
fn unfold<T: Copy + core::ops::Neg<Output = T>>(q: u32, s: T, c: T) -> (T, T) {
    match q {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Q30 multiply with rounding.
#[inline]
fn mul30(a: i32, b: i32) -> i32 {
    ((i64::from(a) * i64::from(b) + (1 << 29)) >> 30) as i32
}

// Taylor coefficients in Q30: round(c · 2^30).
const S1: i32 = -178_956_971; // −1/3!
const S2: i32 = 8_947_849; //     1/5!
const S3: i32 = -213_044; //     −1/7!
const S4: i32 = 2_959; //         1/9!
const C1: i32 = -536_870_912; // −1/2!
const C2: i32 = 44_739_243; //    1/4!
const C3: i32 = -1_491_308; //   −1/6!
const C4: i32 = 26_631; //        1/8!
const C5: i32 = -296; //         −1/10!
const ONE_Q30: i32 = 1 << 30;

/// (sin, cos) in Q30 by the reduction above and Taylor polynomials; |error| ≤ 4e-9.
/// The rig's sin/cos: about 20 multiplies, no table, no float.
#[inline]
pub fn sin_cos(a: Angle) -> (Unit, Unit) {
    let (q, r) = reduce(a);
    let x = ((i64::from(r) * HALF_PI_Q32 + (1 << 31)) >> 32) as i32; // Q30 radians, |x| ≤ π/4
    let x2 = mul30(x, x);
    let mut p = S4;
    p = S3 + mul30(x2, p);
    p = S2 + mul30(x2, p);
    p = S1 + mul30(x2, p);
    let s = x + mul30(x, mul30(x2, p));
    let mut k = C5;
    k = C4 + mul30(x2, k);
    k = C3 + mul30(x2, k);
    k = C2 + mul30(x2, k);
    k = C1 + mul30(x2, k);
    let c = ONE_Q30 + mul30(x2, k);
    let (s, c) = unfold(q, s, c);
    (Unit::from_bits(s), Unit::from_bits(c))
}

/// Entries of the quarter-wave table: sin(i·π/512), i = 0..=256, Q30.
const TABLE_N: usize = 256;

/// sin(x) by its Taylor series in f64, in a const context (f64 arithmetic in `const fn` is
/// stable); 12 terms on [0, π/2] leave < 1e-16, far below the table's Q30 rounding.
const fn taylor_sin(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut n = 1;
    while n < 12 {
        term = -term * x2 / (((2 * n) * (2 * n + 1)) as f64);
        sum += term;
        n += 1;
    }
    sum
}

const fn build_table() -> [i32; TABLE_N + 1] {
    let mut t = [0i32; TABLE_N + 1];
    let mut i = 0;
    while i <= TABLE_N {
        let x = (i as f64) * core::f64::consts::FRAC_PI_2 / (TABLE_N as f64);
        let v = taylor_sin(x) * 1_073_741_824.0;
        // round half away from zero (v ≥ 0 here)
        t[i] = (v + 0.5) as i64 as i32;
        i += 1;
    }
    t
}

/// The quarter-wave sine table, computed at compile time (1 KiB of flash).
static QUARTER_SINE: [i32; TABLE_N + 1] = build_table();

/// sin of a first-quadrant angle u ∈ [0, 2^30] (2^-32 turns) by linear interpolation.
#[inline]
fn table_sin_q1(u: u32) -> i32 {
    // 2^30 / 256 = 2^22 per entry.
    let i = (u >> 22) as usize;
    if i >= TABLE_N {
        return QUARTER_SINE[TABLE_N];
    }
    let frac = i64::from(u & ((1 << 22) - 1));
    let (a, b) = (i64::from(QUARTER_SINE[i]), i64::from(QUARTER_SINE[i + 1]));
    (a + (((b - a) * frac + (1 << 21)) >> 22)) as i32
}

/// (sin, cos) in Q30 from a 257-entry quarter-wave table with linear interpolation;
/// |error| ≤ h²/8 = (π/512)²/8 = 4.7e-6 plus rounding, bound 5e-6.
pub fn sin_cos_table(a: Angle) -> (Unit, Unit) {
    let b = a.to_turns_u32();
    let q = b >> 30;
    let u = b & ((1 << 30) - 1);
    // In quadrant q with offset u: sin = ±sin(u) or ±cos(u) = ±sin(quarter − u).
    let su = table_sin_q1(u);
    let cu = table_sin_q1((1 << 30) - u);
    let (s, c) = match q {
        0 => (su, cu),
        1 => (cu, -su),
        2 => (-su, -cu),
        _ => (-cu, su),
    };
    (Unit::from_bits(s), Unit::from_bits(c))
}

/// (sin, cos) in f32: the exact integer reduction, then Taylor to x⁷ / x⁸ in f32;
/// |error| ≤ 4e-7 (truncation 3.1e-7 at the octant edge is the larger part; f32 rounding ~1e-7).
#[inline]
pub fn sin_cos_f32_poly(a: Angle) -> (f32, f32) {
    let (q, r) = reduce(a);
    let x = r as f32 * (core::f32::consts::TAU / 4_294_967_296.0);
    let x2 = x * x;
    let s = x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0))));
    let c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0))));
    unfold(q, s, c)
}

/// (sin, cos) in f32 through `micromath` (documented max error 2e-3), called explicitly so that
/// host tests run the same approximation as the MCU. For the cost comparison only.
#[inline]
pub fn sin_cos_f32_micromath(a: Angle) -> (f32, f32) {
    let x = a.to_rad() as f32;
    (micromath::F32(x).sin().0, micromath::F32(x).cos().0)
}

/// Gain compensation of the circular CORDIC, Π 1/√(1 + 2^-2i) over 24 iterations, in Q23.
const CORDIC_K_Q23: i32 = 5_094_007; // round(0.607252935 · 2^23)

/// atan(2^-i) in 2^-32 turn, i = 0..24: round(atan(2^-i)/(2π) · 2^32).
const CORDIC_ATAN: [i32; 24] = {
    let mut t = [0i32; 24];
    let mut i = 0;
    while i < 24 {
        // atan(2^-i) by its Taylor series (|x| ≤ 1; at x = 1 use π/4 exactly)
        let x = 1.0 / ((1u64 << i) as f64);
        let a = if i == 0 {
            core::f64::consts::FRAC_PI_4
        } else {
            let x2 = x * x;
            let mut term = x;
            let mut sum = x;
            let mut n = 1;
            while n < 30 {
                term = -term * x2;
                sum += term / ((2 * n + 1) as f64);
                n += 1;
            }
            sum
        };
        t[i] = (a / core::f64::consts::TAU * 4_294_967_296.0 + 0.5) as i64 as i32;
        i += 1;
    }
    t
};

/// (sin, cos) by a software model of a circular CORDIC with a 24-bit datapath and 24
/// iterations — the STM32G4 CORDIC unit's algorithm at its q1.31 precision setting of 6
/// (four iterations per clock). Used only to put an error on the unit in the cost table
/// (`docs/accuracy-mcu.md`); the unit's own rounding may differ in the last bits.
///
/// ```text
/// z₀ = r (|r| ≤ π/4 after the quadrant reduction), x₀ = K = Π 1/√(1 + 2^-2i), y₀ = 0
/// dᵢ = sign zᵢ:  x ← x − dᵢ y 2^-i,  y ← y + dᵢ x 2^-i,  z ← z − dᵢ atan 2^-i     → (y, x) = (sin r, cos r)
/// ```
pub fn sin_cos_cordic_model(a: Angle) -> (Unit, Unit) {
    let (q, r) = reduce(a);
    let (mut x, mut y, mut z) = (CORDIC_K_Q23, 0i32, r);
    for (i, &t) in CORDIC_ATAN.iter().enumerate() {
        let (dx, dy) = (y >> i, x >> i);
        if z >= 0 {
            x -= dx;
            y += dy;
            z -= t;
        } else {
            x += dx;
            y -= dy;
            z += t;
        }
    }
    let (s, c) = unfold(q, y << 7, x << 7); // Q23 → Q30
    (Unit::from_bits(s), Unit::from_bits(c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    /// Max |error| of a sin/cos against f64 libm over a dense sweep of angles plus the octant
    /// and quadrant edges.
    fn max_err(f: impl Fn(Angle) -> (f64, f64)) -> f64 {
        let mut worst: f64 = 0.0;
        let mut check = |a: Angle| {
            let (s, c) = f(a);
            let (es, ec) = math::sin_cos(a.to_rad());
            worst = worst.max((s - es).abs()).max((c - ec).abs());
        };
        for i in 0..200_003u32 {
            check(Angle::from_turns_u32(i.wrapping_mul(21_474_743))); // ≈ 2^32/200003
        }
        for k in 0..8u32 {
            for d in [-1i32, 0, 1] {
                check(Angle::from_turns_u32((k << 29).wrapping_add(d as u32)));
            }
        }
        worst
    }

    #[test]
    fn polynomial_q30_bound() {
        // Bound 4e-9: Taylor remainder 1.8e-9 + Q30 Horner rounding (module doc).
        let e = max_err(|a| {
            let (s, c) = sin_cos(a);
            (s.to_num(), c.to_num())
        });
        assert!(e <= 4e-9, "max error {e:e}");
    }

    #[test]
    fn table_bound() {
        // Bound 5e-6: linear interpolation h²/8 with h = π/512, plus Q30 rounding.
        let e = max_err(|a| {
            let (s, c) = sin_cos_table(a);
            (s.to_num(), c.to_num())
        });
        assert!(e <= 5e-6, "max error {e:e}");
    }

    #[test]
    fn f32_polynomial_bound() {
        // Bound 4e-7: Taylor remainder 3.1e-7 at the octant edge plus f32 rounding (~1e-7).
        let e = max_err(|a| {
            let (s, c) = sin_cos_f32_poly(a);
            (f64::from(s), f64::from(c))
        });
        assert!(e <= 4e-7, "max error {e:e}");
    }

    #[test]
    fn micromath_is_crude() {
        // micromath documents a max error of 0.002 for sin/cos; we check it holds, and that it is
        // indeed far worse than the others (it is kept only for the cost table).
        let e = max_err(|a| {
            let (s, c) = sin_cos_f32_micromath(a);
            (f64::from(s), f64::from(c))
        });
        assert!(e <= 2e-3 && e > 1e-4, "max error {e:e}");
    }

    #[test]
    fn cordic_model_bound() {
        // 24 iterations leave a residual angle ≤ atan 2^-23 ≈ 1.2e-7 rad; the truncating shifts
        // of the 24-bit datapath add up to ~24·2^-23 ≈ 3e-6 in the worst case: bound 2e-6
        // (measured 1.35e-6 ≈ 2^-19.5).
        let e = max_err(|a| {
            let (s, c) = sin_cos_cordic_model(a);
            (s.to_num(), c.to_num())
        });
        assert!(e <= 2e-6 && e > 1e-7, "max error {e:e}");
    }

    #[test]
    fn exact_at_quadrants() {
        // Integer reduction makes the quadrant points exact: sin(90°) = 1, cos(90°) = 0 in Q30.
        assert_eq!(sin_cos(Angle::QUARTER_TURN), (Unit::ONE, Unit::ZERO));
        assert_eq!(sin_cos(Angle::HALF_TURN), (Unit::ZERO, -Unit::ONE));
        assert_eq!(sin_cos_table(Angle::ZERO), (Unit::ZERO, Unit::ONE));
    }
}
