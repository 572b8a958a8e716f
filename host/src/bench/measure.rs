//! One measurement: run a method on a scene, compare its end state with a converged reference,
//! and record the error, the work and the median wall time.
//!
//! ```text
//! error = max(|Δθ|, |Δθ'|/ω)   at the end time, Δθ wrapped to (−π, π], ω the drive frequency
//! ```
//! An evaluation is one evaluation of the acceleration (for the symplectic methods, one force
//! evaluation), as the core's `Stats::rhs_evals` counts it, including the integrator's
//! start-up evaluations. Runs use `classify: false` and the [`Discard`] recorder, so no
//! stroboscopic sample or Lyapunov run is paid for.

use anyhow::{anyhow, Result};
use serde::Serialize;
use std::time::Duration;

use super::scenes::BenchScene;
use crate::timing;
use kapitza_core::integrate::Symplectic;
use kapitza_core::math;
use kapitza_core::sim::sampling::Discard;
use kapitza_core::sim::scene::Fidelity;
use kapitza_core::sim::{simulate, Controller, Format, Method, Options, Report, Scene};

/// Reference tolerance: DOP853 at rtol = atol = 1e-13 (f64).
pub const REFERENCE_TOL: f64 = 1e-13;
/// The reference's check: the same at 1e-12; their difference bounds the reference's error.
pub const CHECK_TOL: f64 = 1e-12;

/// A way of computing, one line on a work-precision plot (with a number format).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// Classical RK4, fixed step; setting: steps per drive period.
    Rk4,
    /// Our DOP853; setting: rtol = atol.
    Dop853,
    /// Our RKN 8(6), a whole number of steps per drive period; setting: rtol = atol.
    Rkn86,
    /// Our DOP853 with the PI step controller (`run.controller = "pi"`); setting: rtol = atol.
    Dop853Pi,
    /// Our adaptive RKN 12(10); setting: rtol = atol.
    Rkn1210,
    /// Störmer–Verlet; setting: steps per drive period.
    Verlet,
    /// Yoshida's 4th-order composition; setting: steps per drive period.
    Yoshida4,
    /// Yoshida's 6th-order composition; setting: steps per drive period.
    Yoshida6,
    /// The averaged model integrated by our DOP853; setting: rtol = atol.
    AveragedDop853,
    /// The averaged model by our adaptive RKN 8(6); setting: rtol = atol.
    AveragedRkn86,
    /// The same with the PI step controller; setting: rtol = atol.
    AveragedRkn86Pi,
    /// The peer: `ode_solvers::Dopri5`; setting: rtol = atol.
    PeerDopri5,
    /// The peer: `ode_solvers::Dop853` as published; setting: rtol = atol.
    PeerDop853,
    /// The peer's Dop853 with time as a state component (see [`super::peer`]).
    PeerDop853Autonomous,
}

