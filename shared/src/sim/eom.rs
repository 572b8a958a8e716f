//! The equations of motion a scene runs, composed from exactly the effects it lists.
//!
//! ```text
//! full:        θ'' = −ω0² sin θ + (s̈/ℓ) sin(θ − θd)  [+ extras]
//! averaged:    φ'' = −ω0² [sin φ + (R_eff σ(t)/2) sin 2(φ − θd)]  [+ extras]
//! linearised:  θ'' = (−ω0² cos θ* + (s̈/ℓ) cos(θ* − θd)) (θ − θ*)  [+ extras],  θ* ∈ {0, π}
//! extras:      viscous −c θ';  Coulomb (while sliding) −μ sign θ'
//! ```
//! (ω0² uses g cos β under tilt; s̈/ℓ comes from the [`DriveSignal`]; σ(t) = (ω(t)/W)² follows a
//! ramp or motor lag; R_eff = R (1 + 4 (a2/a1)²) adds the slider-crank's second harmonic, whose
//! fast force averages separately from the first — Landau & Lifshitz, *Mechanics* §30, applied
//! to each harmonic.)
//!
//! Composition is by type: the drive signal `D` and the extra forces `X` are type parameters, so
//! a scene without damping runs [`NoExtra`], whose `apply` returns its input — no branch, no
//! multiply. Only the combinations that matter for speed are distinct types (steady or shaped
//! drive × none, viscous or sliding friction); everything rarer shares [`super::signal::Shaped`].

use super::signal::DriveSignal;
use super::slow_series::SlowSeries;
use crate::integrate::System;
use crate::model::DriveAngle;
use crate::Real;

/// Forces beyond gravity and the drive, applied to an acceleration.
pub trait Extra<R: Real>: Copy {
    fn apply(&self, acc: R, rate: R) -> R;
}

/// Nothing: the bare scene.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NoExtra;

impl<R: Real> Extra<R> for NoExtra {
    #[inline(always)]
    fn apply(&self, acc: R, _rate: R) -> R {
        acc
    }
}

/// Viscous damping c θ'.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viscous<R> {
    pub c: R,
}

impl<R: Real> Extra<R> for Viscous<R> {
    #[inline(always)]
    fn apply(&self, acc: R, rate: R) -> R {
        acc - self.c * rate
    }
}

/// Sliding Coulomb friction (with any viscous part): −c θ' − μ sign θ', the sign fixed for the
/// segment between two stops (see [`super::friction`]), so the right-hand side stays smooth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sliding<R> {
    pub c: R,
    /// −μ sign θ' for the current segment.
    pub friction: R,
}

impl<R: Real> Extra<R> for Sliding<R> {
    #[inline(always)]
    fn apply(&self, acc: R, rate: R) -> R {
        acc - self.c * rate + self.friction
    }
}

/// The full equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullEom<R, D, X> {
    pub omega0_sq: R,
    sin_d: R,
    cos_d: R,
    pub drive: D,
    pub extra: X,
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> FullEom<R, D, X> {
    pub fn new(omega0_sq: f64, angle: DriveAngle, drive: D, extra: X) -> Self {
        Self {
            omega0_sq: R::from_f64(omega0_sq),
            sin_d: R::from_f64(angle.sin()),
            cos_d: R::from_f64(angle.cos()),
            drive,
            extra,
        }
    }

    /// The same equation with other extra forces.
    pub fn with_extra<Y: Extra<R>>(&self, extra: Y) -> FullEom<R, D, Y> {
        FullEom {
            omega0_sq: self.omega0_sq,
            sin_d: self.sin_d,
            cos_d: self.cos_d,
            drive: self.drive,
            extra,
        }
    }

    /// Gravity and drive only: the acceleration the pendulum would have at rest relative to the
    /// carriage (what static friction must hold).
    #[inline(always)]
    pub fn conservative(&self, t: f64, theta: R) -> R {
        self.conservative_with(self.drive.accel(t), theta)
    }

    /// [`FullEom::conservative`] with the drive's s̈/ℓ given (from a table, say).
    #[inline(always)]
    pub fn conservative_with(&self, accel: R, theta: R) -> R {
        let (s, c) = theta.sin_cos();
        self.conservative_sc(accel, s, c)
    }

    /// The same with (sin θ, cos θ) given.
    #[inline(always)]
    pub fn conservative_sc(&self, accel: R, s: R, c: R) -> R {
        let s_rel = s * self.cos_d - c * self.sin_d;
        -self.omega0_sq * s + accel * s_rel
    }
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> System<2, R> for FullEom<R, D, X> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[R; 2], dy: &mut [R; 2]) {
        dy[0] = y[1];
        dy[1] = self.extra.apply(self.conservative(t, y[0]), y[1]);
    }
}

