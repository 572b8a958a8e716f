//! Level 3: harmonic balance (Butikov, "On the dynamic stabilization of an inverted pendulum",
//! Am. J. Phys. 69, 755 (2001)).
//!
//! On a stability boundary the undamped linearised equation has a periodic solution (Floquet
//! multiplier ±1, or e^{±2πi/n} at an order-n subharmonic). Put a truncated Fourier series of
//! that period into the equation, use cos τ · cos(pτ/n) = ½[cos((p+n)τ/n) + cos((p−n)τ/n)] (and
//! the same for sines), and require each retained harmonic's coefficient to vanish. A
//! non-trivial solution needs the determinant of that linear system to vanish: a polynomial in
//! m, expanded exactly ([`poly::det`]) and solved by real-root isolation ([`Poly::real_roots`]).
//!
//! ```text
//! x'' + (k − m cos τ) x = 0
//!
//! lower boundary (multiplier +1; the limit of infinitely long subharmonics):
//!   x = A0 + A1 cos τ + A2 cos 2τ
//!   1:       k A0 − (m/2) A1                  = 0
//!   cos τ:   −m A0 + (k − 1) A1 − (m/2) A2    = 0
//!   cos 2τ:  −(m/2) A1 + (k − 4) A2           = 0
//!   det = k(k − 1)(k − 4) − m²(3k − 8)/4 = 0  ⇒  m_min = 2 √( k(k−1)(k−4) / (3k−8) )
//!
//! upper boundary (multiplier −1, period 4π: flutter):
//!   x = A1 cos(τ/2) + A3 cos(3τ/2) + A5 cos(5τ/2); each row × 4:
//!   cos(τ/2):   (4k − 1 − 2m) A1 − 2m A3              = 0
//!   cos(3τ/2):  −2m A1 + (4k − 9) A3 − 2m A5          = 0
//!   cos(5τ/2):  −2m A3 + (4k − 25) A5                 = 0      (cos(7τ/2) dropped)
//!   D(m) = (4k−1−2m)[(4k−9)(4k−25) − 4m²] − 4m²(4k−25)          (a cubic)
//!   sine trial: the same with m → −m  ⇒  boundary = min |m| over the real roots of D
//!   dropping A5:  4m² + 2(4k−9) m − (4k−1)(4k−9) = 0
//!     ⇒  m_max = ¼[ √((4k−9)(20k−13)) + 4k − 9 ]      (its |·| is the root of least |m|)
//!
//! second-region upper boundary (1/4 < k ≤ 1; multiplier +1, sine type, the b2 curve):
//!   x = B1 sin τ + B2 sin 2τ + B3 sin 3τ
//!   (k−1) B1 − (m/2) B2 = 0;  −(m/2) B1 + (k−4) B2 − (m/2) B3 = 0;  −(m/2) B2 + (k−9) B3 = 0
//!   det = (k−1)(k−4)(k−9) − m²(2k − 10)/4 = 0  ⇒  m = √( 2(k−1)(k−4)(k−9) / (k−5) )
//!
//! order-n subharmonic (n ≥ 3; multiplier e^{±2πi/n}):
//!   x = Σ A_p sin(pτ/n),  p ∈ P = {1, n−1, n+1, 2n−1, 2n+1}
//!   sin(pτ/n) cos τ = ½[sin((p+n)τ/n) + sin((p−n)τ/n)],  sin(−qτ/n) = −sin(qτ/n)
//!   row p:  (k − p²/n²) A_p − (m/2)(A_(p−n) + A_(p+n)) = 0,   A_(−q) = −A_q,  A_0 = 0,
//!           harmonics outside P dropped; rows × n² below.
//!   couplings: 1 ↔ n−1 (+m/2, through A_(−q) = −A_q), 1 ↔ n+1, n−1 ↔ 2n−1, n+1 ↔ 2n+1 (−m/2):
//!   a symmetric 5×5 matrix linear in m; threshold = least m > 0 with det = 0 (a quintic).
//!   For n ≥ 3 the five p are distinct (1 < n−1 < n+1 < 2n−1 < 2n+1) and p ± n never lands on
//!   another member except through these couplings (3n − 1 = 2n + 1 only for n = 2).
//!   For n = 2 the set collapses to {1, 3, 5} and the threshold is the flutter boundary.
//! ```
//!
//! Butikov's printed systems contain sign misprints (physics §4); the ones above are derived here,
//! and the unit tests check each one independently of the algebra: the series built from a
//! null vector of the matrix at the root balances every retained harmonic of the equation.
//!
//! Truncation error, measured against Floquet (`tests/stability_agreement.rs`): harmonic
//! balance always lies slightly *above* the exact boundary. Lower end: +4e-6 (k = −0.1),
//! +6.9e-5 (k = −0.3), +2.6e-4 (k = −0.5); flutter cubic: +5e-7, +4.3e-6, +1.7e-5; the
//! truncated formula is 100–400× worse (+4e-4, +1.6e-3, +3.9e-3); order-n thresholds at
//! k = −0.3: +3e-4 (n = 3) falling to +8e-5 (n = 10). Cost: a few microseconds per window.

