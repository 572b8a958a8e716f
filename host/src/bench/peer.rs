//! The peer: the `ode_solvers` crate's Dopri5 and Dop853 on exactly our full equation.
//!
//! The right-hand side the peer integrates *is* the simulator's [`FullEom`] (gravity g_eff, the
//! steady drive −(A/ℓ)ω² cos(ωt) sin(θ − θd), viscous c θ' when the scene has it), wrapped into
//! `ode_solvers::System`, so both sides pay for the same sin/cos per evaluation. Evaluations are
//! counted by a counter in the wrapper during an untimed run; the timed runs use a wrapper
//! without the counter.
//!
//! The crate's Dop853 (0.6.2) evaluates its 12th stage at t instead of t + h (its node c₁₂ is
//! 0, not 1; upstream pull request #42), which is invisible on autonomous systems but breaks it
//! on ours, whose drive depends on t: its error estimate stays large, the step collapses and it
//! stops with "the problem seems to become stiff" within the first drive period. It is run as
//! published (and its failure recorded), and also in autonomous form — time carried as a third
//! state component with t' = 1, so the wrong node no longer matters — which is the peer's
//! working Dop853. The third component adds no evaluation of the acceleration and only rescales
//! the error norm (its RMS over 3 components instead of 2).
//!
//! Configuration (fair, and what its API forces):
//! * the crate's own defaults for the controller (Dopri5: safety 0.9, β = 0.04, step factor in
//!   [0.2, 10]; Dop853: safety 0.9, β = 0, factor in [1/3, 6]), its own starting-step guess,
//!   rtol = atol as for ours;
//! * no step limit (`n_max` = u32::MAX; the default 100 000 stops long runs);
//! * `OutputType::Sparse`: the crate then stores (t, y) of every accepted step in a `Vec` — its
//!   API has no "end state only" mode. The alternative, `Dense` with `dx` = the whole interval,
//!   stores two points but computes the dense-output coefficients every step, which for Dop853
//!   costs 3 more evaluations per step (+25 %); Sparse is the cheaper of the two on both counts,
//!   so the peer runs with it and its time includes that storage (24 bytes per step).

use anyhow::{anyhow, bail, Result};
use ode_solvers::{Dop853, Dopri5, OutputType, Vector2, Vector3};
use std::cell::Cell;
use std::time::Duration;

use super::measure::{error, Family, Point, Reference};
use super::scenes::BenchScene;
use crate::timing;
use kapitza_core::integrate::System;
use kapitza_core::sim::eom::{FullEom, NoExtra, Viscous};
use kapitza_core::sim::signal::Steady;
use kapitza_core::sim::{Format, Scene};

/// Counts evaluations, or not.
trait Tally {
    fn tick(&self);
}

struct NoTally;

impl Tally for NoTally {
    #[inline(always)]
    fn tick(&self) {}
}

impl Tally for Cell<u64> {
    #[inline(always)]
    fn tick(&self) {
        self.set(self.get() + 1);
    }
}

/// Our equation as an `ode_solvers::System`.
struct Rhs<'t, S, T> {
    eom: S,
    tally: &'t T,
}

impl<S: System<2, f64>, T: Tally> ode_solvers::System<f64, Vector2<f64>> for Rhs<'_, S, T> {
    #[inline]
    fn system(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        self.tally.tick();
        let mut d = [0.0; 2];
        self.eom.rhs(t, &[y[0], y[1]], &mut d);
        dy[0] = d[0];
        dy[1] = d[1];
    }
}

/// Our equation with time as a third state component (y[2] = t, t' = 1).
struct Autonomous<'t, S, T> {
    eom: S,
    tally: &'t T,
}

impl<S: System<2, f64>, T: Tally> ode_solvers::System<f64, Vector3<f64>> for Autonomous<'_, S, T> {
    #[inline]
    fn system(&self, _x: f64, y: &Vector3<f64>, dy: &mut Vector3<f64>) {
        self.tally.tick();
        let mut d = [0.0; 2];
        self.eom.rhs(y[2], &[y[0], y[1]], &mut d);
        dy[0] = d[0];
        dy[1] = d[1];
        dy[2] = 1.0;
    }
}

/// What one peer run gives back.
struct PeerRun {
    end: (f64, f64),
    steps: u64,
    rejected: u64,
    /// The crate's own evaluation count.
    evals_reported: u64,
}

