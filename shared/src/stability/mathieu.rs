//! Level 2: the small-q series of Mathieu's characteristic values.
//!
//! With z = τ/2 the undamped linearised equation is Mathieu's (physics §4):
//!
//! ```text
//! y'' + (a − 2q cos 2z) y = 0,   a = 4k,  q = 2m
//! ```
//!
//! Its stability regions are bounded by the characteristic values a_r(q) (even solutions) and
//! b_r(q) (odd solutions), on which a solution of period π (r even) or 2π (r odd) exists.
//! Series for small q (Abramowitz & Stegun, *Handbook of Mathematical Functions*, 20.2.25;
//! McLachlan, *Theory and Application of Mathieu Functions*, §2.151; for q ≥ 0, and a1, b1 odd
//! in q are written in |q|):
//!
//! ```text
//! a0(q) = −q²/2 + 7q⁴/128 − 29q⁶/2304
//! b1(q) = 1 − q − q²/8 + q³/64 − q⁴/1536 − 11q⁵/36864
//! a1(q) = 1 + q − q²/8 − q³/64 − q⁴/1536 + 11q⁵/36864
//! b2(q) = 4 − q²/12 + 5q⁴/13824
//! first stable region:   a0(q) < a < b1(q)
//! second stable region:  a1(q) < a < b2(q)
//! ```
//!
//! A window in m at fixed k is where a horizontal line a = 4k crosses these curves:
//!
//! ```text
//! k < 0:         lower: a0(2m) = 4k,   upper: b1(2m) = 4k
//! 0 ≤ k ≤ 1/4:   lower: m = 0,         upper: b1(2m) = 4k
//! 1/4 < k ≤ 1:   lower: m = 0,         upper: the first of a1(2m) = 4k, b2(2m) = 4k
//! k > 1:         beyond the second region; not covered by these four series
//! ```
//!
//! The crossings are the smallest positive real roots of the polynomials a0(q) − a etc.,
//! found by [`Poly::real_roots_in`] — the truncated a0 always crosses, but truncated a1 peaks
//! near a ≈ 2.5 and then no longer does, so "no root" is a real outcome, reported as such.
//!
//! Validity: the series are asymptotic in small q. Measured against Floquet boundaries at
//! fixed q (tests below; Floquet with 1000 RK4 steps, bisected in a to 1e-12), the error in a
//! matches the first omitted term: at q = 0.3 it is 2.3e-7 (a0), 6e-8 (b1, a1), 2.5e-9 (b2).
//! It grows like q⁸ for a0, the worst curve: 2.8e-3 at q = 1, 1.5e-2 at q = 1.25, 5.5e-2 at
//! q = 1.5, 0.42 at q = 2 (b1, a1, b2 stay ≤ 1e-4 up to q = 1 and ≤ 5e-3 up to q = 2). Hence
//! [`Q_VALID`] = 1: inside it every curve is within 3e-3 in a; a window end found beyond it
//! carries the note [`OUTSIDE_RANGE`]. For the inverted position this is nearly always the
//! case (k = −0.3 has its window at q ≈ 1.7–1.9), which is why the series' lower end there is
//! 0.05 below Floquet's (see the tests).

use super::{check_k, End, Window, M_MAX};
use crate::error::ParamError;
use crate::poly::Poly;

/// The largest |q| where the series are trusted (see the module doc for the measurement).
pub const Q_VALID: f64 = 1.0;

/// Note for a window end found at q > [`Q_VALID`].
pub const OUTSIDE_RANGE: &str =
    "Mathieu series used outside its range |q| <= 1: expect errors of 1e-2 or more in m";
/// Reason for a missing end when the truncated series never reaches a = 4k.
pub const NO_CROSSING: &str = "the truncated Mathieu series never reaches a = 4k for q <= 50";
/// Reason for missing ends when the series' curves cross before a window opens.
pub const NO_WINDOW: &str = "the Mathieu series predicts no window: b1 is reached before a0";
/// Reason for a missing upper end for k > 1.
pub const BEYOND_SECOND_REGION: &str =
    "k > 1 lies beyond the second stability region; series not covered here";

/// A characteristic-value curve, as a polynomial in q ≥ 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Curve {
    A0,
    B1,
    A1,
    B2,
}

