//! Level 4 without integration: Hill's method for the undamped linear equation, and damping
//! mapped onto it exactly.
//!
//! With z = τ/2 the undamped equation is Mathieu's (physics §4), and a solution with characteristic
//! exponent ν is y = e^{iνz} Σ_r c_r e^{2irz}. Putting that in gives one row per harmonic r
//! (Hill's three-term recurrence; McLachlan, *Theory and Application of Mathieu Functions*,
//! §2.13–2.15; Abramowitz & Stegun 20.2–20.3):
//!
//! ```text
//! y'' + (a − 2q cos 2z) y = 0,       a = 4k, q = 2m
//! (a − (ν + 2r)²) c_r − q (c_{r−1} + c_{r+1}) = 0,     r ∈ ℤ
//! ⇔ a is an eigenvalue of the symmetric tridiagonal T(ν, q):
//!     diagonal (ν + 2r)²,  off-diagonal q,   r = −N … N
//! ν = 0: a₀, b₂, a₂, b₄, …  (multiplier +1 per drive period: tr M = +2)
//! ν = 1: a₁, b₁, b₃, a₃, …  (multiplier −1: tr M = −2, period 2 — flutter)
//! ν = 2/n: tr M = 2 cos(2π/n): the order-n subharmonic
//! ```
//!
//! The characteristic values interlace as a₀ < b₁ ≤ a₁ < b₂ ≤ a₂ < … (equal only at q = 0) and
//! the position is stable exactly between a₀ and b₁, a₁ and b₂, a₂ and b₃, …: so with C(a, q) the
//! number of eigenvalues of T(0, q) and T(1, q) below a,
//!
//! ```text
//! stable  ⇔  C(a, q) is odd
//! ```
//!
//! and C comes from a Sturm sequence (the signs of the pivots of the LDLᵀ factorisation of
//! T − aI; Wilkinson, *The Algebraic Eigenvalue Problem*, §5.37): no integration, no scan. A
//! boundary is where one characteristic value crosses a. Each value belongs to one of four
//! families (a_even, b_even, a_odd, b_odd), each the spectrum of its own block of T
//! ([`family`]); [`follow`] finds where one value meets a by Newton steps in q on its block's
//! determinant, kept honest by the block's Sturm counts and by bounds on the value's slope and
//! curvature, and [`windows`] picks the values that end a window, never going by a change of
//! parity (which a pair of crossings inside one step hides).
//!
//! Truncation: N harmonics on each side with (2N)² far above |a| + 2|q|; the coefficients then
//! fall faster than geometrically (ratio ≈ q/(2r)²), and truncation only raises eigenvalues
//! (Rayleigh–Ritz), by less than rounding with the margin used here ([`harmonics`], tested
//! against N + 12).
//!
//! Damping (δ > 0) maps onto the undamped problem exactly ([`damped`]):
//!
//! ```text
//! x = e^{−δτ/2} u  ⇒  u'' + (k − δ²/4 − m cos τ) u = 0,   M = e^{−πδ} M_u
//! stable  ⇔  |tr M| < 1 + e^{−2πδ}  ⇔  |tr M_u(k − δ²/4, m)| < 2 cosh(πδ)
//! ```
//!
//! so every point where the shifted undamped problem is stable is stable, and only elsewhere is
//! tr M_u needed.

pub mod damped;
pub mod family;
pub mod follow;
pub mod windows;

pub use damped::{
    damped_window, is_stable_damped, trace_u, trace_u_with, DampedWindow, DEFAULT_HALF_STEPS,
};
pub use windows::{first_window, subharmonic_m, Transition, Windows};

use super::{check_k, check_m};
use crate::error::ParamError;
use crate::math;

/// Harmonics on each side of r = 0 for the pair (a, q): enough that the eigenvalues below a
/// have converged to rounding.
pub fn harmonics(a: f64, q: f64) -> usize {
    // Past r₀ = √(|a| + 2|q|) the coefficients fall by |q|/((2r)² − |a|) ≤ 1/8 per harmonic;
    // 10 beyond it: 8^−10 ≈ 1e-9 in the coefficients, squared (≈ 1e-18) in the eigenvalue.
    let s = math::sqrt(a.abs() + 2.0 * q.abs());
    (s as usize) + 10
}

/// The number of eigenvalues of T(ν, q) (N harmonics each side) below x: a Sturm count.
pub fn count_below(nu: f64, q: f64, x: f64, n: usize) -> u32 {
    let q2 = q * q;
    let n = n as i64;
    let mut count = 0;
    let mut pivot = 1.0;
    for r in -n..=n {
        let t = nu + 2.0 * r as f64;
        let mut p = t * t - x;
        if r > -n {
            p -= q2 / pivot;
        }
        // An exact zero pivot: perturb it to the negative side (x sits on an eigenvalue, which
        // then counts as below; LAPACK's dstebz does the same with its pivmin).
        if p == 0.0 {
            p = -f64::MIN_POSITIVE;
        }
        if p < 0.0 {
            count += 1;
        }
        pivot = p;
    }
    count
}

