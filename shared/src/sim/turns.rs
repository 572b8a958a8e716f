//! Whole turns kept out of the integrated angle.
//!
//! A rotating pendulum's angle grows without bound. In f32, one ulp of θ is 4·10⁻³ rad once
//! θ ≈ 6·10⁴ rad (10⁴ turns, about an hour of rotation), and steps smaller than half an ulp stop
//! moving it at all; in f64 too, DOP853's error test scales with rtol·|θ| and loosens as θ grows.
//! The full and averaged equations are 2π-periodic in θ, so the integrators are handed θ reduced
//! by whole turns, counted here in an integer, and every sample and result adds them back in f64.
//! Reduction waits until |θ| > 3π, so that motion about ±π (the inverted pendulum) is never split.

use super::run::EndState;
use super::sampling::Interpolant;
use crate::{math, Real};

/// Reduce once |θ| exceeds this (rad).
const REDUCE_ABOVE: f64 = 3.0 * math::PI;

/// The whole turns taken out of the integrated angle so far.
#[derive(Debug, Clone, Copy)]
pub(super) struct Turns {
    /// Off for equations that are not periodic in θ (the linearised one).
    enabled: bool,
    count: i64,
}

impl Turns {
    pub fn new(enabled: bool) -> Self {
        Self { enabled, count: 0 }
    }

    /// What to add to an integrated angle to get the true one (rad).
    pub fn offset(&self) -> f64 {
        self.count as f64 * math::TAU
    }

    /// A run's end state with its whole turns put back.
    pub fn end_state<R: Real>(&self, t: f64, theta: R, rate: R) -> EndState {
        EndState {
            t,
            theta: theta.to_f64() + self.offset(),
            rate: rate.to_f64(),
        }
    }

    /// Whether θ has gone far enough to be reduced (never for ±∞ or NaN: a run that blew up
    /// must end with its non-finite state, not a turn count).
    pub fn due<R: Real>(&self, theta: R) -> bool {
        let x = theta.to_f64();
        self.enabled && x.is_finite() && x.abs() > REDUCE_ABOVE
    }

    /// θ without its whole turns (into [−π, π]), the turns counted; unchanged unless due.
    pub fn reduce<R: Real>(&mut self, theta: R) -> R {
        if !self.due(theta) {
            return theta;
        }
        let x = theta.to_f64();
        let k = libm::round(x / math::TAU);
        // |θ| < 2^63 turns for any finite run of ≤ 1e9 periods; saturate rather than wrap.
        self.count = self.count.saturating_add(k as i64);
        R::from_f64(x - k * math::TAU)
    }
}

/// An interpolant of the reduced angle, seen with its turns added back.
pub(super) struct Shifted<I>(pub I, pub f64);

impl<I: Interpolant> Interpolant for Shifted<I> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        let (theta, rate) = self.0.at(t);
        (theta + self.1, rate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_about_the_inverted_position_is_never_reduced() {
        let mut turns = Turns::new(true);
        for theta in [math::PI, -math::PI, 1.4 * math::TAU, -1.4 * math::TAU] {
            assert_eq!(turns.reduce(theta), theta);
        }
        assert_eq!(turns.offset(), 0.0);
    }

    #[test]
    fn reduced_angle_plus_offset_is_the_angle() {
        let mut turns = Turns::new(true);
        // 1000.25 turns in f32: the reduced angle keeps f32's full resolution near π/2.
        let theta = 1000.25 * math::TAU;
        let reduced = turns.reduce(theta as f32);
        assert!((f64::from(reduced) - 0.25 * math::TAU).abs() < 1e-3);
        assert_eq!(turns.offset(), 1000.0 * math::TAU);
        let mut off = Turns::new(false);
        assert_eq!(off.reduce(theta), theta);
    }

    #[test]
    fn a_blown_up_angle_is_left_alone() {
        let mut turns = Turns::new(true);
        assert_eq!(turns.reduce(f64::INFINITY), f64::INFINITY);
        assert!(turns.reduce(f64::NAN).is_nan());
        assert_eq!(turns.offset(), 0.0);
        // Turn counts beyond i64 saturate (overflow checks are on in tests) instead of panicking.
        turns.reduce(1e30);
        turns.reduce(1e30);
        assert_eq!(turns.count, i64::MAX);
    }
}
