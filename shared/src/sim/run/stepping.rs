//! The loops that step a composed smooth equation with DOP853 or a fixed-step method (RK4, the
//! symplectic compositions), feeding the sampler after each step.

use super::compose::RunOut;
use super::plan::Context;
use super::{Method, SimError};
use crate::integrate::{
    rk4_observe, symplectic_fixed, Control, Dop853, Force, IntegrateError, Phase, Stats, Step,
    StepControl, Symplectic, System,
};
use crate::real::Real;
use crate::sim::sampling::{Hermite, Interpolant, Recorder, Sampler, Sink};
use crate::sim::turns::{Shifted, Turns};

/// Dense output of an accepted DOP853 step as an [`Interpolant`].
pub(in crate::sim) struct Dense<'s, 'a, R: Real>(pub &'s Step<'a, 2, R>);

impl<R: Real> Interpolant for Dense<'_, '_, R> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        let y = self.0.eval(t);
        (y[0].to_f64(), y[1].to_f64())
    }
}

fn pair<R: Real>(y: &[R; 2]) -> (f64, f64) {
    (y[0].to_f64(), y[1].to_f64())
}

/// Integrates a smooth equation with the chosen method, feeding the sampler.
///
/// The integrators see the angle reduced by whole turns ([`Turns`]): a run stops when the angle
/// is due for reduction and restarts from the reduced state, at the same step size and, for the
/// fixed-step methods, at the same step times t_i = i·h.
pub(super) fn integrate<'r, R: Real, S: System<2, R>, Rec: Recorder>(
    sys: S,
    ctx: &Context,
    rec: Sink<'r, Rec>,
) -> Result<RunOut<'r, Rec>, SimError> {
    let mut sampler = ctx.sampler(rec);
    let mut turns = Turns::new(ctx.periodic);
    let mut y = [turns.reduce(R::from_f64(ctx.y0.0)), R::from_f64(ctx.y0.1)];
    let mut t = 0.0;
    let mut work = Stats::default();
    match ctx.method {
        Method::Dop853 { rtol, atol } => {
            let mut solver = Dop853::new(rtol, atol);
            solver.h_max = ctx.h_max;
            solver.beta = ctx.beta;
            solver.max_steps = u64::MAX;
            loop {
                let offset = turns.offset();
                let mut last_h = None;
                let sol = solver.solve(&sys, t, y, ctx.t_end, |step| {
                    let (theta, rate) = pair(&step.y1);
                    sampler.step(
                        step.t1,
                        (theta + offset, rate),
                        &mut Shifted(Dense(step), offset),
                    );
                    last_h = Some(step.t1 - step.t0);
                    if turns.due(step.y1[0]) {
                        StepControl::Stop
                    } else {
                        StepControl::Continue
                    }
                })?;
                work.add(sol.stats);
                (t, y) = (sol.t, sol.y);
                if t >= ctx.t_end {
                    break;
                }
                y[0] = turns.reduce(y[0]);
                solver.h_init = last_h;
            }
        }
        Method::Symplectic {
            scheme,
            steps_per_period,
        } => {
            let driver = SymplecticDriver {
                scheme,
                force: AtRest(&sys),
            };
            let n_h = fixed_steps(ctx, steps_per_period);
            (t, y) = in_stretches(&driver, &sys, n_h, y, &mut turns, &mut sampler, &mut work);
        }
        Method::Rkn86 { .. } | Method::Rkn1210 { .. } => {
            return Err(SimError::Unsupported(
                "the RKN methods run through their own loops",
            ))
        }
        Method::Rk4 { steps_per_period } => {
            let n_h = fixed_steps(ctx, steps_per_period);
            (t, y) = in_stretches(
                &Rk4Driver(&sys),
                &sys,
                n_h,
                y,
                &mut turns,
                &mut sampler,
                &mut work,
            );
        }
    }
    for v in y {
        if !v.is_finite() {
            return Err(SimError::Integrate(IntegrateError::NonFinite { t }));
        }
    }
    let end = turns.end_state(t, y[0], y[1]);
    Ok(RunOut {
        sampler,
        work,
        end,
        sticks: None,
    })
}

/// The step count and size of a fixed-step run: whole steps, the last landing on t_end.
fn fixed_steps(ctx: &Context, steps_per_period: f64) -> (u64, f64) {
    let n = libm::round(ctx.t_end / ctx.period * steps_per_period).max(1.0) as u64;
    (n, ctx.t_end / n as f64)
}

/// A fixed-step method run from (t, y) for up to n steps, observed after each.
trait FixedDriver<R: Real> {
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        observer: O,
    ) -> (Stats, [R; 2]);
}

struct Rk4Driver<'s, S>(&'s S);