/// C(a, q): characteristic values a_r, b_r below a (ν = 0 and ν = 1 together).
pub fn stability_count(a: f64, q: f64) -> u32 {
    let n = harmonics(a, q);
    count_below(0.0, q, a, n) + count_below(1.0, q, a, n)
}

/// Whether the undamped equation x'' + (k − m cos τ) x = 0 is stable at (k, m): C(4k, 2m) odd.
///
/// ```
/// use kapitza_core::stability::hill;
/// // Inverted, k = −0.3: stable between m = 0.868 and 0.929 (physics §4; docs/stability.md).
/// assert!(!hill::is_stable(-0.3, 0.85).unwrap());
/// assert!(hill::is_stable(-0.3, 0.90).unwrap());
/// assert!(!hill::is_stable(-0.3, 0.95).unwrap());
/// ```
pub fn is_stable(k: f64, m: f64) -> Result<bool, ParamError> {
    Ok(stability_count(4.0 * check_k(k)?, 2.0 * check_m(m)?) % 2 == 1)
}

/// The n-th smallest eigenvalue (n from 0) of T(ν, q), bisected on its Sturm count to adjacent
/// floats: a₀ is `eigenvalue(0.0, q, 0)`, b₁ is `eigenvalue(1.0, q, 0)` for q > 0.
pub fn eigenvalue(nu: f64, q: f64, index: u32) -> f64 {
    // Gershgorin: every eigenvalue lies within 2|q| of a diagonal entry (ν + 2r)².
    let top = nu.abs() + 2.0 * f64::from(index) + 2.0;
    let n = harmonics(top * top + 2.0 * q.abs(), q);
    let (lo, hi) = math::bisect_flip(
        |x| count_below(nu, q, x, n) > index,
        -2.0 * q.abs() - 1.0,
        top * top + 2.0 * q.abs() + 1.0,
        0.0,
    );
    lo + 0.5 * (hi - lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_oscillator_counts() {
        // q = 0: the characteristic values are a_r = b_r = r² exactly (closed form), so C(a, 0)
        // is 1 + 2⌊√a⌋ for a > 0 not a square, and 0 for a < 0.
        assert_eq!(stability_count(-0.5, 0.0), 0);
        assert_eq!(stability_count(0.5, 0.0), 1);
        assert_eq!(stability_count(2.0, 0.0), 3);
        assert_eq!(stability_count(8.9, 0.0), 5);
        assert_eq!(stability_count(9.1, 0.0), 7);
    }

    #[test]
    fn published_characteristic_values() {
        // Abramowitz & Stegun, Table 20.1 (q = 1 and q = 5), printed to 8 decimals:
        // a0(1) = −0.45513 860, b1(1) = −0.11024 882, a1(1) = 1.85910 807, b2(1) = 3.91702 477;
        // a0(5) = −5.80004 602, b1(5) = −5.79008 060. Tolerance: half the last printed unit.
        let cases = [
            (0.0, 1.0, 0, -0.455_138_60),
            (1.0, 1.0, 0, -0.110_248_82),
            (1.0, 1.0, 1, 1.859_108_07),
            (0.0, 1.0, 1, 3.917_024_77),
            (0.0, 5.0, 0, -5.800_046_02),
            (1.0, 5.0, 0, -5.790_080_60),
        ];
        for (nu, q, i, want) in cases {
            let got = eigenvalue(nu, q, i);
            assert!(
                (got - want).abs() < 5e-9,
                "ν {nu} q {q} #{i}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn truncation_has_converged() {
        // Against 12 more harmonics each side: the same eigenvalue to rounding (1e-12 relative
        // to the scale |a| + 2|q|).
        for (nu, q, i) in [
            (0.0, 50.0, 0),
            (1.0, 50.0, 3),
            (0.0, 3.0, 5),
            (0.4, 20.0, 0),
        ] {
            let top = nu + 2.0 * f64::from(i) + 2.0;
            let n = harmonics(top * top + 2.0 * q, q);
            let bisect = |n: usize| {
                let (mut lo, mut hi) = (-200.0, 400.0);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if count_below(nu, q, mid, n) > i {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                lo
            };
            let (a, b) = (bisect(n), bisect(n + 12));
            assert!((a - b).abs() < 1e-12 * (a.abs() + 2.0 * q), "{nu} {q} {i}");
        }
    }
}
