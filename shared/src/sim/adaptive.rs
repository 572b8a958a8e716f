//! The full or the averaged equation by an adaptive RKN pair ([`AdaptiveRkn`]): `run.method =
//! "rkn86"` on the averaged equation, `"rkn1210"` on either.
//!
//! The averaged equation φ'' = −ω0² [sin φ + (R_eff σ(t)/2) sin 2(φ − θd)] − c φ' has no drive
//! term, so no drive period sets its step: the step follows the slow motion alone. The full
//! equation by 12(10) is for runs whose time scale is not the drive's (chaotic transients, a
//! drive off or ramping). Damping by the change of variable of [`crate::integrate::rkn`].
//!
//! No libm sin/cos of the angle per evaluation: a step computes sin θ0, cos θ0 once at its
//! start. On the averaged equation with a drive of constant strength it also expands the whole
//! force about θ0 ([`SlowSeries`]), and a stage at θ0 + δ costs two short polynomials in δ².
//! Otherwise a stage uses the angle-addition formulas with sin δ and cos δ from their Taylor
//! polynomials (to δ¹³ and δ¹⁴: below 3e-17 for |δ| ≤ 1/2). Either way a larger δ, a step that
//! turns the pendulum by more than half a radian, falls back to libm. The full equation's drive
//! term is the drive signal's own (one cos per stage: its stage times change with every step,
//! so no table can hold them).
//!
//! Samples between step ends (strobes, period means, output) come from the step's quintic
//! Hermite interpolant ([`Span`]), without evaluations.

use super::eom::{AveragedEom, FullEom, NoExtra};
use super::run::{Context, RunOut, SimError};
use super::sampling::{Interpolant, Recorder, Sink};
use super::signal::DriveSignal;
use super::slow_series::{self, SlowSeries};
use super::turns::{Shifted, Turns};
use crate::integrate::rkn::Pair;
use crate::integrate::{Accel, AdaptiveRkn, Span, Stats};
use crate::Real;

/// Beyond this |δ| (rad) the polynomials give way to libm.
const SMALL: f64 = 0.5;

/// (sin δ, cos δ) for |δ| ≤ [`SMALL`]: Taylor polynomials, error < 3e-17. Evaluated in
/// Estrin's scheme (powers u, u², u⁴ of u = δ² and independent pairs) rather than Horner's:
/// every stage waits for the previous one's g, so the latency of this chain is the cost.
#[inline(always)]
fn sin_cos_small<R: Real>(d: R) -> (R, R) {
    let c = |x: f64| R::from_f64(x);
    let u = d * d;
    let u2 = u * u;
    let u4 = u2 * u2;
    // sin δ / δ = Σ (−u)^k/(2k+1)!, k ≤ 6
    let s01 = R::ONE + c(-1.0 / 6.0) * u;
    let s23 = c(1.0 / 120.0) + c(-1.0 / 5040.0) * u;
    let s45 = c(1.0 / 362_880.0) + c(-1.0 / 39_916_800.0) * u;
    let s6 = c(1.0 / 6_227_020_800.0);
    let sin = d * ((s01 + u2 * s23) + u4 * (s45 + u2 * s6));
    // cos δ = Σ (−u)^k/(2k)!, k ≤ 7
    let c01 = R::ONE + c(-0.5) * u;
    let c23 = c(1.0 / 24.0) + c(-1.0 / 720.0) * u;
    let c45 = c(1.0 / 40_320.0) + c(-1.0 / 3_628_800.0) * u;
    let c67 = c(1.0 / 479_001_600.0) + c(-1.0 / 87_178_291_200.0) * u;
    let cos = (c01 + u2 * c23) + u4 * (c45 + u2 * c67);
    (sin, cos)
}

/// (sin θ, cos θ) at θ = θ0 + d inside a step that started at θ0 with (sin θ0, cos θ0).
#[inline(always)]
fn sin_cos_near<R: Real>(&(s0, c0): &(R, R), theta: R, d: R) -> (R, R) {
    if d.abs().to_f64() <= SMALL {
        let (sd, cd) = sin_cos_small(d);
        (s0 * cd + c0 * sd, c0 * cd - s0 * sd)
    } else {
        theta.sin_cos()
    }
}

/// The averaged equation's conservative part seen by the adaptive run: damping is the
/// integrator's.
pub(super) struct Slow<'e, R: Real, D: DriveSignal<R>>(pub &'e AveragedEom<R, D, NoExtra>);

