//! Degree-2 trigonometric polynomials without a constant term, and all their roots on the circle.
//!
//! ```text
//! p(φ) = a1 cos φ + b1 sin φ + a2 cos 2φ + b2 sin 2φ
//! ρ1 = √(a1² + b1²),  ρ2 = √(a2² + b2²)
//! ```
//! The equilibrium condition of the averaged motion and its derivatives all have this form. Such a
//! p has at most four roots. They are isolated without sampling, so none is missed however close
//! two of them come:
//!
//! * ρ2 ≥ 4ρ1: p = ρ2 sin(2φ + α2) + (first harmonic). Every root lies within
//!   ½·asin(ρ1/ρ2) of a zero of the dominant term; there p' has the sign of the dominant term's
//!   derivative (|2ρ2 cos| ≥ 1.9ρ2 > ρ1), so each of the four windows holds exactly one root.
//! * ρ1 ≥ 4ρ2: likewise two windows around the zeros of ρ1 sin(φ + α1).
//! * otherwise the roots of p' (whose ρ2/ρ1 is twice p's, so the recursion ends within four
//!   levels) cut the circle into arcs on which p is monotone; each arc holds at most one root.
//!
//! A critical point where |p| is within rounding of zero is a double (or triple) root: it is
//! reported once, with `touch = true`, and the arcs beside it are not searched again.

use crate::math;

/// p(φ) = a1 cos φ + b1 sin φ + a2 cos 2φ + b2 sin 2φ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrigPoly2 {
    pub a1: f64,
    pub b1: f64,
    pub a2: f64,
    pub b2: f64,
}

/// A root of a [`TrigPoly2`] in [0, 2π).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrigRoot {
    pub angle: f64,
    /// A root where p touches zero at one of its own critical points (multiplicity ≥ 2).
    pub touch: bool,
}

/// At most four roots, in increasing angle.
#[derive(Debug, Clone, Copy)]
pub struct TrigRoots {
    roots: [TrigRoot; 4],
    len: usize,
}

impl TrigRoots {
    const EMPTY: TrigRoot = TrigRoot {
        angle: 0.0,
        touch: false,
    };

    fn new() -> Self {
        Self {
            roots: [Self::EMPTY; 4],
            len: 0,
        }
    }

    fn push(&mut self, r: TrigRoot) {
        // A degree-2 polynomial has at most four roots; a fifth candidate can only be a
        // numerical twin of one already found, which the caller merges away.
        if self.len < 4 {
            self.roots[self.len] = r;
            self.len += 1;
        }
    }

    pub fn as_slice(&self) -> &[TrigRoot] {
        &self.roots[..self.len]
    }

    fn sort(&mut self) {
        self.roots[..self.len].sort_unstable_by(|a, b| a.angle.total_cmp(&b.angle));
    }
}

impl TrigPoly2 {
    pub fn eval(&self, phi: f64) -> f64 {
        let (s, c) = math::sin_cos(phi);
        let (s2, c2) = (2.0 * s * c, c * c - s * s);
        self.a1 * c + self.b1 * s + self.a2 * c2 + self.b2 * s2
    }

    /// dp/dφ.
    pub fn derivative(&self) -> Self {
        Self {
            a1: self.b1,
            b1: -self.a1,
            a2: 2.0 * self.b2,
            b2: -2.0 * self.a2,
        }
    }

    /// Largest possible |p|: a bound for "zero within rounding".
    pub fn scale(&self) -> f64 {
        self.rho1() + self.rho2()
    }

    fn rho1(&self) -> f64 {
        math::sqrt(self.a1 * self.a1 + self.b1 * self.b1)
    }

    fn rho2(&self) -> f64 {
        math::sqrt(self.a2 * self.a2 + self.b2 * self.b2)
    }

    /// All roots in [0, 2π), each once. `tol` is relative to [`TrigPoly2::scale`]: a critical
    /// point with |p| ≤ tol·scale counts as a root of multiplicity ≥ 2.
    ///
    /// The zero polynomial has no isolated roots and returns none.
    pub fn roots(&self, tol: f64) -> TrigRoots {
        let mut out = TrigRoots::new();
        let (r1, r2) = (self.rho1(), self.rho2());
        if r1 == 0.0 && r2 == 0.0 {
            return out;
        }
        if r2 >= 4.0 * r1 {
            // Dominant ρ2 sin(2φ + α2): a2 = ρ2 sin α2, b2 = ρ2 cos α2.
            let alpha = math::atan2(self.a2, self.b2);
            let half = 0.5 * math::asin(r1 / r2) + 1e-3;
            for j in 0..4 {
                let centre = (f64::from(j) * math::PI - alpha) * 0.5;
                self.push_bracketed(&mut out, centre - half, centre + half);
            }
        } else if r1 >= 4.0 * r2 {
            // Dominant ρ1 sin(φ + α1): a1 = ρ1 sin α1, b1 = ρ1 cos α1.
            let alpha = math::atan2(self.a1, self.b1);
            let half = math::asin(r2 / r1) + 1e-3;
            for j in 0..2 {
                let centre = f64::from(j) * math::PI - alpha;
                self.push_bracketed(&mut out, centre - half, centre + half);
            }
        } else {
            self.roots_between_critical_points(&mut out, tol);
        }
        out.sort();
        out
    }

