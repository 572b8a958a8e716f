//! The four families of characteristic values, each the spectrum of its own tridiagonal block.
//!
//! Hill's matrix T(ν, q) ([`super`]) commutes with a reflection of the harmonics (r ↔ −r for
//! ν = 0, r ↔ −1 − r for ν = 1), so it splits into the symmetric (cosine) and antisymmetric
//! (sine) solutions, one block each (McLachlan §2.13–2.15; Abramowitz & Stegun 20.2.7–20.2.10):
//!
//! ```text
//! a₀, a₂, a₄, …   diagonal (2i)²,            coupling √2·q between rows 0 and 1, q elsewhere
//! b₂, b₄, b₆, …   diagonal (2i + 2)²,        coupling q
//! a₁, a₃, a₅, …   diagonal (2i + 1)², +q on row 0,   coupling q
//! b₁, b₃, b₅, …   diagonal (2i + 1)², −q on row 0,   coupling q
//! ```
//!
//! Within one block the eigenvalues are simple for q ≠ 0 and never cross, so "the i-th value of
//! this family" names one analytic curve λ(q), and a window end is where one such curve meets
//! a = 4k. One LDLᵀ pass over a block ([`Family::factor`]) gives, besides the Sturm count, the
//! derivatives of det(B(q) − xI) in x and in q, for Newton steps in either and for the slope
//! dλ/dq (implicit differentiation of det = 0).
//!
//! Two bounds used by the searches: the q-derivative of the block is the coupling pattern, a
//! restriction of T's off-diagonal of ones, whose norm is at most 2; so |dλ/dq| ≤ 2 (Weyl), and
//! by second-order perturbation theory λ'' = 2 Σ (vₖᵀ S vᵢ)²/(λᵢ − λₖ) over the other
//! eigenvectors of the same block, |λ''| ≤ 8/g with g the distance to the nearest other
//! eigenvalue of the block.

/// One family of characteristic values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// a₀, a₂, a₄, …: even order, cosine (ν = 0, tr M = +2).
    EvenCos,
    /// b₂, b₄, …: even order, sine (ν = 0).
    EvenSin,
    /// a₁, a₃, …: odd order, cosine (ν = 1, tr M = −2).
    OddCos,
    /// b₁, b₃, …: odd order, sine (ν = 1).
    OddSin,
}

/// One characteristic value: its family and its index in the family (from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Value {
    pub family: Family,
    pub index: u32,
}

impl Value {
    /// a_r (r ≥ 0).
    pub fn a(r: u32) -> Value {
        if r.is_multiple_of(2) {
            Value {
                family: Family::EvenCos,
                index: r / 2,
            }
        } else {
            Value {
                family: Family::OddCos,
                index: (r - 1) / 2,
            }
        }
    }

    /// b_r (r ≥ 1).
    pub fn b(r: u32) -> Value {
        debug_assert!(r >= 1);
        if r.is_multiple_of(2) {
            Value {
                family: Family::EvenSin,
                index: r / 2 - 1,
            }
        } else {
            Value {
                family: Family::OddSin,
                index: (r - 1) / 2,
            }
        }
    }

    /// Whether it belongs to ν = 1: its crossing of a is a tr M = −2 (flutter) boundary.
    pub fn is_odd(&self) -> bool {
        matches!(self.family, Family::OddCos | Family::OddSin)
    }
}

/// One LDLᵀ pass over B(q) − xI: the Sturm count and what Newton steps need. With pivots
/// p₀ … pₙ, det = (p₀ ⋯ pₙ₋₁)·pₙ, and ∂ det/det = Σ ∂pᵢ/pᵢ; the last pivot is kept apart so
/// that the ratios stay finite where det = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pivots {
    /// Eigenvalues below x.
    pub count: u32,
    /// The last pivot pₙ and its derivatives in x and q.
    pub last: f64,
    pub last_x: f64,
    pub last_q: f64,
    /// Σ ∂pᵢ/pᵢ over the other pivots, in x and in q.
    pub rest_x: f64,
    pub rest_q: f64,
    /// Some pivot was exactly zero (and moved): the derivatives near it are meaningless.
    pub degenerate: bool,
}

