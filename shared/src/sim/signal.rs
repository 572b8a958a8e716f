//! The drive signal: the pivot's acceleration along the drive line, and the drive phase.
//!
//! ```text
//! pivot displacement along u = (sin θd, −cos θd):  s(t) = a1 cos ϕ + a2 cos 2ϕ
//!   a1 = A,  a2 = A²/(4b) with a slider-crank of rod length b (else 0)      (physics §5)
//! phase ϕ(t) = ∫ω dt, so   s̈ = −a1 (ω² cos ϕ + ω̇ sin ϕ) − a2 (4ω² cos 2ϕ + 2ω̇ sin 2ϕ)
//! ```
//! A steady sinusoid ([`Steady`]) is the common case and has its own type, so that a scene
//! without ramp, actuator or slider-crank evaluates exactly `−A ω² cos ωt` and nothing else.
//! Everything else goes through [`Shaped`], whose schedule gives ω(t) and ϕ(t) in closed form:
//!
//! ```text
//! ramp (duration T), commanded ω_c = W·min(t/T, 1); actuator lag τ: ω' = (ω_c − ω)/τ, ω(0) = 0
//! ramp only, t < T:   ω = W t/T,                         ϕ = W t²/(2T)
//! lag only:           ω = W (1 − e^{−t/τ}),               ϕ = W (t − τ(1 − e^{−t/τ}))
//! ramp + lag, t < T:  ω = (W/T)(t − τ(1 − e^{−t/τ})),      ϕ = (W/T)(t²/2 − τt + τ²(1 − e^{−t/τ}))
//! after the ramp:     ω = W + (ω_T − W) e^{−(t−T)/τ},     ϕ = ϕ_T + W(t−T) + (ω_T − W) τ (1 − e^{−(t−T)/τ})
//! ```

use crate::math;
use crate::Real;

/// What the equations of motion need from the drive.
pub trait DriveSignal<R: Real>: Copy {
    /// Pivot acceleration along the drive line over ℓ, s̈(t)/ℓ (1/s²).
    fn accel(&self, t: f64) -> R;
    /// (ω(t)/W)²: the drive strength relative to its set point, for the averaged model.
    fn strength(&self, t: f64) -> R;
    /// The time at which the drive phase reaches 2πk: the k-th stroboscopic instant.
    fn strobe_time(&self, k: u64) -> f64;
    /// Whether [`DriveSignal::strength`] is the same at every t (no ramp, no lag).
    fn constant_strength(&self) -> bool;
    /// The averaged model's third-order push of the two harmonics at the set point, ω0²κ/8 =
    /// (3/16) (a1/ℓ)² (a2/ℓ) W² (physics §5.1; it scales with the strength as R does); zero
    /// for a single harmonic, and a constant the compiler sees for [`Steady`].
    fn push(&self) -> R;
}

/// A steady sinusoid A cos(Wt): no ramp, no lag, no second harmonic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steady<R> {
    /// A W²/ℓ.
    peak: R,
    omega: f64,
}

impl<R: Real> Steady<R> {
    pub fn new(amplitude_over_ell: f64, omega: f64) -> Self {
        Self {
            peak: R::from_f64(amplitude_over_ell * omega * omega),
            omega,
        }
    }
}

impl<R: Real> DriveSignal<R> for Steady<R> {
    #[inline]
    fn accel(&self, t: f64) -> R {
        -self.peak * R::cos_phase(self.omega * t)
    }
    #[inline]
    fn strength(&self, _t: f64) -> R {
        R::ONE
    }
    #[inline(always)]
    fn push(&self) -> R {
        R::ZERO
    }
    fn constant_strength(&self) -> bool {
        true
    }
    fn strobe_time(&self, k: u64) -> f64 {
        k as f64 * math::TAU / self.omega
    }
}

/// How the delivered frequency evolves: ramp and/or first-order motor lag, in closed form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// Set point W (rad/s).
    pub omega: f64,
    /// Ramp duration T (s), if any.
    pub ramp: Option<f64>,
    /// Actuator time constant τ (s), if any.
    pub lag: Option<f64>,
}

/// (ϕ, ω, ω̇) at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveState {
    pub phase: f64,
    pub omega: f64,
    pub omega_dot: f64,
}