impl Curve {
    /// The series as a polynomial in q (valid for q ≥ 0).
    pub fn poly(self) -> Poly {
        let c: &[f64] = match self {
            Curve::A0 => &[0.0, 0.0, -1.0 / 2.0, 0.0, 7.0 / 128.0, 0.0, -29.0 / 2304.0],
            Curve::B1 => &[
                1.0,
                -1.0,
                -1.0 / 8.0,
                1.0 / 64.0,
                -1.0 / 1536.0,
                -11.0 / 36864.0,
            ],
            Curve::A1 => &[
                1.0,
                1.0,
                -1.0 / 8.0,
                -1.0 / 64.0,
                -1.0 / 1536.0,
                11.0 / 36864.0,
            ],
            Curve::B2 => &[4.0, 0.0, -1.0 / 12.0, 0.0, 5.0 / 13824.0],
        };
        // Seven or fewer finite coefficients: always representable.
        Poly::new(c).unwrap_or(Poly::ZERO)
    }

    /// The characteristic value at q (the series in |q|); |q| ≤ 50.
    pub fn value(self, q: f64) -> Result<f64, ParamError> {
        if !(q.is_finite() && q.abs() <= 2.0 * M_MAX) {
            return Err(ParamError {
                name: "q",
                value: q,
                allowed: "a finite number with |q| <= 50",
            });
        }
        Ok(self.poly().eval(q.abs()))
    }

    /// The smallest q in [0, 50] with curve(q) = a, if the truncated series reaches a.
    fn crossing(self, a: f64) -> Option<f64> {
        let p = self.poly() - Poly::constant(a);
        p.real_roots_in(0.0, 2.0 * M_MAX)
            .as_slice()
            .first()
            .copied()
    }
}

/// a0(q) (A&S 20.2.25).
pub fn a0(q: f64) -> Result<f64, ParamError> {
    Curve::A0.value(q)
}
/// b1(q) (A&S 20.2.25).
pub fn b1(q: f64) -> Result<f64, ParamError> {
    Curve::B1.value(q)
}
/// a1(q) (A&S 20.2.25).
pub fn a1(q: f64) -> Result<f64, ParamError> {
    Curve::A1.value(q)
}
/// b2(q) (A&S 20.2.25).
pub fn b2(q: f64) -> Result<f64, ParamError> {
    Curve::B2.value(q)
}

/// The undamped stability window in m predicted by the series (see the module doc).
///
/// ```
/// use kapitza_core::stability::mathieu;
/// // k = 0: upper end where b1(q) = 0, q ≈ 0.908 (m ≈ 0.454); lower end m = 0.
/// let w = mathieu::window(0.0).unwrap();
/// assert_eq!(w.lower.value(), Some(0.0));
/// assert!((w.upper.value().unwrap() - 0.4540).abs() < 1e-3);
/// assert_eq!(w.note, None); // q ≈ 0.91 ≤ 1: inside the series' range
/// ```
pub fn window(k: f64) -> Result<Window, ParamError> {
    let k = check_k(k)?;
    let a = 4.0 * k;
    let end = |q: Option<f64>| q.map_or(End::Missing(NO_CROSSING), |q| End::Value(0.5 * q));
    let (lower, upper) = if k < 0.0 {
        let ql = Curve::A0.crossing(a);
        let qu = Curve::B1.crossing(a);
        match (ql, qu) {
            (Some(l), Some(u)) if u <= l => (End::Missing(NO_WINDOW), End::Missing(NO_WINDOW)),
            _ => (end(ql), end(qu)),
        }
    } else if k <= 0.25 {
        (End::Value(0.0), end(Curve::B1.crossing(a)))
    } else if k <= 1.0 {
        let q = match (Curve::A1.crossing(a), Curve::B2.crossing(a)) {
            (Some(x), Some(y)) => Some(x.min(y)),
            (x, y) => x.or(y),
        };
        (End::Value(0.0), end(q))
    } else {
        (End::Value(0.0), End::Missing(BEYOND_SECOND_REGION))
    };
    let outside = [lower, upper]
        .iter()
        .any(|e| e.value().is_some_and(|m| 2.0 * m > Q_VALID));
    Ok(Window {
        lower,
        upper,
        note: outside.then_some(OUTSIDE_RANGE),
    })
}

#[cfg(test)]
mod tests;
