//! Synchronous averaging: one mean of the pendulum angle per drive period.
//!
//! ```text
//! u_i  = u_{i−1} + wrap(θ_i − θ_{i−1})            unwrapped angle, i64, 2^-32 turn (Q32.32 turns)
//! φ̄_k = θ_start + Σ_{i∈period k} (u_i − u_start) / N_k          (period k: N_k samples)
//! I_k  = (2/N_k) Σ (u_i − u_start) cos ψ_i,   Q_k = (2/N_k) Σ (u_i − u_start) sin ψ_i
//! ```
//! A period ends where the drive phase ψ wraps through zero. Averaging over whole periods of the
//! drive removes the fast wobble ξ ≈ (A/ℓ) sin(φ − θd) cos ψ (physics §3) and all its harmonics, up
//! to the fraction of a sample by which N_k misses a whole period (a residual ≲ |ξ|/N_k). I and
//! Q demodulate the wobble itself. Because the sums run on the unwrapped u, a pendulum that
//! rotates (unbounded angle) still averages correctly, as long as it turns less than half a turn
//! per sample (|θ'| < π·fs = 31 400 rad/s at 10 kHz, the unwrapping limit).
//!
//! Overflow bounds: a period is abandoned (not averaged) beyond [`MAX_SAMPLES`] = 2^14 samples,
//! so |u_i − u_start| < 2^14 · 2^31 = 2^45 and |Σ| < 2^59 < 2^63; the I/Q products use a Q15
//! cosine, |Σ| < 2^14 · 2^45 · 2^15 = 2^74 — too big, so the offsets are first reduced to Q20
//! turns (>> 12) before the product: |Σ| < 2^14 · 2^33 · 2^15 = 2^62. Sums saturate regardless.

use crate::rig::fixed::trig::{Poly, SinCos};
use crate::rig::fixed::Angle;
use core::marker::PhantomData;

/// Longest period averaged (samples); longer ones (drive slower than fs/2^14, 0.6 Hz at 10 kHz)
/// are dropped.
pub const MAX_SAMPLES: u32 = 1 << 14;

/// One drive period's average.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PeriodMean {
    /// Stamp of the middle of the period (µs, wrapping): halfway between its first and last
    /// samples, where the boxcar mean of a steadily moving angle belongs.
    pub t_us: u32,
    /// Time since the previous period's middle (µs).
    pub dt_us: u32,
    pub samples: u32,
    /// The slow angle φ̄ (wrapped).
    pub mean: Angle,
    /// The same on the unwrapped scale (2^-32 turn), for differences across periods.
    pub unwrapped: i64,
    /// Wobble demodulation, in 2^-20 turn (Q20 turns, 6e-6 rad): I (cos ψ), Q (sin ψ).
    pub i: i64,
    pub q: i64,
}

/// The running sums of the current period; `T` is the sin/cos used for the demodulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PeriodAverager<T = Poly> {
    started: bool,
    last_theta: Angle,
    last_psi: u32,
    u: i64,
    u_start: i64,
    theta_start: Angle,
    n: u32,
    sum: i64,
    sum_c: i64,
    sum_s: i64,
    t_first: u32,
    t_last: u32,
    t_prev_mid: Option<u32>,
    trig: PhantomData<T>,
}

impl PeriodAverager {
    pub fn new() -> Self {
        Self::default()
    }
}

impl<T: SinCos> PeriodAverager<T> {
    /// With another sin/cos (for the cost comparison).
    pub fn with_trig() -> Self {
        Self {
            started: false,
            last_theta: Angle::ZERO,
            last_psi: 0,
            u: 0,
            u_start: 0,
            theta_start: Angle::ZERO,
            n: 0,
            sum: 0,
            sum_c: 0,
            sum_s: 0,
            t_first: 0,
            t_last: 0,
            t_prev_mid: None,
            trig: PhantomData,
        }
    }

