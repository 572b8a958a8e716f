//! The one place float functions come from.
//!
//! `f64::sin` and friends need `std`; on the microcontroller they do not exist, and routing every
//! call through here keeps host tests exercising exactly the code the target runs (libm on both).

pub use core::f64::consts::{FRAC_PI_2, PI, TAU};

#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}
/// Both at once; one argument reduction.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}
#[inline]
pub fn sqrt(x: f64) -> f64 {
    libm::sqrt(x)
}
#[inline]
pub fn cbrt(x: f64) -> f64 {
    libm::cbrt(x)
}
#[inline]
pub fn exp(x: f64) -> f64 {
    libm::exp(x)
}
/// Natural logarithm.
#[inline]
pub fn ln(x: f64) -> f64 {
    libm::log(x)
}
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}
#[inline]
pub fn asin(x: f64) -> f64 {
    libm::asin(x)
}
#[inline]
pub fn acos(x: f64) -> f64 {
    libm::acos(x)
}
#[inline]
pub fn powf(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// e^x − 1 without libm's argument reduction for |x| ≤ 1/16, where the Taylor series to x⁹/9!
/// leaves out less than (1/16)⁹/10! < 4e-18 of it (below half an ulp): the damping of an
/// adaptive step, cH, is that small on every run but the most heavily damped, and this call
/// sits on the path from one step's size to the next step's first stage. Beyond, libm.
#[inline]
pub fn expm1(x: f64) -> f64 {
    if x.abs() > 1.0 / 16.0 {
        return libm::expm1(x);
    }
    // x Σ_{n<9} xⁿ/(n+1)!, Estrin's scheme: its chain is four multiply–adds deep.
    let (x2, x4) = (x * x, x * x * (x * x));
    let p01 = 1.0 + x * (1.0 / 2.0);
    let p23 = 1.0 / 6.0 + x * (1.0 / 24.0);
    let p45 = 1.0 / 120.0 + x * (1.0 / 720.0);
    let p67 = 1.0 / 5040.0 + x * (1.0 / 40_320.0);
    let p8 = 1.0 / 362_880.0;
    x * ((p01 + x2 * p23) + x4 * ((p45 + x2 * p67) + x4 * p8))
}

/// x^y for x > 0 and |y| ≤ 1 to a relative error below 1e-5, at a fraction of [`powf`]'s cost:
/// what a step-size controller needs, whose factor is a guess to a few per cent anyway, and
/// whose path from one step's error to the next step's size runs through it.
///
/// ```text
/// x = 2^e m, m in [√½, √2)          (the exponent bits, one higher past √2)
/// log2 x = e + (2/ln 2) atanh t,    t = (m − 1)/(m + 1), |t| ≤ 0.172: to t⁹ (next term < 1e-9)
/// z = y log2 x = n + g              n the nearest integer: z + 1.5·2^52 holds n in its low bits
/// x^y = 2^g · 2^n                   2^g for |g| ≤ ½ from its series to g⁷ (next term < 6e-9)
/// ```
/// No division but the one for t, no float–integer conversion, and both series in Estrin's
/// scheme. x ≤ 0 gives 0; x is clamped to [1e-300, 1e300].
#[inline]
pub fn pow_rough(x: f64, y: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    let bits = x.clamp(1e-300, 1e300).to_bits();
    let mantissa = bits & 0x000f_ffff_ffff_ffff;
    // √2 = 0x3ff6_a09e_667f_3bcd: past its mantissa, m is halved and e taken one higher.
    let past = mantissa > 0x0006_a09e_667f_3bcd;
    let exponent = ((bits >> 52) & 0x7ff) as i32 - 1023 + i32::from(past);
    let m = f64::from_bits(mantissa | if past { 0x3fe0 << 48 } else { 0x3ff0 << 48 });
    let t = (m - 1.0) / (m + 1.0);
    // y log2 x = y e + (2y/ln 2) t (1 + t²/3 + t⁴/5 + t⁶/7 + t⁸/9); the factors of t wait for
    // nothing.
    let (ye, scale) = (y * f64::from(exponent), y * 2.0 * core::f64::consts::LOG2_E);
    let (t2, t4) = (t * t, t * t * (t * t));
    let series =
        (1.0 + t2 * (1.0 / 3.0)) + t4 * ((1.0 / 5.0 + t2 * (1.0 / 7.0)) + t4 * (1.0 / 9.0));
    let z = ye + (scale * t) * series;
    // Round to nearest through the 1.5·2^52 shift: |z| ≤ 997 for |y| ≤ 1.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let shifted = z + SHIFT;
    let g = z - (shifted - SHIFT);
    // 2^g = Σ (g ln 2)^k / k!, k ≤ 7, with ln 2 folded into the coefficients.
    const L: [f64; 8] = {
        let ln2 = core::f64::consts::LN_2;
        let mut c = [1.0; 8];
        let mut k = 1;
        while k < 8 {
            c[k] = c[k - 1] * ln2 / k as f64;
            k += 1;
        }
        c
    };
    let (g2, g4) = (g * g, g * g * (g * g));
    let two_g = ((L[0] + g * L[1]) + g2 * (L[2] + g * L[3]))
        + g4 * ((L[4] + g * L[5]) + g2 * (L[6] + g * L[7]));
    // n + 1023 in the exponent field: the low twelve bits of the shifted value's bits plus
    // 1023 (its higher bits shift out).
    two_g * f64::from_bits(shifted.to_bits().wrapping_add(1023) << 52)
}

/// Wraps an angle to (−π, π].
pub fn wrap_pi(x: f64) -> f64 {
    let r = libm::remainder(x, TAU); // in [−π, π]
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// Wraps an angle in degrees to (−180°, 180°].
pub fn wrap_deg(x: f64) -> f64 {
    let r = libm::remainder(x, 360.0);
    if r <= -180.0 {
        r + 360.0
    } else {
        r
    }
}

#[inline]
pub fn to_rad(deg: f64) -> f64 {
    deg * (PI / 180.0)
}
#[inline]
pub fn to_deg(rad: f64) -> f64 {
    rad * (180.0 / PI)
}

/// sin and cos of an angle given in degrees, exact at multiples of 90°.
///
/// `sin(to_rad(180.0))` is 1.2e-16, not 0; at θd = 0°, 90°, 180° that residue would break exact
/// symmetries (and the special cases of physics §3), so quadrant multiples are reduced first.
pub fn sin_cos_deg(deg: f64) -> (f64, f64) {
    let d = wrap_deg(deg);
    let quarter = libm::round(d / 90.0);
    let rest = d - 90.0 * quarter;
    let (s, c) = sin_cos(to_rad(rest));
    match quarter as i32 {
        0 => (s, c),
        1 => (c, -s),
        -1 => (-c, s),
        _ => (-s, -c), // ±2
    }
}

/// The root of a continuous f in (a, b), given f(a) = `fa` and a sign change between a and b,
/// bisected to adjacent floats (at most ~2100 halvings, even for a root at subnormal scale).
/// Both root finders use it: [`crate::poly`] and [`crate::model::trig`].
pub fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, fa: f64) -> f64 {
    let neg_at_a = fa < 0.0;
    for _ in 0..2200 {
        let mid = a + 0.5 * (b - a);
        if mid <= a || mid >= b {
            break;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm < 0.0) == neg_at_a {
            a = mid;
        } else {
            b = mid;
        }
    }
    a + 0.5 * (b - a)
}

/// Narrows [lo, hi] around where `flipped` turns from false (at lo) to true (at hi), halving
/// until the bracket is at most `tol` wide or no float lies inside it (tol = 0: adjacent floats,
/// within 200 halvings).
/// For questions that are yes/no rather than a sign: a Sturm count, a trace above a threshold.
pub fn bisect_flip(
    mut flipped: impl FnMut(f64) -> bool,
    mut lo: f64,
    mut hi: f64,
    tol: f64,
) -> (f64, f64) {
    for _ in 0..200 {
        let mid = lo + 0.5 * (hi - lo);
        if hi - lo <= tol || mid <= lo || mid >= hi {
            break;
        }
        if flipped(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisect_flip_brackets_the_flip() {
        // x² ≥ 2 flips at √2 (closed form): to adjacent floats with tol = 0, else to width ≤ tol.
        let (lo, hi) = bisect_flip(|x| x * x >= 2.0, 1.0, 2.0, 0.0);
        assert!(lo * lo < 2.0 && hi * hi >= 2.0);
        assert_eq!(hi, f64::from_bits(lo.to_bits() + 1));
        let (lo, hi) = bisect_flip(|x| x * x >= 2.0, 1.0, 2.0, 1e-3);
        assert!(
            hi - lo <= 1e-3 && lo < core::f64::consts::SQRT_2 && core::f64::consts::SQRT_2 <= hi
        );
    }

    #[test]
    fn expm1_matches_libm_on_both_sides_of_the_series_range() {
        // Against libm::expm1 (within 1 ulp of e^x − 1): within 2 ulps of it, relative, for
        // |x| up to 1/16 (the series) and beyond (libm itself), and exact at 0.
        for i in -2000..=2000 {
            let x = f64::from(i) * 5e-5;
            let (got, want) = (expm1(x), libm::expm1(x));
            let ulp = want.abs() * f64::EPSILON;
            assert!((got - want).abs() <= 2.0 * ulp, "{x}: {got:e} vs {want:e}");
        }
        for x in [1e-300, -1e-20, 1e-9, -0.0625, 0.0625] {
            let (got, want) = (expm1(x), libm::expm1(x));
            assert!((got - want).abs() <= 2.0 * want.abs() * f64::EPSILON, "{x}");
        }
        assert_eq!(expm1(0.0), 0.0);
    }

    #[test]
    fn pow_rough_is_within_1e5_of_libm() {
        // Against libm::pow over the controllers' range: x from 1e-299 to 1e299, y in [−1, 1].
        for i in -299..=298 {
            let x = 10f64.powi(i) * 1.37;
            for y in [-1.0, -0.2, -0.04, 0.0, 0.008, 1.0 / 7.0, 0.125, 0.5, 1.0] {
                let (got, want) = (pow_rough(x, y), libm::pow(x, y));
                assert!(
                    (got / want - 1.0).abs() < 1e-5,
                    "{x:e}^{y}: {got:e} vs {want:e}"
                );
            }
        }
        // Every mantissa region, on both sides of √2, at the exponents a controller meets.
        for k in 0..4000 {
            let m = 1.0 + f64::from(k) / 4000.0;
            for scale in [1e-12, 3e-4, 1.0, 17.0] {
                let x = m * scale;
                for y in [-1.0, -1.0 / 11.0, 0.04, 0.125, 1.0] {
                    let (got, want) = (pow_rough(x, y), libm::pow(x, y));
                    assert!(
                        (got / want - 1.0).abs() < 1e-5,
                        "{x:e}^{y}: {got:e} vs {want:e}"
                    );
                }
            }
        }
        assert_eq!(pow_rough(0.0, 0.5), 0.0);
    }

    #[test]
    fn wrap_is_half_open() {
        // (−π, π]: −π maps to +π, +π stays.
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert!((wrap_pi(3.0 * TAU + 0.5) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn sin_cos_deg_exact_at_quadrants() {
        assert_eq!(sin_cos_deg(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_deg(90.0), (1.0, 0.0));
        assert_eq!(sin_cos_deg(180.0), (0.0, -1.0));
        assert_eq!(sin_cos_deg(-90.0), (-1.0, 0.0));
        assert_eq!(sin_cos_deg(270.0), (-1.0, 0.0));
        // Elsewhere it agrees with the plain formula (libm, within 2 ulp-ish).
        for d in [-179.0, -135.0, -45.0, 1.0, 44.9, 135.0, 179.9] {
            let (s, c) = sin_cos_deg(d);
            assert!((s - sin(to_rad(d))).abs() < 1e-15);
            assert!((c - cos(to_rad(d))).abs() < 1e-15);
        }
    }
}
