//! The full equation by Runge–Kutta–Nyström 8(6) with a whole number of steps per drive period.
//!
//! ```text
//! period p: t ∈ [pT, (p+1)T], N steps of H = T/N, stage times pT + kH + τ_i (k < N, i < 9)
//! s̈/ℓ at those times is the same every period: a table of N·9 values, filled once per N
//! error of a step: max(|Δθ|/(atol + rtol |θ|), |Δθ'|/(atol + rtol |θ'|)), Δ = order 8 − order 6
//! period accepted when every step's error ≤ 1; else redone with more steps (counted as work)
//! next N from the worst error (∝ N^(−7)), aiming at 0.3, changed only by more than 20 %
//! ```
//! Strobes fall on period ends, which are step ends: no interpolation. Anything sampled inside
//! a period (period means, output, sensor) is read from a replay of that period's steps with
//! cubic Hermite interpolation inside a step, its evaluations counted. Each evaluation costs one
//! sin/cos of θ and no libm call for the drive. A run whose end is not a period end finishes
//! with steps of the same density that read the drive from its signal.
//!
//! Only the full equation with a drive that is periodic from t = 0 (steady, or with a
//! slider-crank) and viscous damping or none: [`super::run`] refuses the rest by name.

use super::eom::{FullEom, NoExtra};
use super::run::{Context, RunOut, SimError};
use super::sampling::{Hermite, Interpolant, Recorder, Sink};
use super::signal::DriveSignal;
use super::turns::{Shifted, Turns};
use crate::integrate::rkn::tableau::STAGES;
use crate::integrate::{DampedRkn, IntegrateError, Stats, TOLERANCE_FLOOR};
use crate::Real;

/// Most steps per period held in the drive table; beyond it the drive is read from its signal.
const TABLE_STEPS: usize = 256;
/// Most steps per period a run may take.
const MAX_STEPS: u32 = 1_000_000;
/// Steps in the first period tried.
const FIRST_STEPS: u32 = 8;
/// The error a period aims at (of the largest allowed, 1).
const TARGET: f64 = 0.3;

/// The equation's pieces a step needs.
struct Periodic<'e, R: Real, D: DriveSignal<R>> {
    eom: &'e FullEom<R, D, NoExtra>,
    c: R,
    rkn: DampedRkn,
    n: u32,
    table: [R; TABLE_STEPS * STAGES],
    tabled: bool,
}

impl<R: Real, D: DriveSignal<R>> Periodic<'_, R, D> {
    fn set_steps(&mut self, n: u32, period: f64, c: f64) {
        self.n = n;
        self.rkn = DampedRkn::new(period / f64::from(n), c);
        self.tabled = (n as usize) <= TABLE_STEPS;
        if self.tabled {
            for k in 0..n as usize {
                for i in 0..STAGES {
                    let t = k as f64 * self.rkn.h + self.rkn.tau[i];
                    self.table[k * STAGES + i] = self.eom.drive.accel(t);
                }
            }
        }
    }

    /// s̈/ℓ at stage i of step k of the period starting at t0.
    #[inline(always)]
    fn accel(&self, t0: f64, k: u32, i: usize) -> R {
        if self.tabled {
            self.table[k as usize * STAGES + i]
        } else {
            self.eom
                .drive
                .accel(t0 + f64::from(k) * self.rkn.h + self.rkn.tau[i])
        }
    }

    /// Step k of the period starting at t0, from (θ, θ', g).
    #[inline(always)]
    fn step(&self, t0: f64, k: u32, y: (R, R, R)) -> (R, R, R, (R, R)) {
        let out = self.rkn.step(y.0, y.1, y.2, |i, th| {
            self.eom.conservative_with(self.accel(t0, k, i), th)
        });
        (out.theta, out.rate, out.g1, out.error)
    }
}