impl Pivots {
    /// ∂ det/∂x and ∂ det/∂q, both divided by p₀ ⋯ pₙ₋₁.
    fn derivatives(&self) -> (f64, f64) {
        (
            self.last * self.rest_x + self.last_x,
            self.last * self.rest_q + self.last_q,
        )
    }

    /// The Newton step in x towards a zero of det(B(q) − xI).
    pub fn newton_x(&self) -> f64 {
        -self.last / self.derivatives().0
    }

    /// The Newton step in q towards a zero of det(B(q) − xI).
    pub fn newton_q(&self) -> f64 {
        -self.last / self.derivatives().1
    }

    /// dλ/dq of the eigenvalue λ at x (det = 0 there): −(∂det/∂q)/(∂det/∂x).
    pub fn slope(&self) -> f64 {
        let (dx, dq) = self.derivatives();
        -dq / dx
    }
}

/// Newton steps in x end below this relative step.
const CONVERGED: f64 = 1e-9;

/// A pivot that is exactly zero is moved to the negative side (x on an eigenvalue then counts
/// as below, as in [`super::count_below`]), by an amount that keeps 1/p² finite.
const ZERO_PIVOT: f64 = -1e-150;

impl Family {
    /// Diagonal entry of row i and its derivative in q.
    fn diagonal(self, i: usize, q: f64) -> (f64, f64) {
        let i = i as f64;
        match self {
            Family::EvenCos => (4.0 * i * i, 0.0),
            Family::EvenSin => ((2.0 * i + 2.0) * (2.0 * i + 2.0), 0.0),
            Family::OddCos | Family::OddSin => {
                let d = (2.0 * i + 1.0) * (2.0 * i + 1.0);
                let s = if self == Family::OddCos { 1.0 } else { -1.0 };
                if i == 0.0 {
                    (d + s * q, s)
                } else {
                    (d, 0.0)
                }
            }
        }
    }

    /// The squared coupling between rows i − 1 and i, divided by q².
    fn coupling2(self, i: usize) -> f64 {
        if self == Family::EvenCos && i == 1 {
            2.0
        } else {
            1.0
        }
    }

    /// The eigenvalue i at q = 0: the diagonal entry, (order)².
    pub fn at_zero(self, i: u32) -> f64 {
        self.diagonal(i as usize, 0.0).0
    }

    /// The rows of the block for `harmonics` harmonics (as [`super::harmonics`] gives them).
    pub fn rows(harmonics: usize) -> usize {
        harmonics + 1
    }

    /// The LDLᵀ pass over B(q) − xI with `rows` rows.
    pub fn factor(self, q: f64, x: f64, rows: usize) -> Pivots {
        let (d, dq) = self.diagonal(0, q);
        let mut degenerate = d == x;
        let mut p = nonzero(d - x);
        let (mut px, mut pq) = (-1.0, dq);
        let mut count = u32::from(p < 0.0);
        let (mut rest_x, mut rest_q) = (0.0, 0.0);
        for i in 1..rows {
            let inv = 1.0 / p;
            let (rx, rq) = (px * inv, pq * inv);
            rest_x += rx;
            rest_q += rq;
            let c = self.coupling2(i);
            let (w, wq) = (c * q * q, 2.0 * c * q);
            let (d, dq) = self.diagonal(i, q);
            let raw = d - x - w * inv;
            degenerate |= raw == 0.0;
            p = nonzero(raw);
            px = -1.0 + w * rx * inv;
            pq = dq - wq * inv + w * rq * inv;
            count += u32::from(p < 0.0);
        }
        Pivots {
            count,
            last: p,
            last_x: px,
            last_q: pq,
            rest_x,
            rest_q,
            degenerate,
        }
    }

