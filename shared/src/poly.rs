//! Small real polynomials: arithmetic, exact determinants of polynomial matrices, and robust
//! real-root isolation.
//!
//! The stability boundaries of harmonic balance (physics §4, level 3) and of the Mathieu series
//! (level 2) are real roots of polynomials of degree ≤ 7. They are found here without
//! allocation and without a starting guess:
//!
//! ```text
//! isolation by derivative recursion
//!   all real roots of p lie in [−B, B],  B = 1 + max_{i<n} |c_i / c_n|   (Cauchy bound)
//!   the real roots of p′ (found the same way, one degree lower) split [−B, B] into intervals
//!   on which p is monotone: each holds at most one root, and holds one iff p changes sign
//!   → bisect every interval with a sign change (a simple root);
//!   → a critical point where |p| is at the level of its own rounding error is a multiple root
//!     (p touches zero there without changing sign, so no interval would find it).
//! rounding level of Horner at x:  |p̂(x) − p(x)| ≲ 2n·ε·Σ|c_i||x|^i   (Higham, Accuracy and
//!   Stability of Numerical Algorithms, 2nd ed., §5.1)
//! ```
//!
//! Determinants of matrices whose entries are polynomials are expanded exactly (Laplace
//! expansion over the ring of polynomials), so the coefficients of, say, the quintic of a 5×5
//! harmonic-balance system are products and sums of the entries' coefficients rather than values
//! interpolated from sampled determinants.

use core::ops::{Add, Neg, Sub};

/// Capacity of [`Poly`]: degree ≤ `MAX_DEG`.
pub const MAX_DEG: usize = 7;

/// A real polynomial c0 + c1 x + … + c_deg x^deg of degree ≤ [`MAX_DEG`], in a fixed array.
///
/// `deg` is the index of the highest non-zero coefficient (0 for constants, including the zero
/// polynomial); coefficients above it are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Poly {
    c: [f64; MAX_DEG + 1],
    deg: usize,
}

impl Poly {
    /// The zero polynomial.
    pub const ZERO: Poly = Poly {
        c: [0.0; MAX_DEG + 1],
        deg: 0,
    };

    /// From coefficients in increasing powers; `None` if there are more than `MAX_DEG + 1` of
    /// them or any is not finite.
    pub fn new(coeffs: &[f64]) -> Option<Poly> {
        if coeffs.len() > MAX_DEG + 1 || coeffs.iter().any(|c| !c.is_finite()) {
            return None;
        }
        let mut c = [0.0; MAX_DEG + 1];
        c[..coeffs.len()].copy_from_slice(coeffs);
        Some(Poly::trimmed(c))
    }

    /// The constant polynomial `a`.
    pub fn constant(a: f64) -> Poly {
        let mut c = [0.0; MAX_DEG + 1];
        c[0] = a;
        Poly { c, deg: 0 }
    }

    /// `a + b x`.
    pub fn linear(a: f64, b: f64) -> Poly {
        let mut c = [0.0; MAX_DEG + 1];
        c[0] = a;
        c[1] = b;
        Poly::trimmed(c)
    }

    fn trimmed(c: [f64; MAX_DEG + 1]) -> Poly {
        let deg = (0..=MAX_DEG).rev().find(|&i| c[i] != 0.0).unwrap_or(0);
        Poly { c, deg }
    }

    /// Degree (0 for constants and for the zero polynomial).
    pub fn degree(&self) -> usize {
        self.deg
    }

    /// Coefficients c0 … c_deg, increasing powers.
    pub fn coeffs(&self) -> &[f64] {
        &self.c[..=self.deg]
    }

    /// True for the zero polynomial.
    pub fn is_zero(&self) -> bool {
        self.deg == 0 && self.c[0] == 0.0
    }

