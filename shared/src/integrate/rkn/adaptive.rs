//! RKN 8(6) or 12(10) with an adaptive step, for θ'' = g(t, θ) − c θ' where no drive period
//! sets the time scale (the averaged model's slow motion, chaotic transients, a drive off).
//!
//! ```text
//! error of a step  err = max(|Δθ|/(atol + rtol max(|θ0|, |θ1|)), |Δθ'|/(atol + rtol max(|θ0'|, |θ1'|)))
//!                  Δ = high order − embedded order q (local error O(h^(q+1)))
//! accept iff err ≤ 1
//! h_new = h / clamp(err^(1/(q+1) − 0.2β) / err_prev^β / 0.9,  1/5, 1/0.2)    (β = 0: standard)
//! ```
//! After a rejection the next step may not grow. β > 0 is the PI controller (HNW I §IV.2): on
//! an oscillation whose steps cover a sizeable part of its period the error constant changes
//! from step to step, and the standard controller then rejects about one attempt in four;
//! the PI controller's memory of the last error damps that.
//!
//! Each step builds its damping weights afresh ([`Damped`]): one expm1 per step, and one
//! log1p per stage only when g depends on t ([`Accel::autonomous`]). The state between step
//! ends is the quintic Hermite interpolant of θ, θ', θ'' at both ends ([`Span`]), all known
//! without an evaluation: its error is O(h⁶), below the step's own error wherever the step is
//! small enough for tolerances of ~1e-6 or tighter, and it is used only for samples, never to
//! continue the run.

use super::{Damped, Pair, RKN86};
use crate::integrate::{IntegrateError, Solution, Stats};
use crate::{math, Real};

/// g(t, θ) as an adaptive RKN run evaluates it.
pub trait Accel<R: Real> {
    /// What a step computes once at its start (t0, θ0) to make its stage evaluations cheap.
    type Base: Copy;
    /// Whether g is independent of t (then the stage times are never computed).
    fn autonomous(&self) -> bool;
    fn base(&self, t0: f64, theta0: R) -> Self::Base;
    /// g at (t, θ), inside the step whose start gave `base`; `offset` = θ − θ0 (formed without
    /// the rounding of that difference).
    fn accel(&self, base: &Self::Base, t: f64, theta: R, offset: R) -> R;
    /// g at the step's start (t0, θ0) itself: `accel` at offset 0, which an implementation may
    /// read off its base without evaluating anything.
    #[inline(always)]
    fn at_start(&self, base: &Self::Base, t0: f64, theta0: R) -> R {
        self.accel(base, t0, theta0, R::ZERO)
    }
    /// g at (t, θ) and e + f g: the next stage's offset, which an implementation may form
    /// without waiting for g's last operation (the stages' chain runs through it).
    #[inline(always)]
    fn accel_then(&self, base: &Self::Base, t: f64, theta: R, offset: R, (f, e): (R, R)) -> (R, R) {
        let g = self.accel(base, t, theta, offset);
        (g, e + f * g)
    }
}

/// The settings of an adaptive RKN 8(6) run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveRkn {
    pub rtol: f64,
    pub atol: f64,
    /// The PI controller's β in [0, 0.2] (0: the standard controller).
    pub beta: f64,
    /// First step to try; `None` guesses it from the start.
    pub h_init: Option<f64>,
    /// Longest step (time units).
    pub h_max: f64,
    /// Most step attempts before [`IntegrateError::TooManySteps`].
    pub max_steps: u64,
}

/// One accepted step: its ends, with θ'' at both, and the quintic Hermite interpolant between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span<R> {
    pub t0: f64,
    pub t1: f64,
    /// (θ, θ', θ'') at t0 and at t1.
    pub y0: (R, R, R),
    pub y1: (R, R, R),
}

