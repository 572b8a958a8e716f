//! The slider-crank's second harmonic in the averaged theory (physics §5.1).
//!
//! A crank of radius A driving the carriage through a connecting rod b moves the pivot along
//! the drive line as s = A cos ψ + B cos 2ψ + …, B = A²/(4b) (s measured from the crank's axle
//! towards the carriage, ψ = ωt). Averaging θ'' = −ω0² sin θ + (s''/ℓ) sin(θ − θd) over a
//! drive period to third order in the stroke, with u = φ − θd and R = A²ω²/(2gℓ) the first
//! harmonic's drive strength:
//!
//! ```text
//! φ''/ω0² = −sin φ − (R_e/2) sin 2u − κ sin u (cos²u − ½ sin²u)
//! R_e = R (1 + (A/2b)²)          the mean-square pivot speed over a pure sine's
//! κ   = 3 R B/ℓ                  ⟨s'' s²⟩ = −(3/2) ω² A² B: nonzero only with both harmonics
//! ```
//! The second order is the sine's term with R_e for R. The third-order term comes from the fast
//! wobble ξ = (s/ℓ) sin u + (s s'' part) …: ⟨s'' ξ²⟩ and the wobble's own second-order part
//! both average ⟨s'' s²⟩, which vanishes for a pure sine. It acts like a push towards positive
//! φ at the tilted equilibria of a drive across gravity and, hanging, like a mount tilted by
//! κ/(2R) (`calib::plumb`). On the demo rod with a 60 mm rod (A = 12.7 mm, B = 0.67 mm) at
//! R = 1.75, θd = 90°, R_e is 1.12 % above R (0.44° of arccos(1/R)) and the push moves both
//! tilted equilibria by +0.30°: `tests/slider_crank_theory.rs` checks both against the full
//! equation.

use crate::math;

/// A crank of radius `amplitude` and a connecting rod `rod` (m) on a pendulum of equivalent
/// length `ell` (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliderCrank {
    pub amplitude: f64,
    pub rod: f64,
    pub ell: f64,
}

impl SliderCrank {
    /// R_e / R = 1 + (A/2b)².
    pub fn strength_gain(&self) -> f64 {
        let x = self.amplitude / (2.0 * self.rod);
        1.0 + x * x
    }

    /// κ / R = 3B/ℓ with B = A²/(4b).
    pub fn push_per_r(&self) -> f64 {
        3.0 * self.amplitude * self.amplitude / (4.0 * self.rod * self.ell)
    }
}

/// The slow torque over ω0² at φ (rad) for drive angle `theta_d` (rad) and first-harmonic
/// drive strength `r`: the averaged equation's right-hand side without damping.
pub fn slow_torque(phi: f64, theta_d: f64, r: f64, crank: Option<&SliderCrank>) -> f64 {
    let u = phi - theta_d;
    let (su, cu) = math::sin_cos(u);
    let (gain, kappa) = crank.map_or((1.0, 0.0), |c| (c.strength_gain(), r * c.push_per_r()));
    -math::sin(phi) - r * gain * su * cu - kappa * su * (cu * cu - 0.5 * su * su)
}

/// d(slow torque)/du at fixed φ, less the gravity term: the drive's part of the slope.
fn drive_slope(u: f64, r: f64, crank: Option<&SliderCrank>) -> f64 {
    let (su, cu) = math::sin_cos(u);
    let (gain, kappa) = crank.map_or((1.0, 0.0), |c| (c.strength_gain(), r * c.push_per_r()));
    // d/du [sin u cos²u − ½ sin³u] = cos³u − 2 sin²u cos u − (3/2) sin²u cos u
    let push = cu * cu * cu - 3.5 * su * su * cu;
    -r * gain * (cu * cu - su * su) - kappa * push
}

/// Newton's method for a root of `f` near `x0` given its derivative `df`: `None` if it does
/// not converge within 50 iterations or leaves `x0` by more than half a radian.
fn newton(x0: f64, f: impl Fn(f64) -> f64, df: impl Fn(f64) -> f64) -> Option<f64> {
    let mut x = x0;
    for _ in 0..50 {
        let step = f(x) / df(x);
        if !step.is_finite() {
            return None;
        }
        x -= step;
        if (x - x0).abs() > 0.5 {
            return None;
        }
        if step.abs() < 1e-14 {
            return Some(x);
        }
    }
    None
}

/// ωp²/ω0² at φ: minus the slope of the slow torque, positive where the rest is stable.
pub fn stiffness(phi: f64, theta_d: f64, r: f64, crank: Option<&SliderCrank>) -> f64 {
    math::cos(phi) - drive_slope(phi - theta_d, r, crank)
}

/// The equilibrium with the slider-crank's terms nearest `phi` (rad), the same equilibrium
/// without them (or any close guess).
pub fn equilibrium_near(
    phi: f64,
    theta_d: f64,
    r: f64,
    crank: Option<&SliderCrank>,
) -> Option<f64> {
    newton(
        phi,
        |x| slow_torque(x, theta_d, r, crank),
        |x| -stiffness(x, theta_d, r, crank),
    )
}

/// The drive angle nearest `theta_d` (rad) that holds the pendulum at rest at `phi` (rad):
/// the same balance solved for θd.
pub fn drive_angle_near(
    phi: f64,
    theta_d: f64,
    r: f64,
    crank: Option<&SliderCrank>,
) -> Option<f64> {
    newton(
        theta_d,
        |d| slow_torque(phi, d, r, crank),
        |d| -drive_slope(phi - d, r, crank),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pure_sine_has_the_closed_form() {
        // physics §3: θd = 90°, R > 1 → φ0 = ±arccos(1/R).
        for r in [1.2f64, 1.75, 3.0] {
            let g = (1.0 / r).acos();
            let got = equilibrium_near(g + 0.1, math::FRAC_PI_2, r, None).unwrap();
            assert!((got - g).abs() < 1e-12, "{r}: {got}");
        }
    }
}