    /// p(x) by Horner's rule.
    pub fn eval(&self, x: f64) -> f64 {
        self.c[..=self.deg]
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * x + c)
    }

    /// Σ|c_i||x|^i: the scale against which the rounding error of [`Poly::eval`] is measured.
    fn abs_eval(&self, x: f64) -> f64 {
        let ax = x.abs();
        self.c[..=self.deg]
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * ax + c.abs())
    }

    /// p′.
    pub fn derivative(&self) -> Poly {
        let mut c = [0.0; MAX_DEG + 1];
        for i in 1..=self.deg {
            c[i - 1] = self.c[i] * i as f64;
        }
        Poly::trimmed(c)
    }

    /// a·p.
    pub fn scale(&self, a: f64) -> Poly {
        let mut c = self.c;
        c.iter_mut().for_each(|ci| *ci *= a);
        Poly::trimmed(c)
    }

    /// p(−x).
    pub fn reflect(&self) -> Poly {
        let mut c = self.c;
        c.iter_mut().skip(1).step_by(2).for_each(|ci| *ci = -*ci);
        Poly { c, deg: self.deg }
    }

    /// p·q, or `None` if the product's degree would exceed [`MAX_DEG`].
    pub fn checked_mul(&self, other: &Poly) -> Option<Poly> {
        if self.is_zero() || other.is_zero() {
            return Some(Poly::ZERO);
        }
        if self.deg + other.deg > MAX_DEG {
            return None;
        }
        let mut c = [0.0; MAX_DEG + 1];
        for i in 0..=self.deg {
            for j in 0..=other.deg {
                c[i + j] += self.c[i] * other.c[j];
            }
        }
        Some(Poly::trimmed(c))
    }

    /// All real roots, in increasing order (see the module doc for the method).
    ///
    /// A constant polynomial, including zero (whose roots are not isolated), has none.
    pub fn real_roots(&self) -> Roots {
        if self.deg == 0 {
            return Roots::EMPTY;
        }
        let lead = self.c[self.deg].abs();
        let b = 1.0
            + self.c[..self.deg]
                .iter()
                .map(|c| c.abs() / lead)
                .fold(0.0, f64::max);
        self.real_roots_in(-b, b)
    }

    /// The real roots in the closed interval [lo, hi], increasing. An end of the interval is
    /// reported as a root when p is zero there to within rounding.
    pub fn real_roots_in(&self, lo: f64, hi: f64) -> Roots {
        let mut out = Roots::EMPTY;
        if self.deg == 0 || lo.is_nan() || hi.is_nan() || lo > hi {
            return out;
        }
        // Split points: lo, the critical points inside (lo, hi), hi.
        let mut pts = [0.0; MAX_DEG + 1];
        let mut np = 0;
        pts[np] = lo;
        np += 1;
        if self.deg >= 2 {
            let crit = self.derivative().real_roots_in(lo, hi);
            for &x in crit.as_slice() {
                if x > pts[np - 1] && x < hi {
                    pts[np] = x;
                    np += 1;
                }
            }
        }
        if hi > lo {
            pts[np] = hi;
            np += 1;
        }
        let mut vals = [0.0; MAX_DEG + 1];
        let mut zero = [false; MAX_DEG + 1];
        for i in 0..np {
            vals[i] = self.eval(pts[i]);
            let noise = 2.0 * (self.deg as f64 + 1.0) * f64::EPSILON * self.abs_eval(pts[i]);
            zero[i] = vals[i].abs() <= noise;
        }
        for i in 0..np {
            if i > 0 && !zero[i - 1] && !zero[i] && (vals[i - 1] < 0.0) != (vals[i] < 0.0) {
                out.push(self.bisect(pts[i - 1], pts[i], vals[i - 1]), false);
            }
            if zero[i] {
                // Inside the interval a zero critical point is a multiple root; an end of the
                // interval is simply a root at the end.
                let multiple = i > 0 && i + 1 < np;
                out.push(pts[i], multiple);
            }
        }
        out
    }

    /// The root of p in (a, b), where p is monotone and changes sign; `fa` = p(a).
    fn bisect(&self, a: f64, b: f64, fa: f64) -> f64 {
        crate::math::bisect(|x| self.eval(x), a, b, fa)
    }
}

impl Add for Poly {
    type Output = Poly;
    fn add(self, other: Poly) -> Poly {
        let mut c = self.c;
        for (ci, oi) in c.iter_mut().zip(other.c.iter()) {
            *ci += *oi;
        }
        Poly::trimmed(c)
    }
}

impl Neg for Poly {
    type Output = Poly;
    fn neg(self) -> Poly {
        self.scale(-1.0)
    }
}

impl Sub for Poly {
    type Output = Poly;
    fn sub(self, other: Poly) -> Poly {
        self + (-other)
    }
}

/// Real roots of a [`Poly`], increasing, each with a flag for "multiple root".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roots {
    x: [f64; MAX_DEG],
    multiple: [bool; MAX_DEG],
    len: usize,
}

impl Roots {
    const EMPTY: Roots = Roots {
        x: [0.0; MAX_DEG],
        multiple: [false; MAX_DEG],
        len: 0,
    };

    fn push(&mut self, x: f64, multiple: bool) {
        // A polynomial of degree ≤ MAX_DEG has at most MAX_DEG roots; the guard only matters
        // if rounding ever produced more candidates than that.
        if self.len < MAX_DEG {
            self.x[self.len] = x;
            self.multiple[self.len] = multiple;
            self.len += 1;
        }
    }

    /// The roots, increasing.
    pub fn as_slice(&self) -> &[f64] {
        &self.x[..self.len]
    }

    /// Whether root `i` was found as a multiple root (a zero critical point).
    pub fn is_multiple(&self, i: usize) -> bool {
        i < self.len && self.multiple[i]
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// det(A) for a square matrix of polynomials, by Laplace expansion along rows, or `None` if a
/// product would exceed [`MAX_DEG`] or `N` > 8.
///
/// ```text
/// det A = Σ_j (−1)^(position of j among the unused columns) · a_(r,j) · det(minor)
/// ```
/// Exact in the ring of polynomials (up to floating-point rounding of the coefficient
/// arithmetic); N! products, which is 120 for the 5×5 systems used here.
pub fn det<const N: usize>(a: &[[Poly; N]; N]) -> Option<Poly> {
    if N > 8 {
        return None;
    }
    det_rows(a, 0, 0)
}

fn det_rows<const N: usize>(a: &[[Poly; N]; N], row: usize, used: u32) -> Option<Poly> {
    if row == N {
        return Some(Poly::constant(1.0));
    }
    let mut sum = Poly::ZERO;
    let mut position = 0;
    for j in 0..N {
        if used & (1 << j) != 0 {
            continue;
        }
        if !a[row][j].is_zero() {
            let minor = det_rows(a, row + 1, used | (1 << j))?;
            let term = a[row][j].checked_mul(&minor)?;
            sum = if position % 2 == 0 {
                sum + term
            } else {
                sum - term
            };
        }
        position += 1;
    }
    Some(sum)
}