impl<R: Real> Span<R> {
    /// (θ, θ') at t in [t0, t1].
    pub fn eval(&self, t: f64) -> (f64, f64) {
        let h = self.t1 - self.t0;
        let s = (t - self.t0) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (s4, s5) = (s3 * s, s3 * s2);
        let basis = [
            1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
            s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
            0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
            0.5 * s3 - s4 + 0.5 * s5,
            -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
            10.0 * s3 - 15.0 * s4 + 6.0 * s5,
        ];
        let slope = [
            -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
            1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
            s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
            1.5 * s2 - 4.0 * s3 + 2.5 * s4,
            -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
            30.0 * s2 - 60.0 * s3 + 30.0 * s4,
        ];
        let (a, b) = (self.y0, self.y1);
        let v = [
            a.0.to_f64(),
            h * a.1.to_f64(),
            h * h * a.2.to_f64(),
            h * h * b.2.to_f64(),
            h * b.1.to_f64(),
            b.0.to_f64(),
        ];
        let dot = |w: &[f64; 6]| w.iter().zip(&v).map(|(w, v)| w * v).sum::<f64>();
        (dot(&basis), dot(&slope) / h)
    }
}

/// The step may shrink to at most 1/5 and grow to at most 5 times its size in one go.
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 5.0;
const SAFETY: f64 = 0.9;