/// The averaged (slow) equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AveragedEom<R, D, X> {
    omega0_sq: R,
    /// ω0² R_eff / 2.
    half_r: R,
    sin_d: R,
    cos_d: R,
    drive: D,
    extra: X,
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> AveragedEom<R, D, X> {
    pub fn new(omega0_sq: f64, r_eff: f64, angle: DriveAngle, drive: D, extra: X) -> Self {
        Self {
            omega0_sq: R::from_f64(omega0_sq),
            half_r: R::from_f64(0.5 * r_eff * omega0_sq),
            sin_d: R::from_f64(angle.sin()),
            cos_d: R::from_f64(angle.cos()),
            drive,
            extra,
        }
    }
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> AveragedEom<R, D, X> {
    pub fn drive(&self) -> &D {
        &self.drive
    }

    /// The force about φ0 (given sin φ0, cos φ0) as a power series, for a step over which the
    /// drive's strength stays at its value at t.
    #[inline(always)]
    pub(super) fn series(&self, t: f64, s: R, c: R) -> SlowSeries<R> {
        let s_rel = s * self.cos_d - c * self.sin_d;
        let c_rel = c * self.cos_d + s * self.sin_d;
        let sigma = self.drive.strength(t);
        let series = SlowSeries::about(self.omega0_sq, self.half_r * sigma, (s, c), (s_rel, c_rel));
        let push = self.drive.push();
        if push == R::ZERO {
            series
        } else {
            series.with_push(push * sigma, (s_rel, c_rel))
        }
    }

    /// Gravity and the averaged drive force at t, given (sin φ, cos φ).
    #[inline(always)]
    pub fn conservative_sc(&self, t: f64, s: R, c: R) -> R {
        let s_rel = s * self.cos_d - c * self.sin_d;
        let c_rel = c * self.cos_d + s * self.sin_d;
        let two = R::ONE + R::ONE;
        let sigma = self.drive.strength(t);
        // sin 2(φ − θd) = 2 sin(φ − θd) cos(φ − θd)
        let g = -self.omega0_sq * s - self.half_r * sigma * two * s_rel * c_rel;
        let push = self.drive.push();
        if push == R::ZERO {
            return g;
        }
        // The slider-crank's push K (sin u − 3 sin 3u) = −8K sin u (cos²u − ½ sin²u),
        // u = φ − θd (physics §5.1).
        let (s2, c2) = (s_rel * s_rel, c_rel * c_rel);
        g - R::from_f64(8.0) * push * sigma * s_rel * (c2 - s2 / two)
    }
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> System<2, R> for AveragedEom<R, D, X> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[R; 2], dy: &mut [R; 2]) {
        let (s, c) = y[0].sin_cos();
        dy[0] = y[1];
        dy[1] = self.extra.apply(self.conservative_sc(t, s, c), y[1]);
    }
}

/// The equation linearised about an exact fixed point θ* of the full equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearisedEom<R, D, X> {
    /// θ* (rad): 0 or π.
    pub centre: R,
    /// ω0² cos θ*.
    gravity: R,
    /// cos(θ* − θd): ±1.
    coupling: R,
    drive: D,
    extra: X,
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> LinearisedEom<R, D, X> {
    /// `centre_is_inverted`: θ* = π, else 0; `drive_is_up`: θd = π, else 0.
    pub fn new(
        omega0_sq: f64,
        centre_is_inverted: bool,
        drive_is_up: bool,
        drive: D,
        extra: X,
    ) -> Self {
        let sign = |b: bool| if b { -1.0 } else { 1.0 };
        Self {
            centre: R::from_f64(if centre_is_inverted {
                crate::math::PI
            } else {
                0.0
            }),
            gravity: R::from_f64(omega0_sq * sign(centre_is_inverted)),
            coupling: R::from_f64(sign(centre_is_inverted != drive_is_up)),
            drive,
            extra,
        }
    }
}