    /// The Sturm count alone: eigenvalues of the block below x.
    pub fn count(self, q: f64, x: f64, rows: usize) -> u32 {
        let mut p = nonzero(self.diagonal(0, q).0 - x);
        let mut count = u32::from(p < 0.0);
        for i in 1..rows {
            let w = self.coupling2(i) * q * q;
            p = nonzero(self.diagonal(i, q).0 - x - w / p);
            count += u32::from(p < 0.0);
        }
        count
    }
}

fn nonzero(p: f64) -> f64 {
    if p == 0.0 {
        ZERO_PIVOT
    } else {
        p
    }
}

/// Block rows enough for the eigenvalues near x at q (the harmonics of [`super::harmonics`]).
pub fn rows_for(x: f64, q: f64) -> usize {
    Family::rows(super::harmonics(x, q))
}

/// The eigenvalue `index` of the family at q, to within rounding (the slope to ≈ 1e-9):
/// Newton steps on det(B(q) − xI), kept inside the Sturm bracket [lo, hi] (count(lo) ≤ index <
/// count(hi)), from `guess`. Returns the value, its slope dλ/dq and the passes spent.
pub fn eigenvalue_in(
    v: Value,
    q: f64,
    mut lo: f64,
    mut hi: f64,
    guess: f64,
    rows: usize,
) -> (f64, f64, u64) {
    let fam = v.family;
    let mut x = if guess > lo && guess < hi {
        guess
    } else {
        lo + 0.5 * (hi - lo)
    };
    let mut passes = 0u64;
    for _ in 0..200 {
        let p = fam.factor(q, x, rows);
        passes += 1;
        if p.count > v.index {
            hi = x;
        } else {
            lo = x;
        }
        let step = p.newton_x();
        let scale = 1.0 + x.abs();
        // Converged, and onto this eigenvalue: x lies just below it (count = index, step up)
        // or just above it (count = index + 1, step down), not next to a neighbour. Newton's
        // next correction would be ≈ step²/g (g the distance to the neighbours), below
        // rounding for a step of 1e-9 relative.
        let onto = (p.count == v.index && step >= 0.0) || (p.count == v.index + 1 && step <= 0.0);
        if step.abs() <= CONVERGED * scale && onto && !p.degenerate {
            return (x + step, p.slope(), passes);
        }
        let mut next = x + step;
        if !(next > lo && next < hi) {
            next = lo + 0.5 * (hi - lo);
        }
        if next <= lo || next >= hi || hi - lo <= 4.0 * f64::EPSILON * scale {
            let mid = lo + 0.5 * (hi - lo);
            let p = fam.factor(q, mid, rows);
            return (mid, p.slope(), passes + 1);
        }
        x = next;
    }
    let mid = lo + 0.5 * (hi - lo);
    (mid, fam.factor(q, mid, rows).slope(), passes + 1)
}

/// The eigenvalue `index` of the family at q, bracketed by Weyl's bound (each eigenvalue lies
/// within ‖qS‖ ≤ 2|q| of its value at q = 0): the value, its slope dλ/dq and the passes spent.
pub fn eigenvalue_with_slope(v: Value, q: f64) -> (f64, f64, u64) {
    let r = 2.0 * q.abs() + 1.0;
    let (lo, hi) = (v.family.at_zero(v.index) - r, v.family.at_zero(v.index) + r);
    let rows = rows_for(hi, q);
    eigenvalue_in(v, q, lo, hi, v.family.at_zero(v.index), rows)
}

