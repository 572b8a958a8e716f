//! The mount's true drive angle from the hanging pendulum: a plumb line for the servo.
//!
//! Hanging under a drive across it (R < 1, θd near 90°), the slow equilibrium (physics §3)
//!
//! ```text
//! sin φ0 + (R/2) sin 2(φ0 − θd) = 0
//! ```
//! leans by φ0 ≈ −R δ/(1 − R) when the mount sits δ past 90° (R = 0.5: a 2° offset tilts it
//! 2°). Solved for θd on the branch where 2(φ0 − θd) is near −180°:
//!
//! ```text
//! θd = φ0 + π/2 − ½ asin(2 sin φ0 / R)
//! ```
//! With φ0 read through the calibrated zero (0.2°) and R from the calibrated A and ℓ, the
//! mount's angle comes out within about 0.3° at R = 0.5 (δθd ≈ δφ0 (1 − R)/R for the zero's
//! part). This is how calibration corrects the servo's map when nobody is at the marks.

use super::error::CalibError;
use crate::math;

/// The true θd (rad) that holds the pendulum at `phi0` (rad, from hanging) with drive strength
/// `r` (< 1), on the branch near θd = 90°.
pub fn drive_angle(phi0: f64, r: f64) -> Result<f64, CalibError> {
    let r = super::error::positive("R", r)?;
    let s = 2.0 * math::sin(phi0) / r;
    if !(-1.0..=1.0).contains(&s) {
        return Err(CalibError::NotAcrossDrive {
            sin: s.abs(),
            needed: 1.0,
        });
    }
    Ok(phi0 + math::FRAC_PI_2 - math::asin(s) / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{equilibria, DriveAngle};

    #[test]
    fn inverts_the_averaged_equilibrium() {
        // The hanging equilibria of model::equilibria at θd = 88°…92°, R = 0.5 and 0.8: the
        // formula gives θd back to rounding.
        for r in [0.5, 0.8] {
            for deg in [88.0, 90.0, 91.0, 92.0] {
                let d = DriveAngle::from_deg(deg).unwrap();
                let phi0 = equilibria(r, d)
                    .unwrap()
                    .stable()
                    .map(|e| e.angle)
                    .find(|a| a.abs() < 0.5)
                    .unwrap();
                let got = math::to_deg(drive_angle(phi0, r).unwrap());
                assert!((got - deg).abs() < 1e-9, "R {r} θd {deg}: {got}");
            }
        }
        assert!(drive_angle(0.5, 0.5).is_err());
    }
}
