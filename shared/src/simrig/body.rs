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
    use crate::integrate::{rk4_step, Stats};
    use crate::model::{equilibria, DriveAngle};
    use crate::simrig::plant::{MotorModel, Plant};

    /// Where a slewed rod went.
    struct Slewed {
        /// The largest |θ − θd| seen (degrees).
        max_from_blade_deg: f64,
        /// Steps with a contact.
        contacts: u32,
        /// The mean of θ over the last 20 drive periods, and its range over them (degrees).
        rest_deg: f64,
        swing_deg: f64,
    }

    /// The demo rod (L = 0.25 m, A = 12.7 mm, Q = 10) standing inverted at θd = 180° on a crank
    /// turning steadily at R = 1.75; after 2 s the mount slews to θd = 0 at the servo's
    /// 300°/s, and the run goes on for `secs`. RK4 at h = 0.1 ms (the simulated rig's step).
    fn slew_inverted(body: Option<Body>, secs: f64) -> Slewed {
        let ell = 0.25 * 2.0 / 3.0;
        let (g, a, r) = (9.81, 0.0127, 1.75);
        let w = math::sqrt(2.0 * g * ell * r) / a; // R = A²ω²/(2gℓ), physics §3
        let motor = MotorModel::DEFAULT;
        let mut p = Plant {
            omega0_sq: g / ell,
            ell,
            amplitude: a,
            second: 0.0,
            damping: math::sqrt(g / ell) / 10.0,
            coulomb: 0.0,
            theta_d: math::PI,
            motor,
            duty: w / motor.omega_per_duty,
            jammed: false,
        };
        let h = 1e-4;
        let n = libm::round(secs / h) as usize;
        let period = libm::round(math::TAU / w / h) as usize;
        let (rate, mut stats) = (math::to_rad(300.0), Stats::default());
        let mut y = [math::PI, 0.0, 0.0, w];
        let mut out = Slewed {
            max_from_blade_deg: 0.0,
            contacts: 0,
            rest_deg: 0.0,
            swing_deg: 0.0,
        };
        let mut tail = std::vec::Vec::new();
        for k in 0..n {
            let t = k as f64 * h;
            let before = p.theta_d;
            if t >= 2.0 {
                p.theta_d = (p.theta_d - rate * h).max(0.0);
            }
            y = rk4_step(&p, t, &y, h, &mut stats);
            if let Some(b) = &body {
                out.contacts += u32::from(b.contact(&mut y, p.theta_d, (p.theta_d - before) / h));
            }
            out.max_from_blade_deg = out
                .max_from_blade_deg
                .max(math::to_deg(from_blade(y[0], p.theta_d)));
            if k + 20 * period >= n {
                tail.push(math::to_deg(math::wrap_pi(y[0])));
            }
        }
        let (lo, hi) = tail
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        out.rest_deg = tail.iter().sum::<f64>() / tail.len() as f64;
        out.swing_deg = hi - lo;
        out
    }

    #[test]
    fn a_rod_slewed_past_the_body_is_pushed_and_rests_within_reach() {
        let run = slew_inverted(Some(Body::DEFAULT), 30.0);
        std::println!(
            "with the body: max |θ − θd| = {:.3}°, {} contact steps, rests at {:.3}° (range {:.3}°)",
            run.max_from_blade_deg,
            run.contacts,
            run.rest_deg,
            run.swing_deg
        );
        // Pushed: the face at θd + 90° met the rod as θd fell below 90°.
        assert!(run.contacts > 0);
        // Never past the body (the contact's projection is exact; rounding of wrap_pi).
        assert!(run.max_from_blade_deg <= 90.0 + 1e-9);
        // At rest at the model's reachable equilibrium: at θd = 0 the stable equilibria are
        // φ0 = 0 and, for R > 1, φ0 = 180° (physics §3), and only φ0 = 0 is within 90°.
        let eq = equilibria(1.75, DriveAngle::from_deg(0.0).unwrap()).unwrap();
        let nearest = eq
            .stable()
            .min_by(|a, b| {
                let da = math::wrap_pi(a.angle - math::to_rad(run.rest_deg)).abs();
                let db = math::wrap_pi(b.angle - math::to_rad(run.rest_deg)).abs();
                da.total_cmp(&db)
            })
            .unwrap();
        assert!(nearest.within_90_of_drive);
        // Tolerance 0.5°: θ = 0 is an exact fixed point of the full equation at θd = 0, so what
        // is left is the decaying slow swing after 28 s at Q = 10 (e^(−c·t/2) < 1e-3 of ~90°)
        // and the period mean's sampling.
        assert!(
            (run.rest_deg - math::to_deg(nearest.angle)).abs() < 0.5,
            "{}",
            run.rest_deg
        );
        assert!(run.swing_deg < 10.0, "still moving: {}", run.swing_deg);
    }

    #[test]
    fn without_the_body_the_rod_stays_where_the_apparatus_cannot_hold_it() {
        // The same slew on a rig without a body: the inverted rod, stable at θd = 0 too for
        // R > 1 (physics §3), ends 180° from the blade.
        let run = slew_inverted(None, 30.0);
        std::println!(
            "without: max |θ − θd| = {:.3}°, rests at {:.3}° (range {:.3}°)",
            run.max_from_blade_deg,
            run.rest_deg,
            run.swing_deg
        );
        assert!(run.max_from_blade_deg > 90.0);
    }

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
