//! DOP853: the explicit Runge–Kutta pair of Dormand & Prince of order 8 with error estimators of
//! orders 5 and 3, adaptive step size and 7th-order dense output.
//!
//! Source: E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*,
//! 2nd ed. (Springer 1993), §II.10 for the method, its error estimate and its dense output, and
//! §II.4 for step-size control and the starting step. Coefficients: [`tableau`].
//!
//! Why this method: the pendulum's right-hand side is cheap and smooth, and the questions asked of
//! it (converged references, Floquet matrices, long runs) want small errors; at tolerances of
//! 1e-8 and below an 8th-order pair needs several times fewer evaluations than 4th/5th-order ones.
//!
//! # Error estimate and step control
//!
//! ```text
//! sk_i  = atol + rtol · max(|y0_i|, |y1_i|)
//! e5_i  = h Σ er_j k_j,i                        (8th − 5th order)
//! e3_i  = h (Σ b_j k_j,i − bhh1 k1,i − bhh2 k9,i − bhh3 k12,i)   (8th − 3rd order)
//! E5 = Σ (e5_i/sk_i)²,  E3 = Σ (e3_i/sk_i)²
//! err = E5 / √(N (E5 + 0.01 E3))               (HNW I §II.10: behaves like O(h⁸), not O(h⁶))
//! accept iff err ≤ 1
//! h_new = h / clamp(err^(1/8 − 0.2β) / err_prev^β / 0.9,  1/6, 1/0.333)   (PI control for β > 0)
//! ```
//! After a rejection the next accepted step may not grow. β = 0 (the default, as in Hairer's
//! code for this method) is the standard controller; β ≈ 0.04 damps step-size oscillation
//! (HNW I §IV.2, "PI step size control").
//!
//! # Cost
//!
//! 12 evaluations per accepted step (11 new stages plus f at the new point, which is the first
//! stage of the next step: "first same as last"), 11 per rejected step, 2 at the start (f(t0, y0)
//! and one for the starting-step guess, none if `h_init` is given) and 3 more for each step whose
//! dense output is evaluated.
//!
//! # Precision
//!
//! The tolerances in force, relative and absolute, are at least 100·ε of the number format
//! (ε = 2.2e-16 for f64, 1.2e-7 for f32): no format can meet a tolerance near its own rounding.
//! The error estimate cancels stages much larger than the state (on a fast drive |f| ≈ ω|y|),
//! and below that its rounding noise, not the solution, sets the step: an f32 run then takes tens
//! of times the steps for nothing (hard case HC05, docs/hard-cases.md, checks the work per period
//! at the floor). For f32 this means tolerances ≥ 1.2e-5; for f64 ≥ 2.2e-14.

mod dense;
#[cfg(test)]
mod order_conditions;
mod tableau;

pub use dense::Step;

use super::{Solution, Stats, System};
use crate::{math, Real};
use core::fmt;
use tableau::{A, B, BHH1, BHH2, BHH3, C, ER, STAGES};

/// Safety factor on the predicted step (HNW I §II.4).
const SAFETY: f64 = 0.9;
/// The step may shrink to at most 1/3 and grow to at most 6 times its size in one go.
const FAC_MIN: f64 = 0.333;
const FAC_MAX: f64 = 6.0;

/// The settings of a DOP853 run. Build with [`Dop853::new`] and adjust the public fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop853 {
    /// Relative tolerance (raised to 100·ε of the format if below it).
    pub rtol: f64,
    /// Absolute tolerance (raised to 100·ε of the format if below it).
    pub atol: f64,
    /// Largest step allowed (time units; infinity for none).
    pub h_max: f64,
    /// First step to try; `None` lets the starting-step algorithm guess (one extra evaluation).
    pub h_init: Option<f64>,
    /// Most step attempts (accepted and rejected) before [`IntegrateError::TooManySteps`].
    pub max_steps: u64,
    /// The PI controller's β in [0, 0.2] (0 = the standard controller; see the module doc).
    pub beta: f64,
}

/// What the observer of an accepted DOP853 step wants next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepControl {
    /// Take the next step.
    Continue,
    /// End the run at the end of this step.
    Stop,
    /// End the run at time t inside this step (clamped to it), returning the dense-output state
    /// there: the way to stop exactly on an event the observer located.
    StopAt(f64),
}