    /// The general case: p is monotone between consecutive critical points.
    fn roots_between_critical_points(&self, out: &mut TrigRoots, tol: f64) {
        let crit = self.derivative().roots(tol);
        let crit = crit.as_slice();
        let zero = tol * self.scale();
        let is_zero = |x: f64| self.eval(x).abs() <= zero;
        for c in crit {
            if is_zero(c.angle) {
                out.push(TrigRoot {
                    angle: c.angle,
                    touch: true,
                });
            }
        }
        for (i, lo) in crit.iter().enumerate() {
            let hi = if i + 1 < crit.len() {
                crit[i + 1].angle
            } else {
                crit[0].angle + math::TAU
            };
            if hi - lo.angle <= 0.0 || is_zero(lo.angle) || is_zero(hi) {
                continue; // an arc ending at a touching root holds no other (p is monotone)
            }
            let (plo, phi) = (self.eval(lo.angle), self.eval(hi));
            if (plo < 0.0) != (phi < 0.0) {
                let x = self.bisect(lo.angle, hi, plo);
                out.push(TrigRoot {
                    angle: wrap_2pi(x),
                    touch: false,
                });
            }
        }
    }

    /// Pushes the single root in a window where p is known to be strictly monotone and to change
    /// sign.
    fn push_bracketed(&self, out: &mut TrigRoots, lo: f64, hi: f64) {
        let plo = self.eval(lo);
        let x = self.bisect(lo, hi, plo);
        out.push(TrigRoot {
            angle: wrap_2pi(x),
            touch: false,
        });
    }

    /// Bisection to the last representable bit: p(lo) has sign of `plo`, p(hi) the other sign.
    fn bisect(&self, lo: f64, hi: f64, plo: f64) -> f64 {
        math::bisect(|x| self.eval(x), lo, hi, plo)
    }
}

/// Wraps to [0, 2π).
fn wrap_2pi(x: f64) -> f64 {
    let r = x - math::TAU * libm::floor(x / math::TAU);
    if r >= math::TAU {
        0.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn angles(p: &TrigPoly2) -> ([f64; 4], usize) {
        let r = p.roots(1e-13);
        let mut a = [0.0; 4];
        for (i, x) in r.as_slice().iter().enumerate() {
            a[i] = x.angle;
        }
        (a, r.as_slice().len())
    }

    #[test]
    fn pure_harmonics() {
        // sin φ: roots 0 and π (closed form).
        let (a, n) = angles(&TrigPoly2 {
            a1: 0.0,
            b1: 1.0,
            a2: 0.0,
            b2: 0.0,
        });
        assert_eq!(n, 2);
        assert!(a[0].abs() < 1e-15 && (a[1] - math::PI).abs() < 1e-15);
        // cos 2φ: roots π/4 + jπ/2.
        let (a, n) = angles(&TrigPoly2 {
            a1: 0.0,
            b1: 0.0,
            a2: 1.0,
            b2: 0.0,
        });
        assert_eq!(n, 4);
        for (j, x) in a.iter().enumerate() {
            assert!((x - (math::PI / 4.0 + j as f64 * math::PI / 2.0)).abs() < 1e-14);
        }
    }

    #[test]
    fn triple_root_reported_once() {
        // sin φ + ½ sin 2φ = sin φ (1 + cos φ): a triple root at π (the cusp R = 1, θd = 0).
        let p = TrigPoly2 {
            a1: 0.0,
            b1: 1.0,
            a2: 0.0,
            b2: 0.5,
        };
        let r = p.roots(1e-13);
        let near_pi: usize = r
            .as_slice()
            .iter()
            .filter(|x| (x.angle - math::PI).abs() < 1e-3)
            .count();
        assert_eq!(near_pi, 1, "{:?}", r.as_slice());
        assert_eq!(r.as_slice().len(), 2); // and the simple root at 0
    }
}