impl AdaptiveRkn {
    pub const fn new(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            beta: 0.0,
            h_init: None,
            h_max: f64::INFINITY,
            max_steps: u64::MAX,
        }
    }

    /// Integrates θ'' = g(t, θ) − c θ' by RKN 8(6) from (t0, θ0, θ0') to t1 > t0, handing every
    /// accepted step to `on_step`, which returns true to end the run at that step's end.
    pub fn solve<R: Real, A: Accel<R>>(
        &self,
        sys: &A,
        c: f64,
        t0: f64,
        y0: (R, R),
        t1: f64,
        on_step: impl FnMut(&Span<R>) -> bool,
    ) -> Result<Solution<(R, R)>, IntegrateError> {
        self.solve_with(&RKN86, sys, c, t0, y0, t1, on_step)
    }

    /// [`AdaptiveRkn::solve`] with any pair (the error exponent follows its embedded order).
    #[allow(clippy::too_many_arguments)]
    pub fn solve_with<R: Real, A: Accel<R>, const S: usize>(
        &self,
        pair: &'static Pair<S>,
        sys: &A,
        c: f64,
        t0: f64,
        y0: (R, R),
        t1: f64,
        mut on_step: impl FnMut(&Span<R>) -> bool,
    ) -> Result<Solution<(R, R)>, IntegrateError> {
        let exponent = 1.0 / f64::from(pair.orders.1 + 1);
        let floor = crate::integrate::TOLERANCE_FLOOR * R::EPSILON.to_f64();
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !ok(self.rtol) || !ok(self.atol) || self.rtol + self.atol == 0.0 {
            return Err(IntegrateError::BadTolerance);
        }
        let beta_ok = self.beta.is_finite() && (0.0..=0.2).contains(&self.beta);
        if !beta_ok || self.h_max.is_nan() || self.h_max <= 0.0 {
            return Err(IntegrateError::BadTolerance);
        }
        let (rtol, atol) = (self.rtol.max(floor), self.atol.max(floor));
        let mut stats = Stats::default();
        let (mut t, mut y) = (t0, y0);
        if t1.is_nan() || t1 <= t0 || !y.0.is_finite() || !y.1.is_finite() {
            return Ok(Solution { t, y, stats });
        }
        // The start's base serves every attempt from it; a pair that is not first-same-as-last
        // builds the next start's base for its g there.
        let mut base = sys.base(t, y.0);
        let mut g0 = sys.at_start(&base, t, y.0);
        stats.rhs_evals += 1;
        let h_max = self.h_max.min(t1 - t0);
        let mut h = self
            .h_init
            .unwrap_or_else(|| first_step(y, g0, rtol, atol))
            .min(h_max);
        let cr = R::from_f64(c);
        let scaled = |e: R, a: R, b: R| {
            e.to_f64().abs() / (atol + rtol * a.to_f64().abs().max(b.to_f64().abs()))
        };
        // The safety factor times err_prev^β, known a step ahead of the error it multiplies. The growth is
        // formed as a product (err^(0.2β − 1/(q+1)) by pow_rough): divisions would sit on the
        // path from one step's error to the next step's first stage.
        let memory = |err_prev: f64| {
            if self.beta == 0.0 {
                SAFETY
            } else {
                SAFETY * math::pow_rough(err_prev, self.beta)
            }
        };
        let (mut safe_memory, mut after_reject, mut attempts) = (memory(1e-4), false, 0u64);
        loop {
            if attempts >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t });
            }
            attempts += 1;
            if 0.1 * h <= t.abs() * f64::EPSILON {
                return Err(IntegrateError::StepTooSmall { t });
            }
            let last = t + 1.01 * h >= t1;
            let t_new = if last { t1 } else { t + h };
            h = t_new - t;
            let m = Damped::of(pair, h, c, !sys.autonomous());
            let out = m.step_from(y.0, y.1, g0, |i, th, d, next| {
                sys.accel_then(&base, t + m.tau[i], th, d, next)
            });
            stats.rhs_evals += S as u64 - 1;
            let err = scaled(out.error.0, y.0, out.theta).max(scaled(out.error.1, y.1, out.rate));
            if !err.is_finite() || !out.theta.is_finite() || !out.rate.is_finite() {
                return Err(IntegrateError::NonFinite { t });
            }
            let grow_err = math::pow_rough(err, 0.2 * self.beta - exponent);
            if err > 1.0 {
                h *= (grow_err * SAFETY).max(FAC_MIN);
                stats.rejected += 1;
                after_reject = true;
                continue;
            }
            stats.steps += 1;
            // The next step's size first: every stage of that step waits for it.
            let grow = (grow_err * safe_memory).clamp(FAC_MIN, FAC_MAX);
            let mut h_new = (h * grow).min(h_max);
            if after_reject {
                h_new = h_new.min(h);
            }
            safe_memory = memory(err.max(1e-4));
            after_reject = false;
            base = sys.base(t_new, out.theta);
            let g1 = if pair.fsal {
                out.g1
            } else {
                stats.rhs_evals += 1;
                sys.at_start(&base, t_new, out.theta)
            };
            let span = Span {
                t0: t,
                t1: t_new,
                y0: (y.0, y.1, g0 - cr * y.1),
                y1: (out.theta, out.rate, g1 - cr * out.rate),
            };
            let stop = on_step(&span);
            (t, y, g0) = (t_new, (out.theta, out.rate), g1);
            if last || stop {
                return Ok(Solution { t, y, stats });
            }
            h = h_new;
        }
    }
}