impl Schedule {
    pub fn state(&self, t: f64) -> DriveState {
        let w = self.omega;
        if t < 0.0 && (self.ramp.is_some() || self.lag.is_some()) {
            // Before t = 0 a ramped or lagging drive is at rest. Only the backward sub-steps of a
            // Yoshida composition ask for it; the formulas below, continued to t < 0, give a
            // phase of W t²/(2T) and an e^{−t/τ} that overflow for a short ramp or lag.
            return DriveState {
                phase: 0.0,
                omega: 0.0,
                omega_dot: 0.0,
            };
        }
        match (self.ramp, self.lag) {
            (None, None) => DriveState {
                phase: w * t,
                omega: w,
                omega_dot: 0.0,
            },
            (Some(ramp), None) if t < ramp => DriveState {
                phase: 0.5 * w * t * t / ramp,
                omega: w * t / ramp,
                omega_dot: w / ramp,
            },
            (Some(ramp), None) => DriveState {
                phase: w * (t - 0.5 * ramp),
                omega: w,
                omega_dot: 0.0,
            },
            (None, Some(tau)) => {
                let e = math::exp(-t / tau);
                DriveState {
                    phase: w * (t - tau * (1.0 - e)),
                    omega: w * (1.0 - e),
                    omega_dot: w / tau * e,
                }
            }
            (Some(ramp), Some(tau)) => {
                let slope = w / ramp;
                let within = |t: f64| {
                    let e = math::exp(-t / tau);
                    DriveState {
                        phase: slope * (0.5 * t * t - tau * t + tau * tau * (1.0 - e)),
                        omega: slope * (t - tau * (1.0 - e)),
                        omega_dot: slope * (1.0 - e),
                    }
                };
                if t < ramp {
                    return within(t);
                }
                let end = within(ramp);
                let e = math::exp(-(t - ramp) / tau);
                let gap = end.omega - w;
                DriveState {
                    phase: end.phase + w * (t - ramp) + gap * tau * (1.0 - e),
                    omega: w + gap * e,
                    omega_dot: -gap / tau * e,
                }
            }
        }
    }

    /// The time at which ϕ(t) = target (ϕ is increasing for t > 0): Newton from the steady-state
    /// guess, safeguarded by bisection on a bracket.
    pub fn time_of_phase(&self, target: f64) -> f64 {
        if target <= 0.0 {
            return 0.0;
        }
        let w = self.omega;
        let delay = self.ramp.map_or(0.0, |t| 0.5 * t) + self.lag.unwrap_or(0.0);
        // ϕ(t) ≥ W(t − delay) and ϕ(t) ≤ W t, so the root lies in [target/W, target/W + delay].
        let (mut lo, mut hi) = (target / w, target / w + delay);
        let mut t = hi;
        for _ in 0..200 {
            let s = self.state(t);
            let f = s.phase - target;
            if f > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            if hi - lo <= 4.0 * f64::EPSILON * hi {
                break;
            }
            let newton = t - f / s.omega;
            t = if s.omega > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        t
    }
}

/// Any drive: two harmonics and a schedule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaped<R> {
    /// a1/ℓ and a2/ℓ.
    a1: R,
    a2: R,
    pub schedule: Schedule,
}

impl<R: Real> Shaped<R> {
    pub fn new(amplitude_over_ell: f64, second_over_ell: f64, schedule: Schedule) -> Self {
        Self {
            a1: R::from_f64(amplitude_over_ell),
            a2: R::from_f64(second_over_ell),
            schedule,
        }
    }
}

