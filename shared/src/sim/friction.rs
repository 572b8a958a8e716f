//! Coulomb friction without chattering: sliding segments and sticking, switched at events.
//!
//! ```text
//! sliding (θ' ≠ 0):   θ'' = a(t, θ) − c θ' − μ s,   s = sign θ' fixed for the segment
//! at θ' = 0:          a(t, θ) = −ω0² sin θ + (s̈/ℓ) sin(θ − θd)   (what static friction must hold)
//!                     |a| ≤ μ → stick;  else slide with s = sign a
//! sticking:           θ' = 0, θ fixed, until |a(t, θ)| > μ; then slide with s = sign a
//! ```
//! Each sliding segment is smooth, so the adaptive method keeps its order; its end is located on
//! the dense output (θ' turns against the segment's direction), never by a step landing near
//! zero. Two things make that search more than a sign test at the step's ends:
//!
//! ```text
//! start:   a segment starts at θ' = 0, moving the way of s: g = s θ' is taken as > 0 there,
//!          else the first step, whose g(t0) = 0, could never show a sign change
//! inside:  g is probed on the dense output at PROBES points per step, so a step whose ends both
//!          have g > 0 but that dips below zero between them (a double crossing) is caught
//! ```
//! The first probe with g ≤ 0 ends the search, and the reversal is bisected between it and the
//! probe before it. Under a strong drive θ' (which includes the fast wobble) changes sign twice a
//! period and friction acts like weak damping; sticking needs φ near θd or a weak drive
//! (physics §5).

use super::eom::{FullEom, NoExtra, Sliding};
use super::run::{Context, Dense, Method, RunOut, SimError};
use super::sampling::{Interpolant, Recorder, Sampler, Sink};
use super::signal::DriveSignal;
use super::turns::{Shifted, Turns};
use crate::integrate::{Dop853, Stats, Step, StepControl};
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
    rec: Sink<'r, Rec>,
) -> Result<RunOut<'r, Rec>, SimError> {
    let Method::Dop853 { rtol, atol } = ctx.method else {
        return Err(SimError::Unsupported(
            "Coulomb friction needs event location: use method = \"dop853\"",
        ));
    };
    let mut solver = Dop853::new(rtol, atol);
    solver.h_max = 16.0 * ctx.period;
    solver.max_steps = u64::MAX;
    let mut sampler = ctx.sampler(rec);
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
            let stop = reversal(step, direction);
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
        end: turns.end_state(t, theta, rate),
        sticks: Some(sticks),
    })
}

/// Dense-output probes per step in the search for a reversal: a double crossing is missed only
/// if both its roots fall between two probes, h/16 apart.
const PROBES: u32 = 16;

/// The first time in the step where θ' turns against `direction` (the sign of the segment's
/// motion), or `None`. θ'(t0) counts as moving with `direction`, whatever its value: it is 0 at
/// a segment's start and of that sign elsewhere in the segment. Costs the dense output (three
/// evaluations) on every step, and nothing more.
fn reversal<R: Real>(step: &Step<'_, 2, R>, direction: f64) -> Option<f64> {
    let g = |y: &[R; 2]| y[1].to_f64() * direction;
    let h = step.h();
    let mut before = step.t0;
    for i in 1..=PROBES {
        let (t, gt) = if i == PROBES {
            (step.t1, g(&step.y1))
        } else {
            let t = step.t0 + h * f64::from(i) / f64::from(PROBES);
            (t, g(&step.eval(t)))
        };
        if gt == 0.0 {
            return Some(t);
        }
        if gt < 0.0 {
            // g > 0 at `before` (taken so at t0), < 0 at t.
            let (lo, hi) = if h > 0.0 { (before, t) } else { (t, before) };
            let g_lo = if h > 0.0 { 1.0 } else { -1.0 };
            return Some(crate::math::bisect(|s| g(&step.eval(s)), lo, hi, g_lo));
        }
        before = t;
    }
    None
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Dop853, System};

    /// θ'' = −θ + f: a harmonic oscillator (ω0 = 1) pushed by a constant force f, whose rate is
    /// θ'(t) = (f − θ0) sin t + θ0' cos t (closed form).
    struct Pushed(f64);

    impl System<2> for Pushed {
        fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = y[1];
            dy[1] = -y[0] + self.0;
        }
    }

    /// The first accepted step of a run from `y0` with first step `h`, and the reversal found in
    /// it.
    fn first_step(sys: &Pushed, y0: [f64; 2], h: f64, direction: f64) -> (f64, Option<f64>) {
        let mut solver = Dop853::new(1e-2, 1e-2);
        solver.h_init = Some(h);
        let mut seen = None;
        solver
            .solve(sys, 0.0, y0, 10.0, |step| {
                seen = Some((step.t1, reversal(step, direction)));
                StepControl::Stop
            })
            .unwrap();
        seen.unwrap()
    }

    #[test]
    fn reversal_in_the_first_step_of_a_segment() {
        // Released from rest at θ = 0 with f = 1: θ' = sin t, which turns negative at t = π
        // (closed form). A first step of 3.5 contains that reversal, and its start has θ' = 0.
        let (t1, found) = first_step(&Pushed(1.0), [0.0, 0.0], 3.5, 1.0);
        assert!(
            t1 > core::f64::consts::PI,
            "the step must contain the reversal: {t1}"
        );
        let t = found.expect("the reversal inside the segment's first step is found");
        // The dense output's rate is good to a few tolerances (1e-2) at rtol = atol = 1e-2, and
        // |θ''| = 1 at the root, so the root lies within 5e-2 of π.
        assert!((t - core::f64::consts::PI).abs() < 5e-2, "{t}");
    }

    #[test]
    fn double_crossing_inside_one_step() {
        // From θ = 1, θ' = 0.1, f = 0: θ' = 0.1 cos t − sin t (closed form) is positive at t = 0,
        // negative on (0.0997, π + 0.0997) and positive again at t = 3.3 (0.059): both ends of a
        // step [0, 3.3] are positive, the reversal at atan(0.1) = 0.0997 lies inside.
        let (t1, found) = first_step(&Pushed(0.0), [1.0, 0.1], 3.3, 1.0);
        assert!(
            (t1 - 3.3).abs() < 1e-12,
            "the first step must be accepted whole: {t1}"
        );
        let t = found.expect("a double crossing inside one step is found");
        // As above, |θ''| ≈ 1 at the root: within 5e-2 of it.
        assert!((t - libm::atan(0.1)).abs() < 5e-2, "{t}");
    }
}
