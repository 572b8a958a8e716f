//! The equation of a planned run, built once as a concrete type for the decided fidelity with
//! exactly the listed forces, handed to the loop that steps it, then the outcome classified.
//!
//! The drive signal ([`crate::sim::signal::Steady`] or [`crate::sim::signal::Shaped`]), the extra
//! forces ([`NoExtra`] or [`Viscous`]) and the number format are type parameters, so the inner
//! loop of a scene carries no test or evaluation for an effect it does not list. Coulomb friction
//! switches between sliding segments and sticking, so it has its own loop
//! ([`crate::sim::friction`]); the RKN methods have theirs ([`crate::sim::periodic`],
//! [`crate::sim::adaptive`]).

use super::plan::PlannedRun;
use super::stepping::integrate;
use super::{EndState, Method, Report, SimError};
use crate::integrate::rkn::{RKN1210, RKN86};
use crate::integrate::{Stats, System};
use crate::real::Real;
use crate::sim::adaptive::{self, Fast, Slow};
use crate::sim::classify::{self, Outcome, Strobes, Undecided};
use crate::sim::eom::{AveragedEom, FullEom, LinearisedEom, NoExtra, Viscous};
use crate::sim::fidelity;
use crate::sim::friction;
use crate::sim::lyapunov;
use crate::sim::periodic;
use crate::sim::sampling::{Recorder, Sampler, Sink};
use crate::sim::scene::Fidelity;
use crate::sim::signal::DriveSignal;

const NOT_LINEARISED: &str = "methods rkn86 and rkn1210 integrate the full or the averaged equation: set run.fidelity = \"full\" or \"averaged\", or use dop853";

/// The raw result of a generic run, before classification.
pub(in crate::sim) struct RunOut<'a, Rec: Recorder> {
    pub sampler: Sampler<'a, Rec>,
    pub work: Stats,
    pub end: EndState,
    pub sticks: Option<u64>,
}

/// Runs the composed equation, then classifies (running the Lyapunov pair only if asked).
pub(super) fn finish<R: Real, D: DriveSignal<R>, Rec: Recorder>(
    plan: &PlannedRun,
    sig: D,
    rec: &mut Rec,
) -> Result<Report, SimError> {
    let (p, ctx, angle) = (&plan.physical, &plan.ctx, plan.scene.drive.angle);
    let coulomb = plan.scene.effects.coulomb;
    let mut window = None;
    let rec = Sink {
        rec,
        window: ctx.classify.then(|| window.insert(Strobes::default())),
    };
    let full = || FullEom::<R, D, NoExtra>::new(p.omega0 * p.omega0, angle, sig, NoExtra);
    let averaged =
        || AveragedEom::<R, D, _>::new(p.omega0 * p.omega0, plan.r_effective, angle, sig, NoExtra);
    let out = match (coulomb, ctx.method) {
        (Some(mu), _) => friction::run(full(), R::from_f64(p.c), mu, ctx, rec)?,
        (None, Method::Rkn86 { rtol, atol }) => match plan.decision.fidelity {
            Fidelity::Full => periodic::run(full(), p.c, (rtol, atol), ctx, rec)?,
            Fidelity::Averaged => {
                let eom = averaged();
                adaptive::run(Slow(&eom), &RKN86, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Linearised => return Err(SimError::Unsupported(NOT_LINEARISED)),
        },
        (None, Method::Rkn1210 { rtol, atol }) => match plan.decision.fidelity {
            Fidelity::Full => {
                let eom = full();
                adaptive::run(Fast(&eom), &RKN1210, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Averaged => {
                let eom = averaged();
                adaptive::run(Slow(&eom), &RKN1210, p.c, (rtol, atol), ctx, rec)?
            }
            Fidelity::Linearised => return Err(SimError::Unsupported(NOT_LINEARISED)),
        },
        (None, _) => with_equation(plan, sig, Integrate { plan, rec })?,
    };
    let RunOut {
        sampler,
        work,
        end,
        sticks,
    } = out;
    let mut lyapunov_work = Stats::default();
    let outcome = if ctx.classify {
        let Some(strobes) = sampler.strobes.as_deref() else {
            return Err(SimError::Unsupported(
                "a classifying run keeps its window of strobes",
            ));
        };
        classify::classify(strobes, p.omega, ctx.undamped, || {
            match (sampler.window_start, coulomb) {
                (Some(start), None) => {
                    let (lambda, w) = with_equation(plan, sig, lyapunov::Exponent { ctx, start });
                    lyapunov_work = w;
                    lambda
                }
                // The pair-of-trajectories estimate is not defined across stick–slip switches.
                _ => 0.0,
            }
        })
    } else {
        Outcome::Undecided {
            reason: Undecided::NotClassified,
        }
    };
    Ok(Report {
        outcome,
        decision: plan.decision,
        physical: *p,
        duration: ctx.t_end,
        strobes: ctx.strobes_total,
        work,
        lyapunov_work,
        end,
        sticks,
    })
}

/// Something to do with a composed smooth equation.
pub(in crate::sim) trait Job<R: Real> {
    type Out;
    fn run<S: System<2, R> + Copy>(self, sys: S) -> Self::Out;
}

/// Builds the equation for the decided fidelity with exactly the listed forces, and hands it to
/// `job`. Each arm is its own concrete type.
fn with_equation<R: Real, D: DriveSignal<R>, J: Job<R>>(
    plan: &PlannedRun,
    sig: D,
    job: J,
) -> J::Out {
    let p = &plan.physical;
    let w0sq = p.omega0 * p.omega0;
    let angle = plan.scene.drive.angle;
    let viscous = (p.c > 0.0).then_some(Viscous {
        c: R::from_f64(p.c),
    });
    macro_rules! with_extras {
        ($build:expr) => {
            match viscous {
                None => job.run(($build)(NoExtra)),
                Some(v) => job.run(($build)(v)),
            }
        };
    }
    match plan.decision.fidelity {
        Fidelity::Full => with_extras!(|x| FullEom::<R, D, _>::new(w0sq, angle, sig, x)),
        Fidelity::Averaged => {
            let r_eff = plan.r_effective;
            with_extras!(|x| AveragedEom::<R, D, _>::new(w0sq, r_eff, angle, sig, x))
        }
        Fidelity::Linearised => {
            let inverted = fidelity::linearised_centre(&plan.scene);
            let up = angle.cos() < 0.0;
            with_extras!(|x| LinearisedEom::<R, D, _>::new(w0sq, inverted, up, sig, x))
        }
    }
}

/// The main run as a [`Job`].
struct Integrate<'c, 'r, Rec: Recorder> {
    plan: &'c PlannedRun,
    rec: Sink<'r, Rec>,
}

impl<'c, 'r, R: Real, Rec: Recorder> Job<R> for Integrate<'c, 'r, Rec> {
    type Out = Result<RunOut<'r, Rec>, SimError>;
    fn run<S: System<2, R> + Copy>(self, sys: S) -> Self::Out {
        integrate(sys, &self.plan.ctx, self.rec)
    }
}