use super::{check_k, check_order, End, Window};
use crate::error::ParamError;
use crate::math;
use crate::poly::{self, Poly};

/// Reason for missing ends when the lower boundary reaches the upper one.
pub const NO_WINDOW: &str = "harmonic balance predicts no window: lower boundary >= upper";
/// Reason for a missing end for k > 1.
pub const BEYOND_SECOND_REGION: &str =
    "k > 1 lies beyond the second stability region; harmonic balance not set up there";
/// Reason for a missing truncated-formula value.
pub const NO_REAL_ROOT: &str = "(4k−9)(20k−13) < 0: the truncated flutter formula has no real root";
/// Reason for a missing subharmonic threshold: the least positive root lies past the window.
pub const OUTSIDE_WINDOW: &str =
    "the least positive root lies beyond the window: this order is not reached inside it";
/// Reason for a missing subharmonic threshold.
pub const NO_POSITIVE_ROOT: &str = "the 5×5 subharmonic determinant has no positive root";

/// Butikov's improved lower boundary `2 √(k(k−1)(k−4)/(3k−8))` for k < 0; 0 for k ≥ 0.
pub fn improved_lower(k: f64) -> Result<f64, ParamError> {
    let k = check_k(k)?;
    if k >= 0.0 {
        return Ok(0.0);
    }
    // k < 0: numerator k(k−1)(k−4) < 0 and denominator 3k − 8 < 0, so the ratio is positive.
    Ok(2.0 * math::sqrt(k * (k - 1.0) * (k - 4.0) / (3.0 * k - 8.0)))
}

/// The flutter determinant D(m) of the 3×3 system (cos type), exact in m.
pub fn flutter_determinant(k: f64) -> Result<Poly, ParamError> {
    let k = check_k(k)?;
    let l = Poly::linear;
    let z = Poly::ZERO;
    let a = [
        [l(4.0 * k - 1.0, -2.0), l(0.0, -2.0), z],
        [l(0.0, -2.0), l(4.0 * k - 9.0, 0.0), l(0.0, -2.0)],
        [z, l(0.0, -2.0), l(4.0 * k - 25.0, 0.0)],
    ];
    // Degree 3 ≤ poly::MAX_DEG: the expansion cannot overflow the capacity.
    Ok(poly::det(&a).unwrap_or(Poly::ZERO))
}

/// The flutter (period-2) boundary: the least |m| at which D(m) or D(−m) vanishes.
pub fn flutter_upper(k: f64) -> Result<f64, ParamError> {
    let d = flutter_determinant(k)?;
    // A cubic with a non-zero leading coefficient (−(−8) = 8 from −2m · −4m²) always has a real
    // root, so the minimum exists.
    Ok(d.real_roots()
        .as_slice()
        .iter()
        .map(|r| r.abs())
        .fold(f64::INFINITY, f64::min))
}

/// Butikov's truncated formula ¼[√((4k−9)(20k−13)) + 4k − 9], as the least |m| (its absolute
/// value; for k < 1/4 it is already positive).
pub fn truncated_upper(k: f64) -> Result<End, ParamError> {
    let k = check_k(k)?;
    let disc = (4.0 * k - 9.0) * (20.0 * k - 13.0);
    if disc < 0.0 {
        return Ok(End::Missing(NO_REAL_ROOT));
    }
    Ok(End::Value(
        (0.25 * (math::sqrt(disc) + 4.0 * k - 9.0)).abs(),
    ))
}

/// The second-region (b2-type) boundary √(2(k−1)(k−4)(k−9)/(k−5)), for 0 < k ≤ 1 (where the
/// ratio is ≥ 0; `abs` only turns the −0 at k = 1 into +0).
fn second_region_upper(k: f64) -> f64 {
    math::sqrt((2.0 * (k - 1.0) * (k - 4.0) * (k - 9.0) / (k - 5.0)).abs())
}

