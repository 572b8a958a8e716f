//! The envelope's decay, from the half-heights h_k of successive half-swings.
//!
//! ```text
//! x'' + c x' + ω0² x = −μ sgn x'     (linearised; c = 2σ viscous, μ Coulomb, rad/s²)
//! over one half-swing the arc is a damped harmonic about the centre shifted by δ = μ/ω0²
//! against the velocity, so the turning points' distances A_k from the true centre obey
//!     A_{k+1} + δ = r (A_k − δ),   r = e^{−σ T/2}  (T/2: the half-swing's duration)
//! and so does the half-height h_k = (A_k + A_{k+1})/2:
//!     h_{k+1} = r h_k − d,          d = δ (1 + r)
//! ```
//! A straight-line least-squares fit of h_{k+1} against h_k gives r and d, with their standard
//! errors from the residuals. Viscous only is r < 1, d = 0 (a geometric envelope: exponential in
//! time); Coulomb only is r = 1, d > 0 (a linear envelope).
//!
//! **Model selection.** Fit both. A mechanism is *present* when its estimate is more than
//! three standard errors from its null value (1 − r for viscous, d for Coulomb). Both present:
//! [`DecayModel::Both`], keep the two-parameter fit. One present: refit with that mechanism
//! alone (the other held at its null value), which halves the fitted parameters' variance.
//! Neither (too few or too noisy swings to separate them): the one-parameter fit with the
//! smaller residual sum of squares.

use super::error::CalibError;
use crate::math;

/// Which mechanisms the decay shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecayModel {
    Viscous,
    Coulomb,
    Both,
}

impl DecayModel {
    pub fn label(self) -> &'static str {
        match self {
            Self::Viscous => "viscous",
            Self::Coulomb => "coulomb",
            Self::Both => "viscous + coulomb",
        }
    }
}

/// The fitted decay per half-swing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decay {
    pub model: DecayModel,
    /// Amplitude ratio per half-swing (1 without viscous damping).
    pub ratio: f64,
    /// The Coulomb centre shift δ = μ/ω0² (rad; 0 without friction).
    pub shift: f64,
    /// Standard errors of `ratio` and of `shift` in the two-parameter fit.
    pub ratio_se: f64,
    pub shift_se: f64,
}

/// Fits `h` (half-heights of successive half-swings, rad).
pub fn fit(h: &[f64]) -> Result<Decay, CalibError> {
    const NEEDED: usize = 4;
    if h.len() < NEEDED {
        return Err(CalibError::TooFewSwings {
            found: h.len(),
            needed: NEEDED,
        });
    }
    let pairs = || h.windows(2).map(|w| (w[0], w[1]));
    let n = (h.len() - 1) as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in pairs() {
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let sse = |r: f64, d: f64| {
        pairs()
            .map(|(x, y)| (y - r * x + d) * (y - r * x + d))
            .sum::<f64>()
    };
    let den = n * sxx - sx * sx;
    // Two-parameter fit y = r x − d.
    let (r2, d2) = if den > 0.0 {
        let r = (n * sxy - sx * sy) / den;
        (r, (r * sx - sy) / n)
    } else {
        (1.0, 0.0)
    };
    let dof = (n - 2.0).max(1.0);
    let s2 = sse(r2, d2) / dof;
    let (r_se, d_se) = if den > 0.0 {
        (math::sqrt(s2 * n / den), math::sqrt(s2 * sxx / den))
    } else {
        (f64::INFINITY, f64::INFINITY)
    };
    // One-parameter fits: viscous (d = 0) and Coulomb (r = 1).
    let r1 = if sxx > 0.0 { sxy / sxx } else { 1.0 };
    let d1 = (sx - sy) / n;
    let viscous = 1.0 - r2 > 3.0 * r_se;
    let coulomb = d2 > 3.0 * d_se;
    let (model, r, d) = match (viscous, coulomb) {
        (true, true) => (DecayModel::Both, r2, d2),
        (true, false) => (DecayModel::Viscous, r1, 0.0),
        (false, true) => (DecayModel::Coulomb, 1.0, d1),
        (false, false) if sse(r1, 0.0) <= sse(1.0, d1) => (DecayModel::Viscous, r1, 0.0),
        (false, false) => (DecayModel::Coulomb, 1.0, d1),
    };
    if r > 1.0 || d < 0.0 || (r >= 1.0 && d <= 0.0) {
        return Err(CalibError::NotDecaying { ratio: r });
    }
    Ok(Decay {
        model,
        ratio: r,
        shift: d / (1.0 + r),
        ratio_se: r_se,
        shift_se: d_se / (1.0 + r),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn envelope(r: f64, delta: f64, h0: f64) -> [f64; 16] {
        let mut h = [0.0; 16];
        h[0] = h0;
        for k in 1..16 {
            h[k] = r * h[k - 1] - delta * (1.0 + r);
        }
        h
    }

    #[test]
    fn tells_the_mechanisms_apart_and_recovers_them() {
        // Exact recurrences (the module doc's), with a ±1e-5 rad alternating perturbation as
        // the sensor's residual after the peak fit.
        let noisy = |mut h: [f64; 16]| {
            for (k, v) in h.iter_mut().enumerate() {
                *v += if k % 2 == 0 { 1e-5 } else { -1e-5 };
            }
            h
        };
        let v = fit(&noisy(envelope(0.85, 0.0, 0.35))).unwrap();
        assert_eq!(v.model, DecayModel::Viscous);
        assert!((v.ratio - 0.85).abs() < 1e-3);
        let c = fit(&noisy(envelope(1.0, 0.005, 0.2))).unwrap();
        assert_eq!(c.model, DecayModel::Coulomb);
        assert!((c.shift - 0.005).abs() < 1e-4);
        let b = fit(&noisy(envelope(0.9, 0.004, 0.35))).unwrap();
        assert_eq!(b.model, DecayModel::Both);
        assert!(
            (b.ratio - 0.9).abs() < 2e-3 && (b.shift - 0.004).abs() < 2e-4,
            "{b:?}"
        );
    }

    #[test]
    fn refuses_a_growing_swing_and_too_few_swings() {
        let g = fit(&envelope(1.05, 0.0, 0.1));
        assert!(matches!(g, Err(CalibError::NotDecaying { .. })), "{g:?}");
        assert!(matches!(
            fit(&[0.3, 0.2, 0.1]),
            Err(CalibError::TooFewSwings {
                found: 3,
                needed: 4
            })
        ));
    }
}
