//! Integrators, kept apart from the models through the small [`System`] trait.
//!
//! Every integrator reports its work in [`Stats`], so accuracy can be set against cost.

mod rk4;

pub use rk4::{rk4_fixed, rk4_step};

use crate::Real;

/// A first-order system y' = f(t, y) with an N-dimensional state in the number format `R`.
///
/// Time is always f64: it is bookkeeping computed as t0 + i·h, never accumulated, and an f32
/// clock would lose the drive phase within minutes of simulated time (ulp(3600 s) ≈ 0.24 ms in
/// f32, 0.08 rad at ω = 330 rad/s).
pub trait System<const N: usize, R: Real = f64> {
    /// Writes f(t, y) into `dy`.
    fn rhs(&self, t: f64, y: &[R; N], dy: &mut [R; N]);
}

/// The work an integration did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Right-hand-side evaluations (for second-order systems: acceleration evaluations).
    pub rhs_evals: u64,
    /// Rejected steps (adaptive methods only).
    pub rejected: u64,
}

impl Stats {
    /// Adds another run's work to this one.
    pub fn add(&mut self, other: Stats) {
        self.steps += other.steps;
        self.rhs_evals += other.rhs_evals;
        self.rejected += other.rejected;
    }
}
