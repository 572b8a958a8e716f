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
//!
//! A slider-crank's second harmonic leans the hanging pendulum too, as a mount tilted by
//! about 1.5 B/ℓ would (B = A²/4b; 0.35° for the demo rod on a 60 mm rod). With the rod
//! known, the closed form is the start of Newton's method on the balance with its terms
//! ([`crate::model::slider_crank`]).

use super::error::CalibError;
use crate::math;
use crate::model::slider_crank::{drive_angle_near, SliderCrank};

/// The true θd (rad) that holds the pendulum at `phi0` (rad, from hanging) with first-harmonic
/// drive strength `r` (< 1) and the drive's slider-crank, if any, on the branch near θd = 90°.
pub fn drive_angle(phi0: f64, r: f64, crank: Option<&SliderCrank>) -> Result<f64, CalibError> {
    let r = super::error::positive("R", r)?;
    let r_e = r * crank.map_or(1.0, SliderCrank::strength_gain);
    let s = 2.0 * math::sin(phi0) / r_e;
    if !(-1.0..=1.0).contains(&s) {
        return Err(CalibError::NotAcrossDrive {
            sin: s.abs(),
            needed: 1.0,
        });
    }
    let sine = phi0 + math::FRAC_PI_2 - math::asin(s) / 2.0;
    match crank {
        None => Ok(sine),
        Some(c) => drive_angle_near(phi0, sine, r, Some(c)).ok_or(CalibError::NotAcrossDrive {
            sin: s.abs(),
            needed: 1.0,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::slider_crank::equilibrium_near;
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
                let got = math::to_deg(drive_angle(phi0, r, None).unwrap());
                assert!((got - deg).abs() < 1e-9, "R {r} θd {deg}: {got}");
            }
        }
        assert!(drive_angle(0.5, 0.5, None).is_err());
    }

    #[test]
    fn inverts_the_balance_with_a_slider_crank() {
        // The demo rod on a 12.7 mm crank and a 60 mm rod: the hanging equilibrium of the
        // balance with the rod's terms (model::slider_crank, checked there against the full
        // equation) gives θd back to rounding; the sine's formula would miss it by the lean.
        let crank = SliderCrank {
            amplitude: 0.0127,
            rod: 0.06,
            ell: 2.0 * 0.25 / 3.0,
        };
        for deg in [88.0, 90.0, 92.0] {
            let d = math::to_rad(deg);
            let phi0 = equilibrium_near(0.0, d, 0.5, Some(&crank)).unwrap();
            let got = math::to_deg(drive_angle(phi0, 0.5, Some(&crank)).unwrap());
            assert!((got - deg).abs() < 1e-9, "θd {deg}: {got}");
            let sine = math::to_deg(drive_angle(phi0, 0.5, None).unwrap());
            assert!((sine - deg).abs() > 0.2, "θd {deg}: {sine}");
        }
    }
}