/// Why a DOP853 run failed. Each carries the time reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IntegrateError {
    /// The step fell below the resolution of the clock at t (a singularity, or a tolerance the
    /// problem cannot meet).
    StepTooSmall { t: f64 },
    /// `max_steps` step attempts were used up before the end.
    TooManySteps { t: f64 },
    /// The state, its derivative or the error estimate stopped being finite (or the input was not).
    NonFinite { t: f64 },
    /// A tolerance, `h_max` or `h_init` that is negative, zero where it must not be, or not
    /// finite, or a β outside [0, 0.2].
    BadTolerance,
}

impl fmt::Display for IntegrateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::StepTooSmall { t } => write!(f, "step size too small at t = {t}"),
            Self::TooManySteps { t } => write!(f, "step limit reached at t = {t}"),
            Self::NonFinite { t } => write!(f, "non-finite state or derivative at t = {t}"),
            Self::BadTolerance => write!(
                f,
                "bad settings: need rtol, atol ≥ 0 and finite, not both zero; h_max, h_init > 0; \
                 0 ≤ β ≤ 0.2"
            ),
        }
    }
}

impl Dop853 {
    /// Tolerances as given, no step limit but 100 000 attempts, starting step guessed.
    pub const fn new(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            h_max: f64::INFINITY,
            h_init: None,
            max_steps: 100_000,
            beta: 0.0,
        }
    }

    /// Integrates from (t0, y0) to t1 (either direction) without observing the steps.
    pub fn integrate<S: System<N, R>, R: Real, const N: usize>(
        &self,
        sys: &S,
        t0: f64,
        y0: [R; N],
        t1: f64,
    ) -> Result<Solution<[R; N]>, IntegrateError> {
        self.solve(sys, t0, y0, t1, |_| StepControl::Continue)
    }

    /// Integrates from (t0, y0) to t1 (either direction), handing every accepted step to
    /// `on_step`, which may evaluate the dense output inside it and end the run.
    ///
    /// ```
    /// use kapitza_core::integrate::{Dop853, StepControl, System};
    /// struct Oscillator;
    /// impl System<2> for Oscillator {
    ///     fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
    ///         dy[0] = y[1];
    ///         dy[1] = -y[0];
    ///     }
    /// }
    /// // y = cos t: stop where it first crosses zero, t = π/2.
    /// let sol = Dop853::new(1e-10, 1e-10)
    ///     .solve(&Oscillator, 0.0, [1.0, 0.0], 10.0, |step| {
    ///         match step.find_crossing(|_t, y| y[0]) {
    ///             Some(t) => StepControl::StopAt(t),
    ///             None => StepControl::Continue,
    ///         }
    ///     })
    ///     .unwrap();
    /// assert!((sol.t - core::f64::consts::FRAC_PI_2).abs() < 1e-9);
    /// assert!((sol.y[1] + 1.0).abs() < 1e-9);
    /// ```
    pub fn solve<S: System<N, R>, R: Real, const N: usize>(
        &self,
        sys: &S,
        t0: f64,
        y0: [R; N],
        t1: f64,
        mut on_step: impl FnMut(&Step<'_, N, R>) -> StepControl,
    ) -> Result<Solution<[R; N]>, IntegrateError> {
        let tol = self.tolerances::<R>()?;
        let mut stats = Stats::default();
        if !t0.is_finite() || !t1.is_finite() || !all_finite(&y0) {
            return Err(IntegrateError::NonFinite { t: t0 });
        }
        if t1 == t0 {
            return Ok(Solution {
                t: t0,
                y: y0,
                stats,
            });
        }
        let dir = if t1 > t0 { 1.0 } else { -1.0 };
        let h_max = self.h_max.min((t1 - t0).abs());

        // k[j] holds stage j + 1; k[0] is f(t, y) at the start of the current step.
        let mut k = [[R::ZERO; N]; STAGES];
        sys.rhs(t0, &y0, &mut k[0]);
        stats.rhs_evals += 1;
        if !all_finite(&k[0]) {
            return Err(IntegrateError::NonFinite { t: t0 });
        }
        let mut h = dir
            * match self.h_init {
                Some(h) => h.min(h_max),
                None => initial_step(sys, t0, &y0, &k[0], dir, h_max, tol, &mut stats),
            };

        let (mut t, mut y) = (t0, y0);
        let mut err_prev = 1e-4;
        let mut after_reject = false;
        let mut attempts = 0u64;
        loop {
            if attempts >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t });
            }
            attempts += 1;
            if 0.1 * h.abs() <= t.abs() * f64::EPSILON {
                return Err(IntegrateError::StepTooSmall { t });
            }
            // Stretch the last step to land on t1 rather than leave a sliver.
            let last = (t + 1.01 * h - t1) * dir > 0.0;
            let t_new = if last { t1 } else { t + h };
            // The step actually taken is the distance between representable times (exact by
            // Sterbenz's lemma once |t| ≥ |h|), so y_new belongs to t_new, not to t + h ± ulp.
            h = t_new - t;

            stages(sys, t, &y, h, &mut k, 1..12);
            stats.rhs_evals += 11;
            let y_new = combine(&y, h, &k, &B);
            let err = error_norm(&y, &y_new, h, &k, tol);
            if !err.is_finite() || !all_finite(&y_new) {
                return Err(IntegrateError::NonFinite { t });
            }

            // err^(1/8 − 0.2β); with the standard controller (β = 0) three square roots give
            // err^(1/8) at a fraction of powf's cost, which matters on cheap right-hand sides.
            let fac_err = if self.beta == 0.0 {
                math::sqrt(math::sqrt(math::sqrt(err)))
            } else {
                math::pow_rough(err, 0.125 - 0.2 * self.beta)
            };
            if err > 1.0 {
                // Rejected: shrink (never by more than FAC_MIN) and retry.
                h /= (fac_err / SAFETY).min(1.0 / FAC_MIN);
                stats.rejected += 1;
                after_reject = true;
                continue;
            }

            sys.rhs(t_new, &y_new, &mut k[12]); // FSAL: the next step's first stage
            stats.rhs_evals += 1;
            stats.steps += 1;
            if !all_finite(&k[12]) {
                return Err(IntegrateError::NonFinite { t: t_new });
            }

            let step = Step::new(sys, t, t_new, y, y_new, &k);
            let control = on_step(&step);
            let stop = match control {
                StepControl::Continue if !last => None,
                StepControl::Continue | StepControl::Stop => Some((t_new, y_new)),
                StepControl::StopAt(ts) => {
                    let ts = if (ts - t) * dir < 0.0 {
                        t
                    } else if (ts - t_new) * dir > 0.0 {
                        t_new
                    } else {
                        ts
                    };
                    Some((ts, step.eval(ts)))
                }
            };
            stats.rhs_evals += step.dense_evals();
            if let Some((t, y)) = stop {
                return Ok(Solution { t, y, stats });
            }

            let memory = if self.beta == 0.0 {
                1.0
            } else {
                math::pow_rough(err_prev, self.beta)
            };
            let fac = (fac_err / memory / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
            let mut h_new = (h.abs() / fac).min(h_max);
            if after_reject {
                h_new = h_new.min(h.abs());
            }
            err_prev = err.max(1e-4);
            after_reject = false;
            h = dir * h_new;
            t = t_new;
            y = y_new;
            k[0] = k[12];
        }
    }

    /// Checks the settings and returns the tolerances in force.
    fn tolerances<R: Real>(&self) -> Result<Tolerance, IntegrateError> {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        let h_ok = self.h_max > 0.0 && !self.h_max.is_nan();
        let init_ok = self.h_init.is_none_or(|h| h.is_finite() && h > 0.0);
        let beta_ok = self.beta.is_finite() && (0.0..=0.2).contains(&self.beta);
        if !ok(self.rtol) || !ok(self.atol) || self.rtol + self.atol == 0.0 {
            return Err(IntegrateError::BadTolerance);
        }
        if !h_ok || !init_ok || !beta_ok {
            return Err(IntegrateError::BadTolerance);
        }
        let floor = TOLERANCE_FLOOR * R::EPSILON.to_f64();
        Ok(Tolerance {
            rtol: self.rtol.max(floor),
            atol: self.atol.max(floor),
        })
    }
}

