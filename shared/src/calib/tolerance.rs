//! How accurate calibration must be, from the goal: the settle angle at R = 1.75, θd = 90° right
//! within 0.5°.
//!
//! ```text
//! R = A²ω²/(2gℓ), ω exact (the rig generates it)   ⇒   δR/R = 2 δA/A + δℓ/ℓ   (worst case)
//! θd = 90°, R > 1:  φ0 = arccos(1/R)  (physics §3)     ⇒   δφ0 = δR/R / √(R² − 1)
//! R = 1.75, δφ0 = 0.5°:   δR/R ≤ 0.5° · √(1.75² − 1) = 0.00873 · 1.436 = 1.25 %
//! ```
//! Split as ℓ within 0.4 % and A within 0.4 %: 2·0.4 + 0.4 = 1.2 % ≤ 1.25 %. The zero enters the
//! settle angle one for one and gets 0.2°; the damping's Q and Coulomb μ only need 10 % (they
//! enter the stroke's correction as (c/ω)² and the zero not at all).

use crate::math;

/// ℓ's and A's relative tolerances.
pub const LENGTH: f64 = 0.004;
pub const STROKE: f64 = 0.004;
/// Q's and μ's relative tolerances.
pub const Q: f64 = 0.10;
pub const COULOMB: f64 = 0.10;
/// The zero's tolerance (degrees).
pub const ZERO_DEG: f64 = 0.2;

/// The relative R error that moves the settle angle at θd = 90° by `deg` at drive strength `r`
/// (> 1).
pub fn r_budget(r: f64, deg: f64) -> f64 {
    math::to_rad(deg) * math::sqrt(r * r - 1.0)
}

/// The worst-case relative R error from relative errors of A and ℓ.
pub fn r_error(stroke: f64, length: f64) -> f64 {
    2.0 * stroke.abs() + length.abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{equilibria, DriveAngle};

    #[test]
    fn the_split_fits_the_budget() {
        let budget = r_budget(1.75, 0.5);
        assert!((budget - 0.012_53).abs() < 1e-5, "{budget}");
        assert!(r_error(STROKE, LENGTH) <= budget);
        // The sensitivity against the averaged model's equilibria (model::equilibria): R raised
        // by the budget moves the settle angle by 0.5° to within 2 % (arccos's second-order term
        // over a 1.25 % step).
        let d = DriveAngle::from_deg(90.0).unwrap();
        let at = |r: f64| {
            equilibria(r, d)
                .unwrap()
                .stable()
                .map(|e| e.angle.abs())
                .fold(f64::NAN, f64::max)
        };
        let moved = math::to_deg(at(1.75 * (1.0 + budget)) - at(1.75));
        assert!((moved - 0.5).abs() < 0.01, "{moved}");
    }
}