/// What a step of the averaged equation computes at its start.
#[derive(Clone, Copy)]
pub(super) struct SlowBase<R> {
    /// sin φ0, cos φ0.
    sc: (R, R),
    /// The force about φ0, when the drive's strength is constant ([`SlowSeries`]).
    series: Option<SlowSeries<R>>,
}

impl<R: Real, D: DriveSignal<R>> Accel<R> for Slow<'_, R, D> {
    type Base = SlowBase<R>;

    fn autonomous(&self) -> bool {
        self.0.drive().constant_strength()
    }

    #[inline(always)]
    fn base(&self, t0: f64, phi0: R) -> SlowBase<R> {
        let (s, c) = phi0.sin_cos();
        SlowBase {
            sc: (s, c),
            series: self.autonomous().then(|| self.0.series(t0, s, c)),
        }
    }

    #[inline(always)]
    fn accel(&self, base: &SlowBase<R>, t: f64, phi: R, d: R) -> R {
        match &base.series {
            Some(series) if d.abs().to_f64() <= slow_series::REACH => series.at(d),
            _ => {
                let (s, c) = sin_cos_near(&base.sc, phi, d);
                self.0.conservative_sc(t, s, c)
            }
        }
    }

    #[inline(always)]
    fn at_start(&self, base: &SlowBase<R>, t0: f64, phi0: R) -> R {
        match &base.series {
            Some(series) => series.at_zero(),
            None => self.accel(base, t0, phi0, R::ZERO),
        }
    }

    #[inline(always)]
    fn accel_then(&self, base: &SlowBase<R>, t: f64, phi: R, d: R, next: (R, R)) -> (R, R) {
        match &base.series {
            Some(series) if d.abs().to_f64() <= slow_series::REACH => series.at_then(d, next),
            _ => {
                let g = self.accel(base, t, phi, d);
                (g, next.1 + next.0 * g)
            }
        }
    }
}

/// The full equation's conservative part (gravity and drive) seen by the adaptive run.
pub(super) struct Fast<'e, R: Real, D: DriveSignal<R>>(pub &'e FullEom<R, D, NoExtra>);

impl<R: Real, D: DriveSignal<R>> Accel<R> for Fast<'_, R, D> {
    /// sin θ0, cos θ0.
    type Base = (R, R);

    fn autonomous(&self) -> bool {
        false
    }

    #[inline(always)]
    fn base(&self, _t0: f64, theta0: R) -> (R, R) {
        theta0.sin_cos()
    }

    #[inline(always)]
    fn accel(&self, base: &(R, R), t: f64, theta: R, d: R) -> R {
        let (s, c) = sin_cos_near(base, theta, d);
        self.0.conservative_sc(self.0.drive.accel(t), s, c)
    }
}

/// The step's interpolant as the sampler reads it.
struct Between<R>(Span<R>);

impl<R: Real> Interpolant for Between<R> {
    fn at(&mut self, t: f64) -> (f64, f64) {
        self.0.eval(t)
    }
}

