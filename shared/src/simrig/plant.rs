//! The rig's physics: the pendulum on a pivot moved by the crank's *actual* angle, and the DC
//! motor that turns the crank. State `[θ, θ', ψ, ψ']`.
//!
//! ```text
//! pivot along the drive line:  s(ψ) = A cos ψ + (A²/4b) cos 2ψ        (slider-crank, rod b; physics §5)
//!                              s'' = s_ψψ ψ'² + s_ψ ψ''
//!                              s_ψ = −A sin ψ − (A²/2b) sin 2ψ,  s_ψψ = −A cos ψ − (A²/b) cos 2ψ
//! pendulum (pivot frame):      θ'' = −ω0² sin θ + (s''/ℓ) sin(θ − θd) − c θ' − friction
//! motor (first-order speed lag behind the bridge duty u, its true gain, not the configured one):
//!                              ψ'' = (±K u − ψ')/τ,   I = (V u − kₑ ψ')/Rₐ
//! ```
//! With ψ = ωt and no connecting rod, s'' = −Aω² cos ωt and the pendulum equation is physics §3's
//! full equation exactly (tested). The pivot follows the motor, not the reference, so the phase
//! lock's errors reach the pendulum as they would on the bench.
//!
//! Coulomb friction (μ, rad/s²) acts on θ', the angular velocity relative to the carriage
//! (which translates and does not turn). It is a Karnopp model, so a fixed step never chatters:
//! above a small speed it is −μ sign θ'; below it the pendulum sticks while the other torques
//! stay within ±μ (its speed relaxed to zero over `STICK_RELAX`), and slips with −μ sign(torque)
//! once they do not.

use crate::integrate::System;
use crate::math;

/// Below this |θ'| (rad/s) the pendulum may stick.
const STICK_SPEED: f64 = 1e-3;
/// While stuck, θ' relaxes to zero with this time constant (s): stable for steps ≪ it.
const STICK_RELAX: f64 = 2e-3;

/// The crank motor's true behaviour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorModel {
    /// Steady crank speed at full duty (rad/s): the true gain K.
    pub omega_per_duty: f64,
    /// Speed-loop time constant τ (s).
    pub tau: f64,
    /// Supply voltage V, back-EMF constant kₑ (V s/rad), armature resistance Rₐ (Ω).
    pub volts: f64,
    pub ke: f64,
    pub ohms: f64,
    /// +1, or −1 when the motor leads are swapped (positive duty turns the crank backwards).
    pub direction: f64,
}

impl MotorModel {
    /// A brushed 12 V motor reaching 450 rad/s at full duty (10 % below the reference
    /// configuration's 500, the gain error a feed-forward meets on a real motor), τ = 60 ms.
    pub const DEFAULT: Self = Self {
        omega_per_duty: 450.0,
        tau: 0.06,
        volts: 12.0,
        ke: 12.0 / 500.0,
        ohms: 2.0,
        direction: 1.0,
    };

    /// Motor current (A) at duty `u` and crank speed `w`.
    pub fn current(&self, u: f64, w: f64) -> f64 {
        (self.volts * u - self.ke * self.direction * w) / self.ohms
    }
}

/// The pendulum and crank as one system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plant {
    /// ω0² = g/ℓ (1/s²) and ℓ (m): the true pendulum.
    pub omega0_sq: f64,
    pub ell: f64,
    /// The true crank radius A (m) and, for the slider-crank harmonic, A²/(4b) (m; 0 without).
    pub amplitude: f64,
    pub second: f64,
    /// Viscous damping c (1/s) and Coulomb friction μ (rad/s²).
    pub damping: f64,
    pub coulomb: f64,
    /// The true drive angle (rad), where the servo has the mount now.
    pub theta_d: f64,
    pub motor: MotorModel,
    /// H-bridge duty in [−1, 1]; 0 while the bridge sleeps.
    pub duty: f64,
    /// The crank is jammed (a stalled motor).
    pub jammed: bool,
}

impl Plant {
    /// Crank acceleration ψ'' at speed `w`.
    fn crank_accel(&self, w: f64) -> f64 {
        if self.jammed {
            return 0.0;
        }
        (self.motor.direction * self.motor.omega_per_duty * self.duty - w) / self.motor.tau
    }