impl<R: Real, D: DriveSignal<R>, X: Extra<R>> System<2, R> for LinearisedEom<R, D, X> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[R; 2], dy: &mut [R; 2]) {
        let x = y[0] - self.centre;
        dy[0] = y[1];
        dy[1] = self.extra.apply(
            (self.drive.accel(t) * self.coupling - self.gravity) * x,
            y[1],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::signal::Steady;
    use super::*;

    #[test]
    fn full_matches_the_closed_form() {
        // physics §3 written out: θ'' = −(g/ℓ) sin θ − (Aω²/ℓ) sin(θ − θd) cos ωt − c θ'.
        let (ell, g, a, w, c) = (0.2, 9.81, 0.01, 300.0, 0.7);
        let deg = 135.0;
        let angle = DriveAngle::from_deg(deg).unwrap();
        let eom = FullEom::<f64, _, _>::new(g / ell, angle, Steady::new(a / ell, w), Viscous { c });
        for (t, th, v) in [(0.0, 0.3, 1.0), (0.0123, 2.9, -4.0), (7.7, -1.2, 0.5)] {
            let td: f64 = deg.to_radians();
            let want =
                -(g / ell) * th.sin() - a * w * w / ell * (th - td).sin() * (w * t).cos() - c * v;
            let mut d = [0.0; 2];
            eom.rhs(t, &[th, v], &mut d);
            assert!(
                (d[1] - want).abs() < 1e-9 * want.abs().max(1.0),
                "{} vs {want}",
                d[1]
            );
            assert_eq!(d[0], v);
        }
    }

    #[test]
    fn averaged_energy_is_conserved_undamped() {
        // Without damping the averaged motion conserves E = φ'²/(2ω0²) + v(φ) (closed form);
        // RK4 at 2000 steps per time unit keeps its drift near 1e-10 over 3 s.
        use crate::integrate::{rk4_fixed, Stats};
        use crate::model::equilibria::averaged_energy;
        let (w0, r) = (10.0, 3.0);
        let angle = DriveAngle::from_deg(135.0).unwrap();
        let eom = AveragedEom::<f64, _, _>::new(w0 * w0, r, angle, Steady::new(0.0, 1.0), NoExtra);
        let y0 = [2.0, 0.0];
        let y = rk4_fixed(&eom, 0.0, y0, 3.0, 6000, &mut Stats::default());
        let e = |y: [f64; 2]| averaged_energy(r, angle, w0, y[0], y[1]);
        assert!((e(y) - e(y0)).abs() < 1e-9);
    }

    #[test]
    fn linearised_is_the_tangent_of_full() {
        // About θ* = π with θd = 180°: d(full)/dθ at θ* equals the linear coefficient.
        let (w0sq, a, w) = (50.0, 0.05, 200.0);
        let up = DriveAngle::from_deg(180.0).unwrap();
        let full = FullEom::<f64, _, _>::new(w0sq, up, Steady::new(a, w), NoExtra);
        let lin = LinearisedEom::<f64, _, _>::new(w0sq, true, true, Steady::new(a, w), NoExtra);
        let t = 0.01;
        let h = 1e-6;
        let (mut p, mut m, mut l) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        full.rhs(t, &[crate::math::PI + h, 0.0], &mut p);
        full.rhs(t, &[crate::math::PI - h, 0.0], &mut m);
        lin.rhs(t, &[crate::math::PI + 1.0, 0.0], &mut l);
        let slope = (p[1] - m[1]) / (2.0 * h);
        assert!(
            (slope - l[1]).abs() < 1e-5 * slope.abs().max(1.0),
            "{slope} vs {}",
            l[1]
        );
    }
}