/// The tolerances in force are at least this many ε of the number format (see # Precision).
pub(crate) const TOLERANCE_FLOOR: f64 = 100.0;

#[derive(Debug, Clone, Copy)]
struct Tolerance {
    rtol: f64,
    atol: f64,
}

fn all_finite<R: Real, const N: usize>(y: &[R; N]) -> bool {
    y.iter().all(|x| x.is_finite())
}

/// y + h Σ_j w_j k_j over the first `w.len()` stages. The increments are summed first and added
/// to y once, so a low-precision state is rounded once per stage, not once per term.
fn combine<R: Real, const N: usize>(y: &[R; N], h: f64, k: &[[R; N]; STAGES], w: &[f64]) -> [R; N] {
    let mut acc = [R::ZERO; N];
    for (kj, &wj) in k.iter().zip(w) {
        if wj != 0.0 {
            let wj = R::from_f64(wj);
            for (a, &kji) in acc.iter_mut().zip(kj) {
                *a += wj * kji;
            }
        }
    }
    let h = R::from_f64(h);
    let mut out = *y;
    for (o, a) in out.iter_mut().zip(acc) {
        *o += h * a;
    }
    out
}

/// Computes stages `range` (0-based) of a step of size h from (t, y) into `k`.
pub(super) fn stages<R: Real, const N: usize>(
    sys: &(impl System<N, R> + ?Sized),
    t: f64,
    y: &[R; N],
    h: f64,
    k: &mut [[R; N]; STAGES],
    range: core::ops::Range<usize>,
) {
    for s in range {
        let arg = combine(y, h, k, &A[s][..s]);
        sys.rhs(t + C[s] * h, &arg, &mut k[s]);
    }
}