/// Runs `sys` (gravity and drive of the full or averaged equation) by `pair` with viscous
/// damping c.
pub(super) fn run<'r, R: Real, A: Accel<R>, Rec: Recorder, const S: usize>(
    sys: A,
    pair: &'static Pair<S>,
    c: f64,
    (rtol, atol): (f64, f64),
    ctx: &Context,
    rec: Sink<'r, Rec>,
) -> Result<RunOut<'r, Rec>, SimError> {
    let mut sampler = ctx.sampler(rec);
    let mut turns = Turns::new(ctx.periodic);
    let mut solver = AdaptiveRkn::new(rtol, atol);
    solver.beta = ctx.beta;
    let mut y = (turns.reduce(R::from_f64(ctx.y0.0)), R::from_f64(ctx.y0.1));
    let mut t = 0.0;
    let mut work = Stats::default();
    while t < ctx.t_end {
        let offset = turns.offset();
        let mut last_h = None;
        let sol = solver.solve_with(pair, &sys, c, t, y, ctx.t_end, |span| {
            let end = (span.y1.0.to_f64() + offset, span.y1.1.to_f64());
            sampler.step(span.t1, end, &mut Shifted(Between(*span), offset));
            last_h = Some(span.t1 - span.t0);
            turns.due(span.y1.0)
        })?;
        work.add(sol.stats);
        (t, y) = (sol.t, sol.y);
        y.0 = turns.reduce(y.0);
        solver.h_init = last_h;
    }
    Ok(RunOut {
        sampler,
        work,
        end: turns.end_state(t, y.0, y.1),
        sticks: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_angle_polynomials_match_libm() {
        // Against libm's sin/cos (correctly rounded to ~1 ulp) over |δ| ≤ 1/2.
        for i in -500..=500 {
            let d = f64::from(i) * 1e-3;
            let (s, c) = sin_cos_small(d);
            assert!((s - libm::sin(d)).abs() < 2e-16, "sin {d}");
            assert!((c - libm::cos(d)).abs() < 2e-16, "cos {d}");
        }
    }

    #[test]
    fn a_slow_stage_is_the_averaged_force_inside_and_beyond_the_series_reach() {
        // Slow's stage value against the averaged equation's closed form with libm's sin/cos
        // (the tilted scene's ω0² = 73.6, R = 3.3, θd = 135°), for stage offsets on both
        // sides of the series' reach (1/2 rad: beyond it, the angle-addition path): within
        // 1e-14 of ω0² R (a few ulps of the terms' size).
        use crate::model::DriveAngle;
        use crate::sim::signal::{Schedule, Shaped, Steady};
        let (w0sq, r) = (73.6, 3.3);
        let angle = DriveAngle::from_deg(135.0).unwrap();
        fn check<D: DriveSignal<f64>>(eom: &AveragedEom<f64, D, NoExtra>, w0sq: f64, r: f64) {
            let slow = Slow(eom);
            assert!(slow.autonomous());
            for phi0 in [-2.5, 0.3, 2.08, 3.0] {
                let base = slow.base(0.0, phi0);
                for i in -40..=40 {
                    let d = 0.02 * f64::from(i);
                    let (s, c) = libm::sincos(phi0 + d);
                    let want = eom.conservative_sc(0.0, s, c);
                    let got = slow.accel(&base, 0.0, phi0 + d, d);
                    assert!(
                        (got - want).abs() < 1e-14 * w0sq * r,
                        "φ0 {phi0} d {d}: {got} vs {want}"
                    );
                }
            }
        }
        let steady = Steady::new(0.0445, 330.0);
        check(&AveragedEom::new(w0sq, r, angle, steady, NoExtra), w0sq, r);
        // With a slider-crank on a 30 mm connecting rod (a2/ℓ = A²/(4bℓ) = 0.0445 · 0.0089/0.12):
        // the push's harmonics in the series too.
        let schedule = Schedule {
            omega: 330.0,
            ramp: None,
            lag: None,
        };
        let shaped = Shaped::new(0.0445, 0.0445 * 0.0089 / 0.12, schedule);
        check(&AveragedEom::new(w0sq, r, angle, shaped, NoExtra), w0sq, r);
    }

    #[test]
    fn the_averaged_force_with_a_push_is_the_slider_crank_balance() {
        // AveragedEom's closed form with the push against model::slider_crank's slow torque
        // (its other form, sin u (cos²u − ½ sin²u)), both ×ω0²: the demo rod on a 12.7 mm crank
        // and a 60 mm rod at first-harmonic R = 1.75, θd = 90°, to rounding.
        // The push comes from the drive signal's harmonics (a1/ℓ, a2/ℓ, W), the balance's from
        // the crank's dimensions and R: two routes to ω0²κ/8.
        use crate::model::slider_crank::{slow_torque, SliderCrank};
        use crate::model::DriveAngle;
        use crate::sim::signal::{Schedule, Shaped};
        let crank = SliderCrank {
            amplitude: 0.0127,
            rod: 0.06,
            ell: 0.25 * 2.0 / 3.0,
        };
        let (w0sq, r1) = (9.81 / crank.ell, 1.75);
        let schedule = Schedule {
            // R = A²W²/(2gℓ)
            omega: (2.0 * 9.81 * crank.ell * r1).sqrt() / crank.amplitude,
            ramp: None,
            lag: None,
        };
        let a1 = crank.amplitude / crank.ell;
        let a2 = crank.amplitude * crank.amplitude / (4.0 * crank.rod) / crank.ell;
        let angle = DriveAngle::from_deg(90.0).unwrap();
        let eom = AveragedEom::new(
            w0sq,
            r1 * crank.strength_gain(),
            angle,
            Shaped::new(a1, a2, schedule),
            NoExtra,
        );
        for i in -31..=31 {
            let phi = 0.1 * f64::from(i);
            let (s, c) = libm::sincos(phi);
            let want = w0sq * slow_torque(phi, angle.rad(), r1, Some(&crank));
            let got = eom.conservative_sc(0.0, s, c);
            assert!(
                (got - want).abs() < 1e-13 * w0sq,
                "φ {phi}: {got} vs {want}"
            );
        }
    }
}