fn solve<S: System<2, f64> + Copy, T: Tally>(
    family: Family,
    eom: S,
    tally: &T,
    t_end: f64,
    y0: (f64, f64),
    tol: f64,
) -> Result<PeerRun> {
    let f = Rhs { eom, tally };
    let y = Vector2::new(y0.0, y0.1);
    let last2 = |x: &[f64], y: &[Vector2<f64>]| -> Result<(f64, (f64, f64))> {
        match (x.last(), y.last()) {
            (Some(&t), Some(v)) => Ok((t, (v[0], v[1]))),
            _ => bail!("the peer stored no output"),
        }
    };
    let (stats, last) = match family {
        Family::PeerDopri5 => {
            let mut s = Dopri5::from_param(
                f,
                0.0,
                t_end,
                t_end,
                y,
                tol,
                tol,
                0.9,
                0.04,
                0.2,
                10.0,
                t_end,
                0.0,
                u32::MAX,
                1000,
                OutputType::Sparse,
            );
            let stats = s.integrate().map_err(|e| anyhow!("{e}"))?;
            (stats, last2(s.x_out(), s.y_out())?)
        }
        Family::PeerDop853 => {
            let mut s = Dop853::from_param(
                f,
                0.0,
                t_end,
                t_end,
                y,
                tol,
                tol,
                0.9,
                0.0,
                0.333,
                6.0,
                t_end,
                0.0,
                u32::MAX,
                1000,
                OutputType::Sparse,
            );
            let stats = s.integrate().map_err(|e| anyhow!("{e}"))?;
            (stats, last2(s.x_out(), s.y_out())?)
        }
        Family::PeerDop853Autonomous => {
            let f = Autonomous { eom, tally };
            let mut s = Dop853::from_param(
                f,
                0.0,
                t_end,
                t_end,
                Vector3::new(y0.0, y0.1, 0.0),
                tol,
                tol,
                0.9,
                0.0,
                0.333,
                6.0,
                t_end,
                0.0,
                u32::MAX,
                1000,
                OutputType::Sparse,
            );
            let stats = s.integrate().map_err(|e| anyhow!("{e}"))?;
            let last = match (s.x_out().last(), s.y_out().last()) {
                (Some(&t), Some(v)) => (t, (v[0], v[1])),
                _ => bail!("the peer stored no output"),
            };
            (stats, last)
        }
        _ => bail!("{} is not the peer", family.name()),
    };
    let (t, end) = last;
    if (t - t_end).abs() > 1e-9 * t_end.max(1.0) {
        bail!("the peer stopped at t = {t}, not at {t_end}");
    }
    Ok(PeerRun {
        end,
        steps: u64::from(stats.accepted_steps),
        rejected: u64::from(stats.rejected_steps),
        evals_reported: u64::from(stats.num_eval),
    })
}

/// The full equation of a scene, as the simulator composes it for a steady drive.
enum Equation {
    Undamped(FullEom<f64, Steady<f64>, NoExtra>),
    Damped(FullEom<f64, Steady<f64>, Viscous<f64>>),
}

fn equation(scene: &Scene) -> Result<Equation> {
    let e = &scene.effects;
    if e.ramp.is_some()
        || e.actuator.is_some()
        || e.slider_crank.is_some()
        || e.coulomb.is_some()
        || e.sensor.is_some()
    {
        bail!("the peer runs only the steady drive with gravity and viscous damping");
    }
    let p = scene.physical()?;
    let drive = Steady::new(p.amplitude / p.ell, p.omega);
    let w0sq = p.omega0 * p.omega0;
    let angle = scene.drive.angle;
    Ok(if p.c > 0.0 {
        Equation::Damped(FullEom::new(w0sq, angle, drive, Viscous { c: p.c }))
    } else {
        Equation::Undamped(FullEom::new(w0sq, angle, drive, NoExtra))
    })
}

fn run_with<T: Tally>(family: Family, scene: &Scene, tally: &T, tol: f64) -> Result<PeerRun> {
    let p = scene.physical()?;
    let t_end = scene.duration(p.omega);
    let y0 = (scene.initial_angle, scene.initial_rate);
    match equation(scene)? {
        Equation::Undamped(eom) => solve(family, eom, tally, t_end, y0, tol),
        Equation::Damped(eom) => solve(family, eom, tally, t_end, y0, tol),
    }
}

/// One peer point: an untimed run with the evaluation counter for the error and work, then the
/// median time of runs without it.
pub fn peer(
    s: &BenchScene,
    reference: &Reference,
    family: Family,
    tol: f64,
    batch: Duration,
    notes: &mut Vec<String>,
) -> Result<Point> {
    let omega = s.scene.physical()?.omega;
    let counter = Cell::new(0u64);
    let r = run_with(family, &s.scene, &counter, tol)?;
    let err = error(r.end, (reference.theta, reference.rate), omega);
    if !err.is_finite() {
        bail!("the end state is not finite");
    }
    let evals = counter.get();
    if evals != r.evals_reported {
        // Not an error: the crate's count is informational; the counted one is reported.
        notes.push(format!(
            "{} at {tol:e} on {}: counted {evals} evaluations, the crate reports {}",
            family.name(),
            s.name,
            r.evals_reported
        ));
    }
    let cost = timing::cost(batch, || run_with(family, &s.scene, &NoTally, tol));
    Ok(Point {
        scene: s.name.to_string(),
        family,
        who: family.who(),
        fidelity: family.fidelity(),
        format: Format::F64,
        setting_name: family.setting_name(),
        setting: tol,
        error: err,
        wall_s: cost.wall_s,
        cpu_s: cost.cpu_s,
        rhs_evals: evals,
        steps: r.steps,
        rejected: r.rejected,
    })
}

/// Median CPU time of one evaluation of the scene's full right-hand side, for judging how much
/// of a run's time is the equation itself.
pub fn rhs_cost(scene: &Scene, batch: Duration) -> Result<f64> {
    fn time<S: System<2, f64>>(eom: S, batch: Duration) -> f64 {
        let mut k = 0u32;
        timing::cost(batch, || {
            k = k.wrapping_add(1);
            let t = std::hint::black_box(1e-3 * f64::from(k % 1000));
            let y = std::hint::black_box([2.0, 0.5]);
            let mut d = [0.0; 2];
            eom.rhs(t, &y, &mut d);
            d
        })
        .cpu_s
    }
    Ok(match equation(scene)? {
        Equation::Undamped(eom) => time(eom, batch),
        Equation::Damped(eom) => time(eom, batch),
    })
}
