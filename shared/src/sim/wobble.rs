//! The fast wobble the averaged model leaves out: how a full state (θ, θ') becomes the slow
//! state (φ, φ') the averaged equation starts from, and how the slow state is read back as the
//! full one.
//!
//! The slow state is not the full state. A run that starts the averaged model at φ = θ0,
//! φ' = θ0' starts it on the wrong slow orbit (by as much as the wobble's rate, a ω sin(φ − θd),
//! in φ'), and an end state reported as θ = φ misses the wobble itself, ≈ a |sin(φ − θd)|.
//!
//! # Derivation
//!
//! ```text
//! full:    θ'' = −ω0² sin θ + (s̈/ℓ) sin(θ − θd) − c θ'
//!          s/ℓ = w(ψ) = a1 cos ψ + a2 cos 2ψ,   s̈/ℓ = −ω² (a1 cos ψ + 4 a2 cos 2ψ),   ψ = ωt + ψ0
//! ```
//! (a1 = A/ℓ; a2 = A²/(4bℓ) with a slider-crank of rod length b, else 0; physics §3, §5.) Scales:
//! ε = ω0/ω is small and R = a1²ω²/(2ω0²) is of order one, so a1, a2 = O(ε), φ' = O(εω),
//! φ'' = O(ε²ω²), δ = c/ω = O(ε/Q). Write θ = φ + ξ with φ slow and ξ fast (zero mean over a
//! drive period), S = sin(φ − θd), C = cos(φ − θd), and collect the fast terms order by order
//! (Landau & Lifshitz, *Mechanics* §30, carried one order further):
//!
//! ```text
//! order ε:    ξ1'' = (s̈/ℓ) S                           ⇒ ξ1 = S w(ψ)
//! order ε²:   d²/dt² [S w] = S ẅ + 2 C φ' ẇ + O(ε³ω²):  the cross term 2 C φ' ẇ is fast and must
//!             be cancelled,  ξc'' = −2 C φ' ẇ            ⇒ ξc = −(2/ω) C φ' v(ψ)
//!             damping, −c ξ1' = −c S ẇ                    ⇒ ξd = −δ S v(ψ)
//!             sin(θ − θd) ≈ S + C ξ1 puts (s̈/ℓ) C ξ1 = −ω² S C (a1 cos ψ + 4a2 cos 2ψ) w(ψ)
//!             into the force; its mean is the averaged force −ω0² (R_eff/2) sin 2(φ − θd), its
//!             fast part −ω² S C [ (a1²/2) cos 2ψ + (5 a1 a2/2)(cos ψ + cos 3ψ) + 2 a2² cos 4ψ ]
//!                                                      ⇒ ξn = S C N(ψ)
//! v(ψ) = a1 sin ψ + (a2/2) sin 2ψ,    ẇ = −ω (a1 sin ψ + 2 a2 sin 2ψ)
//! N(ψ) = (a1²/8) cos 2ψ + (5 a1 a2/2)(cos ψ + cos 3ψ / 9) + (a2²/8) cos 4ψ
//! ```
//! (a term −ω² K cos nψ in ξ'' gives ξ = (K/n²) cos nψ.) Gravity acting on the wobble,
//! −ω0² cos φ ξ1, and the next terms of sin(θ − θd) are O(ε³) in the angle. So, to O(ε²) in θ and
//! O(ε²ω) in θ':
//!
//! ```text
//! θ  = φ + S w − (2/ω) C φ' v − δ S v + S C N
//! θ' = φ' + [C φ' w + S ẇ] + [−2 C φ' w] − c S w + S C Ṅ
//!    = φ' (1 − C w) + S ẇ − c S w + S C Ṅ,      Ṅ = −ω [ (a1²/4) sin 2ψ
//!                                                 + (5 a1 a2/2)(sin ψ + sin 3ψ/3) + (a2²/2) sin 4ψ ]
//! ```
//! The first bracket is ξ1', the second the leading part of ξc' (its other parts, −(2/ω) d(C φ')/dt
//! · v, are O(ε³ω)). That second bracket is why the slow rate's denominator has a minus: ξ1'
//! alone would give 1 + C w, but the second-order wobble ξc, whose derivative is as large as
//! ξ1's φ'-term, contributes −2 C w. With a1 only and ψ = ψ0 at the start the first-order
//! terms read
//!
//! ```text
//! φ0 = θ0 − a1 S0 cos ψ0,     φ0' = [θ0' + a1 ω S0 sin ψ0] / [1 − a1 C0 cos ψ0]
//! ```
//! and the next-order ones add −(2a1/ω) C0 φ0' sin ψ0 and (a1²/8) S0 C0 cos 2ψ0 to the angle
//! and −(a1²ω/4) S0 C0 sin 2ψ0 to the rate: at a start with θ0' ≠ 0 or ψ0 ≠ 0 they move the slow
//! orbit by O(a1² ω/ωp) in amplitude, which is of the order of a degree on the shipped tilted
//! scene. [`Wobble::full`] is the forward map; [`Wobble::slow`] inverts it by fixed-point
//! iteration (its Jacobian differs from the identity by O(ε)).