impl Family {
    pub fn name(self) -> &'static str {
        match self {
            Family::Rk4 => "rk4",
            Family::Dop853 => "dop853",
            Family::Rkn86 => "rkn86",
            Family::Dop853Pi => "dop853-pi",
            Family::Rkn1210 => "rkn1210",
            Family::Verlet => "verlet",
            Family::Yoshida4 => "yoshida4",
            Family::Yoshida6 => "yoshida6",
            Family::AveragedDop853 => "averaged-dop853",
            Family::AveragedRkn86 => "averaged-rkn86",
            Family::AveragedRkn86Pi => "averaged-rkn86-pi",
            Family::PeerDopri5 => "peer-dopri5",
            Family::PeerDop853 => "peer-dop853",
            Family::PeerDop853Autonomous => "peer-dop853-autonomous",
        }
    }

    /// How people read it in tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Family::Rk4 => "RK4",
            Family::Dop853 => "DOP853",
            Family::Rkn86 => "RKN 8(6)",
            Family::Dop853Pi => "DOP853, PI controller",
            Family::Rkn1210 => "RKN 12(10)",
            Family::Verlet => "Verlet",
            Family::Yoshida4 => "Yoshida 4",
            Family::Yoshida6 => "Yoshida 6",
            Family::AveragedDop853 => "averaged model, DOP853",
            Family::AveragedRkn86 => "averaged model, RKN 8(6)",
            Family::AveragedRkn86Pi => "averaged model, RKN 8(6), PI controller",
            Family::PeerDopri5 => "ode_solvers Dopri5",
            Family::PeerDop853 => "ode_solvers Dop853 as published",
            Family::PeerDop853Autonomous => "ode_solvers Dop853, t as state",
        }
    }

    pub fn is_peer(self) -> bool {
        matches!(
            self,
            Family::PeerDopri5 | Family::PeerDop853 | Family::PeerDop853Autonomous
        )
    }

    /// The full equation (everything but the averaged model).
    pub fn is_full_model(self) -> bool {
        self.fidelity() == Fidelity::Full
    }

    /// The step controller of our adaptive methods.
    pub fn controller(self) -> Controller {
        match self {
            Family::Dop853Pi | Family::AveragedRkn86Pi => Controller::Pi,
            _ => Controller::Standard,
        }
    }

    pub fn adaptive(self) -> bool {
        matches!(
            self,
            Family::Dop853
                | Family::Rkn86
                | Family::Dop853Pi
                | Family::Rkn1210
                | Family::AveragedDop853
                | Family::AveragedRkn86
                | Family::AveragedRkn86Pi
                | Family::PeerDopri5
                | Family::PeerDop853
                | Family::PeerDop853Autonomous
        )
    }

    /// What the setting is: a tolerance or a step count.
    pub fn setting_name(self) -> SettingName {
        if self.adaptive() {
            SettingName::Rtol
        } else {
            SettingName::StepsPerPeriod
        }
    }

    /// Who made the measurement.
    pub fn who(self) -> Who {
        if self.is_peer() {
            Who::Peer
        } else {
            Who::Ours
        }
    }

    pub fn fidelity(self) -> Fidelity {
        match self {
            Family::AveragedDop853 | Family::AveragedRkn86 | Family::AveragedRkn86Pi => {
                Fidelity::Averaged
            }
            _ => Fidelity::Full,
        }
    }

    /// Our simulator's method for a setting (`None` for the peer).
    pub fn method(self, setting: f64) -> Option<Method> {
        let fixed = |scheme| Method::Symplectic {
            scheme,
            steps_per_period: setting,
        };
        Some(match self {
            Family::Rk4 => Method::Rk4 {
                steps_per_period: setting,
            },
            Family::Dop853 | Family::Dop853Pi | Family::AveragedDop853 => Method::Dop853 {
                rtol: setting,
                atol: setting,
            },
            Family::Rkn86 | Family::AveragedRkn86 | Family::AveragedRkn86Pi => Method::Rkn86 {
                rtol: setting,
                atol: setting,
            },
            Family::Rkn1210 => Method::Rkn1210 {
                rtol: setting,
                atol: setting,
            },
            Family::Verlet => fixed(Symplectic::Verlet),
            Family::Yoshida4 => fixed(Symplectic::Yoshida4),
            Family::Yoshida6 => fixed(Symplectic::Yoshida6),
            Family::PeerDopri5 | Family::PeerDop853 | Family::PeerDop853Autonomous => return None,
        })
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Whose integrator a measurement ran: ours or the peer's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Who {
    Ours,
    Peer,
}

impl std::fmt::Display for Who {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Who::Ours => "ours",
            Who::Peer => "peer",
        })
    }
}

/// What a ladder's setting is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SettingName {
    /// A tolerance, rtol = atol.
    Rtol,
    /// Fixed steps per drive period.
    StepsPerPeriod,
}

impl std::fmt::Display for SettingName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SettingName::Rtol => "rtol",
            SettingName::StepsPerPeriod => "steps_per_period",
        })
    }
}

