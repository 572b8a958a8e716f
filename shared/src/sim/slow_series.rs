//! The averaged equation's force as a power series about a step's start: what an adaptive run
//! evaluates at each stage instead of sin and cos.
//!
//! ```text
//! g(φ) = −ω0² sin φ − Hσ sin 2(φ − θd) + Kσ (sin u − 3 sin 3u)
//!          H = ω0² R_eff/2, σ the drive's strength, u = φ − θd,
//!          K = ω0² κ/8 the slider-crank's third-order push (physics §5.1), else 0
//! about φ0, with d = φ − φ0:
//!   sin(φ0 + d)         = sin φ0 cos d + cos φ0 sin d
//!   sin 2(φ0 + d − θd)  = S2 cos 2d + C2 sin 2d,     S2 = sin 2(φ0 − θd), C2 = cos 2(φ0 − θd)
//!   g(φ0 + d) = Σ_n G_n dⁿ
//!   G_2m   = (−1)^m/(2m)!   (−ω0² sin φ0 − Hσ S2 4^m)
//!   G_2m+1 = (−1)^m/(2m+1)! (−ω0² cos φ0 − 2Hσ C2 4^m)
//!   and with K: + (−1)^m/n! Kσ (S1 − 3^(n+1) S3)  (n = 2m; C1, C3 for n = 2m + 1),
//!   S1, C1 = sin, cos (φ0 − θd), S3, C3 = sin, cos 3(φ0 − θd)
//! ```
//! Twenty terms serve |d| ≤ 1/2, sixteen |d| ≤ 1/4, twelve |d| ≤ 1/16: the first terms left
//! out are at most (2d)²⁰/20! < 5e-19, (2d)¹⁶/16! < 8e-19 and (2d)¹²/12! < 4e-20 of 2Hσ (and
//! of ω0²), so the series is g to rounding. The push (sin u cos²u − ½ sin³u = (3 sin 3u −
//! sin u)/8) leaves out (3d)ⁿ/n! of 3Kσ: 4e-18 of it for twelve terms at |d| ≤ 1/16, 1.4e-15
//! for twenty at 1/2, with K a few per cent of H at most.
//!
//! A step computes the coefficients once (one sin/cos of φ0); a stage then costs one polynomial
//! in d evaluated in Estrin's scheme, whose dependency chain is four or five multiply–adds deep
//! instead of the sin, cos and products of the closed form (every stage waits for the previous
//! one's g, so that chain is the cost). σ must be constant over the step (a drive of constant
//! strength).

use crate::Real;

/// Coefficients kept.
const TERMS: usize = 20;
/// The largest |d| the series serves (rad).
pub const REACH: f64 = 0.5;
/// Up to this |d| the first sixteen coefficients suffice.
const NEAR: f64 = 0.25;
/// Up to this |d| the first twelve suffice: most stages of a run near rest.
const CLOSE: f64 = 1.0 / 16.0;

/// (−1)^m kⁿ/n! for k = 1, 2, 3 and n = 2m, 2m + 1 < [`TERMS`]: g's coefficients per unit of
/// the sin (cos) of φ0 or u0, of 2u0 and of 3u0 (u0 = φ0 − θd).
const fn tables() -> [[f64; TERMS]; 3] {
    let mut t = [[0.0; TERMS]; 3];
    let (mut inv_fact, mut two_n, mut three_n) = (1.0, 1.0, 1.0);
    let mut n = 0;
    while n < TERMS {
        let sign = if (n / 2) % 2 == 0 { 1.0 } else { -1.0 };
        t[0][n] = sign * inv_fact;
        t[1][n] = sign * inv_fact * two_n;
        t[2][n] = sign * inv_fact * three_n;
        n += 1;
        inv_fact /= n as f64;
        two_n *= 2.0;
        three_n *= 3.0;
    }
    t
}

const TABLES: [[f64; TERMS]; 3] = tables();