/// The eigenvalue `index` of the family at q.
pub fn eigenvalue(v: Value, q: f64) -> f64 {
    eigenvalue_with_slope(v, q).0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stability::hill::{count_below, harmonics};

    #[test]
    fn published_characteristic_values_per_family() {
        // Abramowitz & Stegun, Table 20.1 (q = 1, 5; 8 decimals): a₀, b₁, a₁, b₂ each from its
        // own block; the √2 coupling and the ±q on row 0 are what make these right.
        // Tolerance: half the last printed unit.
        let cases = [
            (Value::a(0), 1.0, -0.455_138_60),
            (Value::b(1), 1.0, -0.110_248_82),
            (Value::a(1), 1.0, 1.859_108_07),
            (Value::b(2), 1.0, 3.917_024_77),
            (Value::a(0), 5.0, -5.800_046_02),
            (Value::b(1), 5.0, -5.790_080_60),
        ];
        for (v, q, want) in cases {
            let got = eigenvalue(v, q);
            assert!((got - want).abs() < 5e-9, "{v:?} q {q}: {got} vs {want}");
        }
    }

    #[test]
    fn families_split_the_full_count() {
        // The cosine and sine blocks of ν = 0 (and of ν = 1) hold exactly the eigenvalues of
        // T(ν, q): their counts below x add up to the full matrix's, on a grid of (q, x).
        for i in 0..=30 {
            let q = 0.37 * f64::from(i);
            for j in 0..=40 {
                let x = -2.0 * q - 3.0 + 0.813 * f64::from(j);
                let n = harmonics(x, q);
                let rows = Family::rows(n);
                let even = Family::EvenCos.count(q, x, rows) + Family::EvenSin.count(q, x, rows);
                let odd = Family::OddCos.count(q, x, rows) + Family::OddSin.count(q, x, rows);
                assert_eq!(even, count_below(0.0, q, x, n), "ν 0 q {q} x {x}");
                assert_eq!(odd, count_below(1.0, q, x, n), "ν 1 q {q} x {x}");
                let p = Family::OddSin.factor(q, x, rows);
                assert_eq!(p.count, Family::OddSin.count(q, x, rows));
            }
        }
    }

    #[test]
    fn slope_matches_a_central_difference() {
        // dλ/dq by implicit differentiation against (λ(q + h) − λ(q − h))/2h of bisected
        // eigenvalues (h = 1e-5: truncation error ≈ h²λ'''/6 ≲ 1e-9; rounding ≈ 1e-16/h).
        for v in [
            Value::a(0),
            Value::b(1),
            Value::a(1),
            Value::b(2),
            Value::a(3),
        ] {
            for q in [0.3, 1.0, 4.0, 12.0] {
                let lam = eigenvalue(v, q);
                let rows = rows_for(lam.abs() + 10.0, q);
                let slope = v.family.factor(q, lam, rows).slope();
                let h = 1e-5;
                let fd = (eigenvalue(v, q + h) - eigenvalue(v, q - h)) / (2.0 * h);
                assert!((slope - fd).abs() < 1e-7, "{v:?} q {q}: {slope} vs {fd}");
                assert!(
                    slope.abs() <= 2.0,
                    "Weyl: |dλ/dq| ≤ 2 ({v:?} q {q}: {slope})"
                );
            }
        }
    }

    #[test]
    fn curvature_within_the_perturbation_bound() {
        // |λ''| ≤ 8/g (module doc), g the distance to the block's other eigenvalues: checked
        // with a second difference (h = 1e-3) where the bound is tightest, small g.
        for v in [
            Value::a(0),
            Value::b(1),
            Value::a(1),
            Value::b(2),
            Value::a(2),
        ] {
            for q in [0.5, 2.0, 6.0, 15.0] {
                let lam = eigenvalue(v, q);
                let below = (v.index > 0).then(|| {
                    eigenvalue(
                        Value {
                            index: v.index - 1,
                            ..v
                        },
                        q,
                    )
                });
                let above = eigenvalue(
                    Value {
                        index: v.index + 1,
                        ..v
                    },
                    q,
                );
                let g = below.map_or(above - lam, |b| (lam - b).min(above - lam));
                let h = 1e-3;
                let second = (eigenvalue(v, q + h) - 2.0 * lam + eigenvalue(v, q - h)) / (h * h);
                assert!(second.abs() <= 8.0 / g, "{v:?} q {q}: {second} vs 8/{g}");
            }
        }
    }
}
