//! The actuator's body: on the lecture apparatus it sits on one side of the pivot, so the rod
//! cannot pass more than 90° from the direction θd the blade points (physics §3,
//! "reachability"). It moves with the mount, so a slewing θd pushes the rod along.
//!
//! ```text
//! d = wrap(θ − θd) ∈ (−π, π]         the rod against the blade
//! |d| ≤ π/2                           free: the plant's equation alone
//! |d| > π/2                           contact: θ ← θd ± π/2 (the face it crossed, sign d),
//!                                     and if the rod moves into the face (v = θ' − θd', d·v > 0)
//!                                     v ← −e·v    (Newton's restitution, e ∈ [0, 1])
//! ```
//! Applied after each step of the plant, as an impact: the contact is instantaneous, loses the
//! fraction 1 − e² of the rod's kinetic energy relative to the body, and a rod pressed against
//! a face (by gravity, or by the face slewing into it) stays on it, moving with the mount.

use crate::math;

/// The body's contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Coefficient of restitution e ∈ [0, 1]: the rod's speed relative to the body after an
    /// impact, as a fraction of the speed before (0: it stops dead; 1: no loss).
    pub restitution: f64,
}

impl Body {
    /// A rod striking a plastic or aluminium housing bounces back with about a third of its speed.
    pub const DEFAULT: Self = Self { restitution: 0.3 };

    /// Keeps the rod `y = [θ, θ', …]` within 90° of the blade at drive angle `theta_d` (rad)
    /// moving at `theta_d_rate` (rad/s). Returns whether the rod touched the body.
    pub fn contact(&self, y: &mut [f64; 4], theta_d: f64, theta_d_rate: f64) -> bool {
        let d = math::wrap_pi(y[0] - theta_d);
        if d.abs() <= math::FRAC_PI_2 {
            return false;
        }
        let side = if d > 0.0 { 1.0 } else { -1.0 };
        y[0] = theta_d + side * math::FRAC_PI_2;
        let v = y[1] - theta_d_rate;
        if side * v > 0.0 {
            y[1] = theta_d_rate - self.restitution * v;
        }
        true
    }
}

/// The rod's angle from the blade, |wrap(θ − θd)| (rad): at most π/2 with the body.
pub fn from_blade(theta: f64, theta_d: f64) -> f64 {
    math::wrap_pi(theta - theta_d).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_free_rod_is_left_alone() {
        let b = Body::DEFAULT;
        let mut y = [math::to_rad(60.0), 3.0, 1.0, 2.0];
        let before = y;
        assert!(!b.contact(&mut y, math::to_rad(-20.0), 0.5));
        assert_eq!(y, before);
    }

    #[test]
    fn an_impact_keeps_the_fraction_e_of_the_speed() {
        // Newton's law of restitution against a still face: v' = −e·v exactly.
        let b = Body { restitution: 0.3 };
        let mut y = [math::to_rad(91.0), 2.0, 0.0, 0.0];
        assert!(b.contact(&mut y, 0.0, 0.0));
        assert_eq!(y[0], math::FRAC_PI_2);
        assert!((y[1] + 0.6).abs() < 1e-15);
        // The other face, the rod moving into it (negative).
        let mut y = [math::to_rad(-92.0), -1.0, 0.0, 0.0];
        b.contact(&mut y, 0.0, 0.0);
        assert_eq!(y[0], -math::FRAC_PI_2);
        assert!((y[1] - 0.3).abs() < 1e-15);
    }

    #[test]
    fn a_slewing_face_carries_the_rod() {
        // The face at θd + 90° moves at −2 rad/s into a rod at rest: relative speed 2 into the
        // face, so after the impact the rod moves at θd' − e·(0 − θd') = −2·(1 + e).
        let b = Body { restitution: 0.5 };
        let theta_d = math::to_rad(80.0);
        let mut y = [math::to_rad(171.0), 0.0, 0.0, 0.0];
        assert!(b.contact(&mut y, theta_d, -2.0));
        assert!((y[0] - (theta_d + math::FRAC_PI_2)).abs() < 1e-15);
        assert!((y[1] + 3.0).abs() < 1e-12, "{}", y[1]);
        // Already moving away from the face faster than it: placed on it, speed kept.
        let mut y = [math::to_rad(171.0), -5.0, 0.0, 0.0];
        b.contact(&mut y, theta_d, -2.0);
        assert_eq!(y[1], -5.0);
    }

    #[test]
    fn across_the_wrap_the_nearer_face_holds_it() {
        // θd = 170°, rod at −95° (= 265°): 95° past the blade on the positive side.
        let b = Body::DEFAULT;
        let theta_d = math::to_rad(170.0);
        let mut y = [math::to_rad(-95.0), 0.0, 0.0, 0.0];
        assert!(b.contact(&mut y, theta_d, 0.0));
        assert!((from_blade(y[0], theta_d) - math::FRAC_PI_2).abs() < 1e-12);
        assert!((math::wrap_pi(y[0]) - math::to_rad(-100.0)).abs() < 1e-12);
    }
}
