//! Coulomb friction without chattering: sliding segments and sticking, switched at events.
//!
//! ```text
//! sliding (θ' ≠ 0):   θ'' = a(t, θ) − c θ' − μ s,   s = sign θ' fixed for the segment
//! at θ' = 0:          a(t, θ) = −ω0² sin θ + (s̈/ℓ) sin(θ − θd)   (what static friction must hold)
//!                     |a| ≤ μ → stick;  else slide with s = sign a
//! sticking:           θ' = 0, θ fixed, until |a(t, θ)| > μ; then slide with s = sign a
//! ```
//! Each sliding segment is smooth, so the adaptive method keeps its order; its end is located on
//! the dense output (θ' changes sign), never by a step landing near zero. Under a strong drive θ'
//! (which includes the fast wobble) changes sign twice a period and friction acts like weak
//! damping; sticking needs φ near θd or a weak drive (SPEC §5).

use super::eom::{FullEom, NoExtra, Sliding};
use super::run::{Context, Dense, Method, RunOut, SimError};
use super::sampling::{Interpolant, Recorder, Sampler};
use super::signal::DriveSignal;
use super::turns::{Shifted, Turns};
use crate::integrate::{Dop853, Stats, StepControl};
use crate::Real;

/// Resolution of the stick test: the sticking pendulum's force is checked this many times per
/// drive period (or per natural period, if shorter), then the release time is bisected.
const STICK_CHECKS_PER_PERIOD: f64 = 128.0;

/// A constant state, the interpolant of a sticking pendulum.
struct Still(f64);

impl Interpolant for Still {
    fn at(&mut self, _t: f64) -> (f64, f64) {
        (self.0, 0.0)
    }
}

/// Runs the full equation with Coulomb friction μ (rad/s²) and viscous c.
pub(super) fn run<'r, R: Real, D: DriveSignal<R>, Rec: Recorder>(
    eom: FullEom<R, D, NoExtra>,
    c: R,
    mu: f64,
    ctx: &Context,
    rec: &'r mut Rec,
) -> Result<RunOut<'r, Rec>, SimError> {
    let Method::Dop853 { rtol, atol } = ctx.method else {
        return Err(SimError::Unsupported(
            "Coulomb friction needs event location: use method = \"dop853\"",
        ));
    };
    let mut solver = Dop853::new(rtol, atol);
    solver.h_max = 16.0 * ctx.period;
    solver.max_steps = u64::MAX;
    let mut sampler = Sampler::new(
        ctx.schedule,
        ctx.strobes_total,
        ctx.out_dt,
        ctx.sensor.clone(),
        ctx.t_end,
        ctx.classify,
        rec,
    );
    sampler.start(ctx.y0.0, ctx.y0.1);
    let natural = crate::math::TAU / crate::math::sqrt(eom.omega0_sq.to_f64());
    let check_dt = ctx.period.min(natural) / STICK_CHECKS_PER_PERIOD;
    let held = |t: f64, theta: R| eom.conservative(t, theta).to_f64();

    let mut work = Stats::default();
    let mut sticks = 0u64;
    // θ is kept reduced by whole turns, as in every smooth run (see `turns`).
    let mut turns = Turns::new(true);
    let (mut t, mut theta, mut rate) = (0.0, turns.reduce(ctx.y0.0), ctx.y0.1);
    let mut stalled = 0u32;
    while t < ctx.t_end {
        let offset = turns.offset();
        let direction = if rate != 0.0 {
            rate.signum()
        } else {
            let a = held(t, R::from_f64(theta));
            if a.abs() <= mu {
                sticks += 1;
                let force = |s: f64| held(s, R::from_f64(theta));
                let still = (theta, offset);
                t = stick(t, still, mu, check_dt, ctx.t_end, &force, &mut sampler);
                if t >= ctx.t_end {
                    break;
                }
                force(t).signum()
            } else {
                a.signum()
            }
        };
        let sliding = eom.with_extra(Sliding {
            c,
            friction: R::from_f64(-mu * direction),
        });
        let y0 = [R::from_f64(theta), R::from_f64(rate)];
        let start = t;
        let mut stopped = false;
        let sol = solver.solve(&sliding, t, y0, ctx.t_end, |step| {
            let stop = step.find_crossing(|_, y| y[1].to_f64() * direction);
            let t1 = stop.unwrap_or(step.t1);
            let end = if stop.is_some() {
                step.eval(t1)
            } else {
                step.y1
            };
            let (theta, rate) = (end[0].to_f64(), end[1].to_f64());
            sampler.step(
                t1,
                (theta + offset, rate),
                &mut Shifted(Dense(step), offset),
            );
            stopped = stop.is_some();
            match stop {
                Some(t1) => StepControl::StopAt(t1),
                // Whole turns out of θ, then the same sliding segment goes on.
                None if turns.due(step.y1[0]) => StepControl::Stop,
                None => StepControl::Continue,
            }
        })?;
        work.add(sol.stats);
        t = sol.t;
        theta = turns.reduce(sol.y[0].to_f64());
        rate = if stopped && t < ctx.t_end {
            0.0
        } else {
            sol.y[1].to_f64()
        };
        // A segment that ends where it began would loop for ever: treat it as sticking.
        stalled = if t - start <= 1e-12 * t.abs().max(1.0) {
            stalled + 1
        } else {
            0
        };
        if stalled > 3 {
            return Err(SimError::Unsupported(
                "Coulomb friction: sliding segments of zero length (stick–slip did not resolve)",
            ));
        }
    }
    Ok(RunOut {
        sampler,
        work,
        end: (t, theta + turns.offset(), rate),
        sticks: Some(sticks),
    })
}

/// Holds the pendulum at θ (reduced, with its turns' offset) from t0 until |a(t)| > μ (or the
/// run ends), feeding the sampler the still state; returns the release time, bisected between
/// checks. Check times are t0 + i·dt, computed afresh.
fn stick<Rec: Recorder>(
    t0: f64,
    (theta, offset): (f64, f64),
    mu: f64,
    dt: f64,
    t_end: f64,
    force: &dyn Fn(f64) -> f64,
    sampler: &mut Sampler<'_, Rec>,
) -> f64 {
    let shown = theta + offset;
    let mut t = t0;
    let mut checks = 0u64;
    while t < t_end {
        checks += 1;
        let t1 = (t0 + checks as f64 * dt).min(t_end);
        if force(t1).abs() > mu {
            // |a| − μ is ≤ 0 at t and > 0 at t1.
            let release = crate::math::bisect(|s| force(s).abs() - mu, t, t1, -1.0);
            sampler.step(release, (shown, 0.0), &mut Still(shown));
            return release;
        }
        sampler.step(t1, (shown, 0.0), &mut Still(shown));
        t = t1;
    }
    t
}