/// g(φ0 + d) = Σ G_n dⁿ about one step's start.
///
/// The even and the odd coefficients are kept apart, in the order the evaluation pairs them
/// ((G_0, G_2) with (G_1, G_3), …), so that two pairs load as one vector without shuffles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlowSeries<R> {
    /// G_0, G_2, …, G_18.
    even: [R; TERMS / 2],
    /// G_1, G_3, …, G_19.
    odd: [R; TERMS / 2],
}

impl<R: Real> SlowSeries<R> {
    /// About φ0 given sin φ0, cos φ0 and sin, cos of φ0 − θd; `omega0_sq` = ω0², `h_sigma` = Hσ.
    #[inline(always)]
    pub fn about(omega0_sq: R, h_sigma: R, (s0, c0): (R, R), (sr, cr): (R, R)) -> Self {
        let two = R::ONE + R::ONE;
        let (s2, c2) = (two * sr * cr, cr * cr - sr * sr);
        // Even n: the sines' parts; odd n: the cosines'.
        let (ea, eb) = (-omega0_sq * s0, -h_sigma * s2);
        let (oa, ob) = (-omega0_sq * c0, -h_sigma * c2);
        let mut even = [R::ZERO; TERMS / 2];
        let mut odd = [R::ZERO; TERMS / 2];
        for m in 0..TERMS / 2 {
            let (n0, n1) = (2 * m, 2 * m + 1);
            even[m] = R::from_f64(TABLES[0][n0]) * ea + R::from_f64(TABLES[1][n0]) * eb;
            odd[m] = R::from_f64(TABLES[0][n1]) * oa + R::from_f64(TABLES[1][n1]) * ob;
        }
        Self { even, odd }
    }

    /// The slider-crank's push Kσ (sin u − 3 sin 3u) added to the series, given sin and cos of
    /// u0 = φ0 − θd and `k_sigma` = Kσ. Only a drive with a connecting rod calls it.
    #[inline(always)]
    pub fn with_push(mut self, k_sigma: R, (sr, cr): (R, R)) -> Self {
        let three = R::from_f64(3.0);
        let four = R::from_f64(4.0);
        // sin 3u = 3 sin u − 4 sin³u, cos 3u = 4 cos³u − 3 cos u.
        let (s3, c3) = (sr * (three - four * sr * sr), cr * (four * cr * cr - three));
        let (ea, eb) = (k_sigma * sr, -three * k_sigma * s3);
        let (oa, ob) = (k_sigma * cr, -three * k_sigma * c3);
        for m in 0..TERMS / 2 {
            let (n0, n1) = (2 * m, 2 * m + 1);
            self.even[m] += R::from_f64(TABLES[0][n0]) * ea + R::from_f64(TABLES[2][n0]) * eb;
            self.odd[m] += R::from_f64(TABLES[0][n1]) * oa + R::from_f64(TABLES[2][n1]) * ob;
        }
        self
    }

    /// g(φ0) = G_0: the step's start, without the polynomial.
    #[inline(always)]
    pub fn at_zero(&self) -> R {
        self.even[0]
    }

    /// g(φ0 + d) for |d| ≤ [`REACH`].
    #[inline(always)]
    pub fn at(&self, d: R) -> R {
        self.at_then(d, (R::ZERO, R::ZERO)).0
    }

