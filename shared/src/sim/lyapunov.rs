//! The finite-time Lyapunov exponent over the analysis window, from a pair of trajectories.
//!
//! ```text
//! start both at the window's first strobe, the second displaced by d0 in θ;
//! each drive period: d_k = √(Δθ² + (Δθ'/ω)²),  S += ln(d_k/d0),  rescale the displacement to d0
//! λ = S / (t_end − t_start)                                      (Benettin et al. 1980)
//! ```
//! d0 = 10√ε of the number format keeps the pair inside the linear regime yet above rounding.
//! Both trajectories use DOP853 at a tight tolerance whatever the run's method, so λ measures the
//! dynamics, not the integrator.

use super::run::{Context, Job};
use super::sampling::strobe_time;
use super::turns::Turns;
use crate::integrate::{Dop853, Stats, System};
use crate::{math, Real};

/// Two copies of one equation, integrated together.
#[derive(Clone, Copy)]
struct Pair<S>(S);

impl<R: Real, S: System<2, R>> System<4, R> for Pair<S> {
    fn rhs(&self, t: f64, y: &[R; 4], dy: &mut [R; 4]) {
        let (mut a, mut b) = ([R::ZERO; 2], [R::ZERO; 2]);
        self.0.rhs(t, &[y[0], y[1]], &mut a);
        self.0.rhs(t, &[y[2], y[3]], &mut b);
        *dy = [a[0], a[1], b[0], b[1]];
    }
}

/// The Lyapunov run as a [`Job`]: from the window's first strobe (k, t, θ, θ') to the last.
pub(super) struct Exponent<'c> {
    pub ctx: &'c Context,
    pub start: (u64, f64, f64, f64),
}

impl<R: Real> Job<R> for Exponent<'_> {
    type Out = (f64, Stats);

    fn run<S: System<2, R> + Copy>(self, sys: S) -> (f64, Stats) {
        let (k0, t0, theta, rate) = self.start;
        let theta = Turns::new(self.ctx.periodic).reduce(theta);
        let omega = self.ctx.omega;
        let d0 = 10.0 * math::sqrt(R::EPSILON.to_f64());
        let pair = Pair(sys);
        let solver = Dop853::new(1e-10, 1e-10);
        let mut stats = Stats::default();
        let mut y = [
            R::from_f64(theta),
            R::from_f64(rate),
            R::from_f64(theta + d0),
            R::from_f64(rate),
        ];
        let (mut t, mut sum) = (t0, 0.0);
        for k in k0 + 1..=self.ctx.strobes_total {
            let t1 = strobe_time(&self.ctx.schedule, k);
            let Ok(sol) = solver.integrate(&pair, t, y, t1) else {
                return (0.0, stats);
            };
            stats.add(sol.stats);
            let dth = (sol.y[2] - sol.y[0]).to_f64();
            let dv = (sol.y[3] - sol.y[1]).to_f64() / omega;
            let d = math::sqrt(dth * dth + dv * dv);
            if !(d > 0.0 && d.is_finite()) {
                return (0.0, stats);
            }
            sum += libm::log(d / d0);
            let scale = d0 / d;
            // Only the difference matters: whole turns come out of the reference angle.
            let theta = Turns::new(self.ctx.periodic).reduce(sol.y[0]);
            y = [
                theta,
                sol.y[1],
                theta + R::from_f64(dth * scale),
                sol.y[1] + R::from_f64(dv * omega * scale),
            ];
            t = t1;
        }
        if t > t0 {
            (sum / (t - t0), stats)
        } else {
            (0.0, stats)
        }
    }
}