/// One point of a work-precision curve.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    pub scene: String,
    pub family: Family,
    pub who: Who,
    /// Full or averaged.
    pub fidelity: Fidelity,
    pub format: Format,
    pub setting_name: SettingName,
    pub setting: f64,
    /// max(|Δθ|, |Δθ'|/ω) at the end against the reference.
    pub error: f64,
    /// Median wall time of one run (s).
    pub wall_s: f64,
    /// Median CPU time of this thread for one run (s): see [`crate::timing`].
    pub cpu_s: f64,
    pub rhs_evals: u64,
    pub steps: u64,
    pub rejected: u64,
}

/// The end state the errors are measured against, and how converged it is.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Reference {
    /// θ (rad, unwrapped) and θ' (rad/s) at the end, from DOP853 at [`REFERENCE_TOL`].
    pub theta: f64,
    pub rate: f64,
    pub rtol: f64,
    pub check_rtol: f64,
    /// The error measure between the reference and the same run at [`CHECK_TOL`]: an estimate
    /// of the check's error and an upper bound on the reference's own (DOP853's error falls
    /// with the tolerance).
    pub check_difference: f64,
    pub rhs_evals: u64,
}

/// The error measure between two end states.
pub fn error(a: (f64, f64), b: (f64, f64), omega: f64) -> f64 {
    math::wrap_pi(a.0 - b.0)
        .abs()
        .max((a.1 - b.1).abs() / omega)
}

pub fn options(method: Method, format: Format, classify: bool) -> Options {
    Options {
        method,
        format,
        classify,
        ..Options::default()
    }
}

/// One unclassified run.
pub fn run(scene: &Scene, method: Method, format: Format) -> Result<Report> {
    run_with(scene, method, Controller::Standard, format)
}

/// One unclassified run with the given step controller.
pub fn run_with(
    scene: &Scene,
    method: Method,
    controller: Controller,
    format: Format,
) -> Result<Report> {
    let options = Options {
        controller,
        ..options(method, format, false)
    };
    simulate(scene, &options, &mut Discard).map_err(|e| anyhow!("{e}"))
}

/// The converged reference of a scene's full model, with its check.
pub fn reference(s: &BenchScene) -> Result<Reference> {
    let at = |tol: f64| {
        run(
            &s.scene,
            Method::Dop853 {
                rtol: tol,
                atol: tol,
            },
            Format::F64,
        )
    };
    let r = at(REFERENCE_TOL)?;
    let c = at(CHECK_TOL)?;
    let omega = s.scene.physical()?.omega;
    Ok(Reference {
        theta: r.end.theta,
        rate: r.end.rate,
        rtol: REFERENCE_TOL,
        check_rtol: CHECK_TOL,
        check_difference: error(r.end.angle_rate(), c.end.angle_rate(), omega),
        rhs_evals: r.work.rhs_evals,
    })
}

/// What one of our runs needs.
pub struct Job<'a> {
    pub scene: &'a BenchScene,
    pub reference: &'a Reference,
    pub family: Family,
    pub format: Format,
    pub setting: f64,
}

/// Runs one of our methods once for its error and work, then times it (median of five batches
/// of at least `batch`).
pub fn ours(job: &Job, batch: Duration) -> Result<Point> {
    let method = job
        .family
        .method(job.setting)
        .ok_or_else(|| anyhow!("{} is not one of ours", job.family.name()))?;
    let scene = job.scene.with_fidelity(job.family.fidelity());
    let omega = scene.physical()?.omega;
    let controller = job.family.controller();
    let r = run_with(&scene, method, controller, job.format)?;
    let err = error(
        r.end.angle_rate(),
        (job.reference.theta, job.reference.rate),
        omega,
    );
    if !err.is_finite() {
        return Err(anyhow!("the end state is not finite"));
    }
    let cost = timing::cost(batch, || run_with(&scene, method, controller, job.format));
    Ok(Point {
        scene: job.scene.name.to_string(),
        family: job.family,
        who: job.family.who(),
        fidelity: job.family.fidelity(),
        format: job.format,
        setting_name: job.family.setting_name(),
        setting: job.setting,
        error: err,
        wall_s: cost.wall_s,
        cpu_s: cost.cpu_s,
        rhs_evals: r.work.rhs_evals,
        steps: r.work.steps,
        rejected: r.work.rejected,
    })
}
