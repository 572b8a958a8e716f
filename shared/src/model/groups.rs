//! The dimensionless groups of physics §3.
//!
//! ```text
//! ω0 = √(g/ℓ)                  natural frequency
//! R  = A²ω²/(2gℓ) = (ω/ωc)²    drive strength; the inverted position is stable (averaging) iff R > 1
//! ωc = √(2gℓ)/A                critical frequency
//! m  = A/ℓ                     Mathieu amplitude
//! k  = ±g/(ℓω²) = ±(ω0/ω)²     signed: + about the hanging position, − about the inverted one
//! Q  = ω0/c                    quality factor of the damping term c θ'
//! δ  = c/ω                     damping per radian of drive phase
//! ```
//! Then R = m²/(2|k|), the identity the tests check.

use crate::error::{non_negative, positive, ParamError};
use crate::math;

/// Dimensionless groups of one pendulum under one drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Groups {
    pub omega0: f64,
    pub r: f64,
    pub omega_c: f64,
    pub m: f64,
    /// |k| = (ω0/ω)²; the sign depends on the position under study, see [`Groups::k`].
    pub k_abs: f64,
    /// Damping coefficient c (1/s).
    pub c: f64,
}

impl Groups {
    /// From the equivalent length ℓ (m), gravity g (m/s²), amplitude A (m), drive ω (rad/s) and
    /// damping c (1/s).
    pub fn new(
        ell: f64,
        gravity: f64,
        amplitude: f64,
        omega: f64,
        c: f64,
    ) -> Result<Self, ParamError> {
        let ell = positive("equivalent length", ell)?;
        let g = positive("gravity", gravity)?;
        let a = positive("amplitude", amplitude)?;
        let w = positive("omega", omega)?;
        let c = non_negative("damping", c)?;
        if !(c / w).is_finite() {
            // δ = c/ω would overflow.
            return Err(ParamError {
                name: "damping",
                value: c,
                allowed: "a finite number >= 0 with c/omega finite",
            });
        }
        Ok(Self {
            omega0: derived("omega0", math::sqrt(g / ell))?,
            r: derived("R", a * a * w * w / (2.0 * g * ell))?,
            omega_c: derived("omega_c", math::sqrt(2.0 * g * ell) / a)?,
            m: derived("m", a / ell)?,
            k_abs: derived("k", g / (ell * w * w))?,
            c,
        })
    }

    /// Signed k about the hanging (`inverted = false`, k > 0) or inverted (k < 0) position.
    pub fn k(&self, inverted: bool) -> f64 {
        if inverted {
            -self.k_abs
        } else {
            self.k_abs
        }
    }

    /// Q = ω0/c; infinite without damping.
    pub fn quality(&self) -> f64 {
        self.omega0 / self.c
    }

    /// δ = c/ω = √|k| / Q: damping per radian of drive phase.
    pub fn delta(&self) -> f64 {
        self.c / self.omega()
    }

    /// ω recovered from ω0 and |k|.
    pub fn omega(&self) -> f64 {
        self.omega0 / math::sqrt(self.k_abs)
    }
}

/// ω that gives drive strength R: ω = ωc √R (physics §7, "setting R means computing ω").
pub fn omega_for_r(r: f64, ell: f64, gravity: f64, amplitude: f64) -> Result<f64, ParamError> {
    let r = positive("R", r)?;
    let ell = positive("equivalent length", ell)?;
    let g = positive("gravity", gravity)?;
    let a = positive("amplitude", amplitude)?;
    derived("omega", math::sqrt(2.0 * g * ell) / a * math::sqrt(r))
}

/// A group computed from accepted inputs can still overflow or underflow (A = 1e200 m gives
/// R = ∞, a subnormal A gives R = 0): refused rather than returned as ∞ or 0.
fn derived(name: &'static str, value: f64) -> Result<f64, ParamError> {
    positive(name, value).map_err(|e| ParamError {
        allowed: "a finite number > 0 (the inputs overflow or underflow f64)",
        ..e
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_rod_example() {
        // physics §4.5: rod L = 0.25 m, A = 0.0127 m, ω = 188 rad/s, g = 9.81 → R = 1.7433
        // (closed form 3A²ω²/(4gL) = 1.74332…; tolerance 5e-5 covers the 4 printed decimals).
        let c = crate::cases::DEMO_ROD;
        let ell = 2.0 * c.length / 3.0;
        let g = Groups::new(ell, c.gravity, c.amplitude, c.omega, 0.0).unwrap();
        assert!((g.r - c.r.value).abs() < c.r.half_ulp, "R = {}", g.r);
        let closed = 3.0 * c.amplitude.powi(2) * c.omega.powi(2) / (4.0 * c.gravity * c.length);
        assert!((g.r - closed).abs() < 1e-12);
    }

    #[test]
    fn identities() {
        // R = m²/(2|k|) = (ω/ωc)², Q·δ = √|k| (physics §3), to rounding.
        let g = Groups::new(0.17, 9.81, 0.009, 330.0, 0.8).unwrap();
        assert!((g.r - g.m * g.m / (2.0 * g.k_abs)).abs() < 1e-12 * g.r);
        assert!((g.r - (330.0 / g.omega_c).powi(2)).abs() < 1e-12 * g.r);
        assert!((g.quality() * g.delta() - g.k_abs.sqrt()).abs() < 1e-12);
        assert!((g.omega() - 330.0).abs() < 1e-9);
        let w = omega_for_r(g.r, 0.17, 9.81, 0.009).unwrap();
        assert!((w - 330.0).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_input() {
        assert_eq!(
            Groups::new(0.0, 9.81, 0.01, 100.0, 0.0).unwrap_err().name,
            "equivalent length"
        );
        assert_eq!(
            Groups::new(0.1, 9.81, 0.01, f64::NAN, 0.0)
                .unwrap_err()
                .name,
            "omega"
        );
        assert_eq!(
            Groups::new(0.1, 9.81, 0.01, 100.0, -1.0).unwrap_err().name,
            "damping"
        );
        assert_eq!(omega_for_r(-1.0, 0.1, 9.81, 0.01).unwrap_err().name, "R");
    }
}
