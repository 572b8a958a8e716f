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
/// symmetries (and the special cases of SPEC §3), so quadrant multiples are reduced first.
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

#[cfg(test)]
mod tests {
    use super::*;

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