    /// One sample: stamp, pendulum angle, drive phase. Returns a mean when a period completes.
    #[inline]
    pub fn push(&mut self, t_us: u32, theta: Angle, psi: Angle) -> Option<PeriodMean> {
        let psi_u = psi.to_turns_u32();
        if !self.started {
            self.started = true;
            self.last_theta = theta;
            self.last_psi = psi_u;
            self.u = i64::from(theta.to_bits()); // the unwrapped scale starts at the first angle
            self.begin(theta);
            self.t_first = t_us;
            self.t_last = t_us;
            return None;
        }
        self.u = self
            .u
            .wrapping_add(i64::from((theta - self.last_theta).to_bits()));
        self.last_theta = theta;
        let wrapped = psi_u < self.last_psi; // ψ passed through zero: a new period begins here
        self.last_psi = psi_u;
        let mut out = None;
        if wrapped {
            out = self.finish();
            self.begin(theta);
            self.t_first = t_us;
        }
        self.t_last = t_us;
        self.accumulate(psi);
        out
    }

    fn begin(&mut self, theta: Angle) {
        self.u_start = self.u;
        self.theta_start = theta;
        self.n = 0;
        self.sum = 0;
        self.sum_c = 0;
        self.sum_s = 0;
    }

    #[inline]
    fn accumulate(&mut self, psi: Angle) {
        if self.n >= MAX_SAMPLES {
            self.n = MAX_SAMPLES + 1; // marks the period as too long
            return;
        }
        let d = self.u.wrapping_sub(self.u_start);
        self.sum = self.sum.saturating_add(d);
        let (s, c) = T::sin_cos(psi);
        let d20 = d >> 12; // Q20 turns
        let (s15, c15) = (i64::from(s.to_bits() >> 15), i64::from(c.to_bits() >> 15));
        self.sum_c = self.sum_c.saturating_add(d20 * c15);
        self.sum_s = self.sum_s.saturating_add(d20 * s15);
        self.n += 1;
    }

    fn finish(&mut self) -> Option<PeriodMean> {
        let mid = self
            .t_first
            .wrapping_add(self.t_last.wrapping_sub(self.t_first) / 2);
        let prev = self.t_prev_mid.replace(mid);
        let n = self.n;
        if n == 0 || n > MAX_SAMPLES {
            return None;
        }
        let dt = mid.wrapping_sub(prev?);
        let n64 = i64::from(n);
        let off = crate::rig::fixed::approx::div_round(self.sum, n64);
        // (2/N) Σ d20·c15 / 2^15  →  Q20 turns
        let i = crate::rig::fixed::approx::div_round(self.sum_c, n64 << 14);
        let q = crate::rig::fixed::approx::div_round(self.sum_s, n64 << 14);
        Some(PeriodMean {
            t_us: mid,
            dt_us: dt,
            samples: n,
            mean: self.theta_start + Angle::from_bits(off as i32),
            unwrapped: self.u_start.wrapping_add(off),
            i,
            q,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removes_the_wobble_and_demodulates_it() {
        // θ = 0.3 rad + 0.05 cos ψ, 200 samples per period exactly: the mean is 0.3 rad to the
        // Q-rounding (1e-8 rad) and I = 0.05 rad, Q = 0 to the Q20-turn rounding (6e-6 rad) and the
        // Q15 cosine (3e-5 relative).
        let mut p = PeriodAverager::new();
        let mut last = None;
        for k in 0..2000u32 {
            let psi = Angle::from_turns_u32(k.wrapping_mul((1u64 << 32).div_ceil(200) as u32));
            let th = Angle::from_rad(0.3 + 0.05 * crate::math::cos(psi.to_rad()));
            if let Some(m) = p.push(k * 100, th, psi) {
                last = Some(m);
            }
        }
        let m = last.unwrap();
        assert!((m.mean.to_rad() - 0.3).abs() < 1e-6, "{}", m.mean.to_rad());
        let to_rad = |x: i64| x as f64 / 1_048_576.0 * crate::math::TAU;
        assert!((to_rad(m.i) - 0.05).abs() < 2e-5, "{}", to_rad(m.i));
        assert!(to_rad(m.q).abs() < 2e-5);
        assert_eq!(m.dt_us, 200 * 100);
    }
}