impl<R: Real> DriveSignal<R> for Shaped<R> {
    fn accel(&self, t: f64) -> R {
        let d = self.schedule.state(t);
        let (s1, c1) = R::sin_cos_phase(d.phase);
        let (s2, c2) = (R::from_f64(2.0) * s1 * c1, c1 * c1 - s1 * s1);
        let w2 = R::from_f64(d.omega * d.omega);
        let wd = R::from_f64(d.omega_dot);
        let four = R::from_f64(4.0);
        let two = R::from_f64(2.0);
        -self.a1 * (w2 * c1 + wd * s1) - self.a2 * (four * w2 * c2 + two * wd * s2)
    }
    fn strength(&self, t: f64) -> R {
        let r = self.schedule.state(t).omega / self.schedule.omega;
        R::from_f64(r * r)
    }
    fn constant_strength(&self) -> bool {
        self.schedule.ramp.is_none() && self.schedule.lag.is_none()
    }
    fn strobe_time(&self, k: u64) -> f64 {
        self.schedule.time_of_phase(k as f64 * math::TAU)
    }
    fn push(&self) -> R {
        let w = self.schedule.omega;
        R::from_f64(3.0 / 16.0 * w * w) * self.a1 * self.a1 * self.a2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schedules() -> [Schedule; 4] {
        let w = 200.0;
        [
            Schedule {
                omega: w,
                ramp: None,
                lag: None,
            },
            Schedule {
                omega: w,
                ramp: Some(1.5),
                lag: None,
            },
            Schedule {
                omega: w,
                ramp: None,
                lag: Some(0.3),
            },
            Schedule {
                omega: w,
                ramp: Some(1.5),
                lag: Some(0.3),
            },
        ]
    }

    #[test]
    fn phase_is_the_integral_of_omega() {
        // ϕ(t) − ϕ(t0) = ∫ω: check by Simpson on a fine grid (error < 1e-9 rad here), and ω̇
        // against a central difference of ω; continuity across the end of the ramp.
        for s in schedules() {
            for &(a, b) in &[(0.0, 0.7), (0.7, 1.5), (1.4, 1.7), (1.5, 4.0)] {
                let n = 2000;
                let h = (b - a) / n as f64;
                let mut sum = s.state(a).omega + s.state(b).omega;
                for i in 1..n {
                    let w = if i % 2 == 1 { 4.0 } else { 2.0 };
                    sum += w * s.state(a + i as f64 * h).omega;
                }
                let integral = sum * h / 3.0;
                let dphi = s.state(b).phase - s.state(a).phase;
                assert!(
                    (integral - dphi).abs() < 1e-9,
                    "{s:?} [{a},{b}]: {integral} vs {dphi}"
                );
                let t = 0.5 * (a + b);
                let d = 1e-6;
                let fd = (s.state(t + d).omega - s.state(t - d).omega) / (2.0 * d);
                assert!(
                    (fd - s.state(t).omega_dot).abs() < 1e-4 * (1.0 + fd.abs()),
                    "{s:?} t {t}"
                );
            }
        }
    }

    #[test]
    fn strobe_times_hit_whole_turns() {
        for s in schedules() {
            let sig = Shaped::<f64>::new(0.05, 0.0, s);
            for k in [0u64, 1, 7, 100, 1000, 123_456] {
                let t = sig.strobe_time(k);
                let ph = s.state(t).phase;
                assert!(
                    (ph - k as f64 * math::TAU).abs() < 1e-9 * (1.0 + ph),
                    "{s:?} k {k}"
                );
            }
        }
    }

    #[test]
    fn steady_matches_shaped_without_effects() {
        // The two paths compute the same s̈/ℓ = −(A/ℓ) W² cos Wt when nothing shapes the drive.
        let (a, w) = (0.05, 200.0);
        let st = Steady::<f64>::new(a, w);
        let sh = Shaped::<f64>::new(
            a,
            0.0,
            Schedule {
                omega: w,
                ramp: None,
                lag: None,
            },
        );
        for t in [0.0, 0.001, 0.37, 12.5] {
            assert!((st.accel(t) - sh.accel(t)).abs() < 1e-9 * a * w * w);
            assert!((st.strobe_time(9) - sh.strobe_time(9)).abs() < 1e-12);
        }
        // t = 0 is drive phase zero: the pivot at +A, accelerating towards −A.
        assert!((st.accel(0.0) + a * w * w).abs() < 1e-9);
    }

    #[test]
    fn slider_crank_second_harmonic() {
        // s = a1 cos ϕ + a2 cos 2ϕ at constant ω: s̈ = −a1 ω² cos ϕ − 4 a2 ω² cos 2ϕ (closed form).
        let (a1, a2, w) = (0.01, 0.002, 100.0);
        let sh = Shaped::<f64>::new(
            a1,
            a2,
            Schedule {
                omega: w,
                ramp: None,
                lag: None,
            },
        );
        let t = 0.0123;
        let want = -a1 * w * w * (w * t).cos() - 4.0 * a2 * w * w * (2.0 * w * t).cos();
        assert!((sh.accel(t) - want).abs() < 1e-9);
    }
}