/// The scaled error of a step; ≤ 1 means accept (see the module doc).
fn error_norm<R: Real, const N: usize>(
    y: &[R; N],
    y_new: &[R; N],
    h: f64,
    k: &[[R; N]; STAGES],
    tol: Tolerance,
) -> f64 {
    let (mut e5, mut e3) = (0.0, 0.0);
    for i in 0..N {
        let sk = tol.atol + tol.rtol * y[i].abs().max(y_new[i].abs()).to_f64();
        let (mut d5, mut d8) = (0.0, 0.0);
        for j in 0..12 {
            let kj = k[j][i].to_f64();
            d5 += ER[j] * kj;
            d8 += B[j] * kj;
        }
        let d3 = d8 - BHH1 * k[0][i].to_f64() - BHH2 * k[8][i].to_f64() - BHH3 * k[11][i].to_f64();
        e5 += (d5 / sk) * (d5 / sk);
        e3 += (d3 / sk) * (d3 / sk);
    }
    let mut den = e5 + 0.01 * e3;
    if den <= 0.0 {
        den = 1.0;
    }
    h.abs() * e5 / math::sqrt(N.max(1) as f64 * den)
}

/// The starting step (HNW I §II.4, "Starting Step Size"): a first guess from ‖y0‖/‖f0‖, then one
/// explicit Euler step to estimate the second derivative, and h with h⁸·max(‖f'‖, ‖f‖) = 0.01.
#[allow(clippy::too_many_arguments)]
fn initial_step<R: Real, const N: usize>(
    sys: &impl System<N, R>,
    t0: f64,
    y0: &[R; N],
    f0: &[R; N],
    dir: f64,
    h_max: f64,
    tol: Tolerance,
    stats: &mut Stats,
) -> f64 {
    let scale = |i: usize| tol.atol + tol.rtol * y0[i].abs().to_f64();
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..N {
        let (f, y) = (f0[i].to_f64() / scale(i), y0[i].to_f64() / scale(i));
        dnf += f * f;
        dny += y * y;
    }
    let h0 = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        0.01 * math::sqrt(dny / dnf)
    }
    .min(h_max);
    let mut y1 = *y0;
    let h0r = R::from_f64(dir * h0);
    for (y, &f) in y1.iter_mut().zip(f0) {
        *y += h0r * f;
    }
    let mut f1 = [R::ZERO; N];
    sys.rhs(t0 + dir * h0, &y1, &mut f1);
    stats.rhs_evals += 1;
    let mut der2 = 0.0;
    for i in 0..N {
        let d = (f1[i].to_f64() - f0[i].to_f64()) / scale(i);
        der2 += d * d;
    }
    let der12 = (math::sqrt(der2) / h0).max(math::sqrt(dnf));
    let h1 = if der12 <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        math::powf(0.01 / der12, 1.0 / 8.0)
    };
    let h = (100.0 * h0).min(h1).min(h_max);
    // A non-finite f1 poisons the guess; the first step will report it.
    if h.is_finite() && h > 0.0 {
        h
    } else {
        h0
    }
}
