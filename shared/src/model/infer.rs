//! R inferred from a settled angle (physics §7).
//!
//! ```text
//! from the equilibrium condition:   R = −2 sin φ0 / sin 2(φ0 − θd)
//! from the slow frequency:          R = ((ωp/ω0)² − cos φ0) / cos 2(φ0 − θd)
//! ```
//! The first is singular where sin 2(φ0 − θd) = 0 — at θd = 0° and 180° the equilibria sit at
//! φ0 = 0 or π, exactly there — and ill-conditioned near it. The second needs ωp and fails where
//! cos 2(φ0 − θd) = 0. Each is used where it is well conditioned; with neither, an error says why.

use super::drive::DriveAngle;
use crate::error::{finite, positive, ParamError};
use crate::math;

/// Below this |sin 2(φ0 − θd)| the angle formula is not used: its relative error in R grows as
/// 1/|sin 2(φ0 − θd)| times the angle error.
pub const SINGULAR_SIN: f64 = 0.05;

/// How R was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RMethod {
    EquilibriumAngle,
    SlowFrequency,
}

/// R with the formula used and its sensitivity to the settled angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RInference {
    pub r: f64,
    pub method: RMethod,
    /// dR/dφ0 (per radian): multiply by the angle's uncertainty for R's.
    pub dr_dphi: f64,
}

/// Why R could not be inferred.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InferError {
    Param(ParamError),
    /// The angle formula is singular here and no slow frequency was given.
    NeedSlowFrequency,
    /// Both formulas are singular or give a negative R: the angle is not an equilibrium of a
    /// drive at this θd.
    NotAnEquilibrium,
}

impl From<ParamError> for InferError {
    fn from(e: ParamError) -> Self {
        Self::Param(e)
    }
}

impl core::fmt::Display for InferError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Param(e) => e.fmt(f),
            Self::NeedSlowFrequency => f.write_str(
                "R cannot be read from this angle (sin 2(phi0 - theta_d) is ~0, as at theta_d = 0 or 180 deg): \
                 give the slow oscillation frequency omega_p/omega0",
            ),
            Self::NotAnEquilibrium => {
                f.write_str("the angle is not an equilibrium for any R >= 0 at this drive angle")
            }
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for InferError {}

/// R from a settled angle φ0 (rad) at drive angle θd, using ωp/ω0 where the angle alone cannot
/// tell.
pub fn infer_r(
    theta_d: DriveAngle,
    phi0: f64,
    omega_p_over_omega0: Option<f64>,
) -> Result<RInference, InferError> {
    let phi0 = finite("settled angle", phi0)?;
    // Wrapped, so that 2ψ cannot overflow for a huge (finite) φ0.
    let psi = math::wrap_pi(phi0 - theta_d.rad());
    let (s2, c2) = math::sin_cos(2.0 * psi);
    let (sp, cp) = math::sin_cos(phi0);
    if s2.abs() >= SINGULAR_SIN {
        let r = -2.0 * sp / s2;
        if r < 0.0 {
            return Err(InferError::NotAnEquilibrium);
        }
        // d/dφ0 of −2 sin φ0 / sin 2ψ
        let dr = (-2.0 * cp * s2 + 4.0 * sp * c2) / (s2 * s2);
        return Ok(RInference {
            r,
            method: RMethod::EquilibriumAngle,
            dr_dphi: dr,
        });
    }
    let wp = omega_p_over_omega0.ok_or(InferError::NeedSlowFrequency)?;
    let wp = positive("omega_p/omega0", wp)?;
    if c2.abs() < SINGULAR_SIN {
        return Err(InferError::NotAnEquilibrium);
    }
    let r = (wp * wp - cp) / c2;
    if r < 0.0 {
        return Err(InferError::NotAnEquilibrium);
    }
    if !r.is_finite() {
        // (ωp/ω0)² overflowed: no drive gives such a slow frequency.
        return Err(InferError::Param(ParamError {
            name: "omega_p/omega0",
            value: wp,
            allowed: "small enough that R = ((omega_p/omega0)^2 - cos phi0) / cos 2(phi0 - theta_d) is finite",
        }));
    }
    let dr = (sp * c2 + 2.0 * (wp * wp - cp) * s2) / (c2 * c2);
    Ok(RInference {
        r,
        method: RMethod::SlowFrequency,
        dr_dphi: dr,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::equilibria::equilibria;

    #[test]
    fn round_trip_through_equilibria() {
        // Forward: equilibria(R, θd) finds φ0; inverse must return R (to the root's precision).
        for (r, deg) in [(1.75, 90.0), (3.3, 135.0), (2.5, 120.0), (1.2, 60.0)] {
            let d = DriveAngle::from_deg(deg).unwrap();
            for e in equilibria(r, d).unwrap().stable() {
                let got = infer_r(d, e.angle, None).unwrap();
                assert_eq!(got.method, RMethod::EquilibriumAngle);
                assert!((got.r - r).abs() < 1e-9 * r, "R {r} θd {deg}: {got:?}");
            }
        }
    }

    #[test]
    fn singular_angles_use_slow_frequency() {
        // θd = 180°, R = 3: inverted, ωp/ω0 = √(R − 1) (physics §3 closed form).
        let d = DriveAngle::from_deg(180.0).unwrap();
        assert_eq!(
            infer_r(d, math::PI, None),
            Err(InferError::NeedSlowFrequency)
        );
        let got = infer_r(d, math::PI, Some(2f64.sqrt())).unwrap();
        assert_eq!(got.method, RMethod::SlowFrequency);
        assert!((got.r - 3.0).abs() < 1e-12);
        // θd = 0, R = 0.5: hanging, ωp/ω0 = √(1 + R).
        let d = DriveAngle::from_deg(0.0).unwrap();
        let got = infer_r(d, 0.0, Some(1.5f64.sqrt())).unwrap();
        assert!((got.r - 0.5).abs() < 1e-12);
    }

    #[test]
    fn rejects_non_equilibria() {
        // At θd = 90°, f(φ) = sin φ − (R/2) sin 2φ; at φ0 = 120° both terms are positive for every
        // R ≥ 0, so no drive strength holds the pendulum there (the formula gives R = −2).
        let d = DriveAngle::from_deg(90.0).unwrap();
        assert_eq!(
            infer_r(d, math::to_rad(30.0), None).map(|r| r.method),
            Ok(RMethod::EquilibriumAngle)
        );
        assert_eq!(
            infer_r(d, math::to_rad(120.0), None),
            Err(InferError::NotAnEquilibrium)
        );
        assert!(infer_r(d, f64::NAN, None).is_err());
    }
}
