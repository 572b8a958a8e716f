//! The synchronous averager in f32, for the accuracy-and-cost comparison only
//! (`docs/accuracy-mcu.md`); the rig uses the fixed-point [`super::period`].
//!
//! Same algorithm: unwrap by wrapped sample differences, boxcar mean over the drive period, I/Q
//! demodulation, but in f32 radians with an f32 sin/cos ([`SinCosF32`]). Its weak point is the
//! unwrapped angle: f32 has a 24-bit significand, so at |u| ≈ 3 rad its resolution is 2.4e-7 rad
//! and a pendulum that has turned 1000 times has only 1e-4 rad — where the fixed-point sums keep
//! 1.5e-9 rad at any number of turns.

use crate::rig::fixed::trig::SinCosF32;
use crate::rig::fixed::Angle;
use core::marker::PhantomData;

/// One period's result in f32 radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodMeanF32 {
    pub samples: u32,
    /// Mean angle (rad, unwrapped scale).
    pub mean: f32,
    /// Wobble I and Q (rad).
    pub i: f32,
    pub q: f32,
}

/// The f32 averager.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodAveragerF32<T> {
    started: bool,
    last_theta: Angle,
    last_psi: u32,
    u: f32,
    u_start: f32,
    n: u32,
    sum: f32,
    sum_c: f32,
    sum_s: f32,
    trig: PhantomData<T>,
}

const RAD_PER_BIT: f32 = core::f32::consts::TAU / 4_294_967_296.0;

impl<T: SinCosF32> Default for PeriodAveragerF32<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: SinCosF32> PeriodAveragerF32<T> {
    pub fn new() -> Self {
        Self {
            started: false,
            last_theta: Angle::ZERO,
            last_psi: 0,
            u: 0.0,
            u_start: 0.0,
            n: 0,
            sum: 0.0,
            sum_c: 0.0,
            sum_s: 0.0,
            trig: PhantomData,
        }
    }

    /// One sample; returns a result when a drive period completes.
    #[inline]
    pub fn push(&mut self, theta: Angle, psi: Angle) -> Option<PeriodMeanF32> {
        let psi_u = psi.to_turns_u32();
        if !self.started {
            self.started = true;
            self.last_theta = theta;
            self.last_psi = psi_u;
            self.u = theta.to_bits() as f32 * RAD_PER_BIT;
            self.u_start = self.u;
            return None;
        }
        self.u += (theta - self.last_theta).to_bits() as f32 * RAD_PER_BIT;
        self.last_theta = theta;
        let wrapped = psi_u < self.last_psi;
        self.last_psi = psi_u;
        let mut out = None;
        if wrapped {
            if self.n > 0 {
                let inv = 1.0 / self.n as f32;
                out = Some(PeriodMeanF32 {
                    samples: self.n,
                    mean: self.u_start + self.sum * inv,
                    i: 2.0 * self.sum_c * inv,
                    q: 2.0 * self.sum_s * inv,
                });
            }
            self.u_start = self.u;
            self.n = 0;
            self.sum = 0.0;
            self.sum_c = 0.0;
            self.sum_s = 0.0;
        }
        let d = self.u - self.u_start;
        let (s, c) = T::sin_cos(psi);
        self.sum += d;
        self.sum_c += d * c;
        self.sum_s += d * s;
        self.n += 1;
        out
    }
}