/// The window predicted by harmonic balance.
///
/// ```text
/// k < 0:          [improved_lower, flutter_upper]
/// 0 ≤ k ≤ 1/4:    [0, flutter_upper]
/// 1/4 < k ≤ 1:    [0, min(flutter_upper, second-region boundary)]
/// k > 1:          upper missing
/// ```
pub fn window(k: f64) -> Result<Window, ParamError> {
    let lower = improved_lower(k)?;
    if k > 1.0 {
        return Ok(Window {
            lower: End::Value(0.0),
            upper: End::Missing(BEYOND_SECOND_REGION),
            note: None,
        });
    }
    let mut upper = flutter_upper(k)?;
    if k > 0.25 {
        upper = upper.min(second_region_upper(k));
    }
    if lower >= upper && k < 0.0 {
        return Ok(Window {
            lower: End::Missing(NO_WINDOW),
            upper: End::Missing(NO_WINDOW),
            note: None,
        });
    }
    Ok(Window {
        lower: End::Value(lower),
        upper: End::Value(upper),
        note: None,
    })
}

/// The retained harmonics p of the order-n subharmonic trial series (3 ≤ n ≤ 1e6).
pub fn subharmonic_harmonics(n: u32) -> Result<[u32; 5], ParamError> {
    let n = check_order(n)?;
    if n < 3 {
        return Err(ParamError {
            name: "n",
            value: f64::from(n),
            allowed: "an integer >= 3 (for n = 2 the set collapses: use flutter_upper)",
        });
    }
    Ok([1, n - 1, n + 1, 2 * n - 1, 2 * n + 1])
}

/// The 5×5 order-n matrix (rows × n²): entry (i, j) is a polynomial in m.
pub fn subharmonic_matrix(k: f64, n: u32) -> Result<[[Poly; 5]; 5], ParamError> {
    let k = check_k(k)?;
    let set = subharmonic_harmonics(n)?;
    let nf = f64::from(n);
    let mut a = [[Poly::ZERO; 5]; 5];
    for (i, &p) in set.iter().enumerate() {
        let pf = f64::from(p);
        a[i][i] = Poly::constant(k * nf * nf - pf * pf);
        // A_(p−n) and A_(p+n), each with coefficient −(n²/2)·m; A_(−q) = −A_q flips the sign.
        // A_0 = 0 and harmonics outside the set find no column and drop out.
        for t in [i64::from(p) - i64::from(n), i64::from(p) + i64::from(n)] {
            let (q, sign) = if t < 0 { (-t, -1.0) } else { (t, 1.0) };
            if let Some(j) = set.iter().position(|&x| i64::from(x) == q) {
                a[i][j] = a[i][j] + Poly::linear(0.0, -0.5 * nf * nf * sign);
            }
        }
    }
    Ok(a)
}

/// The order-n subharmonic threshold: for n = 2 the flutter boundary, for n ≥ 3 the least
/// m > 0 where the 5×5 determinant vanishes (n = 2 at 1/4 < k ≤ 1, where the window ends on the
/// b2 curve first, is likewise missing).
///
/// The threshold is reported only when it lies inside this level's [`window`]: for the hanging
/// position with 0 < k < 1/4, say, tr M starts at 2 cos(2π√k) and never reaches the orders whose
/// 2 cos(2π/n) lies above that, and the quintic's least positive root is then a spurious one far
/// beyond the window (k = 0.1, n = 4: m ≈ 3.77, window ends at 0.28).
pub fn subharmonic_m(k: f64, n: u32) -> Result<End, ParamError> {
    let n = check_order(n)?;
    let upper = match window(k)?.upper {
        End::Value(u) => u,
        End::Missing(why) => return Ok(End::Missing(why)),
    };
    let least = if n == 2 {
        Some(flutter_upper(k)?)
    } else {
        let d = poly::det(&subharmonic_matrix(k, n)?).unwrap_or(Poly::ZERO);
        d.real_roots().as_slice().iter().copied().find(|&r| r > 0.0)
    };
    Ok(match least {
        Some(m) if m <= upper => End::Value(m),
        Some(_) => End::Missing(OUTSIDE_WINDOW),
        None => End::Missing(NO_POSITIVE_ROOT),
    })
}

#[cfg(test)]
mod tests;