    /// Pivot acceleration along the drive line at crank angle ψ, speed ψ', acceleration ψ''.
    fn pivot_accel(&self, psi: f64, w: f64, wdot: f64) -> f64 {
        let (s1, c1) = math::sin_cos(psi);
        let mut s_psi = -self.amplitude * s1;
        let mut s_psipsi = -self.amplitude * c1;
        if self.second != 0.0 {
            let (s2, c2) = (2.0 * s1 * c1, c1 * c1 - s1 * s1);
            s_psi -= 2.0 * self.second * s2;
            s_psipsi -= 4.0 * self.second * c2;
        }
        s_psipsi * w * w + s_psi * wdot
    }

    /// The friction term for angular velocity `v` when the other torques give `a` (rad/s²).
    fn friction(&self, v: f64, a: f64) -> f64 {
        if self.coulomb == 0.0 {
            return 0.0;
        }
        if v.abs() > STICK_SPEED {
            return -self.coulomb * v.signum();
        }
        if a.abs() <= self.coulomb {
            return -a - v / STICK_RELAX;
        }
        -self.coulomb * a.signum()
    }
}

impl System<4> for Plant {
    fn rhs(&self, _t: f64, y: &[f64; 4], dy: &mut [f64; 4]) {
        let wdot = self.crank_accel(y[3]);
        let s_dd = self.pivot_accel(y[2], y[3], wdot);
        let a = -self.omega0_sq * math::sin(y[0])
            + s_dd / self.ell * math::sin(y[0] - self.theta_d)
            - self.damping * y[1];
        dy[0] = y[1];
        dy[1] = a + self.friction(y[1], a);
        dy[2] = y[3];
        dy[3] = wdot;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plant() -> Plant {
        Plant {
            omega0_sq: 58.86,
            ell: 0.25 * 2.0 / 3.0,
            amplitude: 0.0127,
            second: 0.0,
            damping: 0.3,
            coulomb: 0.0,
            theta_d: 2.0,
            motor: MotorModel::DEFAULT,
            duty: 0.0,
            jammed: false,
        }
    }

    #[test]
    fn at_constant_crank_speed_it_is_the_full_equation() {
        // Also the closed-loop tests' plant (kapitza_test_support::closed_loop).
        // physics §3: θ'' = −ω0² sin θ − (Aω²/ℓ) sin(θ − θd) cos ωt − cθ' when ψ = ωt, ψ' = ω,
        // ψ'' = 0 (the motor at its steady speed: duty = ω/K). Closed form, to rounding.
        let mut p = plant();
        let w = 188.0;
        p.duty = w / p.motor.omega_per_duty;
        for &(t, th, v) in &[(0.0, 0.3, 1.0), (0.0123, -2.0, -4.0), (1.7, 3.1, 0.2)] {
            let y = [th, v, w * t, w];
            let mut dy = [0.0; 4];
            p.rhs(t, &y, &mut dy);
            let want = -p.omega0_sq * math::sin(th)
                - p.amplitude * w * w / p.ell * math::sin(th - p.theta_d) * math::cos(w * t)
                - p.damping * v;
            assert!(
                (dy[1] - want).abs() < 1e-9 * want.abs().max(1.0),
                "{} vs {want}",
                dy[1]
            );
            assert_eq!(dy[3], 0.0);
        }
    }

    #[test]
    fn slider_crank_adds_the_second_harmonic() {
        // s = A cos ψ + a2 cos 2ψ at constant ψ' = ω: s'' = −Aω² cos ψ − 4a2 ω² cos 2ψ.
        let mut p = plant();
        p.second = 0.0127 * 0.0127 / (4.0 * 0.05);
        let (w, psi) = (100.0, 0.7);
        let got = p.pivot_accel(psi, w, 0.0);
        let want =
            -p.amplitude * w * w * math::cos(psi) - 4.0 * p.second * w * w * math::cos(2.0 * psi);
        assert!((got - want).abs() < 1e-12 * want.abs());
    }

    #[test]
    fn friction_sticks_within_mu_and_slips_beyond() {
        let mut p = plant();
        p.coulomb = 1.5;
        // Sliding: opposes the motion with exactly μ.
        assert_eq!(p.friction(0.1, 0.0), -1.5);
        assert_eq!(p.friction(-0.1, 7.0), 1.5);
        // Stuck: cancels the other torques, so the net acceleration only relaxes θ'.
        assert_eq!(p.friction(0.0, 1.2) + 1.2, 0.0);
        // Breaks away: net |a| − μ in the direction of the torque.
        assert_eq!(p.friction(0.0, 2.0), -1.5);
    }
}
