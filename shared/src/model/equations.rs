//! The full and the averaged equations of motion (SPEC §3), as [`System`]s with state (θ, θ').
//!
//! ```text
//! full:      θ'' = −ω0² sin θ − (A ω²/ℓ) sin(θ − θd) cos(ωt) − c θ'
//! averaged:  φ'' = −ω0² [sin φ + (R/2) sin 2(φ − θd)] − c φ'
//! energy of the averaged motion, per I ω0²:  E = φ'²/(2ω0²) + v(φ),
//!            v(φ) = −[cos φ + (R/4) cos 2(φ − θd)]
//! ```
//! The averaged equation is Kapitza's separation into slow and fast motion (Landau & Lifshitz,
//! *Mechanics*, §30), valid for ω ≫ ω0 and A ≪ ℓ.

use super::drive::{Drive, DriveAngle};
use super::equilibria::effective_potential;
use super::groups::Groups;
use crate::integrate::System;
use crate::math;

/// The full equation: the fast drive resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullModel {
    omega0_sq: f64,
    /// A ω²/ℓ: peak drive acceleration over ℓ.
    drive_acc: f64,
    omega: f64,
    angle: DriveAngle,
    c: f64,
}

impl FullModel {
    pub fn new(groups: &Groups, drive: &Drive) -> Self {
        Self {
            omega0_sq: groups.omega0 * groups.omega0,
            drive_acc: groups.m * drive.omega * drive.omega,
            omega: drive.omega,
            angle: drive.angle,
            c: groups.c,
        }
    }
}

impl System<2> for FullModel {
    fn rhs(&self, t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        let (s, c) = math::sin_cos(y[0]);
        // sin(θ − θd) from the exact pair kept by DriveAngle.
        let s_rel = s * self.angle.cos() - c * self.angle.sin();
        dy[0] = y[1];
        dy[1] = -self.omega0_sq * s
            - self.drive_acc * s_rel * math::cos(self.omega * t)
            - self.c * y[1];
    }
}

/// The averaged (slow) equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AveragedModel {
    omega0_sq: f64,
    r: f64,
    angle: DriveAngle,
    c: f64,
}

impl AveragedModel {
    pub fn new(omega0: f64, r: f64, angle: DriveAngle, c: f64) -> Self {
        Self {
            omega0_sq: omega0 * omega0,
            r,
            angle,
            c,
        }
    }

    /// E = φ'²/(2ω0²) + v(φ): conserved when c = 0.
    pub fn energy(&self, y: &[f64; 2]) -> f64 {
        0.5 * y[1] * y[1] / self.omega0_sq + effective_potential(self.r, self.angle, y[0])
    }
}

impl System<2> for AveragedModel {
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        let (s, c) = math::sin_cos(y[0]);
        // sin 2(φ − θd) = 2 sin(φ − θd) cos(φ − θd)
        let s_rel = s * self.angle.cos() - c * self.angle.sin();
        let c_rel = c * self.angle.cos() + s * self.angle.sin();
        dy[0] = y[1];
        dy[1] = -self.omega0_sq * (s + self.r * s_rel * c_rel) - self.c * y[1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{rk4_fixed, Stats};

    #[test]
    fn averaged_energy_conserved_undamped() {
        // With c = 0 the averaged motion conserves E (closed form); RK4 at 2000 steps per slow
        // period keeps the error near 1e-10 over a few periods.
        let m = AveragedModel::new(10.0, 3.0, DriveAngle::from_deg(135.0).unwrap(), 0.0);
        let y0 = [2.0, 0.0];
        let mut st = Stats::default();
        let y = rk4_fixed(&m, 0.0, y0, 3.0, 6000, &mut st);
        assert!((m.energy(&y) - m.energy(&y0)).abs() < 1e-9);
    }

    #[test]
    fn full_model_kapitza_inverted() {
        // Full equation, θd = 180°, R = 3 (averaging: inverted stable, ωp = ω0√2). Start 0.2 rad
        // off inverted with light damping: after many slow periods the period-mean angle is π.
        let ell = 0.2;
        let (g, a) = (9.81, 0.01);
        let omega = super::super::groups::omega_for_r(3.0, ell, g, a).unwrap();
        let groups = Groups::new(ell, g, a, omega, 1.0).unwrap();
        let drive = Drive::new(a, omega, DriveAngle::from_deg(180.0).unwrap()).unwrap();
        let m = FullModel::new(&groups, &drive);
        let period = math::TAU / omega;
        let mut st = Stats::default();
        let n_periods = 2000;
        let y = rk4_fixed(
            &m,
            0.0,
            [math::PI - 0.2, 0.0],
            period * n_periods as f64,
            100 * n_periods,
            &mut st,
        );
        // Fast wobble amplitude ≈ (A/ℓ)|sin(φ − θd)| ≈ 0 at φ = π; the slow deviation has decayed
        // by e^{−c t/2} = e^{−0.5·t} with t ≈ 2000 periods ≈ 15 s.
        assert!(math::wrap_pi(y[0] - math::PI).abs() < 1e-3, "θ = {}", y[0]);
    }
}
