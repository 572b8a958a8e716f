//! Running a scene: check and derive it once into a planned run, compose the equation from the
//! listed effects, integrate, sample, classify.
//!
//! | module | stage |
//! |---|---|
//! | this one | the API: methods, options, the report, [`simulate`] |
//! | [`checks`] | whether the options can run the scene (method, tolerances, step counts, output) |
//! | [`plan`] | the scene checked and derived once ([`PlannedRun`]): ω, ω0, duration, fidelity, schedule, start |
//! | [`compose`] | the equation for the decided fidelity with exactly the listed forces; classification |
//! | [`stepping`] | the loops of DOP853 and the fixed-step methods, feeding the sampler |
//!
//! The equation is built once, as a concrete type, before the loop starts ([`compose`]).

mod checks;
mod compose;
mod plan;
mod stepping;

pub(super) use compose::{Job, RunOut};
pub(super) use plan::Context;
pub use plan::PlannedRun;
pub(super) use stepping::Dense;

use super::classify::Outcome;
use super::fidelity::{Decision, FidelityError};
use super::sampling::Recorder;
use super::scene::{Fidelity, Physical, Scene, SceneError};
use crate::integrate::{IntegrateError, Stats, Symplectic};
use core::fmt;
use serde::Serialize;

/// How to integrate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical RK4 with a fixed step of T/steps_per_period (T: the set-point drive period).
    Rk4 { steps_per_period: f64 },
    /// Adaptive Dormand–Prince 8(5,3) with dense output.
    Dop853 { rtol: f64, atol: f64 },
    /// Runge–Kutta–Nyström 8(6), viscous damping or none. On the full equation (drive periodic
    /// from t = 0): a whole number of steps per drive period, chosen per period from its error
    /// estimate ([`super::periodic`]); on the averaged equation: an adaptive step
    /// ([`super::slow`]).
    Rkn86 { rtol: f64, atol: f64 },
    /// Runge–Kutta–Nyström 12(10) with an adaptive step ([`super::adaptive`]), on the full or
    /// the averaged equation, viscous damping or none: for runs whose time scale is not the
    /// drive's (chaotic transients, a ramping drive).
    Rkn1210 { rtol: f64, atol: f64 },
    /// A symplectic method (Störmer–Verlet or a Yoshida composition) with a fixed step of
    /// T/steps_per_period: undamped scenes only.
    Symplectic {
        scheme: Symplectic,
        steps_per_period: f64,
    },
}

impl Method {
    /// Whether the method adapts its step to an error estimate step by step (what a step
    /// controller acts on) on the given fidelity.
    pub fn has_step_controller(&self, fidelity: Fidelity) -> bool {
        match self {
            Method::Dop853 { .. } | Method::Rkn1210 { .. } => true,
            Method::Rkn86 { .. } => fidelity == Fidelity::Averaged,
            Method::Rk4 { .. } | Method::Symplectic { .. } => false,
        }
    }

    /// The default: DOP853 at rtol = atol = 1e-9.
    pub const DEFAULT: Method = Method::Dop853 {
        rtol: 1e-9,
        atol: 1e-9,
    };
}

/// How an adaptive method picks its next step from its error estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Controller {
    /// From the last error alone (h ∝ err^(−1/(q+1))).
    #[default]
    Standard,
    /// Proportional–integral: the last two errors, β = [`Controller::PI_BETA`] (HNW I §IV.2).
    Pi,
}

impl Controller {
    /// The PI controller's β: the value HNW recommend for explicit Runge–Kutta pairs.
    pub const PI_BETA: f64 = 0.04;

    pub fn beta(self) -> f64 {
        match self {
            Controller::Standard => 0.0,
            Controller::Pi => Self::PI_BETA,
        }
    }

    /// As scene files spell it (`run.controller`): `standard`, `pi`.
    pub fn name(self) -> &'static str {
        match self {
            Controller::Standard => "standard",
            Controller::Pi => "pi",
        }
    }
}

impl fmt::Display for Controller {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The number format of the state and its arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    F64,
    F32,
}

impl Format {
    /// As scene files spell it (`run.format`): `f64`, `f32`.
    pub fn name(self) -> &'static str {
        match self {
            Format::F64 => "f64",
            Format::F32 => "f32",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How to run a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub method: Method,
    /// The step controller of an adaptive method; [`Controller::Pi`] is refused for methods
    /// without one ([`Method::has_step_controller`]).
    pub controller: Controller,
    pub format: Format,
    /// Output sample interval (s); 0 for none.
    pub out_dt: f64,
    /// Seed of the sensor's noise.
    pub seed: u64,
    /// Classify the outcome. Off, a run only integrates and samples (the outcome is
    /// `Undecided`), which is what benchmarks and error measurements want: classifying can cost
    /// a second run for the Lyapunov exponent.
    pub classify: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            method: Method::DEFAULT,
            controller: Controller::Standard,
            format: Format::F64,
            out_dt: 0.0,
            seed: 1,
            classify: true,
        }
    }
}

/// What a run found and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report {
    pub outcome: Outcome,
    pub decision: Decision,
    pub physical: Physical,
    pub duration: f64,
    /// Stroboscopic samples taken (drive periods completed).
    pub strobes: u64,
    /// Work of the run itself (including dense-output and interpolation evaluations).
    pub work: Stats,
    /// Work of the Lyapunov run, when the classifier needed one.
    pub lyapunov_work: Stats,
    /// Where the run ended. From the averaged model: the full state read back from the slow one
    /// ([`super::wobble`]).
    pub end: EndState,
    /// With Coulomb friction: how many times the pendulum stuck.
    pub sticks: Option<u64>,
}

/// The state at the end of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EndState {
    /// Time (s).
    pub t: f64,
    /// Angle (rad), unwrapped: whole turns included.
    pub theta: f64,
    /// Rate (rad/s).
    pub rate: f64,
}

impl EndState {
    /// (θ, θ') without the time.
    pub fn angle_rate(&self) -> (f64, f64) {
        (self.theta, self.rate)
    }
}

/// Why a run did not happen or did not finish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimError {
    Scene(SceneError),
    Fidelity(FidelityError),
    Integrate(IntegrateError),
    /// A method or option that cannot run this scene, with the reason.
    Unsupported(&'static str),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Scene(e) => e.fmt(f),
            SimError::Fidelity(e) => e.fmt(f),
            SimError::Integrate(e) => write!(f, "integration failed: {e}"),
            SimError::Unsupported(why) => f.write_str(why),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SimError {}

impl From<SceneError> for SimError {
    fn from(e: SceneError) -> Self {
        SimError::Scene(e)
    }
}
impl From<FidelityError> for SimError {
    fn from(e: FidelityError) -> Self {
        SimError::Fidelity(e)
    }
}
impl From<IntegrateError> for SimError {
    fn from(e: IntegrateError) -> Self {
        SimError::Integrate(e)
    }
}

/// Runs a scene and classifies the outcome: [`PlannedRun::new`], then [`PlannedRun::run`].
pub fn simulate<Rec: Recorder>(
    scene: &Scene,
    options: &Options,
    rec: &mut Rec,
) -> Result<Report, SimError> {
    PlannedRun::new(scene, options)?.run(rec)
}