use crate::math;
use crate::model::DriveAngle;

/// The wobble of one drive: amplitudes, frequency, damping and drive angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wobble {
    /// a1 = A/ℓ.
    pub a1: f64,
    /// a2 = A²/(4bℓ) of a slider-crank, else 0.
    pub a2: f64,
    /// Drive frequency ω (rad/s).
    pub omega: f64,
    /// Viscous c (1/s).
    pub c: f64,
    /// θd.
    pub angle: DriveAngle,
}

/// Fixed-point iterations of [`Wobble::slow`] at most; each gains a factor O(a1) in accuracy.
const MAX_ITERATIONS: usize = 60;

impl Wobble {
    /// (sin, cos) of φ − θd.
    fn rel(&self, phi: f64) -> (f64, f64) {
        let (s, c) = math::sin_cos(phi);
        let (sd, cd) = (self.angle.sin(), self.angle.cos());
        (s * cd - c * sd, c * cd + s * sd)
    }

    /// The full state (θ, θ') of the slow state (φ, φ') at drive phase ψ.
    pub fn full(&self, (phi, phi_rate): (f64, f64), psi: f64) -> (f64, f64) {
        let (a1, a2, w) = (self.a1, self.a2, self.omega);
        let (s, c) = self.rel(phi);
        let (s1, c1) = math::sin_cos(psi);
        let (s2, c2) = math::sin_cos(2.0 * psi);
        let (s3, c3) = math::sin_cos(3.0 * psi);
        let (s4, c4) = math::sin_cos(4.0 * psi);
        let wob = a1 * c1 + a2 * c2;
        let wob_dot = -w * (a1 * s1 + 2.0 * a2 * s2);
        let v = a1 * s1 + 0.5 * a2 * s2;
        let n = a1 * a1 / 8.0 * c2 + 2.5 * a1 * a2 * (c1 + c3 / 9.0) + a2 * a2 / 8.0 * c4;
        let n_dot =
            -w * (a1 * a1 / 4.0 * s2 + 2.5 * a1 * a2 * (s1 + s3 / 3.0) + a2 * a2 / 2.0 * s4);
        let delta = self.c / w;
        let theta = phi + s * wob - 2.0 / w * c * phi_rate * v - delta * s * v + s * c * n;
        let rate = phi_rate * (1.0 - c * wob) + s * wob_dot - self.c * s * wob + s * c * n_dot;
        (theta, rate)
    }

