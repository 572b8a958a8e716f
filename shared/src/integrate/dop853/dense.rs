//! One accepted DOP853 step and its 7th-order dense output.
//!
//! ```text
//! θ = (t − t0)/h,  θ' = 1 − θ
//! y(t0 + θh) ≈ r1 + θ(r2 + θ'(r3 + θ(r4 + θ'(r5 + θ(r6 + θ'(r7 + θ r8))))))
//! r1 = y0,  r2 = y1 − y0,  r3 = h k1 − r2,  r4 = r2 − h k13 − r3,
//! r(m+1) = h Σ_j d_{m,j} k_j   (m = 4..7; j = 1, 6..16)
//! ```
//! (HNW I §II.10, "Dense output"; the d coefficients are in `tableau`.) The first four terms make
//! the polynomial match y and f at both ends; the last four, built from three extra stages, raise
//! its order to 7. The extra stages are computed on the first call to [`Step::eval`] and not at
//! all if nobody asks, so a run that only wants the end point pays nothing for dense output.

use super::tableau::{D, STAGES};
use super::{combine, stages};
use crate::integrate::System;
use crate::{math, Real};
use core::cell::{Cell, OnceCell};

/// An accepted step from (t0, y0) to (t1, y1), handed to the observer of [`super::Dop853::solve`].
pub struct Step<'a, const N: usize, R: Real> {
    /// Start of the step.
    pub t0: f64,
    /// End of the step.
    pub t1: f64,
    /// State at t0.
    pub y0: [R; N],
    /// State at t1.
    pub y1: [R; N],
    sys: &'a dyn System<N, R>,
    /// Stages 1..13 of the step (13 = f(t1, y1)); 14..16 are filled in by the dense output.
    k: &'a [[R; N]; STAGES],
    /// r2..r8 of the interpolant, once computed.
    poly: OnceCell<[[R; N]; 7]>,
    /// Right-hand-side evaluations spent on the dense output (0 or 3).
    evals: Cell<u64>,
}

impl<'a, const N: usize, R: Real> Step<'a, N, R> {
    pub(super) fn new(
        sys: &'a dyn System<N, R>,
        t0: f64,
        t1: f64,
        y0: [R; N],
        y1: [R; N],
        k: &'a [[R; N]; STAGES],
    ) -> Self {
        Self {
            t0,
            t1,
            y0,
            y1,
            sys,
            k,
            poly: OnceCell::new(),
            evals: Cell::new(0),
        }
    }

    /// The step size t1 − t0 (negative when integrating backwards).
    pub fn h(&self) -> f64 {
        self.t1 - self.t0
    }

    /// The dense-output state at t, 7th-order accurate for t in [t0, t1] (outside, it
    /// extrapolates, and quickly loses accuracy). Exact at the ends: eval(t0) = y0, eval(t1) = y1
    /// up to rounding. The first call costs three right-hand-side evaluations.
    pub fn eval(&self, t: f64) -> [R; N] {
        let r = self.poly.get_or_init(|| self.interpolant());
        let s = (t - self.t0) / self.h();
        let (th, th1) = (R::from_f64(s), R::from_f64(1.0 - s));
        let mut out = [R::ZERO; N];
        for i in 0..N {
            let tail = r[3][i] + th * (r[4][i] + th1 * (r[5][i] + th * r[6][i]));
            out[i] = self.y0[i] + th * (r[0][i] + th1 * (r[1][i] + th * (r[2][i] + th1 * tail)));
        }
        out
    }

    /// A time in this step where g(t, y(t)) changes sign, found by bisection on the dense output
    /// to adjacent floats; `None` if g(t0) and g(t1) have the same sign or g(t0) = 0 (a root at
    /// t0 belongs to the step before). Only sign changes between the ends are seen: a double
    /// root, or two roots inside one step, are not.
    pub fn find_crossing(&self, g: impl Fn(f64, &[R; N]) -> f64) -> Option<f64> {
        let (g0, g1) = (g(self.t0, &self.y0), g(self.t1, &self.y1));
        if g0 == 0.0 || g0.is_nan() || g1.is_nan() || (g1 != 0.0 && (g0 < 0.0) == (g1 < 0.0)) {
            return None;
        }
        if g1 == 0.0 {
            return Some(self.t1);
        }
        let f = |t: f64| g(t, &self.eval(t));
        let (lo, hi, g_lo) = if self.t1 > self.t0 {
            (self.t0, self.t1, g0)
        } else {
            (self.t1, self.t0, g1)
        };
        Some(math::bisect(f, lo, hi, g_lo))
    }

    /// Right-hand-side evaluations spent on the dense output so far.
    pub(super) fn dense_evals(&self) -> u64 {
        self.evals.get()
    }

    /// Computes the three extra stages and r2..r8.
    fn interpolant(&self) -> [[R; N]; 7] {
        let h = self.h();
        let mut k = *self.k;
        stages(self.sys, self.t0, &self.y0, h, &mut k, 13..16);
        self.evals.set(3);
        let hr = R::from_f64(h);
        let zero = [R::ZERO; N];
        let mut r = [[R::ZERO; N]; 7];
        for i in 0..N {
            let dy = self.y1[i] - self.y0[i];
            let bspl = hr * k[0][i] - dy;
            r[0][i] = dy;
            r[1][i] = bspl;
            r[2][i] = dy - hr * k[12][i] - bspl;
        }
        for (m, row) in D.iter().enumerate() {
            // combine(0, h, k, d) = h Σ d_j k_j
            r[3 + m] = combine(&zero, h, &k, row);
        }
        r
    }
}