/// Runs the full equation `eom` (gravity and drive only) with viscous c, to the tolerances.
pub(super) fn run<'r, R: Real, D: DriveSignal<R>, Rec: Recorder>(
    eom: FullEom<R, D, NoExtra>,
    c: f64,
    (rtol, atol): (f64, f64),
    ctx: &Context,
    rec: Sink<'r, Rec>,
) -> Result<RunOut<'r, Rec>, SimError> {
    let mut sampler = ctx.sampler(rec);
    let period = ctx.period;
    let mut m = Periodic {
        eom: &eom,
        c: R::from_f64(c),
        rkn: DampedRkn::new(period, c),
        n: 0,
        table: [R::ZERO; TABLE_STEPS * STAGES],
        tabled: false,
    };
    m.set_steps(FIRST_STEPS, period, c);
    // As DOP853's: tolerances below 100 ε of the format ask for what rounding cannot give.
    let floor = TOLERANCE_FLOOR * R::EPSILON.to_f64();
    let (rtol, atol) = (rtol.max(floor), atol.max(floor));
    let mut work = Stats::default();
    let mut turns = Turns::new(ctx.periodic);
    let theta0 = turns.reduce(R::from_f64(ctx.y0.0));
    let mut y = (theta0, R::from_f64(ctx.y0.1), eom.conservative(0.0, theta0));
    work.rhs_evals += 1;
    let scaled = |e: R, a: R, b: R| {
        e.to_f64().abs() / (atol + rtol * a.to_f64().abs().max(b.to_f64().abs()))
    };
    let whole = libm::floor(ctx.t_end / period * (1.0 + 1e-12)) as u64;
    for p in 0..whole {
        let t0 = p as f64 * period;
        let (end, worst) = loop {
            let (mut z, mut worst) = (y, 0.0f64);
            for k in 0..m.n {
                let (th, v, g, e) = m.step(t0, k, z);
                worst = worst.max(scaled(e.0, z.0, th)).max(scaled(e.1, z.1, v));
                z = (th, v, g);
            }
            work.rhs_evals += 8 * u64::from(m.n);
            if !(z.0.is_finite() && z.1.is_finite()) {
                return Err(SimError::Integrate(IntegrateError::NonFinite { t: t0 }));
            }
            if worst <= 1.0 {
                work.steps += u64::from(m.n);
                break (z, worst);
            }
            work.rejected += u64::from(m.n);
            if m.n >= MAX_STEPS {
                return Err(SimError::Unsupported(
                    "rkn86: more than 1e6 steps per drive period needed: loosen run.rtol/run.atol",
                ));
            }
            let grow = libm::pow(worst / TARGET, 1.0 / 7.0).clamp(1.25, 4.0);
            let n = (libm::ceil(f64::from(m.n) * grow) as u32).min(MAX_STEPS);
            m.set_steps(n, period, c);
        };
        let offset = turns.offset();
        let mut replay = Shifted(
            Replay {
                m: &m,
                t0,
                start: y,
                at: (0, y),
                next: None,
                evals: 0,
            },
            offset,
        );
        let t1 = (p + 1) as f64 * period;
        sampler.step(t1, (end.0.to_f64() + offset, end.1.to_f64()), &mut replay);
        work.rhs_evals += replay.0.evals;
        y = end;
        if turns.due(y.0) {
            y.0 = turns.reduce(y.0);
        }
        // Next period's steps: aim at TARGET; change only by more than 20 %.
        let ideal = f64::from(m.n) * libm::pow(worst.max(1e-300) / TARGET, 1.0 / 7.0);
        let ideal = ideal.clamp(0.5 * f64::from(m.n), 4.0 * f64::from(m.n));
        if !(0.8 * f64::from(m.n)..=f64::from(m.n)).contains(&ideal) {
            let n = (libm::ceil(ideal) as u32).clamp(1, MAX_STEPS);
            if n != m.n {
                m.set_steps(n, period, c);
            }
        }
    }
    // The rest of the run, short of a whole period: steps of the same density.
    let t0 = whole as f64 * period;
    let rest = ctx.t_end - t0;
    let mut t = t0;
    if rest > 1e-12 * ctx.t_end.max(1.0) {
        let n = libm::ceil(rest / period * f64::from(m.n)).max(1.0) as u32;
        let h = rest / f64::from(n);
        let rkn = DampedRkn::new(h, c);
        for k in 0..n {
            let ts = t0 + f64::from(k) * h;
            let out = rkn.step(y.0, y.1, y.2, |i, th| eom.conservative(ts + rkn.tau[i], th));
            work.rhs_evals += 8;
            work.steps += 1;
            let t1 = if k + 1 == n { ctx.t_end } else { ts + h };
            let offset = turns.offset();
            let mut interp = Shifted(
                Hermite {
                    t0: ts,
                    t1,
                    y0: [y.0, y.1],
                    y1: [out.theta, out.rate],
                    f0: [y.1, y.2 - m.c * y.1],
                    f1: [out.rate, out.g1 - m.c * out.rate],
                },
                offset,
            );
            sampler.step(
                t1,
                (out.theta.to_f64() + offset, out.rate.to_f64()),
                &mut interp,
            );
            y = (out.theta, out.rate, out.g1);
            t = t1;
        }
    } else {
        t = ctx.t_end;
    }
    if !(y.0.is_finite() && y.1.is_finite()) {
        return Err(SimError::Integrate(IntegrateError::NonFinite { t }));
    }
    Ok(RunOut {
        sampler,
        work,
        end: turns.end_state(t, y.0, y.1),
        sticks: None,
    })
}

/// The states inside an accepted period, replayed step by step on demand (times are asked in
/// increasing order), with cubic Hermite interpolation inside a step.
struct Replay<'m, 'e, R: Real, D: DriveSignal<R>> {
    m: &'m Periodic<'e, R, D>,
    t0: f64,
    start: (R, R, R),
    /// Step index and state at its start.
    at: (u32, (R, R, R)),
    /// The end of step `at.0`, once computed.
    next: Option<(R, R, R)>,
    evals: u64,
}

impl<R: Real, D: DriveSignal<R>> Interpolant for Replay<'_, '_, R, D> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        let h = self.m.rkn.h;
        let j = (libm::floor((t - self.t0) / h).max(0.0) as u32).min(self.m.n - 1);
        if j < self.at.0 {
            self.at = (0, self.start);
            self.next = None;
        }
        loop {
            let (k, y) = self.at;
            let end = match self.next {
                Some(e) => e,
                None => {
                    let (th, v, g, _) = self.m.step(self.t0, k, y);
                    self.evals += 8;
                    self.next = Some((th, v, g));
                    (th, v, g)
                }
            };
            if k == j {
                let c = self.m.c;
                let t0 = self.t0 + f64::from(k) * h;
                return Hermite {
                    t0,
                    t1: t0 + h,
                    y0: [y.0, y.1],
                    y1: [end.0, end.1],
                    f0: [y.1, y.2 - c * y.1],
                    f1: [end.1, end.2 - c * end.1],
                }
                .at(t);
            }
            self.at = (k + 1, end);
            self.next = None;
        }
    }
}