impl<R: Real, S: System<2, R>> FixedDriver<R> for Rk4Driver<'_, S> {
    #[inline(always)]
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        mut observer: O,
    ) -> (Stats, [R; 2]) {
        let sol = rk4_observe(self.0, t, y, h, n, |t, y| observer(t, *y));
        (sol.stats, sol.y)
    }
}

struct SymplecticDriver<F> {
    scheme: Symplectic,
    force: F,
}

impl<R: Real, F: Force<1, R>> FixedDriver<R> for SymplecticDriver<F> {
    #[inline(always)]
    fn run<O: FnMut(f64, [R; 2]) -> Control>(
        &self,
        t: f64,
        y: [R; 2],
        h: f64,
        n: u64,
        mut observer: O,
    ) -> (Stats, [R; 2]) {
        let x0 = Phase {
            q: [y[0]],
            v: [y[1]],
        };
        let sol = symplectic_fixed(self.scheme, &self.force, t, x0, h, n, |t, x| {
            observer(t, [x.q[0], x.v[0]])
        });
        (sol.stats, [sol.y.q[0], sol.y.v[0]])
    }
}

/// Runs n fixed steps of size h from t = 0 in stretches, each ending when the angle is due for
/// reduction; the next starts from the reduced state at t = done·h (step times stay t0 + i·h,
/// computed afresh). Returns where the run ended.
fn in_stretches<R: Real, S: System<2, R>, D: FixedDriver<R>, Rec: Recorder>(
    driver: &D,
    sys: &S,
    (n, h): (u64, f64),
    mut y: [R; 2],
    turns: &mut Turns,
    sampler: &mut Sampler<'_, Rec>,
    work: &mut Stats,
) -> (f64, [R; 2]) {
    let (mut t, mut done) = (0.0, 0u64);
    while done < n {
        let offset = turns.offset();
        let mut prev = (t, y);
        let mut extra = 0u64;
        let (stats, y_end) = driver.run(t, y, h, n - done, |t, y| {
            observe(sampler, sys, prev, (t, y), offset, &mut extra);
            prev = (t, y);
            if turns.due(y[0]) {
                Control::Stop
            } else {
                Control::Continue
            }
        });
        work.add(stats);
        work.rhs_evals += extra;
        done += stats.steps;
        (t, y) = (done as f64 * h, [turns.reduce(y_end[0]), y_end[1]]);
    }
    (t, y)
}

/// Hands a fixed step from `prev` to `next` to the sampler, with its turns added back.
fn observe<R: Real, S: System<2, R>, Rec: Recorder>(
    sampler: &mut Sampler<'_, Rec>,
    sys: &S,
    prev: (f64, [R; 2]),
    next: (f64, [R; 2]),
    offset: f64,
    extra: &mut u64,
) {
    let (theta, rate) = pair(&next.1);
    let interp = LazyHermite {
        sys,
        t0: prev.0,
        t1: next.0,
        y0: prev.1,
        y1: next.1,
        ready: None,
        evals: extra,
    };
    sampler.step(next.0, (theta + offset, rate), &mut Shifted(interp, offset));
}

/// An undamped equation seen as a force: θ'' = a(t, θ), evaluated at θ' = 0 (the extras of an
/// undamped scene ignore θ', which [`super::checks::check_method`] ensures before a symplectic
/// method runs).
struct AtRest<'s, S>(&'s S);

impl<R: Real, S: System<2, R>> Force<1, R> for AtRest<'_, S> {
    #[inline(always)]
    fn accel(&self, t: f64, q: &[R; 1], a: &mut [R; 1]) {
        let mut dy = [R::ZERO; 2];
        self.0.rhs(t, &[q[0], R::ZERO], &mut dy);
        a[0] = dy[1];
    }
}

/// Hermite interpolation whose end derivatives are evaluated only if a sample falls inside the
/// step (two right-hand-side evaluations, counted as work).
struct LazyHermite<'s, R: Real, S: System<2, R>> {
    sys: &'s S,
    t0: f64,
    t1: f64,
    y0: [R; 2],
    y1: [R; 2],
    ready: Option<Hermite<R>>,
    evals: &'s mut u64,
}

impl<R: Real, S: System<2, R>> Interpolant for LazyHermite<'_, R, S> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        if self.ready.is_none() {
            let (mut f0, mut f1) = ([R::ZERO; 2], [R::ZERO; 2]);
            self.sys.rhs(self.t0, &self.y0, &mut f0);
            self.sys.rhs(self.t1, &self.y1, &mut f1);
            *self.evals += 2;
            self.ready = Some(Hermite {
                t0: self.t0,
                t1: self.t1,
                y0: self.y0,
                y1: self.y1,
                f0,
                f1,
            });
        }
        self.ready
            .as_mut()
            .map_or((f64::NAN, f64::NAN), |h| h.at(t))
    }
}