    /// g(φ0 + d) for |d| ≤ [`REACH`], and e + f g(φ0 + d) formed from the polynomial's
    /// parts: g = q0 + d⁴ q1 + d⁸ q2 + … (q_j: four terms each), so
    /// e + f g = (e + f q0) + (f d⁴) q1 + (f d⁸) q2 + …, whose products f dⁿ are ready before
    /// the q_j and whose chain is therefore two operations shorter than e + f g's.
    #[inline(always)]
    pub fn at_then(&self, d: R, (f, e): (R, R)) -> (R, R) {
        let (ev, od) = (&self.even, &self.odd);
        let d2 = d * d;
        let d4 = d2 * d2;
        let d8 = d4 * d4;
        // G_2m + G_2m+1 d: the terms n = 2m, 2m + 1.
        let pair = |m: usize| ev[m] + od[m] * d;
        // The terms n = 2m … 2m + 3.
        let quad = |m: usize| pair(m) + d2 * pair(m + 1);
        let (q0, q1, q2) = (quad(0), quad(2), quad(4));
        let (fd4, fd8) = (f * d4, f * d8);
        let size = d.abs().to_f64();
        if size <= CLOSE {
            let g = (q0 + d4 * q1) + d8 * q2;
            return (g, (e + f * q0) + (fd4 * q1 + fd8 * q2));
        }
        let q3 = quad(6);
        let d12 = d8 * d4;
        let sixteen = (q0 + d4 * q1) + d8 * (q2 + d4 * q3);
        let next16 = ((e + f * q0) + fd4 * q1) + (fd8 * q2 + (f * d12) * q3);
        if size <= NEAR {
            return (sixteen, next16);
        }
        let q4 = quad(8);
        let d16 = d8 * d8;
        (sixteen + d16 * q4, next16 + (f * d16) * q4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_series_is_the_closed_form_to_rounding() {
        // Against −ω0² sin φ − Hσ sin 2(φ − θd) by libm, about several φ0 and θd, over
        // |d| ≤ REACH (both the sixteen- and the twenty-term range): within 1e-14 of 2Hσ (a
        // few ulps of the terms' size).
        let (w0sq, hs) = (73.6, 121.0);
        let closed = |phi: f64, td: f64| -w0sq * phi.sin() - hs * (2.0 * (phi - td)).sin();
        for phi0 in [-3.0, -1.2, 0.0, 0.4, 2.07, 3.1] {
            for td in [0.0, 0.9, 2.356, -1.6] {
                let ser = SlowSeries::about(
                    w0sq,
                    hs,
                    (phi0.sin(), phi0.cos()),
                    ((phi0 - td).sin(), (phi0 - td).cos()),
                );
                // The start is G_0 itself: the value an evaluation at d = 0 gives.
                assert_eq!(ser.at_zero(), ser.at(0.0));
                for i in -50..=50 {
                    let d = REACH * f64::from(i) / 50.0;
                    let err = (ser.at(d) - closed(phi0 + d, td)).abs();
                    assert!(err < 1e-14 * 2.0 * hs, "φ0 {phi0} θd {td} d {d}: {err:e}");
                }
            }
        }
    }

    #[test]
    fn the_next_offset_is_e_plus_f_g_to_rounding() {
        // at_then's second value against e + f g with g by libm, for factors and offsets of a
        // stage's size (f = S² a w up to ~0.1, e up to ~1 rad) over |d| ≤ REACH: within 1e-14
        // of |e| + |f| 2Hσ (a few ulps of the terms' size).
        let (w0sq, hs) = (73.6, 121.0);
        let closed = |phi: f64, td: f64| -w0sq * phi.sin() - hs * (2.0 * (phi - td)).sin();
        for phi0 in [-2.2, 0.4, 2.07] {
            let td = 2.356;
            let ser = SlowSeries::about(
                w0sq,
                hs,
                (phi0.sin(), phi0.cos()),
                ((phi0 - td).sin(), (phi0 - td).cos()),
            );
            for (f, e) in [(0.0, 0.3), (1e-3, -0.2), (0.1, 1.0), (-0.05, 0.0)] {
                for i in -50..=50 {
                    let d = REACH * f64::from(i) / 50.0;
                    let (g, next) = ser.at_then(d, (f, e));
                    assert_eq!(g, ser.at(d));
                    let want = e + f * closed(phi0 + d, td);
                    let err = (next - want).abs();
                    let scale = e.abs() + f.abs() * 2.0 * hs;
                    assert!(
                        err < 1e-14 * scale.max(1e-300),
                        "φ0 {phi0} f {f} e {e} d {d}: {err:e}"
                    );
                }
            }
        }
    }
}