    /// The slow state (φ, φ') whose full state at drive phase ψ is (θ, θ'): [`Wobble::full`]
    /// inverted by fixed-point iteration, each step corrected by the map's leading diagonal
    /// (∂θ/∂φ ≈ 1 + C w, ∂θ'/∂φ' ≈ 1 − C w).
    pub fn slow(&self, (theta, rate): (f64, f64), psi: f64) -> (f64, f64) {
        let (c1, c2) = (math::cos(psi), math::cos(2.0 * psi));
        let wob = self.a1 * c1 + self.a2 * c2;
        let (mut phi, mut phi_rate) = (theta, rate);
        for _ in 0..MAX_ITERATIONS {
            let (t, r) = self.full((phi, phi_rate), psi);
            let c = self.rel(phi).1;
            let d_phi = (theta - t) / (1.0 + c * wob);
            let d_rate = (rate - r) / (1.0 - c * wob);
            phi += d_phi;
            phi_rate += d_rate;
            if d_phi.abs() <= 1e-15 * (1.0 + phi.abs())
                && d_rate.abs() <= 1e-15 * (self.omega + phi_rate.abs())
            {
                break;
            }
        }
        (phi, phi_rate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{rk4_observe, Control, System};
    use crate::sim::eom::{AveragedEom, FullEom, NoExtra};
    use crate::sim::signal::{DriveSignal, Steady};

    /// The shipped tilted scene's drive (scenes/tilted-135.toml: rod L = 0.20 m so ℓ = 2L/3,
    /// A = 8.9 mm, ω = 330 rad/s, θd = 135°, g = 9.81), undamped: the bench's undamped scene.
    struct Tilted {
        a1: f64,
        omega: f64,
        omega0_sq: f64,
        r: f64,
        angle: DriveAngle,
    }

    /// The tilted example scene's drive and pendulum ([`crate::cases::TILTED_135`]).
    fn tilted() -> Tilted {
        let c = crate::cases::TILTED_135;
        let ell = 2.0 * c.rod_length / 3.0;
        let (a1, omega, g) = (c.amplitude / ell, c.omega, c.gravity);
        Tilted {
            a1,
            omega,
            omega0_sq: g / ell,
            r: a1 * a1 * omega * omega / (2.0 * g / ell),
            angle: DriveAngle::from_deg(c.drive_angle_deg).unwrap(),
        }
    }

    /// A steady sinusoidal drive that starts at phase ψ0: s̈/ℓ = −a1 ω² cos(ωt + ψ0).
    #[derive(Clone, Copy)]
    struct Phased {
        a1: f64,
        omega: f64,
        psi0: f64,
    }

    impl DriveSignal<f64> for Phased {
        fn accel(&self, t: f64) -> f64 {
            -self.a1 * self.omega * self.omega * libm::cos(self.omega * t + self.psi0)
        }
        fn strength(&self, _t: f64) -> f64 {
            1.0
        }
        fn constant_strength(&self) -> bool {
            true
        }
        fn strobe_time(&self, k: u64) -> f64 {
            k as f64 * math::TAU / self.omega
        }
        fn push(&self) -> f64 {
            0.0
        }
    }

    /// Period means of θ (trapezoid rule on RK4 at 256 steps per drive period) over `periods`
    /// drive periods from (θ0, θ0').
    fn period_means<S: System<2>>(sys: &S, y0: [f64; 2], omega: f64, periods: u64) -> Vec<f64> {
        const STEPS: u64 = 256;
        let h = math::TAU / omega / STEPS as f64;
        let (mut means, mut sum, mut i, mut prev) = (Vec::new(), 0.0, 0u64, y0[0]);
        rk4_observe(sys, 0.0, y0, h, STEPS * periods, |_, y| {
            sum += 0.5 * (prev + y[0]);
            prev = y[0];
            i += 1;
            if i % STEPS == 0 {
                means.push(sum / STEPS as f64);
                sum = 0.0;
            }
            Control::Continue
        });
        means
    }

    /// (centre, amplitude) of a sequence: mid-range and half the range, in degrees.
    fn centre_amplitude(xs: &[f64]) -> (f64, f64) {
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (math::to_deg(0.5 * (lo + hi)), math::to_deg(0.5 * (hi - lo)))
    }

    /// The full model's and the averaged model's (centre, amplitude) of the slow oscillation
    /// over the bench's 500 drive periods, the averaged one started from `start`.
    fn compare(
        theta0: f64,
        rate0: f64,
        psi0: f64,
        start: impl Fn(&Wobble) -> (f64, f64),
    ) -> ((f64, f64), (f64, f64)) {
        let s = tilted();
        let full = FullEom::<f64, _, _>::new(
            s.omega0_sq,
            s.angle,
            Phased {
                a1: s.a1,
                omega: s.omega,
                psi0,
            },
            NoExtra,
        );
        let averaged = AveragedEom::<f64, _, _>::new(
            s.omega0_sq,
            s.r,
            s.angle,
            Steady::<f64>::new(0.0, s.omega),
            NoExtra,
        );
        let w = Wobble {
            a1: s.a1,
            a2: 0.0,
            omega: s.omega,
            c: 0.0,
            angle: s.angle,
        };
        let (phi0, phi_rate0) = start(&w);
        let f = centre_amplitude(&period_means(&full, [theta0, rate0], s.omega, 500));
        let a = centre_amplitude(&period_means(&averaged, [phi0, phi_rate0], s.omega, 500));
        (f, a)
    }

    #[test]
    fn map_and_inverse_agree() {
        // slow(full(x)) = x: the fixed-point iteration converges to rounding (1e-12 allows
        // for θ' of order aω ≈ 22 rad/s), slider-crank and damping terms included.
        let s = tilted();
        let w = Wobble {
            a1: s.a1,
            a2: s.a1 * crate::cases::TILTED_135.amplitude / (4.0 * 0.05),
            omega: s.omega,
            c: 0.5,
            angle: s.angle,
        };
        for (phi, rate, psi) in [(1.7, 0.0, 0.0), (2.9, 4.0, 1.0), (-0.4, -7.0, 4.0)] {
            let back = w.slow(w.full((phi, rate), psi), psi);
            assert!((back.0 - phi).abs() < 1e-12, "{back:?}");
            assert!((back.1 - rate).abs() < 1e-12, "{back:?}");
        }
    }

    #[test]
    fn shifted_start_with_rate_gives_the_full_models_slow_oscillation() {
        // Released at 100° with θ0' = 3 rad/s at drive phase ψ0 = 1 rad, the pendulum swings
        // ±125.8° about 29.6° (the full model integrated here, RK4 at 256 steps per period, is
        // the reference). The averaged model started from the mapped slow state must reproduce
        // that to 0.1° in centre and amplitude, the target for the bench's undamped scene.
        // Measured: the second-order start is within 0.03° and 0.05°; the first-order terms
        // alone miss the amplitude by 0.6°, and starting at φ = θ0, φ' = θ0' lands on another
        // orbit altogether (±22.8° about 117.0°).
        let (theta0, rate0, psi0) = (math::to_rad(100.0), 3.0, 1.0);
        let (full, avg) = compare(theta0, rate0, psi0, |w| w.slow((theta0, rate0), psi0));
        assert!((full.0 - avg.0).abs() < 0.1, "centre {full:?} {avg:?}");
        assert!((full.1 - avg.1).abs() < 0.1, "amplitude {full:?} {avg:?}");
    }

    #[test]
    fn shipped_start_gives_the_full_models_slow_oscillation() {
        // The bench's undamped scene as shipped: 100° at rest, ψ0 = 0; the full model swings
        // ±15.94° about 118.08°. Measured: the mapped start is within 0.01° in both; starting at
        // φ = θ0, φ' = 0 gives ±17.81° about 117.85°, 1.9° too wide.
        let theta0 = math::to_rad(100.0);
        let (full, avg) = compare(theta0, 0.0, 0.0, |w| w.slow((theta0, 0.0), 0.0));
        assert!((full.0 - avg.0).abs() < 0.1, "centre {full:?} {avg:?}");
        assert!((full.1 - avg.1).abs() < 0.1, "amplitude {full:?} {avg:?}");
    }
}