/// A first step from the scales of the start (HNW I §II.4's first guess, 0.01 ‖y‖/‖y'‖ on the
/// first-order form (θ, θ')), grown by the controller within a few steps.
fn first_step<R: Real>(y: (R, R), g: R, rtol: f64, atol: f64) -> f64 {
    let sk = |x: R| atol + rtol * x.to_f64().abs();
    let norm = |a: f64, b: f64| libm::sqrt(a * a + b * b);
    let dy = norm(y.0.to_f64() / sk(y.0), y.1.to_f64() / sk(y.1));
    let df = norm(y.1.to_f64() / sk(y.0), g.to_f64() / sk(y.1));
    if dy <= 1e-5 || df <= 1e-5 {
        1e-6
    } else {
        0.01 * dy / df
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// θ'' + c θ' + k θ = 0: g(θ) = −k θ, closed form e^(σt)(P cos ωd t + Q sin ωd t).
    struct Spring(f64);

    impl Accel<f64> for Spring {
        type Base = ();
        fn autonomous(&self) -> bool {
            true
        }
        fn base(&self, _t0: f64, _theta0: f64) {}
        fn accel(&self, _: &(), _t: f64, theta: f64, _: f64) -> f64 {
            -self.0 * theta
        }
    }

    fn exact(k: f64, c: f64, t: f64) -> (f64, f64) {
        let (sig, wd) = (-0.5 * c, (k - 0.25 * c * c).sqrt());
        let (p, q) = (1.0, -sig / wd); // θ0 = 1, θ0' = 0
        let e = (sig * t).exp();
        let (s, co) = (wd * t).sin_cos();
        let th = e * (p * co + q * s);
        let v = sig * th + e * wd * (-p * s + q * co);
        (th, v)
    }

    #[test]
    fn meets_the_tolerance_on_a_damped_oscillator() {
        // Global error at t = 10 (≈ 16 periods of ω = 2π/… ≈ 10 rad/s) against the closed form
        // falls with the tolerance: within 100 × tol for tol = 1e-6, 1e-9 (a tolerance bounds
        // local errors; their sum over ~100 steps stays within a factor 100 here).
        let (k, c) = (100.0, 0.4);
        for tol in [1e-6, 1e-9] {
            for beta in [0.0, 0.04] {
                let mut solver = AdaptiveRkn::new(tol, tol);
                solver.beta = beta;
                let sol = solver
                    .solve(&Spring(k), c, 0.0, (1.0, 0.0), 10.0, |_| false)
                    .unwrap();
                let (th, v) = exact(k, c, 10.0);
                let err = (sol.y.0 - th).abs().max((sol.y.1 - v).abs() / 10.0);
                assert!(err < 100.0 * tol, "tol {tol} β {beta}: error {err:e}");
                assert_eq!(sol.t, 10.0);
            }
        }
    }

    #[test]
    fn the_interpolant_matches_the_closed_form_inside_steps() {
        // At tol 1e-10 the steps are short enough that the O(h⁶) interpolant stays within
        // 1e-7 of the closed form at every step's midpoint.
        let (k, c) = (100.0, 0.4);
        let mut worst = 0.0f64;
        AdaptiveRkn::new(1e-10, 1e-10)
            .solve(&Spring(k), c, 0.0, (1.0, 0.0), 3.0, |span| {
                let tm = 0.5 * (span.t0 + span.t1);
                let (th, v) = span.eval(tm);
                let want = exact(k, c, tm);
                worst = worst
                    .max((th - want.0).abs())
                    .max((v - want.1).abs() / 10.0);
                // The ends are the step's own states.
                assert!((span.eval(span.t1).0 - span.y1.0).abs() < 1e-12);
                false
            })
            .unwrap();
        assert!(worst < 1e-7, "worst midpoint error {worst:e}");
    }

    #[test]
    fn the_pi_controller_rejects_fewer_steps_on_a_pendulum() {
        // θ'' = −k sin θ − c θ' from 2.5 rad: a large-amplitude swing, whose error constant
        // changes along the orbit. Measured: β = 0.04 rejects fewer attempts than β = 0.
        struct Pendulum;
        impl Accel<f64> for Pendulum {
            type Base = ();
            fn autonomous(&self) -> bool {
                true
            }
            fn base(&self, _: f64, _: f64) {}
            fn accel(&self, _: &(), _: f64, th: f64, _: f64) -> f64 {
                -100.0 * th.sin()
            }
        }
        let rejected = |beta| {
            let mut s = AdaptiveRkn::new(1e-6, 1e-6);
            s.beta = beta;
            s.solve(&Pendulum, 0.2, 0.0, (2.5, 0.0), 20.0, |_| false)
                .unwrap()
                .stats
                .rejected
        };
        let (standard, pi) = (rejected(0.0), rejected(0.04));
        assert!(pi < standard, "rejected: standard {standard}, PI {pi}");
    }
}
